//! DOP853 and Verner's 9(8): their measured order on the pendulum,
//! their dense output, the exact period through it, tolerance proportionality, and the accepted /
//! rejected step counts.

use physlab::integrate::{Integrator, Method, MethodOptions};
use physlab::scene::pendulum::reference::ExactPendulum;
use physlab::scene::pendulum::{Pendulum, PendulumParams};

fn params(deg: f64) -> PendulumParams {
    PendulumParams {
        theta0: deg.to_radians(),
        ..PendulumParams::default()
    }
}

/// Largest |θ - θ_exact| at t = k dt over `duration` from 60°, and the integrator at the end.
fn max_error(method: Method, options: MethodOptions, dt: f64, duration: f64) -> (f64, Integrator) {
    max_error_from(60.0, method, options, dt, duration)
}

fn max_error_from(
    deg: f64,
    method: Method,
    options: MethodOptions,
    dt: f64,
    duration: f64,
) -> (f64, Integrator) {
    let p = params(deg);
    let sys = Pendulum::new(&p);
    let exact = ExactPendulum::new(&p).unwrap();
    let mut it = Integrator::new(method, &sys, &[p.theta0], &[0.0], dt, options);
    let mut worst: f64 = 0.0;
    for k in 1..=(duration / dt).round() as u64 {
        it.step(&sys);
        worst = worst.max((it.position()[0] - exact.state(k as f64 * dt).0).abs());
    }
    (worst, it)
}

/// Least-squares slope of ln y against ln x.
fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
}

/// With error control off (rtol 1e300) and the step capped at dt, the pair steps at exactly dt:
/// its order, the least-squares slope of the largest error against dt over five steps of
/// 2^(1/4) (a halving), is within ±0.2 of the registry's (printed).
/// - DOP853: 60°, 10 s, dt 0.2 s to 0.1 s: 7.86 (between 0.4 s and 0.2 s it is 8.63, not yet
///   asymptotic).
/// - vern9: 30°, 100 s, dt 0.4 s to 0.2 s: 9.18. Verner's pair is tuned so that its leading
///   error term is small, and the measured slope comes down to 9 from above only slowly while
///   the errors approach round-off: at 60° over 10 s it is 10.19 (dt 0.4-0.2 s), 9.41 (0.3-0.15 s)
///   and 3.4 at 0.2-0.1 s (errors at the 1e-12 floor); at 120° over 100 s 10.09, 9.97, 9.77 for
///   the same three ranges. This configuration is the one of those measured whose range is both
///   asymptotic and above round-off (errors 3e-8 to 5e-11); it is chosen, not typical.
#[test]
fn dop853_and_vern9_have_their_order_on_the_pendulum() {
    for (m, deg, duration, dt0) in [
        (Method::Dop853, 60.0, 10.0, 0.2),
        (Method::Vern9, 30.0, 100.0, 0.4),
    ] {
        let fixed = |dt: f64| MethodOptions {
            rtol: 1e300,
            max_step: dt,
            ..MethodOptions::default()
        };
        let dts: Vec<f64> = (0..=4)
            .map(|k| dt0 * 2f64.powf(-f64::from(k) / 4.0))
            .collect();
        let errs: Vec<f64> = dts
            .iter()
            .map(|&dt| max_error_from(deg, m, fixed(dt), dt, duration).0)
            .collect();
        let pts: Vec<(f64, f64)> = dts
            .iter()
            .zip(&errs)
            .map(|(d, e)| (d.ln(), e.ln()))
            .collect();
        let order = slope(&pts);
        let shown: Vec<String> = errs.iter().map(|e| format!("{e:.3e}")).collect();
        println!("{m} fixed step: dt {dts:.4?}, errors {shown:?}, fitted order {order:.3}");
        let expected = f64::from(m.info().order);
        assert!(
            (order - expected).abs() <= 0.2,
            "{m}: order {order:.3} ({errs:?})"
        );
        assert!(errs[4] > 1e-13, "{m}: above round-off: {errs:?}");
    }
}

/// The dense output between the steps: with steps of h fixed and samples in between (dt = h/7),
/// the largest error at the samples stays within 10× the error at the step ends (printed; for
/// DOP853 1.8× at h = 0.4 s, 2.6× at 0.2 s: the interpolant is not the weak link). dopri5's
/// fourth-order dense output is one order below its steps, so it is held to 100× at h = 0.1 s.
#[test]
fn dense_output_between_steps() {
    for (m, hs, factor) in [
        (Method::Dop853, [0.4, 0.2], 10.0),
        (Method::Vern9, [0.4, 0.2], 10.0),
        (Method::Dopri5, [0.1, 0.05], 100.0),
    ] {
        for h in hs {
            let opts = MethodOptions {
                rtol: 1e300,
                max_step: h,
                ..MethodOptions::default()
            };
            let (between, _) = max_error(m, opts, h / 7.0, 10.0);
            let (at_ends, _) = max_error(m, opts, h, 10.0);
            println!(
                "{m} h {h}: error at samples between steps {between:.3e}, at step ends {at_ends:.3e}"
            );
            assert!(
                between < factor * at_ends,
                "{m} h {h}: {between:e} vs {at_ends:e}"
            );
        }
    }
}

/// Error-controlled: the error follows rtol (tolerance proportionality, the slope of ln error
/// against ln rtol from 1e-4 to 1e-10 within 1 ± 0.25, printed), the counters add up (per
/// accepted step 12 evaluations for DOP853 and 16 for vern9, per rejected one 11 / 15, per dense
/// build 3 / 4, plus 1 at the start, bound the evaluations), and the adaptive steps are larger
/// than the sample interval.
#[test]
fn error_follows_rtol_and_counts_add_up() {
    for (m, per_step, per_dense) in [(Method::Dop853, 12, 3), (Method::Vern9, 16, 4)] {
        let mut pts = Vec::new();
        for k in 4..=10 {
            let rtol = 10f64.powi(-k);
            let opts = MethodOptions {
                rtol,
                ..MethodOptions::default()
            };
            let (err, it) = max_error(m, opts, 0.01, 20.0);
            let (acc, rej) = (it.accepted_steps(), it.rejected_steps());
            println!(
                "{m} rtol {rtol:.0e}: error {err:.3e} ({:.2} rtol), {acc} accepted, {rej} rejected, {} evals, last step {:.3e} s",
                err / rtol,
                it.evals(),
                it.last_step_size()
            );
            assert!(err < 100.0 * rtol, "{m} rtol {rtol:e}: error {err:e}");
            let base = 1 + per_step * acc + (per_step - 1) * rej;
            assert!(it.evals() <= base + per_dense * acc);
            assert!(it.evals() >= base);
            assert!(
                acc < 2000,
                "{m} stepped past the 0.01 s samples: {acc} steps for 2000 samples"
            );
            pts.push((rtol.ln(), err.ln()));
        }
        let slope = slope(&pts);
        println!("{m}: error ∝ rtol^{slope:.3}");
        assert!((slope - 1.0).abs() < 0.25, "{m}: slope {slope:.3}");
    }
}

/// The period measured from DOP853's and vern9's samples (upward zero crossings through the
/// scene's meter) matches the elliptic value to 1e-9 at rtol 1e-10 (printed).
#[test]
fn period_matches_the_elliptic_value() {
    for m in [Method::Dop853, Method::Vern9] {
        period_of(m);
    }
}

fn period_of(m: Method) {
    use physlab::scene::pendulum::period::PeriodMeter;
    let p = params(60.0);
    let sys = Pendulum::new(&p);
    let exact = ExactPendulum::new(&p).unwrap().period();
    let dt = 0.01;
    let opts = MethodOptions {
        rtol: 1e-10,
        ..MethodOptions::default()
    };
    let mut it = Integrator::new(m, &sys, &[p.theta0], &[0.0], dt, opts);
    let mut meter = PeriodMeter::new();
    meter.push(0.0, p.theta0, 0.0);
    for k in 1..=(10.5 * exact / dt) as u64 {
        it.step(&sys);
        meter.push(k as f64 * dt, it.position()[0], it.velocity()[0]);
    }
    let rel = meter.period().unwrap() / exact - 1.0;
    println!("{m} period error {rel:.2e}");
    assert!(rel.abs() < 1e-9, "{m}: {rel:e}");
}
