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
