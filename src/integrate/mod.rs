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
mod stepper;
mod verlet;
mod verner;

pub use composition::{
    YOSHIDA4_STABILITY_LIMIT, drift as composition_drift, weights as composition_weights,
    yoshida_weights,
};
pub use implicit::scalar_backward_euler;
pub(crate) use registry::serde_as_text;
pub use registry::{AdaptiveEvals, EvalsPerStep, Method, MethodInfo, Stability, UnknownMethod};
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
