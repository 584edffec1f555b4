//! The driver shared by the embedded pairs with dense output (dopri5, DOP853, Verner 9(8)):
//! the method steps on its own grid, chosen by error control, and the state at each sample time
//! comes from the method's interpolant over the step that contains it, so sample times never
//! force a step to end. Each pair ([`Pair`]) gives its stages, error estimate and interpolant;
//! the stepping, the controller, first-same-as-last and the counters are here, once.
//!
//! Width: the state y = (x, v) has n2 = 2n components. For the one-coordinate pendulum the
//! pair's loops are instantiated with n2 = 2 known at compile time ([`Fixed`]), so they unroll
//! with no loop over a runtime length; any other size runs the same code with [`Dynamic`].

use super::{MethodOptions, SecondOrderSystem, State};

/// The number of state components the stage loops run over.
pub(crate) trait Width: Copy {
    fn get(self) -> usize;
}
/// A width known at compile time.
#[derive(Clone, Copy)]
pub(crate) struct Fixed<const N: usize>;
impl<const N: usize> Width for Fixed<N> {
    #[inline(always)]
    fn get(self) -> usize {
        N
    }
}
/// A width known at run time.
#[derive(Clone, Copy)]
pub(crate) struct Dynamic(pub usize);
impl Width for Dynamic {
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
}

/// An embedded explicit Runge–Kutta pair with an interpolant.
pub(crate) trait Pair {
    /// Rows of stage derivatives kept (the step's and the interpolant's extra stages).
    const K_ROWS: usize;
    /// Whether a row holds the acceleration a alone (n wide: the Nyström pairs, whose stages
    /// need nothing else) instead of f = (v, a) (2n wide).
    const ACCELERATION_ROWS: bool = false;
    /// The row that holds f(y_new) after an accepted step (the next step's first stage).
    const FSAL_ROW: usize;
    /// Whether `trial` evaluates f(y_new) itself (into the FSAL row), because its error estimate
    /// needs it (dopri5); otherwise the driver evaluates it once a step is accepted.
    const FSAL_IN_TRIAL: bool = false;
    /// Rows of dense-output coefficients per component.
    const CONT_ROWS: usize;
    /// The controller's exponent 1/q, q the order of the error estimate's leading term plus one
    /// (1/8 in dop853.f; 1/9 for Verner's pair, whose estimate is that of its 8th-order solution).
    const EXPONENT: f64;
    /// The PI controller's weight of the previous accepted step's error (0: the plain
    /// controller of dop853.f).
    const BETA: f64;
    /// The step may shrink and grow at most by these factors (dop853.f's 1/3 and 6).
    const FAC_MIN: f64 = 1.0 / 3.0;
    const FAC_MAX: f64 = 6.0;
    /// Evaluations of one trial step after the first stage, and of the dense output's extra stages.
    const TRIAL_EVALS: u64;
    const DENSE_EVALS: u64;
    /// Stages 1.. of a step of size h from `c.y` (stage 0 in `k[0]`), the new solution into
    /// `c.y_old`; returns the error estimate scaled by the tolerance (accept when ≤ 1).
    fn trial<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W, h: f64) -> f64;
    /// The extra stages and coefficients of the last accepted step (from `c.y_old` to `c.y`).
    fn build_dense<S: SecondOrderSystem, W: Width>(c: &mut Core, sys: &S, w: W);
    /// The interpolant at θ = (t - t_old)/h_last into `out` (n2 components).
    fn interpolate<W: Width>(c: &Core, w: W, theta: f64, out: &mut [f64]);
}

/// The stepper's state, shared by every pair.
#[derive(Clone, Debug)]
pub(crate) struct Core {
    pub rtol: f64,
    h_max: f64,
    pub n2: usize,
    /// The internal state y = (x, v) at the end of the last accepted step, time `t`.
    pub y: Vec<f64>,
    /// The state at the start of the last accepted step (time `t_old`); the trial y_new while a
    /// step is attempted.
    pub y_old: Vec<f64>,
    /// K_ROWS stage derivatives × n2: k[s] = f(stage s) = (v, a); or K_ROWS × n accelerations
    /// (`Pair::ACCELERATION_ROWS`).
    pub k: Vec<f64>,
    /// A stage's argument.
    pub yt: Vec<f64>,
    /// Dense-output coefficients of the last accepted step, CONT_ROWS × n2.
    pub cont: Vec<f64>,
    /// Whether the extra stages and `cont` are built for the last accepted step.
    dense_ready: bool,
    /// Internal time, start of the last accepted step, its size, and the controller's next step.
    /// The times are sums of the steps taken, kept with their rounding error (`t_low`,
    /// `t_old_low`: the exact sum is t + t_low): a plain sum drifts from the time the state is
    /// at, step by step, and the interpolant would be read at the wrong place (a phase error
    /// that grows with the number of steps; see `a_million_steps_keep_their_time`).
    t: f64,
    t_low: f64,
    t_old: f64,
    t_old_low: f64,
    pub h_last: f64,
    h: f64,
    /// Sample steps asked for so far (the reported time is `samples × dt`).
    samples: u64,
    /// 0: k[0] must be evaluated at y; 1: k[0] holds f(y); 2: f(y) is in the FSAL row (after an
    /// accepted step, kept there until the dense output no longer needs the old stages).
    fsal: u8,
    last_rejected: bool,
    /// ln of the error of the last accepted step (for the PI controller), ln 1e-4 at the start
    /// as Hairer's FACOLD.
    ln_err_old: f64,
    pub accepted: u64,
    pub rejected: u64,
}

/// Hairer's dense output of the last accepted step (`dopri5.f`, `dop853.f`), per component:
/// y_old, Δy, h f_old − Δy and Δy − h f_new − (h f_old − Δy), f_new at the stage `fsal_row`,
/// then h Σ_j d_j k_j for each row d of `d`.
#[inline(always)]
pub(crate) fn hairer_dense<const S: usize>(
    c: &mut Core,
    n2: usize,
    fsal_row: usize,
    d: &[[f64; S]],
) {
    let h = c.h_last;
    let rows = 4 + d.len();
    let (k, cont, y, y_old) = (&c.k[..S * n2], &mut c.cont[..rows * n2], &c.y, &c.y_old);
    for i in 0..n2 {
        let ydiff = y[i] - y_old[i];
        let bspl = h * k[i] - ydiff;
        cont[i] = y_old[i];
        cont[n2 + i] = ydiff;
        cont[2 * n2 + i] = bspl;
        cont[3 * n2 + i] = ydiff - h * k[fsal_row * n2 + i] - bspl;
        for (r, dr) in d.iter().enumerate() {
            let mut acc = 0.0;
            for j in 0..S {
                acc += dr[j] * k[j * n2 + i];
            }
            cont[(4 + r) * n2 + i] = h * acc;
        }
    }
}

/// k = f(y) = (v, a(x, v)).
#[inline(always)]
pub(crate) fn eval<S: SecondOrderSystem, W: Width>(sys: &S, w: W, y: &[f64], k: &mut [f64]) {
    let n = w.get() / 2;
    let (y, k) = (&y[..2 * n], &mut k[..2 * n]);
    k[..n].copy_from_slice(&y[n..]);
    sys.acceleration(&y[..n], &y[n..], &mut k[n..]);
}

/// The width of a stage row of pair `P` for a state of n2 components.
#[inline(always)]
pub(crate) const fn row_width<P: Pair>(n2: usize) -> usize {
    if P::ACCELERATION_ROWS { n2 / 2 } else { n2 }
}

/// A stage row of pair `P` at y: f(y) = (v, a), or a alone.
#[inline(always)]
fn eval_row<P: Pair, S: SecondOrderSystem, W: Width>(sys: &S, w: W, y: &[f64], k: &mut [f64]) {
    if P::ACCELERATION_ROWS {
        let n = w.get() / 2;
        sys.acceleration(&y[..n], &y[n..2 * n], &mut k[..n]);
    } else {
        eval(sys, w, y, k);
    }
}

/// Row `r` of k = f(base + h Σ_{j<r} a[j] k_j), `a` the first r coefficients of the tableau's
/// row r (r = a.len()). (Measured: a version
/// with the row as a const generic, fully unrolled and with the zero coefficients dropped at
/// compile time, was 25% slower per evaluation on the pendulum than this plain loop.)
#[inline(always)]
pub(crate) fn stage<S: SecondOrderSystem, W: Width>(
    sys: &S,
    w: W,
    k: &mut [f64],
    yt: &mut [f64],
    base: &[f64],
    a: &[f64],
    h: f64,
) {
    let n2 = w.get();
    let r = a.len();
    let (done, rest) = k.split_at_mut(r * n2);
    let (yt, base) = (&mut yt[..n2], &base[..n2]);
    for i in 0..n2 {
        let mut acc = 0.0;
        for j in 0..r {
            acc += a[j] * done[j * n2 + i];
        }
        yt[i] = base[i] + h * acc;
    }
    eval(sys, w, yt, &mut rest[..n2]);
}

/// (t + t_low) + h as a new (t, t_low) with t_low the part t cannot hold (Knuth's two-sum:
/// exact, so the sum of many steps keeps the time to the last bit of t).
#[inline(always)]
fn add_compensated(t: f64, t_low: f64, h: f64) -> (f64, f64) {
    let h = h + t_low;
    let sum = t + h;
    let h_virtual = sum - t;
    let low = (t - (sum - h_virtual)) + (h - h_virtual);
    (sum, low)
}

/// The stepper: a pair `P` on a [`Core`].
#[derive(Clone, Debug)]
pub struct DenseRk<P> {
    pub(crate) core: Core,
    pair: std::marker::PhantomData<P>,
}

impl<P: Pair> DenseRk<P> {
    pub fn new(x0: &[f64], v0: &[f64], dt: f64, options: MethodOptions) -> Self {
        let (n, rtol, h_max) = (x0.len(), options.rtol, options.max_step);
        let mut y = x0.to_vec();
        y.extend_from_slice(v0);
        DenseRk {
            core: Core {
                rtol,
                h_max,
                n2: 2 * n,
                y_old: y.clone(),
                y,
                k: vec![0.0; P::K_ROWS * row_width::<P>(2 * n)],
                yt: vec![0.0; 2 * n],
                cont: vec![0.0; P::CONT_ROWS * 2 * n],
                dense_ready: false,
                t: 0.0,
                t_low: 0.0,
                t_old: 0.0,
                t_old_low: 0.0,
                h_last: 0.0,
                h: dt.min(h_max),
                samples: 0,
                fsal: 0,
                last_rejected: false,
                ln_err_old: 1e-4f64.ln(),
                accepted: 0,
                rejected: 0,
            },
            pair: std::marker::PhantomData,
        }
    }

    /// One attempted step of size h from (t, y): `Some(accepted)`, or `None` when the error
    /// estimate is not finite (the state blew up). Controller as Hairer's codes: 0.9 err^(-α)
    /// err_old^β (Lund's stabilisation, err_old ≥ 1e-4), clamped to [FAC_MIN, FAC_MAX] times
    /// the step, no growth right after a rejection.
    #[inline(always)]
    fn attempt<S: SecondOrderSystem, W: Width>(
        &mut self,
        sys: &S,
        w: W,
        evals: &mut u64,
        h: f64,
    ) -> Option<bool> {
        let c = &mut self.core;
        let r = row_width::<P>(w.get());
        match c.fsal {
            0 => {
                eval_row::<P, S, W>(sys, w, &c.y, &mut c.k[..r]);
                *evals += 1;
            }
            2 => c.k.copy_within(P::FSAL_ROW * r..(P::FSAL_ROW + 1) * r, 0),
            _ => {}
        }
        c.fsal = 1;
        let err = P::trial(c, sys, w, h);
        *evals += P::TRIAL_EVALS;
        if !err.is_finite() {
            return None;
        }
        // err^(-α) err_old^β as one exp of logarithms: one ln and one exp per step instead of
        // two pow (which took 18% of dopri5's time on the pendulum).
        let ln_err = err.ln();
        let factor = if err == 0.0 {
            P::FAC_MAX
        } else {
            (0.9 * (P::BETA * c.ln_err_old - P::EXPONENT * ln_err).exp())
                .clamp(P::FAC_MIN, P::FAC_MAX)
        };
        if err <= 1.0 {
            // f(y_new): the dense output's last stage and the next step's first.
            if !P::FSAL_IN_TRIAL {
                let (y_new, k) = (&c.y_old, &mut c.k);
                eval_row::<P, S, W>(
                    sys,
                    w,
                    y_new,
                    &mut k[P::FSAL_ROW * r..(P::FSAL_ROW + 1) * r],
                );
                *evals += 1;
            }
            std::mem::swap(&mut c.y, &mut c.y_old);
            c.fsal = 2;
            c.t_old = c.t;
            c.t_old_low = c.t_low;
            (c.t, c.t_low) = add_compensated(c.t, c.t_low, h);
            c.h_last = h;
            c.dense_ready = false;
            c.accepted += 1;
            c.h = h * if c.last_rejected {
                factor.min(1.0)
            } else {
                factor
            };
            c.last_rejected = false;
            c.ln_err_old = ln_err.max(1e-4f64.ln());
            Some(true)
        } else {
            c.rejected += 1;
            c.last_rejected = true;
            c.h = h * factor.min(1.0);
            Some(false)
        }
    }

    /// Advances the reported state (x, v) by dt: steps on until the internal time reaches the
    /// next sample time, then interpolates there.
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, dt: f64) {
        if self.core.n2 == 2 {
            self.advance(sys, Fixed::<2>, s, dt)
        } else {
            let w = Dynamic(self.core.n2);
            self.advance(sys, w, s, dt)
        }
    }

    #[inline(always)]
    fn advance<S: SecondOrderSystem, W: Width>(&mut self, sys: &S, w: W, s: State, dt: f64) {
        self.core.samples += 1;
        let target = self.core.samples as f64 * dt;
        let n = w.get() / 2;
        // A step that ends within 1e-12 (relative) of the sample time counts as ending there:
        // steps of exactly dt (with `max_step`) accumulate rounding in t.
        while self.core.t < target - 1e-12 * target.max(dt) {
            let floor = 1e-14 * target.max(dt);
            let h = self.core.h.min(self.core.h_max);
            let accepted = if self.core.h.abs() < floor {
                None
            } else {
                self.attempt(sys, w, &mut s.counts.evals, h)
            };
            if accepted.is_none() {
                // Leave a non-finite state so the run reports the divergence.
                let c = &mut self.core;
                c.y.fill(f64::NAN);
                s.x.fill(f64::NAN);
                s.v.fill(f64::NAN);
                c.t = f64::INFINITY;
                return;
            }
        }
        let c = &mut self.core;
        if !c.y[0].is_finite() {
            s.x.fill(f64::NAN);
            s.v.fill(f64::NAN);
            return;
        }
        if c.t == target {
            s.x.copy_from_slice(&c.y[..n]);
            s.v.copy_from_slice(&c.y[n..2 * n]);
            return;
        }
        if !c.dense_ready {
            P::build_dense(c, sys, w);
            s.counts.evals += P::DENSE_EVALS;
            c.dense_ready = true;
        }
        // target − t_old is exact (the two are within a step of each other, Sterbenz).
        let theta = ((target - c.t_old) - c.t_old_low) / c.h_last;
        let mut buf = [0.0; 2];
        if w.get() == 2 {
            P::interpolate(c, w, theta, &mut buf);
            s.x[0] = buf[0];
            s.v[0] = buf[1];
        } else {
            let mut out = std::mem::take(&mut c.yt);
            P::interpolate(c, w, theta, &mut out);
            s.x.copy_from_slice(&out[..n]);
            s.v.copy_from_slice(&out[n..2 * n]);
            c.yt = out;
        }
    }
}
