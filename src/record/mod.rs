//! The writing side of Rerun (reading is `crate::rrd`): where a recording goes and how it is
//! written (`recording`), what it says about itself (`provenance`), the viewer's layouts
//! (`views`), each scene's drawing, and the difference recording (`diff`). This module keeps the
//! series styles and the slots scenes stand in.

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
    summary_markdown,
};
pub use recording::{
    BATCHING, CHUNK_BYTES, Destinations, Recording, check_destinations, find_on_path,
};
pub use views::{
    PLOTS_SHARE, Plot, SceneViews, Slot, Staging, WINDOW, about_and_events, all_layout,
    grid_columns, plot_column, scene_blueprint, scene_layout, slot_grid, summary_view,
    view_above_text,
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
