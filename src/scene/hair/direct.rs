//! The direct solver of a strand's length constraints: all of them together, by Newton steps on
//! the Lagrange multipliers (the chain case of Deul, Kugelstadt, Weiler & Bender 2018, "Direct
//! position-based solver for stiff rods"; Han & Harada 2013, "Tridiagonal matrix formulation for
//! inextensible hair strand simulation"; the update is Goldenthal et al.'s 2007 fast projection).
//!
//! Constraint j joins nodes j and j+1: C_j(x) = |x_{j+1} - x_j| - ℓ0, gradient ±u_j (the unit
//! segment direction). With unit masses and the root held (inverse mass 0), one step solves
//!
//! (J W Jᵀ) δλ = -C,   x += W Jᵀ δλ,
//!
//! where J W Jᵀ is tridiagonal: diagonal 1 for the root's segment and 2 elsewhere, off-diagonal
//! -u_j·u_{j+1}. Every pivot of the Thomas elimination is ≥ 1 (|u_j·u_{j+1}| ≤ 1), so the solve
//! needs no pivoting and cannot break down. O(nodes) per step; the back substitution applies the
//! position update and pushes each node out of the head as it goes. The run solves eight strands
//! at once in the lanes of a vector register ([`super::lanes`]).
//!
//! The Newton steps only measure the tensions (their summed multipliers); the positions are then
//! solved with those tensions acting along the end-of-step segments ([`tension_solve_lanes`],
//! which says why).
//!
//! The safeguard (chosen by measurement, see `tests/hair.rs`): from a prediction stretched several
//! times over at 60 Hz the Newton iterates converge quadratically but from far away, so after
//! the `iterations` Newton steps one root-to-tip pass places every node at rest length from its
//! parent and outside the head (the follow-the-leader projection), so length and collision both
//! hold exactly at the end of every step. That pass moves nodes by what the solves left, which
//! is not small where the motion is violent; docs/results.md measures how much, and why the
//! default is two Newton steps.

use glam::DVec3;

use super::StepContext;
use super::simd::{F8, V3};

/// One Newton step of the chain's length constraints on one strand `x` (root x[0] held, no
/// collision): the strand in every lane of [`newton_lanes`], the kernel the run steps eight
/// strands with. Returns the largest |C_j|/ℓ0 before the step.
pub fn newton_step(x: &mut [DVec3], l0: f64) -> f64 {
    let before = residual(x, l0);
    let mut lanes: Vec<V3> = x.iter().map(|p| V3::splat(*p)).collect();
    let n = x.len();
    let (mut u, mut cp, mut dp) = (vec![V3::default(); n], vec![F8::ZERO; n], vec![F8::ZERO; n]);
    let mut mu = vec![F8::ZERO; n];
    newton_lanes(
        &mut lanes, &mut u, &mut cp, &mut dp, &mut mu, l0, true, None,
    );
    for (p, l) in x.iter_mut().zip(&lanes) {
        *p = l.lane(0);
    }
    before
}

/// Largest |C_j|/ℓ0 of a strand.
pub fn residual(x: &[DVec3], l0: f64) -> f64 {
    x.windows(2)
        .map(|w| ((w[1] - w[0]).length() - l0).abs() / l0)
        .fold(0.0, f64::max)
}

/// One Newton step of the chain's length constraints on eight strands (as
/// [`super::direct`] describes it), each lane one strand; the multipliers are added to `mu`
/// (as tensions, -λ). With `move_nodes` the step is applied to `x` (and with `collide` every
/// moved node is pushed out of the head); without, only the tensions are wanted (the last step
/// before the tension solve, which places every node itself).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn newton_lanes(
    x: &mut [V3],
    u: &mut [V3],
    cp: &mut [F8],
    dp: &mut [F8],
    mu: &mut [F8],
    l0: f64,
    move_nodes: bool,
    collide: Option<&StepContext>,
) {
    let m = x.len() - 1;
    let l0 = F8::splat(l0);
    let zero = F8::ZERO;
    let unit_z = V3::splat(DVec3::Z);
    let (one, two) = (F8::splat(1.0), F8::splat(2.0));
    for j in 0..m {
        // Keeps LLVM's loop vectoriser from vectorising across segments (it would gather
        // lanes of four segments, 3× the instructions); the lane operations are vectors already.
        let j = std::hint::black_box(j);
        let d = x[j + 1] - x[j];
        let len = d.length();
        // One division per segment (d·(1/ℓ), not glam's d/ℓ per component).
        u[j] = V3::select(len.test(zero, |a, b| a > b), d * (one / len), unit_z);
        dp[j] = -(len - l0);
    }
    let (mut o_prev, mut cp_prev, mut dp_prev) = (zero, zero, zero);
    for j in 0..m {
        let diag = if j == 0 { one } else { two };
        let inv = one / (diag - o_prev * cp_prev);
        let o = if j + 1 < m { -u[j].dot(u[j + 1]) } else { zero };
        let d = (dp[j] - o_prev * dp_prev) * inv;
        let c = o * inv;
        cp[j] = c;
        dp[j] = d;
        (o_prev, cp_prev, dp_prev) = (o, c, d);
    }
    let mut lambda_next = zero;
    let mut u_next = V3::default();
    for j in (0..m).rev() {
        let lambda = dp[j] - cp[j] * lambda_next;
        mu[j] = mu[j] - lambda;
        if move_nodes {
            x[j + 1] = x[j + 1] + (u[j] * lambda - u_next * lambda_next);
            if let Some(ctx) = collide {
                ctx.collide_lanes(&mut x[j + 1]);
            }
        }
        lambda_next = lambda;
        u_next = u[j];
    }
}

/// The positions that the segment tensions `mu` (accumulated by [`newton_lanes`]) give when
/// they act along the segments at the *end* of the step: the stationarity condition of the
/// closest-point projection of the prediction `q` onto the constraints,
///
/// x_k - q_k = -(μ_{k-1}/ℓ0)(x_k - x_{k-1}) + (μ_k/ℓ0)(x_{k+1} - x_k),   x_0 held,
///
/// a symmetric tridiagonal system in the nodes (the same for x, y and z), solved by the Thomas
/// algorithm. Why: the Newton steps correct along the segment directions of the prediction,
/// which treats the tension's transverse stiffness explicitly (stable only for ω dt < 2 with ω
/// ≈ 2 √(T/(m ℓ0)), the root segment's T carrying the whole strand: ω dt ≈ 3.3 at 16 nodes and
/// 60 Hz, so strands hanging still zig-zag for ever). Here it is implicit (backward Euler in the
/// transverse direction: every mode is damped, none grows). Tensions are clamped at zero (a
/// compressed segment adds no coupling; the root-to-tip finish restores its length), so the
/// matrix is diagonally dominant and the elimination cannot break down. `c` is scratch.
#[inline(always)]
pub(super) fn tension_solve_lanes(x: &mut [V3], q: &[V3], mu: &[F8], c: &mut [F8], l0: f64) {
    let m = x.len() - 1;
    let zero = F8::ZERO;
    let one = F8::splat(1.0);
    let inv_l0 = F8::splat(1.0 / l0);
    // Coupling w_j = max(μ_j, 0)/ℓ0 of segment j (nodes j, j+1); node k has b_k = 1 + w_{k-1} +
    // w_k (w_m = 0), off-diagonals -w.
    let w = |j: usize| {
        if j < m {
            mu[j].max(zero) * inv_l0
        } else {
            zero
        }
    };
    // Forward elimination: c[k] = c'_k, x[k] = d'_k.
    let mut w_prev = w(0);
    let mut c_prev = zero;
    let mut d_prev = x[0];
    for k in 1..=m {
        let w_k = w(k);
        let inv = one / (one + w_prev + w_k - w_prev * c_prev);
        let d = (q[k] + d_prev * w_prev) * inv;
        let ck = w_k * inv;
        c[k] = ck;
        x[k] = d;
        (w_prev, c_prev, d_prev) = (w_k, ck, d);
    }
    // Back substitution: x_k = d'_k + c'_k x_{k+1} (the off-diagonal is -w).
    for k in (1..m).rev() {
        x[k] = x[k] + x[k + 1] * c[k];
    }
}
