//! The diagrams: work-precision, convergence, stability and the hair trade, each from a
//! study's rows.

use super::{Diagram, Key, LEGEND_WIDTH, Panel, Plot, Series, decade_label, decades};
use plotters::prelude::*;
use std::collections::BTreeMap;

use crate::format::sci;
use crate::study::hair::HairRow;
use crate::study::{Limit, Row, methods_of};

/// What the error is, with its unit, for a scene.
pub(super) fn error_desc(scene: &str) -> &'static str {
    match scene {
        "pendulum" => "error: max |θ − θref| [rad]",
        _ => "error: max |x − xref| over nodes [m]",
    }
}

/// Per method and variant (plain, stepping across the samples: `--step` above `dt0`, with
/// compensated sums), its runs' (x, error), x given by `x`, each point saying which run it is
/// (and, given one per row, the command that makes it): a series and a legend key each.
fn series(rows: &[Row], x: fn(&Row) -> f64, commands: &[String], dt0: f64) -> Vec<Series> {
    let across = |r: &Row| r.rtol.is_none() && r.dt > dt0 * (1.0 + 1e-9);
    let mut all: BTreeMap<String, Series> = BTreeMap::new();
    for (i, r) in rows.iter().enumerate() {
        if !r.error.is_some_and(|e| e > 0.0) {
            continue;
        }
        let key = Key::variant(r.method, across(r), r.compensated);
        let series = all.entry(key.name.clone()).or_insert_with(|| Series {
            key,
            points: Vec::new(),
            about: Vec::new(),
        });
        let mut about = crate::report::study::run_about(r);
        if let Some(command) = commands.get(i) {
            about = format!("{about}\nmade by: {command}");
        }
        series.points.push((x(r), r.error.unwrap_or(0.0)));
        series.about.push(about);
    }
    // In the registry's order, each method's variants after it.
    let mut all: Vec<Series> = all.into_values().collect();
    all.sort_by_key(|s| (s.key.shape, s.key.name.len()));
    all
}

/// Work-precision: error against median wall time and against force evaluations, the
/// reference's error `floor` dashed; `commands`, one per row or none, what each point says makes
/// its run; `dt0` the sweep's coarsest level (larger steps are series of their own).
pub fn work_precision(
    scene: &str,
    (rows, dt0): (&[Row], f64),
    floor: f64,
    note: &str,
    commands: Vec<String>,
) -> Diagram {
    Diagram {
        stem: format!("{scene}-work-precision"),
        title: format!("{scene} work-precision"),
        // Tall and wide enough for a legend key per method and variant.
        size: (1600, 1100),
        plot: work_precision_plot(scene, (rows, dt0), floor, note, &commands),
        data: super::rows_data(rows, floor),
    }
}

/// The picture `docs/pendulum-work-precision.png` shows: [`work_precision`] of the pendulum's
/// runs and reference error as `report::figures::work_precision_pendulum_runs` gives them.
pub fn pendulum_work_precision_picture(runs: &(Vec<Row>, f64)) -> Diagram {
    let dt0 =
        crate::study::Sweep::defaults(&crate::study::Problem::Pendulum(Default::default())).dt0;
    work_precision(
        "pendulum",
        (&runs.0, dt0),
        runs.1,
        "wall times: median of the repeats on a two-core machine; machine-dependent.",
        Vec::new(),
    )
}

/// A work-precision panel: title, x axis description, and the cost it plots.
type Axis = (&'static str, &'static str, fn(&Row) -> f64);

fn work_precision_plot(
    scene: &str,
    (rows, dt0): (&[Row], f64),
    floor: f64,
    note: &str,
    commands: &[String],
) -> Plot {
    let errors = || rows.iter().filter_map(|r| r.error);
    let y = decades(errors().chain([floor]));
    let axes: [Axis; 2] = [
        (
            "error against median wall time",
            "median wall time [s]",
            |r| r.wall_seconds,
        ),
        (
            "error against force evaluations",
            "force evaluations",
            |r| r.evals as f64,
        ),
    ];
    let panels = axes.map(|(title, x_desc, cost)| {
        let x = decades(rows.iter().filter(|r| r.error.is_some()).map(cost));
        let (x0, x1) = (10f64.powf(x.start), 10f64.powf(x.end));
        Panel {
            title: format!("{scene}: {title}"),
            x_desc,
            y_desc: error_desc(scene),
            x,
            y: y.clone(),
            series: series(rows, cost, commands, dt0),
            guides: vec![(vec![(x1, floor), (x0, floor)], "reference's error".into())],
            y_names: Vec::new(),
        }
    });
    let floor = crate::study::floor_text(floor);
    Plot {
        keys: panels[0].series.iter().map(|s| s.key.clone()).collect(),
        panels: panels.into(),
        notes: vec![
            format!("{scene}: lower left is better."),
            format!("dashed: the reference's error {floor} (the floor)."),
            note.to_string(),
        ],
        legend_px: LEGEND_WIDTH + 80,
    }
}

/// Convergence: error against dt for the fixed-step methods, dashed slopes for each theoretical
/// order and the reference's error `floor`; `commands` as for [`work_precision`].
pub fn convergence(
    scene: &str,
    (rows, commands): (&[Row], &[String]),
    floor: f64,
    velocity_dependent: bool,
) -> Diagram {
    let fixed = |i: &usize| rows[*i].rtol.is_none();
    let kept: Vec<usize> = (0..rows.len()).filter(fixed).collect();
    let rows: Vec<Row> = kept.iter().map(|&i| rows[i].clone()).collect();
    let commands: Vec<String> = (kept.iter())
        .filter_map(|&i| commands.get(i).cloned())
        .collect();
    let (stem, title) = match velocity_dependent {
        true => ("-damped", ", damped"),
        false => ("", ""),
    };
    Diagram {
        stem: format!("{scene}-convergence{stem}"),
        title: format!("{scene} convergence{title}"),
        size: (1300, 860),
        plot: convergence_plot(scene, (&rows, &commands), floor, velocity_dependent),
        data: super::rows_data(&rows, floor),
    }
}

fn convergence_plot(
    scene: &str,
    (rows, commands): (&[Row], &[String]),
    floor: f64,
    velocity_dependent: bool,
) -> Plot {
    let methods = methods_of(rows, |_| true);
    let x = decades(rows.iter().map(|r| r.dt));
    let y = decades(rows.iter().filter_map(|r| r.error).chain([floor]));
    let series = series(rows, |r| r.dt, commands, f64::INFINITY);
    let keys = series.iter().map(|s| s.key.clone()).collect();
    // One reference slope per theoretical order, parallel to and below that order's lowest
    // curve, over the same steps (from the coarsest dt down to the finest, or to the bottom).
    let dt_min = rows.iter().map(|r| r.dt).fold(f64::INFINITY, f64::min);
    let mut orders: Vec<u32> = methods
        .iter()
        .map(|&m| m.info().order_for(velocity_dependent))
        .collect();
    orders.sort_unstable();
    orders.dedup();
    let (x_lo, x_hi, y_lo) = (10f64.powf(x.start), 10f64.powf(x.end), 10f64.powf(y.start));
    let mut guides: Vec<(Vec<(f64, f64)>, String)> =
        vec![(vec![(x_hi, floor), (x_lo, floor)], "reference floor".into())];
    for &p in &orders {
        // From the coarsest step of this order's methods (each method has its own grid).
        let of_order =
            || (rows.iter()).filter(|r| r.method.info().order_for(velocity_dependent) == p);
        let top = of_order().map(|r| r.dt).fold(0.0, f64::max);
        let lowest = of_order()
            .filter(|r| r.dt == top)
            .filter_map(|r| r.error)
            .filter(|e| *e > floor)
            .fold(f64::INFINITY, f64::min);
        if !lowest.is_finite() {
            continue;
        }
        let anchor = lowest / 4.0;
        let bottom = top * (y_lo / anchor).powf(1.0 / f64::from(p));
        let end = bottom.max(dt_min);
        guides.push((
            vec![(top, anchor), (end, anchor * (end / top).powi(p as i32))],
            format!("∝ dt{}", decade_label(p as i32).trim_start_matches("10")),
        ));
    }
    let damped = match velocity_dependent {
        true => ", damped (velocity-dependent forces)",
        false => "",
    };
    let title = format!("{scene}{damped}: error against step size, fixed-step methods");
    Plot {
        panels: vec![Panel {
            title,
            x_desc: "dt [s]",
            y_desc: error_desc(scene),
            x,
            y,
            series,
            guides,
            y_names: Vec::new(),
        }],
        keys,
        notes: vec![
            "dashed slopes: dtᵖ for each theoretical order p, a quarter below that order's lowest curve."
                .to_string(),
            format!("flat dashed: the reference's error floor {floor:.0e}."),
            "adaptive methods choose their own steps: see work-precision.".to_string(),
        ],
        legend_px: LEGEND_WIDTH,
    }
}

/// Stability: per method a row, its measured largest stable dt a point in its colour (which
/// says on hover the method and both limits) and theory's a grey tick across the row, on a log
/// dt axis; the rows without a finite theory said in the notes.
pub fn stability(scene: &str, limits: &[Limit], omega: f64) -> Diagram {
    let height = 180 + 44 * limits.len() as u32;
    let data: String = (limits.iter())
        .map(|l| {
            let (m, measured, theory) = (l.method.name(), l.measured_dt, l.theory_dt);
            format!("{m} measured={measured:?} theory={theory:?}\n")
        })
        .collect();
    Diagram {
        stem: format!("{scene}-stability"),
        title: format!("{scene} stability"),
        size: (1300, height.max(500)),
        plot: stability_plot(scene, limits, omega),
        data: format!("omega={omega:e}\n{data}"),
    }
}

/// What one method's row of the stability diagram says on hover: its measured limit, theory's
/// and their ratio, or why theory gives none.
fn limit_about(l: &Limit) -> String {
    let (m, measured, theory) = (l.method, l.measured_dt, l.theory_dt);
    let measured = measured.map_or("none found".into(), |d| format!("{} s", sci(d)));
    let theory = match theory {
        Some(t) if t.is_finite() => format!("{} s", sci(t)),
        Some(_) => "stable at every dt (measured: the largest tried)".into(),
        None if m.info().stability == crate::integrate::Stability::Adaptive => {
            "none: error control chooses the steps".into()
        }
        None => "unstable at every dt".into(),
    };
    format!(
        "{}\nlargest stable dt, measured: {measured}\ntheory: {theory}",
        m.name()
    )
}

fn stability_plot(scene: &str, limits: &[Limit], omega: f64) -> Plot {
    let n = limits.len();
    // Row i at log10 y = n-1-i: the first method on top.
    let row = |i: usize, dy: f64| 10f64.powf((n - 1 - i) as f64 + dy);
    let mut series = Vec::new();
    let mut guides = Vec::new();
    for (i, l) in limits.iter().enumerate() {
        if let Some(d) = l.measured_dt {
            let (points, about) = (vec![(d, row(i, 0.0))], vec![limit_about(l)]);
            let key = Key::of(l.method);
            series.push(Series { key, points, about });
        }
        if let Some(t) = l.theory_dt.filter(|t| t.is_finite()) {
            guides.push((vec![(t, row(i, -0.3)), (t, row(i, 0.3))], String::new()));
        }
    }
    let finite = limits
        .iter()
        .flat_map(|l| [l.measured_dt, l.theory_dt])
        .flatten();
    let x = decades(finite.filter(|v| v.is_finite()));
    let title =
        format!("{scene}: largest stable dt, measured against theory (ω = {omega:.4} rad/s)");
    let mut notes = vec![
        "point: measured largest stable dt (bisection); grey tick: theory, limit h / ω on the linearised problem.".to_string(),
    ];
    let adaptive = |l: &Limit| l.method.info().stability == crate::integrate::Stability::Adaptive;
    let said = |which: &dyn Fn(&Limit) -> bool, what: &str| {
        let names: Vec<&str> = (limits.iter())
            .filter(|l| which(l))
            .map(|l| l.method.name())
            .collect();
        (!names.is_empty()).then(|| format!("{}: {what}", names.join(", ")))
    };
    notes.extend(said(
        &|l| l.theory_dt == Some(f64::INFINITY),
        "stable at every dt (point: the largest tried).",
    ));
    notes.extend(said(
        &|l| l.theory_dt.is_none() && adaptive(l),
        "adaptive: error control chooses the steps.",
    ));
    notes.extend(said(
        &|l| l.measured_dt.is_none() && l.theory_dt.is_some_and(f64::is_finite),
        "no limit measured (the table says why).",
    ));
    notes.extend(said(
        &|l| l.theory_dt.is_none() && !adaptive(l),
        "unstable at every dt (point: growth stays below 10⁴).",
    ));
    Plot {
        panels: vec![Panel {
            title,
            x_desc: "dt [s]",
            y_desc: "",
            x,
            y: -0.5..n as f64 - 0.5,
            series,
            guides,
            y_names: (limits.iter())
                .rev()
                .map(|l| l.method.name().to_string())
                .collect(),
        }],
        keys: limits.iter().map(|l| Key::of(l.method)).collect(),
        notes,
        legend_px: LEGEND_WIDTH,
    }
}

/// The hair trade: largest stretch over the run against wall time per frame, a series per family
/// of configurations ([`hair_family`]), each point a configuration of the table.
pub fn hair_trade(rows: &[HairRow], note: &str) -> Diagram {
    Diagram {
        stem: "hair-trade".to_string(),
        title: "hair trade".to_string(),
        size: (1500, 900),
        plot: hair_trade_plot(rows, note),
        data: (rows.iter())
            .map(|r| format!("{} stretch={:?}\n", r.flags(), r.stretch))
            .collect(),
    }
}

/// The family a hair configuration belongs to: what stays fixed along its series.
fn hair_family(r: &HairRow) -> String {
    let method = r.method.name();
    match (r.solver, r.stiffness) {
        (Some(crate::scene::hair::Solver::GaussSeidel), _) => format!(
            "{method} gauss-seidel, {}, over sweeps",
            crate::format::plural(r.substeps, "substep")
        ),
        (Some(s), _) => format!("{method} {}, over Newton steps", s.name()),
        (None, Some(k)) if r.method == crate::scene::hair::HairMethod::ImplicitEuler => {
            format!("{method} k/m = {k:.0e}, over substeps")
        }
        (None, Some(_)) => format!("{method}, over k/m"),
        (None, None) => method.to_string(),
    }
}

fn hair_trade_plot(rows: &[HairRow], note: &str) -> Plot {
    let mut families: Vec<(String, crate::scene::hair::HairMethod)> = Vec::new();
    for r in rows {
        let f = hair_family(r);
        if !families.iter().any(|(g, _)| *g == f) {
            families.push((f, r.method));
        }
    }
    // A method's colour, lighter for each further family of the same method.
    let keys: Vec<Key> = families
        .iter()
        .enumerate()
        .map(|(i, (family, method))| {
            let earlier = families[..i].iter().filter(|(_, m)| m == method).count();
            let share = (0.2 * earlier as f64).min(0.8);
            let lighter = |c: u8| (f64::from(c) + f64::from(255 - c) * share) as u8;
            let [r, g, b] = crate::palette::method_color(method.name());
            Key {
                name: family.clone(),
                color: RGBColor(lighter(r), lighter(g), lighter(b)),
                shape: i,
                dashed: false,
                hollow: false,
            }
        })
        .collect();
    let series: Vec<Series> = keys
        .iter()
        .map(|key| {
            let (points, about) = (rows.iter())
                .filter(|row| hair_family(row) == key.name)
                .filter_map(|row| {
                    let (ms, s) = (row.ms_per_frame, row.stretch?);
                    let about = format!("{}\nstretch {s:.3e}\n{ms:.3} ms per frame", row.flags());
                    Some(((ms, s), about))
                })
                .unzip();
            Series {
                key: key.clone(),
                points,
                about,
            }
        })
        .collect();
    let plotted = || series.iter().flat_map(|s| s.points.iter().copied());
    let x = decades(plotted().map(|(x, _)| x));
    let y = decades(plotted().map(|(_, y)| y).chain([1e-16]));
    Plot {
        panels: vec![Panel {
            title: "hair: largest stretch against cost per frame".into(),
            x_desc: "wall time per frame [ms]",
            y_desc: "max stretch |ℓ − ℓ0|/ℓ0",
            x,
            y,
            series,
            guides: Vec::new(),
            y_names: Vec::new(),
        }],
        keys,
        notes: vec![
            "lower left is better; a diverged configuration has no point.".to_string(),
            "stretch near 1e-16 is round-off: the constraint holds to machine precision."
                .to_string(),
            note.to_string(),
        ],
        legend_px: LEGEND_WIDTH + 150,
    }
}
