//! `physlab study`: resolves the study's scene, runs the measurement, prints markdown tables,
//! and writes the CSV and recording when asked.

use std::fmt::Write as _;

use super::Error;
use super::SceneFile;
use crate::cli::{PendulumArgs, RopeArgs, RopeBody, StudyArgs, StudyKind, StudyScene};
use crate::integrate::{Method, MethodOptions};
use crate::report::study as report;
use crate::scene::params::{MAX_NODE_STEPS, MAX_STEPS, shown};
use crate::study::{Limit, Problem, Sweep, error_floor, stability, sweep};

/// Steps a whole study may take (every method, level and repeat, and the reference): ten
/// times what one scene's method may, about as long as a scene running ten methods.
const STUDY_MAX_STEPS: f64 = 10.0 * MAX_STEPS;

/// Wall time of one node-step (one coordinate triple stepped once) in the estimate a long study
/// is warned with [s]: RK4 on the rope, the common case, measured at 10,000–100,000 nodes on a
/// 2-core x86-64 machine, rounded up; implicit methods cost more, the pendulum less.
const SECONDS_PER_NODE_STEP: f64 = 60e-9;

/// Estimated wall time beyond which a study says, before it starts, how long it will take [s].
const LONG_STUDY_SECONDS: f64 = 60.0;

/// Warns on stderr, before the work starts, when a study of `node_steps` will take minutes.
fn warn_if_long(node_steps: f64) {
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
fn setup(a: &StudyArgs) -> Result<(Problem, Sweep, u64, SceneFile), Error> {
    let file = match &a.config {
        Some(path) => SceneFile::load(path)?,
        None => SceneFile::default(),
    };
    let stability_study = a.kind == StudyKind::Stability;
    let levels = a.levels.unwrap_or(crate::study::DEFAULT_LEVELS);
    if !(2..=20).contains(&levels) {
        return Err(Error::Usage(format!(
            "--levels {levels}: must be between 2 and 20"
        )));
    }
    let repeats = a.repeats.unwrap_or(crate::study::DEFAULT_REPEATS);
    if !(1..=100).contains(&repeats) {
        return Err(Error::Usage(format!(
            "--repeats {repeats}: must be between 1 and 100"
        )));
    }
    let steps = a.steps.unwrap_or(crate::study::DEFAULT_STABILITY_STEPS);
    if !(10..=10_000_000).contains(&steps) {
        return Err(Error::Usage(format!(
            "--steps {steps}: must be between 10 and 10000000"
        )));
    }
    let rtols = a.rtol.clone().unwrap_or_else(crate::study::default_rtols);
    if let Some(bad) = rtols
        .iter()
        .find(|r| !(r.is_finite() && (1e-14..=0.1).contains(*r)))
    {
        return Err(Error::Usage(format!(
            "--rtol {}: must be between 1e-14 and 0.1",
            shown(*bad)
        )));
    }
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
    // The scene file's schedule and methods apply too: its dt is the coarsest step.
    let (file_dt, file_duration, file_methods) = match scene {
        StudyScene::Pendulum => file.pendulum.as_ref().map_or((None, None, None), |t| {
            (t.step.dt, t.step.duration, t.step.methods.clone())
        }),
        StudyScene::Rope => file.rope.as_ref().map_or((None, None, None), |t| {
            (t.step.dt, t.step.duration, t.step.methods.clone())
        }),
    };
    let methods = a
        .methods
        .clone()
        .or(file_methods)
        .unwrap_or_else(|| Method::ALL.to_vec());
    if methods.is_empty() {
        let origin = match &a.config {
            Some(path) if a.methods.is_none() => format!(
                "--config {}: [{}] methods = []",
                path.display(),
                if scene == StudyScene::Rope {
                    "rope"
                } else {
                    "pendulum"
                }
            ),
            _ => "--methods []".into(),
        };
        return Err(Error::Usage(format!(
            "{origin}: must name at least one method (any of: {})",
            Method::names().collect::<Vec<_>>().join(", ")
        )));
    }
    // Tolerances only an adaptive method takes: without one they would be ignored.
    if a.rtol.is_some()
        && !methods
            .iter()
            .any(|m| m.info().family == crate::integrate::Family::Adaptive)
    {
        return Err(Error::Usage(format!(
            "--rtol: no adaptive method among --methods ({}) takes a tolerance; add one or drop --rtol",
            methods
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(",")
        )));
    }
    let mut effective = SceneFile::default();
    let problem = match scene {
        StudyScene::Pendulum => {
            let flags = PendulumArgs {
                initial: a.pendulum.clone(),
                ..PendulumArgs::default()
            };
            let args = flags.over(file.pendulum.unwrap_or_default());
            effective.pendulum = Some(args.clone().over(PendulumArgs::defaults()));
            Problem::Pendulum(super::pendulum_config(&args)?.params)
        }
        StudyScene::Rope => {
            let study = crate::study::study_rope(stability_study);
            let study_defaults = RopeArgs {
                body: RopeBody {
                    stiffness: Some(study.stiffness),
                    spring_damping: Some(study.spring_damping),
                    air_drag: Some(study.air_drag),
                    ..RopeBody::default()
                },
                ..RopeArgs::default()
            };
            let flags = RopeArgs {
                body: a.rope.clone(),
                ..RopeArgs::default()
            };
            let args = flags
                .over(file.rope.unwrap_or_default())
                .over(study_defaults);
            effective.rope = Some(args.clone().effective());
            Problem::Rope(super::rope_config(&args)?.params)
        }
    };
    let (default_dt, default_duration) = crate::study::default_schedule(&problem);
    let (dt0, duration) = (
        a.dt.or(file_dt).unwrap_or(default_dt),
        a.duration.or(file_duration).unwrap_or(default_duration),
    );
    crate::scene::params::positive("--dt", dt0, "s")?;
    crate::scene::params::positive("--duration", duration, "s")?;
    // Errors are compared every SAMPLE_EVERY coarsest steps; fewer than one sample fits nothing.
    let longest = duration / crate::study::SAMPLE_EVERY as f64;
    if dt0 > longest {
        return Err(Error::Usage(format!(
            "--dt {}: must not exceed --duration / {} = {} s (errors are sampled every {} \
             coarsest steps)",
            shown(dt0),
            crate::study::SAMPLE_EVERY,
            shown(longest),
            crate::study::SAMPLE_EVERY
        )));
    }
    // The finest level's steps, and the reference's (8× finer, stored at every sample), must
    // fit in time and memory.
    let finest = dt0 / 2f64.powi(levels as i32 - 1);
    let reference_steps = 8.0 * duration / finest;
    let schedule = format!(
        "--dt {} with --levels {levels} over --duration {} s",
        shown(dt0),
        shown(duration)
    );
    if reference_steps > MAX_STEPS {
        return Err(Error::Usage(format!(
            "{schedule} needs {reference_steps:.2e} reference steps; at most {MAX_STEPS:.0e} are allowed \
             (raise --dt or lower --levels)"
        )));
    }
    // Work per step (coordinates stepped) and memory, for every phase, up front.
    let (work_per_step, dim) = match &problem {
        Problem::Pendulum(_) => (1.0, 1.0),
        Problem::Rope(p) => (p.nodes as f64, 3.0 * p.nodes as f64),
    };
    let nodes = match &problem {
        Problem::Pendulum(_) => String::new(),
        Problem::Rope(p) => format!(" × --nodes {}", p.nodes),
    };
    let fixed = methods
        .iter()
        .filter(|m| m.info().family != crate::integrate::Family::Adaptive)
        .count() as f64;
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
    };
    warn_if_long(work);
    let sweep = Sweep {
        dt0,
        levels,
        duration,
        methods,
        options: MethodOptions::default(),
        repeats,
        rtols,
    };
    // The schedule and methods the sweep starts from, in the scene's table.
    if let Some(t) = effective.pendulum.as_mut() {
        let s = &mut t.step;
        (s.dt, s.duration, s.methods) = (Some(dt0), Some(duration), Some(sweep.methods.clone()));
    }
    if let Some(t) = effective.rope.as_mut() {
        let s = &mut t.step;
        (s.dt, s.duration, s.methods) = (Some(dt0), Some(duration), Some(sweep.methods.clone()));
    }
    Ok((problem, sweep, steps, effective))
}

/// The study kinds, as `physlab study KIND` spells them.
fn kind_name(kind: StudyKind) -> &'static str {
    match kind {
        StudyKind::Convergence => "convergence",
        StudyKind::WorkPrecision => "work-precision",
        StudyKind::Stability => "stability",
        StudyKind::Hair => "hair",
    }
}

/// Every flag of `physlab study` that only some kinds use, whether it was given, and the kinds
/// that use it (`-o`, `--csv` and `-q` serve every kind). Stability measures the linearised
/// problem (θ0 = 1e-8 rad at rest, an undamped rope) for `--steps` steps, so it takes no start,
/// damping or schedule; the hair study runs the hair scene's defaults over `--duration` and
/// draws no diagram.
fn flag_uses(a: &StudyArgs) -> [(&'static str, bool, &'static [StudyKind]); 17] {
    use StudyKind::{Convergence as C, Hair as H, Stability as S, WorkPrecision as W};
    const SWEEP: &[StudyKind] = &[C, W];
    const MEASURED: &[StudyKind] = &[C, W, S];
    [
        ("--scene", a.scene.is_some(), MEASURED),
        ("--config", a.config.is_some(), MEASURED),
        ("--theta0", a.pendulum.theta0.is_some(), SWEEP),
        ("--omega0", a.pendulum.omega0.is_some(), SWEEP),
        ("--nodes", a.rope.nodes.is_some(), MEASURED),
        ("--mass", a.rope.mass.is_some(), MEASURED),
        ("--stiffness", a.rope.stiffness.is_some(), MEASURED),
        ("--spring-damping", a.rope.spring_damping.is_some(), SWEEP),
        ("--air-drag", a.rope.air_drag.is_some(), SWEEP),
        ("--duration", a.duration.is_some(), &[C, W, H]),
        ("--dt", a.dt.is_some(), SWEEP),
        ("--levels", a.levels.is_some(), SWEEP),
        ("--methods", a.methods.is_some(), MEASURED),
        ("--rtol", a.rtol.is_some(), SWEEP),
        ("--repeats", a.repeats.is_some(), SWEEP),
        ("--steps", a.steps.is_some(), &[S]),
        ("--plots", a.plots.is_some(), MEASURED),
    ]
}

/// Refuses a flag the study kind would ignore, naming the flag, the kind and the kinds that
/// take it.
fn refuse_unused(a: &StudyArgs) -> Result<(), Error> {
    for (flag, given, kinds) in flag_uses(a) {
        if given && !kinds.contains(&a.kind) {
            let takers: Vec<String> = kinds
                .iter()
                .map(|&k| format!("`study {}`", kind_name(k)))
                .collect();
            return Err(Error::Usage(format!(
                "{flag}: `study {}` does not use it (it is for {}); drop it",
                kind_name(a.kind),
                takers.join(", ")
            )));
        }
    }
    Ok(())
}

pub fn study(a: &StudyArgs) -> anyhow::Result<()> {
    refuse_unused(a)?;
    if a.kind == StudyKind::Hair {
        return hair_study(a);
    }
    let (problem, sw, steps, scene_file) = setup(a)?;
    let stems: Vec<String> = match a.kind {
        StudyKind::Convergence => vec!["convergence", "convergence-damped"],
        StudyKind::WorkPrecision => vec!["work-precision"],
        _ => vec!["stability"],
    }
    .into_iter()
    .map(|s| format!("{}-{s}", problem.name()))
    .collect();
    let outputs = check_outputs(a, &stems)?;
    let mut out = String::new();
    let csv;
    let mut diagrams: Vec<crate::diagram::Diagram> = Vec::new();
    // Runs (or methods' limits) complete: after Ctrl-C or SIGTERM only those are shown.
    let done;
    match a.kind {
        StudyKind::Convergence | StudyKind::WorkPrecision => {
            let (rows, reference_error) = sweep(&problem, &sw);
            done = rows.len();
            let exact = matches!(&problem, Problem::Pendulum(p)
                if crate::scene::pendulum::reference::ExactPendulum::new(p).is_some());
            let reference = if exact {
                format!(
                    "the exact elliptic solution (θ to {reference_error:.0e} rad over this run: measured against mpmath over whole runs)"
                )
            } else if matches!(&problem, Problem::Pendulum(_)) {
                format!(
                    "the fine-step reference (compensated RK4, as the pendulum scene runs it), its own error estimated at {reference_error:.1e} rad (Richardson; measured against mpmath over whole runs)"
                )
            } else {
                format!(
                    "RK4 at dt/8 of the finest step, its own error estimated at {reference_error:.1e} (Richardson)"
                )
            };
            writeln!(
                out,
                "{} {}: error = largest deviation of the positions from {reference}, sampled every {} s over {} s; \
                 fits leave out errors below {:.0e} (the reference's floor)\n",
                problem.name(),
                if a.kind == StudyKind::Convergence {
                    "convergence"
                } else {
                    "work-precision"
                },
                sw.dt0 * crate::study::SAMPLE_EVERY as f64,
                sw.duration,
                error_floor(reference_error)
            )?;
            if a.kind == StudyKind::Convergence {
                out.push_str(&report::orders_table(
                    &rows,
                    error_floor(reference_error),
                    problem.velocity_dependent(),
                ));
                let stalled = report::stalled_note(&rows, error_floor(reference_error));
                if !stalled.is_empty() {
                    eprint!("{stalled}");
                    out.push('\n');
                    out.push_str(&stalled);
                }
                diagrams.push(crate::diagram::convergence(
                    problem.name(),
                    &rows,
                    error_floor(reference_error),
                    problem.velocity_dependent(),
                ));
                out.push('\n');
                if let Problem::Rope(p) = &problem
                    && !crate::interrupt::requested()
                    && p.spring_damping == 0.0
                    && p.air_drag == 0.0
                {
                    // Velocity-dependent forces change what some methods' orders are: show the
                    // same rope with the scene's damping beside the undamped one.
                    let scene = crate::scene::rope::RopeParams::default();
                    let damped = Problem::Rope(crate::scene::rope::RopeParams {
                        spring_damping: scene.spring_damping,
                        air_drag: scene.air_drag,
                        ..p.clone()
                    });
                    let (damped_rows, damped_error) = sweep(&damped, &sw);
                    // A stop during the damped sweep leaves it out: only complete tables are shown.
                    if !crate::interrupt::requested() {
                        writeln!(
                            out,
                            "the same rope with the scene's spring damping {} N·s/m and air drag {} N·s/m \
                         (velocity-dependent forces):\n",
                            scene.spring_damping, scene.air_drag
                        )?;
                        out.push_str(&report::orders_table(
                            &damped_rows,
                            error_floor(damped_error),
                            true,
                        ));
                        diagrams.push(crate::diagram::convergence(
                            problem.name(),
                            &damped_rows,
                            error_floor(damped_error),
                            true,
                        ));
                        out.push('\n');
                    }
                }
            }
            if rows.iter().any(|r| r.rtol.is_some()) {
                writeln!(
                    out,
                    "tolerance proportionality of the adaptive methods (slope 1: the error follows rtol; \
                     errors below {:.0e} left out):\n",
                    error_floor(reference_error)
                )?;
                out.push_str(&report::proportionality_table(
                    &rows,
                    error_floor(reference_error),
                ));
                out.push('\n');
            }
            out.push_str(&report::rows_table(&rows));
            if a.kind == StudyKind::WorkPrecision {
                // A target is only claimed where the reference resolves it: 10× its accuracy.
                let (targets, unresolved): (Vec<f64>, Vec<f64>) = [1e-3, 1e-6, 1e-9, 1e-12]
                    .into_iter()
                    .partition(|&t| t >= 10.0 * reference_error);
                writeln!(
                    out,
                    "\ncheapest run reaching each error (from the rows above){}:\n",
                    if unresolved.is_empty() {
                        String::new()
                    } else {
                        format!(
                            "; {} left out: below 10× the reference's accuracy {reference_error:.1e}",
                            unresolved
                                .iter()
                                .map(|t| format!("{t:.0e}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    }
                )?;
                out.push_str(&report::cheapest_table(&rows, &targets));
                diagrams.push(crate::diagram::work_precision(
                    problem.name(),
                    &rows,
                    error_floor(reference_error),
                    &format!("wall times: median of {}; machine-dependent.", sw.repeats),
                ));
            }
            csv = report::rows_csv(&rows);
        }
        StudyKind::Stability => {
            let limits: Vec<Limit> = stability(&problem, &sw.methods, steps);
            done = limits.len();
            writeln!(
                out,
                "{} stability: largest dt whose run stays within 10⁴ of its start for {steps} steps (bisection), on the \
                 linearised problem ({}); theory = limit h / ω with ω = {:.6} rad/s\n",
                problem.name(),
                match problem {
                    Problem::Pendulum(_) => "1e-8 rad amplitude, ω = sqrt(g/L)",
                    Problem::Rope(_) =>
                        "straight, weightless, undamped chain pinned at node 0, ω = its highest mode",
                },
                problem.omega()
            )?;
            out.push_str(&report::stability_table(&limits));
            csv = report::limits_csv(&limits);
            diagrams.push(crate::diagram::stability(
                problem.name(),
                &limits,
                problem.omega(),
            ));
        }
        StudyKind::Hair => unreachable!("hair_study runs it"),
    }
    // Ctrl-C or SIGTERM: what is complete is shown and written, then the study ends with 130.
    let interrupted = crate::interrupt::requested();
    let complete = done > 0;
    if !complete {
        // Stopped before a single run was complete: no table to show.
        out.clear();
        diagrams.clear();
    }
    // With `-o -` or `--csv -` standard output carries the file: the tables go to stderr.
    let to_stdout = outputs.to_stdout();
    if to_stdout {
        eprint!("{out}");
    } else {
        print!("{out}");
    }
    if let Some(csv_out) = &outputs.csv
        && complete
    {
        csv_out.write(csv.as_bytes())?;
        if !csv_out.is_stdout() {
            eprintln!("wrote {}", csv_out.given.display());
        }
    }
    let mut images: Vec<(String, Vec<u8>)> = Vec::new();
    if let Some(dir) = outputs.plots.as_ref().filter(|_| complete) {
        for d in &diagrams {
            let w = d.write(dir)?;
            eprintln!("wrote {} and {}", w.svg.display(), w.png.display());
            images.push((d.title.clone(), w.png_bytes));
        }
    }
    if let Some(path) = &a.output
        && complete
    {
        let d = crate::record::Destinations::output(path);
        let config = format!(
            "# the scene of `{}`\n{}",
            crate::record::command_line(),
            scene_file.to_toml()?
        );
        let methods: Vec<&str> = sw.methods.iter().map(|m| m.name()).collect();
        let bytes = crate::record::study::record_study(
            &d,
            problem.name(),
            &images,
            &out,
            (&config, &methods),
        )?;
        report_recording(path, bytes, to_stdout);
    }
    if interrupted {
        return Err(interrupted_error(a, &sw, done, complete));
    }
    Ok(())
}

/// `physlab study hair`: the hair scene's configurations (`study::hair::configurations`) at its
/// defaults (200 strands, tour), over `--duration` (default 4 s).
fn hair_study(a: &StudyArgs) -> anyhow::Result<()> {
    use crate::scene::hair::run::HairConfig;
    let duration = a.duration.unwrap_or(4.0);
    let base = HairConfig {
        duration,
        ..HairConfig::default()
    };
    base.validate()?;
    let outputs = check_outputs(a, &[])?;
    let configs = crate::study::hair::configurations(&base);
    let rows = crate::study::hair::hair_trade(&configs);
    // Ctrl-C or SIGTERM: only the configurations that ran to the end are shown, written and
    // compared; with none, nothing is.
    let interrupted = crate::interrupt::requested();
    let complete = !rows.is_empty();
    let stopped = || -> anyhow::Error {
        crate::error::Error::Interrupted(format!(
            "interrupted: {} of {} configurations complete{}",
            rows.len(),
            configs.len(),
            if complete {
                "; the tables above (and any --csv and -o files) hold the complete ones"
            } else {
                "; nothing was written"
            }
        ))
        .into()
    };
    if !complete {
        return Err(stopped());
    }
    let mut out = String::new();
    writeln!(
        out,
        "hair trade: {} strands × {} nodes, tour over {duration} s at {} Hz; max stretch = largest |ℓ - ℓ0|/ℓ0 over \
         every frame; ms/frame = wall time of the step per simulation frame on {} threads (measured, not \
         deterministic)\n",
        base.params.strands,
        base.params.nodes,
        base.rate,
        rayon::current_num_threads()
    )?;
    out.push_str(&crate::report::hair::trade_table(&rows));
    writeln!(
        out,
        "\ncheapest configuration within each stretch target:\n"
    )?;
    out.push_str(&crate::report::hair::trade_cheapest_table(
        &rows,
        &[1e-2, 1e-3, 1e-6],
    ));
    // With `-o -` or `--csv -` standard output carries the file: the tables go to stderr.
    let to_stdout = outputs.to_stdout();
    if to_stdout {
        eprint!("{out}");
    } else {
        print!("{out}");
    }
    if let Some(csv_out) = &outputs.csv {
        csv_out.write(crate::report::hair::trade_csv(&rows).as_bytes())?;
        if !csv_out.is_stdout() {
            eprintln!("wrote {}", csv_out.given.display());
        }
    }
    if let Some(path) = &a.output {
        let d = crate::record::Destinations::output(path);
        // Provenance: the study's base scene (every configuration varies the solver settings of
        // this one) and the command line.
        let config = format!(
            "# the scene of `{}`\n[hair]\nduration = {duration:?}\n",
            crate::record::command_line()
        );
        let methods: Vec<&str> = crate::scene::hair::HairMethod::ALL
            .iter()
            .map(|m| m.name())
            .collect();
        let bytes = crate::record::study::record_study(&d, "hair", &[], &out, (&config, &methods))?;
        report_recording(path, bytes, to_stdout);
    }
    if interrupted {
        return Err(stopped());
    }
    Ok(())
}

/// Where the study's recording went; on stderr when standard output carries a file.
fn report_recording(path: &std::path::Path, bytes: Option<u64>, to_stdout: bool) {
    let line = match bytes {
        Some(bytes) => format!(
            "\nrecording: {} ({:.2} MB)",
            path.display(),
            bytes as f64 / 1e6
        ),
        None => "\nrecording written to standard output".into(),
    };
    if to_stdout {
        eprintln!("{line}");
    } else {
        println!("{line}");
    }
}

/// What an interrupted study says: how many of its planned runs (or methods' limits) were
/// complete, and whether anything was written.
fn interrupted_error(a: &StudyArgs, sw: &Sweep, done: usize, complete: bool) -> anyhow::Error {
    let planned: usize = match a.kind {
        StudyKind::Stability => sw.methods.len(),
        _ => sw
            .methods
            .iter()
            .map(|m| {
                if m.info().family == crate::integrate::Family::Adaptive {
                    sw.rtols.len()
                } else {
                    sw.levels as usize
                }
            })
            .sum(),
    };
    let kept = if complete {
        "; the tables above (and any --csv and -o files) hold the complete ones"
    } else {
        "; nothing was written"
    };
    crate::error::Error::Interrupted(format!(
        "interrupted: {done} of {planned} {} complete{kept}",
        if a.kind == StudyKind::Stability {
            "methods' limits"
        } else {
            "runs"
        }
    ))
    .into()
}

/// A study's outputs, checked before it runs (`crate::output`): the CSV, the recording, and
/// the diagrams' folder (--plots, else beside the recording or the CSV) with the files the
/// diagrams `stems` will be written to; no two of them one file, none the scene file read.
struct Outputs {
    csv: Option<crate::output::Output>,
    recording: Option<crate::output::Output>,
    plots: Option<std::path::PathBuf>,
}

impl Outputs {
    fn to_stdout(&self) -> bool {
        [&self.csv, &self.recording]
            .into_iter()
            .flatten()
            .any(|o| o.is_stdout())
    }
}

fn check_outputs(a: &StudyArgs, stems: &[String]) -> anyhow::Result<Outputs> {
    use crate::output::{Dash, check, distinct};
    use std::path::{Path, PathBuf};
    let csv = a
        .csv
        .as_deref()
        .map(|p| check("--csv", p, Dash::Text))
        .transpose()?;
    let recording = match &a.output {
        Some(path) => crate::record::Destinations::output(path).written()?,
        None => None,
    };
    let beside = |o: &crate::output::Output| {
        o.target.as_ref().map(|t| match t.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        })
    };
    if a.plots.as_deref() == Some(Path::new("-")) {
        return Err(Error::Usage(
            "--plots -: standard output is not a folder; --plots names the folder of the diagrams"
                .into(),
        )
        .into());
    }
    let plots = a
        .plots
        .clone()
        .or_else(|| recording.as_ref().and_then(beside))
        .or_else(|| csv.as_ref().and_then(beside))
        .filter(|_| !stems.is_empty());
    let mut diagrams = Vec::new();
    if let Some(dir) = &plots {
        if dir.exists() && !dir.is_dir() {
            anyhow::bail!(
                "--plots {}: is not a folder; --plots names the folder the diagrams go to",
                dir.display()
            );
        }
        let no_dash = Dash::Refused("is not a folder");
        for stem in stems {
            for file in crate::diagram::Diagram::files(stem, dir) {
                diagrams.push(check("--plots", &file, no_dash)?);
            }
        }
    }
    let all: Vec<&crate::output::Output> = csv
        .iter()
        .chain(recording.iter())
        .chain(diagrams.iter())
        .collect();
    let inputs: Vec<(&str, &Path)> = a
        .config
        .iter()
        .map(|p| ("the scene file read (--config)", p.as_path()))
        .collect();
    distinct(&all, &inputs)?;
    Ok(Outputs {
        csv,
        recording,
        plots,
    })
}
