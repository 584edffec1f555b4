//! The exact pendulum up to the separatrix: the period and θ(t) of a release
//! from rest just below 180° against `tests/data/separatrix_reference.csv` (100-digit mpmath at
//! the exact radian doubles, two independent routes; `tests/data/separatrix_reference.py` wrote
//! it), and no panic or hang for any finite release angle, on both reference paths.

use physlab::integrate::Method;
use physlab::scene::harness::{NoObserver, run};
use physlab::scene::pendulum::PendulumParams;
use physlab::scene::pendulum::reference::{ExactPendulum, exact_period};
use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};

struct Row {
    deg: f64,
    rad: f64,
    period: f64,
    period_decimal: f64,
    t: f64,
    theta: f64,
    omega: f64,
}

fn rows() -> Vec<Row> {
    include_str!("data/separatrix_reference.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("theta0_deg"))
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            Row {
                deg: f[0],
                rad: f[1],
                period: f[3],
                period_decimal: f[4],
                t: f[5],
                theta: f[6],
                omega: f[7],
            }
        })
        .collect()
}

fn params(rad: f64) -> PendulumParams {
    PendulumParams {
        theta0: rad,
        ..PendulumParams::default()
    }
}

/// The radian double in the table is the one the CLI makes of the degrees (f64::to_radians).
#[test]
fn table_angles_are_what_the_cli_makes_of_the_degrees() {
    for r in rows() {
        assert_eq!(r.deg.to_radians(), r.rad, "{}", r.deg);
    }
}

/// T = 4K/ωn to 1e-12 relative for every angle in the table, 90° to 179.99999999999°
/// (k' down to 8.7e-14); the worst measured is printed.
#[test]
fn period_holds_to_1e_12_up_to_the_separatrix() {
    let mut worst: f64 = 0.0;
    for r in rows().iter().filter(|r| r.t == 0.0) {
        let p = params(r.rad);
        let exact = ExactPendulum::new(&p).unwrap();
        for (what, got) in [
            ("ExactPendulum", exact.period()),
            ("exact_period", exact_period(&p).unwrap()),
        ] {
            let rel = (got / r.period - 1.0).abs();
            worst = worst.max(rel);
            assert!(
                rel <= 1e-12,
                "{what} at {}°: {got} vs {}: {rel:.1e}",
                r.deg,
                r.period
            );
        }
    }
    println!("worst relative period error: {worst:.2e}");
    // The case: 179.9999° is 36.7559359 s (it was 36.7558266 s with 1 - m by cancellation).
    let t = exact_period(&params(179.9999_f64.to_radians())).unwrap();
    assert!((t - 36.755_935_9).abs() < 1e-7, "{t}");
}

/// What the rounding of the decimal degrees to a radian double costs: at 179.9999999° the period
/// of the radian double differs from the decimal angle's by about 2e-9 relative. The table's
/// references are for the radian double; `theta0_from_degrees` keeps what the rounding lost
/// (`typed_angles_get_the_period_of_the_angle_typed`).
#[test]
fn input_rounding_dominates_beyond_179_9999999() {
    let r = rows()
        .into_iter()
        .find(|r| r.deg == 179.999_999_9 && r.t == 0.0)
        .unwrap();
    let rounding = (r.period / r.period_decimal - 1.0).abs();
    assert!(rounding > 1e-10 && rounding < 1e-8, "{rounding:e}");
}

/// θ(t) and ω(t) at sample times over several periods: θ to 4e-12 rad (1.3e-12 of π), ω to
/// 1e-12 of its largest value 2 ωn (the bound). Measured: 9.6e-15 rad and 1.6e-15.
#[test]
fn motion_holds_to_1e_12_up_to_the_separatrix() {
    let (mut worst_theta, mut worst_omega): (f64, f64) = (0.0, 0.0);
    for r in rows() {
        let p = params(r.rad);
        let (theta, omega) = ExactPendulum::new(&p).unwrap().state(r.t);
        let scale = 2.0 * p.omega_n();
        let (et, ew) = ((theta - r.theta).abs(), (omega - r.omega).abs() / scale);
        worst_theta = worst_theta.max(et);
        worst_omega = worst_omega.max(ew);
        assert!(
            et <= 4e-12,
            "θ({}) at {}°: {theta} vs {}: {et:.1e}",
            r.t,
            r.deg,
            r.theta
        );
        assert!(
            ew <= 1e-12,
            "ω({}) at {}°: {omega} vs {}: {ew:.1e}",
            r.t,
            r.deg,
            r.omega
        );
    }
    println!("worst |Δθ| {worst_theta:.2e} rad, worst |Δω|/(2ωn) {worst_omega:.2e}");
    // The accuracy the studies state for the exact solution.
    assert!(
        worst_theta <= physlab::scene::pendulum::reference::EXACT_THETA_ACCURACY,
        "{worst_theta:e}"
    );
}

/// Beyond the table: every double below π is finite, the period grows monotonically, θ(0) = θ0.
#[test]
fn finite_and_monotone_to_the_last_double_below_pi() {
    let mut theta0 = std::f64::consts::PI;
    let mut last = f64::INFINITY;
    for _ in 0..60 {
        theta0 = f64::from_bits(theta0.to_bits() - 1);
        let p = params(theta0);
        let e = ExactPendulum::new(&p).unwrap();
        let t = e.period();
        assert!(t.is_finite() && t < last, "{theta0}: {t}");
        assert_eq!(exact_period(&p).unwrap(), t);
        assert!(
            (e.state(0.0).0 - theta0).abs() <= 4.0 * f64::EPSILON,
            "{theta0}"
        );
        for s in [0.1, 1.0, 7.0, 100.0] {
            let (th, w) = e.state(s);
            assert!(
                th.is_finite() && w.is_finite() && th.abs() <= theta0,
                "{theta0} at {s}"
            );
        }
        last = t;
        theta0 = f64::from_bits(theta0.to_bits() - (1 << 20));
    }
}

/// A short run of the scene (both reference paths, the exact period, the summary's numbers) for
/// release angles the CLI accepts, near and beyond the top: no panic, no hang, finite reference.
#[test]
fn scene_runs_at_any_release_angle() {
    for deg in [
        179.999_999,
        179.999_999_999_999_97,
        180.0,
        -180.0,
        360.0,
        -179.999_999_99,
        540.0,
        1e6,
        -1e6,
        1e300,
    ] {
        let config = PendulumConfig {
            params: params(f64::to_radians(deg)),
            dt: 0.01,
            duration: 2.0,
            fps: 1.0,
            plot_every: 1,
            methods: vec![Method::Rk4, Method::Dopri5],
            ..PendulumConfig::default()
        };
        let started = std::time::Instant::now();
        let mut scene = PendulumScene::new(config);
        let description = scene.reference_description();
        let out = run(&mut scene, &mut NoObserver).unwrap();
        assert!(
            started.elapsed().as_secs_f64() < 30.0,
            "{deg}° took too long"
        );
        assert!(!description.contains("NaN"), "{deg}°: {description}");
        if let Some(t) = scene.exact_period {
            assert!(t.is_finite() && t > 0.0, "{deg}°: {t}");
        }
        assert!(!out.lanes.is_empty(), "{deg}°");
    }
}

/// The period of a release from rest at an angle typed in degrees is that of the very double
/// typed (`tests/data/typed_angle_period.csv`, 60-digit mpmath from the typed double, wrapped as
/// physlab wraps it), 90° to 179.999999999999°, negative, past 180° and several turns out, to
/// 1e-13 relative (measured 4.4e-16); the radian double alone is off by up to 1.4e-4 there.
#[test]
fn typed_angles_get_the_period_of_the_angle_typed() {
    use physlab::scene::pendulum::theta0_from_degrees;
    let rows: Vec<(String, f64)> = include_str!("data/typed_angle_period.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("theta0"))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[2].parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 24);
    let (mut worst, mut worst_radians): (f64, f64) = (0.0, 0.0);
    for (typed, period) in rows {
        let (theta0, theta0_low) = theta0_from_degrees(typed.parse().unwrap());
        let p = PendulumParams {
            theta0,
            theta0_low,
            ..PendulumParams::default()
        };
        for (what, got) in [
            ("ExactPendulum", ExactPendulum::new(&p).unwrap().period()),
            ("exact_period", exact_period(&p).unwrap()),
        ] {
            let rel = (got / period - 1.0).abs();
            worst = worst.max(rel);
            assert!(
                rel <= 1e-13,
                "{what} at {typed}°: {got} vs {period}: {rel:.1e}"
            );
        }
        // Without the low part: what rounding to radians alone costs (the test can fail).
        let rounded = ExactPendulum::new(&PendulumParams {
            theta0_low: 0.0,
            ..p
        })
        .unwrap()
        .period();
        worst_radians = worst_radians.max((rounded / period - 1.0).abs());
    }
    println!("worst {worst:.1e}; from the radian double alone {worst_radians:.1e}");
    assert!(worst_radians > 1e-9, "{worst_radians:e}");
}
