//! The pendulum's closed form: the exact motion after a release from rest with |θ0| < 180°
//! (Jacobi elliptic functions), and the exact period for any energy.

use super::PendulumParams;
use crate::elliptic::{complete_k_m1, jacobi_m1};

/// How well [`ExactPendulum::state`] gives θ [rad] within the first periods: measured against
/// 100-digit mpmath values from 10° to 179.99999999999° (`tests/pendulum.rs`, worst 9.6e-15
/// rad). Over a run it grows by [`EXACT_THETA_DRIFT`] per radian of ωn t
/// ([`ExactPendulum::theta_accuracy`]).
pub const EXACT_THETA_ACCURACY: f64 = 1e-14;

/// How much the closed form's θ error grows per radian of ωn t [rad]: ωn is a rounded double
/// (its relative error, up to 1.1e-16, becomes a phase error growing with t), and so are
/// ωn t and its reduction by the period. Measured over whole runs against mpmath
/// (`tests/pendulum.rs`, 10° to 179.999999°, 30–100 s): at most 5.5e-16 per radian.
pub const EXACT_THETA_DRIFT: f64 = 1e-15;

/// θ(t) = 2 atan2(k sn, dn)(K - ωn t | k²) (= 2 asin(k sn), written so that it keeps its
/// digits near the top, where k sn → 1), ω(t) = -2 k ωn cn(K - ωn t | k²), with k = sin(θ0/2),
/// ωn = sqrt(g/L): the exact motion after release from rest at θ0, |θ0| < 180°.
///
/// Near the separatrix the parameter m = k² rounds to 1, so the complement m1 = k'² is formed
/// from k' = cos(θ0/2) = sin((π - |θ0|)/2), the complement taken from the angle as typed
/// ([`PendulumParams::half_angle`]: θ0 in degrees rounded to radians alone would move k' by up to
/// 1.3e-7 relative at 179.9999999°), and handed to [`complete_k_m1`] and [`jacobi_m1`]. The
/// period and θ(t) then keep their full precision up to the last double below 180°.
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
        let (k, k1) = p.half_angle();
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

    /// How well [`Self::state`] gives θ up to time t [rad]: [`EXACT_THETA_ACCURACY`] plus
    /// [`EXACT_THETA_DRIFT`] per radian of ωn t.
    pub fn theta_accuracy(&self, t: f64) -> f64 {
        EXACT_THETA_ACCURACY + EXACT_THETA_DRIFT * self.omega_n * t.abs()
    }

    /// T = 4 K(k²) / ωn [s].
    pub fn period(&self) -> f64 {
        4.0 * self.quarter / self.omega_n
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
    let (s, c) = p.half_angle();
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

/// The closed form and its constants, as `Reference::describe` states them.
pub fn closed_form_text(e: &ExactPendulum) -> String {
    format!(
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
    )
}
