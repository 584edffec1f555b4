//! A study's problem resolved from its flags and scene file, with the flags each study kind
//! uses (the others refused) and a warning when it will run long.

use super::Error;
use super::SceneFile;
use crate::app::layers::table_of;
use crate::app::load_scene_file;
use crate::app::scenes::given;
use crate::cli::{PendulumArgs, RopeArgs, STUDY_FLAG_KINDS, StudyArgs, StudyKind, StudyScene};
use crate::integrate::{Method, MethodOptions};
use crate::scene::params::{MAX_NODE_STEPS, MAX_STEPS};
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;
use crate::study::{Problem, Sweep};

/// Steps a whole study may take (every method, level and repeat, and the reference): ten
/// times what one scene's method may, about as long as a scene running ten methods.
pub(super) const STUDY_MAX_STEPS: f64 = 10.0 * MAX_STEPS;

/// Wall time of one node-step (one coordinate triple stepped once) in the estimate a long study
/// is warned with [s]: RK4 on the rope, the common case, measured at 10,000–100,000 nodes on a
/// 2-core x86-64 machine, rounded up; implicit methods cost more, the pendulum less.
pub(super) const SECONDS_PER_NODE_STEP: f64 = 60e-9;

/// Estimated wall time beyond which a study says, before it starts, how long it will take [s].
pub(super) const LONG_STUDY_SECONDS: f64 = 60.0;

/// Warns on stderr, before the work starts, when a study of `node_steps` will take minutes.
pub(super) fn warn_if_long(node_steps: f64) {
    let seconds = node_steps * SECONDS_PER_NODE_STEP;
    if seconds > LONG_STUDY_SECONDS {
        eprintln!(
            "warning: this study is {node_steps:.1e} node-steps, roughly {:.0} minutes at ~{:.0} ns each (more with implicit methods); Ctrl-C stops it and keeps the complete rows",
            (seconds / 60.0).ceil(),
            SECONDS_PER_NODE_STEP * 1e9
        );
    }
}

/// The study's problem and sweep from its flags, over the scene file, over the scene defaults
/// (for the rope's convergence and cost: a softer, undamped rope, so that explicit methods
/// converge and the theory's orders apply).
/// Also returns the study's scene as a scene file (its problem, dt, duration and methods), the
/// provenance of its recording.
pub(super) fn setup(a: &StudyArgs) -> Result<(Problem, Sweep, u64, SceneFile), Error> {
    let file = load_scene_file(a.config.as_deref())?;
    let stability_study = a.kind == StudyKind::Stability;
    let steps = a.steps.unwrap_or(crate::study::DEFAULT_STABILITY_STEPS);
    crate::study::validate_stability_steps(steps)?;
    // Flags of the other scene would be silently ignored: refuse them.
    let (pendulum_flags, rope_flags) = (
        [
            ("--theta0", a.pendulum.theta0.is_some()),
            ("--omega0", a.pendulum.omega0.is_some()),
        ],
        [
            ("--nodes", a.rope.nodes.is_some()),
            ("--stiffness", a.rope.stiffness.is_some()),
            ("--mass", a.rope.mass.is_some()),
            ("--spring-damping", a.rope.spring_damping.is_some()),
            ("--air-drag", a.rope.air_drag.is_some()),
        ],
    );
    let scene = a.scene.unwrap_or(StudyScene::Pendulum);
    let foreign = match scene {
        StudyScene::Pendulum => rope_flags.iter().find(|f| f.1).map(|f| (f.0, "rope")),
        StudyScene::Rope => pendulum_flags
            .iter()
            .find(|f| f.1)
            .map(|f| (f.0, "pendulum")),
    };
    if let Some((flag, scene)) = foreign {
        return Err(Error::Usage(format!(
            "{flag} is a {scene} parameter; add --scene {scene}, or drop it"
        )));
    }
    // The scene's configuration: the study's flags over the scene file over the scene's
    // defaults (the rope's replaced by the study's own, see above).
    let (problem, table) = match scene {
        StudyScene::Pendulum => {
            let mut layers = given(&PendulumArgs::default(), "pendulum", &file)?;
            layers.flags = table_of(&a.pendulum)?;
            let config: PendulumConfig = layers.resolve()?;
            (Problem::Pendulum(config.params), table_of(&config)?)
        }
        StudyScene::Rope => {
            let study = crate::study::study_rope(stability_study);
            let mut layers = given(&RopeArgs::default(), "rope", &file)?;
            layers.defaults = toml::Table::from_iter([
                ("stiffness".to_string(), study.stiffness.into()),
                ("spring_damping".to_string(), study.spring_damping.into()),
                ("air_drag".to_string(), study.air_drag.into()),
            ]);
            layers.flags = table_of(&a.rope)?;
            let config: RopeConfig = layers.resolve()?;
            let table = table_of(&config)?;
            (Problem::Rope(config.params), table)
        }
    };
    // The scene file's schedule and methods apply too: its dt is the coarsest step.
    let scene_name = problem.name();
    let from_file = |key: &str| {
        file.table(scene_name)
            .is_some_and(|t| t.contains_key(key))
            .then(|| table[key].clone())
    };
    let file_dt = from_file("dt").and_then(|v| v.as_float());
    let file_duration = from_file("duration").and_then(|v| v.as_float());
    let file_methods: Option<Vec<Method>> = from_file("methods").and_then(|v| v.try_into().ok());
    let given = a.methods.clone().or(file_methods);
    // By default every method that accepts the problem's forces (the drift study: its own
    // set); named ones are checked.
    let methods = match (&problem, given) {
        (Problem::Rope(p), Some(given)) => {
            crate::scene::rope::run::refuse_position_only_methods(p, &given)?;
            given
        }
        (_, Some(given)) => given,
        (_, None) if a.kind == StudyKind::Drift => crate::study::drift::default_methods(&problem),
        (problem, None) => problem.methods(),
    };
    if methods.is_empty() {
        let origin = match &a.config {
            Some(path) if a.methods.is_none() => {
                format!("--config {}: [{scene_name}] methods = []", path.display())
            }
            _ => "--methods []".into(),
        };
        return Err(Error::Usage(format!(
            "{origin}: must name at least one method (any of: {})",
            Method::names().collect::<Vec<_>>().join(", ")
        )));
    }
    // Tolerances only an adaptive method takes: without one they would be ignored.
    if a.rtol.is_some() && !methods.iter().any(|m| m.info().adaptive()) {
        return Err(Error::Usage(format!(
            "--rtol: no adaptive method among --methods ({}) takes a tolerance; add one or drop --rtol",
            methods
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(",")
        )));
    }
    if a.kind == StudyKind::Drift {
        return drift_setup(a, problem, (file_dt, file_duration), methods, table);
    }
    let (default_dt, default_duration) = crate::study::default_schedule(&problem);
    let (dt0, duration) = (
        a.dt.or(file_dt).unwrap_or(default_dt),
        a.duration.or(file_duration).unwrap_or(default_duration),
    );
    let sweep = Sweep {
        dt0,
        levels: a.levels.unwrap_or(crate::study::DEFAULT_LEVELS),
        duration,
        methods,
        options: MethodOptions::default(),
        repeats: a.repeats.unwrap_or(crate::study::DEFAULT_REPEATS),
        rtols: a.rtol.clone().unwrap_or_else(crate::study::default_rtols),
    };
    sweep.validate()?;
    let (levels, repeats, methods) = (sweep.levels, sweep.repeats, &sweep.methods);
    let reference_steps = sweep.reference_steps();
    let schedule = sweep.schedule();
    // Work per step (coordinates stepped) and memory, for every phase, up front.
    let (work_per_step, dim) = match &problem {
        Problem::Pendulum(_) => (1.0, 1.0),
        Problem::Rope(p) => (p.nodes as f64, 3.0 * p.nodes as f64),
    };
    let nodes = match &problem {
        Problem::Pendulum(_) => String::new(),
        Problem::Rope(p) => format!(" × --nodes {}", p.nodes),
    };
    let fixed = methods.iter().filter(|m| !m.info().adaptive()).count() as f64;
    let work = match a.kind {
        StudyKind::Convergence | StudyKind::WorkPrecision => {
            // The reference (fine and coarse runs, for its error estimate), and every fixed-step
            // method over dt0, dt0/2, ... dt0/2^(levels-1), each `repeats` times (the damped
            // rope's second sweep doubles it).
            let sweeps = if a.kind == StudyKind::Convergence && matches!(problem, Problem::Rope(_))
            {
                2.0
            } else {
                1.0
            };
            let steps = sweeps
                * (1.5 * reference_steps
                    + fixed * repeats as f64 * (duration / dt0) * (2f64.powi(levels as i32) - 1.0));
            let work = steps * work_per_step;
            if steps > STUDY_MAX_STEPS || work > MAX_NODE_STEPS {
                return Err(Error::Usage(format!(
                    "{schedule}, --repeats {repeats}{nodes} and {fixed} fixed-step methods is {steps:.2e} steps \
                     ({work:.2e} node-steps) in all; at most {STUDY_MAX_STEPS:.0e} steps and {MAX_NODE_STEPS:.0e} \
                     node-steps are allowed (raise --dt, lower --levels or --repeats, or choose fewer --methods)"
                )));
            }
            // The reference is kept at every sample, twice (fine and coarse).
            let samples = duration / (crate::study::SAMPLE_EVERY as f64 * dt0);
            crate::scene::params::memory(
                &format!("the reference for {schedule}{nodes}"),
                2.0 * samples * dim * 8.0,
                "raise --dt or shorten --duration",
            )?;
            work
        }
        StudyKind::Stability => {
            // Each method: one trial at the bracket's low end and 40 bisections, of up to
            // --steps steps each.
            let runs = 41.0 * methods.len() as f64;
            let work = runs * steps as f64 * work_per_step;
            if work > MAX_NODE_STEPS {
                return Err(Error::Usage(format!(
                    "--steps {steps}{nodes} over {} methods × 41 bisection trials is {work:.2e} node-steps; at most \
                     {MAX_NODE_STEPS:.0e} are allowed (lower --steps or choose fewer --methods)",
                    methods.len()
                )));
            }
            work
        }
        StudyKind::Hair => unreachable!("the hair study has its own setup (hair_study)"),
        StudyKind::Drift => unreachable!("drift_setup returned above"),
    };
    warn_if_long(work);
    let effective = effective_file(&problem, table, &sweep)?;
    Ok((problem, sweep, steps, effective))
}

/// The study's scene as a scene file: the scene's table with the schedule and methods the sweep
/// starts from.
fn effective_file(
    problem: &Problem,
    mut table: toml::Table,
    sweep: &Sweep,
) -> Result<SceneFile, Error> {
    table.insert("dt".into(), sweep.dt0.into());
    table.insert("duration".into(), sweep.duration.into());
    let methods = toml::Value::try_from(&sweep.methods).map_err(|e| Error::Runtime(e.into()))?;
    table.insert("methods".into(), methods);
    let mut effective = SceneFile::default();
    effective.set(problem.name(), table);
    Ok(effective)
}

/// The drift study's problem and schedule: the pendulum released from rest (the closed form
/// gives the exact crossings) or the rope (whose energy balance is kept or not), one tolerance
/// for the adaptive methods, and its steps within the study's limits.
fn drift_setup(
    a: &StudyArgs,
    problem: Problem,
    (file_dt, file_duration): (Option<f64>, Option<f64>),
    methods: Vec<Method>,
    table: toml::Table,
) -> Result<(Problem, Sweep, u64, SceneFile), Error> {
    let (default_dt, default_duration, nodes) = match &problem {
        Problem::Pendulum(p) => {
            let Some(exact) = crate::scene::pendulum::reference::ExactPendulum::new(p) else {
                return Err(Error::Usage(format!(
                    "--theta0 {}: `study drift` needs a release from rest with |θ0| < 180° (the \
                     closed form's crossings are the reference)",
                    crate::scene::params::shown(p.theta0.to_degrees())
                )));
            };
            // At rest at the bottom (or so near it that E0 is 0 in f64) nothing moves: there
            // is no energy error to relate to E0 and no crossing to time.
            if p.initial_energy() <= 0.0 {
                return Err(Error::Usage(format!(
                    "--theta0 {}: `study drift` needs a swing to measure; released from rest \
                     there the pendulum's energy is {:e} J/kg (choose |θ0| between 0° and 180°, \
                     e.g. 60)",
                    crate::scene::params::shown(p.theta0.to_degrees()),
                    p.initial_energy()
                )));
            }
            let periods = crate::study::drift::DEFAULT_PERIODS;
            (
                crate::study::drift::DEFAULT_DT,
                periods * exact.period(),
                1.0,
            )
        }
        Problem::Rope(p) => {
            let (dt, duration) = (
                crate::study::drift::ROPE_DT,
                crate::study::drift::ROPE_DURATION,
            );
            (dt, duration, p.nodes as f64)
        }
    };
    let dt = a.dt.or(file_dt).unwrap_or(default_dt);
    let duration = a.duration.or(file_duration).unwrap_or(default_duration);
    crate::scene::params::positive("--dt", dt, "s")?;
    crate::scene::params::positive("--duration", duration, "s")?;
    let rtol = match a.rtol.as_deref() {
        None => MethodOptions::default().rtol,
        Some([one]) => *one,
        Some(more) => {
            return Err(Error::Usage(format!(
                "--rtol {}: `study drift` runs each adaptive method at one tolerance; give one",
                more.iter()
                    .map(|r| format!("{r:e}"))
                    .collect::<Vec<_>>()
                    .join(",")
            )));
        }
    };
    crate::scene::params::rtol(rtol)?;
    let steps = methods.len() as f64 * duration / dt;
    if steps > STUDY_MAX_STEPS || steps * nodes > MAX_NODE_STEPS || duration / dt < 10.0 {
        return Err(Error::Usage(format!(
            "--dt {} over --duration {} s with {} methods is {steps:.2e} steps; between 10 per \
             method and {STUDY_MAX_STEPS:.0e} in all ({MAX_NODE_STEPS:.0e} node-steps) are \
             allowed (raise --dt, shorten --duration or choose fewer --methods)",
            crate::scene::params::shown(dt),
            crate::scene::params::shown(duration),
            methods.len()
        )));
    }
    warn_if_long(steps * nodes);
    let sweep = Sweep {
        dt0: dt,
        levels: 1,
        duration,
        methods,
        options: MethodOptions {
            rtol,
            ..MethodOptions::default()
        },
        repeats: 1,
        rtols: vec![rtol],
    };
    let effective = effective_file(&problem, table, &sweep)?;
    Ok((problem, sweep, 0, effective))
}

/// Every flag of `physlab study` that only some kinds use, whether it was given, and the kinds
/// that use it (`cli::STUDY_FLAG_KINDS`). Stability measures the linearised problem (θ0 = 1e-8
/// rad at rest, an undamped rope) for `--steps` steps, so it takes no start, damping or
/// schedule; the hair study runs the hair scene's defaults over `--duration`.
pub(super) fn flag_uses(a: &StudyArgs) -> Vec<(&'static str, bool, &'static [StudyKind])> {
    let given = [
        ("--scene", a.scene.is_some()),
        ("--config", a.config.is_some()),
        ("--theta0", a.pendulum.theta0.is_some()),
        ("--omega0", a.pendulum.omega0.is_some()),
        ("--nodes", a.rope.nodes.is_some()),
        ("--mass", a.rope.mass.is_some()),
        ("--stiffness", a.rope.stiffness.is_some()),
        ("--spring-damping", a.rope.spring_damping.is_some()),
        ("--air-drag", a.rope.air_drag.is_some()),
        ("--duration", a.duration.is_some()),
        ("--dt", a.dt.is_some()),
        ("--levels", a.levels.is_some()),
        ("--methods", a.methods.is_some()),
        ("--rtol", a.rtol.is_some()),
        ("--repeats", a.repeats.is_some()),
        ("--steps", a.steps.is_some()),
        ("--plots", a.plots.is_some()),
    ];
    STUDY_FLAG_KINDS
        .iter()
        .map(|&(flag, kinds)| {
            let was = given.iter().any(|&(f, g)| f == flag && g);
            (flag, was, kinds)
        })
        .collect()
}

/// Refuses a flag the study kind would ignore, naming the flag, the kind and the kinds that
/// take it.
pub(super) fn refuse_unused(a: &StudyArgs) -> Result<(), Error> {
    for (flag, given, kinds) in flag_uses(a) {
        if given && !kinds.contains(&a.kind) {
            let takers: Vec<String> = kinds
                .iter()
                .map(|&k| format!("`study {}`", k.name()))
                .collect();
            return Err(Error::Usage(format!(
                "{flag}: `study {}` does not use it (it is for {}); drop it",
                a.kind.name(),
                takers.join(", ")
            )));
        }
    }
    Ok(())
}
