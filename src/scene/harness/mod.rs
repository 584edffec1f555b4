//! The one run loop every scene shares: N lanes (methods, and a reference where a scene has
//! one) side by side on one schedule. The harness steps each lane a block at a time (timing only
//! the stepping), has the scene check every tick of the block, stops a lane that diverged with
//! its event, batches the sampled series, hands 3D frames to the observer, and ends early and
//! cleanly on Ctrl-C. A scene says only what is particular to it through [`Scene`].
//!
//! A "tick" is the scene's unit of time on the schedule: one step of dt for the pendulum and the
//! rope, one simulation frame (of `substeps` steps) for hair.

use std::time::{Duration, Instant};

use crate::integrate::Counts;

mod outcome;
mod schedule;
mod series;
pub use outcome::{LaneStats, Run, divergence_cell};
pub use schedule::{Clock, MAX_PLOT_POINTS, Schedule, Window, Windows};
use series::SERIES_BATCH;
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
    /// Frames counted from 0 at tick 0.
    pub index: u64,
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
    /// progress between the frames it draws).
    fn reached(&mut self, _scene: &S, _tick: u64) {}
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
    let schedule = scene.schedule();
    let (names, mut lanes): (Vec<&'static str>, Vec<S::Lane>) = scene.lanes().into_iter().unzip();
    let mut stats: Vec<LaneStats> = names
        .iter()
        .zip(&lanes)
        .map(|(&name, lane)| LaneStats {
            name,
            is_method: scene.is_method(lane),
            ticks: 0,
            wall: Duration::ZERO,
            timed_ticks: 0,
            counts: scene.counts(lane),
            divergence: None,
        })
        .collect();
    let wanted = observer.rows();
    let plan = match wanted {
        WantedRows::Plotted => schedule.series_plan(&scene.windows()),
        WantedRows::None | WantedRows::Every => None,
    };
    let mut series: Vec<LaneSeries> = lanes
        .iter()
        .map(|l| {
            let absent: Vec<bool> = scene
                .quantities(l)
                .iter()
                .map(|q| absent_when_zero(q))
                .collect();
            LaneSeries::new(
                &schedule,
                &absent,
                plan.as_ref(),
                wanted != WantedRows::None,
            )
        })
        .collect();
    let mut alive = vec![true; lanes.len()];
    let mut accepted = vec![0usize; lanes.len()];
    let mut cost = vec![Duration::ZERO; lanes.len()];
    // The time of each lane's first missed implicit solve, once there was one.
    let mut missed: Vec<Option<f64>> = vec![None; lanes.len()];
    {
        let named: Vec<(&'static str, &S::Lane)> = names.iter().copied().zip(&lanes).collect();
        observer.start(scene, &named)?;
    }

    // Tick 0: the initial state is every lane's first sample and frame 0.
    for (i, lane) in lanes.iter().enumerate() {
        if let Some(values) = scene.initial(lane) {
            Sampler::new(&schedule, &mut series[i]).push(0, &values);
        }
    }
    observer.frame(
        scene,
        &Frame {
            index: 0,
            tick: 0,
            time: 0.0,
            lanes: lanes.iter().map(|l| Some((l, 0))).collect(),
            cost_ms: vec![0.0; lanes.len()],
        },
    )?;
    let mut frames = 1u64;

    let mut first = 1u64;
    let mut interrupted = false;
    while first <= schedule.total {
        // A stop request (Ctrl-C) ends the run at a block boundary; what was done so far stands.
        if crate::interrupt::requested() || stop_after.is_some_and(|tick| first > tick) {
            interrupted = true;
            break;
        }
        let mut last = schedule
            .total
            .min(first.saturating_add(scene.max_block() - 1));
        if !scene.traced() {
            last = last.min(schedule.frame_tick(schedule.next_frame(first)));
        }
        let len = (last - first + 1) as usize;
        scene.prepare(first, len);
        // Shared work can be long (the pendulum's fine-step reference): a stop asked for
        // during it leaves this block unstepped, and what came before stands.
        if crate::interrupt::requested() {
            interrupted = true;
            break;
        }

        // Each live lane is stepped, checked and its series settled on its own; what reaches
        // the observer is then handed on in lane order, so that the run is the same on any
        // number of threads.
        let step_lane =
            |((lane, lane_series), &alive): ((&mut S::Lane, &mut LaneSeries), &bool)| {
                if !alive {
                    return None;
                }
                let started = Instant::now();
                scene.advance(lane, first, len);
                let elapsed = started.elapsed();
                let checked =
                    scene.check(lane, first, len, &mut Sampler::new(&schedule, lane_series));
                lane_series.settle(&schedule);
                if checked.divergence.is_some() {
                    lane_series.finish(&schedule);
                }
                Some((elapsed, checked))
            };
        let stepped: Vec<Option<(Duration, Checked)>> = if scene.side_by_side() {
            use rayon::prelude::*;
            (lanes.par_iter_mut().zip(series.par_iter_mut()))
                .zip(alive.par_iter())
                .map(step_lane)
                .collect()
        } else {
            (lanes.iter_mut().zip(series.iter_mut()))
                .zip(&alive)
                .map(step_lane)
                .collect()
        };

        for (i, (lane, stepped)) in lanes.iter().zip(stepped).enumerate() {
            accepted[i] = 0;
            let Some((elapsed, checked)) = stepped else {
                continue;
            };
            let s = &mut stats[i];
            s.wall += elapsed;
            s.timed_ticks += len as u64;
            cost[i] += elapsed;
            accepted[i] = checked.accepted;
            s.ticks += checked.accepted as u64;
            s.counts = checked.counts.unwrap_or_else(|| scene.counts(lane));
            if let Some((offset, what)) = checked.solver_miss
                && missed[i].is_none()
            {
                // Reported once per lane, and the total at the end (as the summary counts it),
                // so the log stays readable.
                let tick = first + offset as u64;
                let time = schedule.time(tick);
                missed[i] = Some(time);
                observer.event(
                    scene,
                    &Event {
                        lane: i,
                        time,
                        tick,
                        kind: EventKind::SolverNotConverged,
                        message: format!(
                            "{}: an implicit step at t = {time:.6} s missed its Newton tolerance \
                             ({what}); the summary counts all such steps",
                            s.name
                        ),
                    },
                )?;
            }
            if let Some(why) = checked.divergence {
                let tick = first + checked.accepted as u64;
                let time = schedule.time(tick);
                let event = Event {
                    lane: i,
                    time,
                    tick,
                    kind: EventKind::Divergence,
                    message: format!(
                        "{} diverged at t = {time:.6} s (tick {tick}): {why}",
                        s.name
                    ),
                };
                observer.event(scene, &event)?;
                s.divergence = Some(event);
                alive[i] = false;
            }
            let batch = &mut series[i].batch;
            if !batch.is_empty() && (batch.len() >= SERIES_BATCH || !alive[i]) {
                observer.series(scene, i, batch)?;
                batch.clear();
            }
        }

        // 3D frames that fall in this block.
        let mut k = schedule.next_frame(first);
        let mut tick = schedule.frame_tick(k);
        while tick <= last {
            let offset = (tick - first) as usize;
            let view = Frame {
                index: k,
                tick,
                time: schedule.time(tick),
                lanes: lanes
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (offset < accepted[i]).then_some((l, offset)))
                    .collect(),
                cost_ms: cost.iter().map(|c| c.as_secs_f64() * 1e3).collect(),
            };
            observer.frame(scene, &view)?;
            cost.fill(Duration::ZERO);
            frames += 1;
            k = schedule.drawn_from(k + 1);
            tick = schedule.frame_tick(k);
        }
        observer.reached(scene, last);
        first = last + 1;
    }
    for (i, lane_series) in series.iter_mut().enumerate() {
        lane_series.finish(&schedule);
        let batch = &mut lane_series.batch;
        if !batch.is_empty() {
            observer.series(scene, i, batch)?;
            batch.clear();
        }
    }
    // The log's last word on missed solves is the summary's count.
    for (i, s) in stats.iter().enumerate() {
        let failed = s.counts.failed_solves;
        if let Some(first_time) = missed[i]
            && failed > 1
        {
            let tick = s.ticks_taken();
            let time = schedule.time(tick);
            observer.event(
                scene,
                &Event {
                    lane: i,
                    time,
                    tick,
                    kind: EventKind::SolverNotConverged,
                    message: format!(
                        "{}: {failed} implicit steps in all missed their Newton tolerance, the first at \
                         t = {first_time:.6} s",
                        s.name
                    ),
                },
            )?;
        }
    }
    let run = Run {
        lanes,
        stats,
        frames,
        interrupted,
        last_tick: first - 1,
    };
    observer.finish(scene, &run)?;
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene whose one lane counts ticks and "diverges" at a given tick; series = the tick.
    struct Counter {
        schedule: Schedule,
        diverge_at: u64,
        traced: bool,
    }

    struct CounterLane {
        at: u64,
        bad: Option<u64>,
    }

    impl Scene for Counter {
        type Lane = CounterLane;
        fn name(&self) -> &'static str {
            "counter"
        }
        fn schedule(&self) -> Schedule {
            self.schedule
        }
        fn lanes(&self) -> Vec<(&'static str, CounterLane)> {
            vec![("a", CounterLane { at: 0, bad: None })]
        }
        fn quantities(&self, _: &CounterLane) -> &'static [&'static str] {
            &["tick"]
        }
        fn initial(&self, _: &CounterLane) -> Option<Vec<f64>> {
            Some(vec![0.0])
        }
        fn max_block(&self) -> u64 {
            7
        }
        fn traced(&self) -> bool {
            self.traced
        }
        fn advance(&self, lane: &mut CounterLane, first: u64, len: usize) {
            for k in 0..len as u64 {
                lane.at = first + k;
                if lane.at == self.diverge_at {
                    lane.bad = Some(k);
                    return;
                }
            }
        }
        fn check(
            &self,
            lane: &mut CounterLane,
            first: u64,
            len: usize,
            out: &mut Sampler,
        ) -> Checked {
            let ok = lane.bad.map_or(len, |k| k as usize);
            for k in 0..ok as u64 {
                if out.wants(first + k) {
                    out.push(first + k, &[(first + k) as f64]);
                }
            }
            Checked {
                accepted: ok,
                divergence: lane.bad.map(|_| "bad".to_string()),
                solver_miss: None,
                counts: None,
            }
        }
    }

    #[derive(Default)]
    struct Collect {
        rows: Vec<u64>,
        frames: Vec<(u64, bool)>,
        events: Vec<u64>,
    }

    impl Observer<Counter> for Collect {
        fn series(&mut self, _: &Counter, _: usize, b: &SeriesBatch) -> anyhow::Result<()> {
            self.rows.extend(&b.ticks);
            Ok(())
        }
        fn frame(&mut self, _: &Counter, f: &Frame<CounterLane>) -> anyhow::Result<()> {
            self.frames.push((f.tick, f.lanes[0].is_some()));
            Ok(())
        }
        fn event(&mut self, _: &Counter, e: &Event) -> anyhow::Result<()> {
            self.events.push(e.tick);
            Ok(())
        }
    }

    /// Lanes of unequal work side by side: lane i steps x ← x + sin((i + 1) x) / 8 twenty
    /// times (i + 1) per tick, misses a "solve" at one tick when i is even and diverges at
    /// one tick when i is odd; it notes the pool thread that stepped each of its blocks.
    struct SideBySide {
        schedule: Schedule,
    }

    struct SideLane {
        index: usize,
        x: Vec<f64>,
        misses: Vec<usize>,
        bad: Option<usize>,
        evals: u64,
        failed: u64,
        threads: Vec<Option<usize>>,
    }

    impl SideBySide {
        const LANES: usize = 5;

        fn miss_at(i: usize) -> Option<u64> {
            i.is_multiple_of(2).then_some(1000 + 77 * i as u64)
        }

        fn diverge_at(i: usize) -> Option<u64> {
            (i % 2 == 1).then_some(20_000 + 3001 * i as u64)
        }
    }

    impl Scene for SideBySide {
        type Lane = SideLane;
        fn name(&self) -> &'static str {
            "side by side"
        }
        fn schedule(&self) -> Schedule {
            self.schedule
        }
        fn lanes(&self) -> Vec<(&'static str, SideLane)> {
            const NAMES: [&str; SideBySide::LANES] = ["a", "b", "c", "d", "e"];
            (0..Self::LANES)
                .map(|index| {
                    let lane = SideLane {
                        index,
                        x: vec![0.5],
                        misses: Vec::new(),
                        bad: None,
                        evals: 0,
                        failed: 0,
                        threads: Vec::new(),
                    };
                    (NAMES[index], lane)
                })
                .collect()
        }
        fn quantities(&self, _: &SideLane) -> &'static [&'static str] {
            &["x", "theta_error"]
        }
        fn initial(&self, _: &SideLane) -> Option<Vec<f64>> {
            Some(vec![0.5, 0.0])
        }
        fn max_block(&self) -> u64 {
            64
        }
        fn traced(&self) -> bool {
            true
        }
        fn side_by_side(&self) -> bool {
            true
        }
        fn advance(&self, lane: &mut SideLane, first: u64, len: usize) {
            lane.threads.push(rayon::current_thread_index());
            let mut x = *lane.x.last().unwrap();
            lane.x.clear();
            lane.misses.clear();
            let k = (lane.index + 1) as f64;
            for j in 0..len {
                let tick = first + j as u64;
                for _ in 0..20 * (lane.index + 1) {
                    x += (k * x).sin() / 8.0;
                    lane.evals += 1;
                }
                lane.x.push(x);
                if Some(tick) == Self::miss_at(lane.index) {
                    lane.misses.push(j);
                    lane.failed += 1;
                }
                if Some(tick) == Self::diverge_at(lane.index) {
                    lane.bad = Some(j);
                    return;
                }
            }
        }
        fn check(&self, lane: &mut SideLane, first: u64, len: usize, out: &mut Sampler) -> Checked {
            let ok = lane.bad.unwrap_or(len);
            for j in 0..ok {
                if out.wants(first + j as u64) {
                    out.push(first + j as u64, &[lane.x[j], (lane.x[j] - 0.5).abs()]);
                }
            }
            Checked {
                accepted: ok,
                divergence: lane.bad.map(|j| format!("x = {}", lane.x[j])),
                solver_miss: lane.misses.first().map(|&j| (j, "a miss".to_string())),
                counts: None,
            }
        }
        fn counts(&self, lane: &SideLane) -> Counts {
            Counts {
                evals: lane.evals,
                failed_solves: lane.failed,
                adaptive_steps: None,
            }
        }
    }

    /// Everything a run hands an observer, in the order it came.
    #[derive(Default, Debug, PartialEq)]
    struct Transcript {
        /// (lane, tick, time, which quantities need the row, values as bits).
        rows: Vec<(usize, u64, u64, u64, Vec<u64>)>,
        events: Vec<(usize, u64, String)>,
        frames: Vec<(u64, Vec<bool>)>,
    }

    impl Observer<SideBySide> for Transcript {
        fn series(&mut self, _: &SideBySide, lane: usize, b: &SeriesBatch) -> anyhow::Result<()> {
            for r in 0..b.len() {
                let values = b.columns.iter().map(|c| c[r].to_bits()).collect();
                let row = (lane, b.ticks[r], b.times[r].to_bits(), b.needed[r], values);
                self.rows.push(row);
            }
            Ok(())
        }
        fn event(&mut self, _: &SideBySide, e: &Event) -> anyhow::Result<()> {
            self.events.push((e.lane, e.tick, e.message.clone()));
            Ok(())
        }
        fn frame(&mut self, _: &SideBySide, f: &Frame<SideLane>) -> anyhow::Result<()> {
            let alive = f.lanes.iter().map(Option::is_some).collect();
            self.frames.push((f.tick, alive));
            Ok(())
        }
    }

    /// Lanes stepped side by side hand the observer the same rows, events and frames in the
    /// same order, and leave the same counts, on one thread and on two, with the series
    /// aggregated (a run beyond the plotted points) and not; on two threads the lanes were
    /// indeed stepped by both.
    #[test]
    fn lanes_side_by_side_give_the_same_run_on_any_number_of_threads() {
        for total in [2_000, 30_000] {
            let runs = [1, 2].map(|threads| {
                let mut scene = SideBySide {
                    schedule: Schedule::fixed_step(0.01, total as f64 * 0.01, 30.0, 1),
                };
                let mut seen = Transcript::default();
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let run = pool.install(|| run(&mut scene, &mut seen)).unwrap();
                let stats: Vec<_> = (run.stats.iter())
                    .map(|s| (s.ticks, s.counts, s.divergence.as_ref().map(|e| e.tick)))
                    .collect();
                let mut threads: Vec<_> =
                    run.lanes.iter().flat_map(|l| l.threads.clone()).collect();
                threads.sort();
                threads.dedup();
                (seen, stats, threads)
            });
            let [(one, one_stats, one_threads), (two, two_stats, two_threads)] = runs;
            assert_eq!(one_threads, [Some(0)]);
            assert_eq!(
                two_threads,
                [Some(0), Some(1)],
                "both threads stepped lanes"
            );
            assert_eq!(one_stats, two_stats, "{total} ticks");
            assert_eq!(one, two, "{total} ticks");
            // What the run should have seen: each odd lane stops at its tick, each even lane
            // reports its miss.
            for (i, &(ticks, _, diverged)) in one_stats.iter().enumerate() {
                let stop = SideBySide::diverge_at(i).filter(|&t| t <= total);
                assert_eq!(diverged, stop, "lane {i}");
                assert_eq!(ticks, stop.map_or(total, |t| t - 1), "lane {i}");
            }
            let missed: Vec<_> = one
                .events
                .iter()
                .filter(|e| e.2.contains("a miss"))
                .collect();
            assert_eq!(missed.len(), 3, "{:?}", one.events);
            assert!(one.rows.len() > 5 * 1000, "{} rows", one.rows.len());
        }
    }

    fn schedule(total: u64, frame_stride: u64, plot_stride: u64) -> Schedule {
        Schedule {
            total,
            fps: 1.0 / (0.5 * frame_stride as f64),
            plot_stride,
            clock: Clock::Step(0.5),
        }
    }

    #[test]
    fn samples_strides_and_the_last_tick_frames_every_stride_and_stops_at_divergence() {
        for traced in [false, true] {
            let mut scene = Counter {
                schedule: schedule(20, 3, 4),
                diverge_at: 100,
                traced,
            };
            let mut seen = Collect::default();
            let result = run(&mut scene, &mut seen).unwrap();
            assert_eq!(seen.rows, [0, 4, 8, 12, 16, 20]);
            let frames: Vec<u64> = seen.frames.iter().map(|f| f.0).collect();
            assert_eq!(frames, [0, 3, 6, 9, 12, 15, 18]);
            assert_eq!(result.stats[0].ticks, 20);

            let mut scene = Counter {
                schedule: schedule(20, 3, 1),
                diverge_at: 10,
                traced,
            };
            let mut seen = Collect::default();
            let result = run(&mut scene, &mut seen).unwrap();
            assert_eq!(seen.rows, (0..10).collect::<Vec<_>>());
            assert_eq!(seen.events, [10]);
            assert_eq!(result.stats[0].ticks, 9, "ticks 1..=9 passed");
            // Frames after the divergence show the lane as gone.
            assert!(seen.frames.iter().all(|&(t, alive)| alive == (t < 10)));
        }
    }

    /// `--fps 30` at dt = 0.01 s used to log every round(3.33) = 3 steps, 33.3 Hz. Frames now
    /// come at the step nearest k/30 s: 30 Hz on average, each within half a step of its time.
    #[test]
    fn frames_come_at_the_rate_asked_each_within_half_a_tick_of_its_time() {
        for (dt, fps) in [
            (0.01, 30.0),
            (1e-3, 30.0),
            (0.01, 7.0),
            (1.0 / 64.0, 1.0),
            (0.1, 30.0),
        ] {
            let s = Schedule::fixed_step(dt, 20.0, fps, 1);
            let tpf = (1.0 / (fps * dt)).max(1.0);
            assert_eq!(s.frame_rate(), 1.0 / (tpf * dt));
            let mut previous = None;
            for k in 0..s.frames() {
                let tick = s.frame_tick(k);
                assert!(
                    (tick as f64 - k as f64 * tpf).abs() <= 0.5,
                    "dt {dt} fps {fps} k {k}"
                );
                assert!(previous.is_none_or(|p| tick > p));
                previous = Some(tick);
                assert_eq!(s.frame_at(tick), k);
                assert_eq!(s.next_frame(tick), k);
                if tick > 0 && s.frame_tick(k - 1) < tick - 1 {
                    assert_eq!(s.frame_at(tick - 1), k - 1);
                    assert_eq!(s.next_frame(tick - 1), k);
                }
            }
            assert!(s.frame_tick(s.frames()) > s.total);
        }
        // 2000 steps of 0.01 s at 30 Hz: 601 frames (t = 0 to 20 s), not 667.
        assert_eq!(Schedule::fixed_step(0.01, 20.0, 30.0, 1).frames(), 601);
        // A step longer than a frame: every step is one, and the rate says so.
        assert_eq!(Schedule::fixed_step(0.1, 20.0, 30.0, 1).frame_rate(), 10.0);
    }

    /// A run longer than the frame budget draws the budget's frames at its two ends, each at the
    /// tick a run without a budget would draw it at, and no other: checked against the frames
    /// of the same run counted directly (k/fps rounded to the nearest tick), and through the run
    /// loop.
    #[test]
    fn a_long_run_draws_its_frame_budget_at_its_two_ends_only() {
        use super::schedule::MAX_FRAMES;

        for (dt, duration, fps) in [(0.01, 1e4, 30.0), (1e-3, 500.0, 30.0), (0.01, 2e3, 7.0)] {
            let s = Schedule::fixed_step(dt, duration, fps, 1);
            let tpf = 1.0 / (fps * dt);
            let uniform: Vec<u64> = (0..)
                .map(|k| (k as f64 * tpf).round() as u64)
                .take_while(|&t| t <= s.total)
                .collect();
            let half = (MAX_FRAMES / 2) as usize;
            let expected: Vec<u64> = uniform[..half]
                .iter()
                .chain(&uniform[uniform.len() - half..])
                .copied()
                .collect();
            assert_eq!(s.frames(), MAX_FRAMES, "dt {dt} duration {duration}");
            let mut drawn = Vec::new();
            let mut k = s.next_frame(0);
            while s.frame_tick(k) <= s.total {
                drawn.push(s.frame_tick(k));
                k = s.drawn_from(k + 1);
            }
            assert_eq!(drawn, expected, "dt {dt} duration {duration}");
            // A tick between the two ends belongs to the last frame drawn before it.
            let between = (expected[half - 1] + expected[half]) / 2;
            assert_eq!(s.frame_tick(s.frame_at(between)), expected[half - 1]);
            assert_eq!(s.frame_tick(s.next_frame(between)), expected[half]);
            assert!(s.gap_text().unwrap().contains("6000 of the"));

            let mut scene = Counter {
                schedule: Schedule {
                    plot_stride: s.total,
                    ..s
                },
                diverge_at: u64::MAX,
                traced: false,
            };
            let mut seen = Collect::default();
            run(&mut scene, &mut seen).unwrap();
            let ticks: Vec<u64> = seen.frames.iter().map(|f| f.0).collect();
            assert_eq!(ticks, expected, "through the run loop");
        }
        // Within the budget every frame is drawn and nothing is said.
        assert_eq!(Schedule::fixed_step(0.01, 199.0, 30.0, 1).gap(), None);
        assert_eq!(
            Schedule::fixed_step(0.01, 200.0, 30.0, 1).frames(),
            MAX_FRAMES
        );
    }
}
