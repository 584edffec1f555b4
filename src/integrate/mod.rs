//! Integrators for second-order ODEs `x'' = a(x, v)`, knowing nothing of scenes.
//!
//! A scene implements [`SecondOrderSystem`] over flat `f64` coordinates (the pendulum has one,
//! a rope of N nodes has 3N) and an [`Integrator`] advances it with one of the registry's
//! [`Method`]s. Each family of methods is one module and each method owns its scratch; the
//! [`Integrator`] dispatches statically (one `match` on an enum per step, no `dyn`).

// The steppers update several arrays in lockstep (x, v, stages, scratch); one index over all of
// them reads like the formulas, where zips of four or five slices would not.
#![allow(clippy::needless_range_loop)]

mod across;
mod adaptive;
mod composition;
mod dense;
mod dop853;
mod explicit;
mod implicit;
mod registry;
mod rkn;
// The embedded weights (`#[cfg(test)]`) are read by tests/order_conditions only.
#[cfg_attr(test, allow(dead_code))]
mod rkn_tables;
mod runge_kutta;
mod semi_implicit;
mod stepper;
mod verlet;
mod verner;

pub use composition::{
    YOSHIDA4_STABILITY_LIMIT, drift as composition_drift, weights as composition_weights,
    yoshida_weights,
};
pub use implicit::scalar_backward_euler;
pub use registry::{
    AdaptiveEvals, EvalsPerStep, Family, Method, MethodInfo, Stability, UnknownMethod,
};
pub use stepper::{Integrator, whole_steps};

/// What one implicit solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitSolve {
    /// Force evaluations spent, each the work of one [`SecondOrderSystem::acceleration`] call:
    /// one per Newton iteration, plus one for an explicit predictor where the solver uses one.
    pub evals: u32,
    /// Jacobian evaluations spent: one per Newton iteration.
    pub jacobian_evals: u32,
    /// Whether the solve met its tolerance.
    pub converged: bool,
    /// Size of the last Newton update, in the unknown's units.
    pub last_update: f64,
}

/// A second-order ODE `x'' = a(x, v)` over flat coordinates.
pub trait SecondOrderSystem {
    /// Number of scalar coordinates.
    fn dim(&self) -> usize;
    /// Writes `a(x, v)` into `a`.
    fn acceleration(&self, x: &[f64], v: &[f64], a: &mut [f64]);
    /// One backward-Euler step in place: solve `x1 = x0 + dt v1`, `v1 = v0 + dt a(x1, v1)`.
    /// Reports the force and Jacobian evaluations it made, which the integrator counts.
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve;
    /// How many trailing coordinates are first-order accumulators, q' = a(x, v), carried as
    /// velocities whose positions are unused (the rope's dissipated work): every method
    /// integrates them as it integrates v, except that Verlet's damping factor, a change of the
    /// method's dynamics, does not apply to them.
    fn first_order_tail(&self) -> usize {
        0
    }
}

/// Per-method tuning that is not part of the scene.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MethodOptions {
    /// Verlet's damping factor d in `x1 = x0 + (1-d)(x0 - x_-1) + a dt²`; 0 = undamped.
    pub verlet_damping: f64,
    /// The adaptive methods' relative tolerance per step (the absolute one is the same, in the
    /// state's units).
    pub rtol: f64,
    /// The adaptive methods' largest step [s] (default ∞). With a huge rtol and `max_step` = dt it steps at
    /// exactly dt, which is how its fixed-step order is measured. Not a scene parameter.
    #[serde(skip)]
    pub max_step: f64,
    /// Compensated (Kahan) summation of the composition methods' position and velocity
    /// updates: each loses about eps |h v| instead of eps |x| to rounding (on the pendulum at
    /// small steps, two orders of magnitude less energy error; both grow like √n). Off by default,
    /// which keeps every run bit for bit as it was; written to a scene file only when on.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub compensated: bool,
    /// The fixed-step methods' own step [s], when it is not the sample interval dt: they step
    /// at `step` and report every dt from a quintic Hermite interpolant through x, v and a at
    /// both ends of the step that holds the sample (`across.rs`: samples of order min(p, 6));
    /// a step that divides dt ends at every sample, no interpolant. `None`: they step at dt, every step a sample. The adaptive methods ignore it (error
    /// control chooses their steps; `max_step` caps them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            verlet_damping: 0.0,
            rtol: 1e-6,
            max_step: f64::INFINITY,
            compensated: false,
            step: None,
        }
    }
}

/// What a run has spent so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Force evaluations (including Verlet's start).
    pub evals: u64,
    /// Implicit steps whose Newton solve did not meet its tolerance.
    pub failed_solves: u64,
    /// A method's own steps (accepted, rejected) where they are not the scene's steps of dt:
    /// an adaptive method's, which do not end at the samples, or a fixed-step method's stepping
    /// across them (`MethodOptions::step`; none rejected). `None` otherwise.
    pub own_steps: Option<(u64, u64)>,
}

/// The state a stepper advances: positions, velocities and what it cost.
pub(crate) struct State<'a> {
    pub x: &'a mut [f64],
    pub v: &'a mut [f64],
    pub counts: &'a mut Counts,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// x'' = -x: the damped oscillator without damping.
    const UNIT_OSCILLATOR: DampedOscillator = DampedOscillator { c: 0.0 };

    /// The damped oscillator x'' = -x - c x' (c < 2), with a closed-form implicit step.
    pub struct DampedOscillator {
        pub c: f64,
    }
    impl DampedOscillator {
        /// The exact (x, v) at time t from (1, 0).
        pub fn exact(&self, t: f64) -> (f64, f64) {
            let c = self.c;
            let wd = (1.0 - c * c / 4.0).sqrt();
            let e = (-c * t / 2.0).exp();
            (
                e * ((wd * t).cos() + c / (2.0 * wd) * (wd * t).sin()),
                -e / wd * (wd * t).sin(),
            )
        }
    }
    impl SecondOrderSystem for DampedOscillator {
        fn dim(&self) -> usize {
            1
        }
        fn acceleration(&self, x: &[f64], v: &[f64], a: &mut [f64]) {
            a[0] = -x[0] - self.c * v[0];
        }
        fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
            let v1 = (v[0] - dt * x[0]) / (1.0 + dt * self.c + dt * dt);
            x[0] += dt * v1;
            v[0] = v1;
            ImplicitSolve {
                evals: 1,
                jacobian_evals: 1,
                converged: true,
                last_update: 0.0,
            }
        }
    }

    /// Largest |x - x_exact| and |v - v_exact| over t in (0, 10] from (1, 0).
    fn damped_errors(m: Method, c: f64, dt: f64) -> (f64, f64) {
        let sys = DampedOscillator { c };
        let mut it = Integrator::new(m, &sys, &[1.0], &[0.0], dt, MethodOptions::default());
        let (mut ex, mut ev) = (0.0f64, 0.0f64);
        for k in 1..=(10.0 / dt).round() as u32 {
            it.step(&sys);
            let (x, v) = sys.exact(f64::from(k) * dt);
            ex = ex.max((it.position()[0] - x).abs());
            ev = ev.max((it.velocity()[0] - v).abs());
        }
        (ex, ev)
    }

    /// The registry's orders, measured against the exact solution of the oscillator: undamped
    /// (a(x): `order`, positions) and damped with c = 0.5 (a(x, v): `order_velocity_dependent`,
    /// positions and velocities), from the largest error over 10 s as dt halves, within ±0.15.
    /// Damped, the old Verlet (a(x1, ·) at the velocity over the step) and a Yoshida whose kicks
    /// take the pre-kick velocity both measure about 1.0 here (0.98 to 1.01).
    #[test]
    fn measured_orders_on_the_damped_and_undamped_oscillator_match_the_registry() {
        for m in Method::ALL {
            if m.info().stability == Stability::Adaptive {
                continue;
            }
            for (c, order) in [
                (0.0, m.info().order),
                (0.5, m.info().order_velocity_dependent),
            ] {
                if !m.info().accepts_velocity_dependent() && c > 0.0 {
                    continue;
                }
                // In the asymptotic range and above round-off (errors 3e-3 to 1e-7 here; orders
                // 8 and 10 at 7e-9 and 4e-10: at dt = 0.1 kahan-li8 is at 1e-13 and measures
                // 5.6, sofroniou10 at dt = 0.4 measures 7.6, both against round-off).
                let dt = match order {
                    1 => 0.01,
                    2 => 0.02,
                    8 => 0.4,
                    10 => 0.8,
                    _ => 0.08,
                };
                let (x1, v1) = damped_errors(m, c, dt);
                let (x2, v2) = damped_errors(m, c, dt / 2.0);
                let measured_x = (x1 / x2).log2();
                assert!(
                    (measured_x - f64::from(order)).abs() <= 0.15,
                    "{m}, c = {c}: position order {measured_x:.3} (errors {x1:.3e}, {x2:.3e}), \
                     registry says {order}"
                );
                // Undamped, semi-implicit Euler's velocity is a half step more accurate than
                // its position; the velocity order is checked damped only.
                if c > 0.0 {
                    let measured_v = (v1 / v2).log2();
                    assert!(
                        (measured_v - f64::from(order)).abs() <= 0.15,
                        "{m}, c = {c}: velocity order {measured_v:.3} (errors {v1:.3e}, {v2:.3e}), \
                         registry says {order}"
                    );
                }
            }
        }
    }

    /// Largest |x - x_exact| and |v - v_exact| at the samples t = 0.1, 0.2, ..., 10 s of a run on
    /// x'' = -x from (1, 0) whose method steps at its own `h` across them, and the run.
    fn errors_across(m: Method, h: f64) -> (f64, f64, Integrator) {
        let sys = &UNIT_OSCILLATOR;
        let options = MethodOptions {
            step: Some(h),
            ..MethodOptions::default()
        };
        let mut it = Integrator::new(m, sys, &[1.0], &[0.0], 0.1, options);
        let (mut ex, mut ev) = (0.0f64, 0.0f64);
        for k in 1..=100 {
            it.step(sys);
            let t = f64::from(k) * 0.1;
            ex = ex.max((it.position()[0] - t.cos()).abs());
            ev = ev.max((it.velocity()[0] + t.sin()).abs());
        }
        (ex, ev, it)
    }

    /// A fixed-step method stepping across the samples (`MethodOptions::step`): the samples
    /// converge at order min(p, 6) in x and min(p, 5) in v as h halves (the method's order p up
    /// to the quintic interpolant's own), within ±0.15, against the exact solution at every
    /// sample; the steps are h, not dt, and cost the method's evaluations plus one (rkn4: none,
    /// its first stage is the one the interpolant needs).
    #[test]
    fn samples_between_steps_converge_at_the_methods_order_up_to_six() {
        for m in Method::ALL {
            let info = m.info();
            let evals = match info.evals_per_step {
                EvalsPerStep::Fixed(e) => Some(e),
                EvalsPerStep::NewtonIterations => None,
                EvalsPerStep::Adaptive(_) => continue,
            };
            // Steps that do not divide the sample interval, in each order's asymptotic range
            // above round-off; for orders 8 and 10 the interpolant's h⁶/46 080 dominates.
            let h = match info.order {
                1 => 0.0123,
                2 => 0.0237,
                4 => 0.137,
                _ => 0.37,
            };
            let (x1, v1, it) = errors_across(m, h);
            let (x2, v2, _) = errors_across(m, h / 2.0);
            let (px, pv) = ((x1 / x2).log2(), (v1 / v2).log2());
            // yoshida6's own error in v, O(h⁶), is above the interpolant's O(h⁵) at every h
            // above round-off (hundreds of times at h = 0.37), so it measures 6 there.
            let (ex, ev) = match info.order {
                6 => (6, 6),
                p => (p.min(6), p.min(5)),
            };
            assert!(
                (px - f64::from(ex)).abs() <= 0.15 && (pv - f64::from(ev)).abs() <= 0.15,
                "{m}: orders {px:.3} in x, {pv:.3} in v (errors {x1:.2e} {x2:.2e}, {v1:.2e} \
                 {v2:.2e}); expected {ex} and {ev}"
            );
            let steps = (10.0 / h).ceil() as u64;
            assert_eq!(it.accepted_steps(), steps, "{m}");
            assert_eq!(it.last_step_size(), h, "{m}");
            if let Some(evals) = evals {
                let start = u64::from(m == Method::Verlet) + 1;
                let per_step = u64::from(evals) + u64::from(m != Method::Rkn4);
                assert_eq!(it.evals(), start + steps * per_step, "{m}");
            }
        }
    }

    /// One step of each method on x'' = -x from (1, 0) against the method's known amplification
    /// (the Taylor series of cos h, -sin h truncated at the method's order).
    #[test]
    fn one_step_matches_the_methods_linear_amplification() {
        let h = 0.1_f64;
        // (x, v, tolerance): exact amplifications, or for the higher-order methods the exact
        // solution (cos h, -sin h) within their local error.
        let expected = |m: Method| -> (f64, f64, f64) {
            match m {
                Method::ExplicitEuler => (1.0, -h, 1e-14),
                Method::SemiImplicitEuler => (1.0 - h * h, -h, 1e-14),
                Method::ImplicitEuler => (1.0 / (1.0 + h * h), -h / (1.0 + h * h), 1e-14),
                Method::Midpoint | Method::Trapezoid => (1.0 - h * h / 2.0, -h, 1e-14),
                Method::Rk4 => (
                    1.0 - h * h / 2.0 + h.powi(4) / 24.0,
                    -h + h.powi(3) / 6.0,
                    1e-14,
                ),
                // Verlet from rest: x1 = 1 - h²/2, v1 = (x1 - x0)/h + a1 h/2.
                Method::Verlet => (
                    1.0 - h * h / 2.0,
                    -h / 2.0 - (1.0 - h * h / 2.0) * h / 2.0,
                    1e-14,
                ),
                // Fourth order: local error O(h⁵); the triple jump's constants are large (about
                // 0.007 h⁵ in x and 0.1 h⁵ in v here, as a separate evaluation of the composition gives).
                Method::Yoshida4 => (h.cos(), -h.sin(), 0.2 * h.powi(5)),
                // Orders 6 to 10: local errors far below 1e-9 at h = 0.1.
                Method::Yoshida6 | Method::KahanLi8 | Method::Sofroniou10 => {
                    (h.cos(), -h.sin(), 1e-9)
                }
                // One fifth-order substep: local error h⁶/3600 in x, h⁷/5040 in v
                // (tests/integrators.rs checks those constants to 1%).
                Method::Dopri5 => (h.cos(), -h.sin(), 1.01 * h.powi(6) / 3600.0),
                // Error-controlled at rtol 1e-6, sampled by its dense output.
                Method::Dop853
                | Method::Vern9
                | Method::Dprkn6
                | Method::Dprkn8
                | Method::Dprkn12 => (h.cos(), -h.sin(), 1e-6),
                // Nyström's order 4 on x'' = -x from rest: x = 1 - h²/2 + h⁴/24,
                // v = -h + h³/6 - h⁵/96.
                Method::Rkn4 => (
                    1.0 - h * h / 2.0 + h.powi(4) / 24.0,
                    -h + h.powi(3) / 6.0 - h.powi(5) / 96.0,
                    1e-15,
                ),
            }
        };
        for m in Method::ALL {
            let mut it = Integrator::new(
                m,
                &UNIT_OSCILLATOR,
                &[1.0],
                &[0.0],
                h,
                MethodOptions::default(),
            );
            it.step(&UNIT_OSCILLATOR);
            let (x, v, tol) = expected(m);
            assert!(
                (it.position()[0] - x).abs() < tol,
                "{m}: x {} vs {x}",
                it.position()[0]
            );
            assert!(
                (it.velocity()[0] - v).abs() < tol,
                "{m}: v {} vs {v}",
                it.velocity()[0]
            );
        }
    }
}
