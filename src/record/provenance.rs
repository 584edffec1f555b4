//! What a recording says about itself: the configuration and build that made it, the command
//! line, how each scene's run ended, and the summaries.

use anyhow::Context as _;

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
            .with_component::<rerun::components::Text>("methods", [methods.join(",")])
            .with_component::<rerun::components::Text>("config", [config_toml]),
    )
}

/// A difference recording's provenance: the build and command line that wrote it (`scenes` is
/// `diff`) and the two recordings it compares (`diff_a`, `diff_b`); no scene file, since it
/// is no run.
pub fn send_diff_provenance(
    rec: &rerun::RecordingStream,
    a: &std::path::Path,
    b: &std::path::Path,
) -> anyhow::Result<()> {
    let path =
        |p: &std::path::Path| shell_word(std::os::unix::ffi::OsStrExt::as_bytes(p.as_os_str()));
    send_properties(
        rec,
        build_properties("diff")
            .with_component::<rerun::components::Text>("diff_a", [path(a)])
            .with_component::<rerun::components::Text>("diff_b", [path(b)]),
    )
}

/// What every physlab recording says of itself: what it holds (`scenes`), physlab's version and
/// git commit, the Rerun SDK's version and the command line.
fn build_properties(scenes: &str) -> rerun::AnyValues {
    rerun::AnyValues::default()
        .with_component::<rerun::components::Text>("scenes", [scenes])
        .with_component::<rerun::components::Text>("physlab_version", [env!("CARGO_PKG_VERSION")])
        .with_component::<rerun::components::Text>("git_commit", [GIT_COMMIT])
        .with_component::<rerun::components::Text>("rerun_sdk_version", [RERUN_SDK_VERSION])
        .with_component::<rerun::components::Text>("command_line", [command_line()])
}

fn send_properties(rec: &rerun::RecordingStream, values: rerun::AnyValues) -> anyhow::Result<()> {
    rec.send_property("physlab", &values)?;
    // Written out now, not with the first batch of data, so that even a run cut short carries it.
    rec.flush_blocking()
        .context("cannot write the recording's properties")?;
    Ok(())
}

/// The process's command line as one line of text, losslessly: arguments of plain characters
/// as they are, any other (spaces, quotes, control characters, bytes that are not UTF-8) in
/// shell ANSI-C quoting (`$'\xff\xfe.rrd'`), so that pasted into bash it gives the same bytes.
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| shell_word(std::os::unix::ffi::OsStrExt::as_bytes(a.as_os_str())))
        .collect::<Vec<_>>()
        .join(" ")
}

fn shell_word(bytes: &[u8]) -> String {
    let plain = |c: char| c.is_alphanumeric() || "-_./=:,+@%^".contains(c);
    if let Ok(s) = std::str::from_utf8(bytes)
        && !s.is_empty()
        && s.chars().all(plain)
    {
        return s.to_string();
    }
    let mut out = String::from("$'");
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            match c {
                '\\' => out.push_str("\\\\"),
                '\'' => out.push_str("\\'"),
                '\n' => out.push_str("\\n"),
                '\t' => out.push_str("\\t"),
                c if c.is_control() => {
                    for b in c.to_string().bytes() {
                        out.push_str(&format!("\\x{b:02x}"));
                    }
                }
                c => out.push(c),
            }
        }
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02x}"));
        }
    }
    out.push('\'');
    out
}

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
            .with_component::<rerun::components::Text>(key(s, "status")?, [e.status])
            .with_component::<rerun::components::Text>(
                key(s, "last_tick")?,
                [e.last_tick.to_string()],
            )
            .with_component::<rerun::components::Text>(
                key(s, "end_time")?,
                [format!("{:?}", e.end_time)],
            )
            .with_component::<rerun::components::Text>(key(s, "ended")?, [e.text.as_str()]);
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

#[cfg(test)]
mod command_line_tests {
    use super::shell_word;

    /// Every word comes back byte for byte through bash's own reading of the quoting.
    #[test]
    fn words_are_quoted_losslessly_for_bash() {
        let words: [&[u8]; 9] = [
            b"pendulum",
            b"--theta0=-30",
            b"\xff\xfe.rrd",
            b"a b",
            b"it's",
            b"back\\slash\n\ttab",
            b"",
            "\u{e9}t\u{e9} \u{7f}\u{85}".as_bytes(),
            b"$HOME;`x`\"y\"",
        ];
        for word in words {
            let quoted = shell_word(word);
            assert!(!quoted.contains('\n'), "{quoted}");
            let out = std::process::Command::new("bash")
                .arg("-c")
                .arg(format!("printf %s {quoted}"))
                .env("LC_ALL", "C")
                .output()
                .expect("bash runs");
            assert_eq!(out.stdout, word, "{quoted}");
        }
    }
}
