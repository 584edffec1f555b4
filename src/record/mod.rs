//! The only place that calls Rerun: entity paths, styles, blueprints, properties, and writing
//! a recording file safely.

pub mod hair;
pub mod pendulum;
pub mod rope;

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial3DView, TextDocumentView, TextLogView, TimePanel,
    TimeSeriesView, Vertical,
};

/// One colour per method, the same in 3D and in every plot of every scene.
/// (ColorBrewer Set1, which stays distinguishable on the viewer's dark background.)
pub fn method_color(name: &str) -> [u8; 3] {
    match name {
        "explicit-euler" => [228, 26, 28],
        "semi-implicit-euler" => [255, 127, 0],
        "implicit-euler" => [152, 78, 163],
        "midpoint" => [166, 86, 40],
        "trapezoid" => [247, 129, 191],
        "rk4" => [55, 126, 184],
        "verlet" => [77, 175, 74],
        "ftl" => [0, 190, 190],
        "exact" | "reference" => [220, 220, 220],
        _ => [255, 255, 51],
    }
}

/// One plot per quantity, `/<scene>/plots/<name>/*` (every method in each), stacked.
pub fn plot_column(scene: &str, plots: &[(&str, &str)]) -> Vertical {
    Vertical::new(plots.iter().map(|(name, title)| {
        ContainerLike::from(
            TimeSeriesView::new(*title).with_origin(format!("/{scene}/plots/{name}")),
        )
    }))
}

/// The scene's 3D view: everything under `/<scene>` except its plots, events, about text and
/// the given subtrees.
pub fn scene_view(scene: &str, title: &str, exclude: &[&str]) -> Spatial3DView {
    let mut contents = vec![
        "+ $origin/**".to_string(),
        "- $origin/plots/**".to_string(),
        "- $origin/events".to_string(),
        "- $origin/about".to_string(),
    ];
    contents.extend(exclude.iter().map(|e| format!("- $origin/{e}")));
    Spatial3DView::new(title)
        .with_origin(format!("/{scene}"))
        .with_contents(contents)
}

/// The run description (`/<scene>/about`) and the event log (`/<scene>/events`).
pub fn about_and_events(scene: &str) -> [ContainerLike; 2] {
    [
        TextDocumentView::new("about this run")
            .with_origin(format!("/{scene}/about"))
            .into(),
        TextLogView::new("events")
            .with_origin(format!("/{scene}/events"))
            .into(),
    ]
}

/// A single scene's layout: `left` beside the plots, nothing else shown, `sim_time` selected.
pub fn scene_blueprint(left: Vertical, plots: Vertical) -> Blueprint {
    Blueprint::new(Horizontal::new([left.into(), plots.into()]).with_column_shares([1.0, 1.0]))
        .with_auto_views(false)
        .with_time_panel(TimePanel::new().with_timeline("sim_time"))
}

/// A faint floor outline through four corners (static). Besides showing the ground, it widens
/// the bounding box the viewer's default camera frames, so the nearest slots are not cut off by
/// perspective (the camera cannot be set from the Rust SDK).
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
/// the viewer's default camera frames every lane.
pub fn slot_cells(n: usize) -> Vec<(usize, usize)> {
    let columns = n.clamp(1, 4);
    let rows = n.div_ceil(columns);
    (0..n)
        .map(|i| (i % columns, rows - 1 - i / columns))
        .collect()
}

/// A recording being written to a temporary file beside its target. [`FileRecording::commit`]
/// finalises it (footer written) and renames it into place; dropping it uncommitted removes the
/// temporary file, so a failed run never leaves a partial file or touches an earlier recording.
pub struct FileRecording {
    rec: Option<rerun::RecordingStream>,
    tmp_path: PathBuf,
    final_path: PathBuf,
}

impl FileRecording {
    /// Starts a recording for `target` with `blueprint` as its active layout. The wall-clock
    /// `log_time` timeline is off so that the data depend only on the inputs.
    pub fn create(
        target: &Path,
        recording_name: &str,
        blueprint: rerun::blueprint::Blueprint,
    ) -> anyhow::Result<Self> {
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create the output folder {}", dir.display()))?;
        if target.is_dir() {
            anyhow::bail!(
                "output {} is a folder; give a file path such as {}/run.rrd",
                target.display(),
                target.display()
            );
        }
        let file_name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp_path = dir.join(format!(".{file_name}.{}.partial", std::process::id()));
        // Fail now, before simulating, if the folder is not writable.
        std::fs::File::create(&tmp_path)
            .with_context(|| format!("cannot write the recording beside {}", target.display()))?;
        let rec = rerun::RecordingStreamBuilder::new("physlab")
            .recording_name(recording_name)
            .enabled(true) // the file is the product: ignore RERUN=off
            .with_blueprint(blueprint)
            .save(&tmp_path)
            .with_context(|| format!("cannot open {} for writing", tmp_path.display()))?;
        rec.set_log_time_enabled(false);
        Ok(FileRecording {
            rec: Some(rec),
            tmp_path,
            final_path: target.to_path_buf(),
        })
    }

    pub fn stream(&self) -> &rerun::RecordingStream {
        self.rec.as_ref().expect("stream is present until commit")
    }

    /// Flushes, writes the footer, and renames the file into place. Returns its size in bytes.
    pub fn commit(mut self) -> anyhow::Result<u64> {
        let rec = self.rec.take().expect("commit once");
        rec.flush_blocking().context("cannot flush the recording")?;
        // Dropping the last handle finalises the file sink: the footer and manifest are written
        // and its writer thread is joined before `drop` returns.
        drop(rec);
        std::fs::rename(&self.tmp_path, &self.final_path).with_context(|| {
            format!(
                "cannot move {} to {}",
                self.tmp_path.display(),
                self.final_path.display()
            )
        })?;
        Ok(std::fs::metadata(&self.final_path)?.len())
    }
}

impl Drop for FileRecording {
    fn drop(&mut self) {
        if let Some(rec) = self.rec.take() {
            drop(rec);
            let _ = std::fs::remove_file(&self.tmp_path);
        }
    }
}

/// Sends the run's provenance as recording properties (`/__properties/physlab`).
pub fn send_provenance(
    rec: &rerun::RecordingStream,
    scene: &str,
    config_text: &str,
    methods: &[&str],
) -> anyhow::Result<()> {
    let command_line = std::env::args().collect::<Vec<_>>().join(" ");
    rec.send_property(
        "physlab",
        &rerun::AnyValues::default()
            .with_component::<rerun::components::Text>("scene", [scene])
            .with_component::<rerun::components::Text>(
                "physlab_version",
                [env!("CARGO_PKG_VERSION")],
            )
            .with_component::<rerun::components::Text>("rerun_sdk_version", [RERUN_SDK_VERSION])
            .with_component::<rerun::components::Text>("command_line", [command_line])
            .with_component::<rerun::components::Text>("methods", [methods.join(",")])
            .with_component::<rerun::components::Text>("config", [config_text]),
    )?;
    Ok(())
}

/// The Rerun SDK this build links (pinned in Cargo.toml).
pub const RERUN_SDK_VERSION: &str = "0.36.3";
