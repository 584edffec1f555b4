//! Adaptive embedded Runge–Kutta: Dormand–Prince 5(4) with error control and dense output.

use super::SecondOrderSystem;
use super::dense::{Core, Pair, Width, hairer_dense, stage};

mod tables;
use tables::{A, D, E};

/// Dormand–Prince 5(4) as a [`Pair`] of the shared dense-output driver: steps of its own size,
/// error per step ≤ 1 when scaled by rtol (max(|y|, |y_new|) + 1) per component (RMS), the
/// state at each sample time from its dense output; a sample time never ends a step. The
/// seventh stage, at the new solution, is part of the error estimate, so it is evaluated in
/// every trial (6 evaluations per step tried, accepted or not; the first step 7). Controller as
/// `dopri5.f`'s defaults: 0.9 err^(-0.17) err_old^0.04 (Lund's stabilisation, β = 0.04),
/// clamped to [0.2, 10] times the step.
#[derive(Clone, Copy, Debug)]
pub struct Dopri5;

impl Pair for Dopri5 {
    const K_ROWS: usize = 7;
    const FSAL_ROW: usize = 6;
    const FSAL_IN_TRIAL: bool = true;
    const CONT_ROWS: usize = 5;
    const EXPONENT: f64 = 0.2 - 0.75 * 0.04;
    const BETA: f64 = 0.04;
    const FAC_MIN: f64 = 0.2;
    const FAC_MAX: f64 = 10.0;
    const TRIAL_EVALS: u64 = 6;
    const DENSE_EVALS: u64 = 0;

    #[inline(always)]
    fn trial<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W, h: f64) -> f64 {
        let n2 = w.get();
        for s in 1..6 {
            stage(sys, w, &mut c.k, &mut c.yt, &c.y, &A[s][..s], h);
        }
        // The 5th-order solution, then the 7th stage there.
        stage(sys, w, &mut c.k, &mut c.y_old, &c.y, &A[6][..6], h);
        let rtol = c.rtol;
        let mut err2 = 0.0;
        let (y, ynew, k) = (&c.y[..n2], &c.y_old[..n2], &c.k[..7 * n2]);
        for i in 0..n2 {
            let mut e = 0.0;
            for (j, ej) in E.iter().enumerate() {
                e += ej * k[j * n2 + i];
            }
            let sk = rtol * (y[i].abs().max(ynew[i].abs()) + 1.0);
            err2 += (h * e / sk) * (h * e / sk);
        }
        (err2 / n2 as f64).sqrt()
    }

    #[inline(always)]
    fn build_dense<S: SecondOrderSystem, W: Width>(c: &mut Core, _sys: &S, w: W) {
        hairer_dense(c, w.get(), 6, &[D]);
    }

    #[inline(always)]
    fn interpolate<W: Width>(c: &Core, w: W, th: f64, out: &mut [f64]) {
        let n2 = w.get();
        let th1 = 1.0 - th;
        let cont = &c.cont[..5 * n2];
        for i in 0..n2 {
            let r = |q: usize| cont[q * n2 + i];
            out[i] = r(0) + th * (r(1) + th1 * (r(2) + th * (r(3) + th1 * r(4))));
        }
    }
}
