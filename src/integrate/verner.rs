//! Verner's "most efficient" 9(8) pair with its 8th-order interpolant (`vern9`).
//!
//! Source: J. H. Verner, the table "RKV98.IIa.Efficient.00000034399.240407.BetterEfficient" on
//! his page <https://www.sfu.ca/~jverner/> (a 16-stage 9(8) pair; 5 more stages for an
//! interpolant of order 8: stage 16 is f(y_new), stages 17-20 are evaluated only when a sample
//! falls inside the step). The web page was not reachable from this machine; the coefficients
//! below are the ones of `differential-equations` 0.6.1 (`ButcherTableau::rkv988e`, which cites
//! that page), printed as shortest round-trip f64 literals by a script, and checked
//! independently of that crate: `tests/order_conditions` evaluates all 719 + 486 rooted-tree
//! conditions without rounding on these doubles (the ninth-order weights hold every condition of
//! order ≤ 9 to < 4e-16, not those of order 10; the eighth-order ones every condition of order ≤ 8),
//! the interpolant the conditions of order ≤ 8 at every θ, and `tests/integrators.rs` measures the
//! order and the period on the pendulum. (Not Julia's `Vern9`, which is Verner's earlier 2010
//! table with c2 = 0.03462 and a 9th-order interpolant of 10 extra stages.)
//!
//! The error estimate is y9 - y8 (the embedded weights), scaled per component by
//! rtol (max(|y|, |y_new|) + 1), RMS over the components, as in dop853.f; the controller is the
//! shared one ([`super::dense`]) with exponent 1/9. One accepted step costs 16 evaluations (15
//! stages and f(y_new), which is the next step's first); a rejected one 15; the interpolant 4 more.

#![allow(clippy::excessive_precision, clippy::unreadable_literal)]

use super::SecondOrderSystem;
use super::dense::{Core, Pair, Width, stage};

mod tables;
use tables::{A, B, BI, E};

/// Verner's 9(8) as a [`Pair`] of the shared dense-output driver.
#[derive(Clone, Copy, Debug)]
pub struct Vern9;

impl Pair for Vern9 {
    const K_ROWS: usize = 21;
    const FSAL_ROW: usize = 16;
    const CONT_ROWS: usize = 8;
    const EXPONENT: f64 = 0.7 / 9.0;
    const BETA: f64 = 0.4 / 9.0;
    const TRIAL_EVALS: u64 = 15;
    const DENSE_EVALS: u64 = 4;

    #[inline(always)]
    fn trial<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W, h: f64) -> f64 {
        let n2 = w.get();
        for s in 1..16 {
            stage(sys, w, &mut c.k, &mut c.yt, &c.y, &A[s][..s], h);
        }
        let rtol = c.rtol;
        let mut err2 = 0.0;
        let (y, ynew, k) = (&c.y[..n2], &mut c.y_old[..n2], &c.k[..16 * n2]);
        for i in 0..n2 {
            let (mut b, mut e) = (0.0, 0.0);
            for j in 0..16 {
                let kj = k[j * n2 + i];
                b += B[j] * kj;
                e += E[j] * kj;
            }
            ynew[i] = y[i] + h * b;
            let sk = rtol * (y[i].abs().max(ynew[i].abs()) + 1.0);
            err2 += (h * e / sk) * (h * e / sk);
        }
        (err2 / n2 as f64).sqrt()
    }

    /// The extra stages 17-20, then the interpolant as a polynomial in θ per component:
    /// y(t_old + θ h) = y_old + h (θ k_0 + Σ_{j≥1} b_j(θ) (k_j - k_0)) ([`dense_weights`]'s form),
    /// = y_old + θ (r_0 + θ (r_1 + … + θ r_7)), r_p = h Σ_{j≥1} BI[j][p] (k_j - k_0) (+ h k_0 for
    /// p = 0): built once per step, so each sample costs one Horner evaluation.
    #[inline(always)]
    fn build_dense<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W) {
        let n2 = w.get();
        let h = c.h_last;
        for s in 17..21 {
            stage(sys, w, &mut c.k, &mut c.yt, &c.y_old, &A[s][..s], h);
        }
        let (k, cont) = (&c.k[..21 * n2], &mut c.cont[..8 * n2]);
        for i in 0..n2 {
            let k0 = k[i];
            let mut r = [0.0; 8];
            for j in 1..21 {
                let d = k[j * n2 + i] - k0;
                if BI[j] != [0.0; 8] {
                    for p in 0..8 {
                        r[p] += BI[j][p] * d;
                    }
                }
            }
            r[0] += k0;
            for p in 0..8 {
                cont[p * n2 + i] = h * r[p];
            }
        }
    }

    #[inline(always)]
    fn interpolate<W: Width>(c: &Core, w: W, th: f64, out: &mut [f64]) {
        let n2 = w.get();
        let (cont, y0) = (&c.cont[..8 * n2], &c.y_old[..n2]);
        for i in 0..n2 {
            let mut p = cont[7 * n2 + i];
            for q in (0..7).rev() {
                p = p * th + cont[q * n2 + i];
            }
            out[i] = y0[i] + th * p;
        }
    }
}
