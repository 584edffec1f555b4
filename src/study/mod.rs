//! `physlab study`: the speed/accuracy trade and the stability limits, measured against theory.
//!
//! Every measurement steps a [`SecondOrderSystem`] with the registry's [`Integrator`] and compares
//! positions at common sample times (multiples of the coarsest step, so not only turning points)
//! with a reference: the exact elliptic solution for a pendulum released from rest, otherwise
//! RK4 at a step 8× finer than the finest tested, whose own error is estimated by Richardson
//! extrapolation against a run at twice its step.
//!
//! A stop request ([`crate::interrupt::requested`], Ctrl-C or SIGTERM) is looked at after every
//! [`STOP_CHECK_STEPS`] coordinates stepped in every run, the reference's and every bisection
//! trial's included: [`sweep`] and
//! [`stability`] then return the rows and limits complete so far (a run cut short is dropped,
//! never shown), and the caller says the study was interrupted.

pub mod drift;
pub mod hair;
mod limits;
mod orders;
mod roundoff;

pub use limits::{Limit, composition_limit, stability, yoshida4_limit};
use orders::fit;
pub use orders::{
    Order, Proportionality, STALL_BELOW, cheapest, error_floor, methods_of, orders,
    proportionality, stalled,
};
pub use roundoff::{energy_error_rms, growth_exponent};

use std::time::Instant;

use crate::integrate::{Integrator, Method, MethodOptions, SecondOrderSystem};
use crate::scene::params::{self, Invalid};
use crate::scene::pendulum::reference::{ExactPendulum, FineStepReference};
use crate::scene::pendulum::{Pendulum, PendulumParams};
use crate::scene::rope::{Rope, RopeParams};

/// One scene set up for a study: its system, start and the rate that sets its stability.
pub enum Problem {
    Pendulum(PendulumParams),
    Rope(RopeParams),
}

impl Problem {
    pub fn name(&self) -> &'static str {
        match self {
            Problem::Pendulum(_) => "pendulum",
            Problem::Rope(_) => "rope",
        }
    }

    /// Whether its forces depend on the velocity (the rope's spring damping and air drag), which
    /// lowers some methods' order (see the registry).
    pub fn velocity_dependent(&self) -> bool {
        match self {
            Problem::Pendulum(_) => false,
            Problem::Rope(p) => p.velocity_dependent(),
        }
    }

    /// The methods that accept its forces: all, or without a velocity-dependent force those that
    /// need forces of position alone (the Nyström methods) left out.
    pub fn methods(&self) -> Vec<Method> {
        let v = self.velocity_dependent();
        Method::ALL
            .into_iter()
            .filter(|m| !v || m.info().accepts_velocity_dependent())
            .collect()
    }

    /// The angular frequency stability theory is stated in: sqrt(g/L) for the pendulum (its
    /// small-angle frequency), the pinned-free chain's highest mode for the rope.
    pub fn omega(&self) -> f64 {
        match self {
            Problem::Pendulum(p) => p.omega_n(),
            Problem::Rope(p) => p.omega_max_pinned_free(),
        }
    }

    fn start(&self) -> (Vec<f64>, Vec<f64>) {
        match self {
            Problem::Pendulum(p) => (vec![p.theta0], vec![p.omega0]),
            Problem::Rope(p) => {
                let x = p.initial_positions();
                let v = vec![0.0; x.len()];
                (x, v)
            }
        }
    }
}

/// The coarsest step [s] and the duration [s] a study uses unless told otherwise: for the
/// pendulum 0.02 s over 10 s, for the rope 0.002 s over 1 s.
pub fn default_schedule(scene: &Problem) -> (f64, f64) {
    match scene {
        Problem::Pendulum(_) => (0.02, 10.0),
        Problem::Rope(_) => (0.002, 1.0),
    }
}

/// Spring stiffness of the rope the convergence and work-precision studies use by default
/// [N/m]: softer than the scene's, so that every explicit method converges over the sweep.
pub const STUDY_ROPE_STIFFNESS: f64 = 100.0;

/// The rope the studies use by default: undamped, so that the theory's orders apply, and (for
/// convergence and cost, not stability) as soft as [`STUDY_ROPE_STIFFNESS`].
pub fn study_rope(stability: bool) -> RopeParams {
    let scene = RopeParams::default();
    RopeParams {
        stiffness: if stability {
            scene.stiffness
        } else {
            STUDY_ROPE_STIFFNESS
        },
        spring_damping: 0.0,
        air_drag: 0.0,
        ..scene
    }
}

/// Step sizes a sweep tries by default.
pub const DEFAULT_LEVELS: u32 = 6;
/// Timed repeats per run by default (the median is kept).
pub const DEFAULT_REPEATS: u32 = 5;
/// Steps a stability trial must stay bounded for by default.
pub const DEFAULT_STABILITY_STEPS: u64 = 2000;

/// The adaptive methods' tolerances in a work-precision sweep by default: 1e-3 to 1e-13.
pub fn default_rtols() -> Vec<f64> {
    (3..=13).map(|k| 10f64.powi(-k)).collect()
}

impl Sweep {
    /// The study's default sweep of `problem`: every method it accepts, its default schedule.
    pub fn defaults(problem: &Problem) -> Self {
        let (dt0, duration) = default_schedule(problem);
        Sweep {
            dt0,
            levels: DEFAULT_LEVELS,
            duration,
            methods: problem.methods(),
            options: MethodOptions::default(),
            repeats: DEFAULT_REPEATS,
            rtols: default_rtols(),
        }
    }
}

/// One measured run.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: &'static str,
    pub method: Method,
    pub dt: f64,
    /// The adaptive method's tolerance; `None` for fixed-step methods.
    pub rtol: Option<f64>,
    /// Largest deviation from the reference over the run; `None` when the run diverged.
    pub error: Option<f64>,
    /// Force evaluations over the run (rejected steps' included).
    pub evals: u64,
    /// Steps the method accepted (an adaptive method's own steps; the fixed-step count otherwise).
    pub accepted: u64,
    /// Steps the error control rejected (0 for fixed-step methods).
    pub rejected: u64,
    /// Median wall time over the repeats [s].
    pub wall_seconds: f64,
}

/// What one measured run gives: the largest |x - reference| at the sample times (`None` when
/// the state stops being finite), and what it spent.
struct Measured {
    error: Option<f64>,
    evals: u64,
    accepted: u64,
    rejected: u64,
    wall: f64,
}

/// Coordinates stepped between looks at the stop flag: an atomic load, free at this stride, and
/// well under a millisecond of stepping (4096 steps of the pendulum; one step of a rope of more
/// than 1365 nodes, whose single step may take milliseconds).
pub const STOP_CHECK_STEPS: u64 = 4096;

/// Steps between looks at the stop flag for a state of `coordinates` numbers: a fixed amount of
/// work between looks, however large the system, so that a stop is seen within milliseconds.
fn stop_stride(coordinates: usize) -> u64 {
    (STOP_CHECK_STEPS / coordinates.max(1) as u64).max(1)
}

/// Whether a stop was asked for.
fn stop() -> bool {
    crate::interrupt::requested()
}

/// Takes `n` steps, looking at the stop flag every [`stop_stride`]; false when stopped.
fn steps<S: SecondOrderSystem>(it: &mut Integrator, sys: &S, n: u64) -> bool {
    let stride = stop_stride(it.position().len());
    let mut left = n;
    while left > 0 {
        let chunk = left.min(stride);
        for _ in 0..chunk {
            it.step(sys);
        }
        left -= chunk;
        if stop() {
            return false;
        }
    }
    true
}

/// One run of a sweep: the method, its step, its options and its steps per sample.
type Trial = (Method, f64, MethodOptions, u64);

/// Steps the trial's method over the reference's sample times and measures it (`None` when
/// stopped).
fn measure<S: SecondOrderSystem>(
    sys: &S,
    start: &(Vec<f64>, Vec<f64>),
    reference: &[Vec<f64>],
    (method, dt, options, per_sample): Trial,
) -> Option<Measured> {
    let began = Instant::now();
    let mut it = Integrator::new(method, sys, &start.0, &start.1, dt, options);
    let mut worst: f64 = 0.0;
    for r in reference {
        if !steps(&mut it, sys, per_sample) {
            return None;
        }
        let x = it.position();
        let err = x
            .iter()
            .zip(r)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        if !err.is_finite() {
            worst = f64::NAN;
            break;
        }
        worst = worst.max(err);
    }
    let wall = began.elapsed().as_secs_f64();
    Some(Measured {
        error: worst.is_finite().then_some(worst),
        evals: it.evals(),
        accepted: it.accepted_steps(),
        rejected: it.rejected_steps(),
        wall,
    })
}

/// The reference positions at t = k·sample_dt, k = 1..=samples, and an estimate of its own
/// error; `None` when stopped.
pub fn reference(
    problem: &Problem,
    sample_dt: f64,
    samples: usize,
    finest_dt: f64,
) -> Option<(Vec<Vec<f64>>, f64)> {
    let rope = match problem {
        Problem::Rope(rope) => Rope::new(rope.clone()),
        Problem::Pendulum(p) => {
            if let Some(exact) = ExactPendulum::new(p) {
                let r = (1..=samples)
                    .map(|k| vec![exact.state(k as f64 * sample_dt).0])
                    .collect();
                return Some((r, exact.theta_accuracy(samples as f64 * sample_dt)));
            }
            // No closed form (ω0 ≠ 0): the scene's fine-step reference, stepped as the scene
            // steps it (compensated sums, its estimate checked against mpmath over whole runs).
            // Not finer: below its step the error is round-off amplified by the motion, which
            // the estimate (Richardson between two step sizes) does not see.
            let mut fine = FineStepReference::new(p, sample_dt);
            let r: Vec<Vec<f64>> = (0..samples).map(|_| vec![fine.advance().0]).collect();
            if crate::interrupt::requested() || r.iter().any(|x| !x[0].is_finite()) {
                return None;
            }
            return Some((r, fine.error_estimate()));
        }
    };
    let h = finest_dt / 8.0;
    let per = (sample_dt / h).round() as u64;
    let start = problem.start();
    let run = |h: f64, per: u64| fine_run(&rope, &start, h, per, samples);
    let fine = run(h, per)?;
    let coarse = run(2.0 * h, per / 2)?;
    let diff = fine
        .iter()
        .zip(&coarse)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max);
    Some((fine, diff / 15.0))
}

fn fine_run<S: SecondOrderSystem>(
    sys: &S,
    start: &(Vec<f64>, Vec<f64>),
    h: f64,
    per: u64,
    samples: usize,
) -> Option<Vec<Vec<f64>>> {
    let mut it = Integrator::new(
        Method::Rk4,
        sys,
        &start.0,
        &start.1,
        h,
        MethodOptions::default(),
    );
    (0..samples)
        .map(|_| steps(&mut it, sys, per).then(|| it.position().to_vec()))
        .collect()
}

/// Errors are compared every this many coarsest steps: often enough to catch the largest
/// deviation (not only turning points), seldom enough that dopri5 chooses its own substeps.
pub const SAMPLE_EVERY: u64 = 16;

/// How a convergence or work-precision sweep is set up.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The coarsest step; the samples are taken every SAMPLE_EVERY × dt0.
    pub dt0: f64,
    /// Number of step sizes dt0, dt0/2, ...
    pub levels: u32,
    pub duration: f64,
    pub methods: Vec<Method>,
    pub options: MethodOptions,
    /// Timed repeats per run (the median is kept).
    pub repeats: u32,
    /// The adaptive methods' tolerances (each runs with each, asked for the sample times).
    pub rtols: Vec<f64>,
}

impl Sweep {
    /// The sweep's own numbers within their ranges, each named by the flag that sets it, and its
    /// reference within the step limit.
    pub fn validate(&self) -> Result<(), Invalid> {
        params::count_within("--levels", self.levels.into(), 2, 20)?;
        params::count_within("--repeats", self.repeats.into(), 1, 100)?;
        for &rtol in &self.rtols {
            params::rtol(rtol)?;
        }
        params::positive("--dt", self.dt0, "s")?;
        params::positive("--duration", self.duration, "s")?;
        // Errors are compared every SAMPLE_EVERY coarsest steps; fewer than one sample fits
        // nothing.
        let longest = self.duration / SAMPLE_EVERY as f64;
        if self.dt0 > longest {
            return Err(Invalid::Usage(format!(
                "--dt {}: must not exceed --duration / {SAMPLE_EVERY} = {} s (errors are sampled \
                 every {SAMPLE_EVERY} coarsest steps)",
                params::shown(self.dt0),
                params::shown(longest),
            )));
        }
        let reference_steps = self.reference_steps();
        if reference_steps > params::MAX_STEPS {
            return Err(Invalid::Usage(format!(
                "{} needs {reference_steps:.2e} reference steps; at most {:.0e} are allowed \
                 (raise --dt or lower --levels)",
                self.schedule(),
                params::MAX_STEPS
            )));
        }
        Ok(())
    }

    /// The reference's steps: 8× finer than the finest level.
    pub fn reference_steps(&self) -> f64 {
        8.0 * self.duration / self.finest()
    }

    /// The finest level's step.
    fn finest(&self) -> f64 {
        self.dt0 / 2f64.powi(self.levels as i32 - 1)
    }

    /// The schedule as its flags say it, for messages.
    pub fn schedule(&self) -> String {
        format!(
            "--dt {} with --levels {} over --duration {} s",
            params::shown(self.dt0),
            self.levels,
            params::shown(self.duration)
        )
    }
}

/// A stability study's steps per trial within their range.
pub fn validate_stability_steps(steps: u64) -> Result<(), Invalid> {
    params::count_within("--steps", steps, 10, 10_000_000)
}

/// Every (method, dt) of the sweep: fixed-step methods over the halved steps, the adaptive
/// methods (family `Adaptive`: dopri5, dop853, vern9) over their tolerances. Returns the rows and
/// the reference's accuracy (the exact pendulum's [`theta_accuracy`] over the run, or the fine run's
/// Richardson estimate); after a stop request, the rows complete so far (none if the reference
/// was not).
///
/// [`theta_accuracy`]: crate::scene::pendulum::reference::ExactPendulum::theta_accuracy
pub fn sweep(problem: &Problem, s: &Sweep) -> (Vec<Row>, f64) {
    let sample_dt = SAMPLE_EVERY as f64 * s.dt0;
    let samples = ((s.duration / sample_dt).round() as usize).max(1);
    let Some((reference, reference_error)) = reference(problem, sample_dt, samples, s.finest())
    else {
        return (Vec::new(), 0.0);
    };
    let start = problem.start();
    let mut rows = Vec::new();
    let mut one = |trial: Trial, rtol: Option<f64>| {
        let (method, dt, ..) = trial;
        let mut walls = Vec::new();
        let mut result = None;
        for _ in 0..s.repeats.max(1) {
            let Some(m) = (match problem {
                Problem::Pendulum(p) => measure(&Pendulum::new(p), &start, &reference, trial),
                Problem::Rope(p) => measure(&Rope::new(p.clone()), &start, &reference, trial),
            }) else {
                return;
            };
            walls.push(m.wall);
            result = Some(m);
        }
        walls.sort_by(f64::total_cmp);
        let m = result.expect("at least one repeat");
        rows.push(Row {
            scene: problem.name(),
            method,
            dt,
            rtol,
            error: m.error,
            evals: m.evals,
            accepted: m.accepted,
            rejected: m.rejected,
            wall_seconds: walls[walls.len() / 2],
        });
    };
    for &m in &s.methods {
        if m.info().adaptive() {
            // Adaptive: it is asked for the sample times only and chooses its steps itself.
            for &rtol in &s.rtols {
                if stop() {
                    break;
                }
                one(
                    (m, sample_dt, MethodOptions { rtol, ..s.options }, 1),
                    Some(rtol),
                );
            }
        } else {
            for k in 0..s.levels {
                if stop() {
                    break;
                }
                one(
                    (m, s.dt0 / 2f64.powi(k as i32), s.options, SAMPLE_EVERY << k),
                    None,
                );
            }
        }
    }
    (rows, reference_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Yoshida-4's stability limit on x'' = -x: the root of trace(M(w1 h) M(w0 h) M(w1 h)) = 2 for
    /// the closed-form position-Verlet matrix M, 1.57340194743454005662957944196 by
    /// `tests/data/yoshida4_stability.py` (mpmath, 80 digits), as the nearest double. Nothing here
    /// comes from `yoshida4_limit` or `yoshida_weights`.
    const LIMIT_MPMATH: f64 = 1.573_401_947_434_54;

    /// The same root in f64, by bisection on the closed form written out here: one
    /// drift-kick-drift step of size t is [[1 - t²/2, t - t³/4], [-t, 1 - t²/2]], and the weights
    /// are w1 = 1/(2 - ∛2), w0 = 1 - 2 w1.
    fn limit_from_the_closed_form() -> f64 {
        type M = [[f64; 2]; 2];
        let step = |t: f64| -> M {
            [
                [1.0 - t * t / 2.0, t - t * t * t / 4.0],
                [-t, 1.0 - t * t / 2.0],
            ]
        };
        let mul = |a: M, b: M| -> M {
            std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
        };
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
        type M = [[f64; 2]; 2];
        let step = |t: f64| -> M {
            [
                [1.0 - t * t / 2.0, t - t * t * t / 4.0],
                [-t, 1.0 - t * t / 2.0],
            ]
        };
        let mul = |a: M, b: M| -> M {
            std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
        };
        let trace = |h: f64| {
            let p = w
                .iter()
                .fold([[1.0, 0.0], [0.0, 1.0]], |p, &wk| mul(step(wk * h), p));
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

    /// The higher-order compositions' stability limits (the first instability from h = 0; past
    /// it the trace comes back below 2, see `tests/data/composition_stability.py`): the
    /// registry's constants are the mpmath roots, and two f64 roots agree with them: bisection
    /// on the closed-form matrix product here and `composition_limit` on the stepper's
    /// drift/kick sequence, to 1e-11 relative (measured 2e-16 to 3e-15 for yoshida6 and
    /// kahan-li8, 1.7e-13 for sofroniou10, whose trace crosses 2 slowly, at slope about 7e-4,
    /// so that its round-off moves the root further). The
    /// stepper's own one-step matrix is stable on a grid of 10⁴ steps up to the limit and at
    /// 1 - 10⁻ᵏ of it (k = 3..6), unstable at 1 + 10⁻⁶ of it.
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
