//! `physlab study`: resolves the study's scene, runs the measurement, prints markdown tables,
//! and writes the CSV and recording when asked.

use super::Error;
use super::SceneFile;
use crate::cli::{StudyArgs, StudyKind};
use crate::report::study as report;
use crate::study::{Limit, damped_companion, error_floor, stability, sweep};

mod drift;
mod hair;
mod outputs;
mod setup;

use hair::hair_study;
use outputs::{check_outputs, interrupted_error, write_study};
use setup::{refuse_unused, setup};

pub fn study(a: &StudyArgs) -> anyhow::Result<()> {
    refuse_unused(a)?;
    if a.kind == StudyKind::Hair {
        return hair_study(a);
    }
    let (problem, sw, steps, scene_file) = setup(a)?;
    let stems: Vec<String> = match a.kind {
        StudyKind::Convergence => vec!["convergence", "convergence-damped"],
        StudyKind::WorkPrecision => vec!["work-precision"],
        StudyKind::Drift => vec!["drift"],
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
            let (mut rows, reference_error) = sweep(&problem, &sw);
            let mut damped_all = Vec::new();
            let floor = error_floor(reference_error);
            let kind = a.kind.name();
            out.push_str(&report::sweep_header(&problem, &kind, &sw, reference_error));
            if a.kind == StudyKind::Convergence {
                let by_velocity = problem.velocity_dependent();
                out.push_str(&report::orders_table(&rows, floor, by_velocity));
                let stalled = report::stalled_note(&rows, floor);
                if !stalled.is_empty() {
                    eprint!("{stalled}");
                    out.push('\n');
                    out.push_str(&stalled);
                }
                diagrams.push(crate::diagram::convergence(
                    problem.name(),
                    &rows,
                    floor,
                    by_velocity,
                ));
                out.push('\n');
                if let Some(damped) = damped_companion(&problem)
                    && !crate::interrupt::requested()
                {
                    // Velocity-dependent forces change what some methods' orders are: show the
                    // same rope with the scene's damping beside the undamped one.
                    let scene = crate::scene::rope::RopeParams::default();
                    let (damped_rows, damped_error) = sweep(&damped, &sw);
                    // A stop during the damped sweep leaves it out: only complete tables are shown.
                    if !crate::interrupt::requested() {
                        out.push_str(&report::damped_header(&scene));
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
                        damped_all = damped_rows;
                    }
                }
            }
            if rows.iter().any(|r| r.rtol.is_some()) {
                out.push_str(&report::proportionality_header(floor));
                out.push_str(&report::proportionality_table(&rows, floor));
                out.push('\n');
            }
            // Every run in the runs table, the CSV and the count (the damped rope's too).
            rows.extend(damped_all);
            done = rows.len();
            out.push_str(&report::rows_table(&rows));
            if a.kind == StudyKind::WorkPrecision {
                // A target is only claimed where the reference resolves it: 10× its accuracy.
                let (targets, unresolved): (Vec<f64>, Vec<f64>) = [1e-3, 1e-6, 1e-9, 1e-12]
                    .into_iter()
                    .partition(|&t| t >= 10.0 * reference_error);
                out.push_str(&report::cheapest_header(&unresolved, reference_error));
                out.push_str(&report::cheapest_table(&rows, &targets));
                diagrams.push(crate::diagram::work_precision(
                    problem.name(),
                    &rows,
                    floor,
                    &format!("wall times: median of {}; machine-dependent.", sw.repeats),
                ));
            }
            csv = report::rows_csv(&rows);
        }
        StudyKind::Stability => {
            let limits: Vec<Limit> = stability(&problem, &sw.methods, steps);
            done = limits.len();
            out.push_str(&report::stability_header(&problem, steps));
            out.push_str(&report::stability_table(&limits));
            csv = report::limits_csv(&limits);
            diagrams.push(crate::diagram::stability(
                problem.name(),
                &limits,
                problem.omega(),
            ));
        }
        StudyKind::Drift => {
            let (text, table, diagram, complete) = drift::drift_study(a, &problem, &sw);
            (out, csv, done) = (text, table, complete);
            diagrams.push(diagram);
        }
        StudyKind::Hair => unreachable!("hair_study runs it"),
    }
    // Ctrl-C or SIGTERM: what is complete is shown and written, then the study ends with 130;
    // stopped before a single run was complete, nothing is.
    let interrupted = crate::interrupt::requested();
    let complete = done > 0;
    if complete {
        let methods: Vec<&str> = sw.methods.iter().map(|m| m.name()).collect();
        let scene_file = scene_file.to_toml()?;
        let scene = (scene_file.as_str(), methods.as_slice());
        write_study(a, &outputs, problem.name(), (&out, &csv), &diagrams, scene)?;
    }
    if interrupted {
        return Err(interrupted_error(a, &problem, &sw, done, complete));
    }
    Ok(())
}
