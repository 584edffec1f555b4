//! Recording a rope run: `rope/<method>/{nodes,strip,pinned}`, each method's rope in its own slot
//! (or all at one place with `--layout overlay`); `rope/plots/<quantity>/<method>`, `rope/events`
//! and `rope/about`.

use rerun::RecordingStream;

use super::scene::{Draw, SceneRecorder, clear_diverged};
use super::{Framing, Slot, Staging, method_color, slot_cells, view_above_text};
use crate::format::trim_number;
use crate::report::rope::cost_per_step;
use crate::scene::harness::{Event, Frame};
use crate::scene::rope::node;
use crate::scene::rope::run::{ENERGY_GAIN_BOUND, RopeConfig, RopeLane, RopeLayout, RopeScene};

/// The plotted quantities: entity name and plot title (with units).
/// The balance error comes first: it is each method's own error, damping accounted for.
pub const PLOTS: [(&str, &str); 4] = [
    (
        "log10_energy_balance",
        "log10 |E + W − E0| / scale: energy error, damping accounted for",
    ),
    ("energy", "total energy E: kinetic + spring + gravity [J]"),
    (
        "work",
        "work W dissipated by spring damping and air drag [J]",
    ),
    ("max_strain", "maximum strain max |ℓ − ℓ0| / ℓ0"),
];

/// The rope's views, for the layouts.
pub const VIEWS: super::SceneViews = super::SceneViews {
    name: "rope",
    plots: &PLOTS,
    blueprint: |t, s, m, p| view_above_text("rope", s, t, m, p),
};

/// Each lane's slot offset [m]: rows of four stacked upwards (see `slot_cells`), or all at one
/// place with `--layout overlay`.
fn slot_offsets(c: &RopeConfig) -> Vec<[f64; 3]> {
    let span = rope_span(c);
    match c.layout {
        RopeLayout::Overlay => vec![[0.0; 3]; c.methods.len()],
        RopeLayout::SideBySide => slot_cells(c.methods.len())
            .into_iter()
            .map(|(col, row)| [2.3 * span * col as f64, 0.0, 1.6 * span * row as f64])
            .collect(),
    }
}

/// The rope's length at rest [m] (never 0, so slots stay apart).
fn rope_span(c: &RopeConfig) -> f64 {
    (c.params.end - c.params.start).length().max(1e-9)
}

/// What the layout needs of a run: a 3D view per method (one for all with `--layout overlay`)
/// framing one span around its first node, from the floor up, seen from the front and above.
pub fn staging(c: &RopeConfig) -> Staging {
    let p = &c.params;
    let span = rope_span(c);
    let top = p.start.z.max(p.end.z) + 0.1 * span;
    let floor = p.start.z.min(p.end.z) - 1.05 * span;
    let f = |v: f64| v as f32;
    let slot = |o: [f64; 3]| Framing {
        min: [
            f(o[0] + p.start.x - 1.1 * span),
            f(o[1] + p.start.y - 0.3 * span),
            f(o[2] + floor),
        ],
        max: [
            f(o[0] + p.start.x + 1.1 * span),
            f(o[1] + p.start.y + 0.3 * span),
            f(o[2] + top),
        ],
        toward_eye: [0.0, -1.0, 0.3],
    };
    let methods: Vec<&'static str> = c.methods.iter().map(|m| m.name()).collect();
    let slots = match c.layout {
        RopeLayout::Overlay => vec![Slot {
            title: "rope: every method from the same pin".to_string(),
            lanes: methods.clone(),
            framing: slot([0.0; 3]),
            plain: false,
        }],
        RopeLayout::SideBySide => Staging::per_lane(
            methods
                .iter()
                .zip(slot_offsets(c))
                .map(|(&m, o)| (m, slot(o))),
        ),
    };
    Staging {
        slots,
        plots: Staging::plots(&PLOTS, |_| methods.clone()),
        end_time: c.schedule().end_time(),
    }
}

/// Each method's rope in its slot (or overlaid), pins marked and labelled.
#[derive(Default)]
pub struct RopeDraw {
    names: Vec<&'static str>,
    offsets: Vec<[f64; 3]>,
    /// f32 scratch for positions, reused every frame.
    points: Vec<[f32; 3]>,
}

/// A recorder of rope runs.
pub fn recorder(rec: RecordingStream, timings: bool) -> SceneRecorder<RopeDraw> {
    SceneRecorder::new(rec, RopeDraw::default(), timings)
}

/// A point as the viewer takes it (the rope is z up like every scene: drawn as simulated).
fn f32_point(p: [f64; 3]) -> [f32; 3] {
    p.map(|c| c as f32)
}

impl RopeDraw {
    fn fill_points(&mut self, lane: usize, x: &[f64]) {
        let o = self.offsets[lane];
        self.points.clear();
        self.points.extend(
            (0..x.len() / 3)
                .map(|i| f32_point([x[3 * i] + o[0], x[3 * i + 1] + o[1], x[3 * i + 2] + o[2]])),
        );
    }
}

impl Draw<RopeScene> for RopeDraw {
    fn start(
        &mut self,
        rec: &RecordingStream,
        scene: &RopeScene,
        lanes: &[(&'static str, &RopeLane)],
    ) -> anyhow::Result<()> {
        let c = &scene.config;
        let p = &c.params;
        self.names = lanes.iter().map(|l| l.0).collect();
        // Slots sized to the rope: hanging from a pin it sweeps a circle of its own length.
        let span = rope_span(c);
        self.offsets = slot_offsets(c);
        rec.log_static("rope", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        let node_radius = (0.02 * span) as f32;
        for (i, name) in self.names.iter().enumerate() {
            let color = method_color(name);
            rec.log_static(
                format!("rope/{name}/nodes"),
                &rerun::Points3D::update_fields()
                    .with_radii([node_radius])
                    .with_colors([color]),
            )?;
            rec.log_static(
                format!("rope/{name}/strip"),
                &rerun::LineStrips3D::update_fields()
                    .with_radii([0.5 * node_radius])
                    .with_colors([color]),
            )?;
            let o = self.offsets[i];
            let at = |q: glam::DVec3| f32_point([q.x + o[0], q.y + o[1], q.z + o[2]]);
            let pinned: Vec<[f32; 3]> = (p.pinned.iter())
                .map(|&k| at(node(&scene.initial_positions, k)))
                .collect();
            // Each 3D view is titled with its method; a pin is labelled only when its rope
            // diverges, to say when.
            rec.log_static(
                format!("rope/{name}/pinned"),
                &rerun::Points3D::new(pinned)
                    .with_radii([2.5 * node_radius])
                    .with_colors([[235, 235, 235]])
                    .with_show_labels(true),
            )?;
        }
        rec.log_static(
            "rope/about",
            &rerun::TextDocument::from_markdown(about_text(scene)),
        )?;
        Ok(())
    }

    fn frame(
        &mut self,
        rec: &RecordingStream,
        _scene: &RopeScene,
        f: &Frame<RopeLane>,
    ) -> anyhow::Result<()> {
        for (i, lane) in f.lanes.iter().enumerate() {
            let Some((lane, _)) = lane else { continue };
            let name = self.names[i];
            self.fill_points(i, lane.positions());
            rec.log(
                format!("rope/{name}/nodes"),
                &rerun::Points3D::update_fields().with_positions(self.points.iter().copied()),
            )?;
            rec.log(
                format!("rope/{name}/strip"),
                &rerun::LineStrips3D::update_fields().with_strips([self.points.iter().copied()]),
            )?;
        }
        Ok(())
    }

    fn frame_bytes(&self, scene: &RopeScene) -> usize {
        scene.config.params.nodes * 12
    }

    fn diverged(&mut self, rec: &RecordingStream, e: &Event) -> anyhow::Result<()> {
        let name = self.names[e.lane];
        // The rope disappears from its slot; its pin marker stays, relabelled.
        let label = clear_diverged(rec, "rope", name, &["nodes", "strip"], e)?;
        rec.log(
            format!("rope/{name}/pinned"),
            &rerun::Points3D::update_fields().with_labels([label]),
        )?;
        Ok(())
    }
}

fn about_text(scene: &RopeScene) -> String {
    let c = &scene.config;
    let p = &c.params;
    let s = c.schedule();
    let cost = |m: crate::integrate::Method| cost_per_step(m, p.newton_iterations);
    let methods: Vec<String> = (c.methods.iter())
        .map(|&m| format!("| {} | {} |", m.name(), cost(m)))
        .collect();
    format!(
        "# rope\n\n\
         {} point masses from {:?} to {:?} m, springs' rest length = initial spacing \
         {} m; forces: {}; pinned nodes {:?}. f64.\n\n\
         | parameter | value |\n|---|---|\n| mass per node | {} kg |\n| ks | {} N/m |\n| kd | {} N·s/m |\n\
         | ka | {} N·s/m |\n| gravity | {:?} m/s² |\n| dt | {} s |\n| steps | {} |\n| 3D frames | {} |\n\
         | plotted | {} |\n| Verlet damping d | {} |\n| implicit Newton iterations | {} |\n\n\
         The linearised rope's {}.\n\
         Energy E0 = {} J (gravity's zero at the origin), energy scale {:.4} J. {}. A method stops when its \
         state is not finite, a strain exceeds {:.3}, or it gains more than {ENERGY_GAIN_BOUND} × \
         the energy scale (a passive rope never gains energy); the events panel shows when. Frame cost is \
         wall-clock time.\n\n\
         | method | cost per step |\n|---|---|\n{}\n",
        p.nodes,
        p.start.to_array(),
        p.end.to_array(),
        trim_number(scene.rope.rest(), 9),
        crate::report::rope::forces_text(p),
        p.pinned,
        p.mass,
        p.stiffness,
        p.spring_damping,
        p.air_drag,
        p.gravity.to_array(),
        c.dt,
        s.total,
        s.frames_text(),
        s.series_text(&crate::scene::harness::Scene::windows(scene)),
        c.options.verlet_damping,
        p.newton_iterations,
        crate::report::rope::rates_text(scene),
        crate::report::rope::e0_text(scene),
        scene.energy_scale,
        crate::report::rope::ENERGY_COLUMNS,
        scene.strain_bound,
        methods.join("\n"),
    )
}
