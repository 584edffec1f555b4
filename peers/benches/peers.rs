//! physlab against compiled peers at equal accuracy (issue 13, point 4):
//! `cargo bench -p physlab-peers`.
//!
//! The problem: the pendulum θ'' = -(g/L) sin θ, g = 9.81, L = 3.521, released from rest at
//! θ0 = 60°, over 20 s, sampled every 0.1 s (200 sample times). The error of a run is
//! max |θ - θ_exact| over the sample times, θ_exact from physlab's closed form (elliptic
//! functions). Every side runs over a sweep (fixed-step methods: the step halved; adaptive ones:
//! rtol = atol from 1e-2 to 1e-14 in half decades) and each run is timed as the minimum of REPEATS runs; the
//! table shows, per target error, each side's cheapest run reaching it and the ratio
//! peer time / physlab time (> 1: physlab is faster).
//!
//! Peers: `ode_solvers` 0.6.2 (Rk4, Dopri5, Dop853; output every 0.1 s through their dense
//! output, every step for Rk4, of which the samples are taken) and `differential-equations`
//! 0.6.1 (ExplicitRungeKutta::dop853 and ::rkv988e, Verner's 9(8) "efficient" pair, the same
//! tableau as physlab's vern9, with
//! `.even(0.1)` output). State types: nalgebra Vector2 for ode_solvers, [f64; 2] for
//! differential-equations, physlab's own flat slices.
//!
//! Then `peers/benches/scipy_peer.py` times scipy's solve_ivp(method="DOP853") on the same problem at
//! equal error, in the same session, when python3 and scipy are installed.
//!
//! After the tables, criterion times RK4 at h = 1e-3 s over the 20 s (20 000 steps) for physlab
//! and ode_solvers (point 1: RK4's cost per step).

use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::pendulum::reference::ExactPendulum;
use physlab::scene::pendulum::{Pendulum, PendulumParams};

const DURATION: f64 = 20.0;
const SAMPLE_DT: f64 = 0.1;
const SAMPLES: usize = 200;
const REPEATS: usize = 11;
const TARGETS: [f64; 5] = [1e-3, 1e-6, 1e-8, 1e-10, 1e-12];

fn params() -> PendulumParams {
    PendulumParams {
        theta0: 60f64.to_radians(),
        ..PendulumParams::default()
    }
}

/// One run: who, with what setting, its error and its time (min over the repeats) [s].
struct RunResult {
    side: &'static str,
    setting: String,
    error: f64,
    seconds: f64,
}

/// Times `f` (which returns the θ at the sample times) and measures its error.
fn measure(
    side: &'static str,
    setting: String,
    exact: &[f64],
    mut f: impl FnMut() -> Vec<f64>,
) -> RunResult {
    let mut best = f64::INFINITY;
    let mut thetas = Vec::new();
    for _ in 0..REPEATS {
        let t = Instant::now();
        thetas = black_box(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    assert_eq!(thetas.len(), exact.len(), "{side} {setting}: sample count");
    let error = thetas
        .iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, |m, e| {
            if e.is_finite() {
                m.max(e)
            } else {
                f64::INFINITY
            }
        });
    RunResult {
        side,
        setting,
        error,
        seconds: best,
    }
}

fn physlab_run(method: Method, dt: f64, per_sample: usize, options: MethodOptions) -> Vec<f64> {
    let p = params();
    let sys = Pendulum::new(&p);
    let mut it = Integrator::new(method, &sys, &[p.theta0], &[0.0], dt, options);
    let mut out = Vec::with_capacity(SAMPLES);
    for _ in 0..SAMPLES {
        for _ in 0..per_sample {
            it.step(&sys);
        }
        out.push(it.position()[0]);
    }
    out
}

mod os {
    //! ode_solvers 0.6.2.
    use ode_solvers::{Dop853, Dopri5, Rk4, System, Vector2};
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
    /// θ at every `every`-th output after the first (the outputs start at t = 0).
    fn thin(y: &[State], every: usize, samples: usize) -> Vec<f64> {
        (1..=samples).map(|k| y[k * every][0]).collect()
    }
    pub fn rk4(k: f64, theta0: f64, h: f64, per_sample: usize) -> Vec<f64> {
        let mut s = Rk4::new(P { k }, 0.0, State::new(theta0, 0.0), super::DURATION, h);
        s.integrate().unwrap();
        thin(s.y_out(), per_sample, super::SAMPLES)
    }
    pub fn dopri5(k: f64, theta0: f64, tol: f64) -> Vec<f64> {
        let mut s = Dopri5::new(
            P { k },
            0.0,
            super::DURATION,
            super::SAMPLE_DT,
            State::new(theta0, 0.0),
            tol,
            tol,
        );
        s.integrate().unwrap();
        thin(s.y_out(), 1, super::SAMPLES)
    }
    pub fn dop853(k: f64, theta0: f64, tol: f64) -> Vec<f64> {
        let mut s = Dop853::new(
            P { k },
            0.0,
            super::DURATION,
            super::SAMPLE_DT,
            State::new(theta0, 0.0),
            tol,
            tol,
        );
        s.integrate().unwrap();
        thin(s.y_out(), 1, super::SAMPLES)
    }
}

mod de {
    //! differential-equations 0.6.1.
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
    pub fn run(k: f64, theta0: f64, tol: f64, verner: bool) -> Vec<f64> {
        let p = P { k };
        let ivp = IVP::ode(&p, 0.0, super::DURATION, [theta0, 0.0]);
        let sol = if verner {
            ivp.method(ExplicitRungeKutta::rkv988e().rtol(tol).atol(tol))
                .even(super::SAMPLE_DT)
                .solve()
        } else {
            ivp.method(ExplicitRungeKutta::dop853().rtol(tol).atol(tol))
                .even(super::SAMPLE_DT)
                .solve()
        }
        .unwrap();
        // Outputs at 0, 0.1, ..., 20 (the last may repeat 20): the 200 after the start.
        sol.y
            .iter()
            .skip(1)
            .take(super::SAMPLES)
            .map(|y| y[0])
            .collect()
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
    let json = format!(
        "{{\"g_over_l\": {g_over_l:e}, \"theta0\": {theta0:e}, \"duration\": {DURATION:e}, \
         \"times\": [{}], \"exact\": [{}], \"targets\": [{}], \"physlab_best\": [{}]}}",
        list(&mut (1..=SAMPLES).map(|i| format!("{:e}", i as f64 * SAMPLE_DT))),
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

fn table(results: &[RunResult]) {
    let best = |pred: &dyn Fn(&RunResult) -> bool, target: f64| {
        results
            .iter()
            .filter(|r| pred(r) && r.error <= target)
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
    };
    println!(
        "\nCheapest run per target error (pendulum 60°, 20 s, 200 samples; min of {REPEATS} runs):"
    );
    println!(
        "| target | physlab (cheapest) | time [µs] | best peer | time [µs] | peer / physlab |"
    );
    println!("|---|---|---|---|---|---|");
    for target in TARGETS {
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
            _ => "—".into(),
        };
        println!("| {target:.0e} | {on} | {ot} | {pn} | {pt} | {ratio} |");
    }
    println!("\nEvery side's cheapest run per target [µs]:");
    let mut sides: Vec<&str> = results.iter().map(|r| r.side).collect();
    sides.dedup();
    print!("| side |");
    for t in TARGETS {
        print!(" {t:.0e} |");
    }
    println!();
    for side in sides {
        print!("| {side} |");
        for t in TARGETS {
            match best(&|r| r.side == side, t) {
                Some(r) => print!(" {:.1} ({}) |", r.seconds * 1e6, r.setting),
                None => print!(" — |"),
            }
        }
        println!();
    }
}

fn main() {
    let p = params();
    let k = p.gravity / p.length;
    let exact_pendulum = ExactPendulum::new(&p).unwrap();
    let exact: Vec<f64> = (1..=SAMPLES)
        .map(|i| exact_pendulum.state(i as f64 * SAMPLE_DT).0)
        .collect();
    let mut results = Vec::new();
    // Half-decade tolerances (1e-2, 3.2e-3, 1e-3, ..., 1e-14), the same grid for every side.
    let tols: Vec<f64> = (4..=28).map(|e| 10f64.powf(-f64::from(e) / 2.0)).collect();

    // Fixed-step: h = 0.1 / 2^j.
    for j in 0..=9 {
        let per = 1usize << j;
        let h = SAMPLE_DT / per as f64;
        for m in [
            Method::Rk4,
            Method::Yoshida4,
            Method::Verlet,
            Method::Rkn4,
            Method::Yoshida6,
            Method::KahanLi8,
            Method::Sofroniou10,
        ] {
            results.push(measure(
                "physlab-".to_string().leak_name(m),
                format!("h {h:.1e}"),
                &exact,
                || physlab_run(m, h, per, MethodOptions::default()),
            ));
        }
        results.push(measure(
            "ode_solvers-rk4",
            format!("h {h:.1e}"),
            &exact,
            || os::rk4(k, p.theta0, h, per),
        ));
    }
    for &tol in &tols {
        for m in [
            Method::Dopri5,
            Method::Dop853,
            Method::Vern9,
            Method::Dprkn6,
            Method::Dprkn12,
        ] {
            let options = MethodOptions {
                rtol: tol,
                ..MethodOptions::default()
            };
            results.push(measure(
                "physlab-".to_string().leak_name(m),
                format!("rtol {tol:.1e}"),
                &exact,
                || physlab_run(m, SAMPLE_DT, 1, options),
            ));
        }
        results.push(measure(
            "ode_solvers-dopri5",
            format!("tol {tol:.1e}"),
            &exact,
            || os::dopri5(k, p.theta0, tol),
        ));
        results.push(measure(
            "ode_solvers-dop853",
            format!("tol {tol:.1e}"),
            &exact,
            || os::dop853(k, p.theta0, tol),
        ));
        results.push(measure(
            "diffeq-dop853",
            format!("tol {tol:.1e}"),
            &exact,
            || de::run(k, p.theta0, tol, false),
        ));
        results.push(measure(
            "diffeq-rkv988e",
            format!("tol {tol:.1e}"),
            &exact,
            || de::run(k, p.theta0, tol, true),
        ));
    }
    results.sort_by_key(|r| r.side);
    table(&results);
    scipy_peer(&results, &exact, k, p.theta0);

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
            ))
        })
    });
    g.bench_function("ode_solvers", |b| {
        b.iter(|| black_box(os::rk4(k, p.theta0, 1e-3, 100)))
    });
    g.finish();
    c.final_summary();
}

/// `physlab-<method>` as a `&'static str` (a handful of names, leaked once per run).
trait LeakName {
    fn leak_name(self, m: Method) -> &'static str;
}
impl LeakName for String {
    fn leak_name(mut self, m: Method) -> &'static str {
        self.push_str(m.name());
        Box::leak(self.into_boxed_str())
    }
}
