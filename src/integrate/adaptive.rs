//! Adaptive embedded Runge–Kutta: Dormand–Prince 5(4) with error control and dense output.

use super::SecondOrderSystem;
use super::dense::{Core, Pair, Width, hairer_dense, stage};

/// Butcher tableau (Dormand & Prince 1980). The system is autonomous, so the stage times
/// (c = 0, 1/5, 3/10, 4/5, 8/9, 1, 1) are not needed.
pub(super) const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Fifth-order weights are A[6] (first-same-as-last); these are 5th minus 4th order.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Dense output (Hairer's `dopri5.f`, `CONTD5`): with rcont1..5 = y_old, y - y_old,
/// h k1 - (y - y_old), (y - y_old) - h k7 - rcont3, h Σ D_j k_j,
/// y(t_old + θ h) = r1 + θ (r2 + (1-θ) (r3 + θ (r4 + (1-θ) r5))); fourth order, no extra stage.
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

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
