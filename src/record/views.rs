//! The viewer's layouts: one plot per quantity with its legend, a scene's views, `all`'s grid,
//! and the blueprint that shows only them.

use rerun::blueprint::components::{Corner2D, PanelState};
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial3DView, Tabs,
    TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};

use super::{Framing, Layout, ViewProperties, layout, scene};

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

/// Width / height of the single-scene 3D view above the text panels at 1600×1000 (the left
/// half, 3/4 of the height), measured on a screenshot.
const ABOVE_TEXT_ASPECT: f32 = 1.19;

/// A single scene's layout: its 3D view of the methods side by side, framed on `framing`, above
/// its about text and events, beside its plots.
pub fn view_above_text(
    scene: &str,
    plots: &[(&'static str, &'static str)],
    timings: bool,
    framing: Framing,
    props: &mut ViewProperties,
) -> Blueprint {
    let title = format!("{scene}: methods side by side");
    let view = props.eye(scene_view(scene, &title, &[]), framing, ABOVE_TEXT_ASPECT);
    let left = Vertical::new([view, Horizontal::new(about_and_events(scene)).into()])
        .with_row_shares([3.0, 1.0]);
    scene_blueprint(
        left,
        plot_column(scene, &plots_shown(plots, timings), props),
    )
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
    panels_collapsed(blueprint, TimePanel::new().with_timeline("sim_time"))
}

/// No views but the given ones, the panels collapsed (the time panel `time` as it is given).
pub fn panels_collapsed(blueprint: Blueprint, time: TimePanel) -> Blueprint {
    blueprint
        .with_auto_views(false)
        .with_time_panel(time.with_state(PanelState::Collapsed))
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
}
