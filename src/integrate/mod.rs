//! Integrators for second-order ODEs `x'' = a(x, v)`, knowing nothing of scenes.
//!
//! A scene implements [`SecondOrderSystem`] over flat `f64` coordinates (the pendulum has one,
//! a rope of N nodes has 3N) and an [`Integrator`] advances it with one of the registry's
//! [`Method`]s. Each family of methods is one module and each method owns its scratch; the
//! [`Integrator`] dispatches statically (one `match` on an enum per step, no `dyn`).

mod adaptive;
mod composition;
mod explicit;
mod implicit;
mod registry;
mod runge_kutta;
mod semi_implicit;
mod verlet;

pub use composition::{YOSHIDA4_STABILITY_LIMIT, yoshida_weights};
pub use registry::{EvalsPerStep, Family, Method, MethodInfo, Stability, UnknownMethod};

/// What one implicit solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitSolve {
    /// Force evaluations spent (Newton iterations for the pendulum).
    pub evals: u32,
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
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve;
}

/// Per-method tuning that is not part of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodOptions {
    /// Verlet's damping factor d in `x1 = x0 + (1-d)(x0 - x_-1) + a dt²`; 0 = undamped.
    pub verlet_damping: f64,
    /// dopri5's relative tolerance per substep (the absolute one is the same, in the state's units).
    pub rtol: f64,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            verlet_damping: 0.0,
            rtol: 1e-6,
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
}

/// The state a stepper advances: positions, velocities and what it cost.
pub(crate) struct State<'a> {
    pub x: &'a mut [f64],
    pub v: &'a mut [f64],
    pub counts: &'a mut Counts,
}

/// One method's stepper and its scratch.
#[derive(Clone, Debug)]
enum Stepper {
    ExplicitEuler(explicit::ExplicitEuler),
    SemiImplicitEuler(semi_implicit::SemiImplicitEuler),
    ImplicitEuler,
    Midpoint(explicit::Midpoint),
    Trapezoid(explicit::Heun),
    Rk4(runge_kutta::Rk4),
    Verlet(verlet::Verlet),
    Yoshida4(composition::Yoshida4),
    Dopri5(adaptive::Dopri5),
}

/// Advances one [`SecondOrderSystem`] with one [`Method`]. All scratch space is allocated
/// once in [`Integrator::new`], so stepping never allocates.
#[derive(Clone, Debug)]
pub struct Integrator {
    method: Method,
    dt: f64,
    x: Vec<f64>,
    v: Vec<f64>,
    counts: Counts,
    stepper: Stepper,
}

impl Integrator {
    pub fn new<S: SecondOrderSystem>(
        method: Method,
        system: &S,
        x0: &[f64],
        v0: &[f64],
        dt: f64,
        options: MethodOptions,
    ) -> Self {
        let n = system.dim();
        assert_eq!(x0.len(), n, "x0 has the system's dimension");
        assert_eq!(v0.len(), n, "v0 has the system's dimension");
        let mut counts = Counts::default();
        let stepper = match method {
            Method::ExplicitEuler => Stepper::ExplicitEuler(explicit::ExplicitEuler::new(n)),
            Method::SemiImplicitEuler => {
                Stepper::SemiImplicitEuler(semi_implicit::SemiImplicitEuler::new(n))
            }
            Method::ImplicitEuler => Stepper::ImplicitEuler,
            Method::Midpoint => Stepper::Midpoint(explicit::Midpoint::new(n)),
            Method::Trapezoid => Stepper::Trapezoid(explicit::Heun::new(n)),
            Method::Rk4 => Stepper::Rk4(runge_kutta::Rk4::new(n)),
            Method::Verlet => Stepper::Verlet(verlet::Verlet::new(
                system,
                x0,
                v0,
                dt,
                options.verlet_damping,
                &mut counts,
            )),
            Method::Yoshida4 => Stepper::Yoshida4(composition::Yoshida4::new(n)),
            Method::Dopri5 => Stepper::Dopri5(adaptive::Dopri5::new(n, dt, options.rtol)),
        };
        Integrator {
            method,
            dt,
            x: x0.to_vec(),
            v: v0.to_vec(),
            counts,
            stepper,
        }
    }

    pub fn method(&self) -> Method {
        self.method
    }
    pub fn dt(&self) -> f64 {
        self.dt
    }
    pub fn position(&self) -> &[f64] {
        &self.x
    }
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }
    /// Force evaluations spent so far (including Verlet's start).
    pub fn evals(&self) -> u64 {
        self.counts.evals
    }
    /// Implicit steps whose solve did not converge to tolerance.
    pub fn failed_solves(&self) -> u64 {
        self.counts.failed_solves
    }

    /// Advances by one step of `dt`. Returns the implicit solve's report for implicit methods.
    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S) -> Option<ImplicitSolve> {
        let h = self.dt;
        let s = State {
            x: &mut self.x,
            v: &mut self.v,
            counts: &mut self.counts,
        };
        match &mut self.stepper {
            Stepper::ExplicitEuler(m) => m.step(sys, s, h),
            Stepper::SemiImplicitEuler(m) => m.step(sys, s, h),
            Stepper::ImplicitEuler => return Some(implicit::step(sys, s, h)),
            Stepper::Midpoint(m) => m.step(sys, s, h),
            Stepper::Trapezoid(m) => m.step(sys, s, h),
            Stepper::Rk4(m) => m.step(sys, s, h),
            Stepper::Verlet(m) => m.step(sys, s, h),
            Stepper::Yoshida4(m) => m.step(sys, s, h),
            Stepper::Dopri5(m) => m.step(sys, s, h),
        }
        None
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// x'' = -x, with a closed-form implicit step, for unit tests of the steppers.
    pub struct UnitOscillator;
    impl SecondOrderSystem for UnitOscillator {
        fn dim(&self) -> usize {
            1
        }
        fn acceleration(&self, x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = -x[0];
        }
        fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
            let v1 = (v[0] - dt * x[0]) / (1.0 + dt * dt);
            x[0] += dt * v1;
            v[0] = v1;
            ImplicitSolve {
                evals: 1,
                converged: true,
                last_update: 0.0,
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
                // Error-controlled to rtol = 1e-6 per substep.
                Method::Dopri5 => (h.cos(), -h.sin(), 1e-6),
            }
        };
        for m in Method::ALL {
            let mut it = Integrator::new(
                m,
                &UnitOscillator,
                &[1.0],
                &[0.0],
                h,
                MethodOptions::default(),
            );
            it.step(&UnitOscillator);
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
