//! `physlab study`: resolves the study's scene, runs the measurement, prints markdown tables,
//! and writes the CSV and recording when asked.

use super::Error;
use crate::app::progress::Progress;
use crate::cli::StudyKind;
use crate::diagram::{self, Diagram};
use crate::report::study as report;
use crate::study::{
    Limit, Problem, Row, Sweep, damped_companion, error_floor, planned_work, stability_with,
    sweep_against, sweep_with,
};

mod answer;
mod drift;
mod hair;
mod outputs;
mod setup;

use hair::hair_study;
use outputs::{check_outputs, interrupted_error, write_study};
use setup::Setup;

/// What a study measured, and how many runs (or methods' limits) are complete (after Ctrl-C or
/// SIGTERM only those are shown).
#[derive(Default)]
struct Found {
    out: String,
    csv: String,
    diagrams: Vec<Diagram>,
    done: usize,
}

pub fn study(kind: &StudyKind) -> anyhow::Result<()> {
    let (setup, scene, out) = match kind {
        StudyKind::Hair(a) => return hair_study(a),
        StudyKind::Convergence(a) => (setup::sweep_setup(a, None)?, &a.scene, &a.out),
        StudyKind::WorkPrecision(w) => {
            let a = &w.sweep;
            (setup::sweep_setup(a, Some(w))?, &a.scene, &a.out)
        }
        StudyKind::Stability(a) => (setup::stability_setup(a)?, &a.scene, &a.out),
        StudyKind::Drift(a) => (setup::drift_setup(a)?, &a.scene, &a.out),
    };
    let Setup {
        problem,
        sweep,
        steps,
        work,
        targets,
        file,
    } = setup;
    let stems: &[&str] = match kind {
        StudyKind::Convergence(_) => &["convergence", "convergence-damped"],
        _ => &[kind.name()],
    };
    let stems: Vec<String> = (stems.iter())
        .map(|s| format!("{}-{s}", problem.name()))
        .collect();
    let outputs = check_outputs(out, scene.config.as_deref(), &stems)?;
    let damped = damped_companion(&problem).filter(|_| stems.len() > 1);
    // Said before it starts, as a scene says it: the methods whose order drops on its forces.
    let ropes = [(Some(&problem), ""), (damped.as_ref(), "the damped rope: ")];
    for (p, which) in ropes.into_iter().filter(|_| !out.quiet) {
        if let Some(Problem::Rope(rope)) = p {
            for w in crate::scene::rope::run::order_drops(rope, &sweep.methods) {
                let w = format!("warning: {which}{w}");
                eprintln!("{}", crate::report::table::fit_lines(&w));
            }
        }
    }
    // The scenes' bar and notice, its time said up front.
    let mut progress = Progress::new(out.quiet, None);
    // Its planned runs, the damped rope's too.
    let problems: Vec<&Problem> = [Some(&problem), damped.as_ref()]
        .into_iter()
        .flatten()
        .collect();
    let end = match kind {
        StudyKind::Stability(_) | StudyKind::Drift(_) => sweep.methods.len() as f64,
        _ => problems.iter().map(|p| planned_work(p, &sweep)).sum(),
    };
    progress.stage(&format!("study {}", kind.name()), end, None);
    let basis = format!(
        "estimated from its {work:.1e} node-steps at ~{:.0} ns each, more with implicit methods",
        setup::SECONDS_PER_NODE_STEP * 1e9
    );
    progress.judge(work * setup::SECONDS_PER_NODE_STEP, None, &basis);
    let found = match kind {
        StudyKind::Stability(_) => {
            let at = &mut |m| progress.at(m);
            let limits: Vec<Limit> = stability_with(&problem, &sweep.methods, steps, at);
            Found {
                out: report::stability_header(&problem, steps)
                    + &report::stability_table(&limits, out.wide),
                csv: report::limits_csv(&limits),
                diagrams: vec![diagram::stability(problem.name(), &limits, problem.omega())],
                done: limits.len(),
            }
        }
        StudyKind::Drift(_) => drift::drift_study(&mut progress, out, &problem, &sweep),
        _ => {
            let study = (&problem, &sweep, &file);
            sweep_study(kind, study, &targets, &mut progress, out.wide)?
        }
    };
    progress.finish();
    // Ctrl-C or SIGTERM: what is complete is shown and written, then the study ends with 130;
    // stopped before a single run was complete, nothing is.
    let interrupted = crate::interrupt::requested();
    let complete = found.done > 0;
    if complete {
        let methods: Vec<&str> = sweep.methods.iter().map(|m| m.name()).collect();
        let scene_file = file.to_toml()?;
        let scene = (scene_file.as_str(), methods.as_slice());
        let texts = (found.out.as_str(), found.csv.as_str());
        write_study(out, &outputs, problem.name(), texts, &found.diagrams, scene)?;
    }
    if interrupted {
        return Err(interrupted_error(
            kind, &problems, &sweep, found.done, complete,
        ));
    }
    Ok(())
}

/// `study convergence` and `study work-precision`: the reference once (its error the study's
/// floor), the sweep, then work-precision's answer or convergence's fitted orders, and every
/// run.
fn sweep_study(
    kind: &StudyKind,
    (problem, sw, file): (&Problem, &Sweep, &crate::app::SceneFile),
    targets: &(Vec<f64>, bool),
    progress: &mut Progress,
    wide: bool,
) -> Result<Found, Error> {
    let mut found = Found::default();
    let Some((reference, floor)) = sw.reference(problem) else {
        return Ok(found);
    };
    let convergence = matches!(kind, StudyKind::Convergence(_));
    if targets.1 {
        crate::study::refuse_unresolved(&targets.0, floor)?;
    }
    let mut reached = 0.0;
    let mut done = |w: f64| {
        reached += w;
        progress.at(reached);
    };
    let mut rows = sweep_against(problem, sw, (&reference, floor), convergence, &mut done);
    let commands = answer::commands(problem, file, sw, &rows)?;
    let header = report::sweep_header(problem, kind.name(), sw, floor);
    let mut damped = Vec::new();
    if convergence {
        found.out = header;
        let parts = (&mut done as &mut dyn FnMut(f64), wide, file);
        damped = convergence_tables((problem, sw), (&rows, &commands), floor, &mut found, parts)?;
    } else {
        found.out = answer::answer(problem, file, sw, &targets.0, &rows, floor)? + &header;
        let note = format!("wall times: median of {}; machine-dependent.", sw.repeats);
        let runs = (rows.as_slice(), sw.dt0);
        let d = diagram::work_precision(problem.name(), runs, floor, &note, commands);
        found.diagrams.push(d);
    }
    let out = &mut found.out;
    if rows.iter().any(|r| r.rtol.is_some()) {
        out.push_str(&report::proportionality_header(error_floor(floor)));
        out.push_str(&report::proportionality_table(&rows, error_floor(floor)));
        out.push('\n');
    }
    // Every run in the CSV and the count (the damped rope's too); work-precision's table by
    // default each method's cheapest run per target.
    rows.extend(damped);
    match convergence || wide {
        true => out.push_str(&report::rows_table(&rows, wide)),
        false => out.push_str(&report::cheapest_table(&rows, &targets.0)),
    }
    found.csv = report::rows_csv(&rows);
    found.done = rows.len();
    Ok(found)
}

/// The fitted orders, and on the undamped rope the same rope with the scene's damping beside
/// it: velocity-dependent forces change what some methods' orders are.
fn convergence_tables(
    (problem, sw): (&Problem, &Sweep),
    (rows, commands): (&[Row], &[String]),
    floor: f64,
    found: &mut Found,
    (done, wide, file): (&mut dyn FnMut(f64), bool, &crate::app::SceneFile),
) -> Result<Vec<Row>, Error> {
    let by_velocity = problem.velocity_dependent();
    let floor = error_floor(floor);
    let out = &mut found.out;
    out.push_str(&report::orders_table(rows, floor, by_velocity, wide));
    let stalled = report::stalled_note(rows, floor);
    if !stalled.is_empty() {
        eprint!("{stalled}");
        out.push('\n');
        out.push_str(&stalled);
    }
    let name = problem.name();
    let d = diagram::convergence(name, (rows, commands), floor, by_velocity);
    found.diagrams.push(d);
    out.push('\n');
    // Stopped already, or no damped companion: the undamped tables alone.
    let damped = damped_companion(problem).filter(|_| !crate::interrupt::requested());
    let Some(damped) = damped else {
        return Ok(Vec::new());
    };
    let (damped_rows, damped_error) = sweep_with(&damped, sw, true, done);
    // A stop during the damped sweep leaves it out: only complete tables are shown.
    if crate::interrupt::requested() {
        return Ok(Vec::new());
    }
    let floor = error_floor(damped_error);
    let scene = crate::scene::rope::RopeParams::default();
    out.push_str(&report::damped_header(&scene));
    out.push_str(&report::orders_table(&damped_rows, floor, true, wide));
    let commands = answer::commands(&damped, file, sw, &damped_rows)?;
    let d = diagram::convergence(name, (&damped_rows, &commands), floor, true);
    found.diagrams.push(d);
    out.push('\n');
    Ok(damped_rows)
}
