//! The classic fourth-order Runge–Kutta method.

use super::{SecondOrderSystem, State};

#[derive(Clone, Debug)]
pub struct Rk4 {
    a: Vec<f64>,
    xt: Vec<f64>,
    vt: Vec<f64>,
    /// Weighted sums of the stages' slopes.
    sx: Vec<f64>,
    sv: Vec<f64>,
}

impl Rk4 {
    /// One coordinate (the pendulum): the same arithmetic in registers, the stages as one-element
    /// arrays on the stack instead of the heap scratch, so nothing but the force is loaded or
    /// stored per stage. Bit-identical to the general loop (same operations in the same order).
    #[inline]
    fn step_scalar<S: SecondOrderSystem>(sys: &S, s: State, h: f64) {
        let (x0, v0) = (s.x[0], s.v[0]);
        let mut a = [0.0];
        sys.acceleration(&[x0], &[v0], &mut a);
        let (mut sx, mut sv) = (v0, a[0]);
        let (xt, vt) = (x0 + 0.5 * h * v0, v0 + 0.5 * h * a[0]);
        sys.acceleration(&[xt], &[vt], &mut a);
        sx += 2.0 * vt;
        sv += 2.0 * a[0];
        let (xt, vt) = (x0 + 0.5 * h * vt, v0 + 0.5 * h * a[0]);
        sys.acceleration(&[xt], &[vt], &mut a);
        sx += 2.0 * vt;
        sv += 2.0 * a[0];
        let (xt, vt) = (x0 + h * vt, v0 + h * a[0]);
        sys.acceleration(&[xt], &[vt], &mut a);
        s.counts.evals += 4;
        sx += vt;
        sv += a[0];
        s.x[0] = x0 + h / 6.0 * sx;
        s.v[0] = v0 + h / 6.0 * sv;
    }

    pub fn new(n: usize) -> Self {
        Rk4 {
            a: vec![0.0; n],
            xt: vec![0.0; n],
            vt: vec![0.0; n],
            sx: vec![0.0; n],
            sv: vec![0.0; n],
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let n = s.x.len();
        if n == 1 {
            return Self::step_scalar(sys, s, h);
        }
        let (x, v) = (s.x, s.v);
        // k1
        sys.acceleration(x, v, &mut self.a);
        for i in 0..n {
            self.sx[i] = v[i];
            self.sv[i] = self.a[i];
            self.xt[i] = x[i] + 0.5 * h * v[i];
            self.vt[i] = v[i] + 0.5 * h * self.a[i];
        }
        // k2 (at xt, vt)
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        for i in 0..n {
            self.sx[i] += 2.0 * self.vt[i];
            self.sv[i] += 2.0 * self.a[i];
            // xt must use k2's velocity before vt is overwritten.
            self.xt[i] = x[i] + 0.5 * h * self.vt[i];
            self.vt[i] = v[i] + 0.5 * h * self.a[i];
        }
        // k3
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        for i in 0..n {
            self.sx[i] += 2.0 * self.vt[i];
            self.sv[i] += 2.0 * self.a[i];
            self.xt[i] = x[i] + h * self.vt[i];
            self.vt[i] = v[i] + h * self.a[i];
        }
        // k4
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        s.counts.evals += 4;
        for i in 0..n {
            self.sx[i] += self.vt[i];
            self.sv[i] += self.a[i];
            x[i] += h / 6.0 * self.sx[i];
            v[i] += h / 6.0 * self.sv[i];
        }
    }
}
