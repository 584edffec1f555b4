//! The one run loop every scene shares: N lanes (methods, and a reference where a scene has
//! one) side by side on one schedule, stepped a block at a time (only the stepping timed) and
//! checked every tick; a scene says only what is particular to it through [`Scene`].
//!
//! A "tick" is the scene's unit of time on the schedule: one step of dt for the pendulum and the
//! rope, one simulation frame (of `substeps` steps) for hair.

use crate::integrate::Counts;

mod outcome;
mod running;
mod schedule;
mod series;
pub use outcome::{LaneStats, Run, divergence_cell};
use running::Running;
pub use schedule::{Clock, MAX_PLOT_POINTS, Schedule, Window, Windows};
pub use series::{LOG10, LaneSeries, Sampler, SeriesBatch, SeriesPlan, WHOLE, absent_when_zero};

#[derive(Clone, Debug, PartialEq)]
pub enum EventKind {
    /// The lane stopped: its state is not finite or past the scene's stated bound.
    Divergence,
    /// An implicit step's Newton solve missed its tolerance (the step is kept).
    SolverNotConverged,
}

/// Something that happened to one lane at one moment, for the recording's event log.
#[derive(Clone, Debug)]
pub struct Event {
    pub lane: usize,
    pub time: f64,
    pub tick: u64,
    pub kind: EventKind,
    pub message: String,
}

/// What a scene found when it checked a block of ticks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checked {
    /// Ticks that passed, from the block's first; fewer than the block when the lane diverged.
    pub accepted: usize,
    /// Why the tick after the accepted ones failed its check.
    pub divergence: Option<String>,
    /// The first tick (offset in the block, among the accepted or the failing one) whose
    /// implicit solve missed its tolerance, and what the solver was asked for.
    pub solver_miss: Option<(usize, String)>,
    /// What the lane had spent when it failed, for scenes that step past the failing tick
    /// within a block (otherwise [`Scene::counts`] after the block is used).
    pub counts: Option<Counts>,
}

impl Checked {
    /// Every tick of the block passed.
    pub fn all(len: usize) -> Self {
        Checked {
            accepted: len,
            ..Checked::default()
        }
    }
}

/// One scene: its lanes, how a block of ticks is stepped and checked, what is observed.
pub trait Scene: Sync {
    /// One lane's working state: a method's integrator and measurements, or the reference.
    type Lane: Send;

    /// The scene's name: `pendulum`, `rope`, `hair`.
    fn name(&self) -> &'static str;
    fn schedule(&self) -> Schedule;
    /// Every lane, in the order of tables and layouts, with its name.
    fn lanes(&self) -> Vec<(&'static str, Self::Lane)>;
    /// Whether this lane is a method (timed, counted) rather than a reference.
    fn is_method(&self, _lane: &Self::Lane) -> bool {
        true
    }
    /// The scalar series a lane observes, in the order [`Scene::check`] samples them.
    fn quantities(&self, lane: &Self::Lane) -> &'static [&'static str];
    /// The values at tick 0, if the series start there.
    fn initial(&self, lane: &Self::Lane) -> Option<Vec<f64>>;
    /// The run's windows, kept whole when its series are aggregated: the first and last ten
    /// seconds by default.
    fn windows(&self) -> Windows {
        Windows::with(&[])
    }
    /// Longest block of ticks stepped between checks.
    fn max_block(&self) -> u64 {
        u64::MAX
    }
    /// Whether a lane keeps every tick of its block, so that a 3D frame inside a block can be
    /// read back ([`Scene::check`] then sees them all). Otherwise blocks end at 3D frames.
    fn traced(&self) -> bool {
        false
    }
    /// Whether the lanes of a block are stepped and checked side by side on the rayon pool
    /// (each lane's own work is one thread's). A scene whose lanes spread their own work over
    /// the pool (hair) steps them one after another, so that each lane's time is its own.
    fn side_by_side(&self) -> bool {
        false
    }
    /// Work shared by every lane over ticks first..first+len (the pendulum's reference). It may
    /// return early when [`crate::interrupt::requested`]; the block is then not stepped.
    fn prepare(&mut self, _first: u64, _len: usize) {}
    /// Steps the lane over ticks first..first+len. This is what is timed.
    fn advance(&self, lane: &mut Self::Lane, first: u64, len: usize);
    /// Checks every tick the last `advance` took, in order, stopping at the first that fails,
    /// and samples the series where the schedule asks.
    fn check(&self, lane: &mut Self::Lane, first: u64, len: usize, out: &mut Sampler) -> Checked;
    /// Force evaluations and missed implicit solves so far.
    fn counts(&self, _lane: &Self::Lane) -> Counts {
        Counts::default()
    }
}

/// Every lane at one 3D frame.
pub struct Frame<'a, L> {
    pub tick: u64,
    pub time: f64,
    /// Per lane: its state and the offset of this tick in its last block (for untraced scenes
    /// the block ends at this tick, so their state is the lane's current one), or `None` once
    /// the lane has diverged.
    pub lanes: Vec<Option<(&'a L, usize)>>,
    /// Wall-clock milliseconds each lane spent stepping since the previous frame.
    pub cost_ms: Vec<f64>,
}

/// Receives a run as it happens: the recorder, a progress bar, a test's collector. Errors stop
/// the run.
pub trait Observer<S: Scene> {
    /// Which sampled rows this observer is handed.
    fn rows(&self) -> WantedRows {
        WantedRows::Plotted
    }
    fn start(&mut self, _scene: &S, _lanes: &[(&'static str, &S::Lane)]) -> anyhow::Result<()> {
        Ok(())
    }
    fn series(&mut self, _scene: &S, _lane: usize, _batch: &SeriesBatch) -> anyhow::Result<()> {
        Ok(())
    }
    fn frame(&mut self, _scene: &S, _frame: &Frame<S::Lane>) -> anyhow::Result<()> {
        Ok(())
    }
    fn event(&mut self, _scene: &S, _event: &Event) -> anyhow::Result<()> {
        Ok(())
    }
    /// Every lane has stepped up to `tick` (after each block, drawn or not: a long run's
    /// progress between the frames it draws); an error stops the run.
    fn reached(&mut self, _scene: &S, _tick: u64) -> anyhow::Result<()> {
        Ok(())
    }
    fn finish(&mut self, _scene: &S, _run: &Run<S::Lane>) -> anyhow::Result<()> {
        Ok(())
    }
}

/// Which sampled rows an observer is handed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WantedRows {
    /// None: nothing is plotted (the scenes skip computing them).
    None,
    /// Every sampled row, however long the run.
    Every,
    /// What a plot needs ([`LaneSeries`]): every sampled row, or beyond [`MAX_PLOT_POINTS`]
    /// the M4 aggregate and the windows.
    Plotted,
}

/// An observer that ignores everything (measurements without a recording).
pub struct NoObserver;
impl<S: Scene> Observer<S> for NoObserver {
    fn rows(&self) -> WantedRows {
        WantedRows::None
    }
}

/// Runs every lane of `scene` over its schedule, reporting to `observer`.
pub fn run<S: Scene>(
    scene: &mut S,
    observer: &mut dyn Observer<S>,
) -> anyhow::Result<Run<S::Lane>> {
    run_until(scene, observer, None)
}

/// [`run`], stopping as if interrupted at the first block boundary past `stop_after` (a
/// replayed interruption: `physlab reproduce` of a run cut short stops where it stopped).
pub fn run_until<S: Scene>(
    scene: &mut S,
    observer: &mut dyn Observer<S>,
    stop_after: Option<u64>,
) -> anyhow::Result<Run<S::Lane>> {
    let mut run = Running::start(scene, observer)?;
    let mut first = 1u64;
    let mut interrupted = false;
    while first <= run.schedule.total {
        // A stop request (Ctrl-C) ends the run at a block boundary; what was done so far stands.
        if crate::interrupt::requested() || stop_after.is_some_and(|tick| first > tick) {
            interrupted = true;
            break;
        }
        let Some(last) = run.block(scene, observer, first)? else {
            interrupted = true;
            break;
        };
        first = last + 1;
    }
    run.end(scene, observer, interrupted, first - 1)
}
