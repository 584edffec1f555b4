//! The rope run's summary table, as printed on stdout.

use crate::format::{plural, sig, trim_number};
use crate::integrate::{EvalsPerStep, Method};
use crate::report::table::{OWN_STEPS_NOTE, Table, diverged_cell, figure, steps_cell};
use crate::scene::harness::{Run, Scene as _};
use crate::scene::rope::run::{ENERGY_GAIN_BOUND, RopeLane, RopeScene};

/// What one step of `method` costs on an N-node rope, in words.
pub fn cost_per_step(method: Method, newton_iterations: u32) -> String {
    match method.info().evals_per_step {
        EvalsPerStep::Fixed(k) => format!("{} O(N)", plural(k, "force eval")),
        EvalsPerStep::NewtonIterations => {
            format!("≤{newton_iterations} × (force + Jacobian + block-tridiagonal solve) O(N)")
        }
        EvalsPerStep::Adaptive(e) => format!(
            "adaptive: {} force evals O(N) per substep tried",
            e.accepted
        ),
    }
}

/// A vector as "(x, y, z)" with at most six decimals each.
pub fn vector_text(d: glam::DVec3) -> String {
    let [x, y, z] = d.to_array().map(|c| trim_number(c, 6));
    format!("({x}, {y}, {z})")
}

/// The linearised rope's fastest rates against the step, which decide explicit stability.
pub fn rates_text(scene: &RopeScene) -> String {
    let (flag, dt) = crate::scene::params::fixed_step(scene.config.dt, &scene.config.options);
    let name = flag.trim_start_matches("--");
    format!(
        "fastest rates: springs ω_max {} {:.4} rad/s, so ω_max·{name} = {:.4} (undamped, semi-implicit \
         Euler and Verlet need < 2, RK4 < 2.83), damping c_max ≤ (4kd + ka)/m = {} 1/s, so \
         c_max·{name} ≤ {} (explicit methods need it below 2 too)",
        if scene.omega_max_is_exact {
            "(chain pinned at node 0) ="
        } else {
            "≤ 2√(k/m) ="
        },
        scene.omega_max,
        scene.omega_max * dt,
        sig(scene.damping_rate_max, 5),
        sig(scene.damping_rate_max * dt, 4),
    )
}

/// The forces of this run, in words: springs always, then the damping, drag and gravity that
/// are on (an undamped rope says so).
pub fn forces_text(p: &crate::scene::rope::RopeParams) -> String {
    let mut forces = vec!["Hooke springs between neighbours".to_string()];
    if p.spring_damping != 0.0 {
        forces.push(format!(
            "spring damping kd = {} N·s/m along each spring",
            p.spring_damping
        ));
    }
    if p.air_drag != 0.0 {
        forces.push(format!("air drag ka = {} N·s/m", p.air_drag));
    }
    if !p.velocity_dependent() {
        forces.push("undamped (kd = ka = 0: no dissipative force)".to_string());
    }
    if p.gravity != glam::DVec3::ZERO {
        forces.push("gravity".to_string());
    }
    forces.join(", ")
}

/// E0 as a figure that means something: its value, or 0 when it is below a 10⁻¹² of the scale,
/// the round-off of summing the start's energies (the default rope starts straight at the
/// height of gravity's zero, where E0 is 0 J exactly but sums to ~1e-28 J).
pub fn e0_text(scene: &RopeScene) -> String {
    if scene.initial_energy.abs() <= 1e-12 * scene.energy_scale {
        "0".to_string()
    } else {
        sig(scene.initial_energy, 7)
    }
}

/// What the energy columns say, one sentence each (the summary's and `--help`'s).
pub const ENERGY_COLUMNS: &str = "E - E0: the energy's change since the start, the physical loss \
     to damping and drag included; W: the work the damping and drag dissipated, integrated with \
     the state by each method's own stages; E + W - E0: the energy balance, zero for the exact \
     motion, so it is the method's own energy error whatever the damping";

/// A nonzero gravity with no z component is horizontal (z is up in every scene): said, so that a
/// y-up vector such as 0,-9.81,0 is not taken silently.
fn sideways_note(g: glam::DVec3) -> &'static str {
    if g.z == 0.0 && g != glam::DVec3::ZERO {
        " (horizontal: z is up)"
    } else {
        ""
    }
}

/// The summary: the rope, its forces, rates and energy, and one row per lane, its table in full
/// (`wide`) or fitted to 100 columns (W, the final E and the cost in words left out: the
/// balance, E - E0 and the evaluations say them).
pub fn summary_text(scene: &RopeScene, run: &Run<RopeLane>, wide: bool) -> String {
    let c = &scene.config;
    let p = &c.params;
    let schedule = scene.schedule();
    let mut out = format!(
        "rope: {} nodes from {} to {} m, rest length {} m, mass {} kg/node, ks = {} N/m, kd = {} N·s/m, \
         ka = {} N·s/m, g = {} m/s²{}, pinned {:?}\n\
         forces: {}\n\
         dt = {} s{}, {} steps to t = {} s; {}\n\
         E0 = {} J (gravity's zero at the origin), energy scale {} J; divergence = non-finite \
         state, strain > {:.3}, or an energy gain > {ENERGY_GAIN_BOUND} × the scale, checked \
         after every step\n{ENERGY_COLUMNS}\n\
         ns/step: wall time of the stepping and its O(N) energy and strain check \
         (`cargo bench --bench rope_step` times the stepping alone)\n\n",
        p.nodes,
        vector_text(p.start),
        vector_text(p.end),
        trim_number(scene.rope.rest(), 9),
        p.mass,
        p.stiffness,
        p.spring_damping,
        p.air_drag,
        vector_text(p.gravity),
        sideways_note(p.gravity),
        p.pinned,
        forces_text(p),
        c.dt,
        crate::scene::params::own_step_text(&c.options),
        schedule.total,
        trim_number(schedule.end_time(), 9),
        rates_text(scene),
        e0_text(scene),
        sig(scene.energy_scale, 5),
        scene.strain_bound,
    );
    let mut table = Table::with_short([
        ("method", "method"),
        ("cost per step", ""),
        ("steps", "steps"),
        ("force evals", "evals"),
        ("wall [ms]", ""),
        ("ns/step", "ns/step"),
        ("final E [J]", ""),
        ("E - E0 [J]", "E-E0 [J]"),
        ("W [J]", ""),
        ("E + W - E0 [J]", "E+W-E0 [J]"),
        ("max strain", "max strain"),
        ("diverged", "diverged"),
    ]);
    // Digits: four in full, two fitted.
    let e = if wide { 3 } else { 1 };
    for (lane, s) in run.lanes.iter().zip(&run.stats) {
        table.row([
            s.name.to_string(),
            cost_per_step(lane.method, p.newton_iterations),
            steps_cell(s, wide),
            s.counts.evals.to_string(),
            format!("{:.3}", s.wall.as_secs_f64() * 1e3),
            s.ns_per_step().map_or("—".into(), |ns| format!("{ns:.0}")),
            figure(s, sig(lane.final_energy, 7)),
            figure(
                s,
                format!("{:+.e$e}", lane.final_energy - scene.initial_energy),
            ),
            figure(s, format!("{:.e$e}", lane.final_work)),
            figure(
                s,
                format!("{:+.e$e}", lane.balance_error(scene.initial_energy)),
            ),
            figure(s, format!("{:.e$e}", lane.max_strain)),
            diverged_cell(s, wide),
        ]);
    }
    out.push_str(&table.render_at(wide));
    if run.stats.iter().any(|s| s.counts.own_steps.is_some()) {
        out.push_str(OWN_STEPS_NOTE);
    }
    out
}
