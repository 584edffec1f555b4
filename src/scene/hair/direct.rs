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
//! The tension solve ([`super::lanes::tension_solve_lanes`]): Newton's corrections point along
//! the predicted segments, an explicit step on the tension's transverse stiffness (ω dt ≈ 3.3 at
//! the root of a 16-node strand at 60 Hz, beyond the limit 2: hanging strands zig-zagged for
//! ever). So the Newton steps only measure the tensions (their summed multipliers), and the
//! positions are then solved with those tensions acting along the end-of-step segments: the
//! stationarity condition of the closest-point projection, a second tridiagonal system, which
//! damps every transverse mode instead (backward Euler). It costs ~8% more CPU per step.
//!
//! The safeguard (chosen by measurement, see the tests): from a prediction stretched several
//! times over at 60 Hz the Newton iterates converge quadratically but from far away, so after
//! the `iterations` Newton steps one root-to-tip pass places every node at rest length from its
//! parent and outside the head (the follow-the-leader projection), so length and collision both
//! hold exactly at the end of every step. That pass moves nodes by what the solves left, which
//! is not small where the motion is violent. Measured (100 strands, 8 s, 2 Newton steps; the
//! worst segment of each group of four strands, averaged over steps, then the worst of the run):
//! default tour 1.7e-2 (worst 0.99 ℓ0), gusty 30 m/s² wind 4.9e-2 (2.7), shake 0.15 (3.5; the
//! roots move by ~2 segments a frame), 64 nodes 2.0e-2 (3.4). Newton steps alone left 3.9e-2,
//! 0.39, 0.22 and 0.18; one Newton step with the tension solve leaves 1.7e-2, 6.0e-2, 0.20 and
//! 2.5e-2, which is why the default stays at two.

use glam::DVec3;

use super::lanes::{F8, V3, newton_lanes};

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

#[cfg(test)]
mod tests {
    use super::*;

    /// A zig-zag chain stretched to `factor` times its length, root at the origin.
    fn stretched(n: usize, l0: f64, factor: f64) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let side = if k % 2 == 0 { 0.0 } else { 0.3 };
                DVec3::new(k as f64 * l0 * factor, side * l0 * factor, 0.0)
            })
            .collect()
    }

    /// On a short chain the Newton steps converge quadratically: 5.4e-2, 2.2e-2, 2.8e-3, 2.5e-5,
    /// 2.8e-9 of ℓ0 (the same figures as a dense numpy solve of the same system).
    #[test]
    fn newton_converges_quadratically_on_a_short_chain() {
        let (n, l0) = (8, 1.0);
        let mut x = stretched(n, l0, 1.01);
        for _ in 0..4 {
            newton_step(&mut x, l0);
        }
        let r = residual(&x, l0);
        assert!(r < 1e-8, "residual after 4 steps {r:e}");
        assert_eq!(x[0], DVec3::ZERO, "the root is held");
    }

    /// The known catch, measured: on 32 nodes folded into the same zig-zag, plain Newton stalls
    /// (2.3e-2, 1.3e-2, 4.4e-2, 1.5e-2 of ℓ0 after 1 to 4 steps; numpy agrees), which is why
    /// the solver ends every step with the exact root-to-tip finish.
    #[test]
    fn newton_alone_stalls_on_a_long_folded_chain() {
        let (n, l0) = (32, 0.015);
        let mut x = stretched(n, l0, 1.01);
        for _ in 0..4 {
            newton_step(&mut x, l0);
        }
        let r = residual(&x, l0);
        assert!(r > 1e-3 && r < 1e-1, "residual after 4 steps {r:e}");
    }
}
