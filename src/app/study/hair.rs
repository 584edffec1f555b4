//! `physlab study hair`: the hair trade, stretch against cost per frame.

use crate::scene::params::SceneConfig as _;
use std::fmt::Write as _;

use super::outputs::{check_outputs, interrupted_after, write_study};
use crate::cli::HairStudyArgs;

/// `physlab study hair`: the hair scene's configurations (`study::hair::configurations`) at its
/// defaults (200 strands, tour), over `--duration` (default 4 s).
pub(super) fn hair_study(a: &HairStudyArgs) -> anyhow::Result<()> {
    use crate::scene::hair::run::HairConfig;
    let duration = a.duration.unwrap_or(crate::study::hair::DEFAULT_DURATION);
    let base = HairConfig {
        duration,
        ..HairConfig::default()
    };
    base.validate()?;
    let outputs = check_outputs(&a.out, None, &["hair-trade".to_string()])?;
    let configs = crate::study::hair::configurations(&base);
    // Minutes of work: a progress bar with an ETA, paced by each configuration's expected cost.
    let costs: Vec<f64> = configs
        .iter()
        .map(crate::study::hair::expected_cost)
        .collect();
    let mut progress = crate::app::progress::Progress::new(a.out.quiet, None);
    progress.stage("study hair", costs.iter().sum(), None);
    let mut reached = 0.0;
    let rows = crate::study::hair::hair_trade(&configs, |i| {
        reached += costs[i];
        progress.at(reached);
    });
    progress.finish();
    // Ctrl-C or SIGTERM: only the configurations that ran to the end are shown, written and
    // compared; with none, nothing is.
    let interrupted = crate::interrupt::requested();
    let complete = !rows.is_empty();
    let stopped = || interrupted_after(rows.len(), configs.len(), "configurations", complete);
    if !complete {
        return Err(stopped());
    }
    let mut out = String::new();
    writeln!(
        out,
        "hair trade: {} strands × {} nodes, tour over {duration} s at {} Hz; max stretch = largest |ℓ - ℓ0|/ℓ0 over \
         every frame; ms/frame = wall time of the step per simulation frame on {} threads (measured, not \
         deterministic)\n",
        base.params.strands,
        base.params.nodes,
        base.rate,
        rayon::current_num_threads()
    )?;
    out.push_str(&crate::report::hair::trade_table(&rows));
    writeln!(
        out,
        "\ncheapest configuration within each stretch target:\n"
    )?;
    out.push_str(&crate::report::hair::trade_cheapest_table(
        &rows,
        &[1e-2, 1e-3, 1e-6],
        a.out.wide,
    ));
    let csv = crate::report::hair::trade_csv(&rows);
    let threads = rayon::current_num_threads();
    let note = format!("wall times measured on {threads} threads; machine-dependent.");
    let diagram = crate::diagram::hair_trade(&rows, &note);
    // Provenance: the study's base scene (every configuration varies the solver settings of this
    // one).
    let scene_file = format!("[hair]\nduration = {duration:?}\n");
    let methods = crate::scene::hair::HairMethod::ALL.map(|m| m.name());
    write_study(
        &a.out,
        &outputs,
        "hair",
        (&out, &csv),
        &[diagram],
        (&scene_file, &methods),
    )?;
    if interrupted {
        return Err(stopped());
    }
    Ok(())
}
