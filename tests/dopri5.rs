//! dopri5's single step against the Dormand–Prince method's known behaviour on x'' = -x.
//! Its convergence order on the pendulum is in `pendulum_numerics.rs`.
//!
//! On y' = A y with A = [[0, 1], [-1, 0]] (x'' = -x as a first-order system), one Runge–Kutta
//! step is y1 = R(hA) y0 with R the method's stability polynomial. Dormand–Prince 5(4) advances
//! with its fifth-order weights (the seventh stage's row), whose polynomial is
//! R(z) = 1 + z + z²/2 + z³/6 + z⁴/24 + z⁵/120 + z⁶/600 (Hairer & Wanner, Solving ODEs II,
//! IV.2; also b^T A^(k-1) 1 of the published tableau in exact rationals). With A² = -I, from
//! (x, v) = (1, 0):
//!
//!   x1 = 1 - h²/2 + h⁴/24 - h⁶/600,   v1 = -(h - h³/6 + h⁵/120),
//!
//! so x1 - cos h = -h⁶/3600 + O(h⁸) and v1 + sin h = -h⁷/5040 + O(h⁹): a fifth-order step.

use physlab::integrate::{ImplicitSolve, Integrator, Method, MethodOptions, SecondOrderSystem};

/// x'' = -x.
struct UnitOscillator;

impl SecondOrderSystem for UnitOscillator {
    fn dim(&self) -> usize {
        1
    }
    fn acceleration(&self, x: &[f64], _v: &[f64], a: &mut [f64]) {
        a[0] = -x[0];
    }
    fn implicit_euler_step(&self, _x: &mut [f64], _v: &mut [f64], _dt: f64) -> ImplicitSolve {
        unreachable!("dopri5 is explicit")
    }
}

/// One dopri5 step of `h` from (1, 0): (x, v, force evaluations).
fn one_step(h: f64, rtol: f64) -> (f64, f64, u64) {
    let options = MethodOptions {
        rtol,
        ..MethodOptions::default()
    };
    let mut it = Integrator::new(Method::Dopri5, &UnitOscillator, &[1.0], &[0.0], h, options);
    it.step(&UnitOscillator);
    (it.position()[0], it.velocity()[0], it.evals())
}

/// The Dormand–Prince amplification: x1, v1 above.
fn amplification(h: f64) -> (f64, f64) {
    (
        1.0 - h * h / 2.0 + h.powi(4) / 24.0 - h.powi(6) / 600.0,
        -(h - h.powi(3) / 6.0 + h.powi(5) / 120.0),
    )
}

/// With error control off (rtol = 1e6: the first substep, dt itself, is accepted), one step is
/// one Dormand–Prince substep (7 force evaluations: the first stage, then six with the last at
/// the new state) and equals R(hA) (1, 0) to 2e-16 (measured: at most 1 ulp, 1.1e-16) at
/// h = 0.1, 0.2, 0.4: the tableau's whole stability polynomial, down to its z⁶/600 term
/// (1.7e-9 at h = 0.1, 6.8e-6 at h = 0.4), is checked to round-off.
#[test]
fn one_substep_is_the_dormand_prince_amplification() {
    for h in [0.1, 0.2, 0.4] {
        let (x, v, evals) = one_step(h, 1e6);
        let (rx, rv) = amplification(h);
        assert_eq!(evals, 7, "h = {h}: {evals} evaluations, not one substep");
        assert!((x - rx).abs() <= 2e-16, "h = {h}: x {x} vs R {rx}");
        assert!((v - rv).abs() <= 2e-16, "h = {h}: v {v} vs R {rv}");
    }
}

/// With the default options (rtol = 1e-6) a step of h = 0.1 is one substep, and its error against
/// the exact (cos h, -sin h) is the fifth-order step's: x within 1% of -h⁶/3600 = -2.78e-10
/// (measured -2.7803e-10: the O(h⁸) term adds 0.09%) and v within 1% of -h⁷/5040 = -1.98e-11
/// (measured -1.98385e-11). This replaces the unit test's 1e-6 (which a second-order step, 1e-4
/// off here, fails, but a fourth-order one, ~1e-7, passes). The local error's order from h = 0.1,
/// 0.05, 0.025 (one substep each, control off): 6.00 ± 0.05 in x, 7.00 ± 0.05 in v.
#[test]
fn one_step_error_is_that_of_a_fifth_order_method() {
    let h = 0.1_f64;
    let (x, v, evals) = one_step(h, MethodOptions::default().rtol);
    assert_eq!(evals, 7, "default rtol at h = {h}: {evals} evaluations");
    let (ex, ev) = (x - h.cos(), v + h.sin());
    let (tx, tv) = (-h.powi(6) / 3600.0, -h.powi(7) / 5040.0);
    assert!(
        (ex / tx - 1.0).abs() <= 0.01,
        "x error {ex:e}, theory {tx:e}"
    );
    assert!(
        (ev / tv - 1.0).abs() <= 0.01,
        "v error {ev:e}, theory {tv:e}"
    );

    let errors: Vec<(f64, f64)> = [0.1_f64, 0.05, 0.025]
        .iter()
        .map(|&h| {
            let (x, v, _) = one_step(h, 1e6);
            ((x - h.cos()).abs(), (v + h.sin()).abs())
        })
        .collect();
    for w in errors.windows(2) {
        let (ox, ov) = ((w[0].0 / w[1].0).log2(), (w[0].1 / w[1].1).log2());
        assert!((ox - 6.0).abs() <= 0.05, "local order in x {ox:.3}");
        assert!((ov - 7.0).abs() <= 0.05, "local order in v {ov:.3}");
    }
}
