//! The studies' text, tables and CSV: what each measures against what, the fitted orders, every
//! measured run, the cheapest run per target error, the stability limits against theory.

use std::fmt::Write as _;

use crate::format::sci;
use crate::report::table::{Table, WIDTH, fit_lines, list_item};
use crate::scene::pendulum::exact::ExactPendulum;
use crate::scene::rope::RopeParams;
use crate::study::{
    Limit, Problem, Row, SAMPLE_EVERY, Sweep, cheapest, error_floor, orders, proportionality,
};

/// What a convergence or work-precision sweep (`kind`) measures, against which reference, and
/// what its fits leave out.
pub fn sweep_header(problem: &Problem, kind: &str, sweep: &Sweep, reference_error: f64) -> String {
    let reference = match problem {
        Problem::Pendulum(p) if ExactPendulum::new(p).is_some() => format!(
            "the exact elliptic solution (θ to {reference_error:.0e} rad over this run: measured against mpmath over whole runs)"
        ),
        Problem::Pendulum(_) => format!(
            "the fine-step reference (compensated RK4, as the pendulum scene runs it), its own error estimated at {reference_error:.1e} rad (Richardson; measured against mpmath over whole runs)"
        ),
        Problem::Rope(_) => format!(
            "RK4 at dt/8 of the finest step, its own error estimated at {reference_error:.1e} (Richardson)"
        ),
    };
    format!(
        "{} {kind}: error = largest deviation of the positions from {reference}, sampled every {} s over {} s; \
         fits leave out errors below {:.0e} (the reference's floor)\n\n",
        problem.name(),
        sweep.dt0 * SAMPLE_EVERY as f64,
        sweep.duration,
        error_floor(reference_error)
    )
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
         errors below {floor:.0e} left out):\n\n"
    )
}

/// Introduces the cheapest runs, naming the targets left out as below the reference's reach.
pub fn cheapest_header(unresolved: &[f64], reference_error: f64) -> String {
    let left_out = if unresolved.is_empty() {
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
    };
    format!("\ncheapest run reaching each error (from the rows above){left_out}:\n\n")
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
    let mut t = Table::new([
        "method",
        "theory order",
        "fitted order",
        "order range",
        "diverged at dt",
    ])
    .short(["method", "theory", "fitted", "range", "diverged at dt [s]"]);
    let unfitted = if wide {
        "— (fewer than 2 usable rows)"
    } else {
        "— (< 2 rows)"
    };
    for o in orders(rows, floor) {
        t.row([
            o.method.name().to_string(),
            o.method.info().order_for(velocity_dependent).to_string(),
            o.fitted.map_or(unfitted.into(), |f| format!("{f:.3}")),
            o.range
                .map_or("—".into(), |(lo, hi)| format!("{lo:.3} – {hi:.3}")),
            if o.diverged_at.is_empty() {
                "—".into()
            } else {
                o.diverged_at
                    .iter()
                    .map(|d| format!("{d:.3e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
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
            p.range
                .map_or("—".into(), |(lo, hi)| format!("{lo:.3} – {hi:.3}")),
            p.rtols
                .map_or("—".into(), |(lo, hi)| format!("{lo:.0e} – {hi:.0e}")),
        ]);
    }
    t.render()
}

/// A run's step: its dt, or "adaptive" for a method that chooses its own (its `dt` is only the
/// interval it is sampled at; its own steps are counted under "steps accepted").
fn step_text(r: &Row) -> String {
    match r.rtol {
        Some(_) => "adaptive".into(),
        None => sci(r.dt),
    }
}

/// Every measured run; fitted, rtol and the wall time to one digit.
pub fn rows_table(rows: &[Row], wide: bool) -> String {
    let mut t = Table::new([
        "method",
        "dt [s]",
        "rtol",
        "error",
        "force evals",
        "steps accepted",
        "rejected",
        "median wall [s]",
    ])
    .short([
        "method", "dt [s]", "rtol", "error", "evals", "steps", "rejected", "wall [s]",
    ]);
    for r in rows {
        t.row([
            r.method.name().to_string(),
            step_text(r),
            r.rtol.map_or(
                "—".into(),
                |t| if wide { sci(t) } else { format!("{t:.0e}") },
            ),
            r.error.map_or("diverged".into(), sci),
            r.evals.to_string(),
            r.accepted.to_string(),
            r.rejected.to_string(),
            if wide {
                sci(r.wall_seconds)
            } else {
                format!("{:.1e}", r.wall_seconds)
            },
        ]);
    }
    t.render_at(wide)
}

/// The cheapest measured run reaching each target error, by wall time and by evaluations.
pub fn cheapest_table(rows: &[Row], targets: &[f64]) -> String {
    let mut t = Table::new([
        "target error",
        "fastest (wall)",
        "its wall [s]",
        "fewest evaluations",
        "its evals",
    ]);
    for &target in targets {
        let (by_wall, by_evals) = cheapest(rows, target);
        let name = |r: Option<&Row>| {
            r.map_or("none reached it".to_string(), |r| match r.rtol {
                Some(t) => format!("{} (rtol {t:.0e})", r.method.name()),
                None => format!("{} (dt {})", r.method.name(), sci(r.dt)),
            })
        };
        t.row([
            format!("{target:.0e}"),
            name(by_wall),
            by_wall.map_or("—".into(), |r| sci(r.wall_seconds)),
            name(by_evals),
            by_evals.map_or("—".into(), |r| r.evals.to_string()),
        ]);
    }
    t.render()
}

/// Measured stability limits against theory; fitted, each note said once under the table with
/// the methods it concerns.
pub fn stability_table(limits: &[Limit], wide: bool) -> String {
    let mut t = Table::new([
        "method",
        "measured dt [s]",
        "theory dt [s]",
        "measured / theory",
        "note",
    ])
    .short(["method", "measured dt [s]", "theory dt [s]", "ratio", ""]);
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
        "scene,method,dt,rtol,error,evals,accepted_steps,rejected_steps,wall_seconds,stable\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{:e},{},{},{},{},{},{:e},{}",
            r.scene,
            r.method,
            r.dt,
            r.rtol.map_or(String::new(), |t| format!("{t:e}")),
            r.error.map_or(String::new(), |e| format!("{e:e}")),
            r.evals,
            r.accepted,
            r.rejected,
            r.wall_seconds,
            r.error.is_some()
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
            l.theory_dt.map_or("none".into(), |d| if d.is_infinite() {
                "inf".into()
            } else {
                format!("{d:e}")
            })
        );
    }
    csv
}
