//! Composition methods: Yoshida's fourth-order triple jump of a second-order symplectic step.

use super::{SecondOrderSystem, State};

/// Yoshida's fourth-order composition stays stable on the oscillator for h < 1.5734019...,
/// where the trace of its one-step matrix reaches ±2 (see `study::yoshida4_limit`).
pub const YOSHIDA4_STABILITY_LIMIT: f64 = 1.573_401_947_434_54;

/// Yoshida's triple-jump weights: w1 = 1/(2 - 2^(1/3)), w0 = -2^(1/3)/(2 - 2^(1/3)).
pub fn yoshida_weights() -> (f64, f64) {
    let c = 2f64.powf(1.0 / 3.0);
    (1.0 / (2.0 - c), -c / (2.0 - c))
}

/// Three position-Verlet (drift-kick-drift) substeps of w1 h, w0 h, w1 h, written as four
/// drifts and three kicks, one force evaluation per kick.
///
/// For forces of x alone the composition is symplectic and fourth order. A velocity-dependent
/// force (damping, drag) needs the velocity at the kick's middle, (v_pre + v_post)/2, for the
/// substep to stay symmetric, which an explicit step cannot have: a kick with the pre-kick
/// velocity costs the whole composition its order (measured 1.0 on the damped oscillator and
/// the damped rope). Each kick therefore evaluates a(x, v_pre + (w h / 2) a_last), the middle
/// velocity predicted with the last acceleration evaluated (of the previous kick; zero before
/// the first): accurate to O(h²), which makes the step second order with velocity-dependent
/// forces (measured 2.00), at no extra evaluation. For a(x) the velocity argument is unused
/// and nothing changes.
#[derive(Clone, Debug)]
pub struct Yoshida4 {
    /// The last acceleration evaluated; zero before the first kick.
    a: Vec<f64>,
    /// The kick's velocity argument: v predicted at the kick's middle.
    v_mid: Vec<f64>,
}

impl Yoshida4 {
    pub fn new(n: usize) -> Self {
        Yoshida4 {
            a: vec![0.0; n],
            v_mid: vec![0.0; n],
        }
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
                for i in 0..n {
                    self.v_mid[i] = v[i] + 0.5 * kick * h * self.a[i];
                }
                sys.acceleration(x, &self.v_mid, &mut self.a);
                s.counts.evals += 1;
                for i in 0..n {
                    v[i] += kick * h * self.a[i];
                }
            }
        }
    }
}
