//! `physlab diff --output D.rrd`: the differences B − A of two recordings as series, so that the
//! viewer shows where they part.

use std::collections::BTreeMap;
use std::path::Path;

use rerun::TimeColumn;
use rerun::blueprint::{Blueprint, TextDocumentView};

use super::compare::{Key, PairedRow};
use super::{Destinations, Recording};

/// Rows held per series before they are sent: the writer's memory does not grow with the file.
const BATCH: usize = 4096;

/// Writes one series per timed numeric component both recordings hold, at the times both hold,
/// as the comparison pairs their rows: b − a for one value per row, max |b − a| over the row's
/// values otherwise, under `diff/<entity>/<component>`; and at the end the printed report as
/// `diff/report`.
pub struct DiffWriter {
    recording: Recording,
    pending: BTreeMap<Key, (Vec<i64>, Vec<f64>)>,
}

impl DiffWriter {
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let d = Destinations::output(path);
        let blueprint = Blueprint::new(TextDocumentView::new("report").with_origin("/diff/report"))
            .with_auto_views(true);
        Ok(DiffWriter {
            recording: Recording::create(&d, "physlab-diff", "diff", blueprint)?,
            pending: BTreeMap::new(),
        })
    }

    /// One pair of rows at the same time.
    pub fn pair(&mut self, key: &Key, a: &dyn PairedRow, b: &dyn PairedRow) -> anyhow::Result<()> {
        let Some(time) = a.time() else {
            return Ok(());
        };
        let n = a.count();
        if n == 0 || n != b.count() {
            return Ok(());
        }
        let mut differences = a.nums().zip(b.nums()).map(|(x, y)| y - x);
        let value = if n == 1 {
            differences.next().unwrap_or(0.0)
        } else {
            differences.map(f64::abs).fold(0.0, f64::max)
        };
        let (times, values) = self.pending.entry(key.clone()).or_default();
        times.push(time);
        values.push(value);
        if times.len() >= BATCH {
            self.send(key)?;
        }
        Ok(())
    }

    fn send(&mut self, key: &Key) -> anyhow::Result<()> {
        let Some((times, values)) = self.pending.get_mut(key) else {
            return Ok(());
        };
        if times.is_empty() {
            return Ok(());
        }
        let component = key.1.rsplit(':').next().unwrap_or(&key.1);
        self.recording.stream().send_columns(
            format!("diff{}/{component}", key.0),
            [TimeColumn::new_duration_nanos(
                "sim_time",
                std::mem::take(times),
            )],
            rerun::Scalars::new(std::mem::take(values)).columns_of_unit_batches()?,
        )?;
        Ok(())
    }

    /// Sends what is left and the report, and completes the file. Returns the number of series.
    pub fn finish(mut self, report: &str) -> anyhow::Result<usize> {
        let keys: Vec<Key> = self.pending.keys().cloned().collect();
        for key in &keys {
            self.send(key)?;
        }
        self.recording.stream().log_static(
            "diff/report",
            &rerun::TextDocument::from_markdown(format!("```text\n{report}```\n")),
        )?;
        self.recording.commit()?;
        Ok(keys.len())
    }
}
