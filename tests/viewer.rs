//! What the viewer shows on opening a recording, read back from the written file: the blueprint's
//! containers laid out on a 1600×1000 window as the viewer lays them out, every plot with two or
//! more series naming them in a legend that covers no curve, no plot without data or purpose,
//! and every 3D view's eye framing its subject large and whole.

#[cfg(feature = "rerun")]
mod common;

#[cfg(feature = "rerun")]
mod layout {
    use std::collections::BTreeMap;
    use std::path::Path;

    use rerun::components::Range1D;
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::external::re_sdk_types::blueprint::archetypes::{
        ContainerBlueprint, EyeControls3D, PlotLegend, ScalarAxis, TimeAxis, ViewBlueprint,
        ViewContents,
    };
    use rerun::external::re_sdk_types::blueprint::components::TimeRange;
    use rerun::external::re_sdk_types::datatypes::{TimeInt, TimeRangeBoundary};
    use rerun::log::{Chunk, LogMsg};

    use crate::common::{decode, drawn_rows, physlab, scratch_dir};

    /// The viewer's room for views at 1600×1000: the window less its top bar and collapsed time
    /// panel (measured on a screenshot), and the title bar (or tab bar) above each view.
    const WINDOW: [f32; 2] = [1600.0, 943.0];
    const TITLE_PX: f32 = 24.0;
    /// A legend on a screenshot: 22.5 px a line, 104 px for the 19 characters of
    /// "semi-implicit-euler", 31 px more for its colour swatch and margins; a plot 232 px tall
    /// below its title shows 7 of 8 lines, one of 244 px all 8 (its time axis' labels, the
    /// legend's margins).
    const LEGEND_LINE_PX: f32 = 22.5;
    const LEGEND_ROOM_PX: f32 = 64.0;
    const LEGEND_CHAR_PX: f32 = 104.0 / 19.0;
    const LEGEND_FRAME_PX: f32 = 31.0;
    /// The value axis' labels left of a plot's curves [px].
    const VALUE_AXIS_PX: f32 = 30.0;
    /// Rerun's default vertical field of view for a 3D eye.
    const FOV_Y_DEGREES: f32 = 55.0;
    /// A view's title bar on a screenshot: "semi-implicit-euler" takes 106 px of text (5.55 px a
    /// character) after the view's icon, and the buttons at its right take 80 px; a 178 px view
    /// showed "explicit" of "explicit-euler". A 3D label: the same font, 8 px of margin a side.
    const TITLE_CHAR_PX: f32 = 106.0 / 19.0;
    const TITLE_CHROME_PX: f32 = 26.0 + 80.0;
    const LABEL_MARGIN_PX: f32 = 8.0;
    /// A text log on a screenshot: its header row 30 px, each row 18 px.
    const LOG_HEADER_PX: f32 = 30.0;
    const LOG_ROW_PX: f32 = 18.0;
    /// A relative error or length at or below this is round-off (f64's epsilon is 2.2e-16).
    const ROUNDOFF: f64 = 1e-12;

    #[derive(Debug, Default)]
    struct Container {
        kind: u8,
        children: Vec<String>,
        columns: Vec<f32>,
        rows: Vec<f32>,
        grid_columns: Option<u32>,
    }

    #[derive(Debug, Default)]
    struct View {
        class: String,
        title: String,
        origin: String,
        contents: Vec<String>,
        properties: BTreeMap<String, Chunk>,
        /// Width and height of its drawing area [px], once laid out.
        size: [f32; 2],
        /// Whether it is in view on opening (not behind another tab).
        visible: bool,
    }

    /// A recording's blueprint: its containers and views by entity path (`container/<id>`,
    /// `view/<id>`).
    struct Blueprint {
        containers: BTreeMap<String, Container>,
        views: BTreeMap<String, View>,
    }

    fn strings(chunk: &Chunk, descriptor: rerun::ComponentDescriptor) -> Vec<String> {
        chunk
            .iter_slices::<String>(descriptor.component)
            .flat_map(|s| s.iter().map(|x| x.to_string()).collect::<Vec<_>>())
            .collect()
    }

    fn floats(chunk: &Chunk, descriptor: rerun::ComponentDescriptor) -> Vec<f32> {
        chunk
            .iter_slices::<f32>(descriptor.component)
            .flat_map(|s| s.to_vec())
            .collect()
    }

    fn read_blueprint(path: &Path) -> Blueprint {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut containers: BTreeMap<String, Container> = BTreeMap::new();
        let mut views: BTreeMap<String, View> = BTreeMap::new();
        // The viewer shows a copy of the blueprint made when it is activated: what is written
        // into it after its last activation is not seen.
        let mut activated = false;
        for msg in DecoderApp::decode_lazy(file) {
            let msg = msg.unwrap();
            if let LogMsg::BlueprintActivationCommand(a) = &msg {
                activated = a.make_active;
            }
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg else {
                continue;
            };
            if !store_id.is_blueprint() {
                continue;
            }
            activated = false;
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            let entity = chunk.entity_path().to_string();
            let parts: Vec<&str> = entity.trim_start_matches('/').split('/').collect();
            match parts[..] {
                ["container", id] => {
                    let c = containers.entry(format!("container/{id}")).or_default();
                    let kind = ContainerBlueprint::descriptor_container_kind().component;
                    if let Some(k) = chunk.iter_slices::<u8>(kind).next() {
                        c.kind = k[0];
                    }
                    let children = strings(&chunk, ContainerBlueprint::descriptor_contents());
                    if !children.is_empty() {
                        c.children = children
                            .iter()
                            .map(|p| p.trim_start_matches('/').to_string())
                            .collect();
                    }
                    c.columns
                        .extend(floats(&chunk, ContainerBlueprint::descriptor_col_shares()));
                    c.rows
                        .extend(floats(&chunk, ContainerBlueprint::descriptor_row_shares()));
                    let grid = ContainerBlueprint::descriptor_grid_columns().component;
                    if let Some(g) = chunk.iter_slices::<u32>(grid).next() {
                        c.grid_columns = Some(g[0]);
                    }
                }
                ["view", id] => {
                    let v = views.entry(format!("view/{id}")).or_default();
                    if let Some(c) =
                        strings(&chunk, ViewBlueprint::descriptor_class_identifier()).pop()
                    {
                        v.class = c;
                    }
                    if let Some(o) = strings(&chunk, ViewBlueprint::descriptor_space_origin()).pop()
                    {
                        v.origin = o;
                    }
                    if let Some(t) = strings(&chunk, ViewBlueprint::descriptor_display_name()).pop()
                    {
                        v.title = t;
                    }
                }
                ["view", id, "ViewContents"] => {
                    let v = views.entry(format!("view/{id}")).or_default();
                    v.contents = strings(&chunk, ViewContents::descriptor_query());
                }
                ["view", id, property] => {
                    let v = views.entry(format!("view/{id}")).or_default();
                    v.properties.insert(property.to_string(), chunk);
                }
                _ => {}
            }
        }
        let mut blueprint = Blueprint { containers, views };
        let children: Vec<&String> = blueprint
            .containers
            .values()
            .flat_map(|c| &c.children)
            .collect();
        let roots: Vec<String> = blueprint
            .containers
            .keys()
            .filter(|k| !children.contains(k))
            .cloned()
            .collect();
        assert_eq!(roots.len(), 1, "one root container: {roots:?}");
        assert!(
            activated,
            "blueprint rows written after its last activation"
        );
        blueprint.place(&roots[0], WINDOW, true);
        blueprint
    }

    impl Blueprint {
        /// Lays `node` out in a rectangle of `size` [px] as the viewer does: shares along a row or
        /// column (equal when none are given), a grid's cells equal, a tab's views the whole
        /// rectangle (the first in view); every view's drawing area is its rectangle less its
        /// title bar.
        fn place(&mut self, node: &str, size: [f32; 2], visible: bool) {
            if let Some(view) = self.views.get_mut(node) {
                view.size = [size[0], size[1] - TITLE_PX];
                view.visible = visible;
                return;
            }
            let c = &self.containers[node];
            let n = c.children.len();
            let shares = |given: &[f32]| -> Vec<f32> {
                let s = if given.len() == n {
                    given.to_vec()
                } else {
                    vec![1.0; n]
                };
                let total: f32 = s.iter().sum();
                s.iter().map(|x| x / total).collect()
            };
            let sizes: Vec<[f32; 2]> = match c.kind {
                // Tabs: each child has the whole rectangle (the tab bar is its title bar).
                1 => vec![size; n],
                2 => shares(&c.columns)
                    .iter()
                    .map(|f| [size[0] * f, size[1]])
                    .collect(),
                3 => shares(&c.rows)
                    .iter()
                    .map(|f| [size[0], size[1] * f])
                    .collect(),
                4 => {
                    let columns = c
                        .grid_columns
                        .map_or_else(|| (n as f32).sqrt().ceil() as usize, |g| g as usize);
                    let rows = n.div_ceil(columns);
                    vec![[size[0] / columns as f32, size[1] / rows as f32]; n]
                }
                k => panic!("container kind {k}"),
            };
            let tabs = c.kind == 1;
            for (i, (child, size)) in c.children.clone().iter().zip(sizes).enumerate() {
                self.place(child, size, visible && (!tabs || i == 0));
            }
        }

        fn views_of(&self, class: &str) -> impl Iterator<Item = &View> {
            self.views.values().filter(move |v| v.class == class)
        }
    }

    fn vec3(chunk: &Chunk, descriptor: rerun::ComponentDescriptor) -> glam::Vec3 {
        let v = chunk
            .iter_slices::<[f32; 3]>(descriptor.component)
            .next()
            .unwrap_or_else(|| panic!("{} missing", descriptor.component));
        glam::Vec3::from_array(v[0])
    }

    /// Every plot names its series in a legend in a band of the time axis past the last value,
    /// wide enough for its longest name, and the plot is tall enough for every line of it; no
    /// plot is laid out without a series; no plot in view draws only round-off (a flat line).
    fn check_legends(path: &Path, blueprint: &Blueprint) {
        let data = decode(path);
        let corner = PlotLegend::descriptor_corner().component;
        let visible = PlotLegend::descriptor_visible().component;
        let range = TimeAxis::descriptor_view_range().component;
        let plots: Vec<&View> = blueprint.views_of("TimeSeries").collect();
        assert!(!plots.is_empty());
        for plot in plots {
            let series: Vec<(&str, i64)> = data
                .scalars
                .iter()
                .filter(|(e, rows)| e.starts_with(&format!("{}/", plot.origin)) && !rows.is_empty())
                .map(|(e, rows)| {
                    let name = e.rsplit('/').next().unwrap();
                    (name, rows.iter().map(|r| r.0).max().unwrap())
                })
                .collect();
            // The largest value any series reaches: its magnitude, or its log10 in a log plot.
            let log = plot.origin.contains("/log10_");
            let largest = data
                .scalars
                .iter()
                .filter(|(e, _)| e.starts_with(&format!("{}/", plot.origin)))
                .flat_map(|(_, rows)| rows.iter().map(|r| if log { r.1 } else { r.1.abs() }))
                .fold(f64::NEG_INFINITY, f64::max);
            let roundoff = largest <= if log { ROUNDOFF.log10() } else { ROUNDOFF };
            assert!(
                !(plot.visible && roundoff),
                "'{}' draws round-off alone in view (largest {largest:e})",
                plot.title
            );
            assert!(
                !series.is_empty(),
                "'{}' is laid out without data",
                plot.title
            );
            let legend = &plot.properties["PlotLegend"];
            let shown = legend.iter_slices::<bool>(visible).next().unwrap().value(0);
            // A single series too: the title names the quantity, the legend the lane.
            assert!(
                shown,
                "'{}' names none of its {} series",
                plot.title,
                series.len()
            );
            assert_eq!(
                legend.iter_slices::<u8>(corner).next().map(|c| c[0]),
                Some(2), // right top
                "'{}'",
                plot.title
            );
            let axis = plot
                .properties
                .get("TimeAxis")
                .unwrap_or_else(|| panic!("'{}' has no time range", plot.title));
            let view_range = axis
                .component_mono::<TimeRange>(range, 0)
                .unwrap_or_else(|| panic!("'{}': no time range", plot.title))
                .unwrap();
            let TimeRangeBoundary::Absolute(TimeInt(end)) = view_range.0.end else {
                panic!("'{}': {view_range:?}", plot.title);
            };
            let last = series.iter().map(|s| s.1).max().unwrap();
            let longest = series.iter().map(|s| s.0.chars().count()).max().unwrap();
            let legend_width = LEGEND_FRAME_PX + LEGEND_CHAR_PX * longest as f32;
            let curves = plot.size[0] - VALUE_AXIS_PX;
            let band = curves * (end - last) as f32 / end as f32;
            assert!(
                band >= legend_width,
                "'{}': {band:.0} px past the last value, the legend takes {legend_width:.0}",
                plot.title
            );
            let needed = LEGEND_LINE_PX * series.len() as f32 + LEGEND_ROOM_PX;
            assert!(
                plot.size[1] >= needed,
                "'{}': {:.0} px tall, its legend of {} lines needs {needed:.0}",
                plot.title,
                plot.size[1],
                series.len()
            );
        }
    }

    /// Rerun 0.36's time series, read from its source (re_view_time_series `nanos_grid_spacer`,
    /// egui_plot's `log_grid_spacer` and axis labels): time grid lines at 10ⁿ ns up to 10 s, then
    /// 1 min, 10 min, 1 h, 12 h, a day, ×10; the coarsest step whose lines stand 150 px apart
    /// across the view's width is the "medium" one, a tenth (a sixth) of it the "small" one.
    /// Value grid lines at multiples of 10ⁿ alone, the finest at least 8 px apart. A mark is
    /// labelled by the step it belongs to (the largest that divides it), when that step is more
    /// than 60 px apart across (20 px up), fading in to full brightness at 80 (30) px: a label
    /// counts here when drawn at half brightness or more (65 px, 22.5 px), and fits beside the
    /// next ("+10s" is 5.8 px a character).
    const TIME_LINES_PX: f64 = 150.0;
    const TIME_LABEL_PX: f64 = 65.0;
    const VALUE_GRID_PX: f64 = 8.0;
    const VALUE_LABEL_PX: f64 = 22.5;
    /// A plot's frame in its view: less the value labels at its left (up to "-0.001", 45 px)
    /// and the time labels below it (16 px measured: a view 164.6 px tall below its title drew
    /// θ's range of 2.875 on 148.6 px, one 447.5 px tall hair's 0.907 on 432 px; 18 here).
    const VALUE_LABELS_PX: f64 = 45.0;
    const TIME_LABELS_PX: f64 = 18.0;

    fn next_time_step(ns: i64) -> i64 {
        const S: i64 = 1_000_000_000;
        match ns {
            n if n <= S => n * 10,
            n if n == 10 * S || n == 600 * S => n * 6,
            n if n == 60 * S => n * 10,
            n if n == 3600 * S => n * 12,
            n if n == 43_200 * S => n * 2,
            n => n.saturating_mul(10),
        }
    }

    /// The time labels counted on a plot's time axis from 0 to `end` ns, `width` px wide.
    fn time_labels(end: f64, width: f64) -> Vec<String> {
        let lines = width / TIME_LINES_PX;
        let mut small = 1i64;
        while end / next_time_step(small) as f64 > lines {
            small = next_time_step(small);
        }
        let medium = next_time_step(small);
        let big = next_time_step(medium);
        let px = (width - VALUE_LABELS_PX) / end;
        (0..=(end / small as f64).floor() as i64)
            .map(|i| i * small)
            .filter(|&t| {
                let step = [big, medium, small]
                    .into_iter()
                    .find(|s| t % s == 0)
                    .unwrap();
                let label = format!("+{}s", t as f64 / 1e9);
                let spacing = step as f64 * px;
                spacing >= TIME_LABEL_PX && spacing >= 5.8 * label.chars().count() as f64
            })
            .map(|t| format!("+{}s", t as f64 / 1e9))
            .collect()
    }

    /// The value labels counted on a plot's value axis from `lo` to `hi`, `height` px tall.
    fn value_labels(lo: f64, hi: f64, height: f64) -> Vec<f64> {
        let per_px = (hi - lo) / height;
        let small = 10f64.powf((VALUE_GRID_PX * per_px).log10().ceil());
        ((lo / small).ceil() as i64..(hi / small).ceil() as i64)
            .filter(|i| {
                let step = [100, 10, 1].into_iter().find(|s| i % s == 0).unwrap();
                step as f64 * small / per_px >= VALUE_LABEL_PX
            })
            .map(|i| i as f64 * small)
            .collect()
    }

    /// Every plot (in view or behind a tab) shows three tick labels or more on each axis, and
    /// its value axis' range holds every value it plots (no data clipped).
    fn check_ticks(path: &Path, blueprint: &Blueprint) {
        let data = decode(path);
        let range = TimeAxis::descriptor_view_range().component;
        let values = ScalarAxis::descriptor_range().component;
        for plot in blueprint.views_of("TimeSeries") {
            let axis = &plot.properties["TimeAxis"];
            let view_range = axis.component_mono::<TimeRange>(range, 0).unwrap().unwrap();
            let TimeRangeBoundary::Absolute(TimeInt(end)) = view_range.0.end else {
                panic!("'{}': {view_range:?}", plot.title);
            };
            let times = time_labels(end as f64, f64::from(plot.size[0]));
            assert!(
                times.len() >= 3,
                "'{}' ({:.0} px wide, to {} s): time labels {times:?}",
                plot.title,
                plot.size[0],
                end as f64 / 1e9
            );
            let (lo, hi) = (data.scalars.iter())
                .filter(|(e, _)| e.starts_with(&format!("{}/", plot.origin)))
                .flat_map(|(_, rows)| rows.iter().map(|r| r.1))
                .filter(|v| v.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                });
            let set = (plot.properties.get("ScalarAxis"))
                .and_then(|c| c.component_mono::<Range1D>(values, 0)?.ok());
            if let Some(r) = set {
                assert!(
                    r.start() <= lo && hi <= r.end(),
                    "'{}': its range {r:?} clips its values {lo}..{hi}",
                    plot.title
                );
            }
            // Without a range of its own, the viewer's spans the values and 5% more each way.
            let margin = 0.05 * (hi - lo);
            let (lo, hi) = set.map_or((lo - margin, hi + margin), |r| (r.start(), r.end()));
            let height = f64::from(plot.size[1]) - TIME_LABELS_PX;
            let labels = value_labels(lo, hi, height);
            assert!(
                labels.len() >= 3,
                "'{}' ({height:.0} px tall, {lo}..{hi}): value labels {labels:?}",
                plot.title
            );
        }
    }

    /// A point's place in a view `aspect` wide per height, (−1, −1) to (1, 1) from corner to
    /// corner when visible.
    fn project(p: glam::Vec3, eye: glam::Vec3, target: glam::Vec3, aspect: f32) -> glam::Vec2 {
        let back = (eye - target).normalize();
        let right = glam::Vec3::Z.cross(back).normalize();
        let up = back.cross(right);
        let d = p - eye;
        let depth = -d.dot(back);
        assert!(depth > 0.0, "{p} is behind the eye");
        let tan = (0.5 * FOV_Y_DEGREES.to_radians()).tan();
        glam::Vec2::new(
            d.dot(right) / depth / (tan * aspect),
            d.dot(up) / depth / tan,
        )
    }

    /// Every label logged in 3D or 2D (a divergence's, a legend's): entity, its texts.
    fn labels(path: &Path) -> Vec<(String, Vec<String>)> {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut out = Vec::new();
        for msg in DecoderApp::decode_lazy(file) {
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                continue;
            };
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            let texts: Vec<String> = [
                rerun::Points3D::descriptor_labels(),
                rerun::Ellipsoids3D::descriptor_labels(),
                rerun::Points2D::descriptor_labels(),
            ]
            .into_iter()
            .flat_map(|d| strings(&chunk, d))
            .collect();
            if store_id.is_recording() && !texts.is_empty() {
                out.push((chunk.entity_path().to_string(), texts));
            }
        }
        out
    }

    /// Events logged per entity.
    fn event_counts(path: &Path) -> BTreeMap<String, usize> {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut counts = BTreeMap::new();
        for msg in DecoderApp::decode_lazy(file) {
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                continue;
            };
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            let n = strings(&chunk, rerun::TextLog::descriptor_text()).len();
            if store_id.is_recording() && n > 0 {
                *counts.entry(chunk.entity_path().to_string()).or_default() += n;
            }
        }
        counts
    }

    /// Every 3D view is wide enough for its title whole, and no two of a scene are titled the
    /// same.
    fn check_titles(blueprint: &Blueprint) {
        let mut seen = std::collections::BTreeSet::new();
        for view in blueprint.views_of("3D") {
            let needed = TITLE_CHROME_PX + TITLE_CHAR_PX * view.title.chars().count() as f32;
            assert!(
                view.size[0] >= needed,
                "'{}' is {:.0} px wide, its title needs {needed:.0}",
                view.title,
                view.size[0]
            );
            assert!(
                seen.insert((view.origin.clone(), view.title.clone())),
                "two views of {} titled '{}'",
                view.origin,
                view.title
            );
        }
    }

    /// Every event log in view is tall enough for its header and a row per event of its
    /// entities, and one more (it keeps the time cursor's row in view by scrolling).
    fn check_event_logs(path: &Path, blueprint: &Blueprint) {
        let counts = event_counts(path);
        let logs: Vec<&View> = blueprint.views_of("TextLog").collect();
        assert!(!logs.is_empty());
        for log in logs.iter().filter(|v| v.visible) {
            let origin = log.origin.trim_end_matches('/');
            let shown = |entity: &str| {
                if log.contents.is_empty() {
                    return entity.starts_with(origin);
                }
                log.contents.iter().any(|q| {
                    if q.starts_with('-') {
                        return false;
                    }
                    let q = q.trim_start_matches("+ ").replace("$origin", origin);
                    match q.strip_suffix("/**") {
                        Some(base) => entity == base || entity.starts_with(&format!("{base}/")),
                        None => q == entity,
                    }
                })
            };
            let n: usize = counts.iter().filter(|(e, _)| shown(e)).map(|c| c.1).sum();
            let needed = LOG_HEADER_PX + LOG_ROW_PX * (n + 1) as f32;
            assert!(
                log.size[1] >= needed,
                "'{}' is {:.0} px tall: its {n} events need {needed:.0}",
                log.title,
                log.size[1]
            );
        }
    }

    /// The phase portrait names every lane in a legend and draws ω upwards: each lane's curve
    /// mirrored in y below the view's origin, the title saying nothing of a downward axis.
    fn check_phase(path: &Path, blueprint: &Blueprint) {
        let view = blueprint
            .views_of("2D")
            .find(|v| v.origin == "/pendulum/phase")
            .expect("a phase portrait");
        assert!(!view.title.contains("down"), "{}", view.title);
        let lanes: Vec<String> = decode(path)
            .entities
            .iter()
            .filter_map(|e| e.strip_prefix("/pendulum/phase/")?.strip_suffix("/path"))
            .map(str::to_string)
            .collect();
        assert!(lanes.len() >= 2, "{lanes:?}");
        let legend: Vec<String> = labels(path)
            .into_iter()
            .filter(|(e, _)| e == "/pendulum/phase/legend")
            .flat_map(|(_, t)| t)
            .collect();
        let mut named = legend.clone();
        named.sort();
        let mut expected = lanes.clone();
        expected.sort();
        assert_eq!(named, expected, "the phase portrait's legend");
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let scale = rerun::Transform3D::descriptor_scale().component;
        let mut mirrored = std::collections::BTreeSet::new();
        for msg in DecoderApp::decode_lazy(file) {
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                continue;
            };
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            for s in chunk.iter_slices::<[f32; 3]>(scale) {
                if store_id.is_recording() && s.iter().any(|v| v[1] < 0.0) {
                    mirrored.insert(chunk.entity_path().to_string());
                }
            }
        }
        for lane in lanes.iter().map(String::as_str).chain(["legend"]) {
            assert!(
                mirrored.contains(&format!("/pendulum/phase/{lane}")),
                "{lane} is drawn with ω pointing down: {mirrored:?}"
            );
        }
    }

    /// The text of every event logged (warnings of divergence among them).
    fn event_text(path: &Path) -> String {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut text = String::new();
        for msg in DecoderApp::decode_lazy(file) {
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                continue;
            };
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            if store_id.is_recording() && chunk.entity_path().to_string().ends_with("/events") {
                for t in strings(&chunk, rerun::TextLog::descriptor_text()) {
                    text.push_str(&t);
                    text.push('\n');
                }
            }
        }
        text
    }

    /// Every 3D view shows the lanes it names, z up, with all of their drawing inside it (a lane
    /// that diverged may leave before it is stopped), and its subject (the pendulum's rod,
    /// the rope, the strands) spanning at least `fraction` of the view's height, across or down,
    /// at some frame. Returns the views' titles.
    fn check_framing(path: &Path, blueprint: &Blueprint, fraction: f32) -> Vec<String> {
        let diverged = event_text(path);
        let mut titles = Vec::new();
        for view in blueprint.views_of("3D") {
            let eye = &view.properties["EyeControls3D"];
            let position = vec3(eye, EyeControls3D::descriptor_position());
            let target = vec3(eye, EyeControls3D::descriptor_look_target());
            assert_eq!(vec3(eye, EyeControls3D::descriptor_eye_up()), glam::Vec3::Z);
            let aspect = view.size[0] / view.size[1];
            let lanes: Vec<&str> = view
                .contents
                .iter()
                .filter_map(|q| q.strip_prefix("+ $origin/")?.strip_suffix("/**"))
                .collect();
            assert!(
                !lanes.is_empty(),
                "'{}' shows no lane: {:?}",
                view.title,
                view.contents
            );
            for lane in lanes {
                let rows = drawn_rows(path, &format!("{}/{lane}/", view.origin));
                assert!(
                    !rows.is_empty(),
                    "'{}': nothing drawn for {lane}",
                    view.title
                );
                let (mut inside, mut all) = (0usize, 0usize);
                let mut span = 0.0f32;
                let mut far = glam::Vec2::ZERO; // the farthest point from the centre, per axis
                for (entity, points) in &rows {
                    let projected: Vec<glam::Vec2> = points
                        .iter()
                        .map(|p| project(glam::Vec3::from_array(*p), position, target, aspect))
                        .collect();
                    all += projected.len();
                    inside += projected
                        .iter()
                        .filter(|q| q.x.abs() <= 1.0 && q.y.abs() <= 1.0)
                        .count();
                    far = projected.iter().fold(far, |f, q| {
                        let q = q.abs();
                        glam::Vec2::new(f.x.max(q.x), f.y.max(q.y))
                    });
                    if ["/rod", "/strip", "/strands"]
                        .iter()
                        .any(|s| entity.ends_with(s))
                    {
                        // Its size on screen, in view heights: across or down, whichever is
                        // larger (a rope released level spans the view across).
                        let (lo, hi) = projected.iter().fold(
                            (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)),
                            |(lo, hi), q| (lo.min(*q), hi.max(*q)),
                        );
                        let size = 0.5 * (hi - lo);
                        span = span.max(size.y).max(size.x * aspect);
                    }
                }
                // Each label on the lane (a divergence's) inside the view, every line whole.
                for (entity, texts) in labels(path) {
                    if !entity.starts_with(&format!("{}/{lane}/", view.origin)) {
                        continue;
                    }
                    for text in texts {
                        let chars = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
                        let half =
                            (TITLE_CHAR_PX * chars as f32 + 2.0 * LABEL_MARGIN_PX) / view.size[0];
                        for (_, anchors) in drawn_rows(path, &entity) {
                            for a in anchors {
                                let q =
                                    project(glam::Vec3::from_array(a), position, target, aspect);
                                assert!(
                                    q.x.abs() + half <= 1.0 && q.y.abs() <= 1.0,
                                    "'{}': the label '{text}' reaches out of its {:.0} px view",
                                    view.title,
                                    view.size[0]
                                );
                            }
                        }
                    }
                }
                // A lane that diverged may fly off before it is stopped.
                assert!(
                    diverged.contains(&format!("{lane} diverged")) || inside == all,
                    "'{}': {lane} has {} of {all} points outside its view, as far as {far}",
                    view.title,
                    all - inside
                );
                assert!(
                    span >= fraction,
                    "'{}': {lane} spans {:.0}% of its view's height ({:.0}×{:.0} px)",
                    view.title,
                    100.0 * span,
                    view.size[0],
                    view.size[1]
                );
            }
            titles.push(view.title.clone());
        }
        titles
    }

    fn record(dir: &Path, name: &str, args: &[&str]) -> std::path::PathBuf {
        let out = dir.join(name);
        let mut all: Vec<&str> = args.to_vec();
        all.extend(["-q", "-o", out.to_str().unwrap()]);
        let (code, stdout, stderr) = physlab(&all);
        assert_eq!(code, 0, "{args:?}\n{stdout}\n{stderr}");
        out
    }

    #[test]
    fn all_opens_with_every_plot_named_and_every_subject_a_third_of_its_view_or_more() {
        let dir = scratch_dir("viewer-all");
        let out = record(&dir, "all.rrd", &["all"]);
        let blueprint = read_blueprint(&out);
        check_legends(&out, &blueprint);
        check_ticks(&out, &blueprint);
        check_titles(&blueprint);
        check_event_logs(&out, &blueprint);
        let titles = check_framing(&out, &blueprint, 1.0 / 3.0);
        // One view per lane: the reference and seven methods, seven ropes, two heads.
        assert_eq!(titles.len(), 8 + 7 + 2, "{titles:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The scenes as the screenshots show them (docs/pendulum.png, rope.png, hair.png): every
    /// plot, in view or behind a tab, with three tick labels or more on each axis.
    #[test]
    fn every_scene_plot_shows_three_tick_labels_on_each_axis() {
        let dir = scratch_dir("viewer-ticks");
        let three = [
            "pendulum",
            "--methods",
            "explicit-euler,semi-implicit-euler,verlet",
        ];
        for (name, args) in [
            ("pendulum.rrd", &three[..]),
            ("rope.rrd", &["rope"]),
            ("hair.rrd", &["hair"]),
        ] {
            let out = record(&dir, name, args);
            let blueprint = read_blueprint(&out);
            check_legends(&out, &blueprint);
            check_ticks(&out, &blueprint);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `diff -o` on two pendulum runs: B − A of the values where a log10 is plotted, no plot of
    /// a constant (the fixed steps' sizes), each lane's rod and pivot from both runs, both
    /// files named, every plot with its legend.
    #[test]
    fn a_diff_of_pendulum_runs_draws_rods_and_differences_of_values() {
        let dir = scratch_dir("viewer-diff");
        let args = [
            "pendulum",
            "--methods",
            "explicit-euler,verlet",
            "--duration",
            "4",
        ];
        let a = record(&dir, "first.rrd", &args);
        let b = record(
            &dir,
            "second.rrd",
            &[&args[..], &["--theta0", "61"]].concat(),
        );
        let d = dir.join("d.rrd");
        let (code, _, stderr) = physlab(&[
            "diff",
            a.to_str().unwrap(),
            b.to_str().unwrap(),
            "-o",
            d.to_str().unwrap(),
        ]);
        assert_eq!(code, 1, "{stderr}");
        let blueprint = read_blueprint(&d);
        check_legends(&d, &blueprint);
        check_ticks(&d, &blueprint);
        assert!(
            blueprint
                .views_of("TimeSeries")
                .all(|v| !v.origin.ends_with("/step_size")),
            "a fixed step's B − A is a constant"
        );
        let overlay = blueprint.views_of("3D").next().expect("an overlay");
        assert!(
            overlay.title.contains("first.rrd") && overlay.title.contains("second.rrd"),
            "{}",
            overlay.title
        );
        for run in ["A", "B"] {
            for part in ["rod", "pivot"] {
                let rows = drawn_rows(&d, &format!("/diff/3d/{run}/pendulum/verlet/{part}"));
                assert!(!rows.is_empty(), "{run}'s {part}");
            }
        }
        // 10^b − 10^a from the two files, at every time both hold, against the diff's value.
        let entity = "/pendulum/plots/log10_theta_error/verlet";
        let (da, db, dd) = (decode(&a), decode(&b), decode(&d));
        let at = |rows: &Vec<(i64, f64)>| rows.iter().copied().collect::<BTreeMap<i64, f64>>();
        let (ra, rb) = (at(&da.scalars[entity]), at(&db.scalars[entity]));
        let diff = &dd.scalars[&format!("/diff{entity}")];
        assert!(diff.len() > 100, "{}", diff.len());
        for (t, v) in diff {
            let expected = 10f64.powf(rb[t]) - 10f64.powf(ra[t]);
            assert!(
                (v - expected).abs() <= 1e-12 * expected.abs().max(1e-300),
                "t = {t}: {v} vs {expected}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// What a study recording draws under one entity: points (or the points of its strips),
    /// labels and whether they show, and a transform (translation, scale).
    #[derive(Debug, Default)]
    struct Drawn2D {
        points: Vec<[f32; 2]>,
        strips: Vec<Vec<[f32; 2]>>,
        labels: Vec<String>,
        show_labels: Option<bool>,
        transform: Option<([f32; 3], [f32; 3])>,
    }

    fn drawn_2d(path: &Path, prefix: &str) -> BTreeMap<String, Drawn2D> {
        use rerun::{LineStrips2D, Points2D, Transform3D};
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut drawn: BTreeMap<String, Drawn2D> = BTreeMap::new();
        for msg in DecoderApp::decode_lazy(file) {
            let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                continue;
            };
            let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
            let entity = chunk.entity_path().to_string();
            if !store_id.is_recording() || !entity.starts_with(prefix) {
                continue;
            }
            let d = drawn.entry(entity).or_default();
            let points = Points2D::descriptor_positions().component;
            d.points.extend(
                chunk
                    .iter_slices::<[f32; 2]>(points)
                    .flat_map(|s| s.to_vec()),
            );
            let strips = LineStrips2D::descriptor_strips().component;
            for s in chunk.iter_slices::<&[[f32; 2]]>(strips) {
                d.strips.extend(s.iter().map(|strip| strip.to_vec()));
            }
            d.labels
                .extend(strings(&chunk, Points2D::descriptor_labels()));
            let show = Points2D::descriptor_show_labels().component;
            if let Some(b) = chunk.iter_slices::<bool>(show).next() {
                d.show_labels = Some(b.value(0));
            }
            let [t, s] = [
                Transform3D::descriptor_translation(),
                Transform3D::descriptor_scale(),
            ]
            .map(|c| {
                chunk
                    .iter_slices::<[f32; 3]>(c.component)
                    .next()
                    .map(|v| v[0])
            });
            if let (Some(t), Some(s)) = (t, s) {
                d.transform = Some((t, s));
            }
        }
        drawn
    }

    /// A label's box on the canvas [px] as the viewer draws it: centred under its point, 5 px
    /// below it, in a box 6 px wider each side, 22 px tall (measured on screenshots: 5.8 px a
    /// character).
    fn label_box(at: [f32; 2], text: &str) -> [f32; 4] {
        let half = 0.5 * 5.8 * text.chars().count() as f32 + 6.0;
        [at[0] - half, at[1] + 1.0, at[0] + half, at[1] + 23.0]
    }

    /// Every label shown in a study's diagram `prefix`, with its box on the canvas, through its
    /// panel's transform.
    fn shown_labels(drawn: &BTreeMap<String, Drawn2D>, prefix: &str) -> Vec<(String, [f32; 4])> {
        let mut shown = Vec::new();
        for (entity, d) in drawn {
            if d.show_labels != Some(true) {
                continue;
            }
            let place = canvas_of(drawn, entity, prefix);
            for (p, text) in d.points.iter().zip(&d.labels) {
                shown.push((text.clone(), label_box(place(*p), text)));
            }
        }
        shown
    }

    /// The canvas position of a point of `entity`: through the transform of its panel, if any.
    fn canvas_of(
        drawn: &BTreeMap<String, Drawn2D>,
        entity: &str,
        prefix: &str,
    ) -> impl Fn([f32; 2]) -> [f32; 2] {
        let panel = entity[prefix.len()..].split('/').nth(1).unwrap_or("");
        let (t, s) = drawn
            .get(&format!("{prefix}/{panel}"))
            .and_then(|d| d.transform)
            .unwrap_or(([0.0; 3], [1.0; 3]));
        move |p: [f32; 2]| [t[0] + s[0] * p[0], t[1] + s[1] * p[1]]
    }

    fn record_study(dir: &Path, kind: &[&str], csv: &Path) -> (std::path::PathBuf, String) {
        let out = dir.join(format!("{}.rrd", kind[0]));
        let mut args = vec!["study"];
        args.extend(kind);
        let (code, stdout, stderr) = physlab(
            &[
                &args[..],
                &[
                    "--scene",
                    "pendulum",
                    "--csv",
                    csv.to_str().unwrap(),
                    "-q",
                    "-o",
                    out.to_str().unwrap(),
                ],
            ]
            .concat(),
        );
        assert_eq!(code, 0, "{kind:?}\n{stdout}\n{stderr}");
        (out, stdout)
    }

    /// The study's diagram opens on the canvas it is laid out on at about its own size (its
    /// labels are drawn at a fixed size), every label shown inside it, no two overlapping.
    fn check_study_view(out: &Path, drawn: &BTreeMap<String, Drawn2D>) {
        use rerun::blueprint::components::VisualBounds2D;
        let blueprint = read_blueprint(out);
        let views: Vec<&View> = blueprint.views_of("2D").collect();
        assert_eq!(views.len(), 1, "one diagram");
        let bounds = &views[0].properties["VisualBounds2D"];
        let range =
            rerun::external::re_sdk_types::blueprint::archetypes::VisualBounds2D::descriptor_range(
            );
        let b = bounds
            .component_mono::<VisualBounds2D>(range.component, 0)
            .unwrap()
            .unwrap();
        let (x, y) = (b.0.x_range.0, b.0.y_range.0);
        let [w, h] = views[0].size;
        let scale = (w / (x[1] - x[0]) as f32).min(h / (y[1] - y[0]) as f32);
        assert!(
            (0.95..1.1).contains(&scale),
            "drawn at {scale:.2} of its canvas"
        );
        let labels = shown_labels(drawn, "/study/diagrams/0");
        assert!(labels.len() > 20, "{labels:?}");
        for (i, (text, r)) in labels.iter().enumerate() {
            assert!(
                r[0] >= x[0] as f32
                    && r[2] <= x[1] as f32
                    && r[1] >= y[0] as f32
                    && r[3] <= y[1] as f32,
                "'{text}' at {r:?} is outside the view's {x:?} × {y:?}"
            );
            for (other, q) in &labels[i + 1..] {
                let apart = r[2] <= q[0] || q[2] <= r[0] || r[3] <= q[1] || q[3] <= r[1];
                assert!(apart, "'{text}' {r:?} and '{other}' {q:?} overlap");
            }
        }
    }

    /// The number after `word ` in a hover text.
    fn number_after(text: &str, word: &str) -> f64 {
        let at = text
            .find(&format!("{word} "))
            .unwrap_or_else(|| panic!("{word} in {text}"));
        text[at + word.len() + 1..]
            .split([' ', '\n', ','])
            .next()
            .unwrap()
            .parse()
            .unwrap()
    }

    /// A study recording draws its diagram from data: each run of the CSV a point at
    /// (log10 cost, log10 error) in its method's colour, joined by its method's line, whose
    /// hover text names the method and says its error, wall time and evaluations as the CSV
    /// does, and the scene command that makes the run; the reference floor a flat line at the floor the study prints; decade grid lines and
    /// tick labels; every label readable at 1600×1000.
    #[test]
    fn a_study_recording_draws_every_run_as_a_point_that_says_which_run_it_is() {
        let dir = scratch_dir("viewer-study");
        let csv = dir.join("runs.csv");
        let (out, stdout) = record_study(&dir, &["work-precision", "--repeats", "1"], &csv);
        let drawn = drawn_2d(&out, "/study/diagrams/0");
        check_study_view(&out, &drawn);
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut runs: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            if let Ok(error) = f[4].parse::<f64>() {
                let (evals, wall): (f64, f64) = (f[5].parse().unwrap(), f[8].parse().unwrap());
                // Runs stepping across the samples (above the coarsest level, 0.02 s) and a
                // composition's compensated runs are series of their own.
                let mut name = f[1].to_string();
                if f[3].is_empty() && f[2].parse::<f64>().unwrap() > 0.02 * (1.0 + 1e-9) {
                    name.push_str(" --step");
                }
                if f[10] == "true" {
                    name.push_str(" compensated");
                }
                runs.entry(name).or_default().push(vec![wall, evals, error]);
            }
        }
        assert!(runs.len() >= 10, "{runs:?}");
        for (method, rows) in &runs {
            for (panel, cost) in [(0, 0), (1, 1)] {
                // An entity path writes a space in a name escaped.
                let part = method.replace(' ', "\\ ");
                let entity = format!("/study/diagrams/0/panel{panel}/runs/{part}");
                let points = &drawn[&entity];
                let expected: Vec<[f32; 2]> = rows
                    .iter()
                    .map(|r| [r[cost].log10() as f32, r[2].log10() as f32])
                    .collect();
                assert_eq!(points.points.len(), expected.len(), "{entity}");
                for (p, e) in points.points.iter().zip(&expected) {
                    assert!(
                        (p[0] - e[0]).abs() < 1e-5 && (p[1] - e[1]).abs() < 1e-5,
                        "{entity}: {p:?} for {e:?}"
                    );
                }
                // A series stepping across the samples is dashed: its line in pieces.
                let line = &drawn[&format!("{entity}/line")].strips;
                match method.contains("--step") {
                    true => assert!(line.len() >= points.points.len() - 1, "{entity}"),
                    false => assert_eq!(line, &vec![points.points.clone()]),
                }
                assert_eq!(
                    points.show_labels,
                    Some(false),
                    "{entity}: shown on hover only"
                );
                for (about, r) in points.labels.iter().zip(rows) {
                    assert!(
                        about.starts_with(method.split(' ').next().unwrap()),
                        "{about}"
                    );
                    let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-3;
                    assert!(close(number_after(about, "error"), r[2]), "{about}: {r:?}");
                    assert!(close(number_after(about, "wall"), r[0]), "{about}: {r:?}");
                    assert!(
                        about.contains(&format!("{} force evaluations", r[1])),
                        "{about}"
                    );
                    let plain = method.split(' ').next().unwrap();
                    let made = format!("made by: physlab pendulum --methods {plain} ");
                    assert!(about.contains(&made), "{about}");
                }
            }
        }
        // The floor: a flat dashed line across the panel at the floor the header names (a dash
        // every 11 px across a panel about 540 px wide).
        let floor = &drawn["/study/diagrams/0/panel0/guides"];
        let ys: Vec<f32> = floor.strips.iter().flatten().map(|p| p[1]).collect();
        assert!(ys.iter().all(|y| *y == ys[0]) && floor.strips.len() > 45);
        let said = "(the floor) is ";
        let at = stdout.find(said).expect("the header names the floor") + said.len();
        let named: f64 = stdout[at..].split(':').next().unwrap().parse().unwrap();
        assert!(
            (named.log10() - f64::from(ys[0])).abs() < 0.05,
            "floor drawn at 1e{}, named {named}: {stdout}",
            ys[0]
        );
        // The decades: a grid line and a label for each.
        let grid = &drawn["/study/diagrams/0/panel1/grid/decades"];
        let ticks = &drawn["/study/diagrams/0/panel1/ticks"].labels;
        let verticals: Vec<f32> = (grid.strips.iter())
            .filter(|s| s[0][0] == s[1][0])
            .map(|s| s[0][0])
            .collect();
        assert!(verticals.len() >= 4, "{verticals:?}");
        for x in verticals {
            assert_eq!(x.fract(), 0.0, "a decade line at 10^{x}");
            let label = physlab::diagram::decade_label(x as i32);
            assert!(ticks.contains(&label), "{label} among {ticks:?}");
        }

        // Convergence: each slope guide rises p decades per decade of dt, as its name says.
        let (out, _) = record_study(&dir, &["convergence"], &csv);
        let drawn = drawn_2d(&out, "/study/diagrams/0");
        check_study_view(&out, &drawn);
        let guides = &drawn["/study/diagrams/0/panel0/guides"];
        let names = &drawn["/study/diagrams/0/panel0/guides/names"].labels;
        let slopes: Vec<f32> = (guides.strips.iter())
            .map(|s| (s[1][1] - s[0][1]) / (s[1][0] - s[0][0]))
            .collect();
        for p in [1, 2, 4] {
            assert!(
                names.contains(&format!(
                    "~ dt{}",
                    physlab::diagram::decade_label(p).trim_start_matches("10")
                )),
                "{names:?}"
            );
            assert!(
                slopes.iter().any(|s| (s - p as f32).abs() < 1e-3),
                "slope {p}: {slopes:?}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn other_method_sets_get_legends_and_framing_by_the_same_rule() {
        let dir = scratch_dir("viewer-methods");
        // Adaptive methods, the names of unequal length, a scene each of its own.
        let out = record(
            &dir,
            "all.rrd",
            &[
                "all",
                "--methods",
                "rk4,dop853,yoshida4,semi-implicit-euler,ftl",
            ],
        );
        let blueprint = read_blueprint(&out);
        check_legends(&out, &blueprint);
        check_ticks(&out, &blueprint);
        let titles = check_framing(&out, &blueprint, 1.0 / 3.0);
        // The pendulum's reference and four methods, the rope's four, the hair's two.
        assert_eq!(titles.len(), 5 + 4 + 2, "{titles:?}");

        // Alone, every method of the registry with the reference: plots that cannot all hold
        // their legend share a place as tabs; an adaptive method's step sizes are laid out.
        let methods: Vec<&str> = physlab::integrate::Method::ALL
            .iter()
            .map(|m| m.name())
            .collect();
        let pendulum = record(
            &dir,
            "pendulum.rrd",
            &[
                "pendulum",
                "--methods",
                &methods.join(","),
                "--duration",
                "4",
            ],
        );
        let blueprint = read_blueprint(&pendulum);
        check_legends(&pendulum, &blueprint);
        check_ticks(&pendulum, &blueprint);
        check_titles(&blueprint);
        check_event_logs(&pendulum, &blueprint);
        check_phase(&pendulum, &blueprint);
        check_framing(&pendulum, &blueprint, 1.0 / 3.0);
        let step = blueprint
            .views_of("TimeSeries")
            .filter(|v| v.origin.ends_with("/step_size"))
            .count();
        assert_eq!(step, 1, "the step-size plot with adaptive methods");

        // The default pendulum runs no adaptive method: its step sizes are all dt, not laid out.
        let default = record(&dir, "default.rrd", &["pendulum", "--duration", "4"]);
        let blueprint = read_blueprint(&default);
        check_legends(&default, &blueprint);
        check_ticks(&default, &blueprint);
        check_titles(&blueprint);
        check_phase(&default, &blueprint);
        check_framing(&default, &blueprint, 1.0 / 3.0);

        // One method: its error plot holds one series, named in a legend all the same; a hair
        // run whose stretch is not round-off (springs) keeps that plot in view.
        let one = record(
            &dir,
            "one.rrd",
            &["pendulum", "--methods", "rk4", "--duration", "2"],
        );
        let blueprint = read_blueprint(&one);
        check_legends(&one, &blueprint);
        check_ticks(&one, &blueprint);
        let springs = record(
            &dir,
            "springs.rrd",
            &[
                "hair",
                "--methods",
                "ftl,semi-implicit-euler",
                "--duration",
                "0.5",
            ],
        );
        let blueprint = read_blueprint(&springs);
        check_legends(&springs, &blueprint);
        check_ticks(&springs, &blueprint);
        check_titles(&blueprint);
        assert!(
            blueprint
                .views_of("TimeSeries")
                .any(|v| v.visible && v.origin.ends_with("/log10_max_stretch")),
            "springs stretch: the plot in view"
        );
        assert!(
            blueprint
                .views_of("TimeSeries")
                .all(|v| !v.origin.ends_with("/step_size"))
        );

        // The rope overlaid: one view, every rope in it.
        let rope = record(
            &dir,
            "rope.rrd",
            &["rope", "--layout", "overlay", "--duration", "2"],
        );
        let blueprint = read_blueprint(&rope);
        check_legends(&rope, &blueprint);
        check_ticks(&rope, &blueprint);
        assert_eq!(check_framing(&rope, &blueprint, 1.0 / 3.0).len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

mod palette {
    //! One colour per method that a person tells apart from every other on the viewer's dark
    //! background, by the CIE L*a*b* distance of sRGB colours (D65).

    use physlab::integrate::Method;
    use physlab::palette::method_color;

    /// CIE L*a*b* of an sRGB colour.
    fn lab([r, g, b]: [u8; 3]) -> [f64; 3] {
        let linear = |c: u8| {
            let c = f64::from(c) / 255.0;
            if c > 0.04045 {
                ((c + 0.055) / 1.055).powf(2.4)
            } else {
                c / 12.92
            }
        };
        let (r, g, b) = (linear(r), linear(g), linear(b));
        let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
        let f = |t: f64| {
            if t > 0.008856 {
                t.cbrt()
            } else {
                7.787 * t + 16.0 / 116.0
            }
        };
        [
            116.0 * f(y) - 16.0,
            500.0 * (f(x) - f(y)),
            200.0 * (f(y) - f(z)),
        ]
    }

    fn distance(a: [u8; 3], b: [u8; 3]) -> f64 {
        let (a, b) = (lab(a), lab(b));
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    /// The hue angle between two colours [degrees], 0 to 180.
    fn hue_apart(a: [u8; 3], b: [u8; 3]) -> f64 {
        let hue = |c: [u8; 3]| {
            let [_, a, b] = lab(c);
            b.atan2(a).to_degrees()
        };
        let d = (hue(a) - hue(b)).rem_euclid(360.0);
        d.min(360.0 - d)
    }

    #[test]
    fn each_method_has_a_colour_apart_from_every_other() {
        let mut lanes: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        lanes.extend(["ftl", "exact", "reference"]);
        for (i, a) in lanes.iter().enumerate() {
            // Bright enough on the 3D views' background and the plots' black.
            assert!(distance(method_color(a), [24, 24, 28]) > 60.0, "{a}");
            for b in &lanes[i + 1..] {
                if [*a, *b] == ["exact", "reference"] {
                    continue; // one lane under two names, never both in a run
                }
                let d = distance(method_color(a), method_color(b));
                assert!(d >= 30.0, "{a} and {b}: ΔE = {d:.0}");
            }
        }
        // The methods a scene runs by default differ in hue as well (orange and brown, red and
        // pink were told apart by lightness alone).
        let defaults: Vec<&str> = Method::ALL
            .iter()
            .filter(|m| m.info().default)
            .map(|m| m.name())
            .collect();
        assert!(defaults.len() >= 7, "{defaults:?}");
        for (i, a) in defaults.iter().enumerate() {
            for b in &defaults[i + 1..] {
                let h = hue_apart(method_color(a), method_color(b));
                assert!(h >= 25.0, "{a} and {b}: hues {h:.0}° apart");
            }
        }
    }
}
