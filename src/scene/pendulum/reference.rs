//! The pendulum's reference solutions: the closed form for a release from rest with |θ0| < 180°,
//! and a converged fine-step solution for every other start, plus the exact period for any energy.

use super::{Pendulum, PendulumParams};
use crate::elliptic::{complete_k_m1, jacobi_m1};
use crate::integrate::{Integrator, Method, MethodOptions};

/// θ(t) = 2 atan2(k sn, dn)(K - ωn t | k²) (= 2 asin(k sn), written so that it keeps its
/// digits near the top, where k sn → 1), ω(t) = -2 k ωn cn(K - ωn t | k²), with k = sin(θ0/2),
/// ωn = sqrt(g/L): the exact motion after release from rest at θ0, |θ0| < 180°.
///
/// Near the separatrix the parameter m = k² rounds to 1, so the complement m1 = k'² is formed
/// from k' = cos(θ0/2) (no cancellation: θ0/2 is exact and cos of a double is correctly
/// reduced) and handed to [`complete_k_m1`] and [`jacobi_m1`]. The period and θ(t) then keep
/// their full precision up to the last double below π; what is left is the input's own rounding
/// (a release angle in degrees is rounded to radians before it gets here, which at 179.9999999°
/// already moves k' by up to 1.3e-7 relative and T by up to 7e-9).
/// How well [`ExactPendulum::state`] gives θ [rad]: measured against 100-digit mpmath values
/// from 10° to 179.99999999999° (`tests/separatrix.rs`, worst 9.6e-15 rad), so a claimed error
/// is resolved down to ~1e-13 (the studies leave out targets below 10× this).
pub const EXACT_THETA_ACCURACY: f64 = 1e-14;

#[derive(Clone, Copy, Debug)]
pub struct ExactPendulum {
    k: f64,
    m: f64,
    m1: f64,
    quarter: f64,
    omega_n: f64,
}

impl ExactPendulum {
    /// `None` unless the start is a release from rest with |θ0| < 180°.
    pub fn new(p: &PendulumParams) -> Option<Self> {
        if p.omega0 != 0.0 || p.theta0.is_nan() || p.theta0.abs() >= std::f64::consts::PI {
            return None;
        }
        let (k, k1) = (0.5 * p.theta0).sin_cos();
        let (m, m1) = (k * k, k1 * k1);
        Some(ExactPendulum {
            k,
            m,
            m1,
            quarter: complete_k_m1(m, m1),
            omega_n: p.omega_n(),
        })
    }

    /// (θ, ω) at time t [s].
    pub fn state(&self, t: f64) -> (f64, f64) {
        let j = jacobi_m1(self.quarter - self.omega_n * t, self.m, self.m1);
        let theta = 2.0 * (self.k * j.sn).atan2(j.dn);
        let omega = -2.0 * self.k * self.omega_n * j.cn;
        (theta, omega)
    }

    /// T = 4 K(k²) / ωn [s].
    pub fn period(&self) -> f64 {
        4.0 * self.quarter / self.omega_n
    }

    /// The parameter m = k² and its complement m1 = k'² = cos²(θ0/2), as used.
    pub fn parameters(&self) -> (f64, f64) {
        (self.m, self.m1)
    }
}

/// The exact period [s] of the motion with the start's energy: 4K(k²)/ωn for libration
/// (k² = E/(2gL) < 1), 2K(1/k²)/(k ωn) for one full revolution (k² > 1);
/// `None` on the separatrix (k² = 1, infinite period) or at rest at the bottom.
///
/// k² = sin²(θ0/2) + L ω0²/(4g) and its complement 1 - k² = cos²(θ0/2) - L ω0²/(4g) are both
/// formed from half-angle terms, so a release from rest near the top (ω0 = 0) has no
/// cancellation at all; with ω0 ≠ 0 the one subtraction left is the physics' own.
pub fn exact_period(p: &PendulumParams) -> Option<f64> {
    let e0 = p.initial_energy();
    if e0.is_nan() || e0 <= 0.0 {
        return None;
    }
    let (s, c) = (0.5 * p.theta0).sin_cos();
    let kinetic = p.length * p.omega0 * p.omega0 / (4.0 * p.gravity);
    let k2 = s * s + kinetic;
    let k2_complement = c * c - kinetic;
    let wn = p.omega_n();
    if !k2.is_finite() || k2 <= 0.0 || k2_complement == 0.0 {
        None
    } else if k2_complement > 0.0 {
        Some(4.0 * complete_k_m1(k2, k2_complement) / wn)
    } else {
        // Revolution: parameter 1/k², complement 1 - 1/k² = -(1 - k²)/k².
        let m1 = (-k2_complement / k2).min(1.0);
        Some(2.0 * complete_k_m1(1.0 / k2, m1) / (k2.sqrt() * wn))
    }
}

/// A fine-step RK4 solution for starts the closed form does not cover. It is run twice, at
/// h and h/2, and the finer one is used; their difference / (2⁴ - 1) (Richardson for order 4)
/// estimates its error, reported with the run.
#[derive(Clone, Debug)]
pub struct FineStepReference {
    fine: Integrator,
    coarse: Integrator,
    system: Pendulum,
    substeps: u64,
    max_difference: f64,
    step: u64,
}

/// Fine steps are chosen so that (fastest rate) × h ≤ this; RK4's error then sits near 1e-10
/// over tens of periods, far below what the methods under test reach.
const FINE_STEP_RATE_TIMES_H: f64 = 2e-3;

impl FineStepReference {
    /// RK4 substeps per sample step `dt`: (fastest rate) × h ≤ [`FINE_STEP_RATE_TIMES_H`], the
    /// fastest rate being the small-angle frequency or the largest |ω| the energy allows. Each
    /// substep costs three RK4 steps (one at h, two at h/2).
    pub fn substeps(p: &PendulumParams, dt: f64) -> f64 {
        let rate = p
            .omega_n()
            .max((2.0 * p.initial_energy()).sqrt() / p.length);
        (rate * dt / FINE_STEP_RATE_TIMES_H).ceil().max(1.0)
    }

    /// A reference sampled every `dt`, stepped with RK4 at dt / substeps and dt / (2 substeps).
    pub fn new(p: &PendulumParams, dt: f64) -> Self {
        let system = Pendulum::new(p);
        let substeps = Self::substeps(p, dt) as u64;
        let h = dt / substeps as f64;
        let make = |h: f64| {
            Integrator::new(
                Method::Rk4,
                &system,
                &[p.theta0],
                &[p.omega0],
                h,
                MethodOptions::default(),
            )
        };
        FineStepReference {
            coarse: make(h),
            fine: make(0.5 * h),
            system,
            substeps,
            max_difference: 0.0,
            step: 0,
        }
    }

    /// Advances to the next sample time (one outer step dt) and returns (θ, ω) there. A stop
    /// request ([`crate::interrupt::requested`], looked at every 2¹⁶ substeps, well under a
    /// millisecond) ends it early; the caller then discards the sample.
    pub fn advance(&mut self) -> (f64, f64) {
        for k in 0..self.substeps {
            if k % 65_536 == 65_535 && crate::interrupt::requested() {
                break;
            }
            self.coarse.step(&self.system);
            self.fine.step(&self.system);
            self.fine.step(&self.system);
        }
        self.step += 1;
        let diff = (self.fine.position()[0] - self.coarse.position()[0]).abs();
        self.max_difference = self.max_difference.max(diff);
        (self.fine.position()[0], self.fine.velocity()[0])
    }

    /// Estimated largest error of θ so far [rad]: the h/2 run's error is the difference
    /// between the runs / (2⁴ - 1) for a fourth-order method.
    pub fn error_estimate(&self) -> f64 {
        self.max_difference / 15.0
    }

    /// The fine step size [s].
    pub fn fine_step(&self) -> f64 {
        self.fine.dt()
    }
}

/// The reference a run compares against.
#[derive(Clone, Debug)]
pub enum Reference {
    Exact(ExactPendulum),
    FineStep(Box<FineStepReference>),
}

impl Reference {
    /// The closed form where it applies, otherwise the fine-step solution sampled every `dt`.
    pub fn for_start(p: &PendulumParams, dt: f64) -> Self {
        match ExactPendulum::new(p) {
            Some(e) => Reference::Exact(e),
            None => Reference::FineStep(Box::new(FineStepReference::new(p, dt))),
        }
    }

    /// Its lane name in tables and recordings: `exact` or `reference`.
    pub fn name(&self) -> &'static str {
        match self {
            Reference::Exact(_) => "exact",
            Reference::FineStep(_) => "reference",
        }
    }

    /// (θ, ω) at step n (time n·dt). Steps must be asked for in order, 1, 2, 3, ...
    pub fn state_at_step(&mut self, n: u64, dt: f64) -> (f64, f64) {
        match self {
            Reference::Exact(e) => e.state(n as f64 * dt),
            Reference::FineStep(f) => {
                debug_assert_eq!(n, f.step + 1, "fine-step reference is sampled in order");
                f.advance()
            }
        }
    }

    /// One sentence on what the reference is, for the recording and the summary.
    pub fn describe(&self) -> String {
        match self {
            Reference::Exact(e) => format!(
                "exact: closed form θ(t) = 2 asin(k sn(K - ωn t, k²)), k = {:.12}, k' = cos(θ0/2) = {:.6e}, K = {:.15}, T = {} s",
                e.k,
                e.m1.sqrt(),
                e.quarter,
                // 13 significant digits at any scale (fixed point would print a 1e-13 s period
                // as 0.000000000000).
                match e.period() {
                    t if (1e-3..1e6).contains(&t) => format!("{t:.12}"),
                    t => format!("{t:.12e}"),
                }
            ),
            Reference::FineStep(f) => format!(
                "reference: no closed form for this start (ω0 ≠ 0 or |θ0| ≥ 180°); RK4 at h = {:.3e} s, \
                 estimated max θ error {:.1e} rad (Richardson against a run at 2h)",
                f.fine_step(),
                f.error_estimate()
            ),
        }
    }
}
