//! The closed-form pendulum ([`ExactPendulum`]) made cheap enough to evaluate at every step of a
//! long run: the motion after a release from rest is periodic, so one period is tabulated once
//! as a verified piecewise polynomial and each step costs a reduction of its time modulo the
//! period and two polynomials of degree 7.
//!
//! # The interpolant
//! The period T is cut into M intervals at the nodes t_i = fl(i·T/M). On each interval θ and ω
//! are two-point Hermite polynomials of degree 7: value and first three derivatives matched at
//! both ends. The derivatives follow exactly from the equation of motion, θ' = ω,
//! θ'' = -c sin θ, θ''' = -c cos θ ω, θ'''' = c sin θ (ω² + c cos θ) with c = g/L, at the
//! closed form's (θ, ω) at the node, so no derivative is differenced. The Hermite error is
//! h⁸ max|f⁽⁸⁾| / (8! 2⁸); M starts at 4 ωn T (a multiple of 4) and doubles while the error
//! measured against the closed form at ten points inside every interval (besides the nodes)
//! still halves, i.e. until what is left is rounding, not truncation; the error reached is kept
//! ([`PeriodicExact::max_theta_error`]) and is below [`TARGET_THETA_ERROR`] from 0.001° to
//! 179.999° (the tests).
//!
//! # The time argument
//! Step n stands for the time n·dt, the exact product of the step count and the double dt.
//! [`reduce`] forms n·dt mod T within about 2 ulp(T) whatever n is (for n < 2⁵³), so it adds no
//! error that grows with the run. What does grow is the period's own rounding: T = 4K/ωn is a
//! double, within a few ulps of the true period, so the phase moves by about 2 eps T a period:
//! the same order as the closed form's own drift ([`super::exact::EXACT_THETA_DRIFT`]), and far
//! below any method's error.

use super::PendulumParams;
use super::exact::ExactPendulum;

/// The θ error [rad] the interpolant is refined to, against the closed form.
pub const TARGET_THETA_ERROR: f64 = 1e-14;

/// Points checked inside each interval (besides its ends) when the interpolant is verified.
const CHECKS_PER_INTERVAL: usize = 10;

/// Intervals per radian of ωn t to start from; refinement doubles them.
const START_INTERVALS_PER_RADIAN: f64 = 4.0;

/// More intervals than this are not tried (8 MiB of coefficients).
const MAX_INTERVALS: usize = 1 << 16;

/// Two-point Hermite of degree 7 on s ∈ [0, 1]: the top four coefficients from the residuals
/// of the end conditions left by the Taylor part at s = 0 (the inverse of the 4 × 4 system
/// p⁽ᵏ⁾(1) = z_k, k = 0..3, in c4..c7).
const HERMITE_TOP: [[f64; 4]; 4] = [
    [35.0, -15.0, 2.5, -1.0 / 6.0],
    [-84.0, 39.0, -7.0, 0.5],
    [70.0, -34.0, 6.5, -0.5],
    [-20.0, 10.0, -2.0, 1.0 / 6.0],
];

/// θ and ω and their first three time derivatives at one point of the motion.
fn jets(c: f64, theta: f64, omega: f64) -> ([f64; 4], [f64; 4]) {
    let (s, co) = theta.sin_cos();
    let a = -c * s;
    let j = -c * co * omega;
    let snap = c * s * (omega * omega + c * co);
    ([theta, omega, a, j], [omega, a, j, snap])
}

/// The coefficients (in s = (t - t0)/h) of the degree-7 polynomial with time derivatives
/// `y` at t0 and `z` at t0 + h.
fn hermite(y: [f64; 4], z: [f64; 4], h: f64) -> [f64; 8] {
    let scale = [1.0, h, h * h, h * h * h];
    let y: [f64; 4] = std::array::from_fn(|k| y[k] * scale[k]);
    let z: [f64; 4] = std::array::from_fn(|k| z[k] * scale[k]);
    let (c0, c1, c2, c3) = (y[0], y[1], 0.5 * y[2], y[3] / 6.0);
    let r = [
        z[0] - (c0 + c1 + c2 + c3),
        z[1] - (c1 + 2.0 * c2 + 3.0 * c3),
        z[2] - (2.0 * c2 + 6.0 * c3),
        z[3] - 6.0 * c3,
    ];
    let top: [f64; 4] = std::array::from_fn(|i| {
        HERMITE_TOP[i]
            .iter()
            .zip(r)
            .map(|(m, r)| m * r)
            .sum::<f64>()
    });
    [c0, c1, c2, c3, top[0], top[1], top[2], top[3]]
}

fn horner(c: &[f64; 8], s: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * s + k)
}

/// a·b = p + e exactly (Dekker's product by Veltkamp's splitting; no overflow for the step
/// counts and times here). Not `mul_add`: without the FMA target feature that is a library call
/// that costs more than the whole table look-up.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let split = |x: f64| {
        let c = 134_217_729.0 * x; // 2^27 + 1
        let high = c - (c - x);
        (high, x - high)
    };
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    let p = a * b;
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// n·dt mod `period`, in [0, period] (period itself only by the final rounding), within about
/// 2 ulp(period) of the exact value for the doubles dt and period and n < 2⁵³: the product and
/// the subtraction of the whole periods are carried exactly as double-doubles, one rounding at
/// the end. Negative dt is not supported (time runs forward).
pub fn reduce(n: u64, dt: f64, period: f64) -> f64 {
    reduce_with_inverse(n, dt, period, 1.0 / period)
}

/// [`reduce`] with 1 / period given (a multiplication instead of a division per step; the
/// quotient may then be one off, which the end corrects).
fn reduce_with_inverse(n: u64, dt: f64, period: f64, inverse: f64) -> f64 {
    let (p, e) = two_product(n as f64, dt);
    // Truncation is floor here (p ≥ 0), and unlike `floor` needs no library call on x86-64's
    // baseline; a q one off is corrected below.
    let q = (p * inverse) as i64 as f64;
    let (qh, ql) = two_product(q, period);
    // p - qh is exact (Sterbenz: qh = 0, or qh within a factor 2 of p) except when q came out
    // one too small at q = 1, where it rounds by at most ulp(T).
    let mut r = (p - qh) + (e - ql);
    if r < 0.0 {
        r += period;
    } else if r >= period {
        r -= period;
    }
    r
}

/// The closed form at phase τ ∈ [0, T], evaluated at τ's mirror image s in the first quarter
/// period: the motion is even in t and θ(t + T/2) = -θ(t), so θ(T/2 ∓ s) = -θ(s),
/// θ(T - s) = θ(s), with ω following. The mirroring is exact (Sterbenz), and the closed form's
/// argument K - ωn s then rounds on the scale of K instead of 4K: near the separatrix, where
/// K is large and |ω| at the bottom is 2ωn, that rounding is the closed form's largest error.
fn closed_form_at_phase(exact: &ExactPendulum, tau: f64) -> (f64, f64) {
    let period = exact.period();
    let (half, quarter) = (0.5 * period, 0.25 * period);
    let (s, theta_sign, omega_sign) = if tau <= quarter {
        (tau, 1.0, 1.0)
    } else if tau <= half {
        (half - tau, -1.0, 1.0)
    } else if tau <= half + quarter {
        (tau - half, -1.0, -1.0)
    } else {
        (period - tau, 1.0, -1.0)
    };
    let (theta, omega) = exact.state(s);
    (theta_sign * theta, omega_sign * omega)
}

/// One period of the closed form as a verified piecewise polynomial.
#[derive(Clone, Debug)]
pub struct PeriodicExact {
    period: f64,
    inverse_period: f64,
    /// M / T, to find an interval.
    intervals_per_second: f64,
    /// Node times t_0 = 0 ..= t_M = T.
    nodes: Vec<f64>,
    /// 1 / (t_{i+1} - t_i) per interval.
    inverse_widths: Vec<f64>,
    /// θ and ω coefficients per interval.
    theta: Vec<[f64; 8]>,
    omega: Vec<[f64; 8]>,
    max_theta_error: f64,
    max_omega_error: f64,
}

impl PeriodicExact {
    /// The interpolant of the closed form for this start; `None` where there is no closed form
    /// (not a release from rest with |θ0| < 180°).
    pub fn new(p: &PendulumParams) -> Option<Self> {
        let exact = ExactPendulum::new(p)?;
        let c = p.gravity / p.length;
        let turn = exact.period() * p.omega_n();
        // A multiple of 4, so that the nodes fall on the quarter periods and the table has the
        // motion's symmetries.
        let mut intervals = ((turn * START_INTERVALS_PER_RADIAN / 4.0).ceil() as usize).max(1) * 4;
        let mut best = Self::build(&exact, c, intervals);
        // Refine while the error still halves: past that it is the closed form's own rounding.
        while intervals < MAX_INTERVALS {
            intervals *= 2;
            let finer = Self::build(&exact, c, intervals);
            if finer.scaled_error() >= 0.5 * best.scaled_error() {
                break;
            }
            best = finer;
        }
        Some(best)
    }

    /// The interpolant on `intervals` intervals, with its errors measured.
    fn build(exact: &ExactPendulum, c: f64, intervals: usize) -> Self {
        let period = exact.period();
        let mut nodes: Vec<f64> = (0..intervals)
            .map(|i| i as f64 * period / intervals as f64)
            .collect();
        nodes.push(period);
        let jet: Vec<_> = nodes
            .iter()
            .map(|&t| {
                let (th, w) = closed_form_at_phase(exact, t);
                jets(c, th, w)
            })
            .collect();
        let (mut theta, mut omega, mut inverse_widths) = (vec![], vec![], vec![]);
        for i in 0..intervals {
            let h = nodes[i + 1] - nodes[i];
            theta.push(hermite(jet[i].0, jet[i + 1].0, h));
            omega.push(hermite(jet[i].1, jet[i + 1].1, h));
            inverse_widths.push(1.0 / h);
        }
        let mut table = PeriodicExact {
            period,
            inverse_period: 1.0 / period,
            intervals_per_second: intervals as f64 / period,
            nodes,
            inverse_widths,
            theta,
            omega,
            max_theta_error: 0.0,
            max_omega_error: 0.0,
        };
        for i in 0..intervals {
            let (t0, t1) = (table.nodes[i], table.nodes[i + 1]);
            for k in 1..=CHECKS_PER_INTERVAL {
                let t = t0 + (t1 - t0) * k as f64 / (CHECKS_PER_INTERVAL + 1) as f64;
                let (th, w) = closed_form_at_phase(exact, t);
                let (ith, iw) = table.at_phase(t);
                table.max_theta_error = table.max_theta_error.max((ith - th).abs());
                table.max_omega_error = table.max_omega_error.max((iw - w).abs());
            }
        }
        table
    }

    /// The larger of the θ error and the ω error over ωn, the small-angle ratio of ω to θ.
    fn scaled_error(&self) -> f64 {
        self.max_theta_error
            .max(self.max_omega_error * self.period / (2.0 * std::f64::consts::PI))
    }

    /// (θ, ω) at phase τ ∈ [0, T] [s].
    pub fn at_phase(&self, tau: f64) -> (f64, f64) {
        let last = self.theta.len() - 1;
        let i = ((tau * self.intervals_per_second) as usize).min(last);
        // The guess can be one off at a node; the polynomial is as good a hair beyond its ends.
        let s = (tau - self.nodes[i]) * self.inverse_widths[i];
        (horner(&self.theta[i], s), horner(&self.omega[i], s))
    }

    /// (θ, ω) at step n of a run with step dt: at time n·dt exactly (see [`reduce`]).
    pub fn state_at_step(&self, n: u64, dt: f64) -> (f64, f64) {
        self.at_phase(reduce_with_inverse(n, dt, self.period, self.inverse_period))
    }

    /// The period T [s] tabulated (the closed form's, [`ExactPendulum::period`]).
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Intervals per period.
    pub fn intervals(&self) -> usize {
        self.theta.len()
    }

    /// Largest |θ - θ_closed form| [rad] found when the table was verified.
    pub fn max_theta_error(&self) -> f64 {
        self.max_theta_error
    }

    /// Largest |ω - ω_closed form| [rad/s] found when the table was verified.
    pub fn max_omega_error(&self) -> f64 {
        self.max_omega_error
    }
}
