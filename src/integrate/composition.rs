//! Composition methods: Yoshida's fourth-order triple jump of a second-order symplectic step.

use super::{SecondOrderSystem, State};

/// Yoshida's fourth-order composition stays stable on the oscillator for h < 1.5734019...,
/// where the trace of its one-step matrix reaches ±2 (see `study::yoshida4_limit`).
pub const YOSHIDA4_STABILITY_LIMIT: f64 = 1.573_401_947_434_540_4;

/// Yoshida's triple-jump weights: w1 = 1/(2 - 2^(1/3)), w0 = -2^(1/3)/(2 - 2^(1/3)).
pub fn yoshida_weights() -> (f64, f64) {
    let c = 2f64.powf(1.0 / 3.0);
    (1.0 / (2.0 - c), -c / (2.0 - c))
}

/// Three Verlet substeps of w1 h, w0 h, w1 h, written as four drifts and three kicks; the
/// composition is symplectic and fourth order for forces that depend on x only (a
/// velocity-dependent force is kicked explicitly, which costs the order).
#[derive(Clone, Debug)]
pub struct Yoshida4 {
    a: Vec<f64>,
}

impl Yoshida4 {
    pub fn new(n: usize) -> Self {
        Yoshida4 { a: vec![0.0; n] }
    }

    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, h: f64) {
        let n = s.x.len();
        let (x, v) = (s.x, s.v);
        let (w1, w0) = yoshida_weights();
        let drifts = [0.5 * w1, 0.5 * (w0 + w1), 0.5 * (w0 + w1), 0.5 * w1];
        let kicks = [w1, w0, w1];
        for (stage, drift) in drifts.iter().enumerate() {
            for i in 0..n {
                x[i] += drift * h * v[i];
            }
            if let Some(kick) = kicks.get(stage) {
                sys.acceleration(x, v, &mut self.a);
                s.counts.evals += 1;
                for i in 0..n {
                    v[i] += kick * h * self.a[i];
                }
            }
        }
    }
}
