//! Implicit (backward) Euler. The nonlinear solve is the system's own
//! ([`SecondOrderSystem::implicit_euler_step`]): a scalar Newton iteration for the pendulum
//! ([`scalar_backward_euler`]), a block-tridiagonal Newton step for the rope. Here only its
//! cost is counted, as the solve reports it.

use super::{ImplicitSolve, SecondOrderSystem, State};

#[inline]
pub fn step<S: SecondOrderSystem>(sys: &S, s: State, h: f64) -> ImplicitSolve {
    let solve = sys.implicit_euler_step(s.x, s.v, h);
    s.counts.evals += u64::from(solve.evals);
    if !solve.converged {
        s.counts.failed_solves += 1;
    }
    solve
}

/// Backward Euler for one coordinate under a force of position only, x'' = a(x): with
/// x1 = x0 + dt v1, solves F(v1) = v1 - v0 - dt a(x0 + dt v1) = 0 by Newton
/// (F' = 1 - dt² a'(x1)) from the explicit-Euler guess v1 = v0 + dt a(x0). Stops when
/// |Δv1| ≤ `tol` (1 + |v1|) (converged) or after `max_iterations` iterations, or at a
/// non-finite update (not converged). Returns (x1, v1) and what the solve did.
///
/// The force enters only through the two closures, in the form one step of it takes:
/// `kick(x)` = dt a(x) (one force evaluation) and `kick_and_slope(x)` = (dt a(x), dt² a'(x))
/// (one force and one Jacobian evaluation; the slope is ∂/∂v1 of dt a(x0 + dt v1)). Callers
/// scale by dt themselves, so their rounding is theirs. The counts returned are the calls made:
/// `evals` = 1 (the guess) + iterations, `jacobian_evals` = iterations.
#[inline]
pub fn scalar_backward_euler(
    x0: f64,
    v0: f64,
    dt: f64,
    tol: f64,
    max_iterations: u32,
    mut kick: impl FnMut(f64) -> f64,
    mut kick_and_slope: impl FnMut(f64) -> (f64, f64),
) -> (f64, f64, ImplicitSolve) {
    let mut v = v0 + kick(x0);
    let mut iterations = 0;
    let mut converged = false;
    let mut update = f64::INFINITY;
    while iterations < max_iterations {
        let (k, slope) = kick_and_slope(x0 + dt * v);
        iterations += 1;
        let f = v - v0 - k;
        let df = 1.0 - slope;
        update = f / df;
        if !update.is_finite() {
            break;
        }
        v -= update;
        if update.abs() <= tol * (1.0 + v.abs()) {
            converged = true;
            break;
        }
    }
    let solve = ImplicitSolve {
        evals: 1 + iterations,
        jacobian_evals: iterations,
        converged,
        last_update: update.abs(),
    };
    (x0 + dt * v, v, solve)
}
