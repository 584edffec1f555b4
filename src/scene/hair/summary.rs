//! The hair run's summary table.

use super::run::HairSummary;
use crate::scene::schedule::divergence_cell;
use crate::table::{Table, trim_number};

pub fn summary_text(s: &HairSummary) -> String {
    let c = &s.config;
    let p = &c.params;
    let mut out = format!(
        "hair: {} strands × {} nodes, segment {} m, head radius {} m ({:?}), wind {:?} m/s² ± {}%, damping {} 1/s\n\
         {} iterations, {} substeps per frame at {} Hz (dt = {:.3e} s), {} frames to t = {} s, {} threads\n\
         collision pushes nodes to R(1 + {}); invariants: penetration into R, root distance from its anchor, \
         |ℓ - ℓ0|/ℓ0\n\n",
        p.strands,
        p.nodes,
        p.segment_length,
        p.head_radius,
        p.motion,
        p.wind.to_array(),
        trim_number(100.0 * p.gust, 3),
        p.damping,
        p.iterations,
        c.substeps,
        c.rate,
        c.step_dt(),
        c.frames(),
        trim_number(c.frames() as f64 / c.rate, 6),
        s.threads,
        p.margin,
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
        "final KE [J/kg]",
        "diverged",
    ]);
    for l in &s.lanes {
        let fps = l.frames_per_second();
        table.row([
            l.method.name().to_string(),
            l.frames.to_string(),
            format!("{:.1}", l.wall.as_secs_f64() * 1e3),
            format!("{:.3}", l.wall.as_secs_f64() * 1e3 / l.frames.max(1) as f64),
            format!("{fps:.0}"),
            format!("{:.1}", fps / c.rate),
            format!("{:.2e}", l.max_stretch),
            format!("{:.1e}", l.max_penetration),
            format!("{:.1e}", l.max_root_error),
            format!("{:.4e}", l.final_kinetic_energy),
            divergence_cell(l.divergence.as_ref(), "t", 0),
        ]);
    }
    out.push_str(&table.render());
    out
}
