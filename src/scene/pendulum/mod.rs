//! The simple pendulum θ'' = -(g/L) sin θ as a one-degree-of-freedom ODE in (θ, ω), f64.
//!
//! Energy is per unit bob mass with the potential's zero at the lowest point,
//! E = ½ L² ω² + g L (1 - cos θ) [J/kg], so E ≥ 0 and E = 0 only at rest at the bottom.

pub mod exact;
pub mod period;
pub mod periodic;
pub mod reference;
pub mod run;

use crate::integrate::{ImplicitSolve, Integrator, SecondOrderSystem, scalar_backward_euler};

/// Newton's tolerance on the implicit-Euler step: stop when |Δω| ≤ NEWTON_TOL·(1 + |ω|) [rad/s].
pub const NEWTON_TOL: f64 = 1e-12;
/// Newton iterations before a step is reported as not converged.
pub const NEWTON_MAX_ITERATIONS: u32 = 50;

/// Physical parameters of the pendulum and its initial state.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PendulumParams {
    /// g [m/s²]
    #[serde(deserialize_with = "crate::scene::params::magnitude")]
    pub gravity: f64,
    /// L [m]
    pub length: f64,
    /// θ(0) [rad], measured from straight down (given in degrees: `PendulumConfig::theta0`)
    #[serde(skip)]
    pub theta0: f64,
    /// What θ0 lost to rounding when it was converted from degrees [rad]: θ0 + theta0_low is the
    /// angle typed to about 1e-32 rad. Only the closed form reads it, for π - |θ0| near the top,
    /// where that rounding would otherwise be all the digits of the complement; 0 when θ0 was
    /// given in radians, and always within half an ulp of θ0, so a stale value is harmless.
    #[serde(skip)]
    pub theta0_low: f64,
    /// ω(0) = θ'(0) [rad/s]
    pub omega0: f64,
}

/// Largest |θ0| accepted, in turns: any pendulum state is reached within one, so an angle
/// thousands of turns out is a typo, not a start (and beyond ~1e16° f64 keeps no degree at all).
pub const MAX_THETA0_TURNS: f64 = 1000.0;

/// π/180 as a double-double (the second part is the first's rounding error).
const RADIANS_PER_DEGREE: (f64, f64) = (0.017_453_292_519_943_295, 2.948_652_270_870_168_7e-19);

/// π as a double-double.
const PI_DD: (f64, f64) = (std::f64::consts::PI, 1.224_646_799_147_353_2e-16);

/// θ0 [rad] and the part of it below its last bit (see [`PendulumParams::theta0_low`]) from an
/// angle in degrees, wrapped into (-180°, 180°] (the same pendulum state, so that 181° is the
/// release from -179° that the closed form covers; `rem_euclid` on f64 is exact). An angle
/// beyond [`MAX_THETA0_TURNS`], or not finite, is returned unwrapped for `validate()` to refuse
/// by its value.
pub fn theta0_from_degrees(degrees: f64) -> (f64, f64) {
    if degrees.is_nan() || degrees.abs() > MAX_THETA0_TURNS * 360.0 {
        return (degrees.to_radians(), 0.0);
    }
    let r = degrees.rem_euclid(360.0);
    let d = if r > 180.0 { r - 360.0 } else { r };
    // d × π/180 in double-double: the product's rounding error by fma, plus d × the low part.
    // θ0 is d·π/180 correctly rounded (`to_radians` can be an ulp off, as at 60°), and what
    // that rounding lost is kept beside it for the closed form near the separatrix.
    let hi = d * RADIANS_PER_DEGREE.0;
    let low = d.mul_add(RADIANS_PER_DEGREE.0, -hi) + d * RADIANS_PER_DEGREE.1;
    let theta = hi + low;
    (theta, low - (theta - hi))
}

impl Default for PendulumParams {
    fn default() -> Self {
        PendulumParams {
            gravity: 9.81,
            length: 3.521,
            // As `--theta0` converts it, so that a run with and without the flag agree. (Its
            // low part only matters beyond 90°; 0 here so that `..default()` adds none.)
            theta0: theta0_from_degrees(run::DEFAULT_THETA0_DEGREES).0,
            theta0_low: 0.0,
            omega0: 0.0,
        }
    }
}

impl PendulumParams {
    /// (sin(θ0/2), cos(θ0/2)). Beyond ±90° the cosine is taken as sin((π - |θ0|)/2), with the
    /// complement π - |θ0| formed from π and θ0 as double-doubles: the subtraction of the high
    /// parts is exact (Sterbenz), so near the top the complement keeps the digits of the angle
    /// typed rather than those of its rounding to radians.
    pub fn half_angle(&self) -> (f64, f64) {
        let (s, c) = (0.5 * self.theta0).sin_cos();
        if self.theta0.abs() <= std::f64::consts::FRAC_PI_2 {
            return (s, c);
        }
        // |θ0 + low| = |θ0| + low·sign(θ0).
        let low = if self.theta0 < 0.0 {
            -self.theta0_low
        } else {
            self.theta0_low
        };
        let complement = (PI_DD.0 - self.theta0.abs()) + (PI_DD.1 - low);
        (s, (0.5 * complement).sin())
    }

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

    /// Backward Euler: with θ1 = θ0 + dt ω1, solve F(ω1) = ω1 - ω0 + dt (g/L) sin(θ0 + dt ω1) = 0.
    ///
    /// While dt² g/L < 1, F' = 1 + dt² (g/L) cos θ1 > 0, the root is unique, and Newton from the
    /// explicit-Euler guess ([`scalar_backward_euler`]) converges in a few iterations. A force
    /// evaluation is one sin, a Jacobian evaluation one cos: the guess costs one sin, every
    /// iteration one sin and one cos.
    ///
    /// From dt² g/L ≥ 1 on, the equation has several roots, and Newton from the guess can land
    /// on one that gains energy (×58 in one step at dt = 5 s). The step then takes the root that
    /// minimises the step's incremental potential ([`minimising_root`]), the one backward Euler
    /// means: its first step from rest provably never gains energy (Φ(θ1) ≤ Φ(θ0)), and runs
    /// from rest keep E ≤ E0 at every dt tried (`tests/pendulum.rs`, `physics`).
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
        let c = self.g_over_l;
        let a = dt * dt * c;
        if a >= 1.0 {
            let (theta, sin_theta, solve) = minimising_root(
                x[0] + dt * v[0],
                a,
                dt,
                x[0],
                NEWTON_TOL,
                NEWTON_MAX_ITERATIONS,
            );
            v[0] -= dt * c * sin_theta;
            x[0] = theta;
            return solve;
        }
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

/// The root of R(θ) = θ - b + a sin θ (b = θ0 + dt ω0, a = dt² g/L ≥ 1) that minimises the
/// step's incremental potential Φ(θ) = ½ (θ - b)² + a (1 - cos θ), whose stationary points are
/// exactly R's roots; returns θ1, sin θ1 and what the solve spent.
///
/// The global minimiser is a root where Φ'' = R' = 1 + a cos θ ≥ 0, so it lies in one of the
/// intervals I_k = [2πk - α, 2πk + α], α = acos(-1/a), on each of which R increases (one root
/// at most, found by Newton safeguarded by bisection in the sign-change bracket). Since
/// Φ(θ) ≥ ½ (θ - b)² and Φ(2πk) = ½ (2πk - b)² ≤ ½ π² for the k nearest b/2π, only k within
/// one of that nearest can hold it: at most three intervals are searched, and the root with
/// the least Φ is kept. Every iteration costs one sin and one cos (a force and a Jacobian
/// evaluation), and each interval searched one more pair at its root; converged when the
/// Newton update is within `tol`·(1 + |ω1|)·dt in θ (the scalar solver's |Δω| criterion).
pub fn minimising_root(
    b: f64,
    a: f64,
    dt: f64,
    theta0: f64,
    tol: f64,
    max_iterations: u32,
) -> (f64, f64, ImplicitSolve) {
    use std::f64::consts::TAU;
    let alpha = (-1.0 / a).acos();
    // R at the ends of I_k (in u = θ - 2πk): ∓(α + a sin α) - (b - 2πk).
    let reach = alpha + a * (1.0 - 1.0 / (a * a)).sqrt();
    let nearest = (b / TAU).round();
    let mut solve = ImplicitSolve {
        evals: 0,
        jacobian_evals: 0,
        converged: true,
        last_update: 0.0,
    };
    // (Φ, θ1, sin θ1, converged, last update) of the best root so far.
    let mut best: Option<(f64, f64, f64, bool, f64)> = None;
    for k in [nearest - 1.0, nearest, nearest + 1.0] {
        let centre = TAU * k;
        let offset = b - centre;
        if offset.is_nan() || offset.abs() > reach {
            continue; // R keeps one sign on I_k: no root there.
        }
        // Solve u - offset + a sin u = 0 on [-α, α], where it increases.
        let (mut lo, mut hi) = (-alpha, alpha);
        let mut u = (offset / (1.0 + a)).clamp(lo, hi);
        let mut converged = false;
        let mut update = f64::INFINITY;
        let mut iterations = 0;
        while iterations < max_iterations {
            let (s, co) = u.sin_cos();
            iterations += 1;
            let r = u - offset + a * s;
            if r == 0.0 {
                update = 0.0;
                converged = true;
                break;
            }
            if r < 0.0 {
                lo = u;
            } else {
                hi = u;
            }
            let slope = 1.0 + a * co;
            let newton = u - r / slope;
            let next = if slope > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            update = (next - u).abs();
            u = next;
            let omega = (centre + u - theta0) / dt;
            if update <= tol * (1.0 + omega.abs()) * dt || hi - lo <= f64::EPSILON * (1.0 + u.abs())
            {
                converged = true;
                break;
            }
        }
        // The root's own sin (for ω1) and cos (for Φ without cancellation).
        let (s, co) = u.sin_cos();
        solve.evals += iterations + 1;
        solve.jacobian_evals += iterations + 1;
        // 1 - cos u without cancellation near u = 0.
        let one_minus_cos = if co > 0.0 {
            s * s / (1.0 + co)
        } else {
            1.0 - co
        };
        let phi = 0.5 * (u - offset) * (u - offset) + a * one_minus_cos;
        if best.is_none_or(|(p, ..)| phi < p) {
            best = Some((phi, centre + u, s, converged, update));
        }
    }
    match best {
        Some((_, theta, s, converged, update)) => {
            solve.converged = converged;
            solve.last_update = update;
            (theta, s, solve)
        }
        // Unreachable for finite b (one of the three intervals holds the minimiser); a
        // non-finite start is handed back as it is, and the run's check stops the lane.
        None => {
            solve.converged = false;
            solve.last_update = f64::NAN;
            (b, b.sin(), solve)
        }
    }
}

/// Takes `theta.len()` steps, storing (θ, ω), the evaluations spent so far and the size of the
/// method's last accepted step (an adaptive method's own, or --step's, dt otherwise) after each;
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
