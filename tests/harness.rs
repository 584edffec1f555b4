//! The run loop (`physlab::scene::harness`) checked with scenes made for it: strides, frames,
//! the frame budget, divergence, and lanes side by side on any number of threads.

use physlab::integrate::Counts;
use physlab::scene::harness::*;

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
    fn check(&self, lane: &mut CounterLane, first: u64, len: usize, out: &mut Sampler) -> Checked {
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
    /// Pool threads that have stepped a first block, one bit each. In a pool of more than
    /// one thread a lane's first block waits (at most 5 s) until two threads have come:
    /// the lanes are so cheap that one thread could otherwise take every block before
    /// another wakes, and "both threads stepped lanes" would hold only by luck.
    arrived: std::sync::atomic::AtomicU64,
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
        if first <= 1 && rayon::current_num_threads() > 1 {
            use std::sync::atomic::Ordering;
            let me = rayon::current_thread_index().unwrap_or(63).min(63);
            self.arrived.fetch_or(1 << me, Ordering::SeqCst);
            let started = std::time::Instant::now();
            while self.arrived.load(Ordering::SeqCst).count_ones() < 2
                && started.elapsed() < std::time::Duration::from_secs(5)
            {
                std::thread::yield_now();
            }
        }
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
            own_steps: None,
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
                arrived: Default::default(),
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
            let mut threads: Vec<_> = run.lanes.iter().flat_map(|l| l.threads.clone()).collect();
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

/// Frames come at the step nearest k/fps s (at dt = 0.01 s and 30 fps not every 3rd step, 33.3
/// Hz): fps on average, each within half a step of its time.
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
    // The frame budget the recordings' `about` panels state ("at most 6000 are drawn").
    const MAX_FRAMES: u64 = 6000;
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
