//! The pendulum run's summary table, as printed on stdout.

use super::run::RunSummary;
use crate::scene::schedule::divergence_cell;
use crate::table::Table;

/// The summary: a few header lines (reference, energy, bounds) and one row per lane.
pub fn summary_text(s: &RunSummary) -> String {
    let c = &s.setup.config;
    let p = &c.params;
    let mut out = String::new();
    out.push_str(&format!(
        "pendulum: g = {} m/s², L = {} m, θ0 = {}°, ω0 = {} rad/s, dt = {} s, {} steps to t = {} s\n",
        p.gravity,
        p.length,
        crate::table::trim_number(p.theta0.to_degrees(), 9),
        p.omega0,
        c.dt,
        c.total_steps(),
        crate::table::trim_number(c.total_steps() as f64 * c.dt, 9)
    ));
    out.push_str(&format!("{}\n", s.setup.reference_description));
    out.push_str(&format!(
        "E0 = {:.6} J/kg (per unit mass, zero at the bottom); energy errors are (E - E0)/{:.6}; \
         divergence = non-finite state or E > {:.4} J/kg\n",
        s.setup.initial_energy, s.setup.energy_scale, s.setup.energy_bound
    ));
    match s.setup.exact_period {
        Some(t) => out.push_str(&format!("exact period from E0: {t:.9} s\n\n")),
        None => {
            out.push_str("exact period: none (at rest at the bottom, or on the separatrix)\n\n")
        }
    }

    let mut table = Table::new([
        "method",
        "steps",
        "force evals",
        "wall [ms]",
        "ns/step",
        "max |θ-θref| [rad]",
        "max |ΔE/E0|",
        "period [s]",
        "period rel. err",
        "diverged",
    ]);
    for l in &s.lanes {
        let timed = l.method.is_some();
        let period = l
            .period
            .map_or_else(|| "— (< 2 crossings)".to_string(), |t| format!("{t:.9}"));
        let period_err = match (l.period, s.setup.exact_period) {
            (Some(m), Some(e)) => format!("{:+.2e}", m / e - 1.0),
            _ => "—".to_string(),
        };
        let diverged = divergence_cell(l.divergence.as_ref(), "t", l.failed_solves);
        table.row([
            l.name.to_string(),
            l.steps.to_string(),
            if timed {
                l.evals.to_string()
            } else {
                "—".into()
            },
            if timed {
                format!("{:.3}", l.wall.as_secs_f64() * 1e3)
            } else {
                "—".into()
            },
            match (timed, l.ns_per_step()) {
                (true, Some(ns)) => format!("{ns:.1}"),
                _ => "—".into(),
            },
            if timed {
                format!("{:.3e}", l.max_theta_error)
            } else {
                "—".into()
            },
            format!("{:.3e}", l.max_energy_error),
            period,
            period_err,
            diverged,
        ]);
    }
    out.push_str(&table.render());
    out
}
