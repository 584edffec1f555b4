//! Implicit (backward) Euler. The nonlinear solve is the system's own
//! ([`SecondOrderSystem::implicit_euler_step`]): a scalar Newton iteration for the pendulum, a
//! block-tridiagonal Newton step for the rope. Here only its cost is counted.

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
