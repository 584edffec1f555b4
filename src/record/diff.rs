//! `physlab diff --output D.rrd`: a recording that shows where two runs part at a glance: per
//! plotted quantity B − A of the values (10^B − 10^A where a log10 is plotted), a line per
//! method; both runs' 3D points overlaid (A grey, B orange) and their largest distance over
//! time; and the printed report.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use rerun::TimeColumn;
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, Spatial3DView, Tabs, TextDocumentView,
    TimeSeriesView, Vertical,
};

use super::{Destinations, Framing, Recording, SceneViews, ViewProperties, log_series_style};
use crate::rrd::compare::{Key, RowView};

/// Rows held per series before they are sent: the writer's memory does not grow with the file.
const BATCH: usize = 4096;

/// A 3D row with more coordinates than this is not redrawn (a dense hair frame): its distance
/// plot still shows where the runs part.
const MAX_OVERLAID_COORDINATES: usize = 3 * 4096;

/// A's points and B's in the overlay: A as a grey reference, B in a colour of its own.
const A_COLOR: [u8; 3] = [150, 150, 150];
const B_COLOR: [u8; 3] = [255, 140, 0];

/// What the two recordings hold in common, read before the difference recording is opened:
/// its views are laid out from it.
pub struct DiffPlan<'a> {
    /// The entities both recordings hold (B's renamed onto A's lanes when paired).
    pub shared: BTreeSet<String>,
    /// The lanes (methods and references): the last segment of a plotted series.
    pub lanes: &'a BTreeSet<String>,
    /// The scenes' plots, for their titles.
    pub scenes: &'a [&'a SceneViews],
    /// B's lane paired with A's, when each ran one method: its series are named "B − A".
    pub paired: Option<(String, String)>,
    /// Each scene's 3D framing, as A's configuration draws it: one overlay view per scene.
    pub framings: Vec<(&'static str, Framing)>,
    /// The later of the two runs' ends [s] (the plots' legends stand past it).
    pub end_time: f64,
}

impl DiffPlan<'_> {
    /// (scene, quantity) of every plotted series both hold, with the lanes plotted.
    fn quantities(&self) -> BTreeMap<(String, String), Vec<String>> {
        let mut out: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
        for entity in &self.shared {
            let parts: Vec<&str> = entity.trim_start_matches('/').split('/').collect();
            if let [scene, "plots", quantity, lane] = parts[..]
                && self.lanes.contains(lane)
                && !constant(quantity, lane)
            {
                out.entry((scene.to_string(), quantity.to_string()))
                    .or_default()
                    .push(lane.to_string());
            }
        }
        out
    }

    /// The report beside the 3D overlay, above the plots of B − A (a tab per scene, and one of the
    /// 3D distances); `names` the files A and B.
    fn layout(&self, names: [&str; 2]) -> super::Layout {
        let mut props = ViewProperties::default();
        let mut by_scene: BTreeMap<String, Vec<ContainerLike>> = BTreeMap::new();
        let quantities = self.quantities();
        // A plot's height: the lower two thirds of the window less the tabs' bar, in rows of three.
        let height = |scene: &str| {
            let n = quantities.keys().filter(|(s, _)| s == scene).count();
            (2.0 / 3.0 * super::WINDOW[1] - 24.0) / n.div_ceil(3) as f32
        };
        for ((scene, quantity), lanes) in &quantities {
            let plots = self.scenes.iter().filter(|v| v.name == scene);
            let title = (plots.flat_map(|v| v.plots.iter()))
                .find(|(name, _)| name == quantity)
                .map_or(quantity.as_str(), |(_, title)| title);
            // A log10 plot's values, not their logarithms: its title's quantity without "log10".
            let title = match title.strip_prefix("log10 ") {
                Some(q) => format!(
                    "B − A: {} (values, not their log10)",
                    q.split(':').next().unwrap_or(q)
                ),
                None => format!("B − A: {title}"),
            };
            let origin = format!("/diff/{scene}/plots/{quantity}");
            let view = TimeSeriesView::new(title).with_origin(origin.clone());
            // Each plot's legend in a band past the run's end, as in the scenes' own plots; the
            // plots are a third of the window wide.
            let lanes: Vec<&str> = lanes.iter().map(String::as_str).collect();
            let view = props.legend_beside(view, &lanes, self.end_time, 1600.0 / 3.0);
            let view = props.value_axis(view, origin, height(scene), None);
            by_scene.entry(scene.clone()).or_default().push(view);
        }
        // Three plots a row: each tall enough for a legend of eight methods at 1600×1000.
        let grid = |views: Vec<ContainerLike>| Grid::new(views).with_grid_columns(3);
        let mut plots: Vec<ContainerLike> = by_scene
            .into_iter()
            .map(|(scene, views)| grid(views).with_name(scene).into())
            .collect();
        // Its legend names the 3D entities (those both hold outside the plots: at most these).
        let drawn: Vec<&str> = (self.shared.iter())
            .map(|e| e.trim_start_matches('/'))
            .filter(|e| !e.contains("/plots/"))
            .collect();
        let distance = TimeSeriesView::new("3D: largest distance between A's and B's points [m]")
            .with_origin("/diff/distance");
        let distance = props.legend_beside(distance, &drawn, self.end_time, 1600.0);
        let height = 2.0 / 3.0 * super::WINDOW[1] - 24.0;
        plots.push(props.value_axis(distance, "/diff/distance".into(), height, None));
        let plots: ContainerLike = match plots.len() {
            1 => plots.remove(0),
            _ => Tabs::new(plots).into(),
        };
        let mut top: Vec<ContainerLike> = vec![
            TextDocumentView::new("what differs")
                .with_origin("/diff/report")
                .into(),
        ];
        // The report and the scenes' overlays share the top third of the window.
        let aspect = (3.0 / (1.0 + self.framings.len().max(1) as f32)) * 1.6;
        for (scene, framing) in &self.framings {
            let view = Spatial3DView::new(format!(
                "{scene}: A = {} grey, B = {} orange",
                names[0], names[1]
            ))
            .with_origin("/diff/3d")
            .with_contents([
                format!("+ $origin/A/{scene}/**"),
                format!("+ $origin/B/{scene}/**"),
            ]);
            top.push(props.eye(view, *framing, aspect));
        }
        if self.framings.is_empty() {
            top.push(
                Spatial3DView::new(format!("A = {} grey, B = {} orange", names[0], names[1]))
                    .with_origin("/diff/3d")
                    .into(),
            );
        }
        let top = Horizontal::new(top);
        let blueprint = super::views::only_these_views(Blueprint::new(
            Vertical::new([top.into(), plots]).with_row_shares([1.0, 2.0]),
        ));
        props.layout(blueprint)
    }
}

/// Writes, as the comparison pairs the rows of both recordings: B − A of every plotted series
/// under `diff/<scene>/plots/<quantity>/<lane>`, both runs' 3D points under `diff/3d/A|B/<entity>`
/// and their largest distance under `diff/distance/<entity>`; at the end `diff/report`.
pub struct DiffWriter {
    recording: Recording,
    pending: BTreeMap<String, (Vec<i64>, Vec<f64>)>,
    /// Series whose style is logged.
    styled: BTreeSet<String>,
    lanes: BTreeSet<String>,
    paired: Option<(String, String)>,
    /// Per scene, the offsets of a ring around a point ([`ring`]).
    rings: BTreeMap<&'static str, Vec<[f32; 3]>>,
}

/// A fixed step's size is the same at every sample: its B − A, a constant, is left out (an
/// adaptive method's steps vary).
fn constant(quantity: &str, lane: &str) -> bool {
    quantity == "step_size"
        && !(lane.parse::<crate::integrate::Method>()).is_ok_and(|m| m.info().adaptive())
}

/// A closed ring of 24 segments around the origin, facing the eye of `framing`, 2 % of its box
/// across.
fn ring(framing: &Framing) -> Vec<[f32; 3]> {
    let v = glam::Vec3::from_array;
    let r = 0.02 * (v(framing.max) - v(framing.min)).length();
    let back = v(framing.toward_eye).normalize();
    let right = glam::Vec3::Z.cross(back).normalize();
    let up = back.cross(right);
    (0..=24)
        .map(|k| {
            let a = k as f32 / 24.0 * std::f32::consts::TAU;
            (r * (a.cos() * right + a.sin() * up)).to_array()
        })
        .collect()
}

impl DiffWriter {
    /// `a` and `b` are named in the recording's provenance, with the command line that wrote it.
    pub fn create(path: &Path, plan: &DiffPlan, a: &Path, b: &Path) -> anyhow::Result<Self> {
        let d = Destinations::output(path);
        let name = |p: &Path| {
            p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        };
        let layout = plan.layout([&name(a), &name(b)]);
        let recording = Recording::create(&d, "physlab-diff", "diff", layout)?;
        super::provenance::send_diff_provenance(recording.stream(), a, b)?;
        Ok(DiffWriter {
            recording,
            pending: BTreeMap::new(),
            styled: BTreeSet::new(),
            lanes: plan.lanes.clone(),
            paired: plan.paired.clone(),
            rings: plan.framings.iter().map(|(s, f)| (*s, ring(f))).collect(),
        })
    }

    /// One pair of rows at the same time.
    pub fn pair(&mut self, key: &Key, a: &RowView, b: &RowView) -> anyhow::Result<()> {
        let Some(time) = a.time() else {
            return Ok(());
        };
        let n = a.count();
        if n == 0 || n != b.count() {
            return Ok(());
        }
        let entity = key.0.trim_start_matches('/');
        let plotted = entity.split('/').nth(1) == Some("plots");
        let lane = entity.rsplit('/').next().unwrap_or_default();
        if n == 1 && plotted && self.lanes.contains(lane) {
            let quantity = entity.split('/').nth(2).unwrap_or_default();
            if constant(quantity, lane) {
                return Ok(());
            }
            let (x, y) = (a.nums().next(), b.nums().next());
            let (x, y) = (x.unwrap_or(0.0), y.unwrap_or(0.0));
            // A log10 plot's B − A would be the log of a ratio: the values' difference instead.
            let value = if quantity.starts_with("log10_") {
                10f64.powf(y) - 10f64.powf(x)
            } else {
                y - x
            };
            let series = format!("diff/{entity}");
            if self.styled.insert(series.clone()) {
                // The legend names the method, in its colour (the paired B's: what changed).
                let (name, colored) = match &self.paired {
                    Some((b_lane, a_lane)) if a_lane == lane => {
                        (format!("{b_lane} − {a_lane}"), b_lane.as_str())
                    }
                    _ => (lane.to_string(), lane),
                };
                log_series_style(self.recording.stream(), series.clone(), &name, colored)?;
            }
            return self.push(series, time, value);
        }
        if key.1.ends_with("strips") && entity.ends_with("/rod") && n == 6 {
            return self.rods(entity, time, a, b);
        }
        if !key.1.ends_with("positions") || !n.is_multiple_of(3) {
            return Ok(());
        }
        let points = |row: &RowView| -> Vec<[f32; 3]> {
            let v: Vec<f64> = row.nums().collect();
            v.chunks_exact(3)
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
                .collect()
        };
        let (pa, pb) = (points(a), points(b));
        let v = |p: &[f32; 3]| glam::Vec3::from_array(*p).as_dvec3();
        let distance = (pa.iter().zip(&pb))
            .map(|(p, q)| v(q).distance(v(p)))
            .fold(0.0, f64::max);
        let series = format!("diff/distance/{entity}");
        if self.styled.insert(series.clone()) {
            self.recording.stream().log_static(
                series.clone(),
                &rerun::SeriesLines::new()
                    .with_names([entity])
                    .with_widths([1.5]),
            )?;
        }
        self.push(series, time, distance)?;
        if n <= MAX_OVERLAID_COORDINATES {
            self.overlay(entity, time, pa, pb)?;
        }
        Ok(())
    }

    /// Both runs' points of a 3D row at `time`: A as rings facing the eye, B as points, so that
    /// where they coincide A rings B.
    fn overlay(
        &mut self,
        entity: &str,
        time: i64,
        pa: Vec<[f32; 3]>,
        pb: Vec<[f32; 3]>,
    ) -> anyhow::Result<()> {
        let rec = self.stream_at(time);
        let scene = entity.split('/').next().unwrap_or_default();
        match self.rings.get(scene) {
            Some(ring) => {
                let strips: Vec<Vec<[f32; 3]>> = pa
                    .iter()
                    .map(|p| {
                        ring.iter()
                            .map(|r| [p[0] + r[0], p[1] + r[1], p[2] + r[2]])
                            .collect()
                    })
                    .collect();
                rec.log(
                    format!("diff/3d/A/{entity}"),
                    &rerun::LineStrips3D::new(strips)
                        .with_colors([A_COLOR])
                        .with_radii([rerun::Radius::new_ui_points(1.5)]),
                )?;
            }
            None => rec.log(
                format!("diff/3d/A/{entity}"),
                &rerun::Points3D::new(pa)
                    .with_colors([A_COLOR])
                    .with_radii([rerun::Radius::new_ui_points(8.0)]),
            )?,
        }
        rec.log(
            format!("diff/3d/B/{entity}"),
            &rerun::Points3D::new(pb)
                .with_colors([B_COLOR])
                .with_radii([rerun::Radius::new_ui_points(5.0)]),
        )?;
        Ok(())
    }

    /// Both runs' pendulum rods at `time`, each from its pivot (a point) to the bob, A grey and
    /// B orange (B's drawn thinner, so A's shows around it where they coincide).
    fn rods(&mut self, entity: &str, time: i64, a: &RowView, b: &RowView) -> anyhow::Result<()> {
        let rec = self.stream_at(time);
        for (run, row, color, width) in [("A", a, A_COLOR, 3.0), ("B", b, B_COLOR, 1.5)] {
            let v: Vec<f32> = row.nums().map(|x| x as f32).collect();
            let (pivot, bob) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
            rec.log(
                format!("diff/3d/{run}/{entity}"),
                &rerun::LineStrips3D::new([[pivot, bob]])
                    .with_colors([color])
                    .with_radii([rerun::Radius::new_ui_points(width)]),
            )?;
            let pivot_entity = entity.trim_end_matches("rod").to_string() + "pivot";
            rec.log(
                format!("diff/3d/{run}/{pivot_entity}"),
                &rerun::Points3D::new([pivot])
                    .with_colors([color])
                    .with_radii([rerun::Radius::new_ui_points(4.0)]),
            )?;
        }
        Ok(())
    }

    /// The stream, its `sim_time` set to `time` [ns].
    fn stream_at(&self, time: i64) -> &rerun::RecordingStream {
        let rec = self.recording.stream();
        rec.set_time(
            "sim_time",
            std::time::Duration::from_nanos(time.max(0) as u64),
        );
        rec
    }

    fn push(&mut self, series: String, time: i64, value: f64) -> anyhow::Result<()> {
        let (times, values) = self.pending.entry(series.clone()).or_default();
        times.push(time);
        values.push(value);
        if times.len() >= BATCH {
            self.send(&series)?;
        }
        Ok(())
    }

    fn send(&mut self, series: &str) -> anyhow::Result<()> {
        let pending = self.pending.get_mut(series).filter(|(t, _)| !t.is_empty());
        let Some((times, values)) = pending else {
            return Ok(());
        };
        self.recording.stream().send_columns(
            series,
            [TimeColumn::new_duration_nanos(
                "sim_time",
                std::mem::take(times),
            )],
            rerun::Scalars::new(std::mem::take(values)).columns_of_unit_batches()?,
        )?;
        Ok(())
    }

    /// Sends what is left and the report, and completes the file. Returns the number of series.
    pub fn finish(mut self, report: &str) -> anyhow::Result<usize> {
        let series: Vec<String> = self.pending.keys().cloned().collect();
        for s in &series {
            self.send(s)?;
        }
        self.recording.stream().log_static(
            "diff/report",
            &rerun::TextDocument::from_markdown(format!("```text\n{report}```\n")),
        )?;
        self.recording.commit()?;
        Ok(series.len())
    }
}
