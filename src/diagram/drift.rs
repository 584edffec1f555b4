//! The drift diagram: energy error and phase error against time, log-log, one series per
//! method, with dashed guides of slopes 0, 1 and 2 (what the theory says they grow like).

use super::{Diagram, Key, LEGEND_WIDTH, Panel, Plot, Series, decades};
use crate::format::sci;
use crate::study::drift::Drift;

/// Energy error (left) and phase error (right, where a run measured one) against simulated
/// time, per method; `commands`, one per run or none, what its points say measures it.
pub fn drift(scene: &str, (runs, commands): (&[Drift], Vec<String>), note: &str) -> Diagram {
    Diagram {
        stem: format!("{scene}-drift"),
        title: format!("{scene} drift"),
        size: (1600, 820),
        plot: drift_plot(scene, (runs, &commands), note),
        data: (runs.iter())
            .flat_map(|r| r.checkpoints.iter().map(move |c| (r, c)))
            .map(|(r, c)| {
                let (m, dt, t, e) = (r.method.name(), r.dt, c.t, c.energy);
                format!("{m} dt={dt:e} t={t:e} energy={e:e} phase={:?}\n", c.phase)
            })
            .collect(),
    }
}

/// The picture `docs/pendulum-drift.png` shows: [`drift`] of the runs
/// `report::figures::drift_pendulum_runs` gives.
pub fn pendulum_drift_picture(runs: &[Drift]) -> Diagram {
    drift(
        "pendulum",
        (runs, Vec::new()),
        "dt = 0.01 s, θ0 = 60°, 10⁵ periods.",
    )
}

/// A quantity of a checkpoint, positive where it was measured.
type Quantity = fn(&crate::study::drift::Checkpoint) -> Option<f64>;

fn drift_plot(scene: &str, (runs, commands): (&[Drift], &[String]), note: &str) -> Plot {
    // The rope has no phase: its energy alone, over the whole width.
    let phased = (runs.iter().flat_map(|r| &r.checkpoints)).any(|c| c.phase.is_some());
    let energy_desc = if scene == "pendulum" {
        "max |E − E0| / E0 since the last point"
    } else {
        "max |E − E0| / energy scale since the last point"
    };
    let quantities: [(&str, &'static str, Quantity); 2] = [
        ("energy error", energy_desc, |c| Some(c.energy)),
        (
            "phase error",
            "|phase error| at the last upward crossing [rad]",
            |c| c.phase,
        ),
    ];
    let times = || runs.iter().flat_map(|r| r.checkpoints.iter().map(|c| c.t));
    let x = decades(times());
    let (x0, x1) = (10f64.powf(x.start), 10f64.powf(x.end));
    let panels = quantities.iter().take(if phased { 2 } else { 1 });
    let panels = panels.map(|&(title, y_desc, quantity)| {
        let series: Vec<Series> = (runs.iter().enumerate())
            .map(|(i, r)| {
                let made = (commands.get(i)).map_or(String::new(), |c| format!("\nmade by: {c}"));
                let (points, about) = (r.checkpoints.iter())
                    .filter_map(|c| {
                        let v = quantity(c).filter(|v| *v > 0.0)?;
                        let run = format!("{} (dt {} s", r.method.name(), sci(r.dt));
                        let about = format!(
                            "{run}, {} evaluations in all)\nt = {} s\n{title} {}{made}",
                            r.evals,
                            sci(c.t),
                            sci(v)
                        );
                        Some(((c.t, v), about))
                    })
                    .unzip();
                Series {
                    key: Key::of(r.method),
                    points,
                    about,
                }
            })
            .collect();
        let y = decades(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
        // Guides through the panel's middle value at the first time: t⁰, t¹, t².
        let mid = 10f64.powf(0.5 * (y.start + y.end));
        let guides = [(0, "t⁰"), (1, "t¹"), (2, "t²")]
            .iter()
            .map(|&(p, name)| {
                let end = mid * (x1 / x0).powi(p);
                (vec![(x0, mid), (x1, end)], name.to_string())
            })
            .collect();
        Panel {
            title: format!("{scene}: {title} against time"),
            x_desc: "simulated time [s]",
            y_desc,
            x: x.clone(),
            y,
            series,
            guides,
            y_names: Vec::new(),
        }
    });
    Plot {
        panels: panels.collect(),
        keys: runs.iter().map(|r| Key::of(r.method)).collect(),
        notes: vec![
            "symplectic: energy bounded, phase ∝ t; others: energy ∝ t, phase ∝ t².".into(),
            "dashed: slopes 0, 1 and 2.".into(),
            note.to_string(),
        ],
        legend_px: LEGEND_WIDTH,
    }
}
