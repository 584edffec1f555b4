//! The pendulum run's summary table, as printed on stdout.

use crate::format::{sig, trim_number};
use crate::report::table::{OWN_STEPS_NOTE, Table, diverged_cell, figure, steps_cell};
use crate::scene::harness::{Run, Scene as _};
use crate::scene::pendulum::run::{PendulumLane, PendulumScene};

/// The summary: a few header lines (reference, energy, bounds) and one row per lane, its table
/// in full (`wide`) or fitted to 100 columns.
pub fn summary_text(scene: &PendulumScene, run: &Run<PendulumLane>, wide: bool) -> String {
    let mut out = header_text(scene);
    out.push('\n');
    out.push_str(&lanes_table(scene, run, wide));
    if run.stats.iter().any(|s| s.counts.own_steps.is_some()) {
        out.push_str(OWN_STEPS_NOTE);
    }
    out
}

/// The lines above the table: the run, the reference, the energy and its bounds, and what a
/// method's settings mean for its figures.
fn header_text(scene: &PendulumScene) -> String {
    let c = &scene.config;
    let p = &c.params;
    let schedule = scene.schedule();
    let mut out = String::new();
    out.push_str(&format!(
        "pendulum: g = {} m/s², L = {} m, θ0 = {}°, ω0 = {} rad/s, dt = {} s{}, {} steps to t = {} s\n",
        p.gravity,
        p.length,
        trim_number(p.theta0.to_degrees(), 9),
        p.omega0,
        c.dt,
        crate::scene::params::own_step_text(&c.options),
        schedule.total,
        trim_number(schedule.end_time(), 9)
    ));
    out.push_str(&format!("{}\n", scene.reference_description()));
    out.push_str(&format!(
        "E0 = {} J/kg (per unit mass, zero at the bottom); energy errors are (E - E0)/{}; \
         divergence = non-finite state or E > {} J/kg\n",
        sig(scene.initial_energy, 7),
        sig(scene.energy_scale, 7),
        sig(scene.energy_bound, 5)
    ));
    match scene.exact_period {
        Some(t) => out.push_str(&format!("exact period from E0: {t:.9} s\n")),
        None => out.push_str("exact period: none (at rest at the bottom, or on the separatrix)\n"),
    }
    if c.options.verlet_damping != 0.0 && c.methods.contains(&crate::integrate::Method::Verlet) {
        // The pendulum has no dissipative force: a loss is a method's, and stays in its error.
        out.push_str(&format!(
            "verlet: --verlet-damping {} is the method's own artificial damping, not a force of the \
             pendulum (which has none): the energy it takes out is part of verlet's energy error\n",
            c.options.verlet_damping
        ));
    }
    let stiffness = c.dt * c.dt * p.gravity / p.length;
    if stiffness >= 1.0 && c.methods.contains(&crate::integrate::Method::ImplicitEuler) {
        // θ1 + (dt² g/L) sin θ1 = θ0 + dt ω0 has one root only while dt² g/L < 1.
        out.push_str(&format!(
            "implicit-euler: dt²·g/L = {} ≥ 1 (dt ≥ sqrt(L/g) = {} s), so its step equation \
             θ1 + (dt²g/L) sin θ1 = θ0 + dt·ω0 has several roots; each step takes the one that minimises \
             the step's incremental potential ½(θ1 - θ0 - dt·ω0)² + dt²(g/L)(1 - cos θ1) (Newton bracketed \
             in at most three intervals), which keeps a release from rest at or below E0 (tested to dt²g/L = 7000)\n",
            sig(stiffness, 4),
            sig((p.length / p.gravity).sqrt(), 4)
        ));
    }
    out
}

/// One row per lane: cost, errors against the reference, period, outcome; fitted, the errors to
/// two digits and the period by its error alone.
fn lanes_table(scene: &PendulumScene, run: &Run<PendulumLane>, wide: bool) -> String {
    let mut table = Table::with_short([
        ("method", "method"),
        ("steps", "steps"),
        ("force evals", "evals"),
        ("wall [ms]", ""),
        ("ns/step", "ns/step"),
        ("max abs(θ−θref) [rad]", "θ err [rad]"),
        ("max abs(ΔE/E0)", "max ΔE/E0"),
        ("period [s]", ""),
        ("period rel. err", "period err"),
        ("diverged", "diverged"),
    ]);
    let digits = if wide { 3 } else { 1 };
    let err = |x: f64| format!("{x:.digits$e}");
    let dash = || "—".to_string();
    for (lane, s) in run.lanes.iter().zip(&run.stats) {
        // The reference is not timed, and has no error of its own.
        let timed = |shown: bool, text: String| if s.is_method && shown { text } else { dash() };
        let period = lane.meter.period();
        let period_err = match (period, scene.exact_period) {
            (Some(m), Some(e)) if wide => format!("{:+.2e}", m / e - 1.0),
            (Some(m), Some(e)) => format!("{:+.1e}", m / e - 1.0),
            _ => dash(),
        };
        table.row([
            s.name.to_string(),
            steps_cell(s, wide),
            timed(true, s.counts.evals.to_string()),
            timed(true, format!("{:.3}", s.wall.as_secs_f64() * 1e3)),
            s.ns_per_step().map_or_else(dash, |ns| format!("{ns:.1}")),
            timed(!s.failed_at_once(), err(lane.max_theta_error)),
            figure(s, err(lane.max_energy_error)),
            period.map_or_else(|| "— (< 2 crossings)".to_string(), |t| format!("{t:.9}")),
            period_err,
            diverged_cell(s, wide),
        ]);
    }
    table.render_at(wide)
}
