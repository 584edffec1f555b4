//! What `study drift` prints: how it measured, and per method the fitted growth exponents of
//! its energy and phase errors against theory, each row with the command that measures it.

use super::table::Table;
use crate::format::shown;
use crate::scene::rope::RopeParams;
use crate::study::drift::{Drift, FIT_SPAN, exponent, theory};

/// The pendulum study's first lines: the problem, the schedule and how the errors are measured.
pub fn pendulum_header(theta0_degrees: f64, period: f64, dt: f64, duration: f64) -> String {
    format!(
        "pendulum drift: released from rest at θ0 = {}°, period T = {period:.6} s; dt = {} s \
         over {} s ({:.3e} periods, {:.3e} steps per method). Every step is checked: energy \
         error |E − E0|/E0 (its largest since the previous point, 10 points a decade) and phase \
         error 2π·|t_k − t_k,exact|/T at each upward crossing of θ = 0 (the k-th against the \
         closed form's). Exponents: least-squares slopes of log error against log t over the \
         last {} decades (t ≥ end/{FIT_SPAN}).\n\n",
        shown(theta0_degrees),
        shown(dt),
        shown(duration),
        duration / period,
        duration / dt,
        FIT_SPAN.log10(),
    )
}

/// The rope study's first lines.
pub fn rope_header(p: &RopeParams, dt: f64, duration: f64) -> String {
    format!(
        "rope drift: {} nodes, ks = {} N/m, {}, released horizontal; dt = {} s over {} s \
         ({:.3e} steps per method). Every step is checked: energy error {} over the \
         rope's energy scale (its largest since the previous point, 10 points a decade). No \
         phase: no closed form gives the rope's. Exponents: least-squares slopes of log error \
         against log t over the last {} decades (t ≥ end/{FIT_SPAN}); a method whose energy \
         left the scene's bound is marked lost.\n\n",
        p.nodes,
        shown(p.stiffness),
        crate::report::rope::forces_text(p),
        shown(dt),
        shown(duration),
        duration / dt,
        if p.velocity_dependent() {
            "|E + W − E0| (the energy balance, W the dissipated work integrated with the state; \
             the theory: bounded once the motion has decayed)"
        } else {
            "|E − E0|"
        },
        FIT_SPAN.log10(),
    )
}

/// Relative energy errors below this at the end of a run are round-off (about 10⁴ ulps).
const ROUND_OFF: f64 = 1e-11;

/// An exponent to three decimals, or why there is none.
fn exponent_text(e: Option<f64>) -> String {
    e.map_or("—".into(), |e| format!("{e:.3}"))
}

/// What the theory says, or why it says nothing; fitted, in a word.
fn theory_text(t: Option<f64>, method: crate::integrate::Method, wide: bool) -> String {
    match (t, method == crate::integrate::Method::ExplicitEuler, wide) {
        (Some(t), ..) => format!("{t}"),
        (None, true, true) => "none (grows geometrically)".into(),
        (None, true, false) => "geometric".into(),
        (None, false, true) => "none (decays to rest)".into(),
        (None, false, false) => "decays".into(),
    }
}

/// The exponents against theory per method, in full (`wide`) or fitted (each exponent beside
/// its theory, counts to two digits); with the scene's flags and `rtol`, the command that
/// measures one method alone is said once above it (docs/results.md's table gives one for all).
pub fn drift_table(runs: &[Drift], command: Option<(&str, f64)>, wide: bool) -> String {
    let mut header = if wide {
        vec![
            "method",
            "symplectic",
            "energy exponent",
            "theory",
            "phase exponent",
            "theory",
            "energy error at end",
            "phase error at end [rad]",
            "force evals",
        ]
    } else {
        vec![
            "method",
            "energy t^p",
            "phase t^p",
            "energy at end",
            "phase [rad]",
            "evals",
        ]
    };
    let rope = runs.iter().any(|r| r.shortest_spring.is_some());
    if rope {
        header.push(pick(wide, "shortest spring / rest", "min spring/rest"));
    }
    let mut t = Table::new(header);
    for r in runs {
        let mut row = drift_row(r, wide);
        if rope {
            row.push(r.shortest_spring.map_or("—".into(), |s| format!("{s:.2e}")));
        }
        t.row(row);
    }
    let mut out = String::new();
    if let (Some((flags, rtol)), Some(r)) = (command, runs.first()) {
        let adaptive = runs.iter().any(|r| r.method.info().adaptive());
        let rtol = if adaptive {
            format!(" (adaptive methods add --rtol {rtol:e})")
        } else {
            String::new()
        };
        let command = run_command("NAME", flags, r, None);
        out = format!("each row measured alone by{rtol}:\n  {command}\n\n");
    }
    if !wide {
        out.push_str(
            "t^p: the error's growth as a power of t, p fitted (the theory's p); energy and phase \
             [rad] at end: the errors at the last point\n\n",
        );
    }
    out + &t.render_at(wide)
}

/// The command that measures `r` alone: `method` (a name, or "NAME" for every row), the
/// scene's `flags`, its step and duration, and `rtol` (for an adaptive method).
pub fn run_command(method: &str, flags: &str, r: &Drift, rtol: Option<f64>) -> String {
    let rtol = rtol.map_or(String::new(), |t| format!(" --rtol {t:e}"));
    format!(
        "physlab study drift --methods {method} {flags} --dt {} --duration {}{rtol}",
        shown(r.dt),
        shown(r.duration),
    )
}

/// `full` in the full table (`wide`), else its `word`.
fn pick<'a>(wide: bool, full: &'a str, word: &'a str) -> &'a str {
    if wide { full } else { word }
}

/// One method's row of [`drift_table`] (without the rope's shortest spring).
fn drift_row(r: &Drift, wide: bool) -> Vec<String> {
    let energy: Vec<(f64, f64)> = r.checkpoints.iter().map(|c| (c.t, c.energy)).collect();
    let phase: Vec<(f64, f64)> = (r.checkpoints.iter())
        .filter_map(|c| c.phase.map(|p| (c.t, p)))
        .collect();
    let (energy_theory, phase_theory) = theory(r.method, r.damped);
    // A run without a single crossing measured has no phase to speak of (the rope).
    let phased = !phase.is_empty();
    let last = r.checkpoints.last();
    let end = r.lost_at.map_or_else(
        || last.map_or("—".into(), |c| format!("{:.2e}", c.energy)),
        |t| format!("lost at {}{} s", if wide { "t = " } else { "" }, shown(t)),
    );
    // A method whose energy error stays near f64's resolution measures its round-off, not
    // its truncation, which the theory speaks of.
    let round_off = last.is_some_and(|c| c.energy < ROUND_OFF);
    let said = |full, word| pick(wide, full, word).to_string();
    let energy_said = if round_off {
        said("none: at round-off (a random walk, ~0.5)", "round-off")
    } else {
        theory_text(energy_theory, r.method, wide)
    };
    let phase_said = if round_off && phased {
        said("none: at round-off", "round-off")
    } else if phased || r.lost_at.is_some() {
        theory_text(phase_theory, r.method, wide)
    } else {
        said("none (no closed form)", "no closed form")
    };
    let energy_exponent = exponent_text(r.lost_at.map_or(exponent(&energy), |_| None));
    let phase_exponent = exponent_text(r.lost_at.map_or(exponent(&phase), |_| None));
    let phase_end = (last.and_then(|c| c.phase)).map_or("—".into(), |p| format!("{p:.2e}"));
    let name = r.method.name().to_string();
    if !wide {
        return vec![
            name,
            format!("{energy_exponent} ({energy_said})"),
            format!("{phase_exponent} ({phase_said})"),
            end,
            phase_end,
            format!("{:.1e}", r.evals as f64),
        ];
    }
    let symplectic = r.method.info().symplectic;
    vec![
        name,
        if symplectic { "yes" } else { "no" }.into(),
        energy_exponent,
        energy_said,
        phase_exponent,
        phase_said,
        end,
        phase_end,
        r.evals.to_string(),
    ]
}

/// One row per checkpoint: method, dt, t, energy error, phase error.
pub fn drift_csv(scene: &str, runs: &[Drift]) -> String {
    let mut out = String::from("scene,method,dt,t,energy_error,phase_error\n");
    for r in runs {
        for c in &r.checkpoints {
            out.push_str(&format!(
                "{scene},{},{:e},{:e},{:e},{}\n",
                r.method.name(),
                r.dt,
                c.t,
                c.energy,
                c.phase.map_or(String::new(), |p| format!("{p:e}"))
            ));
        }
    }
    out
}
