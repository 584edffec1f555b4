//! Position Verlet, x1 = x0 + (1-d)(x0 - x_-1) + a dt², with a damping factor and a synchronous velocity.

use super::{Counts, SecondOrderSystem, State};

/// x1 = x0 + (1-d)(x0 - x_-1) + a0 dt², then a1 = a(x1, v1*) and the velocity at x1 from the
/// velocity-Verlet identity v1 = (x1 - x0)/dt + a1 dt/2.
///
/// The velocity argument v1* of a(x1, ·) is that identity with a0 in place of the a1 not yet
/// known: v1* = (x1 - x0)/dt + a0 dt/2, off from v1 by (a0 - a1) dt/2 = O(dt²). That keeps the
/// method second order with velocity-dependent forces (damping, drag) at one evaluation per
/// step. The velocity over the step, (x1 - x0)/dt, is the velocity at the half step; used at
/// x1 it is off by O(dt) and made the method first order with such forces.
#[derive(Clone, Debug)]
pub struct Verlet {
    /// 1 - d.
    keep: f64,
    /// The previous position x_-1.
    x_prev: Vec<f64>,
    /// a at the current position, kept from the last step (one evaluation per step).
    a: Vec<f64>,
    /// The velocity over the last step, (x1 - x0)/dt.
    vt: Vec<f64>,
}

impl Verlet {
    /// Second-order start: x_-1 = x0 - v0 dt + a0 dt²/2 (Taylor backwards). The naive
    /// start x_-1 = x0 makes the first step a symplectic-Euler step and the whole run first order.
    /// `a` keeps a(x0, v0) for the first step; this start is the method's one extra evaluation.
    pub fn new<S: SecondOrderSystem>(
        sys: &S,
        x0: &[f64],
        v0: &[f64],
        dt: f64,
        damping: f64,
        counts: &mut Counts,
    ) -> Self {
        let n = x0.len();
        let mut a = vec![0.0; n];
        sys.acceleration(x0, v0, &mut a);
        counts.evals += 1;
        let x_prev = (0..n)
            .map(|i| x0[i] - v0[i] * dt + 0.5 * a[i] * dt * dt)
            .collect();
        Verlet {
            keep: 1.0 - damping,
            x_prev,
            a,
            vt: vec![0.0; n],
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let (x, v) = (s.x, s.v);
        // The system's first-order accumulators (the rope's dissipated work) advance undamped.
        let damped = x.len() - sys.first_order_tail();
        self.drift(x, v, 0..damped, self.keep, h);
        self.drift(x, v, damped..x.len(), 1.0, h);
        sys.acceleration(x, v, &mut self.a);
        s.counts.evals += 1;
        // v1 at the same instant as x1 (a central difference would lag a step). a1 is kept for
        // the next step, so this is still one evaluation per step.
        for i in 0..x.len() {
            v[i] = self.vt[i] + 0.5 * h * self.a[i];
        }
    }

    /// x1 = x0 + keep (x0 - x_-1) + a0 h² over `range`, with the velocity over the step and
    /// v1* (see the type's docs), held in v until v1.
    #[inline(always)]
    fn drift(
        &mut self,
        x: &mut [f64],
        v: &mut [f64],
        range: std::ops::Range<usize>,
        keep: f64,
        h: f64,
    ) {
        for i in range {
            let x1 = x[i] + keep * (x[i] - self.x_prev[i]) + self.a[i] * h * h;
            self.x_prev[i] = x[i];
            x[i] = x1;
            self.vt[i] = (x1 - self.x_prev[i]) / h;
            v[i] = self.vt[i] + 0.5 * h * self.a[i];
        }
    }
}
