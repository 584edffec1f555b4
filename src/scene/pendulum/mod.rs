//! The simple pendulum θ'' = -(g/L) sin θ as a one-degree-of-freedom ODE in (θ, ω), f64.
//!
//! Energy is per unit bob mass with the potential's zero at the lowest point,
//! E = ½ L² ω² + g L (1 - cos θ) [J/kg], so E ≥ 0 and E = 0 only at rest at the bottom.

pub mod period;
pub mod reference;
pub mod run;

use crate::integrate::{ImplicitSolve, Integrator, SecondOrderSystem, scalar_backward_euler};

/// Newton's tolerance on the implicit-Euler step: stop when |Δω| ≤ NEWTON_TOL·(1 + |ω|) [rad/s].
pub const NEWTON_TOL: f64 = 1e-12;
/// Newton iterations before a step is reported as not converged.
pub const NEWTON_MAX_ITERATIONS: u32 = 50;

/// Physical parameters of the pendulum and its initial state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PendulumParams {
    /// g [m/s²]
    pub gravity: f64,
    /// L [m]
    pub length: f64,
    /// θ(0) [rad], measured from straight down
    pub theta0: f64,
    /// ω(0) = θ'(0) [rad/s]
    pub omega0: f64,
}

impl Default for PendulumParams {
    fn default() -> Self {
        PendulumParams {
            gravity: 9.81,
            length: 3.521,
            theta0: run::DEFAULT_THETA0_DEGREES.to_radians(),
            omega0: 0.0,
        }
    }
}

impl PendulumParams {
    /// Small-angle angular frequency sqrt(g/L) [rad/s].
    pub fn omega_n(&self) -> f64 {
        (self.gravity / self.length).sqrt()
    }

    /// Total energy per unit mass [J/kg] at (θ, ω). The potential g L (1 - cos θ) is written
    /// 2 g L sin²(θ/2): the same value without the cancellation of 1 - cos θ, which at θ = 1e-3
    /// rad loses half the digits and at 1e-8 rad all of them.
    pub fn energy(&self, theta: f64, omega: f64) -> f64 {
        let l = self.length;
        let s = (0.5 * theta).sin();
        0.5 * l * l * omega * omega + 2.0 * self.gravity * l * s * s
    }

    pub fn initial_energy(&self) -> f64 {
        self.energy(self.theta0, self.omega0)
    }

    /// The scale relative energy errors are taken against: E0, or g L when E0 = 0
    /// (at rest at the bottom, where (E - E0)/E0 is undefined).
    pub fn energy_scale(&self) -> f64 {
        let e0 = self.initial_energy();
        if e0 > 0.0 {
            e0
        } else {
            self.gravity * self.length
        }
    }

    /// Energy needed to swing over the top from rest at the bottom, 2 g L [J/kg].
    pub fn over_the_top_energy(&self) -> f64 {
        2.0 * self.gravity * self.length
    }

    /// Bob position relative to the pivot in the swing plane (x right, z up) [m].
    pub fn bob_offset(&self, theta: f64) -> (f64, f64) {
        (self.length * theta.sin(), -self.length * theta.cos())
    }
}

/// The pendulum as a [`SecondOrderSystem`] with one coordinate, θ.
#[derive(Clone, Copy, Debug)]
pub struct Pendulum {
    /// g / L [1/s²]
    g_over_l: f64,
}

impl Pendulum {
    pub fn new(params: &PendulumParams) -> Self {
        Pendulum {
            g_over_l: params.gravity / params.length,
        }
    }
}

impl SecondOrderSystem for Pendulum {
    fn dim(&self) -> usize {
        1
    }

    #[inline]
    fn acceleration(&self, x: &[f64], _v: &[f64], a: &mut [f64]) {
        a[0] = -self.g_over_l * x[0].sin();
    }

    /// Backward Euler: with θ1 = θ0 + dt ω1, solve F(ω1) = ω1 - ω0 + dt (g/L) sin(θ0 + dt ω1) = 0
    /// by Newton from the explicit-Euler guess ([`scalar_backward_euler`]). F' = 1 + dt² (g/L)
    /// cos θ1 > 0 while dt² g/L < 1, so the root is then unique and Newton converges in a few
    /// iterations. A force evaluation is one sin, a Jacobian evaluation one cos: the guess costs
    /// one sin, every iteration one sin and one cos.
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
        let c = self.g_over_l;
        let (theta, omega, solve) = scalar_backward_euler(
            x[0],
            v[0],
            dt,
            NEWTON_TOL,
            NEWTON_MAX_ITERATIONS,
            |t| -(dt * c * t.sin()),
            |t| {
                let (s, co) = t.sin_cos();
                (-(dt * c * s), -(dt * dt * c * co))
            },
        );
        x[0] = theta;
        v[0] = omega;
        solve
    }
}

/// Takes `theta.len()` steps, storing (θ, ω), the evaluations spent so far and the size of the
/// method's last accepted step (an adaptive method's own, dt otherwise) after each;
/// appends the indices of steps whose implicit solve missed its tolerance to `unconverged`.
///
/// This is the loop the lab times and the benchmark measures. It is not generic and never
/// inlined, so both run the very same machine code (a generic stepper is compiled anew, and
/// optimised differently, in every crate that calls it).
#[inline(never)]
pub fn step_block(
    it: &mut Integrator,
    system: &Pendulum,
    theta: &mut [f64],
    omega: &mut [f64],
    evals: &mut [u64],
    step_size: &mut [f64],
    unconverged: &mut Vec<usize>,
) {
    for (j, (((th, w), e), h)) in theta
        .iter_mut()
        .zip(omega.iter_mut())
        .zip(evals.iter_mut())
        .zip(step_size.iter_mut())
        .enumerate()
    {
        if let Some(solve) = it.step(system)
            && !solve.converged
        {
            unconverged.push(j);
        }
        *th = it.position()[0];
        *w = it.velocity()[0];
        *e = it.evals();
        *h = it.last_step_size();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn implicit_step_satisfies_backward_euler_equations() {
        let p = PendulumParams::default();
        let sys = Pendulum::new(&p);
        let (theta0, omega0) = (1.0, 0.3);
        let (mut x, mut v) = ([theta0], [omega0]);
        let dt = 0.05;
        let r = sys.implicit_euler_step(&mut x, &mut v, dt);
        assert!(r.converged && r.jacobian_evals <= 6, "{r:?}");
        // The guess's force evaluation and one force + one Jacobian per Newton iteration.
        assert_eq!(r.evals, r.jacobian_evals + 1, "{r:?}");
        // The backward-Euler equations from scratch. Eliminating ω1 leaves one equation in θ1
        // alone, R(θ1) = θ1 - θ0 - dt ω0 + dt² (g/L) sin θ1 = 0 (the solver iterates on ω1, so
        // this is not true by construction); then ω1 = ω0 - dt (g/L) sin θ1.
        let c = p.gravity / p.length;
        let (theta1, omega1) = (x[0], v[0]);
        let residual = theta1 - theta0 - dt * omega0 + dt * dt * c * theta1.sin();
        assert!(residual.abs() < 1e-14, "R(θ1) = {residual:e}");
        assert!((omega1 - (omega0 - dt * c * theta1.sin())).abs() < 1e-12);
        // R is that small only at the root: at the explicit-Euler guess it is not.
        let guess = theta0 + dt * (omega0 - dt * c * theta0.sin());
        let miss = guess - theta0 - dt * omega0 + dt * dt * c * guess.sin();
        assert!(miss.abs() > 1e-6, "R(guess) = {miss:e}");
    }

    #[test]
    fn energy_zero_at_bottom_and_2gl_at_top() {
        let p = PendulumParams::default();
        assert_eq!(p.energy(0.0, 0.0), 0.0);
        let top = p.energy(std::f64::consts::PI, 0.0);
        assert!((top - p.over_the_top_energy()).abs() < 1e-12);
    }
}
