//! Runge–Kutta–Nyström methods for x'' = a(x): forces of position alone. A stage evaluates the
//! acceleration at x_s = x + c_s h v + h² Σ_j ā_sj g_j, g_j the earlier stages' accelerations,
//! and the step is x1 = x + h v + h² Σ b̄_j g_j, v1 = v + h Σ b_j g_j (Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, 2nd ed., §II.14). With no velocity in the stages
//! they need fewer evaluations for an order than a first-order method on (x, v); with a force
//! that depends on the velocity they would be wrong (the velocity passed to a stage is the
//! step's first), so the scenes refuse them there (`MethodInfo::accepts_velocity_dependent`).
//!
//! `Rkn4` is fixed-step; the embedded pairs are [`Pair`]s of the shared driver (`dense.rs`)
//! whose stage rows hold the acceleration alone (`Pair::ACCELERATION_ROWS`).

use super::dense::{Core, Dynamic, Pair, Width};
use super::rkn_tables as t;
use super::{SecondOrderSystem, State};

/// The classical fourth-order Nyström method for x'' = a(x) (HNW I, §II.14; the tableau of
/// OrdinaryDiffEq's `Nystrom4VelocityIndependent`): c = (0, 1/2, 1), ā_21 = 1/8, ā_32 = 1/2,
/// b̄ = (1/6, 1/3, 0), b = (1/6, 2/3, 1/6). Three evaluations per step.
#[derive(Clone, Debug)]
pub struct Rkn4 {
    /// The first stage's acceleration a(x), the other two stages', and a stage's position.
    g0: Vec<f64>,
    g1: Vec<f64>,
    g2: Vec<f64>,
    xs: Vec<f64>,
}

impl Rkn4 {
    pub fn new(n: usize) -> Self {
        Rkn4 {
            g0: vec![0.0; n],
            g1: vec![0.0; n],
            g2: vec![0.0; n],
            xs: vec![0.0; n],
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        sys.acceleration(s.x, s.v, &mut self.g0);
        s.counts.evals += 1;
        let g0 = std::mem::take(&mut self.g0);
        self.step_from(sys, s, h, &g0, Dynamic(g0.len()));
        self.g0 = g0;
    }

    /// A step whose first stage, a(x), is known (`g0`): two evaluations.
    #[inline]
    pub fn step_from<S: SecondOrderSystem, W: Width>(
        &mut self,
        sys: &S,
        s: State,
        h: f64,
        g0: &[f64],
        w: W,
    ) {
        let n = w.get();
        let (g1, g2, xs) = (&mut self.g1, &mut self.g2, &mut self.xs);
        // Each update adds the newest acceleration last, on its own, with its weight times h or
        // h² formed beforehand: the stages form one dependent chain (a stage's position needs
        // the previous stage's force), and this leaves one multiply-add on it between two
        // evaluations, as `rkn_stage` does for the pairs.
        let h2 = h * h;
        let (a21, a32) = (h2 * 0.125, h2 * 0.5);
        let (bx0, bx1) = (h2 * (1.0 / 6.0), h2 * (1.0 / 3.0));
        let (bv0, bv1, bv2) = (h * (1.0 / 6.0), h * (2.0 / 3.0), h * (1.0 / 6.0));
        for i in 0..n {
            xs[i] = (s.x[i] + (0.5 * h) * s.v[i]) + a21 * g0[i];
        }
        sys.acceleration(xs, s.v, g1);
        for i in 0..n {
            xs[i] = (s.x[i] + h * s.v[i]) + a32 * g1[i];
        }
        sys.acceleration(xs, s.v, g2);
        s.counts.evals += 2;
        for i in 0..n {
            s.x[i] = ((s.x[i] + h * s.v[i]) + bx0 * g0[i]) + bx1 * g1[i];
            s.v[i] = ((s.v[i] + bv0 * g0[i]) + bv1 * g1[i]) + bv2 * g2[i];
        }
    }
}

/// The largest stable h = ω dt of [`Rkn4`] on x'' = −ω² x: its amplification matrix has trace
/// 2 − h² + h⁴/12 and determinant 1 − h⁶/288, and its eigenvalues leave the unit disc where the
/// trace reaches −(1 + det), the root of 4 − h² + h⁴/12 − h⁶/288 = 0 in (2, 3).
pub const RKN4_STABILITY_LIMIT: f64 = 2.586518894519562;

/// An embedded RKN pair's coefficients and continuous extension (see `rkn_tables`).
pub(crate) trait RknTableau {
    /// Stages of a step (stage 0 is a(x) at the step's start).
    const STAGES: usize;
    /// Whether the last stage is a(x1) (c = 1, ā = b̄), so the trial evaluates it (DPRKN6, DPRKN8).
    const FSAL: bool;
    /// Stages the dense output adds: a(x1) when the step has not evaluated it, then its own.
    const DENSE_STAGES: usize;
    /// ā rows (row s has s entries) and c of every stage, the dense output's included.
    const A: &'static [&'static [f64]];
    const C: &'static [f64];
    const BBAR: &'static [f64];
    const B: &'static [f64];
    /// b̄ − b̂̄ and b − b̂: the difference of the two solutions, the error estimate.
    const EBAR: &'static [f64];
    const E: &'static [f64];
    /// The continuous extension x(θ) = x + θ h v + h² Σ_i B̄_i(θ) g_i,
    /// v(θ) = v + h Σ_i B_i(θ) g_i, as B̄_i(θ) = Σ_k PX[k][i] θ^k. The pairs' velocity weights
    /// are the derivative, B_i = dB̄_i/dθ (v(θ) = x'(θ)/h; for DPRKN6 the paper's own velocity
    /// weights are, to the 80 digits `tools/rkn_tables.py` checks), so they are not tabulated.
    const PX: &'static [&'static [f64]];
    const EXPONENT: f64;
}

/// Stage `s`: row s of `k` (n wide) gets a(x_s), x_s = x + c_s h v + h² Σ_{j<s} ā_sj g_j from
/// `base` = (x, v). The velocity passed to the force is v (a(x) does not read it). With one
/// coordinate, the previous stage's acceleration comes in `previous` (used when the row's last
/// entry is that stage's: DPRKN12's dense stages skip each other) and this one's goes out as the
/// return value, in registers (0 otherwise): through memory, each would wait on the stages'
/// chain for its store to be forwarded to its load.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn rkn_stage<S: SecondOrderSystem, T: RknTableau, W: Width>(
    sys: &S,
    w: W,
    k: &mut [f64],
    xs: &mut [f64],
    base: &[f64],
    s: usize,
    h: f64,
    previous: f64,
) -> f64 {
    let n2 = w.get();
    let n = n2 / 2;
    let (a, cs) = (T::A[s], T::C[s]);
    let (done, rest) = k.split_at_mut(s * n);
    let (x, v) = (&base[..n], &base[n..n2]);
    // The newest acceleration the row uses is added last, on its own: the rest does not wait
    // for the previous stage's force, so one multiply-add separates two force evaluations on
    // the stages' dependent chain, which is what a Nyström step's time is made of.
    let (newest, earlier) = a.split_last().expect("a stage after the first");
    let h2_newest = h * h * newest;
    let latest = &done[earlier.len() * n..a.len() * n];
    for i in 0..n {
        let mut acc = 0.0;
        for (j, aj) in earlier.iter().enumerate() {
            acc += aj * done[j * n + i];
        }
        let newest = if n == 1 && a.len() == s {
            previous
        } else {
            latest[i]
        };
        xs[i] = (x[i] + h * (cs * v[i] + h * acc)) + h2_newest * newest;
    }
    sys.acceleration(&xs[..n], v, &mut rest[..n]);
    if n == 1 { rest[0] } else { 0.0 }
}

/// The most stages, the dense output's included, a pair may have (dprkn12 has 23).
const MAX_STAGES: usize = 32;

/// The most rows of dense-output coefficients a pair may have (dprkn12 has the most).
const MAX_CONT_ROWS: usize = 16;

/// An embedded RKN pair on the shared driver. Error per step: the two solutions' difference in
/// x (h² Σ (b̄ − b̂̄) g) and v (h Σ (b − b̂) g), each scaled by rtol (max(|y|, |y_new|) + 1),
/// RMS over the components, as the other pairs; controller 0.9 err^(-α) err_old^0.04 with
/// α = 1/(q + 1) − 0.03, q the embedded order.
#[derive(Clone, Copy, Debug)]
pub struct Nystrom<T>(std::marker::PhantomData<T>);

impl<T: RknTableau> Nystrom<T> {
    /// Whether stage j has a weight in the dense output at all (DPRKN12's stages 1–5 have none).
    const DENSE_USES: [bool; MAX_STAGES] = {
        let mut used = [false; MAX_STAGES];
        let mut p = 0;
        while p < T::PX.len() {
            let mut j = 0;
            while j < T::PX[p].len() {
                used[j] = used[j] || T::PX[p][j] != 0.0;
                j += 1;
            }
            p += 1;
        }
        used
    };
}

impl<T: RknTableau> Pair for Nystrom<T> {
    const K_ROWS: usize = T::STAGES + T::DENSE_STAGES;
    const ACCELERATION_ROWS: bool = true;
    const FSAL_ROW: usize = if T::FSAL { T::STAGES - 1 } else { T::STAGES };
    const FSAL_IN_TRIAL: bool = T::FSAL;
    const CONT_ROWS: usize = {
        assert!(T::PX.len() <= MAX_CONT_ROWS);
        T::PX.len()
    };
    const EXPONENT: f64 = T::EXPONENT;
    const BETA: f64 = 0.04;
    const TRIAL_EVALS: u64 = T::STAGES as u64 - 1;
    const DENSE_EVALS: u64 = T::DENSE_STAGES as u64 - if T::FSAL { 0 } else { 1 };

    #[inline(always)]
    fn trial<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W, h: f64) -> f64 {
        let n2 = w.get();
        let n = n2 / 2;
        let last = if T::FSAL { T::STAGES - 1 } else { T::STAGES };
        let mut g = c.k[0];
        for s in 1..last {
            g = rkn_stage::<S, T, W>(sys, w, &mut c.k, &mut c.yt, &c.y, s, h, g);
        }
        let rtol = c.rtol;
        let (y, ynew, k) = (&c.y[..n2], &mut c.y_old[..n2], &c.k[..T::STAGES * n]);
        // The new position (the FSAL stage's argument, same arithmetic as `rkn_stage`).
        let h2_newest = h * h * T::BBAR[last - 1];
        for i in 0..n {
            let mut acc = 0.0;
            for j in 0..last - 1 {
                acc += T::BBAR[j] * k[j * n + i];
            }
            let newest = if n == 1 { g } else { k[(last - 1) * n + i] };
            ynew[i] = (y[i] + h * (y[n + i] + h * acc)) + h2_newest * newest;
        }
        if T::FSAL {
            let (x1, v) = (&ynew[..n], &y[n..n2]);
            sys.acceleration(x1, v, &mut c.k[last * n..(last + 1) * n]);
        }
        let k = &c.k[..T::STAGES * n];
        let mut err2 = 0.0;
        for i in 0..n {
            let (mut bv, mut ex, mut ev) = (0.0, 0.0, 0.0);
            for j in 0..T::STAGES {
                let g = k[j * n + i];
                bv += T::B[j] * g;
                ex += T::EBAR[j] * g;
                ev += T::E[j] * g;
            }
            ynew[n + i] = y[n + i] + h * bv;
            let sx = rtol * (y[i].abs().max(ynew[i].abs()) + 1.0);
            let sv = rtol * (y[n + i].abs().max(ynew[n + i].abs()) + 1.0);
            let (ex, ev) = (h * h * ex / sx, h * ev / sv);
            err2 += ex * ex + ev * ev;
        }
        (err2 / n2 as f64).sqrt()
    }

    /// The dense output's own stages, then per component the polynomial in θ of the position
    /// and of the velocity, x(θ) = Σ_p r_p θ^p in the first half of cont row p and v(θ) in the
    /// second. Written in differences g_j − g_0 (Σ_i B̄_i(θ) = θ²/2, Σ_i B_i(θ) = θ), so that
    /// the weights' rounding multiplies O(h) differences, not the accelerations.
    #[inline(always)]
    fn build_dense<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W) {
        let n2 = w.get();
        let n = n2 / 2;
        let h = c.h_last;
        let first_own = Self::FSAL_ROW + 1;
        let mut g = c.k[(first_own - 1) * n];
        for s in first_own..Self::K_ROWS {
            g = rkn_stage::<S, T, W>(sys, w, &mut c.k, &mut c.yt, &c.y_old, s, h, g);
        }
        let rows = Self::CONT_ROWS;
        let (k, cont, y0) = (
            &c.k[..Self::K_ROWS * n],
            &mut c.cont[..rows * n2],
            &c.y_old[..n2],
        );
        for i in 0..n {
            let g0 = k[i];
            // Stage by stage into every row's sum at once, so that the rows' sums (independent
            // chains of dependent additions) run side by side; each row adds its terms in stage
            // order.
            let mut rx = [0.0; MAX_CONT_ROWS];
            for j in 1..Self::K_ROWS {
                if !Self::DENSE_USES[j] {
                    continue;
                }
                let d = k[j * n + i] - g0;
                for p in 0..rows {
                    rx[p] += T::PX[p][j] * d;
                }
            }
            // v(θ) = x'(θ)/h: the velocity's row p is (p + 1) times the position's row p + 1,
            // over h (half the work of summing the velocity's own weights).
            for p in 0..rows {
                cont[p * n2 + i] = h * h * rx[p];
                let next = if p + 1 < rows { rx[p + 1] } else { 0.0 };
                cont[p * n2 + n + i] = h * ((p + 1) as f64 * next);
            }
            cont[i] += y0[i];
            cont[n2 + i] += h * y0[n + i];
            cont[2 * n2 + i] += 0.5 * h * h * g0;
            cont[n + i] += y0[n + i];
            cont[n2 + n + i] += h * g0;
        }
    }

    #[inline(always)]
    fn interpolate<W: Width>(c: &Core, w: W, th: f64, out: &mut [f64]) {
        let n2 = w.get();
        let rows = Self::CONT_ROWS;
        let cont = &c.cont[..rows * n2];
        for i in 0..n2 {
            let mut p = cont[(rows - 1) * n2 + i];
            for q in (0..rows - 1).rev() {
                p = p * th + cont[q * n2 + i];
            }
            out[i] = p;
        }
    }
}

/// Dormand, El-Mikkawy & Prince's RKN6(4)6FD: six stages, the last a(x1) (first same as last,
/// five evaluations per step), its continuous extension of order 6 in x and 5 in v at no cost.
#[derive(Clone, Copy, Debug)]
pub struct Dprkn6;

impl RknTableau for Dprkn6 {
    const STAGES: usize = 6;
    const FSAL: bool = true;
    const DENSE_STAGES: usize = 0;
    const A: &'static [&'static [f64]] = t::A6;
    const C: &'static [f64] = &t::C6;
    const BBAR: &'static [f64] = &t::BBAR6;
    const B: &'static [f64] = &t::B6;
    const EBAR: &'static [f64] = &t::EBAR6;
    const E: &'static [f64] = &t::E6;
    const PX: &'static [&'static [f64]] = t::PX6;
    /// The embedded solution is of order 4.
    const EXPONENT: f64 = 1.0 / 5.0 - 0.75 * 0.04;
}

/// Dormand, El-Mikkawy & Prince's RKN8(6)9FM: nine stages, the last a(x1) (first same as last,
/// eight evaluations per step). Its dense output (not in the paper) is a Hermite–Birkhoff
/// interpolant through x, v, a at both ends and a at interior points found by bootstrapping,
/// built in `rkn_tables` (order stated there and in the registry).
#[derive(Clone, Copy, Debug)]
pub struct Dprkn8;

impl RknTableau for Dprkn8 {
    const STAGES: usize = 9;
    const FSAL: bool = true;
    const DENSE_STAGES: usize = t::C8.len() - 9;
    const A: &'static [&'static [f64]] = t::A8;
    const C: &'static [f64] = &t::C8;
    const BBAR: &'static [f64] = &t::BBAR8;
    const B: &'static [f64] = &t::B8;
    const EBAR: &'static [f64] = &t::EBAR8;
    const E: &'static [f64] = &t::E8;
    const PX: &'static [&'static [f64]] = t::PX8;
    /// The embedded solution is of order 6.
    const EXPONENT: f64 = 1.0 / 7.0 - 0.75 * 0.04;
}

/// Dormand, El-Mikkawy & Prince's RKN12(10)17M: seventeen stages (sixteen evaluations after the
/// first, plus a(x1), which is the next step's first). Its dense output (not in the paper) is a
/// Hermite–Birkhoff interpolant through x, v, a at both ends and a at interior points found by
/// bootstrapping, built in `rkn_tables` (order stated there and in the registry).
#[derive(Clone, Copy, Debug)]
pub struct Dprkn12;

impl RknTableau for Dprkn12 {
    const STAGES: usize = 17;
    const FSAL: bool = false;
    const DENSE_STAGES: usize = t::C12.len() - 17;
    const A: &'static [&'static [f64]] = t::A12;
    const C: &'static [f64] = &t::C12;
    const BBAR: &'static [f64] = &t::BBAR12;
    const B: &'static [f64] = &t::B12;
    const EBAR: &'static [f64] = &t::EBAR12;
    const E: &'static [f64] = &t::E12;
    const PX: &'static [&'static [f64]] = t::PX12;
    /// The embedded solution is of order 10.
    const EXPONENT: f64 = 1.0 / 11.0 - 0.75 * 0.04;
}
