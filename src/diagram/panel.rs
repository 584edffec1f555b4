//! A log-log plot as data (its panels, legend and notes: what both the pictures and the
//! recordings draw), and one panel and the legend drawn with `plotters`.

use super::{
    BACKGROUND, FAINT, FONT, GRID, INK, Key, PANEL, Res, Ticks, hole, label_of, log_axis, marker,
};
use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::report::table::wrap;

/// A log-log plot: its panels side by side, the legend's keys and the notes under them, in a
/// column `legend_px` wide at the right.
pub struct Plot {
    pub panels: Vec<Panel>,
    pub keys: Vec<Key>,
    pub notes: Vec<String>,
    pub legend_px: u32,
}

/// One log-log panel: decades on both axes (log10 ranges), the given series (x, y in linear
/// units; points outside (0, ∞) dropped), plus extra dashed lines with labels.
pub struct Panel {
    pub title: String,
    pub x_desc: &'static str,
    pub y_desc: &'static str,
    pub x: Range<f64>,
    pub y: Range<f64>,
    pub series: Vec<Series>,
    /// Dashed grey guides: points (linear units) and a label at the last point.
    pub guides: Vec<(Vec<(f64, f64)>, String)>,
    /// The rows' names when the y axis is rows (row k at 10^k, so at log10 y = k), not
    /// decades; empty for decades.
    pub y_names: Vec<String>,
}

/// One series of a panel: its key, its points and what each point is (shown on hover in the
/// viewer; empty where a point needs no more than its place).
pub struct Series {
    pub key: Key,
    pub points: Vec<(f64, f64)>,
    pub about: Vec<String>,
}

/// Draws `plot` whole: the panels side by side, the legend in its column.
pub(super) fn draw_plot<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, plot: &Plot) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&BACKGROUND)?;
    let (body, legend) = root.split_horizontally(root.dim_in_pixel().0 - plot.legend_px);
    let areas = body.split_evenly((1, plot.panels.len()));
    for (area, panel) in areas.iter().zip(&plot.panels) {
        draw_panel(&area.margin(6, 6, 6, 6), panel)?;
    }
    draw_legend(&legend, &plot.keys, &plot.notes)
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Res
where
    DB::ErrorType: 'static,
{
    area.fill(&PANEL)?;
    let (bold, light) = p.y_ticks();
    let y_ticks = Ticks {
        range: p.y.clone(),
        bold,
        light,
    };
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 24).into_font().color(&INK))
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(if p.y_names.is_empty() { 78 } else { 190 })
        .build_cartesian_2d(Ticks::decades(p.x.clone()), y_ticks)?;
    // A rows axis (stability's methods) names its rows.
    let y_label = |v: &f64| (p.y_names.get(v.round() as usize).cloned()).unwrap_or(label_of(v));
    chart
        .configure_mesh()
        .bold_line_style(GRID.stroke_width(1))
        .light_line_style(FAINT.stroke_width(1))
        .axis_style(INK.stroke_width(1))
        .x_label_formatter(&label_of)
        .y_label_formatter(&y_label)
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
        let grey = RGBColor(170, 170, 170).stroke_width(1);
        chart.draw_series(DashedLineSeries::new(l.clone(), 6, 5, grey))?;
        if label.is_empty() {
            continue;
        }
        // The label sits above the line's last point, on the side away from the plot's edge.
        let end = l[l.len() - 1];
        let h = if end.0 < l[0].0 && end.0 > p.x.start + 0.3 {
            HPos::Right
        } else {
            HPos::Left
        };
        let font = (FONT, 17).into_font().color(&RGBColor(190, 190, 190));
        let text = Text::new(label.clone(), end, font.pos(Pos::new(h, VPos::Bottom)));
        chart.draw_series(std::iter::once(text))?;
    }
    for Series { key, points, .. } in &p.series {
        let l: Vec<(f64, f64)> = points.iter().copied().filter_map(log).collect();
        let style = key.color.stroke_width(2);
        if key.dashed {
            chart.draw_series(DashedLineSeries::new(l.clone(), 9, 6, style))?;
        } else {
            chart.draw_series(LineSeries::new(l.clone(), style))?;
        }
        let dot = |&q| EmptyElement::at(q) + marker(key, 4.5) + hole(key, 4.5);
        chart.draw_series(l.iter().map(dot))?;
    }
    Ok(())
}

impl Panel {
    /// The y axis' ticks, bold and light: decades, or a row per name.
    pub fn y_ticks(&self) -> (Vec<f64>, Vec<f64>) {
        match self.y_names.is_empty() {
            true => log_axis(self.y.clone()),
            false => (
                (0..self.y_names.len()).map(|k| k as f64).collect(),
                Vec::new(),
            ),
        }
    }
}

/// The legend column: one swatch and name per series, and notes below.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[Key],
    notes: &[String],
) -> Res
where
    DB::ErrorType: 'static,
{
    let font = (FONT, 19).into_font().color(&INK);
    // About 10 px per character of the legend's text, right of its swatch.
    let chars = ((area.dim_in_pixel().0 as usize).saturating_sub(70) / 10).max(12);
    let mut y = 70;
    // Many keys (a method's variants each its own) closer together.
    let gap = if keys.len() > 20 { 2 } else { 8 };
    for key in keys {
        let swatch = match key.dashed {
            true => vec![
                vec![(14, y + 10), (22, y + 10)],
                vec![(40, y + 10), (48, y + 10)],
            ],
            false => vec![vec![(14, y + 10), (48, y + 10)]],
        };
        for part in swatch {
            area.draw(&PathElement::new(part, key.color.stroke_width(3)))?;
        }
        area.draw(&(EmptyElement::at((31, y + 10)) + marker(key, 5.5) + hole(key, 5.5)))?;
        let lines = wrap(&key.name, chars);
        for (i, line) in lines.iter().enumerate() {
            let at = (58, y + 22 * i as i32);
            area.draw(&Text::new(line.clone(), at, font.clone()))?;
        }
        y += gap + 22 * lines.len() as i32;
    }
    y += 16;
    let small = (FONT, 15).into_font().color(&RGBColor(180, 180, 180));
    for n in notes {
        for line in wrap(n, chars + 10) {
            area.draw(&Text::new(line, (14, y), small.clone()))?;
            y += 20;
        }
        y += 8;
    }
    Ok(())
}
