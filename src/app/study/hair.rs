//! `physlab study hair`: the hair trade, stretch against cost per frame.

use crate::report::hair as report;
use crate::scene::params::SceneConfig as _;
use crate::study::hair;

use super::outputs::{check_outputs, interrupted_after, write_study};
use crate::cli::HairStudyArgs;

/// `physlab study hair`: the hair scene's configurations at its defaults, over `--duration`.
pub(super) fn hair_study(a: &HairStudyArgs) -> anyhow::Result<()> {
    use crate::scene::hair::run::HairConfig;
    let duration = a.duration.unwrap_or(hair::DEFAULT_DURATION);
    let base = HairConfig {
        duration,
        ..HairConfig::default()
    };
    base.validate()?;
    let outputs = check_outputs(&a.out, None, &["hair-trade".to_string()])?;
    let configs = hair::configurations(&base);
    // Minutes of work: a progress bar with an ETA, paced by each configuration's expected cost.
    let costs: Vec<f64> = (configs.iter()).map(hair::expected_cost).collect();
    let mut progress = crate::app::progress::Progress::new(a.out.quiet, None);
    progress.stage("study hair", costs.iter().sum(), None);
    let mut reached = 0.0;
    let rows = hair::hair_trade(&configs, |i| {
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
    let threads = rayon::current_num_threads();
    let mut out = format!(
        "hair trade: {} strands × {} nodes, tour over {duration} s at {} Hz; max stretch = largest |ℓ - ℓ0|/ℓ0 over \
         every frame; ms/frame = wall time of the step per simulation frame on {threads} threads (measured, not \
         deterministic)\n\n",
        base.params.strands, base.params.nodes, base.rate,
    );
    out.push_str(&report::trade_table(&rows));
    out.push_str("\ncheapest configuration within each stretch target:\n\n");
    out.push_str(&report::trade_cheapest_table(
        &rows,
        &[1e-2, 1e-3, 1e-6],
        a.out.wide,
    ));
    let csv = report::trade_csv(&rows);
    let note = format!("wall times measured on {threads} threads; machine-dependent.");
    let diagram = crate::diagram::hair_trade(&rows, &note);
    // Provenance: the base scene, whose solver settings every configuration varies.
    let scene_file = format!("[hair]\nduration = {duration:?}\n");
    let methods = crate::scene::hair::HairMethod::ALL.map(|m| m.name());
    let texts = (out.as_str(), csv.as_str());
    write_study(
        &a.out,
        &outputs,
        "hair",
        texts,
        &[diagram],
        (&scene_file, &methods),
    )?;
    if interrupted {
        return Err(stopped());
    }
    Ok(())
}
