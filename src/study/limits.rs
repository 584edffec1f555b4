//! Stability limits: each method's largest stable step on the linearised problem, found by
//! bisection and set against theory.

use super::{Problem, largest_difference, stop_stride};
use crate::integrate::{Integrator, Method, MethodOptions, SecondOrderSystem, Stability};
use crate::interrupt::requested as stop;
use crate::scene::params::{self, Invalid};
use crate::scene::pendulum::{Pendulum, PendulumParams};
use crate::scene::rope::{Rope, RopeParams};

/// One method's measured stability limit next to theory, in dt.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    pub scene: &'static str,
    pub method: Method,
    /// Largest dt found stable; for unconditionally stable methods, the largest tried.
    pub measured_dt: Option<f64>,
    /// Theory's largest stable dt: limit/ω; infinite when unconditional, `None` when there is
    /// none (unstable for every dt) or the step is adaptive.
    pub theory_dt: Option<f64>,
    pub note: String,
}

/// The linearised problem stability theory speaks of: the pendulum at 1e-12 rad (so that even
/// 10⁴-fold growth stays below 2.6e-8 rad, where sin θ rounds to θ: a larger swing detunes the
/// resonance and saturates the growth, which hid the instability of yoshida6 up to 1.2e-5 past
/// its limit at 1e-8 rad), the rope straight, weightless and undamped, displaced along itself by
/// ±1e-6 of its rest length so that every mode, the highest included, is excited.
fn linearised(problem: &Problem) -> (Problem, (Vec<f64>, Vec<f64>)) {
    match problem {
        Problem::Pendulum(p) => {
            let q = PendulumParams {
                theta0: 1e-12,
                omega0: 0.0,
                ..*p
            };
            (Problem::Pendulum(q), (vec![q.theta0], vec![0.0]))
        }
        Problem::Rope(p) => {
            let q = RopeParams {
                gravity: glam::DVec3::ZERO,
                spring_damping: 0.0,
                air_drag: 0.0,
                pinned: vec![0],
                ..p.clone()
            };
            let mut x = q.initial_positions();
            let axis = (q.end - q.start).normalize();
            let l0 = q.rest_length();
            for i in 1..q.nodes {
                let s = if i % 2 == 0 { 1e-6 } else { -1e-6 } * l0;
                for c in 0..3 {
                    x[3 * i + c] += s * axis[c];
                }
            }
            let v = vec![0.0; x.len()];
            (Problem::Rope(q), (x, v))
        }
    }
}

/// Whether `method` at `dt` keeps the linearised problem's displacement within 10⁴ of its start
/// over `steps` steps.
fn bounded(
    problem: &Problem,
    start: &(Vec<f64>, Vec<f64>),
    method: Method,
    dt: f64,
    steps: u64,
) -> bool {
    fn run<S: SecondOrderSystem>(
        sys: &S,
        start: &(Vec<f64>, Vec<f64>),
        rest: &[f64],
        method: Method,
        dt: f64,
        steps: u64,
    ) -> bool {
        let size = |x: &[f64]| largest_difference(x, rest);
        let initial = size(&start.0);
        let stride = stop_stride(start.0.len());
        let options = MethodOptions::default();
        let mut it = Integrator::new(method, sys, &start.0, &start.1, dt, options);
        for k in 0..steps {
            it.step(sys);
            let s = size(it.position());
            // NaN compares false: a non-finite state counts as unbounded.
            if s.is_nan() || s > 1e4 * initial {
                return false;
            }
            // Stopped: the answer is dropped by `stability`, so any will do.
            if k % stride == stride - 1 && stop() {
                return false;
            }
        }
        true
    }
    match problem {
        Problem::Pendulum(p) => run(&Pendulum::new(p), start, &[0.0], method, dt, steps),
        Problem::Rope(p) => {
            let rest = p.initial_positions();
            run(&Rope::new(p.clone()), start, &rest, method, dt, steps)
        }
    }
}

/// Largest stable dt by bisection (geometric, 40 halvings of the bracket), for every method.
/// A run is stable when its displacement stays within 10⁴ of the start over `steps` steps.
/// After a stop request, the limits of the methods complete so far.
pub fn stability(problem: &Problem, methods: &[Method], steps: u64) -> Vec<Limit> {
    stability_with(problem, methods, steps, &mut |_| {})
}

/// [`stability`], telling `done` how many methods' bisections are done (in fractions of one).
pub fn stability_with(
    problem: &Problem,
    methods: &[Method],
    steps: u64,
    done: &mut dyn FnMut(f64),
) -> Vec<Limit> {
    let (lin, start) = linearised(problem);
    let w = lin.omega();
    let mut limits = Vec::new();
    for (i, &m) in methods.iter().enumerate() {
        if stop() {
            break;
        }
        let theory = match m.info().stability {
            Stability::Below(h) => Some(h / w),
            Stability::Always => Some(f64::INFINITY),
            Stability::Never | Stability::Adaptive => None,
        };
        let bounded = |dt| bounded(&lin, &start, m, dt, steps);
        let at = &mut |k| done(i as f64 + k);
        let (measured, note) = measure(m, (w, theory), steps, bounded, at);
        // A bisection cut short by a stop has no limit to show.
        if !stop() {
            limits.push(Limit {
                scene: problem.name(),
                method: m,
                measured_dt: measured,
                theory_dt: theory,
                note,
            });
            done((i + 1) as f64);
        }
    }
    limits
}

/// `m`'s largest stable dt on a problem of rate `w` whose runs `bounded` tells apart, and its
/// note, telling `done` how far its bisection is (in fractions of one).
fn measure(
    m: Method,
    (w, theory): (f64, Option<f64>),
    steps: u64,
    bounded: impl Fn(f64) -> bool,
    done: &mut dyn FnMut(f64),
) -> (Option<f64>, String) {
    match m.info().stability {
        Stability::Adaptive => {
            return (None, "adaptive: error control chooses the substeps".into());
        }
        Stability::Always => {
            let tried = 1000.0 * 2.0 / w;
            return match bounded(tried) {
                true => (
                    Some(tried),
                    "stable at 1000 × 2/ω, the largest tried".into(),
                ),
                false => (None, "unstable at 1000 × 2/ω".into()),
            };
        }
        Stability::Never | Stability::Below(_) => {}
    }
    // Bisection needs its upper end in the first unstable stretch: past theory's limit the
    // high-order compositions are stable again (gaps). The end is the first of 1e-4, 1e-3, 1e-2
    // past theory's limit that a run finds unbounded (none found: no limit measured), or
    // 10 × 2/ω for the methods with none.
    let just_past = theory.map(|limit| {
        [1e-4, 1e-3, 1e-2]
            .into_iter()
            .map(|r| limit * (1.0 + r))
            .find(|&dt| !bounded(dt))
    });
    let (mut lo, hi) = (1e-4 * 2.0 / w, just_past.unwrap_or(Some(10.0 * 2.0 / w)));
    let Some(mut hi) = hi else {
        let why =
            format!("instability past theory's limit too slow for {steps} steps: more --steps");
        return (None, why);
    };
    if !bounded(lo) {
        return (None, "unstable even at 1e-4 × 2/ω".into());
    }
    for k in 0..40 {
        if stop() {
            break;
        }
        done(f64::from(k) / 40.0);
        let mid = (lo * hi).sqrt();
        if bounded(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let note = match m.info().stability {
        Stability::Never => format!(
            "no true limit: growth is slow below this, and the value shrinks as the run ({steps} steps) lengthens"
        ),
        _ => String::new(),
    };
    (Some(lo), note)
}

/// A stability study's steps per trial within their range.
pub fn validate_stability_steps(steps: u64) -> Result<(), Invalid> {
    params::count_within("--steps", steps, 10, 10_000_000)
}
