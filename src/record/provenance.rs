//! What a recording says about itself: the configuration and build that made it, the command
//! line, how each scene's run ended, and the summaries.

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
/// `diff`) and the two recordings it compares (`diff_a`, `diff_b`); no scene file, since it
/// is no run.
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

/// The process's command line as one line of text, losslessly: arguments of plain characters
/// as they are, any other (spaces, quotes, control characters, bytes that are not UTF-8) in
/// shell ANSI-C quoting (`$'\xff\xfe.rrd'`), so that pasted into bash it gives the same bytes.
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| shell_word(std::os::unix::ffi::OsStrExt::as_bytes(a.as_os_str())))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A path as one shell word ([`shell_word`]).
pub fn shell_path(path: &std::path::Path) -> String {
    shell_word(std::os::unix::ffi::OsStrExt::as_bytes(path.as_os_str()))
}

/// One argument as a shell word that bash reads back byte for byte and a terminal shows as it
/// is: plain characters as they are, anything else in ANSI-C quoting (`$'a b'`,
/// `$'\xff.rrd'`), its unsafe characters escaped as [`escaped`] shows them. No word it makes
/// can run anything: `$(…)`, `;` and quotes stay inside the quotes.
pub fn shell_word(bytes: &[u8]) -> String {
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
                c => push_shown(&mut out, c),
            }
        }
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02x}"));
        }
    }
    out.push('\'');
    out
}

/// The words [`shell_word`] made, read back (words joined by single spaces); `None` for text it
/// cannot have made. What a recording says its command was is rebuilt from these, never
/// copied.
pub fn shell_words(line: &str) -> Option<Vec<Vec<u8>>> {
    let mut words = Vec::new();
    let mut rest = line.as_bytes();
    while !rest.is_empty() {
        let mut word = Vec::new();
        if let Some(quoted) = rest.strip_prefix(b"$'") {
            let mut i = 0;
            loop {
                match *quoted.get(i)? {
                    b'\'' => break,
                    b'\\' => {
                        let (byte, used) = match *quoted.get(i + 1)? {
                            b'n' => (b'\n', 2),
                            b't' => (b'\t', 2),
                            b'r' => (b'\r', 2),
                            b @ (b'\\' | b'\'') => (b, 2),
                            b'x' => {
                                let hex = std::str::from_utf8(quoted.get(i + 2..i + 4)?).ok()?;
                                (u8::from_str_radix(hex, 16).ok()?, 4)
                            }
                            _ => return None,
                        };
                        word.push(byte);
                        i += used;
                    }
                    b => {
                        word.push(b);
                        i += 1;
                    }
                }
            }
            rest = &quoted[i + 1..];
        } else {
            let end = rest.iter().position(|&b| b == b' ').unwrap_or(rest.len());
            word.extend_from_slice(&rest[..end]);
            rest = &rest[end..];
            if shell_word(&word) != std::str::from_utf8(&word).ok()? {
                return None;
            }
        }
        words.push(word);
        match rest {
            [] => {}
            [b' ', more @ ..] if !more.is_empty() => rest = more,
            _ => return None,
        }
    }
    Some(words)
}

/// Where the physlab recording `path`, about to be replaced, came from: "from `COMMAND` at
/// TIME", its command line escaped (the old file may be anyone's) and shortened so that the
/// line fits a terminal whatever the file holds: the program by its file name, then its words
/// up to [`MADE_BY_CHARS`], "…" for the rest (`physlab inspect` shows it whole); `None` for
/// another file.
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

/// Text from a recording as a terminal may show it: every control character (ESC, a line
/// break, a C1 code) and every bidirectional override written out (`\x1b`, `\n`,
/// `\xe2\x80\xae`), so that no recording moves the cursor, clears the screen, retitles the
/// window or starts a line of its own. Everything `inspect`, `diff` and `reproduce` print
/// passes through it (entity paths come escaped by Rerun already).
pub fn escaped(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(unsafe_char) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        push_shown(&mut out, c);
    }
    out.into()
}

/// A character a terminal acts on rather than shows, that reorders what follows it (the bidi
/// marks, embeddings, overrides and isolates, U+061C included), or that is invisible or breaks a
/// line where nothing shows it (zero-width space and joiners, BOM, line and paragraph separators).
fn unsafe_char(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061c}'
                | '\u{200b}'..='\u{200f}'
                | '\u{2028}'..='\u{202e}'
                | '\u{2066}'..='\u{2069}'
                | '\u{feff}'
        )
}

/// `c`, or its escape when it is unsafe: `\n`, `\t`, `\r`, else its UTF-8 bytes as `\xNN`
/// (what bash's `$'…'` reads back).
fn push_shown(out: &mut String, c: char) {
    match c {
        '\n' => out.push_str("\\n"),
        '\t' => out.push_str("\\t"),
        '\r' => out.push_str("\\r"),
        c if unsafe_char(c) => {
            for b in c.to_string().bytes() {
                out.push_str(&format!("\\x{b:02x}"));
            }
        }
        c => out.push(c),
    }
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
