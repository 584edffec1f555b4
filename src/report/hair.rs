//! The hair run's summary table.

use crate::format::{plural, sig, trim_number};
use crate::report::table::{Table, WIDTH, diverged_cell, figure};
use crate::scene::hair::run::{HairConfig, HairLane, HairScene};
use crate::scene::hair::{HairMethod, SPRING_STRETCH_BOUND, SPRING_WAVE_SPEEDS, Solver};
use crate::scene::harness::Run;
use crate::study::hair::{HairRow, cheapest_within};

/// The summary: the strands, head, wind and solver, the invariants, and one row per lane, its
/// table in full (`wide`) or fitted to 100 columns (the frames, said above, and the rates that
/// ms/frame gives left out).
pub fn summary_text(scene: &HairScene, run: &Run<HairLane>, wide: bool) -> String {
    let c = &scene.config;
    let p = &c.params;
    let spring = c.methods.iter().any(|m| m.is_spring());
    let springs_text = if spring { springs(c) } else { String::new() };
    let mut out = format!(
        "hair: {} strands × {} nodes, segment {} m, head radius {} m (head motion {}), wind {:?} m/s² ± {}%, damping {} 1/s\n\
         verlet solver {}, {} iterations; {}\
         {} per frame at {} Hz (dt = {:.3e} s), {} frames to t = {} s\n\
         collision pushes nodes to R(1 + {}); invariants: penetration of non-root nodes into R(1 + margin), \
         root distance from its anchor, |ℓ - ℓ0|/ℓ0; KE = kinetic energy per unit mass of hair, ½|Δx/dt|² \
         averaged over the nodes; divergence = a non-finite position or a stretch |ℓ - ℓ0|/ℓ0 > {}\n\n",
        p.strands,
        p.nodes,
        p.segment_length,
        p.head_radius,
        format!("{:?}", p.motion).to_lowercase(),
        p.wind.to_array(),
        trim_number(100.0 * p.gust, 3),
        p.damping,
        p.solver.name(),
        p.iterations,
        springs_text,
        plural(c.substeps, "substep"),
        c.rate,
        c.step_dt(),
        c.frames(),
        trim_number(c.frames() as f64 / c.rate, 6),
        p.margin,
        crate::scene::hair::run::STRETCH_BOUND,
    );
    let mut table = Table::with_short([
        ("method", "method"),
        ("frames", ""),
        ("wall [ms]", ""),
        ("ms/frame", "ms/frame"),
        ("frames/s", ""),
        ("× real time", ""),
        ("max stretch", "max stretch"),
        ("max penetration [m]", "penetr. [m]"),
        ("max root error [m]", "root err [m]"),
        ("final KE per kg [J/kg]", "KE [J/kg]"),
        ("diverged", "diverged"),
    ]);
    for (lane, s) in run.lanes.iter().zip(&run.stats) {
        let wall = s.wall.as_secs_f64();
        let fps = s.timed_ticks as f64 / wall.max(1e-12);
        let w = &lane.worst;
        table.row([
            s.name.to_string(),
            s.ticks.to_string(),
            format!("{:.1}", wall * 1e3),
            format!("{:.3}", wall * 1e3 / s.timed_ticks.max(1) as f64),
            format!("{fps:.0}"),
            sig(fps / c.rate, 3),
            figure(s, format!("{:.2e}", w.max_stretch)),
            figure(s, format!("{:.1e}", w.max_penetration)),
            figure(s, format!("{:.1e}", w.max_root_error)),
            figure(
                s,
                format!("{:.*e}", if wide { 4 } else { 2 }, w.kinetic_energy),
            ),
            diverged_cell(s, wide),
        ]);
    }
    out.push_str(&table.render_at(wide));
    out
}

/// The hair trade study's rows: configuration, largest stretch, cost per frame.
pub fn trade_table(rows: &[HairRow]) -> String {
    let mut t = Table::new([
        "method",
        "solver",
        "iters",
        "substeps",
        "k/m [1/s²]",
        "max stretch",
        "ms/frame",
    ]);
    for r in rows {
        t.row([
            r.method.name().to_string(),
            r.solver.map_or("—".into(), |s| s.name().to_string()),
            r.iterations.to_string(),
            r.substeps.to_string(),
            r.stiffness.map_or("—".into(), |k| format!("{k:.0e}")),
            r.stretch.map_or("diverged".into(), |s| format!("{s:.2e}")),
            trim_number(r.ms_per_frame, 3),
        ]);
    }
    t.render_within(WIDTH)
}

/// The cheapest configuration (by wall time per frame) within each stretch target: over all
/// rows, then for each method (and verlet's solver); fitted, a configuration by the flags its
/// `among` does not already say.
pub fn trade_cheapest_table(rows: &[HairRow], targets: &[f64], wide: bool) -> String {
    let mut kinds: Vec<(HairMethod, Option<Solver>)> = Vec::new();
    for r in rows {
        if !kinds.contains(&(r.method, r.solver)) {
            kinds.push((r.method, r.solver));
        }
    }
    let mut t = Table::with_short([
        ("max stretch ≤", "target"),
        ("among", "among"),
        ("cheapest", "cheapest"),
        ("max stretch", "stretch"),
        ("ms/frame", "ms/frame"),
    ]);
    let kind = |m: HairMethod, s: Option<Solver>| match s {
        Some(s) => format!("{} {}", m.name(), s.name()),
        None => m.name().to_string(),
    };
    for &target in targets {
        let mut line = |among: String, r: Option<&HairRow>| {
            let cheapest = |r: &HairRow| match (wide, among == "all") {
                (true, _) => r.flags(),
                (false, true) => format!("{} {}", kind(r.method, r.solver), r.settings()),
                (false, false) if r.settings().is_empty() => "defaults".into(),
                (false, false) => r.settings(),
            };
            let cells = r.map_or(["none measured".into(), "—".into(), "—".into()], |r| {
                let stretch = r.stretch.map_or(String::new(), |s| format!("{s:.2e}"));
                [cheapest(r), stretch, trim_number(r.ms_per_frame, 3)]
            });
            t.row([format!("{target:.0e}"), among].into_iter().chain(cells));
        };
        line("all".into(), cheapest_within(rows, target));
        for &(m, s) in &kinds {
            line(
                kind(m, s),
                cheapest_within(
                    rows.iter().filter(|r| (r.method, r.solver) == (m, s)),
                    target,
                ),
            );
        }
    }
    t.render_at(wide)
}

/// One CSV row per configuration of the hair trade study.
pub fn trade_csv(rows: &[HairRow]) -> String {
    use std::fmt::Write as _;
    let mut csv =
        String::from("method,solver,iterations,substeps,stiffness,max_stretch,ms_per_frame\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{:e}",
            r.method.name(),
            r.solver.map_or("", |s| s.name()),
            r.iterations,
            r.substeps,
            r.stiffness.map_or(String::new(), |k| format!("{k:e}")),
            r.stretch.map_or(String::new(), |s| format!("{s:e}")),
            r.ms_per_frame
        );
    }
    csv
}

/// The springs' stiffness and damping, semi-implicit-euler's inner steps, and the springs' wave
/// speed against the strands' speed scale, which says whether the stretch bound is stated.
fn springs(c: &HairConfig) -> String {
    let p = &c.params;
    let wave = p.segment_length * p.stiffness.sqrt();
    let v = p.speed_scale();
    let ratio = wave / v;
    let bound = if ratio >= SPRING_WAVE_SPEEDS * (1.0 - 1e-9) {
        format!("the stretch bound {SPRING_STRETCH_BOUND:e} is stated from {SPRING_WAVE_SPEEDS} ×")
    } else {
        format!(
            "below the {SPRING_WAVE_SPEEDS} × at which the stretch bound {SPRING_STRETCH_BOUND:e} \
             is stated; the stretch grows about as 1/(wave speed)"
        )
    };
    format!(
        "springs k/m = {:.3e} 1/s², kd/m = {} 1/s (semi-implicit-euler: {} inner steps per \
         substep), wave speed ℓ0·√(k/m) = {} m/s = {} × the strands' speed scale {} m/s ({bound}); ",
        p.stiffness,
        p.spring_damping,
        (c.step_dt() / p.spring_step_limit()).ceil().max(1.0),
        sig(wave, 3),
        sig(ratio, 3),
        sig(v, 3)
    )
}
