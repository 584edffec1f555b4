//! The viewer layout a recording opens with, and the view properties the Rust SDK's view builders
//! do not take in Rerun 0.36.3: a time series' legend and axes, a 3D view's eye and background.
//!
//! They are plain blueprint archetypes at `view/<view id>/<archetype>` in the blueprint store
//! (where the Python SDK puts them). The Rust SDK has no handle to add them (`View::add_property`
//! is `pub(crate)`), but a view's path is public: [`Layout::send`] lets the SDK write the
//! blueprint into a memory sink, appends the properties to the same store, and sends the whole
//! batch, activation last, through `RecordingStream::send_blueprint` (`tests/recording.rs` reads
//! them back).

use rerun::blueprint::components::{BackgroundKind, Corner2D};
use rerun::blueprint::{Blueprint, BlueprintActivation, ContainerLike};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    Background, EyeControls3D, LineGrid3D, PlotLegend, ScalarAxis, TimeAxis, VisualBounds2D,
};
use rerun::external::re_sdk_types::datatypes::{TimeInt, TimeRange, TimeRangeBoundary};
use rerun::log::LogMsg;

use super::axes::{LateAxes, ValueAxis, property_messages, time_end};
use rerun::{AsComponents, SerializedComponentBatch};

/// The box a 3D view frames [m, z up]: where a scene draws its subject (slots, swings, labels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// The direction from the box's centre towards the eye (any length).
    pub toward_eye: [f32; 3],
}

/// The viewer's vertical field of view for a 3D eye (Rerun's default, 55°).
const FOV_Y_DEGREES: f32 = 55.0;
/// The share of the view's half-width or half-height the framed box fills.
const FILL: f32 = 0.95;

impl Framing {
    /// The box around both (the eye's direction `self`'s).
    pub fn union(self, other: Framing) -> Framing {
        Framing {
            min: std::array::from_fn(|i| self.min[i].min(other.min[i])),
            max: std::array::from_fn(|i| self.max[i].max(other.max[i])),
            toward_eye: self.toward_eye,
        }
    }

    /// An orbit eye looking at the box's centre from `toward_eye`, z up, as close as it can be
    /// with every corner of the box inside [`FILL`] of a view of width/height `aspect`.
    pub fn eye(&self, aspect: f32) -> ([f32; 3], [f32; 3]) {
        let v = |a: [f32; 3]| glam::Vec3::from_array(a);
        let (lo, hi) = (v(self.min), v(self.max));
        let center = 0.5 * (lo + hi);
        let back = v(self.toward_eye).normalize();
        let right = glam::Vec3::Z.cross(back).normalize();
        let up = back.cross(right);
        let tan_y = (0.5 * FOV_Y_DEGREES.to_radians()).tan() * FILL;
        let tan_x = tan_y * aspect;
        let mut distance = 0.0f32;
        for i in 0..8 {
            let corner = glam::Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            ) - center;
            // The corner is in view when its sideways offset over its depth in front of the eye
            // is within the half-angle's tangent.
            let toward = corner.dot(back);
            distance = distance
                .max(toward + corner.dot(right).abs() / tan_x)
                .max(toward + corner.dot(up).abs() / tan_y);
        }
        ((center + distance * back).to_array(), center.to_array())
    }
}

/// The 3D views' background colour.
const BACKGROUND: [u8; 3] = [24, 24, 28];

/// A legend line's height and a name's width per character in the viewer [logical px], measured
/// on screenshots, and what a legend adds around its names (colour swatch, margins).
pub const LEGEND_ROW_PX: f32 = 22.5;
const LEGEND_CHAR_PX: f32 = 5.6;
const LEGEND_FRAME_PX: f32 = 40.0;

/// The end of a plot's time axis [s]: past the run's end (`end_time`) by the band of a legend
/// naming `series` right of the curves in a plot `width` px wide, further where three tick
/// labels need it; and whether the band's end is enough.
pub fn time_axis_end(series: &[&str], end_time: f64, width: f32) -> (f64, bool) {
    let longest = series.iter().map(|s| s.chars().count()).max().unwrap_or(0);
    let legend = LEGEND_FRAME_PX + LEGEND_CHAR_PX * longest as f32;
    let curves = (width - PLOT_AXIS_PX - legend).max(0.25 * width);
    let band = end_time * f64::from((curves + legend) / curves);
    let end = time_end(band, width);
    (end, end == band)
}

/// The part of a plot's width its value axis' labels take [logical px].
const PLOT_AXIS_PX: f32 = 40.0;

/// A recording's layout: the SDK's blueprint and the view properties gathered while building it.
pub struct Layout {
    blueprint: Blueprint,
    properties: Vec<(String, Vec<SerializedComponentBatch>)>,
    axes: Vec<ValueAxis>,
}

/// View properties gathered while a layout is built: (entity path in the blueprint store, the
/// archetype's components), and the plots whose value range is set at the recording's end.
#[derive(Default)]
pub struct ViewProperties(Vec<(String, Vec<SerializedComponentBatch>)>, Vec<ValueAxis>);

impl ViewProperties {
    /// `view` as a container entry, with `property` (an archetype called `name`) set on it.
    fn add(
        &mut self,
        view: impl Into<ContainerLike>,
        name: &str,
        property: &dyn AsComponents,
    ) -> ContainerLike {
        let view = view.into();
        if let ContainerLike::View(v) = &view {
            self.0.push((
                format!("{}/{name}", v.blueprint_path()),
                property.as_serialized_batches(),
            ));
        }
        view
    }

    /// A time series whose legend names `series` in a band of its own at the right, past the
    /// run's end (`end_time` [s]) where no curve reaches, in a plot `width` px wide (a single
    /// series too: the title names the quantity, the legend the lane); an empty plot none.
    pub fn legend_beside(
        &mut self,
        view: impl Into<ContainerLike>,
        series: &[&str],
        end_time: f64,
        width: f32,
    ) -> ContainerLike {
        if series.is_empty() {
            return self.add(view, "PlotLegend", &PlotLegend::new().with_visible(false));
        }
        let view = self.add(
            view,
            "PlotLegend",
            &PlotLegend::new()
                .with_corner(Corner2D::RightTop)
                .with_visible(true),
        );
        let end = time_axis_end(series, end_time, width).0;
        let at = |t: f64| TimeRangeBoundary::Absolute(TimeInt((t * 1e9).round() as i64));
        let range = TimeRange {
            start: at(0.0),
            end: at(end),
        };
        self.add(view, "TimeAxis", &TimeAxis::new().with_view_range(range))
    }

    /// A plot of the series under `origin`, `height` px tall (its title bar included), whose
    /// value range is set when the recording ends: around its data and `floor` (a range a
    /// round-off level sits on, which it also opens on), with three tick labels or more.
    pub fn value_axis(
        &mut self,
        view: impl Into<ContainerLike>,
        origin: String,
        height: f32,
        floor: Option<(f64, f64)>,
    ) -> ContainerLike {
        let mut view = view.into();
        if let ContainerLike::View(v) = &view {
            self.1.push(ValueAxis {
                view: v.blueprint_path().to_string(),
                origin,
                height,
                floor,
            });
        }
        if let Some((lo, hi)) = floor {
            let range = rerun::components::Range1D::new(lo, hi);
            view = self.add(view, "ScalarAxis", &ScalarAxis::new().with_range(range));
        }
        view
    }

    /// A 3D view opening on the eye that frames `framing` in a view of width/height `aspect`.
    pub fn eye(
        &mut self,
        view: impl Into<ContainerLike>,
        framing: Framing,
        aspect: f32,
    ) -> ContainerLike {
        let (position, target) = framing.eye(aspect);
        let eye = EyeControls3D::new()
            .with_kind(rerun::blueprint::components::Eye3DKind::Orbital)
            .with_position(position)
            .with_look_target(target)
            .with_eye_up([0.0, 0.0, 1.0]);
        self.add(view, "EyeControls3D", &eye)
    }

    /// A 2D view opening on `min..max` (x right, y down) of its scene.
    pub fn bounds_2d(
        &mut self,
        view: impl Into<ContainerLike>,
        min: [f32; 2],
        max: [f32; 2],
    ) -> ContainerLike {
        let range = rerun::datatypes::Range2D {
            x_range: [f64::from(min[0]), f64::from(max[0])].into(),
            y_range: [f64::from(min[1]), f64::from(max[1])].into(),
        };
        self.add(view, "VisualBounds2D", &VisualBounds2D::new(range))
    }

    /// A 3D view on a plain dark background without the grid: the default gradient tints the
    /// floor green under green hair, and the grid's plane at z = 0 cuts through the heads.
    pub fn plain_backdrop(&mut self, view: impl Into<ContainerLike>) -> ContainerLike {
        let view = self.add(
            view,
            "Background",
            &Background::new(BackgroundKind::SolidColor).with_color(BACKGROUND),
        );
        self.add(view, "LineGrid3D", &LineGrid3D::new().with_visible(false))
    }

    pub fn layout(self, blueprint: Blueprint) -> Layout {
        Layout {
            blueprint,
            properties: self.0,
            axes: self.1,
        }
    }
}

impl Layout {
    /// Sends the layout to `rec` as its active and default blueprint, with the view properties
    /// before the activation. Returns the value axes to set at the end.
    pub fn send(
        self,
        rec: &rerun::RecordingStream,
        application_id: &str,
    ) -> anyhow::Result<LateAxes> {
        let app = rerun::ApplicationId::try_new(application_id)?;
        let (scratch, storage) = rerun::RecordingStreamBuilder::new(app.clone())
            .send_properties(false)
            .memory()?;
        self.blueprint.send(
            &scratch,
            BlueprintActivation {
                make_active: true,
                make_default: true,
            },
        )?;
        let mut messages: Vec<LogMsg> = storage
            .take()
            .into_iter()
            .filter(|m| m.store_id().is_blueprint())
            .collect();
        let Some(LogMsg::BlueprintActivationCommand(activation)) = messages.pop() else {
            anyhow::bail!("the Rerun SDK wrote no blueprint activation");
        };
        messages.extend(property_messages(&app, &activation, self.properties, 0)?);
        rec.send_blueprint(messages, activation.clone());
        Ok(LateAxes {
            application_id: app,
            activation,
            axes: self.axes,
        })
    }
}
