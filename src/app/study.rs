//! `physlab study`: resolves the study's scene, runs the measurement, prints markdown tables,
//! and writes the CSV and recording when asked.

use std::fmt::Write as _;

use super::SceneFile;
use super::UsageError;
use crate::cli::{PendulumArgs, RopeArgs, StudyArgs, StudyKind, StudyScene};
use crate::integrate::{Method, MethodOptions};
use crate::report::table::Table;
use crate::study::{Limit, Problem, Row, Sweep, cheapest, error_floor, orders, stability, sweep};

/// The study's problem and sweep from its flags, over the scene file, over the scene defaults
/// (for the rope's convergence and cost: a softer, undamped rope, so that explicit methods
/// converge and the theory's orders apply).
fn setup(a: &StudyArgs) -> Result<(Problem, Sweep, u64), UsageError> {
    let file = match &a.config {
        Some(path) => SceneFile::load(path)?,
        None => SceneFile::default(),
    };
    let stability_study = a.kind == StudyKind::Stability;
    let levels = a.levels.unwrap_or(6);
    if !(2..=20).contains(&levels) {
        return Err(UsageError(format!(
            "--levels {levels}: must be between 2 and 20"
        )));
    }
    let repeats = a.repeats.unwrap_or(5);
    if !(1..=100).contains(&repeats) {
        return Err(UsageError(format!(
            "--repeats {repeats}: must be between 1 and 100"
        )));
    }
    let steps = a.steps.unwrap_or(2000);
    if !(10..=10_000_000).contains(&steps) {
        return Err(UsageError(format!(
            "--steps {steps}: must be between 10 and 10000000"
        )));
    }
    let rtols = a
        .rtol
        .clone()
        .unwrap_or_else(|| (3..=12).map(|k| 10f64.powi(-k)).collect());
    if let Some(bad) = rtols
        .iter()
        .find(|r| !(r.is_finite() && (1e-14..=0.1).contains(*r)))
    {
        return Err(UsageError(format!(
            "--rtol {bad}: must be between 1e-14 and 0.1"
        )));
    }
    let methods = a.methods.clone().unwrap_or_else(|| Method::ALL.to_vec());
    let (problem, dt0, duration) = match a.scene {
        StudyScene::Pendulum => {
            let flags = PendulumArgs {
                theta0: a.theta0,
                omega0: a.omega0,
                ..PendulumArgs::default()
            };
            let args = flags.over(file.pendulum.unwrap_or_default());
            let c = super::pendulum_config(&args)?;
            (
                Problem::Pendulum(c.params),
                a.dt.unwrap_or(0.02),
                a.duration.unwrap_or(10.0),
            )
        }
        StudyScene::Rope => {
            let study_defaults = RopeArgs {
                stiffness: (!stability_study).then_some(100.0),
                spring_damping: Some(0.0),
                air_drag: Some(0.0),
                ..RopeArgs::default()
            };
            let flags = RopeArgs {
                nodes: a.nodes,
                stiffness: a.stiffness,
                mass: a.mass,
                spring_damping: a.spring_damping,
                air_drag: a.air_drag,
                ..RopeArgs::default()
            };
            let args = flags
                .over(file.rope.unwrap_or_default())
                .over(study_defaults);
            let c = super::rope_config(&args)?;
            (
                Problem::Rope(c.params),
                a.dt.unwrap_or(0.002),
                a.duration.unwrap_or(1.0),
            )
        }
    };
    crate::scene::params::positive("--dt", dt0, "s")?;
    crate::scene::params::positive("--duration", duration, "s")?;
    if dt0 > duration {
        return Err(UsageError(format!(
            "--dt {dt0}: must not exceed --duration {duration} s"
        )));
    }
    let sweep = Sweep {
        dt0,
        levels,
        duration,
        methods,
        options: MethodOptions::default(),
        repeats,
        rtols,
    };
    Ok((problem, sweep, steps))
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

pub fn study(a: &StudyArgs) -> anyhow::Result<()> {
    let (problem, sw, steps) = setup(a)?;
    let mut out = String::new();
    let mut csv = String::new();
    let mut rows: Vec<Row> = Vec::new();
    let mut limits: Vec<Limit> = Vec::new();
    match a.kind {
        StudyKind::Convergence | StudyKind::WorkPrecision => {
            let (r, reference_error) = sweep(&problem, &sw);
            rows = r;
            let reference = if reference_error == 0.0 {
                "the exact elliptic solution".to_string()
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
                let mut t = Table::new([
                    "method",
                    "theory order",
                    "fitted order",
                    "order range",
                    "diverged at dt",
                ]);
                for o in orders(&rows, error_floor(reference_error)) {
                    t.row([
                        o.method.name().to_string(),
                        o.method.info().order.to_string(),
                        o.fitted.map_or("— (fewer than 2 usable rows)".into(), |f| {
                            format!("{f:.3}")
                        }),
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
                out.push_str(&t.render());
                out.push('\n');
            }
            let mut t = Table::new([
                "method",
                "dt [s]",
                "rtol",
                "error",
                "force evals",
                "median wall [s]",
            ]);
            for r in &rows {
                t.row([
                    r.method.name().to_string(),
                    sci(r.dt),
                    r.rtol.map_or("—".into(), sci),
                    r.error.map_or("diverged".into(), sci),
                    r.evals.to_string(),
                    sci(r.wall_seconds),
                ]);
            }
            out.push_str(&t.render());
            if a.kind == StudyKind::WorkPrecision {
                writeln!(
                    out,
                    "\ncheapest run reaching each error (from the rows above):\n"
                )?;
                let mut t = Table::new([
                    "target error",
                    "fastest (wall)",
                    "its wall [s]",
                    "fewest evaluations",
                    "its evals",
                ]);
                for target in [1e-3, 1e-6, 1e-9] {
                    let (by_wall, by_evals) = cheapest(&rows, target);
                    let name = |r: Option<&Row>| {
                        r.map_or("none reached it".to_string(), |r| {
                            format!(
                                "{} (dt {}{})",
                                r.method.name(),
                                sci(r.dt),
                                r.rtol.map_or(String::new(), |t| format!(", rtol {t:.0e}"))
                            )
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
                out.push_str(&t.render());
            }
            csv.push_str("scene,method,dt,rtol,error,evals,wall_seconds,stable\n");
            for r in &rows {
                writeln!(
                    csv,
                    "{},{},{:e},{},{},{},{:e},{}",
                    r.scene,
                    r.method,
                    r.dt,
                    r.rtol.map_or(String::new(), |t| format!("{t:e}")),
                    r.error.map_or(String::new(), |e| format!("{e:e}")),
                    r.evals,
                    r.wall_seconds,
                    r.error.is_some()
                )?;
            }
        }
        StudyKind::Stability => {
            limits = stability(&problem, &sw.methods, steps);
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
            let mut t = Table::new([
                "method",
                "measured dt [s]",
                "theory dt [s]",
                "measured / theory",
                "note",
            ]);
            for l in &limits {
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
            out.push_str(&t.render());
            csv.push_str("scene,method,measured_dt,theory_dt\n");
            for l in &limits {
                writeln!(
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
                )?;
            }
        }
    }
    print!("{out}");
    if let Some(path) = &a.csv {
        std::fs::write(path, &csv)
            .map_err(|e| anyhow::anyhow!("--csv {}: cannot write it: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &a.output {
        let d = crate::record::Destinations {
            file: Some(path.clone()),
            ..Default::default()
        };
        let bytes = crate::record::study::record_study(&d, problem.name(), &rows, &limits, &out)?;
        println!(
            "\nrecording: {} ({:.2} MB)",
            path.display(),
            bytes.unwrap_or(0) as f64 / 1e6
        );
    }
    Ok(())
}
