//! Convergence and work-precision sweeps: every method over halved steps (the adaptive ones over
//! tolerances), each run's largest deviation from the reference and what it spent.

use std::time::Instant;

use super::grid;
use super::{
    DEFAULT_LEVELS, DEFAULT_REPEATS, Problem, default_rtols, default_schedule, largest_difference,
    steps,
};
use crate::format;
use crate::integrate::{
    EvalsPerStep, Integrator, Method, MethodOptions, SecondOrderSystem, composition_weights,
    whole_steps,
};
use crate::scene::params::{self, Invalid};
use crate::scene::pendulum::Pendulum;
use crate::scene::pendulum::exact::ExactPendulum;
use crate::scene::pendulum::reference::FineStepReference;
use crate::scene::rope::Rope;

/// One measured run.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: &'static str,
    pub method: Method,
    pub dt: f64,
    /// The adaptive method's tolerance; `None` for fixed-step methods.
    pub rtol: Option<f64>,
    /// A composition method with compensated sums (`--compensated`).
    pub compensated: bool,
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

/// One run of a sweep: the method, its step, its options, its steps between compared samples
/// and how many samples apart those are.
type Trial = (Method, f64, MethodOptions, u64, usize);

/// Steps the trial's method over the reference's sample times and measures it (`None` when
/// stopped).
fn measure<S: SecondOrderSystem>(
    sys: &S,
    start: &(Vec<f64>, Vec<f64>),
    reference: &[Vec<f64>],
    (method, dt, options, per_sample, every): Trial,
) -> Option<Measured> {
    let began = Instant::now();
    let mut it = Integrator::new(method, sys, &start.0, &start.1, dt, options);
    let mut worst: f64 = 0.0;
    for r in reference.iter().skip(every - 1).step_by(every) {
        if !steps(&mut it, sys, per_sample) {
            return None;
        }
        let err = largest_difference(it.position(), r);
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
    let differences = fine
        .iter()
        .zip(&coarse)
        .map(|(a, b)| largest_difference(a, b));
    let diff = differences.fold(0.0, f64::max);
    Some((fine, diff / 15.0))
}

fn fine_run<S: SecondOrderSystem>(
    sys: &S,
    start: &(Vec<f64>, Vec<f64>),
    h: f64,
    per: u64,
    samples: usize,
) -> Option<Vec<Vec<f64>>> {
    let options = MethodOptions::default();
    let mut it = Integrator::new(Method::Rk4, sys, &start.0, &start.1, h, options);
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
    /// The coarsest step.
    pub dt0: f64,
    /// The interval the error is sampled at: a multiple of dt0 (`--sample-every`; by default
    /// SAMPLE_EVERY × the scene's default dt0).
    pub sample_dt: f64,
    /// Whether the fixed-step methods also step across the samples at steps above dt0, up to
    /// 4 × sample_dt, and the compositions also run with compensated sums (work-precision).
    pub all_settings: bool,
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
    /// The study's default sweep of `problem`: every method it accepts, its default schedule.
    pub fn defaults(problem: &Problem) -> Self {
        let (dt0, duration) = default_schedule(problem);
        Sweep {
            dt0,
            sample_dt: SAMPLE_EVERY as f64 * dt0,
            all_settings: false,
            levels: DEFAULT_LEVELS,
            duration,
            methods: problem.methods(),
            options: MethodOptions::default(),
            repeats: DEFAULT_REPEATS,
            rtols: default_rtols(),
        }
    }

    /// `study work-precision`'s default sweep of `problem`: every setting physlab has
    /// ([`Sweep::all_settings`]) and the half-decade tolerances.
    pub fn work_precision(problem: &Problem) -> Self {
        Sweep {
            all_settings: true,
            rtols: super::work_precision_rtols(),
            ..Self::defaults(problem)
        }
    }

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
        params::positive("--sample-every", self.sample_dt, "s")?;
        let rule = format!(
            "must be a multiple of --dt {} s, the fixed-step methods' coarsest step (their steps \
             end at every sample)",
            format::shown(self.dt0)
        );
        let whole = whole_steps(self.sample_dt, self.dt0).is_some();
        params::require(whole, "--sample-every", self.sample_dt, rule)?;
        // Convergence samples every SAMPLE_EVERY coarsest steps: its --dt is what is too large.
        let longest = self.duration / SAMPLE_EVERY as f64;
        if !self.all_settings && self.dt0 > longest {
            return Err(Invalid::Usage(format!(
                "--dt {}: must not exceed --duration / {SAMPLE_EVERY} = {} s (errors are sampled \
                 every {SAMPLE_EVERY} coarsest steps)",
                format::shown(self.dt0),
                format::shown(longest),
            )));
        }
        let rule = format!(
            "must not exceed --duration {} s",
            format::shown(self.duration)
        );
        params::require(
            self.sample_dt <= self.duration,
            "--sample-every",
            self.sample_dt,
            rule,
        )?;
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

    /// The samples the error is taken at: every `sample_dt` to the end of the run.
    pub fn samples(&self) -> usize {
        ((self.duration / self.sample_dt).round() as usize).max(1)
    }

    /// The reference at the samples and its error ([`reference`]); `None` when stopped.
    pub fn reference(&self, problem: &Problem) -> Option<(Vec<Vec<f64>>, f64)> {
        reference(problem, self.sample_dt, self.samples(), self.finest())
    }

    /// The steps above dt0 that `m` also runs at when [`Sweep::all_settings`] and its order is at
    /// least 4 (a lower order needs steps below dt0 for any error worth a target): 4 × sample_dt ×
    /// 2^(-j/8) for j = 0, 1, ... (eight a halving, as in the peer benchmark), to three digits,
    /// each stepping across the samples or, where it divides sample_dt, ending at them.
    pub fn steps_above(&self, m: Method) -> Vec<f64> {
        let top = 4.0 * self.sample_dt;
        let wanted = self.all_settings && !m.info().adaptive() && m.info().order >= 4;
        (0..)
            .map(|j| top * 2f64.powf(-f64::from(j) / 8.0))
            .map(|h| format!("{h:.2e}").parse().unwrap_or(h))
            .take_while(|&h| wanted && h > self.dt0 * (1.0 + 1e-9))
            .collect()
    }

    /// Each fixed-step method's variants: plain, and the compositions compensated too when
    /// [`Sweep::all_settings`].
    fn compensations(&self, m: Method) -> &'static [bool] {
        match self.all_settings && composition_weights(m).is_some() {
            true => &[false, true],
            false => &[false],
        }
    }

    /// The finest level's step.
    fn finest(&self) -> f64 {
        self.dt0 / 2f64.powi(self.levels as i32 - 1)
    }

    /// The schedule as its flags say it, for messages.
    pub fn schedule(&self) -> String {
        format!(
            "--dt {} with --levels {} over --duration {} s",
            format::shown(self.dt0),
            self.levels,
            format::shown(self.duration)
        )
    }
}

/// The runs [`sweep`] makes of `problem`: each accepted method over the levels, or the
/// adaptive ones over the tolerances.
pub fn planned_runs(problem: &Problem, s: &Sweep) -> usize {
    plan(problem, s).len()
}

/// The damped rope `study convergence` runs beside an undamped one (velocity-dependent forces
/// change some methods' orders): the same rope with the scene's default damping and drag.
pub fn damped_companion(problem: &Problem) -> Option<Problem> {
    match problem {
        Problem::Rope(p) if !p.velocity_dependent() => {
            let scene = crate::scene::rope::RopeParams::default();
            Some(Problem::Rope(crate::scene::rope::RopeParams {
                spring_damping: scene.spring_damping,
                air_drag: scene.air_drag,
                ..p.clone()
            }))
        }
        _ => None,
    }
}

/// Every (method, dt) of the sweep: fixed-step methods over the halved steps, the adaptive
/// methods over their tolerances. Returns the rows and the reference's accuracy (the exact
/// pendulum's [`theta_accuracy`] over the run, or the fine run's Richardson estimate); after a
/// stop request, the rows complete so far (none if the reference was not).
///
/// [`theta_accuracy`]: crate::scene::pendulum::exact::ExactPendulum::theta_accuracy
pub fn sweep(problem: &Problem, s: &Sweep) -> (Vec<Row>, f64) {
    sweep_with(problem, s, false, &mut |_| {})
}

/// [`sweep`], the fixed-step methods each on its own grid ([`grid::by_order`]) when `by_order`
/// (`study convergence`), telling `done` the work of each part as it completes (the reference,
/// then each run: the units of [`planned_work`]).
pub fn sweep_with(
    problem: &Problem,
    s: &Sweep,
    by_order: bool,
    done: &mut dyn FnMut(f64),
) -> (Vec<Row>, f64) {
    match s.reference(problem) {
        Some((reference, error)) => {
            let rows = sweep_against(problem, s, (&reference, error), by_order, done);
            (rows, error)
        }
        None => (Vec::new(), 0.0),
    }
}

/// [`sweep_with`] against a reference computed before ([`Sweep::reference`]: once per study)
/// and its error.
pub fn sweep_against(
    problem: &Problem,
    s: &Sweep,
    (reference, reference_error): (&[Vec<f64>], f64),
    by_order: bool,
    done: &mut dyn FnMut(f64),
) -> Vec<Row> {
    let sample_dt = s.sample_dt;
    done(reference_work(problem, s));
    let start = problem.start();
    let run = |trial: Trial| match problem {
        Problem::Pendulum(p) => measure(&Pendulum::new(p), &start, reference, trial),
        Problem::Rope(p) => measure(&Rope::new(p.clone()), &start, reference, trial),
    };
    let mut rows = Vec::new();
    let mut one = |trial: Trial, rtol: Option<f64>| {
        let (method, dt, options, ..) = trial;
        let mut walls = Vec::new();
        let mut result = None;
        for _ in 0..s.repeats.max(1) {
            let Some(m) = run(trial) else {
                return;
            };
            walls.push(m.wall);
            result = Some(m);
        }
        walls.sort_by(f64::total_cmp);
        let m = result.expect("at least one repeat");
        rows.push(Row {
            // A damped rope's rows are told apart from the undamped one's in one table and CSV.
            scene: match problem.velocity_dependent() {
                true => "rope-damped",
                false => problem.name(),
            },
            method,
            dt: options.step.unwrap_or(dt),
            rtol,
            compensated: options.compensated,
            error: m.error,
            evals: m.evals,
            accepted: m.accepted,
            rejected: m.rejected,
            wall_seconds: walls[walls.len() / 2],
        });
    };
    let floor = super::error_floor(reference_error);
    let mut grid = Vec::new();
    for (part, steps, evals) in plan(problem, s) {
        if crate::interrupt::requested() {
            break;
        }
        match part {
            Part::Asked(m, options, rtol) => one((m, sample_dt, options, 1, 1), rtol),
            Part::Level(m, options, k) => {
                // A method's grid is chosen at its first level, from its order when `by_order`.
                if k == 0 {
                    grid = match by_order {
                        true => grid::by_order(m, problem, s, floor, |l| {
                            run((m, l.dt, options, l.per, l.every))?.error
                        }),
                        false => grid::halving(s),
                    };
                }
                if let Some(l) = grid.get(k) {
                    one((m, l.dt, options, l.per, l.every), None);
                }
            }
        }
        done(work(problem, s, (steps, evals)));
    }
    rows
}

/// One run of a sweep as planned: asked for the sample times only (an adaptive method at its
/// tolerance, or a fixed-step one at a `--step` across them), or a fixed-step method's k-th
/// level on its grid.
enum Part {
    Asked(Method, MethodOptions, Option<f64>),
    Level(Method, MethodOptions, usize),
}

/// The runs of a sweep of `problem`, in the order [`sweep_with`] makes them, each with its
/// steps (a fixed-step method's levels as on the default grid, an adaptive run's steps guessed
/// from its tolerance and order) and force evaluations a step (Newton: about three).
fn plan(problem: &Problem, s: &Sweep) -> Vec<(Part, f64, f64)> {
    let samples = s.duration / s.sample_dt;
    let mut parts = Vec::new();
    for m in s.methods.iter().copied().filter(|&m| problem.accepts(m)) {
        let (order, evals) = (f64::from(m.info().order), m.info().evals_per_step);
        let per_step = match evals {
            EvalsPerStep::Adaptive(e) => {
                parts.extend(s.rtols.iter().map(|&rtol| {
                    let steps = samples * (1.0 + 0.2 * rtol.powf(-1.0 / order));
                    let options = MethodOptions { rtol, ..s.options };
                    (
                        Part::Asked(m, options, Some(rtol)),
                        steps,
                        f64::from(e.accepted),
                    )
                }));
                continue;
            }
            EvalsPerStep::Fixed(n) => f64::from(n),
            _ => 3.0,
        };
        for &compensated in s.compensations(m) {
            let options = MethodOptions {
                compensated,
                ..s.options
            };
            parts.extend(s.steps_above(m).into_iter().map(|h| {
                let step = Some(h);
                let asked = MethodOptions { step, ..options };
                (Part::Asked(m, asked, None), s.duration / h, per_step)
            }));
            parts.extend((0..s.levels).map(|k| {
                let steps = s.duration / s.dt0 * f64::from(1u32 << k);
                (Part::Level(m, options, k as usize), steps, per_step)
            }));
        }
    }
    parts
}

/// The work of a planned run over its repeats (force evaluations × coordinates): the units the
/// progress bar paces by.
fn work(problem: &Problem, s: &Sweep, (steps, evals): (f64, f64)) -> f64 {
    f64::from(s.repeats.max(1)) * problem.start().0.len() as f64 * steps * evals
}

/// The steps of a sweep's planned runs over their repeats (its reference's not included).
pub fn planned_steps(problem: &Problem, s: &Sweep) -> f64 {
    let steps = plan(problem, s).iter().map(|p| p.1).sum::<f64>();
    f64::from(s.repeats.max(1)) * steps
}

/// The work of a sweep's reference (the rope's fine and coarse runs), in [`plan`]'s units.
fn reference_work(problem: &Problem, s: &Sweep) -> f64 {
    match problem {
        Problem::Rope(_) => 1.5 * 4.0 * s.reference_steps() * problem.start().0.len() as f64,
        Problem::Pendulum(_) => 0.0,
    }
}

/// The whole work of a sweep of `problem`, in the units [`sweep_with`] reports.
pub fn planned_work(problem: &Problem, s: &Sweep) -> f64 {
    let runs = (plan(problem, s).iter())
        .map(|p| work(problem, s, (p.1, p.2)))
        .sum::<f64>();
    reference_work(problem, s) + runs
}
