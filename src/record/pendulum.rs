//! Recording a pendulum run (`<lane>` is `exact`/`reference` or a method name):
//! `pendulum/<lane>/{pivot,rod,bob}` in slots side by side, the pivot labelled when the lane
//! diverges; `pendulum/<method>/<reference lane>_ghost`, the reference bob as a grey disc behind
//! each method's bob (a ring around it while the method keeps to it); the phase portrait
//! `pendulum/phase/<lane>/{path,state}`; `pendulum/plots/<quantity>/<lane>`, `pendulum/events`
//! and `pendulum/about`.

use rerun::RecordingStream;
use rerun::blueprint::{Blueprint, Horizontal, Spatial2DView, Vertical};

use super::scene::{Draw, SceneRecorder, clear_diverged, plotted};
use super::{
    Framing, PLOTS_SHARE, Staging, ViewProperties, WINDOW, about_and_events, method_color,
    scene_blueprint, slot_cells, slot_grid,
};
use crate::scene::harness::{Event, Frame, Run, Scene as _, SeriesBatch, WHOLE};
use crate::scene::pendulum::exact::ExactPendulum;
use crate::scene::pendulum::run::{PendulumConfig, PendulumLane, PendulumScene, QUANTITIES};

/// The plotted quantities: entity name and plot title (with units).
pub const PLOTS: [(&str, &str); 6] = [
    ("theta", "θ [rad]"),
    ("omega", "ω [rad/s]"),
    ("energy", "total energy E = ½L²ω² + gL(1 − cos θ) [J/kg]"),
    (
        "log10_energy_error",
        "log10 |ΔE/E0|: relative energy error (−16 = machine precision)",
    ),
    (
        "log10_theta_error",
        "log10 |θ − θref| [θ in rad]: error against the reference",
    ),
    (
        "step_size",
        "last accepted step [s] (adaptive methods and --step: their own steps, not ended at the samples)",
    ),
];

/// At most this many points per phase-portrait curve.
const MAX_PHASE_POINTS: usize = 5_000;

/// The pendulum's views, for the layouts.
pub const VIEWS: super::SceneViews = super::SceneViews {
    name: "pendulum",
    plots: &PLOTS,
    blueprint,
};

/// The pendulum's layout: a 3D view per lane, phase portrait and events on the left, the plots
/// on the right, every plot holding all lanes.
pub fn blueprint(
    timings: bool,
    staging: &Staging,
    methods: &[&'static str],
    props: &mut ViewProperties,
) -> Blueprint {
    let left = (1.0 - PLOTS_SHARE) * WINDOW[0];
    let left = Vertical::new([
        slot_grid("pendulum", &staging.slots, [left, 0.6 * WINDOW[1]], props),
        Horizontal::new([
            Spatial2DView::new("phase portrait: x = θ [rad], y = ω [rad/s]")
                .with_origin("/pendulum/phase")
                .into(),
            Vertical::new(about_and_events("pendulum")).into(),
        ])
        .with_column_shares([3.0, 2.0])
        .into(),
    ])
    .with_row_shares([3.0, 2.0]);
    scene_blueprint(left, "pendulum", staging, (timings, methods), props)
}

/// What the layout needs of a run: a 3D view per lane, each framing its slot's swing, and the
/// plots with their series (the step-size plot only when an adaptive method runs: a fixed step
/// draws a flat line).
pub fn staging(c: &PendulumConfig) -> Staging {
    // `exact` where the closed form applies.
    let reference = match ExactPendulum::new(&c.params) {
        Some(_) => "exact",
        None => "reference",
    };
    let methods: Vec<&'static str> = c.methods.iter().map(|m| m.name()).collect();
    let lanes: Vec<&'static str> = std::iter::once(reference)
        .chain(methods.iter().copied())
        .collect();
    let l = c.params.length as f32;
    let pivots = slot_pivots(lanes.len(), l);
    let (width, top) = swing(c);
    let slots = Staging::per_lane(lanes.iter().zip(&pivots).map(|(&lane, p)| {
        (
            lane,
            Framing {
                // Depth: the bob, and the ghost set back behind it.
                min: [p[0] - width, -0.12 * l, p[2] - 1.15 * l],
                max: [p[0] + width, 0.3 * l, p[2] + top],
                toward_eye: TOWARD_EYE,
            },
        )
    }));
    let mut slots = slots;
    slots[0].title = format!("{reference} = grey rings");
    let adaptive = c.methods.iter().any(|m| m.info().adaptive());
    let plots = Staging::plots(&PLOTS, |name| {
        let q = QUANTITIES
            .iter()
            .position(|&q| plotted(q) == name)
            .unwrap_or(0);
        match name {
            "step_size" if !adaptive => Vec::new(),
            // The reference has no error of its own and no step of its own.
            _ if q >= 4 => methods.clone(),
            _ => lanes.clone(),
        }
    });
    Staging {
        slots,
        plots,
        end_time: c.schedule().end_time(),
    }
}

/// From where the 3D views look: the front and a little above (the slots are a wall in the x–z
/// plane).
const TOWARD_EYE: [f32; 3] = [0.0, -1.0, 0.25];

/// How far the reference's swing reaches from its pivot [m], sideways and above it, from its
/// energy: its amplitude θm (cos θm = 1 − E0/(gL)), over the top when E0 ≥ 2gL; with room for
/// the bob and a ring around it.
fn swing(c: &PendulumConfig) -> (f32, f32) {
    let p = &c.params;
    let l = p.length;
    let e0 = 0.5 * l * l * p.omega0 * p.omega0 + p.gravity * l * (1.0 - p.theta0.cos());
    let cos_max = 1.0 - e0 / (p.gravity * l);
    let (side, up) = if cos_max <= -1.0 {
        (1.0, 1.0)
    } else if cos_max <= 0.0 {
        (1.0, -cos_max)
    } else {
        ((1.0 - cos_max * cos_max).sqrt(), 0.0)
    };
    let ring = 0.15 * l;
    ((side * l + ring) as f32, (up * l + ring) as f32)
}

/// The reference's ghost: its radius over a bob's, how far behind the bob it is set (in bob
/// radii: enough for the bob's whole disc to stay in front), and its colour.
const GHOST_SCALE: f32 = 1.45;
const GHOST_SETBACK: f32 = 1.4;
const GHOST: [u8; 3] = [150, 150, 150];

/// Pivots for `n` lanes: slots 2.2 L apart (a full swing spans 2 L) in rows 2.6 L apart (room
/// for the label), 1.2 L above the ground grid.
fn slot_pivots(n: usize, length: f32) -> Vec<[f32; 3]> {
    slot_cells(n)
        .into_iter()
        .map(|(column, row)| {
            [
                2.2 * length * column as f32,
                0.0,
                (1.2 + 2.6 * row as f32) * length,
            ]
        })
        .collect()
}

/// The pendulum's 3D slots, ghosts and phase portrait (every field set by `start`).
#[derive(Default)]
pub struct PendulumDraw {
    lanes: Vec<&'static str>,
    /// Each lane's pivot [m]: a wall of slots in the x-z plane, above the viewer's ground grid.
    pivots: Vec<[f32; 3]>,
    length: f64,
    /// Decimated (θ, ω) per lane for the phase portrait, a strip per stretch kept whole (the
    /// whole run, or an aggregated run's windows); and the tick of each lane's last point.
    phase: Vec<Vec<Vec<[f32; 2]>>>,
    phase_last: Vec<Option<u64>>,
    phase_stride: u64,
    /// The reference as described at the start (a fine-step estimate grows during the run).
    reference_description: String,
}

/// A recorder of pendulum runs.
pub fn recorder(rec: RecordingStream, timings: bool) -> SceneRecorder<PendulumDraw> {
    SceneRecorder::new(rec, PendulumDraw::default(), timings)
}

impl PendulumDraw {
    fn bob_position(&self, lane: usize, theta: f64) -> [f32; 3] {
        let (x, z) = (self.length * theta.sin(), -self.length * theta.cos());
        let [px, py, pz] = self.pivots[lane];
        [px + x as f32, py, pz + z as f32]
    }
}

impl Draw<PendulumScene> for PendulumDraw {
    fn start(
        &mut self,
        rec: &RecordingStream,
        scene: &PendulumScene,
        lanes: &[(&'static str, &PendulumLane)],
    ) -> anyhow::Result<()> {
        let c = &scene.config;
        let schedule = scene.schedule();
        self.lanes = lanes.iter().map(|l| l.0).collect();
        self.pivots = slot_pivots(self.lanes.len(), c.params.length as f32);
        self.length = c.params.length;
        self.phase = vec![Vec::new(); self.lanes.len()];
        self.phase_last = vec![None; self.lanes.len()];
        self.reference_description = scene.reference_description();
        self.phase_stride = schedule.plot_stride
            * schedule
                .whole_rows(&scene.windows())
                .div_ceil(MAX_PHASE_POINTS as u64);

        rec.log_static("pendulum", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        log_phase_frame(rec, c, &self.lanes)?;
        let bob_radius = 0.1 * c.params.length as f32;
        for (i, name) in self.lanes.iter().enumerate() {
            let color = method_color(name);
            // Each lane's 3D view is titled with its name, so the pivot carries no label until
            // a divergence says why the lane stopped.
            rec.log_static(
                format!("pendulum/{name}/pivot"),
                &rerun::Points3D::new([self.pivots[i]])
                    .with_radii([0.3 * bob_radius])
                    .with_colors([[128, 128, 128]])
                    .with_show_labels(true),
            )?;
            rec.log_static(
                format!("pendulum/{name}/bob"),
                &rerun::Points3D::update_fields()
                    .with_radii([bob_radius])
                    .with_colors([color]),
            )?;
            rec.log_static(
                format!("pendulum/{name}/rod"),
                &rerun::LineStrips3D::update_fields()
                    .with_radii([0.2 * bob_radius])
                    .with_colors([color]),
            )?;
            if i > 0 {
                // The reference bob a size larger and set back along the line of sight: a grey
                // ring around the method's bob while the method keeps to the reference, a grey
                // disc where it should be once it parts; the method's colour always in front.
                let ghost = format!("pendulum/{name}/{}_ghost", self.lanes[0]);
                let back =
                    glam::Vec3::from_array(TOWARD_EYE).normalize() * (-GHOST_SETBACK * bob_radius);
                // One call: two static logs to one entity may land in one chunk or two,
                // as the batcher's timing has it, and identical runs must write the same chunks.
                let transform = rerun::Transform3D::from_translation(back.to_array());
                let style = rerun::Points3D::update_fields()
                    .with_radii([GHOST_SCALE * bob_radius])
                    .with_colors([GHOST]);
                rec.log_static(ghost, &[&transform as &dyn rerun::AsComponents, &style])?;
            }
            rec.log_static(
                format!("pendulum/phase/{name}/path"),
                &rerun::LineStrips2D::update_fields()
                    .with_colors([color])
                    .with_radii([rerun::Radius::new_ui_points(1.0)]),
            )?;
            rec.log_static(
                format!("pendulum/phase/{name}/state"),
                // No labels: eight of them overlap where the curves agree; colours match the plots.
                &rerun::Points2D::update_fields()
                    .with_colors([color])
                    .with_radii([rerun::Radius::new_ui_points(5.0)]),
            )?;
        }

        rec.log_static(
            "pendulum/about",
            &rerun::TextDocument::from_markdown(about_text(scene)),
        )?;
        rec.set_duration_secs("sim_time", 0.0);
        rec.set_time_sequence("frame", 0);
        rec.log(
            "pendulum/events",
            &rerun::TextLog::new(self.reference_description.clone())
                .with_level(rerun::TextLogLevel::INFO),
        )?;
        Ok(())
    }

    /// The phase portrait follows the rows of stretches kept whole: the rows an aggregated run
    /// keeps for a column's extremes are far apart in time, and a curve through them would draw
    /// chords across the orbit.
    fn series(&mut self, lane: usize, batch: &SeriesBatch) {
        let (theta, omega) = (&batch.columns[0], &batch.columns[1]);
        for (k, &tick) in batch.ticks.iter().enumerate() {
            if batch.needed[k] != WHOLE || !tick.is_multiple_of(self.phase_stride) {
                continue;
            }
            let strips = &mut self.phase[lane];
            if self.phase_last[lane].is_none_or(|last| tick - last > self.phase_stride) {
                strips.push(Vec::new());
            }
            self.phase_last[lane] = Some(tick);
            if let Some(strip) = strips.last_mut() {
                strip.push([theta[k] as f32, omega[k] as f32]);
            }
        }
    }

    fn frame(
        &mut self,
        rec: &RecordingStream,
        _scene: &PendulumScene,
        frame: &Frame<PendulumLane>,
    ) -> anyhow::Result<()> {
        let reference = frame.lanes[0].map(|(l, offset)| l.state(offset));
        for (i, lane) in frame.lanes.iter().enumerate() {
            let Some((lane, offset)) = lane else {
                continue;
            };
            let (theta, omega) = lane.state(*offset);
            let name = self.lanes[i];
            let bob = self.bob_position(i, theta);
            rec.log(
                format!("pendulum/{name}/bob"),
                &rerun::Points3D::update_fields().with_positions([bob]),
            )?;
            rec.log(
                format!("pendulum/{name}/rod"),
                &rerun::LineStrips3D::update_fields().with_strips([[self.pivots[i], bob]]),
            )?;
            if i > 0
                && let Some((theta_ref, _)) = reference
            {
                rec.log(
                    format!("pendulum/{name}/{}_ghost", self.lanes[0]),
                    &rerun::Points3D::update_fields()
                        .with_positions([self.bob_position(i, theta_ref)]),
                )?;
            }
            rec.log(
                format!("pendulum/phase/{name}/state"),
                &rerun::Points2D::update_fields().with_positions([[theta as f32, omega as f32]]),
            )?;
        }
        Ok(())
    }

    fn diverged(&mut self, rec: &RecordingStream, event: &Event) -> anyhow::Result<()> {
        let name = self.lanes[event.lane];
        let ghost = format!("{}_ghost", self.lanes[0]);
        let label = clear_diverged(rec, "pendulum", name, &["rod", &ghost], event)?;
        rec.log(
            format!("pendulum/phase/{name}/state"),
            &rerun::Clear::flat(),
        )?;
        // The bob rests on the pivot, whose label now says why.
        rec.log(
            format!("pendulum/{name}/bob"),
            &rerun::Points3D::new([self.pivots[event.lane]]).with_colors([method_color(name)]),
        )?;
        rec.log(
            format!("pendulum/{name}/pivot"),
            &rerun::Points3D::update_fields().with_labels([label]),
        )?;
        Ok(())
    }

    fn finish(
        &mut self,
        rec: &RecordingStream,
        scene: &PendulumScene,
        _run: &Run<PendulumLane>,
    ) -> anyhow::Result<()> {
        for (i, name) in self.lanes.iter().enumerate() {
            let strips: Vec<Vec<[f32; 2]>> = std::mem::take(&mut self.phase[i])
                .into_iter()
                .filter(|s| s.len() >= 2)
                .collect();
            if !strips.is_empty() {
                rec.log_static(
                    format!("pendulum/phase/{name}/path"),
                    &rerun::LineStrips2D::update_fields().with_strips(strips),
                )?;
            }
        }
        // A fine-step reference's error estimate is known only at the end.
        let description = scene.reference_description();
        if description != self.reference_description {
            let schedule = scene.schedule();
            rec.set_duration_secs("sim_time", schedule.end_time());
            rec.log(
                "pendulum/events",
                &rerun::TextLog::new(description).with_level(rerun::TextLogLevel::INFO),
            )?;
            rec.log_static(
                "pendulum/about",
                &rerun::TextDocument::from_markdown(about_text(scene)),
            )?;
        }
        Ok(())
    }
}

/// The phase portrait's legend, as a 2D view has none: a dot in each lane's colour with its name,
/// in a column right of the reference's orbit (amplitude θm, ωm = √(2 E0) / L).
fn phase_legend(c: &PendulumConfig, lanes: &[&str]) -> rerun::Points2D {
    let p = &c.params;
    let e0 = 0.5 * p.length * p.length * p.omega0 * p.omega0
        + p.gravity * p.length * (1.0 - p.theta0.cos());
    let theta = (1.0 - e0 / (p.gravity * p.length)).clamp(-1.0, 1.0).acos();
    let omega = (2.0 * e0).sqrt() / p.length;
    let n = lanes.len().max(2) as f64 - 1.0;
    let at = |k: usize| {
        [
            (1.8 * theta) as f32,
            (omega * (1.0 - 2.0 * k as f64 / n)) as f32,
        ]
    };
    rerun::Points2D::new((0..lanes.len()).map(at))
        .with_colors(lanes.iter().map(|l| method_color(l)))
        .with_labels(lanes.iter().copied())
        .with_radii([rerun::Radius::new_ui_points(5.0)])
        .with_show_labels(true)
}

/// The run described in Markdown, for the `about` panel.
fn about_text(scene: &PendulumScene) -> String {
    let c = &scene.config;
    let p = &c.params;
    let s = scene.schedule();
    let methods: Vec<&str> = c.methods.iter().map(|m| m.name()).collect();
    format!(
        "# pendulum\n\n\
         θ'' = −(g/L) sin θ, f64, state (θ, ω).\n\n\
         | parameter | value |\n|---|---|\n\
         | g | {} m/s² |\n| L | {} m |\n| θ0 | {}° |\n| ω0 | {} rad/s |\n| dt | {} s |\n\
         | steps | {} (to t = {} s) |\n| 3D frames | {} |\n| plotted | {} |\n\
         | methods | {} |\n| Verlet damping d | {} |\n\n\
         **Reference**: {}\n\n\
         Energy is per unit mass with zero at the bottom: E0 = {:.9} J/kg; the relative energy error is \
         (E − E0)/{:.6}. A method is stopped (divergence) when θ or ω is not finite or E > {:.4} J/kg \
         (10 × max(E0, 2gL)); the events panel shows when.\n\n\
         The phase portrait shows each lane's whole run as a curve and its current state as a dot.\n",
        p.gravity,
        p.length,
        crate::format::trim_number(p.theta0.to_degrees(), 9),
        p.omega0,
        c.dt,
        s.total,
        crate::format::trim_number(s.end_time(), 9),
        s.frames_text(),
        s.series_text(&scene.windows()),
        methods.join(", "),
        c.options.verlet_damping,
        scene.reference_description(),
        scene.initial_energy,
        scene.energy_scale,
        scene.energy_bound,
    )
}

/// The phase portrait's frame: the viewer's 2D y axis points down, so each lane's curve is drawn
/// mirrored (a transform below the view's origin; the origin's own is the view's frame) and ω
/// points up, the values logged being θ and ω as they are; and its legend.
fn log_phase_frame(
    rec: &RecordingStream,
    c: &PendulumConfig,
    lanes: &[&'static str],
) -> anyhow::Result<()> {
    let mirror = rerun::Transform3D::from_scale([1.0, -1.0, 1.0]);
    for name in lanes {
        rec.log_static(format!("pendulum/phase/{name}"), &mirror)?;
    }
    // One call: two static logs to one entity may land in one chunk or two.
    let legend = phase_legend(c, lanes);
    rec.log_static(
        "pendulum/phase/legend",
        &[&mirror as &dyn rerun::AsComponents, &legend],
    )?;
    Ok(())
}
