//! `physlab study`: resolves the study's scene, runs the measurement, prints markdown tables,
//! and writes the CSV and recording when asked.

use super::Error;
use crate::cli::StudyKind;
use crate::diagram::{self, Diagram};
use crate::report::study as report;
use crate::study::{Limit, Problem, Row, Sweep, damped_companion, error_floor, stability, sweep};

mod drift;
mod hair;
mod outputs;
mod setup;

use hair::hair_study;
use outputs::{check_outputs, interrupted_error, write_study};
use setup::Setup;

/// What a study measured: its printed tables, its CSV, its diagrams, and how many runs (or
/// methods' limits) are complete (after Ctrl-C or SIGTERM only those are shown).
struct Found {
    out: String,
    csv: String,
    diagrams: Vec<Diagram>,
    done: usize,
}

pub fn study(kind: &StudyKind) -> anyhow::Result<()> {
    let (setup, scene, out) = match kind {
        StudyKind::Hair(a) => return hair_study(a),
        StudyKind::Convergence(a) => (setup::sweep_setup(a, true)?, &a.scene, &a.out),
        StudyKind::WorkPrecision(a) => (setup::sweep_setup(a, false)?, &a.scene, &a.out),
        StudyKind::Stability(a) => (setup::stability_setup(a)?, &a.scene, &a.out),
        StudyKind::Drift(a) => (setup::drift_setup(a)?, &a.scene, &a.out),
    };
    let Setup {
        problem,
        sweep,
        steps,
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
    let found = match kind {
        StudyKind::Stability(_) => {
            let limits: Vec<Limit> = stability(&problem, &sweep.methods, steps);
            Found {
                out: report::stability_header(&problem, steps)
                    + &report::stability_table(&limits, out.wide),
                csv: report::limits_csv(&limits),
                diagrams: vec![diagram::stability(problem.name(), &limits, problem.omega())],
                done: limits.len(),
            }
        }
        StudyKind::Drift(_) => drift::drift_study(out, &problem, &sweep),
        _ => sweep_study(kind, &problem, &sweep, out.wide),
    };
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
            kind, &problem, &sweep, found.done, complete,
        ));
    }
    Ok(())
}

/// `study convergence` and `study work-precision`: the sweep's runs, the fitted orders or the
/// cheapest run per target, how the adaptive methods' error follows rtol, and every run.
fn sweep_study(kind: &StudyKind, problem: &Problem, sw: &Sweep, wide: bool) -> Found {
    let (mut rows, reference_error) = sweep(problem, sw);
    let floor = error_floor(reference_error);
    let mut found = Found {
        out: report::sweep_header(problem, kind.name(), sw, reference_error),
        csv: String::new(),
        diagrams: Vec::new(),
        done: 0,
    };
    let mut damped = Vec::new();
    if let StudyKind::Convergence(_) = kind {
        damped = convergence_tables(problem, sw, &rows, floor, &mut found, wide);
    }
    let out = &mut found.out;
    if rows.iter().any(|r| r.rtol.is_some()) {
        out.push_str(&report::proportionality_header(floor));
        out.push_str(&report::proportionality_table(&rows, floor));
        out.push('\n');
    }
    if let StudyKind::WorkPrecision(_) = kind {
        out.push_str(&report::rows_table(&rows, wide));
        // A target is only claimed where the reference resolves it: 10× its accuracy.
        let (targets, unresolved): (Vec<f64>, Vec<f64>) = [1e-3, 1e-6, 1e-9, 1e-12]
            .into_iter()
            .partition(|&t| t >= 10.0 * reference_error);
        out.push_str(&report::cheapest_header(&unresolved, reference_error));
        out.push_str(&report::cheapest_table(&rows, &targets));
        let note = format!("wall times: median of {}; machine-dependent.", sw.repeats);
        (found.diagrams).push(diagram::work_precision(problem.name(), &rows, floor, &note));
    } else {
        // Every run in the runs table, the CSV and the count (the damped rope's too).
        rows.extend(damped);
        out.push_str(&report::rows_table(&rows, wide));
    }
    found.csv = report::rows_csv(&rows);
    found.done = rows.len();
    found
}

/// The fitted orders, and on the undamped rope the same rope with the scene's damping beside
/// it: velocity-dependent forces change what some methods' orders are.
fn convergence_tables(
    problem: &Problem,
    sw: &Sweep,
    rows: &[Row],
    floor: f64,
    found: &mut Found,
    wide: bool,
) -> Vec<Row> {
    let by_velocity = problem.velocity_dependent();
    let out = &mut found.out;
    out.push_str(&report::orders_table(rows, floor, by_velocity, wide));
    let stalled = report::stalled_note(rows, floor);
    if !stalled.is_empty() {
        eprint!("{stalled}");
        out.push('\n');
        out.push_str(&stalled);
    }
    let name = problem.name();
    (found.diagrams).push(diagram::convergence(name, rows, floor, by_velocity));
    out.push('\n');
    let Some(damped) = damped_companion(problem) else {
        return Vec::new();
    };
    if crate::interrupt::requested() {
        return Vec::new();
    }
    let (damped_rows, damped_error) = sweep(&damped, sw);
    // A stop during the damped sweep leaves it out: only complete tables are shown.
    if crate::interrupt::requested() {
        return Vec::new();
    }
    let floor = error_floor(damped_error);
    out.push_str(&report::damped_header(
        &crate::scene::rope::RopeParams::default(),
    ));
    out.push_str(&report::orders_table(&damped_rows, floor, true, wide));
    (found.diagrams).push(diagram::convergence(name, &damped_rows, floor, true));
    out.push('\n');
    damped_rows
}
