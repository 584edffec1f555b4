//! A log-log plot ([`crate::diagram::Plot`]) as Rerun 2D primitives, since Rerun has no log
//! axes: each panel an entity whose children hold log10 coordinates and whose transform places
//! the decades on a canvas of about the view's pixels; lines as line strips, text as labelled
//! points (the viewer draws a label centred below its point); each run a point whose hidden
//! label, shown on hover, says what run it is.

use rerun::components::{DrawOrder, Radius};
use rerun::{LineStrips2D, Points2D, RecordingStream, Transform3D};

use crate::diagram::{Panel, Plot, Series, decade_label, log_axis};
use crate::report::table::wrap;

/// The canvas a plot is drawn on: the study tab's view at 1600×1000 [view units ≈ logical px].
pub const CANVAS: [f32; 2] = [1600.0, 915.0];
/// A label's character width and line height in the viewer [logical px], on screenshots.
const CHAR_PX: f32 = 5.8;
const LINE_PX: f32 = 18.0;
/// Room around a panel's plotting area [px]: left for the value labels, below for the cost's
/// labels and name, above for the title and the error's name.
const LEFT: f32 = 70.0;
const RIGHT: f32 = 24.0;
const TOP: f32 = 64.0;
const BOTTOM: f32 = 62.0;

const INK: [u8; 3] = [225, 225, 225];
const GRID: [u8; 3] = [95, 100, 110];
const FAINT: [u8; 3] = [58, 62, 70];
const GUIDE: [u8; 3] = [170, 170, 170];
/// The inside of a hollow marker: the viewer's 2D background.
const HOLE: [u8; 3] = [13, 16, 17];

/// Logs `plot` under `base`, drawn on [`CANVAS`].
pub fn log_plot(rec: &RecordingStream, base: &str, plot: &Plot) -> anyhow::Result<()> {
    let body = CANVAS[0] - plot.legend_px as f32;
    let width = body / plot.panels.len().max(1) as f32;
    // Rows' names (stability's methods) need more room at the left than decades' labels.
    let names = plot.panels.iter().flat_map(|p| &p.y_names);
    let left = names.fold(LEFT, |l, n| {
        l.max(CHAR_PX * n.chars().count() as f32 + 24.0)
    });
    for (i, panel) in plot.panels.iter().enumerate() {
        let area = [
            i as f32 * width + left,
            TOP,
            (i + 1) as f32 * width - RIGHT,
            CANVAS[1] - BOTTOM,
        ];
        log_panel(rec, &format!("{base}/panel{i}"), panel, area)?;
    }
    log_legend(rec, &format!("{base}/legend"), plot, body + 16.0)
}

/// Labels at `at` (one per point) in `color`, always shown, with no visible point.
fn labels(at: Vec<[f32; 2]>, text: Vec<String>, color: [u8; 3]) -> Points2D {
    Points2D::new(at)
        .with_labels(text)
        .with_colors([color])
        .with_radii([Radius::new_ui_points(0.0)])
        .with_show_labels(true)
}

fn lines(strips: Vec<Vec<[f32; 2]>>, color: [u8; 3], width: f32, order: f32) -> LineStrips2D {
    LineStrips2D::new(strips)
        .with_colors([color])
        .with_radii([Radius::new_ui_points(0.5 * width)])
        .with_draw_order(DrawOrder(order.into()))
}

/// One panel in the canvas rectangle `area` (left, top, right, bottom).
fn log_panel(rec: &RecordingStream, path: &str, p: &Panel, area: [f32; 4]) -> anyhow::Result<()> {
    let (x0, x1, y0, y1) = (p.x.start, p.x.end, p.y.start, p.y.end);
    // Canvas px per decade; the canvas' y grows downwards, the error upwards.
    let sx = (area[2] - area[0]) / (x1 - x0) as f32;
    let sy = (area[3] - area[1]) / (y1 - y0) as f32;
    rec.log_static(
        path,
        &Transform3D::from_translation_scale(
            [area[0] - x0 as f32 * sx, area[3] + y0 as f32 * sy, 0.0],
            [sx, -sy, 1.0],
        ),
    )?;
    let (x0, x1, y0, y1) = (x0 as f32, x1 as f32, y0 as f32, y1 as f32);
    let (bold_x, light_x) = log_axis(p.x.clone());
    let (bold_y, light_y) = p.y_ticks();
    let vertical = |x: &f64| vec![[*x as f32, y0], [*x as f32, y1]];
    let horizontal = |y: &f64| vec![[x0, *y as f32], [x1, *y as f32]];
    let strips = |xs: &[f64], ys: &[f64]| -> Vec<Vec<[f32; 2]>> {
        xs.iter()
            .map(vertical)
            .chain(ys.iter().map(horizontal))
            .collect()
    };
    rec.log_static(
        format!("{path}/grid/minor"),
        &lines(strips(&light_x, &light_y), FAINT, 1.0, 1.0),
    )?;
    rec.log_static(
        format!("{path}/grid/decades"),
        &lines(strips(&bold_x, &bold_y), GRID, 1.0, 2.0),
    )?;
    let frame = vec![[x0, y1], [x0, y0], [x1, y0]];
    rec.log_static(
        format!("{path}/grid/axes"),
        &lines(vec![frame], INK, 1.5, 2.0),
    )?;
    // Tick labels: under the cost axis, left of the error axis (a label's top is 5 px below
    // its point, centred on it).
    let ticks: Vec<([f32; 2], String)> = (bold_x.iter())
        .map(|&k| ([k as f32, y0 - 8.0 / sy], decade_label(k.round() as i32)))
        .chain(bold_y.iter().map(|&k| {
            let text = match p.y_names.get(k as usize) {
                Some(name) => name.clone(),
                None => decade_label(k.round() as i32),
            };
            let half = 0.5 * CHAR_PX * text.chars().count() as f32;
            ([x0 - (half + 10.0) / sx, k as f32 + 14.0 / sy], text)
        }))
        .collect();
    let (at, text) = ticks.into_iter().unzip();
    rec.log_static(format!("{path}/ticks"), &labels(at, text, INK))?;
    // The title and the error's name above the panel from its left edge (the error's right
    // of the top tick label), the cost's name centred below the tick labels.
    let from_left = |s: &str, x: f32, y: f32| {
        let half = 0.5 * CHAR_PX * s.chars().count() as f32;
        ([x0 + (half + x) / sx, y1 + y / sy], s.to_string())
    };
    let names = [
        from_left(&p.title, -40.0, TOP - LINE_PX),
        from_left(p.y_desc, 4.0, 2.0 + LINE_PX),
        ([0.5 * (x0 + x1), y0 - 34.0 / sy], p.x_desc.to_string()),
    ];
    let (at, text) = names.into_iter().unzip();
    rec.log_static(format!("{path}/names"), &labels(at, text, INK))?;
    log_guides(rec, path, p, [sx, sy])?;
    for s in &p.series {
        log_series(rec, path, s, [sx, sy])?;
    }
    Ok(())
}

/// One series: its points (each saying on hover which run it is) and the line through them,
/// dashed for a series stepping across the samples; a compensated one's points hollow (a dot of
/// the view's background inside each).
fn log_series(rec: &RecordingStream, path: &str, s: &Series, px: [f32; 2]) -> anyhow::Result<()> {
    let (at, about): (Vec<[f32; 2]>, Vec<String>) = (s.points.iter().zip(&s.about))
        .filter(|((x, y), _)| *x > 0.0 && *y > 0.0)
        .map(|((x, y), about)| ([x.log10() as f32, y.log10() as f32], about.clone()))
        .unzip();
    let color = s.key.rgb();
    // One path part whatever the name holds (a hair family's "k/m", say).
    let name = rerun::EntityPath::new(vec![s.key.name.as_str().into()]);
    let entity = rerun::EntityPath::from(format!("{path}/runs")).join(&name);
    let strips = match s.key.dashed {
        true => (at.windows(2))
            .flat_map(|w| dashed(w[0], w[1], px))
            .collect(),
        false => vec![at.clone()],
    };
    rec.log_static(entity.join(&"line".into()), &lines(strips, color, 2.0, 3.0))?;
    if s.key.hollow {
        rec.log_static(entity.join(&"holes".into()), &holes(at.clone(), 4.5))?;
    }
    rec.log_static(
        entity,
        &Points2D::new(at)
            .with_colors([color])
            .with_radii([Radius::new_ui_points(4.5)])
            .with_labels(about)
            .with_show_labels(false)
            .with_draw_order(DrawOrder(4.0.into())),
    )?;
    Ok(())
}

/// The insides of hollow markers at `at`: dots of the view's background, drawn at `order`.
fn holes(at: Vec<[f32; 2]>, order: f32) -> Points2D {
    Points2D::new(at)
        .with_colors([HOLE])
        .with_radii([Radius::new_ui_points(2.0)])
        .with_draw_order(DrawOrder(order.into()))
}

/// The guides (the reference floor, the slopes) as dashed grey lines, each named above its
/// last point, on the side towards the panel's middle.
fn log_guides(rec: &RecordingStream, path: &str, p: &Panel, px: [f32; 2]) -> anyhow::Result<()> {
    let mut dashes = Vec::new();
    let mut ends = Vec::new();
    for (points, name) in &p.guides {
        let strip: Vec<[f32; 2]> = (points.iter())
            .filter(|(x, y)| *x > 0.0 && *y > 0.0)
            .map(|(x, y)| [x.log10() as f32, y.log10() as f32])
            .collect();
        // Cut where it leaves the panel: a slope may run past the top or the bottom.
        let (lo, hi) = (p.y.start as f32, p.y.end as f32);
        let cut: Vec<[[f32; 2]; 2]> = (strip.windows(2))
            .filter_map(|w| clip(w[0], w[1], lo, hi))
            .collect();
        for [a, b] in &cut {
            dashes.extend(dashed(*a, *b, px));
        }
        if let Some([_, [x, y]]) = cut.last().filter(|_| !name.is_empty()) {
            let name = shown(name);
            let half = (0.5 * CHAR_PX * name.chars().count() as f32 + 24.0) / px[0];
            let inward = if f64::from(*x) < 0.5 * (p.x.start + p.x.end) {
                half
            } else {
                -half
            };
            ends.push(([x + inward, (y + 26.0 / px[1]).min(hi)], name));
        }
    }
    if dashes.is_empty() {
        return Ok(());
    }
    rec.log_static(format!("{path}/guides"), &lines(dashes, GUIDE, 1.0, 2.5))?;
    let (at, text) = ends.into_iter().unzip();
    rec.log_static(format!("{path}/guides/names"), &labels(at, text, GUIDE))?;
    Ok(())
}

/// The part of the segment from `a` to `b` with `lo` ≤ y ≤ `hi`, if any.
fn clip(a: [f32; 2], b: [f32; 2], lo: f32, hi: f32) -> Option<[[f32; 2]; 2]> {
    if (a[1] > hi && b[1] > hi) || (a[1] < lo && b[1] < lo) {
        return None;
    }
    // An end outside moves along the segment to the edge it crosses (the ends' y then differ).
    let onto = |p: [f32; 2]| {
        let y = p[1].clamp(lo, hi);
        if y == p[1] {
            p
        } else {
            [a[0] + (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]), y]
        }
    };
    Some([onto(a), onto(b)])
}

/// Text as the viewer's font can show it: it has no "∝".
fn shown(text: &str) -> String {
    text.replace('∝', "~")
}

/// The line from `a` to `b` (log10 coordinates, `px` canvas px per decade along x and y) as
/// dashes of 6 px, 5 px apart, as the pictures draw their guides.
fn dashed(a: [f32; 2], b: [f32; 2], px: [f32; 2]) -> Vec<Vec<[f32; 2]>> {
    let length = ((b[0] - a[0]) * px[0]).hypot((b[1] - a[1]) * px[1]);
    let at = |d: f32| {
        let f = (d / length).min(1.0);
        [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
    };
    let n = (length / 11.0).ceil() as usize;
    (0..n)
        .map(|i| vec![at(11.0 * i as f32), at(11.0 * i as f32 + 6.0)])
        .collect()
}

/// The legend: per key a short line and dot in its colour and its name right of them; the
/// notes below, wrapped to the column.
fn log_legend(rec: &RecordingStream, path: &str, plot: &Plot, left: f32) -> anyhow::Result<()> {
    let mut y = TOP;
    let mut swatches = Vec::new();
    let mut colors = Vec::new();
    let mut names = Vec::new();
    // Many keys (a method's variants each its own) closer together.
    let pitch = LINE_PX + if plot.keys.len() > 24 { 4.0 } else { 6.0 };
    for key in &plot.keys {
        let ends = [[left, y], [left + 30.0, y]];
        // A dashed key's swatch in two dashes, either side of its dot.
        if key.dashed {
            swatches.extend([
                vec![ends[0], [left + 9.0, y]],
                vec![[left + 21.0, y], ends[1]],
            ]);
            colors.extend([key.rgb(), key.rgb()]);
        } else {
            swatches.push(ends.to_vec());
            colors.push(key.rgb());
        }
        let half = 0.5 * CHAR_PX * key.name.chars().count() as f32;
        names.push(([left + 42.0 + half, y - 13.0], key.name.clone()));
        y += pitch;
    }
    let marks: Vec<[f32; 2]> = (0..plot.keys.len())
        .map(|i| [left + 15.0, TOP + i as f32 * pitch])
        .collect();
    let mark_colors: Vec<[u8; 3]> = plot.keys.iter().map(|k| k.rgb()).collect();
    rec.log_static(
        format!("{path}/swatches"),
        &LineStrips2D::new(swatches)
            .with_colors(colors.clone())
            .with_radii([Radius::new_ui_points(1.5)]),
    )?;
    rec.log_static(
        format!("{path}/swatches/marks"),
        &Points2D::new(marks.clone())
            .with_colors(mark_colors)
            .with_radii([Radius::new_ui_points(4.5)]),
    )?;
    let hollow: Vec<[f32; 2]> = (marks.iter().zip(&plot.keys))
        .filter(|(_, k)| k.hollow)
        .map(|(m, _)| *m)
        .collect();
    rec.log_static(format!("{path}/swatches/holes"), &holes(hollow, 31.0))?;
    let (at, text) = names.into_iter().unzip();
    rec.log_static(format!("{path}/names"), &labels(at, text, INK))?;
    let chars = ((plot.legend_px as f32 - 24.0) / CHAR_PX) as usize;
    let mut notes = Vec::new();
    y += LINE_PX;
    for line in plot.notes.iter().flat_map(|n| wrap(&shown(n), chars)) {
        let half = 0.5 * CHAR_PX * line.chars().count() as f32;
        notes.push(([left + half, y], line));
        y += LINE_PX + 4.0;
    }
    let (at, text) = notes.into_iter().unzip();
    Ok(rec.log_static(format!("{path}/notes"), &labels(at, text, [180, 180, 180]))?)
}
