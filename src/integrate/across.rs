//! A fixed-step method stepping at its own step h while the run reports every dt
//! ([`super::MethodOptions::step`]): as with the adaptive pairs' dense output, sample times never
//! end a step. The state at a sample time comes from the quintic Hermite interpolant through x,
//! x' = v and x'' = a at both ends of the step that holds it.
//!
//! The interpolant matches x, x', x'' at both ends, so it is exact for quintics, and on a smooth
//! solution its own error is x⁽⁶⁾ (t − t0)³ (t − t1)³ / 6!: at most h⁶ |x⁽⁶⁾| / 46 080 in x (at the
//! middle of the step) and O(h⁵) in v (its derivative). Built from the method's values at the
//! step ends, which a method of order p has to O(hᵖ), the samples are of order min(p, 6) in x and
//! min(p, 5) in v (`samples_converge_at_the_methods_order_up_to_six` measures it).
//!
//! a at a step's end is one more force evaluation per step, except where the method's next step
//! starts with it: [`super::rkn::Rkn4`] takes it as its first stage.

use super::dense::Width;
use super::{Counts, SecondOrderSystem};

/// The step in hand: x, v, a at its start and at its end (the method's own state), where it is
/// on the time axis, and its interpolant's coefficients once a sample needs them.
#[derive(Clone, Debug)]
pub(crate) struct Across {
    pub h: f64,
    /// 1 / h, for the samples.
    inv_h: f64,
    /// The method's steps so far: the step in hand ends at `steps × h` (a product, not a sum of
    /// steps, so the step ends do not drift from the sample times over long runs).
    pub steps: u64,
    pub x0: Vec<f64>,
    pub v0: Vec<f64>,
    pub a0: Vec<f64>,
    pub x1: Vec<f64>,
    pub v1: Vec<f64>,
    pub a1: Vec<f64>,
    /// The interpolant over the step in hand as polynomials in s = (t − t0)/h: x − x0 and v
    /// (`ROWS` rows per component), built for step `built`.
    c: Vec<f64>,
    built: u64,
}

impl Across {
    /// The vectors of the system's dimension it keeps.
    pub const VECTORS: usize = 6 + ROWS;

    /// Starts at (x0, v0) with no step taken: one force evaluation, a(x0, v0).
    pub fn new<S: SecondOrderSystem>(
        sys: &S,
        x0: &[f64],
        v0: &[f64],
        h: f64,
        counts: &mut Counts,
    ) -> Self {
        let mut a = vec![0.0; x0.len()];
        sys.acceleration(x0, v0, &mut a);
        counts.evals += 1;
        Across {
            h,
            inv_h: 1.0 / h,
            steps: 0,
            x0: x0.to_vec(),
            v0: v0.to_vec(),
            a0: a.clone(),
            x1: x0.to_vec(),
            v1: v0.to_vec(),
            a1: a,
            c: vec![0.0; ROWS * x0.len()],
            built: 0,
        }
    }

    /// The time the step in hand ends.
    #[inline]
    pub fn end(&self) -> f64 {
        self.steps as f64 * self.h
    }

    /// Makes the last step's end the next step's start; the method then advances (x1, v1).
    #[inline]
    pub fn next<W: Width>(&mut self, w: W) {
        for i in 0..w.get() {
            self.x0[i] = self.x1[i];
            self.v0[i] = self.v1[i];
        }
        // a1 is evaluated anew after the step: its buffer can be the old a0.
        std::mem::swap(&mut self.a0, &mut self.a1);
        self.steps += 1;
    }

    /// The interpolant at time `t` (within the step in hand) into `x` and `v`.
    #[inline]
    pub fn sample<W: Width>(&mut self, t: f64, x: &mut [f64], v: &mut [f64], w: W) {
        let (h, n) = (self.h, w.get());
        let c = &mut self.c[..ROWS * n];
        if self.built != self.steps {
            self.built = self.steps;
            for i in 0..n {
                // The weights of Δ = x1 − x0, h v0, h v1, h² a0, h² a1 in c_3, c_4, c_5: the
                // quintic with these values and slopes at s = 0 and 1.
                let d = self.x1[i] - self.x0[i];
                let (v0, v1) = (h * self.v0[i], h * self.v1[i]);
                let (a0, a1) = (h * h * self.a0[i], h * h * self.a1[i]);
                let c2 = 0.5 * a0;
                let c3 = 10.0 * d - 6.0 * v0 - 4.0 * v1 - 1.5 * a0 + 0.5 * a1;
                let c4 = -15.0 * d + 8.0 * v0 + 7.0 * v1 + 1.5 * a0 - a1;
                let c5 = 6.0 * d - 3.0 * v0 - 3.0 * v1 - 0.5 * a0 + 0.5 * a1;
                // x(s) = x0 + s (c1 + s (c2 + ...)), v(s) = x'(s) / h.
                let row = [
                    v0,
                    c2,
                    c3,
                    c4,
                    c5,
                    self.v0[i],
                    2.0 * c2 * self.inv_h,
                    3.0 * c3 * self.inv_h,
                    4.0 * c4 * self.inv_h,
                    5.0 * c5 * self.inv_h,
                ];
                for (r, value) in row.into_iter().enumerate() {
                    c[r * n + i] = value;
                }
            }
        }
        let s = (t - self.steps.saturating_sub(1) as f64 * h) * self.inv_h;
        let r = |k: usize, i: usize| c[k * n + i];
        for i in 0..n {
            let dx = s * (r(0, i) + s * (r(1, i) + s * (r(2, i) + s * (r(3, i) + s * r(4, i)))));
            x[i] = self.x0[i] + dx;
            v[i] = r(5, i) + s * (r(6, i) + s * (r(7, i) + s * (r(8, i) + s * r(9, i))));
        }
    }
}

/// Rows of interpolant coefficients per component: five for x − x0, five for v.
const ROWS: usize = 10;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::dense::Dynamic;

    /// The interpolant reproduces a quintic and its derivative from its values, slopes and
    /// curvatures at a step's ends (so it is the quintic Hermite interpolant: there is one), at
    /// a step that is not the first and over a step that is not 1.
    #[test]
    fn the_interpolant_is_exact_for_quintics() {
        let c = [0.3, -1.1, 0.7, 2.0, -0.9, 0.45];
        let q = |t: f64| c.iter().rev().fold(0.0, |acc, ck| acc * t + ck);
        let dq = |t: f64| (1..6).rev().fold(0.0, |acc, k| acc * t + k as f64 * c[k]);
        let ddq = |t: f64| {
            (2..6)
                .rev()
                .fold(0.0, |acc, k| acc * t + (k * (k - 1)) as f64 * c[k])
        };
        let (h, steps) = (0.7, 3);
        let (t0, t1) = (2.0 * h, 3.0 * h);
        let mut a = Across {
            h,
            inv_h: 1.0 / h,
            steps,
            x0: vec![q(t0)],
            v0: vec![dq(t0)],
            a0: vec![ddq(t0)],
            x1: vec![q(t1)],
            v1: vec![dq(t1)],
            a1: vec![ddq(t1)],
            c: vec![0.0; ROWS],
            built: 0,
        };
        for k in 0..=20 {
            let t = t0 + h * f64::from(k) / 20.0;
            let (mut x, mut v) = ([0.0], [0.0]);
            a.sample(t, &mut x, &mut v, Dynamic(1));
            assert!(
                (x[0] - q(t)).abs() < 1e-13,
                "x at {t}: {} vs {}",
                x[0],
                q(t)
            );
            assert!(
                (v[0] - dq(t)).abs() < 1e-12,
                "v at {t}: {} vs {}",
                v[0],
                dq(t)
            );
        }
    }
}
