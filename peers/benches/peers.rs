//! physlab against compiled peers at equal accuracy: `cargo bench -p physlab-peers`.
//!
//! The problem: the pendulum θ'' = -(g/L) sin θ, g = 9.81, L = 3.521, released from rest at
//! θ0 = 60°, sampled every 0.1 s. The error of a run is max |θ - θ_exact| over the sample times,
//! θ_exact from physlab's closed form (elliptic functions) at the time the solver reports for
//! the sample. Every side runs over a sweep (fixed-step methods: the step halved; adaptive ones:
//! rtol = atol from 1e-2 to 1e-14 in half decades), from its cheapest setting on, until a run
//! reaches the smallest target or takes longer than the horizon's budget; each run is timed as
//! the minimum of several. The tables show, per target error, each side's cheapest run reaching
//! it and the ratio peer time / physlab time (> 1: physlab is faster).
//!
//! Two horizons: 20 s (200 samples), and 10⁴ periods (40 397 s, 403 972 samples), where a
//! non-symplectic method's phase error grows like t² and a symplectic one's like t, and where
//! summing 10⁵–10⁸ steps in plain floating point costs digits. There the closed form itself is
//! good to 6e-12 rad at the end (checked against 40-digit mpmath values at 10⁴ s and 4·10⁴ s).
//!
//! Peers: `ode_solvers` 0.6.2 (Rk4, Dopri5, Dop853; output every 0.1 s through their dense
//! output, every step for Rk4, of which the samples are taken) and `differential-equations`
//! 0.6.1 (ExplicitRungeKutta::dop853 and ::rkv988e, Verner's 9(8) "efficient" pair, the same
//! tableau as physlab's vern9, with
//! `.even(0.1)` output). State types: nalgebra Vector2 for ode_solvers, [f64; 2] for
//! differential-equations, physlab's own flat slices. The adaptive peers run without their
//! step caps (100 000 and 10 000 steps), which 10⁴ periods exceed.
//!
//! Then `peers/benches/scipy_peer.py` times scipy's solve_ivp(method="DOP853") on the same problem at
//! equal error, in the same session, when python3 and scipy are installed.
//!
//! After the 20 s table, the study's answer at 1e-3 (`physlab study work-precision` on this
//! problem, its sweep from physlab's library) is timed against the benchmark's best physlab run
//! at 1e-3, interleaved; `cargo bench -p physlab-peers -- study-answer` stops there.
//!
//! After the tables, criterion times RK4 at h = 1e-3 s over the 20 s (20 000 steps) for physlab
//! and ode_solvers (RK4's cost per step).

use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::pendulum::exact::ExactPendulum;
use physlab::scene::pendulum::{Pendulum, PendulumParams};
use physlab::study::{Problem, Row, Sweep, cheapest};

const SAMPLE_DT: f64 = 0.1;
const TARGETS: [f64; 5] = [1e-3, 1e-6, 1e-8, 1e-10, 1e-12];

/// A comparison's horizon: how long, how many repeats per run, and when a side's sweep stops.
struct Horizon {
    title: String,
    /// Sample times 0.1, 0.2, ..., samples × 0.1 s; the run ends at the last.
    samples: usize,
    /// Each run is timed as the minimum of up to this many runs (fewer when one run is long:
    /// the repeats of a run take at most about `REPEAT_BUDGET`).
    repeats: usize,
    /// A side's sweep (from its cheapest setting on) stops after a run slower than this [s]:
    /// its finer settings cost more still.
    budget: f64,
    /// The targets shown; a side's sweep also stops once a run reaches the smallest.
    targets: &'static [f64],
}

const REPEAT_BUDGET: f64 = 0.3;

fn params() -> PendulumParams {
    PendulumParams {
        theta0: 60f64.to_radians(),
        ..PendulumParams::default()
    }
}

/// The sample times a run reports and θ there. physlab reports at k × 0.1 s; the peers report
/// their own times (both accumulate t += 0.1, which drifts from k × 0.1 by up to ~1e-7 s over
/// 10⁴ periods), and each sample is compared with the exact θ at the time the solver reports.
struct Samples {
    times: Option<Vec<f64>>,
    theta: Vec<f64>,
}

impl Samples {
    /// A run that stopped with an error (counted as an infinite error).
    fn failed(samples: usize) -> Self {
        Samples {
            times: None,
            theta: vec![f64::NAN; samples],
        }
    }
}

/// One run: who, with what setting, its error and its time (min over the repeats) [s].
struct RunResult {
    side: &'static str,
    setting: String,
    error: f64,
    seconds: f64,
    /// physlab's runs: what made it, to be run again.
    physlab: Option<PhyslabRun>,
}

/// The exact θ at the sample grid, and at any other time a solver reports.
struct Reference {
    exact: ExactPendulum,
    grid: Vec<f64>,
}

impl Reference {
    fn new(samples: usize) -> Self {
        let exact = ExactPendulum::new(&params()).expect("a release from rest below 180°");
        let grid = (1..=samples)
            .map(|i| exact.state(i as f64 * SAMPLE_DT).0)
            .collect();
        Reference { exact, grid }
    }

    /// max |θ − θ_exact| over the samples (∞ if any is not finite, or if the run did not give
    /// every sample).
    fn error(&self, s: &Samples) -> f64 {
        let n = self.grid.len();
        let complete = s.theta.len() == n && s.times.as_ref().is_none_or(|t| t.len() == n);
        if !complete {
            return f64::INFINITY;
        }
        (0..n)
            .map(|i| {
                let exact = match &s.times {
                    Some(t) if t[i] != (i + 1) as f64 * SAMPLE_DT => self.exact.state(t[i]).0,
                    _ => self.grid[i],
                };
                (s.theta[i] - exact).abs()
            })
            .fold(0.0f64, |m, e| {
                if e.is_finite() {
                    m.max(e)
                } else {
                    f64::INFINITY
                }
            })
    }
}

/// Times `f` (which returns the samples) and measures its error.
fn measure(
    h: &Horizon,
    reference: &Reference,
    side: &'static str,
    setting: String,
    mut f: impl FnMut() -> Samples,
) -> RunResult {
    let t = Instant::now();
    let samples = black_box(f());
    let mut best = t.elapsed().as_secs_f64();
    let repeats = ((REPEAT_BUDGET / best) as usize).clamp(1, h.repeats);
    for _ in 1..repeats {
        let t = Instant::now();
        black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    RunResult {
        side,
        setting,
        error: reference.error(&samples),
        seconds: best,
        physlab: None,
    }
}

/// Runs one side's settings from the cheapest on, until a run reaches the smallest target or
/// takes longer than the horizon's budget.
fn sweep<S>(
    h: &Horizon,
    reference: &Reference,
    results: &mut Vec<RunResult>,
    side: &'static str,
    settings: impl IntoIterator<Item = (String, S)>,
    mut run: impl FnMut(&S) -> Samples,
) {
    let smallest = h.targets.iter().copied().fold(f64::INFINITY, f64::min);
    for (label, setting) in settings {
        let r = measure(h, reference, side, label, || run(&setting));
        // A failed run (a peer's error) stops the side too: finer settings fail sooner.
        let stop = r.error <= smallest || r.seconds > h.budget || r.error.is_infinite();
        results.push(r);
        if stop {
            break;
        }
    }
}

/// One physlab run: the method, its step (the sample interval / `per_sample`), its options
/// (a step across the samples, a tolerance, compensated sums).
#[derive(Clone, Copy, Debug)]
struct PhyslabRun {
    method: Method,
    dt: f64,
    per_sample: usize,
    options: MethodOptions,
}

impl PhyslabRun {
    /// The run `physlab study work-precision` measured as `row` and prints as its command: a
    /// fixed-step method at `--step` (across or ending at the samples), an adaptive one at
    /// `--rtol`, both asked for every sample.
    fn of(row: &Row) -> Self {
        let step = (row.rtol.is_none() && row.dt != SAMPLE_DT).then_some(row.dt);
        let options = MethodOptions {
            rtol: row.rtol.unwrap_or(MethodOptions::default().rtol),
            compensated: row.compensated,
            step,
            ..MethodOptions::default()
        };
        PhyslabRun {
            method: row.method,
            dt: SAMPLE_DT,
            per_sample: 1,
            options,
        }
    }

    fn samples(&self, samples: usize) -> Samples {
        let p = params();
        let sys = Pendulum::new(&p);
        let mut it = Integrator::new(
            self.method,
            &sys,
            &[p.theta0],
            &[0.0],
            self.dt,
            self.options,
        );
        let mut theta = Vec::with_capacity(samples);
        for _ in 0..samples {
            for _ in 0..self.per_sample {
                it.step(&sys);
            }
            theta.push(it.position()[0]);
        }
        Samples { times: None, theta }
    }
}

fn physlab_run(
    method: Method,
    dt: f64,
    per_sample: usize,
    options: MethodOptions,
    samples: usize,
) -> Samples {
    let run = PhyslabRun {
        method,
        dt,
        per_sample,
        options,
    };
    run.samples(samples)
}

/// [`sweep`] over physlab runs, each result keeping the run that made it.
fn physlab_sweep(
    h: &Horizon,
    reference: &Reference,
    results: &mut Vec<RunResult>,
    side: &'static str,
    settings: Vec<(String, PhyslabRun)>,
) {
    let first = results.len();
    let runs: Vec<PhyslabRun> = settings.iter().map(|s| s.1).collect();
    sweep(h, reference, results, side, settings, |run| {
        run.samples(h.samples)
    });
    for (r, run) in results[first..].iter_mut().zip(runs) {
        r.physlab = Some(run);
    }
}

/// The 1e-3 claim in one call: `physlab study work-precision --theta0 60 --sample-every 0.1
/// --duration 20` (this problem) swept from physlab's library, its cheapest run at 1e-3 (the
/// answer it prints) timed against this benchmark's cheapest physlab run at 1e-3, the two
/// interleaved run by run, in three rounds of `repeats` pairs; each round's ratio is the
/// minima's.
fn study_answer(h: &Horizon, reference: &Reference, results: &[RunResult]) {
    const TARGET: f64 = 1e-3;
    let problem = Problem::Pendulum(params());
    let sw = Sweep {
        sample_dt: SAMPLE_DT,
        duration: h.samples as f64 * SAMPLE_DT,
        ..Sweep::work_precision(&problem)
    };
    let (rows, _) = physlab::study::sweep(&problem, &sw);
    let ours = results
        .iter()
        .filter(|r| r.physlab.is_some() && r.error <= TARGET)
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds));
    let (Some(row), Some(best)) = (cheapest(&rows, TARGET).0, ours) else {
        println!("\nthe study or the benchmark reaches no {TARGET:e}");
        return;
    };
    let study = PhyslabRun::of(row);
    let bench = best.physlab.expect("a physlab run");
    let words = physlab::study::settings(row, SAMPLE_DT).join(" ");
    println!(
        "\nAt {TARGET:.0e}: the study's answer (`physlab study work-precision --theta0 60 \
         --sample-every 0.1 --duration 20`, {} runs) is `{words}` (error {:.2e}); the \
         benchmark's best physlab run is {} {} (error {:.2e}).",
        rows.len(),
        reference.error(&study.samples(h.samples)),
        best.side,
        best.setting,
        best.error,
    );
    let time = |run: &PhyslabRun| {
        let t = Instant::now();
        black_box(run.samples(h.samples));
        t.elapsed().as_secs_f64()
    };
    let mut ratios = Vec::new();
    for round in 1..=3 {
        let (mut a, mut b) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..20_000 {
            a = a.min(time(&study));
            b = b.min(time(&bench));
        }
        println!(
            "round {round}: study {:.2} µs, benchmark {:.2} µs, study / benchmark {:.3}",
            a * 1e6,
            b * 1e6,
            a / b
        );
        ratios.push(a / b);
    }
    ratios.sort_by(f64::total_cmp);
    println!(
        "study / benchmark at {TARGET:.0e}: median {:.3} (spread {:.3}–{:.3}; ≤ 1: the study's \
         answer is at least as fast)",
        ratios[1], ratios[0], ratios[2]
    );
}

mod os {
    //! ode_solvers 0.6.2.
    use super::Samples;
    use ode_solvers::{Dop853, Dopri5, OutputType, Rk4, System, Vector2};
    pub type State = Vector2<f64>;
    pub struct P {
        pub k: f64,
    }
    impl System<f64, State> for P {
        fn system(&self, _t: f64, y: &State, dy: &mut State) {
            dy[0] = y[1];
            dy[1] = -self.k * y[0].sin();
        }
    }
    /// Every `every`-th output after the first (the outputs start at t = 0); the outputs that
    /// exist (a run with fewer counts as failed).
    fn thin(t: &[f64], y: &[State], every: usize, samples: usize) -> Samples {
        let at = |k: usize| k * every;
        Samples {
            times: Some(
                (1..=samples)
                    .filter_map(|k| t.get(at(k)).copied())
                    .collect(),
            ),
            theta: (1..=samples)
                .filter_map(|k| y.get(at(k)).map(|y| y[0]))
                .collect(),
        }
    }
    pub fn rk4(k: f64, theta0: f64, h: f64, per_sample: usize, samples: usize) -> Samples {
        let end = samples as f64 * super::SAMPLE_DT;
        let mut s = Rk4::new(P { k }, 0.0, State::new(theta0, 0.0), end, h);
        s.integrate().unwrap();
        thin(s.x_out(), s.y_out(), per_sample, samples)
    }
    pub fn dopri5(k: f64, theta0: f64, tol: f64, samples: usize) -> Samples {
        let end = samples as f64 * super::SAMPLE_DT;
        let y0 = State::new(theta0, 0.0);
        // `new`'s settings, without its cap of 100 000 steps (10⁴ periods need more).
        let mut s = Dopri5::from_param(
            P { k },
            0.0,
            end,
            super::SAMPLE_DT,
            y0,
            tol,
            tol,
            0.9,
            0.04,
            0.2,
            10.0,
            end,
            0.0,
            u32::MAX,
            1000,
            OutputType::Dense,
        );
        match s.integrate() {
            Ok(_) => thin(s.x_out(), s.y_out(), 1, samples),
            Err(_) => Samples::failed(samples),
        }
    }
    pub fn dop853(k: f64, theta0: f64, tol: f64, samples: usize) -> Samples {
        let end = samples as f64 * super::SAMPLE_DT;
        let y0 = State::new(theta0, 0.0);
        let mut s = Dop853::from_param(
            P { k },
            0.0,
            end,
            super::SAMPLE_DT,
            y0,
            tol,
            tol,
            0.9,
            0.0,
            0.333,
            6.0,
            end,
            0.0,
            u32::MAX,
            1000,
            OutputType::Dense,
        );
        match s.integrate() {
            Ok(_) => thin(s.x_out(), s.y_out(), 1, samples),
            Err(_) => Samples::failed(samples),
        }
    }
}

mod de {
    //! differential-equations 0.6.1.
    use super::Samples;
    use differential_equations::prelude::*;
    pub struct P {
        pub k: f64,
    }
    impl ODE<f64, [f64; 2]> for P {
        fn diff(&self, _t: f64, y: &[f64; 2], dydt: &mut [f64; 2]) {
            dydt[0] = y[1];
            dydt[1] = -self.k * y[0].sin();
        }
    }
    pub fn run(k: f64, theta0: f64, tol: f64, verner: bool, samples: usize) -> Samples {
        let p = P { k };
        let end = samples as f64 * super::SAMPLE_DT;
        let ivp = IVP::ode(&p, 0.0, end, [theta0, 0.0]);
        let steps = usize::MAX;
        let sol = if verner {
            let m = ExplicitRungeKutta::rkv988e().rtol(tol).atol(tol);
            ivp.method(m.max_steps(steps))
                .even(super::SAMPLE_DT)
                .solve()
        } else {
            let m = ExplicitRungeKutta::dop853().rtol(tol).atol(tol);
            ivp.method(m.max_steps(steps))
                .even(super::SAMPLE_DT)
                .solve()
        };
        let Ok(sol) = sol else {
            return Samples::failed(samples);
        };
        // Outputs at 0, 0.1, ..., the end (the last may repeat): the ones after the start.
        Samples {
            times: Some(sol.t.iter().skip(1).take(samples).copied().collect()),
            theta: sol.y.iter().skip(1).take(samples).map(|y| y[0]).collect(),
        }
    }
}

/// Writes the problem, the exact θ and physlab's cheapest run per target to a JSON file and runs
/// `benches/scipy_peer.py` on it (same session), which times scipy's solve_ivp(DOP853) at equal
/// error when python3 and scipy are installed.
fn scipy_peer(results: &[RunResult], exact: &[f64], g_over_l: f64, theta0: f64) {
    let mut best = Vec::new();
    for target in TARGETS {
        let ours = results
            .iter()
            .filter(|r| r.side.starts_with("physlab") && r.error <= target)
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds));
        best.push(match ours {
            Some(r) => format!(
                "{{\"setting\": \"{} {}\", \"seconds\": {:e}}}",
                r.side, r.setting, r.seconds
            ),
            None => "null".into(),
        });
    }
    let list = |v: &mut dyn Iterator<Item = String>| v.collect::<Vec<_>>().join(", ");
    let duration = exact.len() as f64 * SAMPLE_DT;
    let json = format!(
        "{{\"g_over_l\": {g_over_l:e}, \"theta0\": {theta0:e}, \"duration\": {duration:e}, \
         \"times\": [{}], \"exact\": [{}], \"targets\": [{}], \"physlab_best\": [{}]}}",
        list(&mut (1..=exact.len()).map(|i| format!("{:e}", i as f64 * SAMPLE_DT))),
        list(&mut exact.iter().map(|x| format!("{x:e}"))),
        list(&mut TARGETS.iter().map(|t| format!("{t:e}"))),
        best.join(", ")
    );
    let path = std::env::temp_dir().join("physlab_peers_scipy.json");
    if let Err(e) = std::fs::write(&path, json) {
        println!(
            "\nscipy comparison skipped: cannot write {}: {e}",
            path.display()
        );
        return;
    }
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/scipy_peer.py");
    match std::process::Command::new("python3")
        .arg(script)
        .arg(&path)
        .status()
    {
        Ok(s) if s.success() => {}
        Ok(s) => println!("\nscipy comparison failed ({s})"),
        Err(e) => println!("\nscipy comparison skipped: python3 not found ({e})"),
    }
}

fn table(h: &Horizon, results: &[RunResult]) {
    let best = |pred: &dyn Fn(&RunResult) -> bool, target: f64| {
        results
            .iter()
            .filter(|r| pred(r) && r.error <= target)
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
    };
    println!("\n{}", h.title);
    println!(
        "| target | physlab (cheapest) | time [µs] | best peer | time [µs] | peer / physlab |"
    );
    println!("|---|---|---|---|---|---|");
    for &target in h.targets {
        let ours = best(&|r| r.side.starts_with("physlab"), target);
        let peer = best(&|r| !r.side.starts_with("physlab"), target);
        let show = |r: Option<&RunResult>| {
            r.map_or(("none reached it".to_string(), "—".to_string()), |r| {
                (
                    format!("{} {}", r.side, r.setting),
                    format!("{:.1}", r.seconds * 1e6),
                )
            })
        };
        let (on, ot) = show(ours);
        let (pn, pt) = show(peer);
        let ratio = match (ours, peer) {
            (Some(o), Some(p)) => format!("{:.2}", p.seconds / o.seconds),
            (Some(_), None) => "no peer reached it".into(),
            _ => "—".into(),
        };
        println!("| {target:.0e} | {on} | {ot} | {pn} | {pt} | {ratio} |");
    }
    println!("\nEvery side's cheapest run per target [µs] (error of that run):");
    let mut sides: Vec<&str> = results.iter().map(|r| r.side).collect();
    sides.sort();
    sides.dedup();
    print!("| side |");
    for t in h.targets {
        print!(" {t:.0e} |");
    }
    println!("\n|---|{}", "---|".repeat(h.targets.len()));
    for side in sides {
        print!("| {side} |");
        for &t in h.targets {
            match best(&|r| r.side == side, t) {
                Some(r) => print!(" {:.1} ({}, {:.1e}) |", r.seconds * 1e6, r.setting, r.error),
                None => print!(" — |"),
            }
        }
        println!();
    }
}

/// Every side over its settings on one horizon.
fn compare(h: &Horizon, long: bool) -> (Reference, Vec<RunResult>) {
    let p = params();
    let k = p.gravity / p.length;
    let n = h.samples;
    let reference = Reference::new(n);
    let mut results = Vec::new();
    // Half-decade tolerances (1e-2, 3.2e-3, 1e-3, ..., 1e-14), the same grid for every side.
    let tols: Vec<(String, f64)> = (4..=28)
        .map(|e| 10f64.powf(-f64::from(e) / 2.0))
        .map(|t| (format!("rtol {t:.1e}"), t))
        .collect();
    // Fixed steps h = 0.1 / 2^j.
    let steps: Vec<(String, usize)> = (0..=12)
        .map(|j| 1usize << j)
        .map(|per| (format!("h {:.1e}", SAMPLE_DT / per as f64), per))
        .collect();
    // physlab's fixed-step methods also step across the samples (`MethodOptions::step`), at
    // h = 0.1 · 2^(j/8) s from 0.4 s down, before the grid of steps that end at every sample
    // (the peers' fixed-step method cannot: its steps are its samples).
    let across: Vec<(String, (usize, Option<f64>))> = (1..=16)
        .rev()
        .map(|j| SAMPLE_DT * 2f64.powf(f64::from(j) / 8.0))
        .map(|h| (format!("h {h:.2e} across samples"), (1, Some(h))))
        .chain(steps.iter().map(|(l, per)| (l.clone(), (*per, None))))
        .collect();
    let r = &mut results;
    let mut fixed = vec![
        (Method::Rk4, false),
        (Method::Yoshida4, false),
        (Method::Verlet, false),
        (Method::Rkn4, false),
        (Method::Yoshida6, false),
        (Method::KahanLi8, false),
        (Method::Sofroniou10, false),
    ];
    if long {
        // Over 10⁸ steps rounding matters: the compositions with compensated sums too.
        fixed.extend([(Method::KahanLi8, true), (Method::Sofroniou10, true)]);
    }
    for (m, compensated) in fixed {
        let runs = (across.iter())
            .map(|(label, (per, step))| {
                let options = MethodOptions {
                    compensated,
                    step: *step,
                    ..MethodOptions::default()
                };
                let run = PhyslabRun {
                    method: m,
                    dt: SAMPLE_DT / *per as f64,
                    per_sample: *per,
                    options,
                };
                (label.clone(), run)
            })
            .collect();
        physlab_sweep(h, &reference, r, side_name(m, compensated), runs);
    }
    for m in [
        Method::Dopri5,
        Method::Dop853,
        Method::Vern9,
        Method::Dprkn6,
        Method::Dprkn8,
        Method::Dprkn12,
    ] {
        let runs = (tols.iter())
            .map(|(label, rtol)| {
                let options = MethodOptions {
                    rtol: *rtol,
                    ..MethodOptions::default()
                };
                let run = PhyslabRun {
                    method: m,
                    dt: SAMPLE_DT,
                    per_sample: 1,
                    options,
                };
                (label.clone(), run)
            })
            .collect();
        physlab_sweep(h, &reference, r, side_name(m, false), runs);
    }
    let tol_peer = |s: &(String, f64)| (s.0.replace("rtol", "tol"), s.1);
    sweep(h, &reference, r, "ode_solvers-rk4", steps.clone(), |&per| {
        os::rk4(k, p.theta0, SAMPLE_DT / per as f64, per, n)
    });
    sweep(
        h,
        &reference,
        r,
        "ode_solvers-dopri5",
        tols.iter().map(tol_peer),
        |&tol| os::dopri5(k, p.theta0, tol, n),
    );
    sweep(
        h,
        &reference,
        r,
        "ode_solvers-dop853",
        tols.iter().map(tol_peer),
        |&tol| os::dop853(k, p.theta0, tol, n),
    );
    sweep(
        h,
        &reference,
        r,
        "diffeq-dop853",
        tols.iter().map(tol_peer),
        |&tol| de::run(k, p.theta0, tol, false, n),
    );
    sweep(
        h,
        &reference,
        r,
        "diffeq-rkv988e",
        tols.iter().map(tol_peer),
        |&tol| de::run(k, p.theta0, tol, true, n),
    );
    (reference, results)
}

fn main() {
    let p = params();
    let k = p.gravity / p.length;
    let short = Horizon {
        title:
            "Cheapest run per target error (pendulum 60°, 20 s, 200 samples; min of up to 11 runs):"
                .into(),
        samples: 200,
        repeats: 11,
        budget: 0.05,
        targets: &TARGETS,
    };
    let (reference, results) = compare(&short, false);
    table(&short, &results);
    study_answer(&short, &reference, &results);
    // `cargo bench -p physlab-peers -- study-answer`: the short horizon and the study's answer
    // only.
    if std::env::args().any(|a| a == "study-answer") {
        return;
    }
    scipy_peer(&results, &reference.grid, k, p.theta0);

    // The same over 10⁴ periods: sample every 0.1 s up to 10⁴ T.
    let period = reference.exact.period();
    let samples = (1e4 * period / SAMPLE_DT).floor() as usize;
    let long = Horizon {
        title: format!(
            "Over 10⁴ periods (pendulum 60°, T = {period:.6} s, {:.0} s, {samples} samples every \
             0.1 s; min of up to 3 runs; a side stops after a run over 2 s):",
            samples as f64 * SAMPLE_DT
        ),
        samples,
        repeats: 3,
        budget: 2.0,
        targets: &[1e-3, 1e-6, 1e-8, 1e-10],
    };
    let (_, results) = compare(&long, true);
    table(&long, &results);

    // RK4 per step, criterion.
    let mut c = Criterion::default().configure_from_args();
    let mut g = c.benchmark_group("peers_rk4_20s_h1e-3");
    g.bench_function("physlab", |b| {
        b.iter(|| {
            black_box(physlab_run(
                Method::Rk4,
                1e-3,
                100,
                MethodOptions::default(),
                200,
            ))
        })
    });
    g.bench_function("ode_solvers", |b| {
        b.iter(|| black_box(os::rk4(k, p.theta0, 1e-3, 100, 200)))
    });
    g.finish();
    c.final_summary();
}

/// `physlab-<method>` (with `+compensated`) as a `&'static str` (a handful of names, leaked
/// once per run).
fn side_name(m: Method, compensated: bool) -> &'static str {
    let suffix = if compensated { "+compensated" } else { "" };
    Box::leak(format!("physlab-{}{suffix}", m.name()).into_boxed_str())
}
