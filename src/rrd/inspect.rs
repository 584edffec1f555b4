//! `physlab inspect`: what a recording holds and how it was made, read back chunk by chunk.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use super::read::each_chunk;

/// A warning or info line of a scene's event log.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedEvent {
    pub entity: String,
    /// Simulated time [s].
    pub time: f64,
    pub level: String,
    pub text: String,
}

/// What `inspect` reports.
#[derive(Clone, Debug, Default)]
pub struct RecordingInfo {
    pub application_id: String,
    /// The `physlab` recording properties: version, commit, config, command line, methods...
    pub properties: BTreeMap<String, String>,
    /// The `physlab_run` properties: where each scene ended (`<scene>_status`, `_ended`...).
    pub run: BTreeMap<String, String>,
    pub entities: BTreeSet<String>,
    /// Smallest and largest `sim_time` [s].
    pub time_range: Option<(f64, f64)>,
    pub events: Vec<LoggedEvent>,
    pub chunks: usize,
    pub has_footer: bool,
    /// Why it has none, in words (empty when it has one).
    pub why_no_footer: String,
    /// Why it is not a whole recording though it has its footer: its data start without their
    /// store's info.
    pub headless: Option<String>,
}

impl RecordingInfo {
    /// A provenance property as text, `(not recorded)` when the recording has none.
    pub fn property(&self, key: &str) -> &str {
        self.properties
            .get(key)
            .map_or("(not recorded)", String::as_str)
    }

    /// The scenes: the first component of every entity path but the properties'.
    pub fn scenes(&self) -> BTreeSet<String> {
        let first = |e: &String| {
            e.trim_start_matches('/')
                .split('/')
                .next()
                .map(str::to_string)
        };
        let scenes = self.entities.iter().filter_map(first);
        scenes
            .filter(|s| !s.is_empty() && !s.starts_with("__"))
            .collect()
    }
}

/// The most text a recording's description may hold: its properties, event texts and entity
/// names together. physlab's own take kilobytes; without a cap, text logged message by message
/// piles up whatever the per-message cap (16 properties of 200 MB in a 13 MB file took 3.5 GB).
pub const MAX_DESCRIPTION_BYTES: usize = 64 << 20;

/// A properties chunk's values by key (`command_line`, ...), the first of each.
fn properties(chunk: &rerun::log::Chunk) -> impl Iterator<Item = (String, String)> + '_ {
    chunk.component_descriptors().filter_map(|descriptor| {
        let key = descriptor.component.as_str();
        let key = key.rsplit(':').next().unwrap_or(key).to_string();
        let values = chunk.iter_slices::<String>(descriptor.component).next()?;
        Some((key, values.first()?.as_str().to_string()))
    })
}

/// The command line that made the physlab recording `path`, and when: the nanoseconds since
/// the epoch of its provenance chunk's id (Rerun draws chunk ids from the clock). Only the
/// blueprint and properties at the file's start are read; `None` for a file that is no
/// recording, or whose data starts without physlab's provenance.
pub fn made_by(path: &Path) -> Option<(String, u64)> {
    let mut messages = super::read::Messages::open(path).ok()?;
    while let Ok(Some(msg)) = messages.next_chunk() {
        let entity = msg.chunk.entity_path().to_string();
        if !msg.recording {
            continue; // the blueprint
        } else if entity == "/__properties/physlab" {
            let (_, command) = properties(&msg.chunk).find(|(k, _)| k == "command_line")?;
            return Some((command, msg.chunk.id().as_tuid().nanos_since_epoch()));
        } else if !entity.starts_with("/__properties") {
            return None;
        }
    }
    None
}

/// Reads a recording. A missing, empty, non-rrd, corrupt or truncated file is a usage error
/// naming the file and what is wrong with it; a stop request `Error::Interrupted`.
pub fn read_recording(path: &Path) -> anyhow::Result<RecordingInfo> {
    read_recording_within(path, MAX_DESCRIPTION_BYTES)
}

/// [`read_recording`], refusing a file whose description holds more than `cap` bytes of text.
pub(super) fn read_recording_within(path: &Path, cap: usize) -> anyhow::Result<RecordingInfo> {
    let mut info = RecordingInfo::default();
    let mut held = 0usize;
    // `each_chunk` names the file.
    let mut hold = |bytes: usize, freed: usize| -> Result<(), String> {
        held = (held + bytes).saturating_sub(freed);
        if held > cap {
            return Err(format!(
                "its properties, event texts and entity names hold more than {} MiB (physlab's \
                 own take kilobytes)",
                cap >> 20
            ));
        }
        Ok(())
    };
    let sim_time = rerun::TimelineName::from("sim_time");
    let text = rerun::TextLog::descriptor_text().component;
    let end = each_chunk(path, |msg| {
        if !msg.recording {
            return Ok(()); // the blueprint
        }
        if info.application_id.is_empty() {
            info.application_id = msg.application_id;
        }
        let chunk = msg.chunk;
        info.chunks += 1;
        let entity = chunk.entity_path().to_string();
        if entity.starts_with("/__properties") {
            let target = match entity.rsplit('/').next() {
                Some("physlab") => &mut info.properties,
                Some("physlab_run") => &mut info.run,
                _ => return Ok(()),
            };
            if !target.is_empty() {
                // physlab sends each once a run: two are two runs under one recording id.
                return Err(format!(
                    "it holds two runs' provenance ({entity} twice) in one recording, and \
                     physlab reads one run a file"
                ));
            }
            for (key, v) in properties(&chunk) {
                let freed = target.get(&key).map_or(0, |old| key.len() + old.len());
                hold(key.len() + v.len(), freed)?;
                target.insert(key, v);
            }
            return Ok(());
        }
        if !info.entities.contains(&entity) {
            hold(entity.len(), 0)?;
            info.entities.insert(entity.clone());
        }
        if let Some(column) = chunk.timelines().get(&sim_time) {
            let range = column.time_range();
            let (lo, hi) = (
                range.min().as_i64() as f64 * 1e-9,
                range.max().as_i64() as f64 * 1e-9,
            );
            info.time_range = Some(match info.time_range {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        }
        if chunk.components().contains_component(text) && !chunk.is_static() {
            events(&mut info.events, &entity, &chunk, &mut hold)?;
        }
        Ok(())
    })?;
    info.has_footer = end.has_footer();
    if !info.has_footer {
        info.why_no_footer = end.missing_footer();
    }
    info.headless = end.headless.map(|at| {
        format!(
            "its data start at byte {at} without the store info Rerun writes before them (a \
             piece cut from a recording, or an edited file)"
        )
    });
    info.events.sort_by(|a, b| {
        a.time
            .total_cmp(&b.time)
            .then_with(|| a.entity.cmp(&b.entity))
    });
    Ok(info)
}

/// A text log's events, each of its texts counted by `hold` (which refuses past the cap).
fn events(
    events: &mut Vec<LoggedEvent>,
    entity: &str,
    chunk: &rerun::log::Chunk,
    hold: &mut impl FnMut(usize, usize) -> Result<(), String>,
) -> Result<(), String> {
    let text = rerun::TextLog::descriptor_text().component;
    let level = rerun::TextLog::descriptor_level().component;
    let levels: Vec<Option<String>> = chunk
        .iter_slices::<String>(level)
        .map(|l| l.first().map(|s| s.as_str().to_string()))
        .collect();
    let times = chunk.iter_indices(&rerun::TimelineName::from("sim_time"));
    for (k, ((t, _), texts)) in times.zip(chunk.iter_slices::<String>(text)).enumerate() {
        for s in texts {
            hold(entity.len() + s.as_str().len(), 0)?;
            events.push(LoggedEvent {
                entity: entity.to_string(),
                time: t.as_i64() as f64 * 1e-9,
                level: levels.get(k).cloned().flatten().unwrap_or_default(),
                text: s.as_str().to_string(),
            });
        }
    }
    Ok(())
}
