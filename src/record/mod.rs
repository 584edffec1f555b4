//! The only place that calls Rerun: entity paths, styles, blueprints, properties, and writing
//! a recording file safely.

pub mod compare;
pub mod diff;
mod framing;
pub mod hair;
pub mod inspect;
pub mod pendulum;
pub mod read;
pub mod rope;
pub mod scene;
pub mod study;

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use rerun::blueprint::components::{Corner2D, PanelState};
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial3DView, Tabs,
    TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};

pub mod layout;
pub use layout::{Framing, Layout, ViewProperties};

/// One colour per method (the palette is shared with the diagrams: `crate::palette`).
pub use crate::palette::method_color;

/// One plot per quantity, `/<scene>/plots/<name>/*`, every method in each, its legend placed by
/// [`legend_corner`].
fn plot_views(
    scene: &str,
    plots: &[(&str, &str)],
    in_all: bool,
    props: &mut ViewProperties,
) -> Vec<ContainerLike> {
    plots
        .iter()
        .map(|(name, title)| {
            let view = TimeSeriesView::new(*title).with_origin(format!("/{scene}/plots/{name}"));
            props.legend(view, legend_corner(scene, name, in_all))
        })
        .collect()
}

/// Where a plot's legend goes: a corner its curves leave empty in the default run (read from
/// viewer screenshots at 1600×1000), or `None` (hidden) where every corner holds data or the
/// legend (about 20 px per method) is taller than the free space, as in `all`'s short plots of
/// seven or more lanes and the pendulum's nine-lane plots. The 3D views label every method in
/// the same colour.
fn legend_corner(scene: &str, plot: &str, in_all: bool) -> Option<Corner2D> {
    match (scene, plot, in_all) {
        // Energy and strain rise where midpoint and trapezoid diverge (≈ 7.5 s) and stop there.
        ("rope", "energy" | "max_strain", false) => Some(Corner2D::RightTop),
        // After the first second every curve sits above 10⁰ J.
        ("rope", "log10_energy_change", false) => Some(Corner2D::RightBottom),
        // Two lanes; after the first frames no curve comes down to the bottom right.
        ("hair", "max_penetration", _) => Some(Corner2D::RightBottom),
        // Kinetic energy decays towards 0 after the head stops.
        ("hair", "specific_kinetic_energy", false) => Some(Corner2D::RightTop),
        _ => None,
    }
}

/// A scene's plots, and the wall-clock cost plot when timings are recorded.
pub fn plots_shown(
    plots: &[(&'static str, &'static str)],
    timings: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut shown = plots.to_vec();
    if timings {
        shown.push(scene::FRAME_COST);
    }
    shown
}

/// The scene's plots stacked.
pub fn plot_column(scene: &str, plots: &[(&str, &str)], props: &mut ViewProperties) -> Vertical {
    Vertical::new(plot_views(scene, plots, false, props))
}

/// What the layouts need of a scene: its views alone, and its column in `physlab all`.
pub struct SceneViews {
    pub name: &'static str,
    /// Its plots: entity name and title.
    pub plots: &'static [(&'static str, &'static str)],
    /// Subtrees its 3D view leaves out in `all` (drawn in views of their own when alone).
    pub exclude_in_all: &'static [&'static str],
    /// Its layout when it runs alone, its 3D view framed on the given box.
    pub blueprint: fn(bool, Framing, &mut ViewProperties) -> Blueprint,
}

/// A single scene's layout, its 3D view framed on `framing`.
pub fn scene_layout(scene: &SceneViews, timings: bool, framing: Framing) -> Layout {
    let mut props = ViewProperties::default();
    let blueprint = (scene.blueprint)(timings, framing, &mut props);
    props.layout(blueprint)
}

/// The plots `physlab all` shows (fewer and wider than a single scene's, so that each stays
/// readable at 1600×1000); the recording holds every series all the same.
const ALL_PLOTS: [&str; 7] = [
    "theta",
    "log10_theta_error",
    "log10_energy_error",
    "log10_energy_change",
    "max_strain",
    "log10_max_stretch",
    "max_penetration",
];

/// `physlab all`: the scenes side by side, each 3D view above its plots and its event log,
/// each 3D view framed on its scene's framing.
pub fn all_layout(timings: bool, scenes: &[(&SceneViews, Framing)]) -> Layout {
    let mut props = ViewProperties::default();
    let mut column = |views: &SceneViews, framing: Framing| -> ContainerLike {
        let scene = views.name;
        let shown: Vec<(&str, &str)> = plots_shown(views.plots, timings)
            .into_iter()
            .filter(|(name, _)| ALL_PLOTS.contains(name) || *name == scene::FRAME_COST.0)
            .collect();
        let view = scene_view(scene, scene, views.exclude_in_all);
        let view = props.eye(view, framing, layout::ALL_VIEW_ASPECT);
        Vertical::new([
            view,
            Vertical::new(plot_views(scene, &shown, true, &mut props)).into(),
            Tabs::new([
                TextLogView::new(format!("{scene} events"))
                    .with_origin(format!("/{scene}/events"))
                    .into(),
                summary_view(scene).into(),
            ])
            .into(),
        ])
        .with_row_shares([3.0, 4.0, 1.0])
        .into()
    };
    let columns: Vec<ContainerLike> = scenes.iter().map(|(v, f)| column(v, *f)).collect();
    let blueprint = only_these_views(Blueprint::new(Horizontal::new(columns)));
    props.layout(blueprint)
}

/// The scene's 3D view: everything under `/<scene>` except its plots, events, about text,
/// summary and the given subtrees.
pub fn scene_view(scene: &str, title: &str, exclude: &[&str]) -> Spatial3DView {
    let mut contents = vec![
        "+ $origin/**".to_string(),
        "- $origin/plots/**".to_string(),
        "- $origin/events".to_string(),
        "- $origin/about".to_string(),
        "- $origin/summary".to_string(),
    ];
    contents.extend(exclude.iter().map(|e| format!("- $origin/{e}")));
    Spatial3DView::new(title)
        .with_origin(format!("/{scene}"))
        .with_contents(contents)
}

/// The run description (`/<scene>/about`) with the summary (`/<scene>/summary`) in a tab beside
/// it, and the event log (`/<scene>/events`).
pub fn about_and_events(scene: &str) -> [ContainerLike; 2] {
    [
        Tabs::new([
            TextDocumentView::new("about this run")
                .with_origin(format!("/{scene}/about"))
                .into(),
            summary_view(scene).into(),
        ])
        .into(),
        TextLogView::new("events")
            .with_origin(format!("/{scene}/events"))
            .into(),
    ]
}

/// The scene's summary table (`/<scene>/summary`), written when the run ends.
pub fn summary_view(scene: &str) -> TextDocumentView {
    TextDocumentView::new(format!("{scene} summary")).with_origin(format!("/{scene}/summary"))
}

/// A single scene's layout: `left` beside the plots, nothing else shown, `sim_time` selected.
pub fn scene_blueprint(left: Vertical, plots: Vertical) -> Blueprint {
    only_these_views(Blueprint::new(
        Horizontal::new([left.into(), plots.into()]).with_column_shares([1.0, 1.0]),
    ))
}

/// No views but the given ones, the panels collapsed, `sim_time` selected.
fn only_these_views(blueprint: Blueprint) -> Blueprint {
    blueprint
        .with_auto_views(false)
        .with_time_panel(
            TimePanel::new()
                .with_timeline("sim_time")
                .with_state(PanelState::Collapsed),
        )
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
}

/// The legend name and colour of one method's series in a plot (static, logged once).
pub fn log_series_style(
    rec: &rerun::RecordingStream,
    entity: String,
    name: &str,
) -> anyhow::Result<()> {
    rec.log_static(
        entity,
        &rerun::SeriesLines::new()
            .with_names([name])
            .with_colors([method_color(name)])
            .with_widths([1.5]),
    )?;
    Ok(())
}

/// A faint floor outline through four corners (static): the ground the slots stand on.
pub fn log_stage(
    rec: &rerun::RecordingStream,
    entity: &str,
    corners: [[f32; 3]; 4],
) -> anyhow::Result<()> {
    let mut outline = corners.to_vec();
    outline.push(corners[0]);
    rec.log_static(
        entity,
        &rerun::LineStrips3D::new([outline])
            .with_colors([[90, 90, 90]])
            .with_radii([rerun::Radius::new_ui_points(1.0)]),
    )?;
    Ok(())
}

/// Grid cells (column, row counted from the bottom) for `n` side-by-side lanes, in rows of at
/// most four in reading order from the top left. A compact block rather than one long row, so
/// a 3D view frames every lane large.
pub fn slot_cells(n: usize) -> Vec<(usize, usize)> {
    // Near-square (8 lanes: 3 × 3 less one), so that the labels of neighbouring slots do not
    // overlap in `all`'s narrow views.
    let columns = (1..=4).find(|c| c * c >= n).unwrap_or(4);
    let rows = n.div_ceil(columns);
    (0..n)
        .map(|i| (i % columns, rows - 1 - i / columns))
        .collect()
}

/// Where a recording goes: a file (written beside its target and renamed when complete), a
/// running viewer, a viewer started for it, or any combination.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Destinations {
    pub file: Option<PathBuf>,
    /// A viewer's gRPC proxy URL, e.g. rerun+http://127.0.0.1:9876/proxy.
    pub connect: Option<String>,
    /// Start `rerun` from PATH and stream to it.
    pub spawn: bool,
    /// Write the recording to standard output (`-o -`), e.g. piped into `rerun -`.
    pub stdout: bool,
}

impl Destinations {
    /// `-o PATH`, where `-` means standard output.
    pub fn output(path: &Path) -> Self {
        if path.as_os_str() == "-" {
            Destinations {
                stdout: true,
                ..Default::default()
            }
        } else {
            Destinations {
                file: Some(path.to_path_buf()),
                ..Default::default()
            }
        }
    }

    /// The recording as a checked output (`crate::output`): a file or standard output.
    pub fn written(&self) -> anyhow::Result<Option<crate::output::Output>> {
        use crate::output::{Dash, check};
        match (&self.file, self.stdout) {
            (Some(path), _) => check("-o", path, Dash::Binary).map(Some),
            (None, true) => check("-o", Path::new("-"), Dash::Binary).map(Some),
            (None, false) => Ok(None),
        }
    }
}

/// Checks the destinations before anything is simulated: the file can be written
/// (`crate::output::check`), the viewer URL parses, `rerun` is on PATH for --spawn.
pub fn check_destinations(d: &Destinations) -> anyhow::Result<()> {
    d.written()?;
    if let Some(url) = &d.connect {
        parse_proxy_url(url)?;
    }
    if d.spawn && find_on_path("rerun").is_none() {
        anyhow::bail!(
            "--spawn: no `rerun` executable on PATH; install the viewer with `pip install rerun-sdk==0.36.3`, \
             or open the file later"
        );
    }
    Ok(())
}

fn parse_proxy_url(url: &str) -> anyhow::Result<rerun::external::re_uri::ProxyUri> {
    url.parse().map_err(|e| {
        crate::error::Error::Usage(format!(
            "--connect {url}: not a viewer URL ({e}); expected e.g. rerun+http://127.0.0.1:9876/proxy"
        ))
        .into()
    })
}

/// Whether something accepts connections at the viewer's address (within a second).
fn viewer_listens(uri: &rerun::external::re_uri::ProxyUri) -> bool {
    use std::net::ToSocketAddrs as _;
    let origin = &uri.origin;
    let Ok(addrs) = (origin.host.to_string(), origin.port).to_socket_addrs() else {
        return false;
    };
    addrs.into_iter().any(|a| {
        std::net::TcpStream::connect_timeout(&a, std::time::Duration::from_secs(1)).is_ok()
    })
}

/// The first executable called `name` on PATH.
pub fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| {
            use std::os::unix::fs::PermissionsExt as _;
            p.metadata()
                .map(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
                .unwrap_or(false)
        })
}

/// How rows logged one at a time become chunks: per entity, a chunk every 1024 rows (or
/// [`CHUNK_BYTES`], see below), never on a clock, so the chunks depend only on what was logged
/// (Rerun's default 200 ms clock cuts identical runs differently). The rows still pending when a
/// run ends are turned into chunks then, on Rerun's batcher thread, one row at a time: 1024 rows
/// per entity keeps that under a few tenths of a second, so a Ctrl-C is answered within 1 s
/// (4096, the size `rerun rrd optimize` compacts to, took over a second for the pendulum).
///
/// Rerun's byte count of pending rows varies between identical runs (two `physlab all` runs cut
/// hair's strands after 11 and after 10 rows), so the batcher counts rows only, and the scene
/// recorder flushes after every [`CHUNK_BYTES`] of its largest 3D entity (hair strands, rope
/// nodes), counted by itself.
pub const BATCHING: rerun::log::ChunkBatcherConfig = rerun::log::ChunkBatcherConfig {
    flush_tick: std::time::Duration::MAX,
    flush_num_bytes: u64::MAX,
    flush_num_rows: 1024,
    ..rerun::log::ChunkBatcherConfig::DEFAULT
};

/// The chunk size `rerun rrd optimize` compacts to (`ChunkStoreConfig::DEFAULT`: 384 KiB).
pub const CHUNK_BYTES: usize = 12 * 8 * 4096;

/// A recording being written. A file goes through `crate::output` (a hidden file beside its
/// target, renamed into place when complete); [`Recording::commit`] finalises it (footer
/// written, fsynced) and renames it into place, and dropping it uncommitted removes the hidden
/// file, so a failed run never leaves a partial file or touches an earlier recording. A write
/// error (a full disk) stops the run at its next check, as a signal would, and `commit` reports it.
pub struct Recording {
    rec: Option<rerun::RecordingStream>,
    file: Option<std::sync::Arc<sink::Shared>>,
    /// Where the file goes, for the size reported.
    target: Option<PathBuf>,
}

impl Recording {
    /// Starts a recording with `blueprint` as its active layout, under its own application id
    /// (`physlab-pendulum`, `physlab-all`, `physlab-study`...: the viewer keys blueprints by
    /// application id, so one scene's layout never applies to another's recording).
    ///
    /// No wall-clock data: the `log_time` timeline and the start-time property are off, and
    /// chunks are cut by [`BATCHING`] (rows and bytes per entity), not by the batcher's 200 ms
    /// clock, so two runs of the same inputs write the same chunks (row ids, recording id and
    /// chunk ids, which Rerun draws from the clock and at random, aside). Streaming to a viewer
    /// (--connect, --spawn) keeps Rerun's clock-driven batching, so the viewer sees data live.
    pub fn create(
        d: &Destinations,
        application_id: &'static str,
        recording_name: &str,
        layout: impl Into<Layout>,
    ) -> anyhow::Result<Self> {
        let layout = layout.into();
        check_destinations(d)?;
        let mut sinks: Vec<Box<dyn rerun::sink::LogSink>> = Vec::new();
        let mut file = None;
        let mut target = None;
        if let Some(output) = d.written()? {
            let shared = std::sync::Arc::new(sink::Shared::new(output.create()?)?);
            sinks.push(Box::new(sink::EncodedSink(shared.clone())));
            file = Some(shared);
            target = output.target;
        }
        if d.spawn {
            rerun::spawn(&rerun::SpawnOptions::default())
                .context("--spawn: cannot start the Rerun viewer")?;
            let url = format!(
                "rerun+http://127.0.0.1:{}/proxy",
                rerun::DEFAULT_SERVER_PORT
            );
            sinks.push(Box::new(rerun::sink::GrpcSink::new(parse_proxy_url(&url)?)));
        }
        if let Some(url) = &d.connect {
            let uri = parse_proxy_url(url)?;
            if viewer_listens(&uri) {
                sinks.push(Box::new(rerun::sink::GrpcSink::new(uri)));
            } else if d.file.is_some() {
                // A missing viewer must not cost the user the recording.
                eprintln!(
                    "warning: --connect {url}: no viewer answers there; writing the file only"
                );
            } else {
                anyhow::bail!(
                    "--connect {url}: no viewer answers there, and --no-save leaves nothing to write \
                     (start `rerun`, or drop --no-save)"
                );
            }
        }
        let mut builder = rerun::RecordingStreamBuilder::new(application_id)
            .enabled(true) // the recording is the product: ignore RERUN=off
            .send_properties(false);
        if d.connect.is_none() && !d.spawn {
            builder = builder.batcher_config(BATCHING);
        } // A live viewer needs data as it comes: Rerun's clock-driven default then.
        let rec = builder
            .set_sinks(sinks)
            .context("cannot start the recording")?;
        layout.send(&rec, application_id)?;
        rec.set_log_time_enabled(false);
        rec.send_recording_name(recording_name)?;
        Ok(Recording {
            rec: Some(rec),
            file,
            target,
        })
    }

    pub fn stream(&self) -> &rerun::RecordingStream {
        self.rec.as_ref().expect("stream is present until commit")
    }

    /// Flushes, writes the footer, fsyncs and renames the file into place. Returns the file's
    /// size.
    pub fn commit(mut self) -> anyhow::Result<Option<u64>> {
        let rec = self.rec.take().expect("commit once");
        let flushed = rec.flush_blocking();
        // Dropping the last handle hands every message still batched to the sinks.
        drop(rec);
        let Some(file) = self.file.take() else {
            flushed.context("cannot flush the recording")?;
            return Ok(None);
        };
        file.finish()?;
        Ok(match &self.target {
            Some(target) => Some(std::fs::metadata(target)?.len()),
            None => None,
        })
    }
}

impl Drop for Recording {
    fn drop(&mut self) {
        // Uncommitted: the stream is dropped first, then the hidden file with `file`.
        drop(self.rec.take());
    }
}

mod sink;

/// Sends the run's provenance as recording properties (`/__properties/physlab`): the scene file
/// that reproduces it, physlab's version and git commit, the Rerun SDK's version, the command
/// line and the methods.
pub fn send_provenance(
    rec: &rerun::RecordingStream,
    scenes: &str,
    config_toml: &str,
    methods: &[&str],
) -> anyhow::Result<()> {
    let command_line = command_line();
    rec.send_property(
        "physlab",
        &rerun::AnyValues::default()
            .with_component::<rerun::components::Text>("scenes", [scenes])
            .with_component::<rerun::components::Text>(
                "physlab_version",
                [env!("CARGO_PKG_VERSION")],
            )
            .with_component::<rerun::components::Text>("git_commit", [GIT_COMMIT])
            .with_component::<rerun::components::Text>("rerun_sdk_version", [RERUN_SDK_VERSION])
            .with_component::<rerun::components::Text>("command_line", [command_line])
            .with_component::<rerun::components::Text>("methods", [methods.join(",")])
            .with_component::<rerun::components::Text>("config", [config_toml]),
    )?;
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
