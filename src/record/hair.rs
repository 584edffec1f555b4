//! Recording a hair run.
//!
//! Layout: `hair/<method>/{head,strands,roots}` per method, each on its own copy of the head
//! (slots side by side along x); all strands of a frame are one line-strip entity, with colour and
//! radius logged once and only positions per frame. Plots `hair/plots/<quantity>/<method>`.

use rerun::RecordingStream;
use rerun::blueprint::{Blueprint, Horizontal, Vertical};

use super::scene::{Draw, SceneRecorder, clear_diverged};
use super::{
    about_and_events, log_stage, method_color, plot_column, plots_shown, scene_blueprint,
    scene_view,
};
use crate::scene::hair::Hair;
use crate::scene::hair::run::{HairConfig, HairLane, HairScene};
use crate::scene::harness::{Event, Frame};

pub const PLOTS: [(&str, &str); 3] = [
    ("max_stretch", "maximum relative stretch |ℓ − ℓ0| / ℓ0"),
    (
        "max_penetration",
        "maximum penetration of non-root nodes into R(1 + margin) [m]",
    ),
    (
        "specific_kinetic_energy",
        "kinetic energy per unit mass of hair, ½|v|² averaged over the nodes [J/kg]",
    ),
];

pub fn blueprint(timings: bool) -> Blueprint {
    let left = Vertical::new([
        scene_view("hair", "hair: methods side by side", &[]).into(),
        Horizontal::new(about_and_events("hair")).into(),
    ])
    .with_row_shares([3.0, 1.0]);
    scene_blueprint(left, plot_column("hair", &plots_shown(&PLOTS, timings)))
}

/// Each method's head and strands in its slot.
pub struct HairDraw {
    names: Vec<&'static str>,
    offsets: Vec<glam::DVec3>,
    nodes: usize,
}

/// A recorder of hair runs.
pub fn recorder(rec: RecordingStream, timings: bool) -> SceneRecorder<HairDraw> {
    SceneRecorder::new(
        rec,
        HairDraw {
            names: Vec::new(),
            offsets: Vec::new(),
            nodes: 1,
        },
        timings,
    )
}

impl HairDraw {
    fn log_state(&self, rec: &RecordingStream, lane: usize, hair: &Hair) -> anyhow::Result<()> {
        let name = self.names[lane];
        let o = self.offsets[lane];
        let f = |p: glam::DVec3| {
            let q = p + o;
            [q.x as f32, q.y as f32, q.z as f32]
        };
        let strips: Vec<Vec<[f32; 3]>> = hair
            .pos
            .chunks(self.nodes)
            .map(|s| s.iter().map(|&p| f(p)).collect())
            .collect();
        rec.log(
            format!("hair/{name}/strands"),
            &rerun::LineStrips3D::update_fields().with_strips(strips),
        )?;
        let roots: Vec<[f32; 3]> = hair.pos.chunks(self.nodes).map(|s| f(s[0])).collect();
        rec.log(
            format!("hair/{name}/roots"),
            &rerun::Points3D::update_fields().with_positions(roots),
        )?;
        let q = hair.head_rotation.as_quat();
        rec.log(
            format!("hair/{name}/head"),
            &rerun::Ellipsoids3D::update_fields()
                .with_centers([f(hair.head_center)])
                .with_quaternions([rerun::Quaternion::from_xyzw([q.x, q.y, q.z, q.w])]),
        )?;
        Ok(())
    }
}

impl Draw<HairScene> for HairDraw {
    /// Hair's `frame` is the simulation frame.
    fn frame_index(&self, tick: u64) -> i64 {
        tick as i64
    }

    fn start(
        &mut self,
        rec: &RecordingStream,
        scene: &HairScene,
        lanes: &[(&'static str, &HairLane)],
    ) -> anyhow::Result<()> {
        let config = &scene.config;
        let p = &config.params;
        self.names = lanes.iter().map(|l| l.0).collect();
        self.nodes = p.nodes;
        let reach = p.head_radius + p.segment_length * (p.nodes - 1) as f64;
        let spacing = 2.6 * reach + 2.0 * 2.0 * p.head_radius; // room for the sway
        self.offsets = (0..self.names.len())
            .map(|i| glam::DVec3::new(spacing * i as f64, 0.0, 0.0))
            .collect();
        rec.log_static("hair", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        let x_max = spacing * (self.names.len().max(1) - 1) as f64;
        let (a, b, floor) = (
            (-1.5 * reach) as f32,
            (x_max + 1.5 * reach) as f32,
            (-1.2 * reach) as f32,
        );
        let depth = (1.5 * reach) as f32;
        log_stage(
            rec,
            "hair/stage",
            [
                [a, -depth, floor],
                [b, -depth, floor],
                [b, depth, floor],
                [a, depth, floor],
            ],
        )?;
        let r = p.head_radius as f32;
        for name in &self.names {
            let color = method_color(name);
            rec.log_static(
                format!("hair/{name}/strands"),
                &rerun::LineStrips3D::update_fields()
                    .with_colors([color])
                    .with_radii([0.004 * r]),
            )?;
            rec.log_static(
                format!("hair/{name}/roots"),
                &rerun::Points3D::update_fields()
                    .with_colors([[230, 230, 230]])
                    .with_radii([0.01 * r]),
            )?;
            rec.log_static(
                format!("hair/{name}/head"),
                &rerun::Ellipsoids3D::update_fields()
                    .with_half_sizes([[r, r, r]])
                    .with_colors([[150, 150, 160]])
                    .with_fill_mode(rerun::components::FillMode::MajorWireframe)
                    .with_labels([*name])
                    .with_show_labels(true),
            )?;
        }
        rec.log_static(
            "hair/about",
            &rerun::TextDocument::from_markdown(about_text(config)),
        )?;
        Ok(())
    }

    fn frame(
        &mut self,
        rec: &RecordingStream,
        _scene: &HairScene,
        f: &Frame<HairLane>,
    ) -> anyhow::Result<()> {
        for (i, lane) in f.lanes.iter().enumerate() {
            if let Some((lane, _)) = lane {
                self.log_state(rec, i, &lane.hair)?;
            }
        }
        Ok(())
    }

    fn diverged(&mut self, rec: &RecordingStream, e: &Event) -> anyhow::Result<()> {
        let name = self.names[e.lane];
        let label = clear_diverged(rec, "hair", name, &["strands", "roots"], e)?;
        rec.log(
            format!("hair/{name}/head"),
            &rerun::Ellipsoids3D::update_fields().with_labels([label]),
        )?;
        Ok(())
    }
}

fn about_text(c: &HairConfig) -> String {
    let p = &c.params;
    let methods: Vec<String> = c
        .methods
        .iter()
        .map(|m| format!("| {} | {} |", m.name(), m.description()))
        .collect();
    format!(
        "# hair\n\n\
         {} strands × {} nodes (segment {} m) rooted on a head of radius {} m by a golden-angle spiral over the \
         cap; head motion `{:?}`; gravity {:?} m/s², wind {:?} m/s² with gusts ±{}%, damping {} 1/s; \
         verlet solver {}, {} iterations; spring stiffness k/m {:e} 1/s², damping kd/m {} 1/s; {} substeps per frame at {} Hz; collision margin {} R.\n\n\
         Each method has its own head copy (slots side by side). Plots are per simulation frame; the \
         3D state every {} frames.\n\n| method | update |\n|---|---|\n{}\n",
        p.strands,
        p.nodes,
        p.segment_length,
        p.head_radius,
        p.motion,
        p.gravity.to_array(),
        p.wind.to_array(),
        100.0 * p.gust,
        p.damping,
        p.solver.name(),
        p.iterations,
        p.stiffness,
        p.spring_damping,
        c.substeps,
        c.rate,
        p.margin,
        c.log_stride(),
        methods.join("\n"),
    )
}
