//! Semi-implicit (symplectic) Euler: the velocity first, then the position with the new velocity.

use super::{SecondOrderSystem, State};

/// v += a(x, v) h; x += v_new h. Symplectic, first order, stable for ω h < 2.
#[derive(Clone, Debug)]
pub struct SemiImplicitEuler {
    a: Vec<f64>,
}

impl SemiImplicitEuler {
    pub fn new(n: usize) -> Self {
        SemiImplicitEuler { a: vec![0.0; n] }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        sys.acceleration(s.x, s.v, &mut self.a);
        s.counts.evals += 1;
        for i in 0..s.x.len() {
            s.v[i] += self.a[i] * h;
            s.x[i] += s.v[i] * h;
        }
    }
}
