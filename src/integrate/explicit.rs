//! Explicit one-step methods: explicit and semi-implicit (symplectic) Euler, the explicit
//! midpoint rule (RK2) and Heun's method (the explicit trapezoid rule, named `trapezoid`: not
//! the implicit one).

use super::{SecondOrderSystem, State};

/// Euler's two first-order steps: explicit, x += v h; v += a(x, v) h, both from the old state;
/// semi-implicit (symplectic, stable for ω h < 2), v += a(x, v) h; x += v_new h.
#[derive(Clone, Debug)]
pub struct Euler {
    a: Vec<f64>,
}

impl Euler {
    pub fn new(n: usize) -> Self {
        Euler { a: vec![0.0; n] }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        sys.acceleration(s.x, s.v, &mut self.a);
        s.counts.evals += 1;
        for i in 0..s.x.len() {
            s.x[i] += s.v[i] * h;
            s.v[i] += self.a[i] * h;
        }
    }

    #[inline]
    pub fn step_symplectic<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        sys.acceleration(s.x, s.v, &mut self.a);
        s.counts.evals += 1;
        for i in 0..s.x.len() {
            s.v[i] += self.a[i] * h;
            s.x[i] += s.v[i] * h;
        }
    }
}

/// Explicit RK2 through the half step.
#[derive(Clone, Debug)]
pub struct Midpoint {
    a: Vec<f64>,
    xt: Vec<f64>,
    vt: Vec<f64>,
}

impl Midpoint {
    pub fn new(n: usize) -> Self {
        Midpoint {
            a: vec![0.0; n],
            xt: vec![0.0; n],
            vt: vec![0.0; n],
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let n = s.x.len();
        sys.acceleration(s.x, s.v, &mut self.a);
        for i in 0..n {
            self.xt[i] = s.x[i] + 0.5 * h * s.v[i];
            self.vt[i] = s.v[i] + 0.5 * h * self.a[i];
        }
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        s.counts.evals += 2;
        for i in 0..n {
            s.x[i] += h * self.vt[i];
            s.v[i] += h * self.a[i];
        }
    }
}

/// Heun: an explicit-Euler predictor, then the average of the slopes at both ends (the
/// explicit trapezoid rule; not the implicit trapezoid rule of the theory tables).
#[derive(Clone, Debug)]
pub struct Heun {
    a0: Vec<f64>,
    a1: Vec<f64>,
    xt: Vec<f64>,
    vt: Vec<f64>,
}

impl Heun {
    pub fn new(n: usize) -> Self {
        Heun {
            a0: vec![0.0; n],
            a1: vec![0.0; n],
            xt: vec![0.0; n],
            vt: vec![0.0; n],
        }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let n = s.x.len();
        sys.acceleration(s.x, s.v, &mut self.a0);
        for i in 0..n {
            self.xt[i] = s.x[i] + h * s.v[i];
            self.vt[i] = s.v[i] + h * self.a0[i];
        }
        sys.acceleration(&self.xt, &self.vt, &mut self.a1);
        s.counts.evals += 2;
        for i in 0..n {
            s.x[i] += 0.5 * h * (s.v[i] + self.vt[i]);
            s.v[i] += 0.5 * h * (self.a0[i] + self.a1[i]);
        }
    }
}
