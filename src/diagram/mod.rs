//! The studies' diagrams (work-precision, convergence, stability, drift, the hair trade) drawn
//! with `plotters` into SVG and PNG: axes in decades, each method in its recordings' colour
//! ([`crate::palette`], chosen for the viewer's dark grey, the background here too), the legend
//! in a column of its own so that it never covers data. Text in the DejaVu Sans of
//! `assets/fonts/` (Bitstream Vera licence), registered from bytes: no system font is needed.
//! Behind the `diagrams` cargo feature (on with `rerun`): the core builds without plotters.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use crate::integrate::Method;
use crate::palette::method_color;
use crate::study::Row;

mod axes;
mod drift;
mod kinds;
mod panel;
pub mod stamp;

use axes::{Ticks, decades, label_of};
pub use axes::{decade_label, log_axis};
pub use drift::{drift, pendulum_drift_picture};
pub use kinds::{
    convergence, hair_trade, pendulum_work_precision_picture, stability, work_precision,
};
use panel::draw_plot;
pub use panel::{Panel, Plot, Series};

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
    /// What it draws as a log-log plot (stability's y axis its methods' rows): the data both
    /// its picture and the study's recording are drawn from.
    pub plot: Plot,
    /// What it draws, without wall times: a line per point (method or series, settings,
    /// deterministic values), stamped below its title into its PNG ([`stamp`]).
    data: String,
}

/// The files a diagram was written to.
pub struct Written {
    pub svg: PathBuf,
    pub png: PathBuf,
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

    /// Writes `<dir>/<prefix><stem>.svg` and `.png`, each whole or not at all
    /// (`crate::output`).
    pub fn write(&self, dir: &Path, prefix: &str) -> anyhow::Result<Written> {
        use crate::output::{Dash, check};
        register_font();
        let [svg, png] = Self::files(&format!("{prefix}{}", self.stem), dir);
        let no_dash = Dash::Refused("is not a folder; --plots names the folder of the diagrams");
        let (svg_out, png_out) = (
            check("--plots", &svg, no_dash)?,
            check("--plots", &png, no_dash)?,
        );
        let mut text = String::new();
        self.paint(SVGBackend::with_string(&mut text, self.size))?;
        svg_out.write(text.as_bytes())?;
        png_out.write(&self.png()?)?;
        Ok(Written { svg, png })
    }

    /// The picture as PNG bytes, stamped with what it draws ([`stamp`]).
    pub fn png(&self) -> anyhow::Result<Vec<u8>> {
        register_font();
        let mut rgb = vec![0; 3 * self.size.0 as usize * self.size.1 as usize];
        self.paint(BitMapBackend::with_buffer(&mut rgb, self.size))?;
        stamp::png_with_text(&rgb, self.size, &self.data())
    }

    /// What it draws under its title, as its PNG is stamped with.
    pub fn data(&self) -> String {
        format!("{}\n{}", self.title, self.data)
    }

    /// Draws it whole on `backend`.
    fn paint<DB: DrawingBackend>(&self, backend: DB) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let root = backend.into_drawing_area();
        draw_plot(&root, &self.plot).map_err(err)?;
        root.present().map_err(|e| err(Box::new(e)))
    }
}

/// A sweep's runs as [`Diagram`]'s stamp says them, below the reference's error `floor`.
fn rows_data(rows: &[Row], floor: f64) -> String {
    let runs = rows.iter().map(|r| {
        let (m, dt, rtol, evals, error) = (r.method.name(), r.dt, r.rtol, r.evals, r.error);
        format!("{m} dt={dt:e} rtol={rtol:?} evals={evals} error={error:?}\n")
    });
    format!("floor={floor:e}\n{}", runs.collect::<String>())
}

type Res = Result<(), Box<dyn std::error::Error>>;

fn err(e: Box<dyn std::error::Error>) -> anyhow::Error {
    anyhow::anyhow!("drawing a diagram: {e}")
}

/// What names a series in a diagram: its legend text, colour and marker shape.
#[derive(Clone, Debug)]
pub struct Key {
    pub name: String,
    pub color: RGBColor,
    shape: usize,
    /// Drawn as a dashed line (a method's runs stepping across the samples).
    pub dashed: bool,
    /// Drawn with hollow markers (a composition's runs with compensated sums).
    pub hollow: bool,
}

impl Key {
    /// Its colour as RGB bytes.
    pub fn rgb(&self) -> [u8; 3] {
        [self.color.0, self.color.1, self.color.2]
    }

    /// A method's series: its name and colour (the recordings' own), and a shape by its place
    /// in the registry, so methods whose curves coincide still show both.
    fn of(m: Method) -> Key {
        let [r, g, b] = method_color(m.name());
        Key {
            name: m.name().to_string(),
            color: RGBColor(r, g, b),
            shape: Method::ALL.iter().position(|&x| x == m).unwrap_or(0),
            dashed: false,
            hollow: false,
        }
    }

    /// A method's series of one variant: its runs stepping across the samples (`--step`, a
    /// dashed line), with compensated sums (hollow markers, its colour a third lighter).
    fn variant(m: Method, across: bool, compensated: bool) -> Key {
        let mut key = Key::of(m);
        if across {
            key.name.push_str(" --step");
            key.dashed = true;
        }
        if compensated {
            key.name.push_str(" compensated");
            key.hollow = true;
            let lighter = |c: u8| c + (255 - c) / 3;
            let RGBColor(r, g, b) = key.color;
            key.color = RGBColor(lighter(r), lighter(g), lighter(b));
        }
        key
    }
}

/// The hole of a hollow marker ([`Key::hollow`]) in the panel's colour, or nothing.
fn hole(key: &Key, size: f64) -> Polygon<(i32, i32)> {
    let inner = Key {
        color: if key.hollow { PANEL } else { key.color },
        ..key.clone()
    };
    marker(&inner, if key.hollow { 0.5 * size } else { 0.0 })
}

/// A filled marker of `key`'s shape and colour at pixel offset (0, 0).
fn marker(key: &Key, size: f64) -> Polygon<(i32, i32)> {
    let k = key.shape;
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
    let c = key.color;
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
