//! The writing side of Rerun (reading is `crate::rrd`): where a recording goes (`recording`),
//! what it says about itself (`provenance`), the viewer's layouts (`views`), each scene's drawing
//! and the difference recording (`diff`); here, the series styles and the slots of the scenes.

pub mod diff;
pub mod hair;
pub mod loglog;
pub mod pendulum;
pub mod rope;
pub mod scene;
pub mod study;

mod axes;
pub mod layout;
pub mod live;
mod provenance;
mod recording;
mod sink;
mod views;
pub use layout::{Framing, Layout, ViewProperties};
pub use provenance::{
    GIT_COMMIT, RERUN_SDK_VERSION, SceneEnd, log_summary, send_provenance, send_run_status,
};
pub use recording::{CHUNK_BYTES, Destinations, Recording};
pub use views::{
    PLOTS_SHARE, SceneViews, Slot, Staging, WINDOW, about_and_events, all_layout, scene_blueprint,
    scene_layout, slot_grid, view_above_text,
};

/// One colour per method (the palette is shared with the diagrams: `crate::palette`).
pub use crate::palette::method_color;

/// The legend name of a series in a plot and the colour of the method `colored` (static, logged
/// once).
pub fn log_series_style(
    rec: &rerun::RecordingStream,
    entity: String,
    name: &str,
    colored: &str,
) -> anyhow::Result<()> {
    rec.log_static(
        entity,
        &rerun::SeriesLines::new()
            .with_names([name])
            .with_colors([method_color(colored)])
            .with_widths([1.5]),
    )?;
    Ok(())
}

/// Grid cells (column, row counted from the bottom) for `n` lanes in reading order: a near-square
/// block (8 lanes: 3 × 3 less one), so that a 3D view frames every lane large and neighbouring
/// labels do not overlap in `all`'s narrow views.
pub fn slot_cells(n: usize) -> Vec<(usize, usize)> {
    let columns = (1..=4).find(|c| c * c >= n).unwrap_or(4);
    let rows = n.div_ceil(columns);
    (0..n)
        .map(|i| (i % columns, rows - 1 - i / columns))
        .collect()
}
