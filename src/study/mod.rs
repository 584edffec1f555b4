//! `physlab study`: the speed/accuracy trade and the stability limits, measured against theory.
//!
//! Every measurement steps a [`SecondOrderSystem`] with the registry's [`Integrator`] and compares
//! positions at common sample times (multiples of the coarsest step, so not only turning points)
//! with a reference: the exact elliptic solution for a pendulum released from rest, otherwise
//! RK4 at a step 8× finer than the finest tested, whose own error is estimated by Richardson
//! extrapolation against a run at twice its step.
//!
//! A stop request ([`crate::interrupt::requested`], Ctrl-C or SIGTERM) is looked at after every
//! [`STOP_CHECK_STEPS`] coordinates stepped in every run, the reference's and every bisection
//! trial's included: [`sweep`] and [`stability`] then return the rows and limits complete so far
//! (a run cut short is dropped, never shown), and the caller says the study was interrupted.

mod answer;
pub mod drift;
mod grid;
pub mod hair;
mod limits;
mod orders;
mod sweep;

pub use answer::{
    Answer, DEFAULT_TARGETS, RESOLVES, answers, floor_text, refuse_unresolved, scene_command,
    settings, validate_targets,
};
pub use limits::{Limit, stability, stability_with, validate_stability_steps};
pub use orders::{
    Order, Proportionality, STALL_BELOW, cheapest, error_floor, methods_of, orders,
    proportionality, stalled,
};
pub use sweep::{
    Row, SAMPLE_EVERY, Sweep, damped_companion, planned_runs, planned_steps, planned_work,
    reference, sweep, sweep_against, sweep_with,
};

use crate::integrate::{Integrator, Method, SecondOrderSystem};
use crate::scene::pendulum::PendulumParams;
use crate::scene::rope::RopeParams;

/// One scene set up for a study: its system, start and the rate that sets its stability.
pub enum Problem {
    Pendulum(PendulumParams),
    Rope(RopeParams),
}

impl Problem {
    pub fn name(&self) -> &'static str {
        match self {
            Problem::Pendulum(_) => "pendulum",
            Problem::Rope(_) => "rope",
        }
    }

    /// Whether its forces depend on the velocity (the rope's spring damping and air drag), which
    /// lowers some methods' order (see the registry).
    pub fn velocity_dependent(&self) -> bool {
        match self {
            Problem::Pendulum(_) => false,
            Problem::Rope(p) => p.velocity_dependent(),
        }
    }

    /// Whether `m` accepts its forces: on velocity-dependent ones (a damped rope) not the methods
    /// that need forces of position alone (the Nyström methods), which the scene refuses.
    pub fn accepts(&self, m: Method) -> bool {
        !self.velocity_dependent() || m.info().accepts_velocity_dependent()
    }

    /// The methods that accept its forces.
    pub fn methods(&self) -> Vec<Method> {
        (Method::ALL.into_iter())
            .filter(|&m| self.accepts(m))
            .collect()
    }

    /// The angular frequency stability theory is stated in: sqrt(g/L) for the pendulum (its
    /// small-angle frequency), the pinned-free chain's highest mode for the rope.
    pub fn omega(&self) -> f64 {
        match self {
            Problem::Pendulum(p) => p.omega_n(),
            Problem::Rope(p) => p.omega_max_pinned_free(),
        }
    }

    fn start(&self) -> (Vec<f64>, Vec<f64>) {
        match self {
            Problem::Pendulum(p) => (vec![p.theta0], vec![p.omega0]),
            Problem::Rope(p) => {
                let x = p.initial_positions();
                let v = vec![0.0; x.len()];
                (x, v)
            }
        }
    }
}

/// The coarsest step [s] and the duration [s] a study uses unless told otherwise: for the
/// pendulum 0.02 s over 10 s, for the rope 0.002 s over 1 s.
pub fn default_schedule(scene: &Problem) -> (f64, f64) {
    match scene {
        Problem::Pendulum(_) => (0.02, 10.0),
        Problem::Rope(_) => (0.002, 1.0),
    }
}

/// Spring stiffness of the rope the convergence and work-precision studies use by default
/// [N/m]: softer than the scene's, so that every explicit method converges over the sweep.
pub const STUDY_ROPE_STIFFNESS: f64 = 100.0;

/// The rope the studies use by default: undamped, so that the theory's orders apply, and (for
/// convergence and cost, not stability) as soft as [`STUDY_ROPE_STIFFNESS`].
pub fn study_rope(stability: bool) -> RopeParams {
    let scene = RopeParams::default();
    RopeParams {
        stiffness: if stability {
            scene.stiffness
        } else {
            STUDY_ROPE_STIFFNESS
        },
        spring_damping: 0.0,
        air_drag: 0.0,
        ..scene
    }
}

/// Step sizes a sweep tries by default.
pub const DEFAULT_LEVELS: u32 = 6;
/// Timed repeats per run by default (the median is kept).
pub const DEFAULT_REPEATS: u32 = 5;
/// Steps a stability trial must stay bounded for by default.
pub const DEFAULT_STABILITY_STEPS: u64 = 2000;

/// The adaptive methods' tolerances in a work-precision sweep by default: 1e-3 to 1e-13.
pub fn default_rtols() -> Vec<f64> {
    (3..=13).map(|k| 10f64.powi(-k)).collect()
}

/// The adaptive methods' tolerances in a work-precision study by default: half-decades from 1e-2
/// to 1e-14 (the peer benchmark's grid), to two digits.
pub fn work_precision_rtols() -> Vec<f64> {
    let rounded = |t: f64| format!("{t:.1e}").parse().unwrap_or(t);
    (4..=28)
        .map(|e| rounded(10f64.powf(-f64::from(e) / 2.0)))
        .collect()
}

/// Coordinates stepped between looks at the stop flag: an atomic load, free at this stride, and
/// well under a millisecond of stepping (4096 steps of the pendulum; one step of a rope of more
/// than 1365 nodes, whose single step may take milliseconds).
pub const STOP_CHECK_STEPS: u64 = 4096;

/// Steps between looks at the stop flag for a state of `coordinates` numbers: a fixed amount of
/// work between looks, however large the system, so that a stop is seen within milliseconds.
fn stop_stride(coordinates: usize) -> u64 {
    (STOP_CHECK_STEPS / coordinates.max(1) as u64).max(1)
}

/// The largest |a − b| over two states' coordinates (`f64::max` passes over a NaN).
fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Takes `n` steps, looking at the stop flag every [`stop_stride`]; false when stopped.
fn steps<S: SecondOrderSystem>(it: &mut Integrator, sys: &S, n: u64) -> bool {
    let stride = stop_stride(it.position().len());
    let mut left = n;
    while left > 0 {
        let chunk = left.min(stride);
        for _ in 0..chunk {
            it.step(sys);
        }
        left -= chunk;
        if crate::interrupt::requested() {
            return false;
        }
    }
    true
}
