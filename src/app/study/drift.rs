//! `physlab study drift`: each method's long run, reported as it completes; the tables, CSV and
//! diagram of the complete ones.

use super::Found;
use crate::app::progress::Progress;
use crate::cli::StudyOutputs;
use crate::format::shown;
use crate::report::{drift as report, rope};
use crate::study::drift::{Drift, pendulum_drift, rope_drift};
use crate::study::{Problem, Sweep};

/// The study's findings; a run cut short by Ctrl-C is left out.
pub(super) fn drift_study(
    progress: &mut Progress,
    out: &StudyOutputs,
    problem: &Problem,
    sw: &Sweep,
) -> Found {
    let mut runs: Vec<Drift> = Vec::new();
    for (i, &m) in sw.methods.iter().enumerate() {
        if crate::interrupt::requested() {
            break;
        }
        let run = match problem {
            Problem::Pendulum(p) => pendulum_drift(p, m, sw.dt0, sw.duration, sw.options),
            Problem::Rope(p) => Some(rope_drift(p, m, sw.dt0, sw.duration, sw.options)),
        };
        if let Some(run) = run.filter(|_| !crate::interrupt::requested()) {
            runs.push(run);
            progress.at((i + 1) as f64);
        }
    }
    let (header, flags, note) = match problem {
        Problem::Pendulum(p) => {
            // θ0 as given in degrees (its radians turned back carry a last-digit residue).
            let degrees = (p.theta0.to_degrees() * 1e9).round() / 1e9;
            let period = crate::scene::pendulum::exact::ExactPendulum::new(p)
                .map_or(f64::NAN, |e| e.period());
            (
                report::pendulum_header(degrees, period, sw.dt0, sw.duration),
                format!("--theta0 {}", shown(degrees)),
                format!("dt = {} s, θ0 = {degrees}°.", shown(sw.dt0)),
            )
        }
        Problem::Rope(p) => (
            report::rope_header(p, sw.dt0, sw.duration),
            format!(
                "--scene rope --nodes {} --stiffness {} --spring-damping {} --air-drag {}",
                p.nodes,
                shown(p.stiffness),
                shown(p.spring_damping),
                shown(p.air_drag)
            ),
            format!("dt = {} s, {}.", shown(sw.dt0), rope::forces_text(p)),
        ),
    };
    let command = Some((flags.as_str(), sw.options.rtol));
    // Per run, the command that measures it alone: what its points say on hover.
    let commands = (runs.iter())
        .map(|r| {
            let rtol = r.method.info().adaptive().then_some(sw.options.rtol);
            report::run_command(r.method.name(), &flags, r, rtol)
        })
        .collect();
    Found {
        out: header + &report::drift_table(&runs, command, out.wide),
        csv: report::drift_csv(problem.name(), &runs),
        done: runs.len(),
        diagrams: vec![crate::diagram::drift(
            problem.name(),
            (&runs, commands),
            &note,
        )],
    }
}
