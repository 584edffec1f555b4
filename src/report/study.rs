//! The studies' text, tables and CSV: what each measures against what, the fitted orders, every
//! measured run, the cheapest run per target error, the stability limits against theory.

use std::fmt::Write as _;

use crate::format::{sci, shown, trim_number};
use crate::report::table::{Table, WIDTH, fit_lines, list_item};
use crate::scene::pendulum::exact::ExactPendulum;
use crate::scene::rope::RopeParams;
use crate::study::{
    Answer, Limit, Problem, RESOLVES, Row, Sweep, error_floor, floor_text, orders, proportionality,
    settings,
};

/// What a convergence or work-precision sweep (`kind`) measures, against which reference, and
/// what its fits leave out. `reference_error` is the study's floor, said as [`floor_text`] says
/// it wherever it is shown.
pub fn sweep_header(problem: &Problem, kind: &str, sweep: &Sweep, reference_error: f64) -> String {
    let floor = floor_text(reference_error);
    let reference = match problem {
        Problem::Pendulum(p) if ExactPendulum::new(p).is_some() => format!(
            "the exact elliptic solution (θ to {floor} rad over this run: measured against mpmath over whole runs)"
        ),
        Problem::Pendulum(_) => format!(
            "the fine-step reference (compensated RK4, as the pendulum scene runs it), its own error estimated at {floor} rad (Richardson; measured against mpmath over whole runs)"
        ),
        Problem::Rope(_) => format!(
            "RK4 at dt/8 of the finest step, its own error estimated at {floor} (Richardson)"
        ),
    };
    format!(
        "{} {kind}: error = largest deviation of the positions from {reference}, sampled every {} s over {} s; \
         fits leave out errors below {} (100× the reference's error, its floor)\n\n",
        problem.name(),
        shown(sweep.sample_dt),
        shown(sweep.duration),
        floor_text(error_floor(reference_error))
    )
}

/// Work-precision's first lines: per target the cheapest run (its method and settings, error,
/// median wall time and evaluations), the targets left out below the floor, and the scene
/// command (shell words) that makes each run.
pub fn answer(
    problem: &Problem,
    sw: &Sweep,
    reference_error: f64,
    found: &[Answer],
    unresolved: &[f64],
) -> String {
    let (periods, error) = match problem {
        Problem::Pendulum(p) => (
            ExactPendulum::new(p).map_or(String::new(), |e| {
                format!(" ({} periods)", trim_number(sw.duration / e.period(), 3))
            }),
            "max |θ − θref| [rad]",
        ),
        Problem::Rope(_) => (String::new(), "max |x − xref| over the nodes [m]"),
    };
    let mut out = format!(
        "{} work-precision: the cheapest run (median wall time) per target error\n\
         over {} s{periods}, error = {} at the samples every {} s;\n\
         the reference's error (the floor) is {}:\n\n",
        problem.name(),
        trim_number(sw.duration, 6),
        error,
        shown(sw.sample_dt),
        floor_text(reference_error),
    );
    let mut t = Table::new(["target", "cheapest run", "error", "wall [s]", "force evals"]);
    for (target, row, _) in found {
        let run = row.map_or("none reached it".into(), |r| {
            settings(r, sw.sample_dt)[1..].join(" ")
        });
        t.row([
            format!("{target:.0e}"),
            run,
            row.and_then(|r| r.error).map_or("—".into(), sci),
            row.map_or("—".into(), |r| sci(r.wall_seconds)),
            row.map_or("—".into(), |r| r.evals.to_string()),
        ]);
    }
    out.push_str(&t.render_within(WIDTH));
    for t in unresolved {
        let _ = writeln!(out, "{t:.0e} left out: below {RESOLVES}× the floor.");
    }
    // The rope scene has no reference lane: its summary cannot show the error the study
    // measured, so the answer says where the error comes from and how to check it.
    out.push_str(&match problem {
        Problem::Pendulum(_) => {
            "\nthe command that makes each run as a scene (it measures the same error):\n".into()
        }
        Problem::Rope(_) => fit_lines(
            "\nnote: the rope scene has no reference, so its summary does not show these errors: \
             they were measured against this study's reference (RK4 at dt/8 of the finest step). \
             To check one, run this study again with --methods and that run's method: the same \
             reference measures each of its runs.\n\nthe command that makes each run as a scene:\n",
        ),
    });
    for (target, _, words) in found.iter().filter(|a| a.1.is_some()) {
        out.push_str(&wrapped(&format!("{target:.0e}:"), words, 100));
    }
    out.push('\n');
    out
}

/// `words` after `label`, a line each up to `width` columns, continued by ` \` (a shell reads
/// them as one command); a flag and its value stay on one line.
fn wrapped(label: &str, words: &[String], width: usize) -> String {
    let indent = " ".repeat(label.chars().count() + 3);
    let mut units: Vec<String> = Vec::new();
    for w in words {
        match units.last_mut() {
            Some(u) if u.starts_with('-') && !u.contains(' ') && !w.starts_with('-') => {
                u.push(' ');
                u.push_str(w);
            }
            _ => units.push(w.clone()),
        }
    }
    let mut out = format!("{label:<w$}", w = indent.len() - 2);
    let mut line = out.chars().count();
    for (i, unit) in units.iter().enumerate() {
        let n = unit.chars().count();
        if i > 0 && line + 1 + n + 2 > width {
            out.push_str(" \\\n");
            out.push_str(&indent);
            line = indent.len();
        } else if i > 0 {
            out.push(' ');
            line += 1;
        }
        out.push_str(unit);
        line += n;
    }
    out.push('\n');
    out
}

/// Introduces the damped rope's table beside the undamped one's.
pub fn damped_header(scene: &RopeParams) -> String {
    format!(
        "the same rope with the scene's spring damping {} N·s/m and air drag {} N·s/m \
         (velocity-dependent forces):\n\n",
        scene.spring_damping, scene.air_drag
    )
}

/// Introduces the adaptive methods' tolerance proportionality.
pub fn proportionality_header(floor: f64) -> String {
    format!(
        "tolerance proportionality of the adaptive methods (slope 1: the error follows rtol; \
         errors below {} left out):\n\n",
        floor_text(floor)
    )
}

/// What a stability study measures, on which linearised problem, against which theory.
pub fn stability_header(problem: &Problem, steps: u64) -> String {
    format!(
        "{} stability: largest dt whose run stays within 10⁴ of its start for {steps} steps (bisection), on the \
         linearised problem ({}); theory = limit h / ω with ω = {:.6} rad/s\n\n",
        problem.name(),
        match problem {
            Problem::Pendulum(_) => "1e-12 rad amplitude, ω = sqrt(g/L)",
            Problem::Rope(_) =>
                "straight, weightless, undamped chain pinned at node 0, ω = its highest mode",
        },
        problem.omega()
    )
}

/// Fitted order per method against theory (the order for velocity-dependent forces when the
/// problem has them), leaving out errors below `floor`; in full (`wide`) or fitted.
pub fn orders_table(rows: &[Row], floor: f64, velocity_dependent: bool, wide: bool) -> String {
    let mut t = Table::with_short([
        ("method", "method"),
        ("theory order", "theory"),
        ("fitted order", "fitted"),
        ("order range", "range"),
        ("diverged at dt", "diverged at dt [s]"),
    ]);
    let unfitted = match wide {
        true => "— (fewer than 2 usable rows)",
        false => "— (< 2 rows)",
    };
    for o in orders(rows, floor) {
        let diverged: Vec<String> = (o.diverged_at.iter()).map(|d| format!("{d:.3e}")).collect();
        t.row([
            o.method.name().to_string(),
            o.method.info().order_for(velocity_dependent).to_string(),
            o.fitted.map_or(unfitted.into(), |f| format!("{f:.3}")),
            (o.range).map_or("—".into(), |(lo, hi)| format!("{lo:.3} – {hi:.3}")),
            match diverged.is_empty() {
                true => "—".into(),
                false => diverged.join(", "),
            },
        ]);
    }
    t.render_at(wide)
}

/// One line per method whose errors stopped falling as the step halved ([`crate::study::stalled`]):
/// where, and that those rows are left out of its fit. Empty when none did.
pub fn stalled_note(rows: &[Row], floor: f64) -> String {
    let mut note = String::new();
    for o in orders(rows, floor) {
        if let Some(dt) = o.stalled_at {
            let error = |dt: f64| {
                rows.iter()
                    .find(|r| r.method == o.method && r.rtol.is_none() && r.dt == dt)
                    .and_then(|r| r.error)
                    .map_or("—".into(), sci)
            };
            let _ = writeln!(
                note,
                "warning: {}'s error stops falling at dt = {} s ({}, against {} at twice the step): the floor of round-off (amplified by the motion) or of the reference is reached there; that row and the finer ones are left out of its fit",
                o.method.name(),
                sci(dt),
                error(dt),
                error(2.0 * dt)
            );
        }
    }
    fit_lines(&note)
}

/// Tolerance proportionality per adaptive method: the slope of log error against log rtol
/// (1: the error follows the tolerance), leaving out errors below `floor`.
pub fn proportionality_table(rows: &[Row], floor: f64) -> String {
    let mut t = Table::new([
        "method",
        "error = C·rtol^slope, fitted",
        "slope range",
        "rtols fitted",
    ]);
    for p in proportionality(rows, floor) {
        t.row([
            p.method.name().to_string(),
            p.fitted.map_or("— (fewer than 2 usable rows)".into(), |f| {
                format!("{f:.3}")
            }),
            (p.range).map_or("—".into(), |(lo, hi)| format!("{lo:.3} – {hi:.3}")),
            (p.rtols).map_or("—".into(), |(lo, hi)| format!("{lo:.0e} – {hi:.0e}")),
        ]);
    }
    t.render_within(WIDTH)
}

/// What one run is, as a point of a diagram shows it on hover in the viewer: the method and
/// its settings, then what it measured (the one place that text is made, for every study
/// diagram of sweep rows).
pub fn run_about(r: &Row) -> String {
    let settings = match r.rtol {
        Some(rtol) => format!("rtol {}, sampled every {} s", sci(rtol), sci(r.dt)),
        None => format!("dt {} s", sci(r.dt)),
    } + if r.compensated { ", compensated" } else { "" };
    format!(
        "{} ({settings})\nerror {}\nwall {} s\n{} force evaluations, {} steps ({} rejected)",
        r.method.name(),
        r.error.map_or("diverged".into(), sci),
        sci(r.wall_seconds),
        r.evals,
        r.accepted,
        r.rejected
    )
}

/// Every measured run; fitted, rtol and the wall time to one digit.
pub fn rows_table(rows: &[Row], wide: bool) -> String {
    let mut t = Table::with_short([
        ("method", "method"),
        ("dt [s]", "dt [s]"),
        ("rtol", "rtol"),
        ("error", "error"),
        ("force evals", "evals"),
        ("steps accepted", "steps"),
        ("rejected", "rejected"),
        ("median wall [s]", "wall [s]"),
    ]);
    for r in rows {
        t.row([
            r.method.name().to_string(),
            // An adaptive run's dt is only the interval it is sampled at.
            r.rtol.map_or_else(|| sci(r.dt), |_| "adaptive".into()),
            r.rtol.map_or("—".into(), |t| match wide {
                true => sci(t),
                false => format!("{t:.0e}"),
            }),
            r.error.map_or("diverged".into(), sci),
            r.evals.to_string(),
            r.accepted.to_string(),
            r.rejected.to_string(),
            match wide {
                true => sci(r.wall_seconds),
                false => format!("{:.1e}", r.wall_seconds),
            },
        ]);
    }
    t.render_at(wide)
}

/// Work-precision's runs as its table shows them by default: per method its cheapest run (median
/// wall time) reaching each target, and how many runs that leaves out and where they are.
pub fn cheapest_table(rows: &[Row], targets: &[f64]) -> String {
    let mut picked: Vec<&Row> = Vec::new();
    for m in crate::study::methods_of(rows, |_| true) {
        let of: Vec<Row> = rows.iter().filter(|r| r.method == m).cloned().collect();
        for &t in targets {
            let at = crate::study::cheapest(&of, t)
                .0
                .and_then(|c| rows.iter().find(|r| *r == c));
            picked.extend(at.filter(|r| !picked.iter().any(|p| std::ptr::eq(*p, *r))));
        }
    }
    let shown: Vec<Row> = (rows.iter())
        .filter(|r| picked.iter().any(|p| std::ptr::eq(*p, *r)))
        .cloned()
        .collect();
    let note = format!(
        "{} of {} runs shown: each method's cheapest run per target; every run with --wide and \
         in --csv.\n",
        shown.len(),
        rows.len()
    );
    rows_table(&shown, false) + "\n" + &fit_lines(&note)
}

/// Measured stability limits against theory; fitted, each note said once under the table with
/// the methods it concerns.
pub fn stability_table(limits: &[Limit], wide: bool) -> String {
    let mut t = Table::with_short([
        ("method", "method"),
        ("measured dt [s]", "measured dt [s]"),
        ("theory dt [s]", "theory dt [s]"),
        ("measured / theory", "ratio"),
        ("note", ""),
    ]);
    for l in limits {
        let ratio = match (l.measured_dt, l.theory_dt) {
            (Some(m), Some(t)) if t.is_finite() => format!("{:.4}", m / t),
            _ => "—".into(),
        };
        t.row([
            l.method.name().to_string(),
            l.measured_dt.map_or("—".into(), sci),
            match l.theory_dt {
                Some(t) if t.is_infinite() => "unconditional".into(),
                Some(t) => sci(t),
                None => "none".into(),
            },
            ratio,
            l.note.clone(),
        ]);
    }
    let mut out = t.render_at(wide);
    if !wide {
        let mut notes: Vec<&str> = Vec::new();
        for l in limits.iter().filter(|l| !l.note.is_empty()) {
            if !notes.contains(&l.note.as_str()) {
                notes.push(&l.note);
            }
        }
        if !notes.is_empty() {
            out.push('\n');
        }
        for note in notes {
            let methods: Vec<&str> = (limits.iter().filter(|l| l.note == note))
                .map(|l| l.method.name())
                .collect();
            out.push_str(&list_item(&methods.join(", "), note, WIDTH));
        }
    }
    out
}

/// One CSV row per run.
pub fn rows_csv(rows: &[Row]) -> String {
    let mut csv = String::from(
        "scene,method,dt,rtol,error,evals,accepted_steps,rejected_steps,wall_seconds,stable,\
         compensated\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{:e},{},{},{},{},{},{:e},{},{}",
            r.scene,
            r.method,
            r.dt,
            r.rtol.map_or(String::new(), |t| format!("{t:e}")),
            r.error.map_or(String::new(), |e| format!("{e:e}")),
            r.evals,
            r.accepted,
            r.rejected,
            r.wall_seconds,
            r.error.is_some(),
            r.compensated
        );
    }
    csv
}

/// One CSV row per method's stability limit.
pub fn limits_csv(limits: &[Limit]) -> String {
    let mut csv = String::from("scene,method,measured_dt,theory_dt\n");
    for l in limits {
        let _ = writeln!(
            csv,
            "{},{},{},{}",
            l.scene,
            l.method,
            l.measured_dt.map_or(String::new(), |d| format!("{d:e}")),
            // An unconditional limit, infinite, is written "inf".
            l.theory_dt.map_or("none".into(), |d| format!("{d:e}"))
        );
    }
    csv
}
