//! Stability limits: each method's largest stable step on the linearised problem, found by
//! bisection and set against theory.

use super::{Problem, largest_difference, stop_stride};
use crate::integrate::{
    Integrator, Method, MethodOptions, SecondOrderSystem, Stability, composition_drift,
    yoshida_weights,
};
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

/// Yoshida's stability limit on the oscillator from theory: the h at which the trace of the
/// composition's one-step matrix reaches 2 in magnitude, found by bisection on the matrix product.
pub fn yoshida4_limit() -> f64 {
    let (w1, w0) = yoshida_weights();
    composition_limit(&[w1, w0, w1])
}

/// The stability limit of the composition of position-Verlet substeps of weights `w` on
/// x'' = -x: the first h > 0 at which the trace of its one-step matrix, multiplied out in the
/// stepper's own drift/kick sequence, exceeds 2 in magnitude. Past it the trace may come back
/// below 2 (gaps), so the first crossing is found by a scan on a grid of 1e-4 (the gaps of the
/// registry's compositions are 7.6e-4 wide or more), then bisection in its cell.
pub fn composition_limit(w: &[f64]) -> f64 {
    let last = w.len();
    let trace = |h: f64| {
        // Columns: the images of (1, 0) and (0, 1) under x'' = -x.
        let mut m = [[1.0, 0.0], [0.0, 1.0]];
        for k in 0..=last {
            let d = composition_drift(w, k);
            for col in &mut m {
                col[0] += d * h * col[1];
                if let Some(kick) = w.get(k) {
                    col[1] -= kick * h * col[0];
                }
            }
        }
        m[0][0] + m[1][1]
    };
    let grid = 1e-4;
    let mut cell = 1.0;
    while trace(cell * grid).abs() <= 2.0 {
        cell += 1.0;
        assert!(cell < 1e5, "no instability below h = 10");
    }
    let (mut lo, mut hi) = ((cell - 1.0) * grid, cell * grid);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if trace(mid).abs() <= 2.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}

/// A stability study's steps per trial within their range.
pub fn validate_stability_steps(steps: u64) -> Result<(), Invalid> {
    params::count_within("--steps", steps, 10, 10_000_000)
}

#[cfg(test)]
mod tests {
    use super::*;

    type M = [[f64; 2]; 2];

    /// One drift-kick-drift step of size t on x'' = -x in closed form:
    /// [[1 - t²/2, t - t³/4], [-t, 1 - t²/2]].
    fn step(t: f64) -> M {
        [
            [1.0 - t * t / 2.0, t - t * t * t / 4.0],
            [-t, 1.0 - t * t / 2.0],
        ]
    }

    fn mul(a: M, b: M) -> M {
        std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
    }

    /// Yoshida-4's stability limit on x'' = -x: the root of trace(M(w1 h) M(w0 h) M(w1 h)) = 2 for
    /// the closed-form position-Verlet matrix M, 1.57340194743454005662957944196 by
    /// `tests/data/yoshida4_stability.py` (mpmath, 80 digits), as the nearest double. Nothing here
    /// comes from `yoshida4_limit` or `yoshida_weights`.
    const LIMIT_MPMATH: f64 = 1.573_401_947_434_54;

    /// The same root in f64, by bisection on the closed form of [`step`], with the weights
    /// w1 = 1/(2 - ∛2), w0 = 1 - 2 w1.
    fn limit_from_the_closed_form() -> f64 {
        let w1 = 1.0 / (2.0 - 2f64.cbrt());
        let w0 = 1.0 - 2.0 * w1;
        let trace = |h: f64| {
            let p = mul(step(w1 * h), mul(step(w0 * h), step(w1 * h)));
            p[0][0] + p[1][1]
        };
        // Below 2 on (0, limit), above past it (the script checks the shape on a grid).
        let (mut lo, mut hi) = (1.4, 1.7);
        assert!(trace(lo) < 2.0 && trace(hi) > 2.0);
        while hi - lo > f64::EPSILON * hi {
            let mid = 0.5 * (lo + hi);
            if trace(mid) < 2.0 { lo = mid } else { hi = mid }
        }
        lo
    }

    /// The closed-form bisection, `yoshida4_limit()` (bisection on the stepper's own drift/kick
    /// sequence) and the registry's constant all agree with the mpmath root to 4 eps = 8.9e-16
    /// (measured: -2.2e-16, +4.4e-16 and +4.4e-16). A relative error of 1e-9 in w1 alone moves the
    /// root by 5e-9, so anything but the right weights in the right order fails.
    #[test]
    fn yoshida_limit_matches_an_independent_root() {
        let tol = 4.0 * f64::EPSILON;
        let closed = limit_from_the_closed_form();
        assert!((closed - LIMIT_MPMATH).abs() <= tol, "closed form {closed}");
        for (what, value) in [
            ("yoshida4_limit()", yoshida4_limit()),
            (
                "YOSHIDA4_STABILITY_LIMIT",
                crate::integrate::YOSHIDA4_STABILITY_LIMIT,
            ),
        ] {
            assert!(
                (value - LIMIT_MPMATH).abs() <= tol,
                "{what} = {value}, independent root {LIMIT_MPMATH} ({:+.1e})",
                value - LIMIT_MPMATH
            );
        }
    }

    /// The first crossing of |trace| = 2 of the composition of closed-form position-Verlet
    /// matrices (as `limit_from_the_closed_form`) of weights `w`: a scan on a grid of 1e-4, then
    /// bisection in the first cell past 2.
    fn first_crossing_of_the_closed_form(w: &[f64]) -> f64 {
        let trace = |h: f64| {
            let p = (w.iter()).fold([[1.0, 0.0], [0.0, 1.0]], |p, &wk| mul(step(wk * h), p));
            (p[0][0] + p[1][1]).abs()
        };
        let mut k = 1.0;
        while trace(k * 1e-4) <= 2.0 {
            k += 1.0;
        }
        let (mut lo, mut hi) = ((k - 1.0) * 1e-4, k * 1e-4);
        while hi - lo > f64::EPSILON * hi {
            let mid = 0.5 * (lo + hi);
            if trace(mid) <= 2.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        lo
    }

    /// |trace| of the one-step matrix of `method`'s own stepper on x'' = -x at h, its columns
    /// one step from (1, 0) and from (0, 1).
    fn stepper_trace(method: Method, h: f64) -> f64 {
        let sys = crate::integrate::tests::DampedOscillator { c: 0.0 };
        let column = |x: f64, v: f64| {
            let mut it = crate::integrate::Integrator::new(
                method,
                &sys,
                &[x],
                &[v],
                h,
                MethodOptions::default(),
            );
            it.step(&sys);
            (it.position()[0], it.velocity()[0])
        };
        (column(1.0, 0.0).0 + column(0.0, 1.0).1).abs()
    }

    /// The higher-order compositions' stability limits (the first instability from h = 0; past it
    /// the trace comes back below 2, see `tests/data/composition_stability.py`): the registry's
    /// constants are the mpmath roots, and two f64 roots agree with them: bisection on the
    /// closed-form matrix product here and `composition_limit` on the stepper's drift/kick
    /// sequence, to 1e-11 relative (measured 2e-16 to 3e-15 for yoshida6 and kahan-li8, 1.7e-13 for
    /// sofroniou10, whose trace crosses 2 slowly, at slope about 7e-4, so that its round-off moves
    /// the root further). The stepper's own one-step matrix is stable on a grid of 10⁴ steps up to
    /// the limit and at 1 - 10⁻ᵏ of it (k = 3..6), unstable at 1 + 10⁻⁶ of it.
    #[test]
    fn composition_limits_match_independent_roots_and_the_stepper_is_stable_below() {
        use crate::integrate::{Stability, composition_weights};
        for (method, mpmath) in [
            (Method::Yoshida6, 2.269_057_996_397_659_6),
            (Method::KahanLi8, 3.096_438_680_000_732),
            (Method::Sofroniou10, 3.141_081_862_896_623_3),
        ] {
            let Stability::Below(registry) = method.info().stability else {
                panic!("{method}: a limit")
            };
            assert_eq!(registry, mpmath, "{method}");
            let w = composition_weights(method).unwrap();
            for (what, root) in [
                ("closed form", first_crossing_of_the_closed_form(w)),
                ("composition_limit", composition_limit(w)),
            ] {
                assert!(
                    (root / mpmath - 1.0).abs() <= 1e-11,
                    "{method}: {what} {root} vs mpmath {mpmath} ({:+.1e})",
                    root / mpmath - 1.0
                );
            }
            for k in 1..=10_000 {
                let h = mpmath * f64::from(k) / 10_000.0 * (1.0 - 1e-6);
                assert!(
                    stepper_trace(method, h) < 2.0,
                    "{method}: unstable at h = {h}"
                );
            }
            for r in [1e-3, 1e-4, 1e-5, 1e-6] {
                let t = stepper_trace(method, mpmath * (1.0 - r));
                assert!(t < 2.0, "{method}: |trace| {t} at (1 - {r:e}) × limit");
            }
            let t = stepper_trace(method, mpmath * (1.0 + 1e-6));
            assert!(t > 2.0, "{method}: |trace| {t} just past the limit");
        }
    }
}
