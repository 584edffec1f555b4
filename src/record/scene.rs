//! One recorder for every scene: it logs the sampled series, the events and (with --timings)
//! the frame costs the same way for all of them, and leaves the 3D picture to the scene's
//! [`Draw`].

use rerun::{RecordingStream, TimeColumn};

use super::log_series_style;
use crate::scene::harness::{Event, EventKind, Frame, LOG10, Observer, Run, Scene, SeriesBatch};

/// The plot of wall-clock costs, shown with --timings.
pub const FRAME_COST: (&str, &str) = (
    "frame_cost",
    "simulation cost per 3D frame [ms, wall clock]",
);

/// The entity name a quantity is plotted under: its log10 name for the error-like ones.
pub fn plotted(quantity: &'static str) -> &'static str {
    LOG10
        .iter()
        .find(|(q, _)| *q == quantity)
        .map_or(quantity, |(_, log)| *log)
}

/// What is particular to one scene's recording: its 3D picture.
pub trait Draw<S: Scene> {
    /// Static styles, the stage, the run's description.
    fn start(
        &mut self,
        rec: &RecordingStream,
        scene: &S,
        lanes: &[(&'static str, &S::Lane)],
    ) -> anyhow::Result<()>;
    /// Sampled series of one lane arrived (the pendulum's phase portrait follows them).
    fn series(&mut self, _lane: usize, _batch: &SeriesBatch) {}
    /// The 3D state at one frame; the time is already set.
    fn frame(
        &mut self,
        rec: &RecordingStream,
        scene: &S,
        frame: &Frame<S::Lane>,
    ) -> anyhow::Result<()>;
    /// Bytes of the largest entity one 3D frame logs, when it is large (hair strands, rope
    /// nodes): the recorder cuts chunks every [`super::CHUNK_BYTES`] of it.
    fn frame_bytes(&self, _scene: &S) -> usize {
        0
    }
    /// A lane diverged at this moment (the time is already set): show it is gone, and why.
    fn diverged(&mut self, rec: &RecordingStream, event: &Event) -> anyhow::Result<()>;
    fn finish(
        &mut self,
        _rec: &RecordingStream,
        _scene: &S,
        _run: &Run<S::Lane>,
    ) -> anyhow::Result<()> {
        Ok(())
    }
}

/// Clears a diverged lane's moving entities (`<scene>/<lane>/<part>` for each part) and returns
/// the label that says when it stopped, for the entity that stays in its slot.
pub fn clear_diverged(
    rec: &RecordingStream,
    scene: &str,
    lane: &str,
    parts: &[&str],
    event: &Event,
) -> anyhow::Result<String> {
    for part in parts {
        rec.log(format!("{scene}/{lane}/{part}"), &rerun::Clear::flat())?;
    }
    // Two short lines rather than one long one: the label stays inside a narrow view.
    Ok(format!("{lane}\ndiverged at t = {:.3} s", event.time))
}

/// Records a scene's run: `<scene>/plots/<quantity>/<lane>` series, `<scene>/events`, and the
/// scene's own 3D entities. `frame` N is at N / `frame_rate` s in every scene of a recording (one
/// moment in `physlab all`), and only on 3D frames and events: the series are sampled more often,
/// and one frame index must not hold several samples.
pub struct SceneRecorder<D> {
    rec: RecordingStream,
    draw: D,
    names: Vec<&'static str>,
    /// Each lane's plotted quantities, in the order of its batches' columns.
    quantities: Vec<&'static [&'static str]>,
    /// Whether wall-clock frame costs are plotted.
    timings: bool,
    /// The recording's `frame` rate [Hz] (the highest of its scenes'); the scene's own by default.
    frame_rate: Option<f64>,
    /// Bytes of the largest 3D entity logged since the last flush.
    unflushed: usize,
}

impl<D> SceneRecorder<D> {
    pub fn new(rec: RecordingStream, draw: D, timings: bool) -> Self {
        SceneRecorder {
            rec,
            draw,
            names: Vec::new(),
            quantities: Vec::new(),
            timings,
            frame_rate: None,
            unflushed: 0,
        }
    }

    /// Numbers the `frame` timeline at `hz` frames per second, for a recording of several scenes.
    pub fn with_frame_rate(mut self, hz: f64) -> Self {
        self.frame_rate = Some(hz);
        self
    }

    /// Sets `sim_time`, and `frame` to the last 3D frame at or before `tick`.
    fn set_time<S: Scene>(&self, scene: &S, tick: u64, time: f64) {
        let schedule = scene.schedule();
        let rate = self.frame_rate.unwrap_or(schedule.fps);
        let frame_time = schedule.time(schedule.frame_tick(schedule.frame_at(tick)));
        self.rec.set_duration_secs("sim_time", time);
        self.rec
            .set_time_sequence("frame", (frame_time * rate).round() as i64);
    }
}

impl<S: Scene, D: Draw<S>> Observer<S> for SceneRecorder<D> {
    fn start(&mut self, scene: &S, lanes: &[(&'static str, &S::Lane)]) -> anyhow::Result<()> {
        self.names = lanes.iter().map(|l| l.0).collect();
        self.quantities = lanes.iter().map(|l| scene.quantities(l.1)).collect();
        self.draw.start(&self.rec, scene, lanes)?;
        for &(name, lane) in lanes {
            let timed = self.timings && scene.is_method(lane);
            let plots = scene.quantities(lane).iter().map(|&q| plotted(q));
            for plot in plots.chain(timed.then_some(FRAME_COST.0)) {
                let entity = format!("{}/plots/{plot}/{name}", scene.name());
                log_series_style(&self.rec, entity, name, name)?;
            }
        }
        // The static styles in a flush of their own (see `event`).
        self.rec.flush_blocking()?;
        Ok(())
    }

    fn series(&mut self, scene: &S, lane: usize, batch: &SeriesBatch) -> anyhow::Result<()> {
        self.draw.series(lane, batch);
        let name = self.names[lane];
        for (q, (&quantity, values)) in self.quantities[lane].iter().zip(&batch.columns).enumerate()
        {
            let entity = format!("{}/plots/{}/{name}", scene.name(), plotted(quantity));
            let log = plotted(quantity) != quantity;
            // The rows this quantity's plot needs: an aggregated run keeps other quantities'
            // extremes in the same rows; a log plot leaves zeros out (log10 = −∞).
            let kept: Vec<usize> = (0..values.len())
                .filter(|&i| batch.needed[i] & (1 << q) != 0 && !(log && values[i] == 0.0))
                .collect();
            if kept.is_empty() {
                continue;
            }
            let value = |i: usize| {
                if log {
                    values[i].abs().log10()
                } else {
                    values[i]
                }
            };
            self.rec.send_columns(
                entity,
                [TimeColumn::new_duration_secs(
                    "sim_time",
                    kept.iter().map(|&i| batch.times[i]),
                )],
                rerun::Scalars::new(kept.iter().map(|&i| value(i))).columns_of_unit_batches()?,
            )?;
        }
        Ok(())
    }

    fn frame(&mut self, scene: &S, frame: &Frame<S::Lane>) -> anyhow::Result<()> {
        self.set_time(scene, frame.tick, frame.time);
        self.draw.frame(&self.rec, scene, frame)?;
        // Large rows are cut into chunks here, at points that depend only on what was logged
        // (Rerun's own byte count varies from run to run).
        self.unflushed += self.draw.frame_bytes(scene);
        if self.unflushed >= super::CHUNK_BYTES {
            self.rec.flush_blocking()?;
            self.unflushed = 0;
        }
        if self.timings && frame.tick > 0 {
            for (i, lane) in frame.lanes.iter().enumerate() {
                if let Some((l, _)) = lane
                    && scene.is_method(l)
                {
                    self.rec.log(
                        format!("{}/plots/{}/{}", scene.name(), FRAME_COST.0, self.names[i]),
                        &rerun::Scalars::single(frame.cost_ms[i]),
                    )?;
                }
            }
        }
        Ok(())
    }

    fn event(&mut self, scene: &S, event: &Event) -> anyhow::Result<()> {
        self.set_time(scene, event.tick, event.time);
        self.rec.log(
            format!("{}/events", scene.name()),
            &rerun::TextLog::new(event.message.clone()).with_level(rerun::TextLogLevel::WARN),
        )?;
        if event.kind == EventKind::Divergence {
            // Its own flush on both sides: rows of one entity with different components (the
            // positions, then the clear) that meet in one flush become chunks in an order that
            // varies between processes, which would make identical runs' files differ in order.
            self.rec.flush_blocking()?;
            self.draw.diverged(&self.rec, event)?;
            self.rec.flush_blocking()?;
            self.unflushed = 0;
        }
        Ok(())
    }

    fn finish(&mut self, scene: &S, run: &Run<S::Lane>) -> anyhow::Result<()> {
        // As at a divergence: what the end adds (the phase portrait's path) in a flush of its own.
        self.rec.flush_blocking()?;
        self.draw.finish(&self.rec, scene, run)
    }
}
