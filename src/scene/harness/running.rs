//! The run loop's steps: a run's working state ([`Running`]), its start (tick 0), one block of
//! ticks (stepped, checked, its events, series and 3D frames handed on) and its end.

use std::time::{Duration, Instant};

use super::series::SERIES_BATCH;
use super::{
    Checked, Event, EventKind, Frame, LaneSeries, LaneStats, Observer, Run, Sampler, Scene,
    Schedule, WantedRows, absent_when_zero,
};

/// A run under way: every lane's state, bookkeeping and series.
pub(super) struct Running<L> {
    pub(super) schedule: Schedule,
    lanes: Vec<L>,
    stats: Vec<LaneStats>,
    series: Vec<LaneSeries>,
    alive: Vec<bool>,
    /// Ticks each lane accepted in the last block.
    accepted: Vec<usize>,
    /// Wall time each lane spent stepping since the last 3D frame.
    cost: Vec<Duration>,
    /// The time of each lane's first missed implicit solve, once there was one.
    missed: Vec<Option<f64>>,
}

impl<L: Send> Running<L> {
    /// The lanes set up and tick 0 handed on: the initial state is every lane's first sample
    /// and frame 0.
    pub(super) fn start<S: Scene<Lane = L>>(
        scene: &S,
        observer: &mut dyn Observer<S>,
    ) -> anyhow::Result<Self> {
        let schedule = scene.schedule();
        let (names, lanes): (Vec<&'static str>, Vec<L>) = scene.lanes().into_iter().unzip();
        let stats = names
            .iter()
            .zip(&lanes)
            .map(|(&name, lane)| LaneStats {
                name,
                is_method: scene.is_method(lane),
                counts: scene.counts(lane),
                ..LaneStats::default()
            })
            .collect();
        let wanted = observer.rows();
        let keep = wanted != WantedRows::None;
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
                LaneSeries::new(&schedule, &absent, plan.as_ref(), keep)
            })
            .collect();
        let named: Vec<(&'static str, &L)> = names.iter().copied().zip(&lanes).collect();
        observer.start(scene, &named)?;
        for (i, lane) in lanes.iter().enumerate() {
            if let Some(values) = scene.initial(lane) {
                Sampler::new(&schedule, &mut series[i]).push(0, &values);
            }
        }
        let start = Frame {
            tick: 0,
            time: 0.0,
            lanes: lanes.iter().map(|l| Some((l, 0))).collect(),
            cost_ms: vec![0.0; lanes.len()],
        };
        observer.frame(scene, &start)?;
        let n = lanes.len();
        Ok(Running {
            schedule,
            lanes,
            stats,
            series,
            alive: vec![true; n],
            accepted: vec![0; n],
            cost: vec![Duration::ZERO; n],
            missed: vec![None; n],
        })
    }

    /// Steps, checks and hands on the block from tick `first`; returns its last tick, or none
    /// when a stop asked for during the scene's shared work left it unstepped.
    pub(super) fn block<S: Scene<Lane = L>>(
        &mut self,
        scene: &mut S,
        observer: &mut dyn Observer<S>,
        first: u64,
    ) -> anyhow::Result<Option<u64>> {
        let schedule = self.schedule;
        // A block is at most as long as the ticks before it: the first ones are short, so that
        // a run's pace is measured within its first moments whatever a tick costs.
        let mut last = (schedule.total).min(first.saturating_add(scene.max_block().min(first) - 1));
        if !scene.traced() {
            last = last.min(schedule.frame_tick(schedule.next_frame(first)));
        }
        let len = (last - first + 1) as usize;
        scene.prepare(first, len);
        // Shared work can be long (the pendulum's fine-step reference): a stop asked for
        // during it leaves this block unstepped, and what came before stands.
        if crate::interrupt::requested() {
            return Ok(None);
        }
        let stepped = self.step(scene, first, len);
        for (i, stepped) in stepped.into_iter().enumerate() {
            self.accepted[i] = 0;
            if let Some(stepped) = stepped {
                self.checked(scene, observer, i, (first, len), stepped)?;
            }
        }
        self.frames_in(scene, observer, first, last)?;
        observer.reached(scene, last)?;
        Ok(Some(last))
    }

    /// Each live lane stepped, checked and its series settled on its own (side by side on the
    /// rayon pool when the scene says so); what reaches the observer is then handed on in lane
    /// order, so that the run is the same on any number of threads.
    fn step<S: Scene<Lane = L>>(
        &mut self,
        scene: &S,
        first: u64,
        len: usize,
    ) -> Vec<Option<(Duration, Checked)>> {
        let schedule = &self.schedule;
        let step_lane = |((lane, lane_series), &alive): ((&mut L, &mut LaneSeries), &bool)| {
            if !alive {
                return None;
            }
            let started = Instant::now();
            scene.advance(lane, first, len);
            let elapsed = started.elapsed();
            let checked = scene.check(lane, first, len, &mut Sampler::new(schedule, lane_series));
            lane_series.settle(schedule);
            if checked.divergence.is_some() {
                lane_series.finish(schedule);
            }
            Some((elapsed, checked))
        };
        if scene.side_by_side() {
            use rayon::prelude::*;
            (self.lanes.par_iter_mut().zip(self.series.par_iter_mut()))
                .zip(self.alive.par_iter())
                .map(step_lane)
                .collect()
        } else {
            (self.lanes.iter_mut().zip(self.series.iter_mut()))
                .zip(&self.alive)
                .map(step_lane)
                .collect()
        }
    }

    /// Lane `i`'s block checked: its bookkeeping, its first missed solve and its divergence
    /// (events), and its series batch handed on when full or when the lane stopped.
    fn checked<S: Scene<Lane = L>>(
        &mut self,
        scene: &S,
        observer: &mut dyn Observer<S>,
        i: usize,
        (first, len): (u64, usize),
        (elapsed, checked): (Duration, Checked),
    ) -> anyhow::Result<()> {
        let schedule = self.schedule;
        let s = &mut self.stats[i];
        s.wall += elapsed;
        s.timed_ticks += len as u64;
        self.cost[i] += elapsed;
        self.accepted[i] = checked.accepted;
        s.ticks += checked.accepted as u64;
        s.counts = (checked.counts).unwrap_or_else(|| scene.counts(&self.lanes[i]));
        if let Some((offset, what)) = checked.solver_miss
            && self.missed[i].is_none()
        {
            // Reported once per lane, and the total at the end (as the summary counts it),
            // so the log stays readable.
            let tick = first + offset as u64;
            let time = schedule.time(tick);
            self.missed[i] = Some(time);
            let message = format!(
                "{}: an implicit step at t = {time:.6} s missed its Newton tolerance ({what}); \
                 the summary counts all such steps",
                s.name
            );
            observer.event(
                scene,
                &event(i, &schedule, tick, EventKind::SolverNotConverged, message),
            )?;
        }
        if let Some(why) = checked.divergence {
            let tick = first + checked.accepted as u64;
            let time = schedule.time(tick);
            let message = format!(
                "{} diverged at t = {time:.6} s (tick {tick}): {why}",
                s.name
            );
            let event = event(i, &schedule, tick, EventKind::Divergence, message);
            observer.event(scene, &event)?;
            s.divergence = Some(event);
            self.alive[i] = false;
        }
        let batch = &mut self.series[i].batch;
        if !batch.is_empty() && (batch.len() >= SERIES_BATCH || !self.alive[i]) {
            observer.series(scene, i, batch)?;
            batch.clear();
        }
        Ok(())
    }

    /// The 3D frames that fall in the block first..=last.
    fn frames_in<S: Scene<Lane = L>>(
        &mut self,
        scene: &S,
        observer: &mut dyn Observer<S>,
        first: u64,
        last: u64,
    ) -> anyhow::Result<()> {
        let schedule = self.schedule;
        let mut k = schedule.next_frame(first);
        let mut tick = schedule.frame_tick(k);
        while tick <= last {
            let offset = (tick - first) as usize;
            let view = Frame {
                tick,
                time: schedule.time(tick),
                lanes: (self.lanes.iter().enumerate())
                    .map(|(i, l)| (offset < self.accepted[i]).then_some((l, offset)))
                    .collect(),
                cost_ms: self.cost.iter().map(|c| c.as_secs_f64() * 1e3).collect(),
            };
            observer.frame(scene, &view)?;
            self.cost.fill(Duration::ZERO);
            k = schedule.drawn_from(k + 1);
            tick = schedule.frame_tick(k);
        }
        Ok(())
    }

    /// The run's end at `last_tick`: every series' remaining rows, the log's last word on
    /// missed solves (the summary's count), and the run handed to the observer.
    pub(super) fn end<S: Scene<Lane = L>>(
        mut self,
        scene: &S,
        observer: &mut dyn Observer<S>,
        interrupted: bool,
        last_tick: u64,
    ) -> anyhow::Result<Run<L>> {
        let schedule = self.schedule;
        for (i, lane_series) in self.series.iter_mut().enumerate() {
            lane_series.finish(&schedule);
            let batch = &mut lane_series.batch;
            if !batch.is_empty() {
                observer.series(scene, i, batch)?;
                batch.clear();
            }
        }
        for (i, s) in self.stats.iter().enumerate() {
            let failed = s.counts.failed_solves;
            if let Some(first_time) = self.missed[i]
                && failed > 1
            {
                let message = format!(
                    "{}: {failed} implicit steps in all missed their Newton tolerance, the first \
                     at t = {first_time:.6} s",
                    s.name
                );
                let kind = EventKind::SolverNotConverged;
                observer.event(scene, &event(i, &schedule, s.ticks_taken(), kind, message))?;
            }
        }
        let run = Run {
            lanes: self.lanes,
            stats: self.stats,
            interrupted,
            last_tick,
        };
        observer.finish(scene, &run)?;
        Ok(run)
    }
}

fn event(lane: usize, schedule: &Schedule, tick: u64, kind: EventKind, message: String) -> Event {
    Event {
        lane,
        time: schedule.time(tick),
        tick,
        kind,
        message,
    }
}
