//! Plot axes with at least three tick labels at 1600×1000. Rerun 0.36.3 has no tick setting:
//! its time series labels the time axis at whole 10ⁿ s (then 1, 10 min, ...), the coarsest of
//! them that leaves 150 px between grid lines, and a finer one only when its spacing is over
//! 60 px (fading in up to 80); the value axis at multiples of 10ⁿ alone, drawn when over 20 px
//! apart (fading in up to 30). The time axis' end is chosen with the layout; the value axis'
//! range when the data are known: [`Extents`] sees every scalar written, and [`LateAxes`] sends
//! each plot's range around all of its data when the recording ends.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use rerun::external::re_log_types::BlueprintActivationCommand;
use rerun::external::re_sdk_types::blueprint::archetypes::ScalarAxis;
use rerun::log::{Chunk, LogMsg};
use rerun::sink::{LogSink, SinkFlushError};

/// What a plot's frame leaves of its view [logical px, measured on screenshots]: the value
/// axis' labels at the left, the title bar and time axis' labels in the height.
const VALUE_LABELS_PX: f32 = 50.0;
const TITLE_AND_TIME_LABELS_PX: f32 = 42.0;
/// The spacing at which a label is drawn at least half as bright as a full one [px].
const TIME_LABEL_PX: f64 = 65.0;
const VALUE_LABEL_PX: f64 = 24.0;

/// Rerun's time grid steps [ns]: 10ⁿ up to 10 s, then a minute, ten minutes, an hour, ...
fn next_step(ns: i64) -> i64 {
    match ns {
        ..=1_000_000_000 => ns * 10,
        10_000_000_000 | 600_000_000_000 => ns * 6,
        60_000_000_000 => ns * 10,
        3_600_000_000_000 => ns * 12,
        43_200_000_000_000 => ns * 2,
        _ => ns.saturating_mul(10),
    }
}

/// The time labels readable on a time axis from 0 to `end` [s] in a view `width` px wide.
fn time_labels(end: f64, width: f32) -> f64 {
    let ns = end * 1e9;
    let lines = f64::from(width - 10.0) / 150.0;
    let mut small = 1;
    while ns / next_step(small) as f64 > lines && next_step(small) > small {
        small = next_step(small);
    }
    let px_per_ns = f64::from(width - VALUE_LABELS_PX) / ns;
    let step = if small as f64 * px_per_ns >= TIME_LABEL_PX {
        small
    } else {
        next_step(small)
    };
    (ns / step as f64).floor() + 1.0
}

/// The end of a time axis from 0 that reaches `end` [s] and shows three labels or more in a view
/// `width` px wide: `end` itself where it does, else just past the nearest multiple of a grid
/// step past it.
pub fn time_end(end: f64, width: f32) -> f64 {
    if time_labels(end, width) >= 3.0 {
        return end;
    }
    std::iter::successors(Some(1i64), |&s| (next_step(s) > s).then(|| next_step(s)))
        .take_while(|&s| s as f64 <= end * 1e9)
        // 6% to spare: the last label whole, not cut at the plot's edge.
        .map(|s| (end * 1e9 / s as f64).ceil().max(2.0) * s as f64 / 1e9 * 1.06)
        .filter(|&e| time_labels(e, width) >= 3.0)
        .fold(f64::INFINITY, f64::min)
        .min(20.0 * end)
}

/// The value range around `lo..hi` that shows three labelled multiples of one 10ⁿ, each
/// readable, in a view `height` px tall: the narrowest of those 10ⁿ give (the data's own
/// range where it holds three already), with 3% to spare at each end.
pub fn value_range(lo: f64, hi: f64, height: f32) -> (f64, f64) {
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    };
    let frame = f64::from(height - TITLE_AND_TIME_LABELS_PX).max(1.0);
    let decade = (hi - lo).log10().floor() as i32;
    let fitted = (decade - 3..=decade + 1).filter_map(|k| {
        let step = 10f64.powi(k);
        let (mut first, mut last) = ((lo / step).ceil(), (hi / step).floor());
        let (mut bottom, mut top) = (lo, hi);
        // Fewer than three multiples inside: take in the nearest one, below or above.
        while last - first < 2.0 {
            if bottom - (first - 1.0) * step <= (last + 1.0) * step - top {
                first -= 1.0;
                bottom = first * step;
            } else {
                last += 1.0;
                top = last * step;
            }
        }
        let span = 1.06 * (top - bottom);
        (step * frame / span >= VALUE_LABEL_PX).then_some((bottom, top, span))
    });
    let (bottom, top, span) =
        fitted
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .unwrap_or((lo, hi, hi - lo));
    let spare = (span - (top - bottom)) / 2.0;
    (bottom - spare, top + spare)
}

/// The lowest and highest finite value each entity's `Scalars` reached in the recording.
#[derive(Clone, Default)]
pub struct Extents(Arc<Mutex<BTreeMap<String, (f64, f64)>>>);

impl Extents {
    /// The range of every entity under `origin` together, if any holds a value.
    fn of(&self, origin: &str) -> Option<(f64, f64)> {
        let map = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let prefix = format!("{origin}/");
        map.iter()
            .filter(|(e, _)| e.starts_with(&prefix))
            .map(|(_, r)| *r)
            .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
    }
}

impl LogSink for Extents {
    fn send(&self, msg: LogMsg) {
        let LogMsg::ArrowMsg(store, arrow) = msg else {
            return;
        };
        let scalars = rerun::Scalars::descriptor_scalars().component;
        let Ok(chunk) = Chunk::from_arrow_msg(&arrow) else {
            return;
        };
        if !store.is_recording() || !chunk.components().contains_component(scalars) {
            return;
        }
        let values = chunk.iter_slices::<f64>(scalars).flatten().copied();
        let (lo, hi) = values
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if lo <= hi {
            let mut map = self.0.lock().unwrap_or_else(|e| e.into_inner());
            let r = map
                .entry(chunk.entity_path().to_string())
                .or_insert((lo, hi));
            *r = (r.0.min(lo), r.1.max(hi));
        }
    }

    fn flush_blocking(&self, _timeout: std::time::Duration) -> Result<(), SinkFlushError> {
        Ok(())
    }
}

/// A plot whose value range is set when the recording ends: its view's path in the blueprint
/// store, its entity origin, its height [px] and a range it opens on in any case.
#[derive(Clone, Debug)]
pub struct ValueAxis {
    pub view: String,
    pub origin: String,
    pub height: f32,
    pub floor: Option<(f64, f64)>,
}

/// The value axes of a sent layout, with what it takes to update its blueprint.
pub struct LateAxes {
    pub application_id: rerun::ApplicationId,
    pub activation: BlueprintActivationCommand,
    pub axes: Vec<ValueAxis>,
}

impl LateAxes {
    /// Sends each plot's range around its data and floor, and makes the layout active again (the
    /// viewer shows a copy of the blueprint made at its activation).
    pub fn send(self, rec: &rerun::RecordingStream, extents: &Extents) -> anyhow::Result<()> {
        let properties: Vec<_> = (self.axes.iter())
            .filter_map(|a| {
                let (lo, hi) = extents.of(&a.origin)?;
                let (lo, hi) = a.floor.map_or((lo, hi), |f| (lo.min(f.0), hi.max(f.1)));
                let (lo, hi) = value_range(lo, hi, a.height);
                let axis = ScalarAxis::new().with_range(rerun::components::Range1D::new(lo, hi));
                let batches = rerun::AsComponents::as_serialized_batches(&axis);
                Some((format!("{}/ScalarAxis", a.view), batches))
            })
            .collect();
        if !properties.is_empty() {
            let (app, activation) = (&self.application_id, &self.activation);
            let messages = property_messages(app, activation, properties, 1)?;
            rec.send_blueprint(messages, self.activation);
        }
        Ok(())
    }
}

/// The messages that write `properties` into the blueprint store `activation` names, at
/// `blueprint` = `time` (as the SDK logs blueprints).
pub fn property_messages(
    app: &rerun::ApplicationId,
    activation: &BlueprintActivationCommand,
    properties: Vec<(String, Vec<rerun::SerializedComponentBatch>)>,
    time: i64,
) -> anyhow::Result<Vec<LogMsg>> {
    if properties.is_empty() {
        return Ok(Vec::new());
    }
    let (props, storage) = rerun::RecordingStreamBuilder::new(app.clone())
        .recording_id(activation.blueprint_id.recording_id().clone())
        .blueprint()
        .send_properties(false)
        .memory()?;
    props.set_log_time_enabled(false); // no wall clock in a recording
    props.set_time_sequence("blueprint", time);
    for (path, batches) in properties {
        props.log_serialized_batches(path, false, batches)?;
    }
    Ok(storage
        .take()
        .into_iter()
        .filter(|m| matches!(m, LogMsg::ArrowMsg(..)))
        .collect())
}
