//! The hair run's summary table.

use crate::report::table::{Table, trim_number};
use crate::scene::hair::run::{HairLane, HairScene};
use crate::scene::harness::{Run, divergence_cell};

pub fn summary_text(scene: &HairScene, run: &Run<HairLane>) -> String {
    let c = &scene.config;
    let p = &c.params;
    let mut out = format!(
        "hair: {} strands × {} nodes, segment {} m, head radius {} m ({:?}), wind {:?} m/s² ± {}%, damping {} 1/s\n\
         verlet solver {}, {} iterations; springs k/m = {:.3e} 1/s², kd/m = {} 1/s (semi-implicit-euler: {} inner steps per substep); \
         {} substeps per frame at {} Hz (dt = {:.3e} s), {} frames to t = {} s, {} threads\n\
         collision pushes nodes to R(1 + {}); invariants: penetration of non-root nodes into R(1 + margin), \
         root distance from its anchor, |ℓ - ℓ0|/ℓ0; KE = kinetic energy per unit mass of hair, ½|Δx/dt|² \
         averaged over the nodes; divergence = a non-finite position or a stretch |ℓ - ℓ0|/ℓ0 > {}\n\n",
        p.strands,
        p.nodes,
        p.segment_length,
        p.head_radius,
        p.motion,
        p.wind.to_array(),
        trim_number(100.0 * p.gust, 3),
        p.damping,
        p.solver.name(),
        p.iterations,
        p.stiffness,
        p.spring_damping,
        (c.step_dt() / p.spring_step_limit()).ceil().max(1.0),
        c.substeps,
        c.rate,
        c.step_dt(),
        c.frames(),
        trim_number(c.frames() as f64 / c.rate, 6),
        scene.threads,
        p.margin,
        crate::scene::hair::run::STRETCH_BOUND,
    );
    let mut table = Table::new([
        "method",
        "frames",
        "wall [ms]",
        "ms/frame",
        "frames/s",
        "× real time",
        "max stretch",
        "max penetration [m]",
        "max root error [m]",
        "final KE per kg [J/kg]",
        "diverged",
    ]);
    for (lane, s) in run.lanes.iter().zip(&run.stats) {
        let wall = s.wall.as_secs_f64();
        let fps = s.timed_ticks as f64 / wall.max(1e-12);
        let w = &lane.worst;
        // A lane that failed its first frame has no figures (not the zeros it started from).
        let shown = |v: String| {
            if s.failed_at_once() {
                "—".to_string()
            } else {
                v
            }
        };
        table.row([
            s.name.to_string(),
            s.ticks.to_string(),
            format!("{:.1}", wall * 1e3),
            format!("{:.3}", wall * 1e3 / s.timed_ticks.max(1) as f64),
            format!("{fps:.0}"),
            format!("{:.1}", fps / c.rate),
            shown(format!("{:.2e}", w.max_stretch)),
            shown(format!("{:.1e}", w.max_penetration)),
            shown(format!("{:.1e}", w.max_root_error)),
            shown(format!("{:.4e}", w.kinetic_energy)),
            divergence_cell(s),
        ]);
    }
    out.push_str(&table.render());
    out
}
