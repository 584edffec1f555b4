//! The viewer's layouts: one plot per quantity with its legend, a scene's views, `all`'s grid,
//! and the blueprint that shows only them.

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Grid, Horizontal, SelectionPanel, Spatial3DView,
    Tabs, TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};

use super::layout::{LEGEND_ROW_PX, time_axis_end};
use super::{Framing, Layout, ViewProperties, scene};

/// The viewer's room for views at 1600×1000 [logical px]: the window less its top bar and the
/// collapsed time panel, measured on a screenshot.
pub const WINDOW: [f32; 2] = [1600.0, 943.0];
/// A view's title bar [logical px].
const TITLE_PX: f32 = 24.0;

/// The narrowest view whose title bar shows `title` whole [logical px]: its icon and margins
/// and the buttons at its right, and a width per character (measured on a screenshot:
/// "semi-implicit-euler" takes 106 px, and a 225 px view shows it whole).
pub fn title_width(title: &str) -> f32 {
    120.0 + 5.6 * title.chars().count() as f32
}

/// One 3D view of a scene: a title, the lanes (subtrees of `/<scene>`) it shows, and the box
/// its eye frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    pub title: String,
    pub lanes: Vec<&'static str>,
    pub framing: Framing,
    /// A plain dark backdrop without the grid (see [`ViewProperties::plain_backdrop`]): each
    /// view property is a chunk of its own in the recording, so it is set only where needed.
    pub plain: bool,
}

/// One plot of a run: its entity name under `/<scene>/plots`, title, and the series it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    pub name: &'static str,
    pub title: &'static str,
    pub series: Vec<&'static str>,
    /// Where its value axis opens, when a fixed floor says more than the data's own range.
    pub range: Option<(f64, f64)>,
    /// Every series is expected at round-off: the plot stands in a tab behind the scene's
    /// statement of its largest value (`/<scene>/roundoff`), not in view as a flat line.
    pub roundoff: bool,
}

/// What a scene's layout needs of its run: its 3D views, its plots and its end [s].
#[derive(Clone, Debug, PartialEq)]
pub struct Staging {
    pub slots: Vec<Slot>,
    pub plots: Vec<Plot>,
    pub end_time: f64,
}

impl Staging {
    /// One 3D view per lane (titled with its name), each framed on its own slot.
    pub fn per_lane(lanes: impl IntoIterator<Item = (&'static str, Framing)>) -> Vec<Slot> {
        lanes
            .into_iter()
            .map(|(lane, framing)| Slot {
                title: lane.to_string(),
                lanes: vec![lane],
                framing,
                plain: false,
            })
            .collect()
    }

    /// The plots of `titles` that some lane plots: each with the lanes `series` gives it.
    pub fn plots(
        titles: &[(&'static str, &'static str)],
        series: impl Fn(&str) -> Vec<&'static str>,
    ) -> Vec<Plot> {
        titles
            .iter()
            .map(|&(name, title)| Plot {
                name,
                title,
                series: series(name),
                range: None,
                roundoff: false,
            })
            .filter(|p| !p.series.is_empty())
            .collect()
    }

    /// The plots shown: the run's, and its methods' wall-clock costs with `timings`.
    fn shown(&self, timings: bool, methods: &[&'static str]) -> Vec<Plot> {
        let mut shown = self.plots.clone();
        if timings {
            shown.push(Plot {
                name: scene::FRAME_COST.0,
                title: scene::FRAME_COST.1,
                series: methods.to_vec(),
                range: None,
                roundoff: false,
            });
        }
        shown
    }
}

/// A scene's plots in a column of `size` [px], each legend beside its curves: as many stacked
/// as are tall enough for their legends, the rest in tabs in the last place; those expected at
/// round-off in tabs behind the scene's statement of their largest values.
fn plot_views(
    scene: &str,
    plots: &[Plot],
    end_time: f64,
    size: [f32; 2],
    props: &mut ViewProperties,
) -> Vertical {
    let (quiet, shown): (Vec<&Plot>, Vec<&Plot>) = plots.iter().partition(|p| p.roundoff);
    let room = usize::from(!quiet.is_empty());
    let tall = |rows: usize| PLOT_CHROME_PX + LEGEND_ROW_PX * rows as f32;
    let longest = plots.iter().map(|p| p.series.len()).max().unwrap_or(0);
    let stacked = ((size[1] / tall(longest)).floor() as usize).clamp(1, plots.len().max(1));
    let places = stacked.max(room + 1) - room;
    let low = quiet.iter().map(|p| p.series.len()).max().map_or(0.0, tall);
    let high = (size[1] - low) / places.min(shown.len()).max(1) as f32;
    let mut view = |p: &Plot, height: f32| {
        let origin = format!("/{scene}/plots/{}", p.name);
        let view = TimeSeriesView::new(p.title).with_origin(origin.clone());
        let view = props.legend_beside(view, &p.series, end_time, size[0]);
        props.value_axis(view, origin, height, p.range)
    };
    let mut views: Vec<ContainerLike> = shown.iter().map(|p| view(p, high)).collect();
    if views.len() > places {
        let rest = views.split_off(places - 1);
        views.push(Tabs::new(rest).into());
    }
    let mut shares = vec![high; views.len()];
    if !quiet.is_empty() {
        let statement =
            TextDocumentView::new("round-off").with_origin(format!("/{scene}/roundoff"));
        let tabs = std::iter::once(statement.into()).chain(quiet.iter().map(|p| view(p, low)));
        views.push(Tabs::new(tabs).into());
        shares.push(low);
    }
    Vertical::new(views).with_row_shares(shares)
}

/// What a plot's height holds besides its legend's lines [logical px]: its title bar, time axis
/// labels and the legend's margins, measured on screenshots.
const PLOT_CHROME_PX: f32 = 88.0;

/// The scene's 3D views in a grid filling `size` [px]: as many columns as make the subjects
/// largest, each view's eye framing its slot.
pub fn slot_grid(
    scene: &str,
    slots: &[Slot],
    size: [f32; 2],
    props: &mut ViewProperties,
) -> ContainerLike {
    let (columns, aspect) = grid_columns(slots, size);
    let views: Vec<ContainerLike> = slots
        .iter()
        .map(|slot| {
            let view = props.eye(slot_view(scene, slot), slot.framing, aspect);
            if slot.plain {
                props.plain_backdrop(view)
            } else {
                view
            }
        })
        .collect();
    if views.len() == 1 {
        return views.into_iter().next().expect("one view");
    }
    Grid::new(views).with_grid_columns(columns as u32).into()
}

/// A grid's subjects drawn at this share of the largest they could be are nearly as large.
const NEARLY: f32 = 0.9;

/// The number of columns that draws `slots` (nearly) largest in `size` [px], and the width /
/// height of each view's drawing area then.
pub fn grid_columns(slots: &[Slot], size: [f32; 2]) -> (usize, f32) {
    let n = slots.len().max(1);
    let view = |c: usize| {
        let rows = n.div_ceil(c);
        let w = size[0] / c as f32;
        let h = (size[1] / rows as f32 - TITLE_PX).max(1.0);
        (w, h)
    };
    // Pixels per metre at the subjects' centres: the view's height over the eye's distance
    // (the same field of view in every view).
    let scale = |c: usize| {
        let (w, h) = view(c);
        let distance = slots
            .iter()
            .map(|s| {
                let (eye, target) = s.framing.eye(w / h);
                glam::Vec3::from_array(eye).distance(glam::Vec3::from_array(target))
            })
            .fold(f32::MIN_POSITIVE, f32::max);
        h / distance
    };
    // No more columns than keep every title whole; of those, the fewest that draw the subjects
    // nearly as large as any: wider views keep the lanes' names in their titles whole.
    let title = slots
        .iter()
        .map(|s| title_width(&s.title))
        .fold(0.0, f32::max);
    let most = ((size[0] / title) as usize).clamp(1, n);
    let largest = (1..=most).map(scale).fold(0.0f32, f32::max);
    let best = (1..=most)
        .find(|&c| scale(c) >= NEARLY * largest)
        .unwrap_or(1);
    let (w, h) = view(best);
    (best, w / h)
}

/// A 3D view of some of a scene's lanes: `/<scene>/<lane>/**` for each.
fn slot_view(scene: &str, slot: &Slot) -> Spatial3DView {
    let contents: Vec<String> = slot
        .lanes
        .iter()
        .map(|lane| format!("+ $origin/{lane}/**"))
        .collect();
    Spatial3DView::new(slot.title.as_str())
        .with_origin(format!("/{scene}"))
        .with_contents(contents)
}

/// What the layouts need of a scene: its name, its plots and its layout alone.
pub struct SceneViews {
    pub name: &'static str,
    /// Every plot the scene can draw: (entity name under `/<scene>/plots`, title).
    pub plots: &'static [(&'static str, &'static str)],
    pub blueprint: fn(bool, &Staging, &[&'static str], &mut ViewProperties) -> Blueprint,
}

/// A single scene's layout.
pub fn scene_layout(
    scene: &SceneViews,
    timings: bool,
    staging: &Staging,
    methods: &[&'static str],
) -> Layout {
    let mut props = ViewProperties::default();
    let blueprint = (scene.blueprint)(timings, staging, methods, &mut props);
    props.layout(blueprint)
}

/// The plots `physlab all` shows (fewer than a single scene's, so that each stays tall enough
/// for its legend at 1600×1000); the recording holds every series all the same.
const ALL_PLOTS: [&str; 7] = [
    "theta",
    "log10_theta_error",
    "log10_energy_balance",
    "max_strain",
    "specific_kinetic_energy",
    "log10_max_stretch",
    "max_penetration",
];

/// `physlab all`'s rows: 3D views, plots, the event log [shares of the height]; the log holds
/// its tab, its header and five rows of 18 px (at 132 px it scrolled its first row away).
const ALL_ROWS: [f32; 3] = [4.2, 4.3, 1.7];

/// The most rows of 3D views a scene stacks in `physlab all`.
const ALL_3D_ROWS: usize = 3;

/// `physlab all`: the scenes' 3D views side by side, each as wide as its lanes' titles need,
/// above the scenes' plots, above one event log of every scene (its summaries in tabs beside).
pub fn all_layout(timings: bool, scenes: &[(&SceneViews, Staging, Vec<&'static str>)]) -> Layout {
    let mut props = ViewProperties::default();
    let share = |row: usize| WINDOW[1] * ALL_ROWS[row] / ALL_ROWS.iter().sum::<f32>();
    // Each scene's 3D views in at most ALL_3D_ROWS rows, every title whole; what is left over
    // shared evenly.
    let needs: Vec<f32> = scenes
        .iter()
        .map(|(_, s, _)| {
            let widest = s.slots.iter().map(|x| title_width(&x.title));
            s.slots.len().div_ceil(ALL_3D_ROWS) as f32 * widest.fold(0.0, f32::max)
        })
        .collect();
    let spare = (WINDOW[0] - needs.iter().sum::<f32>()) / scenes.len().max(1) as f32;
    let widths: Vec<f32> = needs.iter().map(|w| (w + spare).max(1.0)).collect();
    let grids: Vec<ContainerLike> = scenes
        .iter()
        .zip(&widths)
        .map(|((v, s, _), &w)| slot_grid(v.name, &s.slots, [w, share(0)], &mut props))
        .collect();
    let shown: Vec<Vec<Plot>> = (scenes.iter())
        .map(|(_, staging, methods)| {
            let shown = staging.shown(timings, methods).into_iter();
            (shown.filter(|p| ALL_PLOTS.contains(&p.name) || p.name == scene::FRAME_COST.0))
                .collect()
        })
        .collect();
    let ends: Vec<f64> = scenes.iter().map(|s| s.1.end_time).collect();
    let plot_widths = time_widths(&shown, &ends);
    let plots: Vec<ContainerLike> = (scenes.iter().zip(&shown).zip(&plot_widths))
        .map(|(((views, staging, _), shown), &w)| {
            let size = [w, share(1)];
            plot_views(views.name, shown, staging.end_time, size, &mut props).into()
        })
        .collect();
    let log = TextLogView::new("events").with_origin("/").with_contents(
        scenes
            .iter()
            .map(|(v, _, _)| format!("+ $origin/{}/events", v.name)),
    );
    let bottom = std::iter::once(log.into())
        .chain(scenes.iter().map(|(v, _, _)| summary_view(v.name).into()));
    let blueprint = only_these_views(Blueprint::new(
        Vertical::new([
            Horizontal::new(grids).with_column_shares(widths).into(),
            Horizontal::new(plots)
                .with_column_shares(plot_widths)
                .into(),
            Tabs::new(bottom).into(),
        ])
        .with_row_shares(ALL_ROWS),
    ));
    props.layout(blueprint)
}

/// A column of plots is at least this wide in `physlab all` [px].
const NARROWEST_PLOTS: f32 = 300.0;

/// The widths of `physlab all`'s columns of plots (of runs ending at `ends` [s]): each as wide
/// as its time axes need for three tick labels within the legend's band, narrowest needs first
/// while the rest keep [`NARROWEST_PLOTS`]; the unmet share what is left, or all what is spare.
fn time_widths(plots: &[Vec<Plot>], ends: &[f64]) -> Vec<f32> {
    let needs: Vec<f32> = (plots.iter().zip(ends))
        .map(|(plots, &end)| {
            let fits = |w: f32| (plots.iter()).all(|p| time_axis_end(&p.series, end, w).1);
            let widths = (30..=160).map(|w| w as f32 * 10.0);
            widths
                .into_iter()
                .find(|&w| fits(w))
                .unwrap_or(f32::INFINITY)
        })
        .collect();
    let mut order: Vec<usize> = (0..needs.len()).collect();
    order.sort_by(|&a, &b| needs[a].total_cmp(&needs[b]));
    let mut widths = vec![0.0; needs.len()];
    let mut left = WINDOW[0];
    for (k, &i) in order.iter().enumerate() {
        let others = (needs.len() - k - 1) as f32 * NARROWEST_PLOTS;
        if needs[i] + others <= left {
            widths[i] = needs[i];
            left -= needs[i];
        }
    }
    let unmet = widths.iter().filter(|w| **w == 0.0).count();
    let spare = left / unmet.max(widths.len()) as f32;
    (widths.iter())
        .map(|&w| if w == 0.0 || unmet == 0 { w + spare } else { w })
        .collect()
}

/// A single scene's plots take this share of the window's width (the rest its 3D views): a
/// rope's plots need 880 px for a tick label a second on their time axes.
pub const PLOTS_SHARE: f32 = 0.55;

/// A single scene's layout: its 3D views (3/4 of the left column) above its about text and
/// events, beside its plots.
pub fn view_above_text(
    scene: &str,
    staging: &Staging,
    timings: bool,
    methods: &[&'static str],
    props: &mut ViewProperties,
) -> Blueprint {
    let left = (1.0 - PLOTS_SHARE) * WINDOW[0];
    let grid = slot_grid(scene, &staging.slots, [left, 0.75 * WINDOW[1]], props);
    let left = Vertical::new([grid, Horizontal::new(about_and_events(scene)).into()])
        .with_row_shares([3.0, 1.0]);
    scene_blueprint(left, scene, staging, (timings, methods), props)
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

/// A single scene's layout: `left` beside its plots (with the wall-clock cost of `methods` when
/// `timings`), nothing else shown, `sim_time` selected.
pub fn scene_blueprint(
    left: Vertical,
    scene: &str,
    staging: &Staging,
    (timings, methods): (bool, &[&'static str]),
    props: &mut ViewProperties,
) -> Blueprint {
    let plots = staging.shown(timings, methods);
    let size = [PLOTS_SHARE * WINDOW[0], WINDOW[1]];
    let plots = plot_views(scene, &plots, staging.end_time, size, props);
    only_these_views(Blueprint::new(
        Horizontal::new([left.into(), plots.into()])
            .with_column_shares([1.0 - PLOTS_SHARE, PLOTS_SHARE]),
    ))
}

/// No views but the given ones, the panels collapsed, `sim_time` selected.
pub(super) fn only_these_views(blueprint: Blueprint) -> Blueprint {
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
