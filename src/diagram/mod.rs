//! The studies' diagrams as pictures: log-log work-precision (error against wall time and
//! against force evaluations), convergence (error against dt with reference slopes) and
//! stability (measured limit against theory), drawn with `plotters` into SVG and PNG.
//!
//! Axes are in decades (ticks at every power of ten, faint lines at 2…9 × 10ᵏ), every axis has
//! its unit, each method has its colour from [`crate::palette`] (the recordings' colours), and the
//! legend stands in its own column to the right of the plots, so it never covers data. The
//! background is the Rerun viewer's dark grey, which the palette was chosen for. Text uses the
//! DejaVu Sans shipped under `assets/fonts/` (Bitstream Vera licence, see the LICENSE file
//! there), registered from bytes, so no system font or C library is needed.
//!
//! Behind the `diagrams` cargo feature (on with `rerun`): the core builds without plotters.

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::integrate::Method;
use crate::palette::method_color;
use crate::study::{Limit, Row};

const FONT: &str = "sans-serif";
const BACKGROUND: RGBColor = RGBColor(24, 26, 30);
const PANEL: RGBColor = RGBColor(32, 35, 40);
const INK: RGBColor = RGBColor(225, 225, 225);
const FAINT: RGBColor = RGBColor(70, 74, 82);
const GRID: RGBColor = RGBColor(95, 100, 110);
const LEGEND_WIDTH: u32 = 250;

/// A diagram: its file stem (`<scene>-<study>`), size and what it shows.
pub struct Diagram {
    pub stem: String,
    pub title: String,
    pub size: (u32, u32),
    content: Content,
}

enum Content {
    WorkPrecision {
        scene: String,
        rows: Vec<Row>,
        floor: f64,
        note: String,
    },
    Convergence {
        scene: String,
        rows: Vec<Row>,
        floor: f64,
        velocity_dependent: bool,
    },
    Stability {
        scene: String,
        limits: Vec<LimitRow>,
        omega: f64,
    },
}

/// The files a diagram was written to, and the PNG's bytes (for the recording).
pub struct Written {
    pub svg: PathBuf,
    pub png: PathBuf,
    pub png_bytes: Vec<u8>,
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The shipped font parses (the tests draw diagrams with it).
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            include_bytes!("../../assets/fonts/DejaVuSans.ttf"),
        );
    });
}

impl Diagram {
    /// The files it is written to in `dir`: `<stem>.svg` and `<stem>.png`.
    pub fn files(stem: &str, dir: &Path) -> [PathBuf; 2] {
        [
            dir.join(format!("{stem}.svg")),
            dir.join(format!("{stem}.png")),
        ]
    }

    /// Writes `<dir>/<stem>.svg` and `<dir>/<stem>.png`, each whole or not at all
    /// (`crate::output`).
    pub fn write(&self, dir: &Path) -> anyhow::Result<Written> {
        use crate::output::{Dash, check};
        register_font();
        let [svg, png] = Self::files(&self.stem, dir);
        let no_dash = Dash::Refused("is not a folder; --plots names the folder of the diagrams");
        let (svg_out, png_out) = (
            check("--plots", &svg, no_dash)?,
            check("--plots", &png, no_dash)?,
        );
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, self.size).into_drawing_area();
            self.draw(&root).map_err(err)?;
            root.present().map_err(|e| err(Box::new(e)))?;
        }
        svg_out.write(text.as_bytes())?;
        // plotters encodes the PNG into a path, by its extension: the hidden file of the
        // atomic write, named `.NAME.PID.partial.png`.
        let partial = png_out.create_keeping_extension()?;
        let hidden = partial.path().context("a diagram's PNG goes to a file")?;
        {
            let root = BitMapBackend::new(hidden, self.size).into_drawing_area();
            self.draw(&root).map_err(err)?;
            root.present().map_err(|e| {
                let e = e.to_string();
                let disk_full = e.contains("No space left on device");
                anyhow::anyhow!(
                    "{}: cannot write it: {}{e}; the previous file, if any, is unchanged",
                    png_out.named(),
                    if disk_full { "disk full: " } else { "" }
                )
            })?;
        }
        let png_bytes = std::fs::read(hidden)
            .with_context(|| format!("{}: cannot read it back", png_out.named()))?;
        partial.commit()?;
        Ok(Written {
            svg,
            png,
            png_bytes,
        })
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Res
    where
        DB::ErrorType: 'static,
    {
        match &self.content {
            Content::WorkPrecision {
                scene,
                rows,
                floor,
                note,
            } => work_precision_on(root, scene, rows, *floor, note),
            Content::Convergence {
                scene,
                rows,
                floor,
                velocity_dependent,
            } => convergence_on(root, scene, rows, *floor, *velocity_dependent),
            Content::Stability {
                scene,
                limits,
                omega,
            } => stability_on(root, scene, limits, *omega),
        }
    }
}

type Res = Result<(), Box<dyn std::error::Error>>;

fn err(e: Box<dyn std::error::Error>) -> anyhow::Error {
    anyhow::anyhow!("drawing a diagram: {e}")
}

fn color(m: Method) -> RGBColor {
    let [r, g, b] = method_color(m.name());
    RGBColor(r, g, b)
}

/// A filled marker for method `m` at pixel offset (0, 0): a shape per method (by its place in
/// the registry), so methods whose curves coincide still show both.
fn marker(m: Method, size: f64) -> Polygon<(i32, i32)> {
    let k = Method::ALL.iter().position(|&x| x == m).unwrap_or(0);
    // (sides, rotation in turns, scale): circle, triangle up, square, diamond, triangle down,
    // pentagon, hexagon, …
    let shapes = [
        (16, 0.0, 1.0),
        (3, 0.25, 1.3),
        (4, 0.125, 1.2),
        (4, 0.0, 1.35),
        (3, 0.75, 1.3),
        (5, 0.25, 1.2),
        (6, 0.0, 1.15),
        (8, 0.0625, 1.1),
    ];
    let (sides, turn, scale) = shapes[k % shapes.len()];
    let r = size * scale;
    let c = color(m);
    Polygon::new(
        (0..sides)
            .map(|i| {
                let a = std::f64::consts::TAU * (turn + f64::from(i) / f64::from(sides));
                ((r * a.cos()).round() as i32, (-r * a.sin()).round() as i32)
            })
            .collect::<Vec<_>>(),
        c.filled(),
    )
}

/// 10ᵏ with a superscript exponent.
pub fn decade_label(k: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
}

/// The decades spanning `values` (log10, whole decades, at least one).
fn decades(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .map(f64::log10)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let (lo, hi) = ((lo - 0.02).floor(), (hi + 0.02).ceil());
    lo..hi.max(lo + 1.0)
}

/// Ticks at every decade (every second or third one when there are many, labelled), faint
/// lines at 2…9 × 10ᵏ when the axis spans few decades.
fn log_axis(range: Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.start as i32, range.end as i32);
    let span = hi - lo;
    let step = if span > 16 {
        3
    } else if span > 9 {
        2
    } else {
        1
    };
    let bold: Vec<f64> = (lo..=hi)
        .filter(|k| (k - lo) % step == 0)
        .map(f64::from)
        .collect();
    let light: Vec<f64> = if span <= 9 {
        (lo..hi)
            .flat_map(|k| (2..10).map(move |m| f64::from(k) + f64::from(m).log10()))
            .collect()
    } else {
        (lo..=hi).map(f64::from).collect()
    };
    (bold, light)
}

/// A linear axis over log10 values (or category indices) with the ticks given: bold ones
/// labelled, light ones drawn faint.
#[derive(Clone)]
struct Ticks {
    range: Range<f64>,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl Ticks {
    fn decades(range: Range<f64>) -> Self {
        let (bold, light) = log_axis(range.clone());
        Ticks { range, bold, light }
    }
}

impl Ranged for Ticks {
    type ValueType = f64;
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.range.start) / (self.range.end - self.range.start);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }
}

fn label_of(v: &f64) -> String {
    decade_label(v.round() as i32)
}

/// One log-log panel: decades on both axes, the given series (x, y in linear units; points
/// outside (0, ∞) dropped), plus extra dashed lines with labels.
struct Panel<'a> {
    title: &'a str,
    x_desc: &'a str,
    y_desc: &'a str,
    x: Range<f64>,
    y: Range<f64>,
    series: Vec<(Method, Vec<(f64, f64)>)>,
    /// Dashed grey guides: points (linear units) and a label at the last point.
    guides: Vec<(Vec<(f64, f64)>, String)>,
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Res
where
    DB::ErrorType: 'static,
{
    area.fill(&PANEL)?;
    let mut chart = ChartBuilder::on(area)
        .caption(p.title, (FONT, 24).into_font().color(&INK))
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(78)
        .build_cartesian_2d(Ticks::decades(p.x.clone()), Ticks::decades(p.y.clone()))?;
    chart
        .configure_mesh()
        .bold_line_style(GRID.stroke_width(1))
        .light_line_style(FAINT.stroke_width(1))
        .axis_style(INK.stroke_width(1))
        .x_label_formatter(&label_of)
        .y_label_formatter(&label_of)
        .x_desc(p.x_desc)
        .y_desc(p.y_desc)
        .label_style((FONT, 18).into_font().color(&INK))
        .axis_desc_style((FONT, 19).into_font().color(&INK))
        .draw()?;
    let log = |(x, y): (f64, f64)| (x > 0.0 && y > 0.0).then(|| (x.log10(), y.log10()));
    for (pts, label) in &p.guides {
        let l: Vec<(f64, f64)> = pts.iter().copied().filter_map(log).collect();
        if l.len() < 2 {
            continue;
        }
        chart.draw_series(DashedLineSeries::new(
            l.clone(),
            6,
            5,
            RGBColor(170, 170, 170).stroke_width(1),
        ))?;
        // The label sits above the line's last point, on the side away from the plot's edge.
        let end = l[l.len() - 1];
        let h = if end.0 < l[0].0 && end.0 > p.x.start + 0.3 {
            plotters::style::text_anchor::HPos::Right
        } else {
            plotters::style::text_anchor::HPos::Left
        };
        chart.draw_series(std::iter::once(Text::new(
            label.clone(),
            end,
            (FONT, 17).into_font().color(&RGBColor(190, 190, 190)).pos(
                plotters::style::text_anchor::Pos::new(
                    h,
                    plotters::style::text_anchor::VPos::Bottom,
                ),
            ),
        )))?;
    }
    for (m, pts) in &p.series {
        let l: Vec<(f64, f64)> = pts.iter().copied().filter_map(log).collect();
        chart.draw_series(LineSeries::new(l.clone(), color(*m).stroke_width(2)))?;
        chart.draw_series(l.iter().map(|&q| EmptyElement::at(q) + marker(*m, 4.5)))?;
    }
    Ok(())
}

/// The legend column: one swatch and name per method, and notes below.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    methods: &[Method],
    notes: &[String],
) -> Res
where
    DB::ErrorType: 'static,
{
    let font = (FONT, 19).into_font().color(&INK);
    let mut y = 70;
    for &m in methods {
        area.draw(&PathElement::new(
            vec![(14, y + 10), (48, y + 10)],
            color(m).stroke_width(3),
        ))?;
        area.draw(&(EmptyElement::at((31, y + 10)) + marker(m, 5.5)))?;
        area.draw(&Text::new(m.name(), (58, y), font.clone()))?;
        y += 30;
    }
    y += 16;
    let small = (FONT, 15).into_font().color(&RGBColor(180, 180, 180));
    for n in notes {
        for line in wrap(n, 28) {
            area.draw(&Text::new(line, (14, y), small.clone()))?;
            y += 20;
        }
        y += 8;
    }
    Ok(())
}

fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.chars().count() + 1 + word.chars().count() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

fn methods_of(rows: &[Row]) -> Vec<Method> {
    let mut ms: Vec<Method> = Vec::new();
    for r in rows {
        if !ms.contains(&r.method) {
            ms.push(r.method);
        }
    }
    ms
}

/// What the error is, with its unit, for a scene.
fn error_desc(scene: &str) -> &'static str {
    match scene {
        "pendulum" => "error: max |θ − θref| [rad]",
        _ => "error: max |x − xref| over nodes [m]",
    }
}

/// Runs of one method that produced an error, in the order of their setting (dt or rtol).
fn runs(rows: &[Row], m: Method) -> Vec<&Row> {
    rows.iter()
        .filter(|r| r.method == m && r.error.is_some_and(|e| e > 0.0))
        .collect()
}

/// Work-precision: error against median wall time (left) and against force evaluations
/// (right); `floor` is the reference's error floor, drawn as a dashed line.
pub fn work_precision(scene: &str, rows: &[Row], floor: f64, note: &str) -> Diagram {
    Diagram {
        stem: format!("{scene}-work-precision"),
        title: format!("{scene} work-precision"),
        size: (1600, 820),
        content: Content::WorkPrecision {
            scene: scene.to_string(),
            rows: rows.to_vec(),
            floor,
            note: note.to_string(),
        },
    }
}

/// A work-precision panel: title, x axis description, and the cost it plots.
type Axis = (&'static str, &'static str, fn(&Row) -> f64);

fn work_precision_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &str,
    rows: &[Row],
    floor: f64,
    note: &str,
) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&BACKGROUND)?;
    let (body, legend) = root.split_horizontally(root.dim_in_pixel().0 - LEGEND_WIDTH);
    let methods = methods_of(rows);
    let errors = || rows.iter().filter_map(|r| r.error);
    let y = decades(errors().chain([floor]));
    let panels = body.split_evenly((1, 2));
    let axes: [Axis; 2] = [
        (
            "error against median wall time",
            "median wall time [s]",
            |r| r.wall_seconds,
        ),
        (
            "error against force evaluations",
            "force evaluations",
            |r| r.evals as f64,
        ),
    ];
    for (area, (title, x_desc, cost)) in panels.iter().zip(axes) {
        let x = decades(rows.iter().filter(|r| r.error.is_some()).map(cost));
        let series = methods
            .iter()
            .map(|&m| {
                (
                    m,
                    runs(rows, m)
                        .iter()
                        .map(|r| (cost(r), r.error.unwrap_or(0.0)))
                        .collect(),
                )
            })
            .collect();
        let (x0, x1) = (10f64.powf(x.start), 10f64.powf(x.end));
        draw_panel(
            &area.margin(6, 6, 6, 6),
            &Panel {
                title: &format!("{scene}: {title}"),
                x_desc,
                y_desc: error_desc(scene),
                x,
                y: y.clone(),
                series,
                guides: vec![(vec![(x1, floor), (x0, floor)], "reference floor".into())],
            },
        )?;
    }
    draw_legend(
        &legend,
        &methods,
        &[
            format!("{scene}: lower left is better."),
            format!("dashed: the reference's error floor {floor:.0e}."),
            note.to_string(),
        ],
    )
}

/// Convergence: error against dt for the fixed-step methods, with dashed reference slopes for
/// each theoretical order present; `floor` is the reference's error floor.
pub fn convergence(scene: &str, rows: &[Row], floor: f64, velocity_dependent: bool) -> Diagram {
    Diagram {
        stem: format!(
            "{scene}-convergence{}",
            if velocity_dependent { "-damped" } else { "" }
        ),
        title: format!("{scene} convergence"),
        size: (1300, 860),
        content: Content::Convergence {
            scene: scene.to_string(),
            rows: rows.iter().filter(|r| r.rtol.is_none()).cloned().collect(),
            floor,
            velocity_dependent,
        },
    }
}

fn order_of(m: Method, velocity_dependent: bool) -> u32 {
    let info = m.info();
    if velocity_dependent {
        info.order_velocity_dependent
    } else {
        info.order
    }
}

fn convergence_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &str,
    rows: &[Row],
    floor: f64,
    velocity_dependent: bool,
) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&BACKGROUND)?;
    let (body, legend) = root.split_horizontally(root.dim_in_pixel().0 - LEGEND_WIDTH);
    let methods = methods_of(rows);
    let x = decades(rows.iter().map(|r| r.dt));
    let y = decades(rows.iter().filter_map(|r| r.error).chain([floor]));
    let series = methods
        .iter()
        .map(|&m| {
            (
                m,
                runs(rows, m)
                    .iter()
                    .map(|r| (r.dt, r.error.unwrap_or(0.0)))
                    .collect(),
            )
        })
        .collect();
    // One reference slope per theoretical order, parallel to and below that order's lowest
    // curve, over the same steps (from the coarsest dt down to the finest, or to the bottom).
    let dt_max = rows.iter().map(|r| r.dt).fold(0.0, f64::max);
    let dt_min = rows.iter().map(|r| r.dt).fold(f64::INFINITY, f64::min);
    let mut orders: Vec<u32> = methods
        .iter()
        .map(|&m| order_of(m, velocity_dependent))
        .collect();
    orders.sort_unstable();
    orders.dedup();
    let (x_lo, x_hi, y_lo) = (10f64.powf(x.start), 10f64.powf(x.end), 10f64.powf(y.start));
    let mut guides: Vec<(Vec<(f64, f64)>, String)> =
        vec![(vec![(x_hi, floor), (x_lo, floor)], "reference floor".into())];
    for &p in &orders {
        let lowest = rows
            .iter()
            .filter(|r| r.dt == dt_max && order_of(r.method, velocity_dependent) == p)
            .filter_map(|r| r.error)
            .filter(|e| *e > floor)
            .fold(f64::INFINITY, f64::min);
        if !lowest.is_finite() {
            continue;
        }
        let anchor = lowest / 4.0;
        let bottom = dt_max * (y_lo / anchor).powf(1.0 / f64::from(p));
        let end = bottom.max(dt_min);
        guides.push((
            vec![
                (dt_max, anchor),
                (end, anchor * (end / dt_max).powi(p as i32)),
            ],
            format!("∝ dt{}", superscript(p)),
        ));
    }
    draw_panel(
        &body.margin(6, 6, 6, 6),
        &Panel {
            title: &format!(
                "{scene}{}: error against step size, fixed-step methods",
                if velocity_dependent {
                    ", damped (velocity-dependent forces)"
                } else {
                    ""
                }
            ),
            x_desc: "dt [s]",
            y_desc: error_desc(scene),
            x,
            y,
            series,
            guides,
        },
    )?;
    draw_legend(
        &legend,
        &methods,
        &[
            "dashed slopes: dtᵖ for each theoretical order p, a quarter below that order's lowest curve."
                .to_string(),
            format!("flat dashed: the reference's error floor {floor:.0e}."),
            "adaptive methods choose their own steps: see work-precision.".to_string(),
        ],
    )
}

fn superscript(p: u32) -> String {
    decade_label(p as i32).trim_start_matches("10").to_string()
}

/// Stability: per method, the measured largest stable dt (the method's marker) against theory
/// (a cross), on a log dt axis; unconditional and absent limits said in words.
pub fn stability(scene: &str, limits: &[Limit], omega: f64) -> Diagram {
    let limits: Vec<LimitRow> = limits
        .iter()
        .map(|l| (l.method, l.measured_dt, l.theory_dt))
        .collect();
    let height = 180 + 44 * limits.len() as u32;
    Diagram {
        stem: format!("{scene}-stability"),
        title: format!("{scene} stability"),
        size: (1300, height.max(500)),
        content: Content::Stability {
            scene: scene.to_string(),
            limits,
            omega,
        },
    }
}

type LimitRow = (Method, Option<f64>, Option<f64>);

fn stability_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &str,
    limits: &[LimitRow],
    omega: f64,
) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&BACKGROUND)?;
    let (body, legend) = root.split_horizontally(root.dim_in_pixel().0 - LEGEND_WIDTH);
    let finite = limits
        .iter()
        .flat_map(|(_, m, t)| [*m, *t])
        .flatten()
        .filter(|v| v.is_finite());
    let x = decades(finite);
    let n = limits.len();
    let names: Vec<String> = limits.iter().map(|l| l.0.name().to_string()).collect();
    body.fill(&PANEL)?;
    let mut chart = ChartBuilder::on(&body.margin(6, 6, 6, 6))
        .caption(
            format!("{scene}: largest stable dt, measured against theory (ω = {omega:.4} rad/s)"),
            (FONT, 24).into_font().color(&INK),
        )
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(190)
        .build_cartesian_2d(
            Ticks::decades(x.clone()),
            Ticks {
                range: -0.5..n as f64 - 0.5,
                bold: (0..n).map(|i| i as f64).collect(),
                light: Vec::new(),
            },
        )?;
    let name_of = |v: &f64| {
        let i = v.round();
        if (0.0..n as f64).contains(&i) {
            names[n - 1 - i as usize].clone()
        } else {
            String::new()
        }
    };
    chart
        .configure_mesh()
        .bold_line_style(GRID.stroke_width(1))
        .light_line_style(FAINT.stroke_width(1))
        .axis_style(INK.stroke_width(1))
        .x_label_formatter(&label_of)
        .y_label_formatter(&name_of)
        .x_desc("dt [s]")
        .label_style((FONT, 18).into_font().color(&INK))
        .axis_desc_style((FONT, 19).into_font().color(&INK))
        .draw()?;
    let words = (FONT, 16).into_font().color(&RGBColor(200, 200, 200));
    for (i, (m, measured, theory)) in limits.iter().enumerate() {
        let yv = (n - 1 - i) as f64;
        let said = match theory {
            Some(t) if t.is_finite() => {
                chart.draw_series(std::iter::once(Cross::new(
                    (t.log10(), yv),
                    9,
                    INK.stroke_width(2),
                )))?;
                None
            }
            Some(_) => Some("theory: stable at every dt (marker: the largest tried)"),
            None if m.info().stability == crate::integrate::Stability::Adaptive => {
                Some("adaptive: error control chooses the steps")
            }
            None => Some("theory: unstable at every dt (marker: growth stays below 10⁴)"),
        };
        if let Some(d) = measured {
            chart.draw_series(std::iter::once(
                EmptyElement::at((d.log10(), yv)) + marker(*m, 7.0),
            ))?;
        }
        if let Some(text) = said {
            // Beside the dot, on the side with room; at the left edge when there is no dot.
            let at = match measured {
                Some(d) if d.log10() > (x.start + x.end) / 2.0 => d.log10() - 0.12,
                Some(d) => d.log10() + 0.12,
                None => x.start + 0.05,
            };
            let style = if measured.is_some_and(|d| d.log10() > (x.start + x.end) / 2.0) {
                words.clone().pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Right,
                    plotters::style::text_anchor::VPos::Center,
                ))
            } else {
                words.clone().pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Left,
                    plotters::style::text_anchor::VPos::Center,
                ))
            };
            chart.draw_series(std::iter::once(Text::new(text, (at, yv), style)))?;
        }
    }
    draw_legend(
        &legend,
        &limits.iter().map(|l| l.0).collect::<Vec<_>>(),
        &[
            "marker: measured largest stable dt (bisection; for unconditionally stable methods the largest tried)."
                .to_string(),
            "cross: theory, limit h / ω on the linearised problem.".to_string(),
        ],
    )
}
