//! The pendulum's numbers against theory and independent references (issue 2, point 7 a-c).
//! Theory: `../shared/reference/oscillator_theory.md`; periods: `tests/data/pendulum_period.csv`
//! (a verbatim copy of `../shared/reference/pendulum_period.csv`, computed with 40-digit mpmath).

use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::harness::{NoObserver, Run, run};
use physlab::scene::pendulum::period::PeriodMeter;
use physlab::scene::pendulum::reference::{ExactPendulum, exact_period};
use physlab::scene::pendulum::run::{PendulumConfig, PendulumLane, PendulumScene};
use physlab::scene::pendulum::{Pendulum, PendulumParams};

fn params(theta0_deg: f64) -> PendulumParams {
    PendulumParams {
        theta0: theta0_deg.to_radians(),
        ..PendulumParams::default()
    }
}

/// A run without a recording.
fn simulate(config: PendulumConfig) -> Run<PendulumLane> {
    run(&mut PendulumScene::new(config), &mut NoObserver).unwrap()
}

fn config(method: Method, theta0_deg: f64, dt: f64, duration: f64) -> PendulumConfig {
    PendulumConfig {
        params: params(theta0_deg),
        dt,
        duration,
        fps: 1.0,
        plot_every: 1,
        methods: vec![method],
        options: MethodOptions::default(),
    }
}

/// Steps one method by hand and returns (E_n - E0)/E0 after every step.
fn energy_errors(method: Method, theta0_deg: f64, dt: f64, steps: usize) -> Vec<f64> {
    let p = params(theta0_deg);
    let sys = Pendulum::new(&p);
    let mut it = Integrator::new(
        method,
        &sys,
        &[p.theta0],
        &[0.0],
        dt,
        MethodOptions::default(),
    );
    let e0 = p.initial_energy();
    (0..steps)
        .map(|_| {
            it.step(&sys);
            (p.energy(it.position()[0], it.velocity()[0]) - e0) / e0
        })
        .collect()
}

/// (a) The order measured from the largest |θ - θ_exact| over a 10 s run (every step, so not
/// only turning points, where the observed order would double) as dt halves, for every method.
#[test]
fn measured_convergence_order_matches_the_registry() {
    for &m in Method::DEFAULT {
        let order = m.info().order;
        // Asymptotic ranges: first-order methods need small dt for errors ≪ amplitude; RK4 must
        // stay above round-off (errors here run from 2e-5 down to 6e-9).
        let dts: [f64; 4] = if order == 4 {
            [0.08, 0.04, 0.02, 0.01]
        } else {
            [0.004, 0.002, 0.001, 0.0005]
        };
        let errors: Vec<f64> = dts
            .iter()
            .map(|&dt| {
                let s = simulate(config(m, 60.0, dt, 10.0));
                assert!(s.stats[1].divergence.is_none(), "{m} diverged at dt = {dt}");
                s.lanes[1].max_theta_error
            })
            .collect();
        for (w, dt) in errors.windows(2).zip(dts) {
            let measured = (w[0] / w[1]).log2();
            assert!(
                (measured - order as f64).abs() <= 0.15,
                "{m}: order {measured:.3} from dt {dt} to {} (errors {:.3e}, {:.3e}), registry says {order}",
                dt / 2.0,
                w[0],
                w[1]
            );
        }
    }
}

/// Rows (θ0 [deg], T/T0, T [s] for g = 9.81, L = 3.521) of the reference table.
fn period_table() -> Vec<(f64, f64, f64)> {
    let text = include_str!("data/pendulum_period.csv");
    let rows: Vec<(f64, f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("theta0"))
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            (f[0], f[1], f[2])
        })
        .collect();
    assert_eq!(rows.len(), 7, "the reference table has 7 amplitudes");
    rows
}

/// (b) The closed-form solution's period matches the table to 1e-9, both from K(m) and as
/// measured from the zero crossings of the closed-form θ(t) itself.
#[test]
fn exact_solution_matches_reference_periods() {
    for (deg, ratio, period) in period_table() {
        let p = params(deg);
        let exact = ExactPendulum::new(&p).unwrap();
        let t0 = 2.0 * std::f64::consts::PI / p.omega_n();
        assert!(
            (exact.period() / period - 1.0).abs() < 1e-9,
            "{deg}°: T = {} vs {period}",
            exact.period()
        );
        assert!(
            (exact.period() / t0 / ratio - 1.0).abs() < 1e-9,
            "{deg}°: T/T0"
        );
        assert!((exact_period(&p).unwrap() / period - 1.0).abs() < 1e-9);

        let mut meter = PeriodMeter::new();
        let dt = 1e-3;
        let steps = (10.5 * period / dt) as usize;
        for n in 0..=steps {
            let t = n as f64 * dt;
            let (th, w) = exact.state(t);
            meter.push(t, th, w);
        }
        let measured = meter.period().unwrap();
        assert!(
            (measured / period - 1.0).abs() < 1e-9,
            "{deg}°: crossings give {measured} vs {period}"
        );
    }
}

/// (b) RK4 (dt = 1 ms) and Verlet (dt = 0.1 ms) reproduce the reference periods to 1e-6 relative,
/// measured from zero crossings over ten periods.
#[test]
fn rk4_and_verlet_reproduce_reference_periods() {
    for (deg, _, period) in period_table() {
        for (m, dt) in [(Method::Rk4, 1e-3), (Method::Verlet, 1e-4)] {
            let s = simulate(config(m, deg, dt, 10.5 * period));
            let meter = &s.lanes[1].meter;
            assert!(
                meter.periods_seen() >= 9,
                "{m} {deg}°: {} periods",
                meter.periods_seen()
            );
            let measured = meter.period().unwrap();
            assert!(
                (measured / period - 1.0).abs() < 1e-6,
                "{m} at {deg}°: period {measured} vs reference {period} ({:+.2e})",
                measured / period - 1.0
            );
        }
    }
}

/// (c) Explicit Euler multiplies the oscillator's energy by exactly 1 + h² per step (h = ωn dt)
/// and implicit Euler by 1/(1 + h²). At θ0 = 1° the pendulum is that oscillator to ~1e-4, so
/// the energy must change monotonically and land within 1e-3 (relative) of the theory after 2000 steps.
#[test]
fn euler_energy_grows_and_implicit_euler_energy_decays_as_theory_says() {
    let dt = 0.01;
    let n = 2000;
    let h = params(1.0).omega_n() * dt;
    for (m, per_step) in [
        (Method::ExplicitEuler, 1.0 + h * h),
        (Method::ImplicitEuler, 1.0 / (1.0 + h * h)),
    ] {
        let e = energy_errors(m, 1.0, dt, n);
        let growing = per_step > 1.0;
        for w in e.windows(2) {
            assert!(
                if growing { w[1] > w[0] } else { w[1] < w[0] },
                "{m}: energy not monotone"
            );
        }
        let theory = per_step.powi(n as i32) - 1.0;
        let last = e[n - 1];
        assert!(
            (last / theory - 1.0).abs() < 1e-3,
            "{m}: ΔE/E0 = {last:.6e}, theory {theory:.6e}"
        );
    }
}

/// Largest |x| of a slice.
fn max_abs(s: &[f64]) -> f64 {
    s.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

fn mean(s: &[f64]) -> f64 {
    s.iter().sum::<f64>() / s.len() as f64
}

/// (c) Semi-implicit Euler and Verlet keep the energy bounded with no drift over 1000 periods.
///
/// Bounds, from the exactly conserved modified energy of each map on the linear oscillator
/// (oscillator_theory.md; the pendulum's softening only lowers them): semi-implicit Euler
/// conserves (v² + x² - h x v)/2, so |ΔE/E0| ≤ (h/2)/(1 - h/2); Verlet conserves
/// (v² + (1 - h²/4) x²)/2, so |ΔE/E0| ≤ h²/4. At 5° the measured maximum must also reach 95% of
/// the bound: the oscillation has the predicted size, not merely some bounded size.
///
/// Drift: the mean of ΔE/E0 over the last ten periods may differ from that over the first ten
/// by at most 1% of the oscillation's amplitude. The same measure flags midpoint, whose energy
/// grows by h⁴/4 per step, at more than 10× the amplitude, so it does discriminate.
#[test]
fn symplectic_methods_keep_energy_bounded_without_drift_over_1000_periods() {
    let dt = 0.01;
    for deg in [5.0, 60.0] {
        let p = params(deg);
        let h = p.omega_n() * dt;
        let period = exact_period(&p).unwrap();
        let window = (10.0 * period / dt).round() as usize;
        let steps = (1000.0 * period / dt).round() as usize;
        let drift = |e: &[f64]| {
            (mean(&e[e.len() - window..]) - mean(&e[..window])).abs() / max_abs(&e[..window])
        };

        for (m, bound) in [
            (Method::SemiImplicitEuler, 0.5 * h / (1.0 - 0.5 * h)),
            (Method::Verlet, 0.25 * h * h),
        ] {
            let e = energy_errors(m, deg, dt, steps);
            let max = max_abs(&e);
            assert!(
                max <= bound * (1.0 + 1e-9),
                "{m} at {deg}°: max |ΔE/E0| {max:.4e} > bound {bound:.4e}"
            );
            if deg == 5.0 {
                assert!(
                    max >= 0.95 * bound,
                    "{m} at {deg}°: max |ΔE/E0| {max:.4e} far below theory {bound:.4e}"
                );
            }
            assert!(
                drift(&e) < 0.01,
                "{m} at {deg}°: energy drifts by {:.2}% of its oscillation",
                100.0 * drift(&e)
            );
        }
        let e = energy_errors(Method::Midpoint, deg, dt, steps);
        assert!(
            drift(&e) > 10.0,
            "midpoint at {deg}°: drift measure {:.2} should flag it",
            drift(&e)
        );
    }
}
