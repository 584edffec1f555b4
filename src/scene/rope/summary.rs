//! The rope run's summary table, as printed on stdout.

use super::run::{ENERGY_GAIN_BOUND, RopeSummary};
use crate::method::{EvalsPerStep, Method};
use crate::scene::schedule::divergence_cell;
use crate::table::{Table, trim_number};

/// What one step of `method` costs on an N-node rope, in words.
pub fn cost_per_step(method: Method, newton_iterations: u32) -> String {
    match method.info().evals_per_step {
        EvalsPerStep::Fixed(k) => format!("{k} force eval{} O(N)", if k == 1 { "" } else { "s" }),
        EvalsPerStep::NewtonIterations => {
            format!("≤{newton_iterations} × (force + Jacobian + block-tridiagonal solve) O(N)")
        }
        EvalsPerStep::Adaptive => "6 force evals O(N) per accepted substep".to_string(),
    }
}

pub fn summary_text(s: &RopeSummary) -> String {
    let c = &s.setup.config;
    let p = &c.params;
    let v = |d: glam::DVec3| {
        format!(
            "({}, {}, {})",
            trim_number(d.x, 6),
            trim_number(d.y, 6),
            trim_number(d.z, 6)
        )
    };
    let schedule = c.schedule();
    let mut out = format!(
        "rope: {} nodes from {} to {} m, rest length {} m, mass {} kg/node, ks = {} N/m, kd = {} N·s/m, \
         ka = {} N·s/m, g = {} m/s², pinned {:?}\n\
         dt = {} s, {} steps to t = {} s; ω_max (pinned-free chain) = {:.4} rad/s, so ω_max·dt = {:.4} \
         (semi-implicit Euler and Verlet need < 2, RK4 < 2.83 without damping)\n\
         E0 = {:.6} J, energy scale {:.4} J; divergence = non-finite state, strain > {:.3}, \
         or an energy gain > {ENERGY_GAIN_BOUND} × the scale\n\
         ns/step: wall time of the stepping alone, read between plot samples (`cargo bench --bench rope_step` \
         times it without the clock reads)\n\n",
        p.nodes,
        v(p.start),
        v(p.end),
        trim_number(s.setup.rest_length, 9),
        p.mass,
        p.stiffness,
        p.spring_damping,
        p.air_drag,
        v(p.gravity),
        p.pinned,
        c.dt,
        schedule.total_steps,
        trim_number(schedule.total_steps as f64 * c.dt, 9),
        s.setup.omega_max,
        s.setup.omega_max * c.dt,
        s.setup.initial_energy,
        s.setup.energy_scale,
        s.setup.strain_bound,
    );
    let mut table = Table::new([
        "method",
        "cost per step",
        "steps",
        "force evals",
        "wall [ms]",
        "ns/step",
        "final E [J]",
        "E - E0 [J]",
        "max strain",
        "diverged",
    ]);
    for l in &s.lanes {
        let diverged = divergence_cell(l.divergence.as_ref(), "by t", l.failed_solves);
        table.row([
            l.method.name().to_string(),
            cost_per_step(l.method, p.newton_iterations),
            l.steps.to_string(),
            l.evals.to_string(),
            format!("{:.3}", l.wall.as_secs_f64() * 1e3),
            l.ns_per_step().map_or("—".into(), |ns| format!("{ns:.0}")),
            l.final_energy.map_or("—".into(), |e| format!("{e:.6}")),
            l.final_energy.map_or("—".into(), |e| {
                format!("{:+.3e}", e - s.setup.initial_energy)
            }),
            format!("{:.3e}", l.max_strain),
            diverged,
        ]);
    }
    out.push_str(&table.render());
    out
}
