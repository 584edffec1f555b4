//! `physlab diff --output D.rrd`: the differences B − A of two recordings as series, so that the
//! viewer shows where they part.

use std::path::Path;

use rerun::TimeColumn;
use rerun::blueprint::{Blueprint, TextDocumentView};

use super::compare::{Contents, Row};
use super::{Destinations, Recording};

/// Writes one series per timed numeric component both recordings hold, at the times both hold:
/// b − a for one value per row, max |b − a| over the row's values otherwise, under
/// `diff/<entity>/<component>`; and the printed report as `diff/report`. Returns the number of
/// series.
pub fn record_diff(path: &Path, a: &Contents, b: &Contents, report: &str) -> anyhow::Result<usize> {
    let d = Destinations::output(path);
    let blueprint = Blueprint::new(TextDocumentView::new("report").with_origin("/diff/report"))
        .with_auto_views(true);
    let recording = Recording::create(&d, "physlab-diff", "diff", blueprint)?;
    let rec = recording.stream();
    let mut series = 0;
    for (key, rows_a) in a {
        if crate::interrupt::requested() {
            // Dropped uncommitted: the hidden file goes, an earlier file stays as it was.
            return Err(crate::interrupt::Interrupted(format!(
                "interrupted: {} not written",
                path.display()
            ))
            .into());
        }
        let Some(rows_b) = b.get(key) else {
            continue;
        };
        let (times, values) = paired(rows_a, rows_b);
        if times.is_empty() {
            continue;
        }
        let component = key.1.rsplit(':').next().unwrap_or(&key.1);
        let entity = format!("diff{}/{component}", key.0);
        rec.send_columns(
            entity.clone(),
            [TimeColumn::new_duration_nanos("sim_time", times)],
            rerun::Scalars::new(values).columns_of_unit_batches()?,
        )?;
        series += 1;
    }
    rec.log_static(
        "diff/report",
        &rerun::TextDocument::from_markdown(format!("```text\n{report}```\n")),
    )?;
    recording.commit()?;
    Ok(series)
}

/// The times both series hold (rows paired in order within a time) and the difference there.
fn paired(a: &[Row], b: &[Row]) -> (Vec<i64>, Vec<f64>) {
    let (mut times, mut values) = (Vec::new(), Vec::new());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (ra, rb) = (&a[i], &b[j]);
        match (ra.time, rb.time) {
            (Some(ta), Some(tb)) if ta == tb => {
                if !ra.nums.is_empty() && ra.nums.len() == rb.nums.len() {
                    times.push(ta);
                    values.push(if ra.nums.len() == 1 {
                        rb.nums[0] - ra.nums[0]
                    } else {
                        ra.nums
                            .iter()
                            .zip(&rb.nums)
                            .map(|(x, y)| (y - x).abs())
                            .fold(0.0, f64::max)
                    });
                }
                i += 1;
                j += 1;
            }
            (ta, tb) if ta < tb => i += 1,
            _ => j += 1,
        }
    }
    (times, values)
}
