//! What a recording says about itself: the configuration and build that made it, the command
//! line, how each scene's run ended, and the summaries.

use crate::shell::{command_line, escaped, shell_path};
use anyhow::Context as _;
use rerun::components::Text;

/// Sends the run's provenance as recording properties (`/__properties/physlab`): the scene file
/// that reproduces it, physlab's version and git commit, the Rerun SDK's version, the command
/// line and the methods.
pub fn send_provenance(
    rec: &rerun::RecordingStream,
    scenes: &str,
    config_toml: &str,
    methods: &[&str],
) -> anyhow::Result<()> {
    send_properties(
        rec,
        build_properties(scenes)
            .with_component::<Text>("methods", [methods.join(",")])
            .with_component::<Text>("config", [config_toml]),
    )
}

/// A difference recording's provenance: the build and command line that wrote it (`scenes` is
/// `diff`) and the two recordings it compares (`diff_a`, `diff_b`).
pub fn send_diff_provenance(
    rec: &rerun::RecordingStream,
    a: &std::path::Path,
    b: &std::path::Path,
) -> anyhow::Result<()> {
    send_properties(
        rec,
        build_properties("diff")
            .with_component::<Text>("diff_a", [shell_path(a)])
            .with_component::<Text>("diff_b", [shell_path(b)]),
    )
}

/// What every physlab recording says of itself: what it holds (`scenes`), physlab's version and
/// git commit, the Rerun SDK's version and the command line.
fn build_properties(scenes: &str) -> rerun::AnyValues {
    rerun::AnyValues::default()
        .with_component::<Text>("scenes", [scenes])
        .with_component::<Text>("physlab_version", [env!("CARGO_PKG_VERSION")])
        .with_component::<Text>("git_commit", [GIT_COMMIT])
        .with_component::<Text>("rerun_sdk_version", [RERUN_SDK_VERSION])
        .with_component::<Text>("command_line", [command_line()])
}

fn send_properties(rec: &rerun::RecordingStream, values: rerun::AnyValues) -> anyhow::Result<()> {
    rec.send_property("physlab", &values)?;
    // Written out now, not with the first batch of data, so that even a run cut short carries it.
    rec.flush_blocking()
        .context("cannot write the recording's properties")?;
    Ok(())
}

/// Where the physlab recording `path`, about to be replaced, came from: "from `COMMAND` at
/// TIME", its command line escaped (the old file may be anyone's) and cut after
/// [`MADE_BY_CHARS`] so that the line fits a terminal; `None` for another file.
pub fn made_by(path: &std::path::Path) -> Option<String> {
    let (command, nanos) = crate::rrd::inspect::made_by(path)?;
    let at = crate::format::utc((nanos / 1_000_000_000) as i64);
    let command = escaped(&command);
    let mut words = command.split(' ');
    let program = words.next().unwrap_or_default();
    let mut shown = program.rsplit('/').next().unwrap_or(program).to_string();
    for word in words {
        if shown.chars().count() + 1 + word.chars().count() > MADE_BY_CHARS {
            shown.push_str(" …");
            break;
        }
        shown = format!("{shown} {word}");
    }
    Some(format!("from `{shown}` at {at}"))
}

/// The most of an old recording's command line the "replaced" line shows.
const MADE_BY_CHARS: usize = 40;

/// Where one scene of a recording ended (`physlab inspect` and `reproduce` read it back).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneEnd {
    pub scene: &'static str,
    /// `complete`, `interrupted` or `not run`.
    pub status: &'static str,
    /// The last tick reached, and its simulated time [s].
    pub last_tick: u64,
    pub end_time: f64,
    /// In words: where and why it ended, which lanes diverged when.
    pub text: String,
}

/// Sends where each scene ended as the `physlab_run` property: `<scene>_status`,
/// `<scene>_last_tick`, `<scene>_end_time` (s, shortest exact decimal) and `<scene>_ended` (text).
pub fn send_run_status(rec: &rerun::RecordingStream, ends: &[SceneEnd]) -> anyhow::Result<()> {
    let mut values = rerun::AnyValues::default();
    let key = |s: &str, k: &str| rerun::ComponentIdentifier::try_new(format!("{s}_{k}"));
    for e in ends {
        let s = e.scene;
        values = values
            .with_component::<Text>(key(s, "status")?, [e.status])
            .with_component::<Text>(key(s, "last_tick")?, [e.last_tick.to_string()])
            .with_component::<Text>(key(s, "end_time")?, [format!("{:?}", e.end_time)])
            .with_component::<Text>(key(s, "ended")?, [e.text.as_str()]);
    }
    rec.send_property("physlab_run", &values)?;
    Ok(())
}

/// The summaries' columns that hold wall-clock measurements.
const WALL_CLOCK_COLUMNS: [&str; 5] = [
    "wall [ms]",
    "ns/step",
    "ms/frame",
    "frames/s",
    "× real time",
];

/// The scene's summary (the table printed at the end of a run) as a markdown document at
/// `<scene>/summary`, with where the run ended, so that the recording holds its own results.
/// Without `timings` its wall-clock columns are left out, as every wall-clock value is: the
/// recording then depends on its inputs only, and `reproduce` checks the summary too.
pub fn log_summary(
    rec: &rerun::RecordingStream,
    scene: &str,
    summary: &str,
    ended: &str,
    timings: bool,
) -> anyhow::Result<()> {
    rec.log_static(
        format!("{scene}/summary"),
        &rerun::TextDocument::from_markdown(summary_markdown(scene, summary, ended, timings)),
    )?;
    Ok(())
}

/// A summary as markdown: its header lines as paragraphs (a plain line break would join them),
/// its tables (already in pipe syntax) as they are, less the wall-clock columns unless `timings`.
pub fn summary_markdown(scene: &str, summary: &str, ended: &str, timings: bool) -> String {
    let mut out = format!("# {scene}: summary\n\n**Run {ended}.**\n\n");
    let mut dropped: Vec<usize> = Vec::new();
    let mut in_table = false;
    for line in summary.lines() {
        let row = line.trim();
        if !row.starts_with('|') {
            in_table = false;
            out.push_str(line);
            out.push_str("\n\n");
            continue;
        }
        let cells: Vec<&str> = row.trim_matches('|').split('|').map(str::trim).collect();
        if !in_table {
            in_table = true;
            dropped = (0..cells.len())
                .filter(|&i| !timings && WALL_CLOCK_COLUMNS.contains(&cells[i]))
                .collect();
        }
        let kept: Vec<&str> = cells
            .iter()
            .enumerate()
            .filter(|(i, _)| !dropped.contains(i))
            .map(|(_, c)| *c)
            .collect();
        out.push_str(&format!("| {} |\n", kept.join(" | ")));
    }
    out
}

/// The commit physlab was built from (`-dirty` with uncommitted changes), from build.rs.
pub const GIT_COMMIT: &str = env!("PHYSLAB_GIT_COMMIT");

/// The Rerun SDK this build links (pinned in Cargo.toml).
pub const RERUN_SDK_VERSION: &str = "0.36.3";
