//! A measuring study's problem resolved from its flags and scene file, its sweep within the
//! work and memory limits.

use toml::Table;

use super::Error;
use crate::app::SceneFile;
use crate::app::layers::table_of;
use crate::app::load_scene_file;
use crate::app::scenes::{MethodFlag, given, refuse_unread};
use crate::cli::{
    DriftArgs, PendulumArgs, RopeArgs, StabilityArgs, StudyScene, StudySceneArgs, SweepArgs,
    WorkPrecisionArgs,
};
use crate::format::shown;
use crate::integrate::{Method, MethodOptions};
use crate::scene::params::{self, MAX_NODE_STEPS, MAX_STEPS};
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;
use crate::study::{self, Problem, Sweep, drift};

/// Steps a whole study may take (every method, level and repeat, and the reference): ten
/// times what one scene's method may, about as long as a scene running ten methods.
pub(super) const STUDY_MAX_STEPS: f64 = 10.0 * MAX_STEPS;

/// Wall time of one node-step in the estimate a long study is warned with [s]: RK4 on the rope,
/// the common case, rounded up; implicit methods cost more, the pendulum less.
pub(super) const SECONDS_PER_NODE_STEP: f64 = 60e-9;

/// A measuring study's problem and sweep, and its scene as a scene file: the provenance of its
/// recording.
pub(super) struct Setup {
    pub(super) problem: Problem,
    pub(super) sweep: Sweep,
    /// The steps each stability trial takes (`study stability`).
    pub(super) steps: u64,
    pub(super) work: f64,
    /// The target errors `study work-precision` answers for, and whether they were given
    /// (given ones the reference cannot resolve are refused, default ones left out).
    pub(super) targets: (Vec<f64>, bool),
    pub(super) file: SceneFile,
}

/// `study convergence` and `study work-precision` (`wp`): the sweep over halved steps (and the
/// adaptive methods over tolerances), within the limits.
pub(super) fn sweep_setup(a: &SweepArgs, wp: Option<&WorkPrecisionArgs>) -> Result<Setup, Error> {
    let scene = Scene::resolve(&a.scene, table_of(&a.start)?, table_of(&a.losses)?, false)?;
    let methods = scene.methods(&a.scene, a.rtol.is_some(), Problem::methods)?;
    let sweep = scene.sweep(a, methods, wp)?;
    let mut targets = (study::DEFAULT_TARGETS.to_vec(), false);
    if let Some(given) = wp.and_then(|w| w.target.as_ref()) {
        study::validate_targets(given)?;
        targets = (given.clone(), true);
    }
    let work = sweep_work(&scene.problem, &sweep, wp.is_none())?;
    Ok(Setup {
        work,
        targets,
        ..scene.with(sweep)?
    })
}

/// Work-precision's horizon in periods and its sample interval (by default the study's default
/// for the scene whatever --dt).
fn horizon(wp: &WorkPrecisionArgs, problem: &Problem, sweep: &mut Sweep) -> Result<(), Error> {
    if let Some(n) = wp.periods {
        params::positive("--periods", n, "periods")?;
        let period = match problem {
            Problem::Pendulum(p) => crate::scene::pendulum::exact::exact_period(p),
            Problem::Rope(_) => None,
        };
        let rule = "needs a scene with a period: the pendulum with a swing (not at rest at the \
                    bottom, not on the separatrix); give --duration in seconds instead";
        let period = period.ok_or_else(|| Error::param("--periods", shown(n), rule))?;
        sweep.duration = n * period;
    }
    sweep.sample_dt = (wp.sample_every).unwrap_or(Sweep::work_precision(problem).sample_dt);
    Ok(())
}

/// `study stability`: the methods' bisections of `--steps` steps each, within the limits.
pub(super) fn stability_setup(a: &StabilityArgs) -> Result<Setup, Error> {
    let steps = a.steps.unwrap_or(study::DEFAULT_STABILITY_STEPS);
    study::validate_stability_steps(steps)?;
    let scene = Scene::resolve(&a.scene, Table::new(), Table::new(), true)?;
    let methods = scene.methods(&a.scene, false, Problem::methods)?;
    let sweep = scene.sweep(&SweepArgs::default(), methods, None)?;
    // Each method: one trial at the bracket's low end and 40 bisections, of up to --steps steps.
    let (work_per_step, _, nodes) = size(&scene.problem);
    let n = sweep.methods.len();
    let work = 41.0 * n as f64 * steps as f64 * work_per_step;
    if work > MAX_NODE_STEPS {
        return Err(Error::Usage(format!(
            "--steps {steps}{nodes} over {n} methods × 41 bisection trials is {work:.2e} node-steps; at most \
             {MAX_NODE_STEPS:.0e} are allowed (lower --steps or choose fewer --methods)"
        )));
    }
    Ok(Setup {
        steps,
        work,
        ..scene.with(sweep)?
    })
}

/// `study drift`: the pendulum released from rest (the closed form gives the exact crossings)
/// or the rope, one tolerance for the adaptive methods, its steps within the study's limits.
pub(super) fn drift_setup(a: &DriftArgs) -> Result<Setup, Error> {
    let theta0 = a.theta0.map(|t| ("theta0".to_string(), t.into()));
    let losses = table_of(&a.losses)?;
    let scene = Scene::resolve(&a.scene, Table::from_iter(theta0), losses, false)?;
    let methods = scene.methods(&a.scene, a.rtol.is_some(), drift::default_methods)?;
    let (default_dt, default_duration, nodes) = drift_defaults(&scene.problem)?;
    let (dt, duration) = scene.schedule(a.dt, a.duration, (default_dt, default_duration));
    params::positive("--dt", dt, "s")?;
    params::positive("--duration", duration, "s")?;
    let rtol = a.rtol.unwrap_or(MethodOptions::default().rtol);
    params::rtol(rtol)?;
    let steps = methods.len() as f64 * duration / dt;
    if steps > STUDY_MAX_STEPS || steps * nodes > MAX_NODE_STEPS || duration / dt < 10.0 {
        return Err(Error::Usage(format!(
            "--dt {} over --duration {} s with {} methods is {steps:.2e} steps; between 10 per \
             method and {STUDY_MAX_STEPS:.0e} in all ({MAX_NODE_STEPS:.0e} node-steps) are \
             allowed (raise --dt, shorten --duration or choose fewer --methods)",
            shown(dt),
            shown(duration),
            methods.len()
        )));
    }
    let setup = scene.with(Sweep {
        dt0: dt,
        sample_dt: study::SAMPLE_EVERY as f64 * dt,
        all_settings: false,
        levels: 1,
        duration,
        methods,
        options: MethodOptions {
            rtol,
            ..MethodOptions::default()
        },
        repeats: 1,
        rtols: vec![rtol],
    })?;
    Ok(Setup {
        work: steps * nodes,
        ..setup
    })
}

/// The drift study's default step and duration for its problem and the coordinates a step
/// moves; a start it cannot measure refused.
fn drift_defaults(problem: &Problem) -> Result<(f64, f64, f64), Error> {
    match problem {
        Problem::Pendulum(p) => {
            let Some(exact) = crate::scene::pendulum::exact::ExactPendulum::new(p) else {
                return Err(Error::Usage(format!(
                    "--theta0 {}: `study drift` needs a release from rest with |θ0| < 180° (the \
                     closed form's crossings are the reference)",
                    shown(p.theta0.to_degrees())
                )));
            };
            // At rest at the bottom (or so near it that E0 is 0 in f64) nothing moves: there
            // is no energy error to relate to E0 and no crossing to time.
            if p.initial_energy() <= 0.0 {
                return Err(Error::Usage(format!(
                    "--theta0 {}: `study drift` needs a swing to measure; released from rest \
                     there the pendulum's energy is {:e} J/kg (choose |θ0| between 0° and 180°, \
                     e.g. 60)",
                    shown(p.theta0.to_degrees()),
                    p.initial_energy()
                )));
            }
            let duration = drift::DEFAULT_PERIODS * exact.period();
            Ok((drift::DEFAULT_DT, duration, 1.0))
        }
        Problem::Rope(p) => Ok((drift::ROPE_DT, drift::ROPE_DURATION, p.nodes as f64)),
    }
}

/// The study's scene before its schedule, and the schedule and methods the scene file sets.
struct Scene {
    problem: Problem,
    table: Table,
    file_dt: Option<f64>,
    file_duration: Option<f64>,
    file_methods: Option<Vec<Method>>,
}

impl Scene {
    /// The study's flags over the scene file over the scene's defaults, the rope's replaced by
    /// the study's own: undamped, so that the theory's orders apply, and but for `stability`
    /// softer, so that explicit methods converge. A flag of the other scene is refused.
    fn resolve(
        s: &StudySceneArgs,
        pendulum: Table,
        losses: Table,
        stability: bool,
    ) -> Result<Scene, Error> {
        let file = load_scene_file(s.config.as_deref())?;
        let mut rope = table_of(&s.rope)?;
        rope.extend(losses);
        let scene = s.scene.unwrap_or(StudyScene::Pendulum);
        let (name, other, foreign) = match scene {
            StudyScene::Pendulum => ("pendulum", "rope", &rope),
            StudyScene::Rope => ("rope", "pendulum", &pendulum),
        };
        if let Some(key) = foreign.keys().next() {
            let flag = key.replace('_', "-");
            return Err(Error::Usage(format!(
                "--{flag} is a {other} parameter; add --scene {other}, or drop it"
            )));
        }
        file.require(name)?;
        let (problem, table) = match scene {
            StudyScene::Pendulum => {
                let mut layers = given(&PendulumArgs::default(), name, &file)?;
                layers.flags = pendulum;
                let config: PendulumConfig = layers.resolve()?;
                (Problem::Pendulum(config.params), table_of(&config)?)
            }
            StudyScene::Rope => {
                let study = study::study_rope(stability);
                let mut layers = given(&RopeArgs::default(), name, &file)?;
                layers.defaults = Table::from_iter([
                    ("stiffness".to_string(), study.stiffness.into()),
                    ("spring_damping".to_string(), study.spring_damping.into()),
                    ("air_drag".to_string(), study.air_drag.into()),
                ]);
                layers.flags = rope;
                let config: RopeConfig = layers.resolve()?;
                let table = table_of(&config)?;
                (Problem::Rope(config.params), table)
            }
        };
        // The scene file's schedule and methods apply too: its dt is the coarsest step.
        let from_file = |key: &str| {
            (file.table(name))
                .is_some_and(|t| t.contains_key(key))
                .then(|| table[key].clone())
        };
        Ok(Scene {
            file_dt: from_file("dt").and_then(|v| v.as_float()),
            file_duration: from_file("duration").and_then(|v| v.as_float()),
            file_methods: from_file("methods").and_then(|v| v.try_into().ok()),
            problem,
            table,
        })
    }

    /// The methods given (the flag over the scene file), else the study's `default`; `--rtol`
    /// given (`rtol`) refused without an adaptive method among them.
    fn methods(
        &self,
        s: &StudySceneArgs,
        rtol: bool,
        default: fn(&Problem) -> Vec<Method>,
    ) -> Result<Vec<Method>, Error> {
        let methods = match s.methods.as_ref().or(self.file_methods.as_ref()) {
            None => default(&self.problem),
            Some(given) => {
                if let Problem::Rope(p) = &self.problem {
                    crate::scene::rope::run::refuse_position_only_methods(p, given)?;
                }
                given.clone()
            }
        };
        let flags = [MethodFlag::rtol(rtol)];
        refuse_unread(&flags, &methods, &Method::ALL, Method::name)?;
        Ok(methods)
    }

    /// The step and duration given, else the scene file's, else `default`.
    fn schedule(&self, dt: Option<f64>, duration: Option<f64>, default: (f64, f64)) -> (f64, f64) {
        (
            dt.or(self.file_dt).unwrap_or(default.0),
            duration.or(self.file_duration).unwrap_or(default.1),
        )
    }

    /// The sweep of `a` (and `wp`) over the scene file over the study's defaults, validated.
    fn sweep(
        &self,
        a: &SweepArgs,
        methods: Vec<Method>,
        wp: Option<&WorkPrecisionArgs>,
    ) -> Result<Sweep, Error> {
        let base = match wp {
            Some(_) => Sweep::work_precision(&self.problem),
            None => Sweep::defaults(&self.problem),
        };
        let (dt0, duration) = self.schedule(a.dt, a.duration, (base.dt0, base.duration));
        let mut sweep = Sweep {
            dt0,
            sample_dt: study::SAMPLE_EVERY as f64 * dt0,
            levels: a.levels.unwrap_or(base.levels),
            duration,
            methods,
            repeats: a.repeats.unwrap_or(base.repeats),
            rtols: a.rtol.clone().unwrap_or(base.rtols.clone()),
            ..base
        };
        if let Some(wp) = wp {
            horizon(wp, &self.problem, &mut sweep)?;
        }
        if let Some(n) = wp.and_then(|w| w.periods) {
            self.refuse_periods(n, &sweep)?;
        }
        sweep.validate()?;
        Ok(sweep)
    }

    /// `--periods n` beyond the study's limits refused by its own name, with the most periods
    /// those allow (found by bisection over the same checks).
    fn refuse_periods(&self, n: f64, sweep: &Sweep) -> Result<(), Error> {
        let period = sweep.duration / n;
        let fits = |n: f64| {
            let s = Sweep {
                duration: n * period,
                ..sweep.clone()
            };
            s.validate().is_ok() && sweep_work(&self.problem, &s, false).is_ok()
        };
        let mut lo = 1.0;
        if fits(n) || !fits(lo) {
            return Ok(());
        }
        let mut hi = n;
        while hi / lo > 1.001 {
            let mid = (lo * hi).sqrt();
            if fits(mid) { lo = mid } else { hi = mid }
        }
        // Two digits, rounded down: the number said fits.
        let unit = 10f64.powf(lo.log10().floor() - 1.0);
        let lo = (lo / unit).floor() * unit;
        let most = crate::format::sig(lo, 2);
        Err(Error::param(
            "--periods",
            shown(n),
            format!(
                "at most about {most} periods ({} s) fit the study's limits on steps, work and \
                 the reference's memory at --dt {} with --levels {}; lower --periods or raise --dt",
                crate::format::sig(lo * period, 2),
                shown(sweep.dt0),
                sweep.levels
            ),
        ))
    }

    /// The study set up, its scene's table with the schedule and methods the sweep starts from.
    fn with(self, sweep: Sweep) -> Result<Setup, Error> {
        let mut table = self.table;
        table.insert("dt".into(), sweep.dt0.into());
        table.insert("duration".into(), sweep.duration.into());
        let methods =
            toml::Value::try_from(&sweep.methods).map_err(|e| Error::Runtime(e.into()))?;
        table.insert("methods".into(), methods);
        let mut file = SceneFile::default();
        file.set(self.problem.name(), table);
        Ok(Setup {
            problem: self.problem,
            sweep,
            steps: 0,
            work: 0.0,
            targets: (Vec::new(), false),
            file,
        })
    }
}

/// Work per step (coordinates stepped), the numbers a state holds, and ` × --nodes N` for the
/// messages.
fn size(problem: &Problem) -> (f64, f64, String) {
    match problem {
        Problem::Pendulum(_) => (1.0, 1.0, String::new()),
        Problem::Rope(p) => {
            let n = p.nodes as f64;
            (n, 3.0 * n, format!(" × --nodes {}", p.nodes))
        }
    }
}

/// A sweep's work in node-steps, the reference's (fine and coarse) and every planned run's,
/// and its reference's memory, refused beyond the limits.
fn sweep_work(problem: &Problem, sweep: &Sweep, convergence: bool) -> Result<f64, Error> {
    let (repeats, schedule) = (sweep.repeats, sweep.schedule());
    let (work_per_step, dim, nodes) = size(problem);
    let sweeps = match convergence && matches!(problem, Problem::Rope(_)) {
        true => 2.0,
        false => 1.0,
    };
    let planned = study::planned_steps(problem, sweep);
    let steps = sweeps * (1.5 * sweep.reference_steps() + planned);
    let work = steps * work_per_step;
    if steps > STUDY_MAX_STEPS || work > MAX_NODE_STEPS {
        return Err(Error::Usage(format!(
            "{schedule}, --repeats {repeats}{nodes} and {} methods is {steps:.2e} steps \
             ({work:.2e} node-steps) in all; at most {STUDY_MAX_STEPS:.0e} steps and \
             {MAX_NODE_STEPS:.0e} node-steps are allowed (raise --dt, lower --levels or --repeats, \
             or choose fewer --methods)",
            sweep.methods.len()
        )));
    }
    // The reference is kept at every sample, twice (fine and coarse).
    params::memory(
        &format!("the reference for {schedule}{nodes}"),
        2.0 * sweep.samples() as f64 * dim * 8.0,
        "raise --dt or shorten --duration",
    )?;
    Ok(work)
}
