//! Recording a hair run: `hair/<method>/{head,strands,roots}` per method, each on its own copy of
//! the head (slots side by side along x), all strands of a frame one line-strip entity. Plots
//! `hair/plots/<quantity>/<method>`.

use rerun::RecordingStream;

use super::scene::{Draw, SceneRecorder, clear_diverged};
use super::{Framing, Staging, method_color, view_above_text};
use crate::scene::hair::Hair;
use crate::scene::hair::run::{HairConfig, HairLane, HairScene};
use crate::scene::hair::{HairMethod, Solver};
use crate::scene::harness::{Event, Frame, Run};

pub const PLOTS: [(&str, &str); 3] = [
    (
        "log10_max_stretch",
        "log10 max |ℓ − ℓ0|/ℓ0: largest stretch (−17 to −14: round-off)",
    ),
    (
        "max_penetration",
        "max penetration into R(1 + margin) [m] (~1e-17: round-off)",
    ),
    (
        "specific_kinetic_energy",
        "kinetic energy per unit mass of hair, ½|v|² averaged over the nodes [J/kg]",
    ),
];

/// The hair's views, for the layouts.
pub const VIEWS: super::SceneViews = super::SceneViews {
    name: "hair",
    plots: &PLOTS,
    blueprint: |t, s, m, p| view_above_text("hair", s, t, m, p),
};

/// The strands' reach from the head's centre [m], and the spacing of the slots along x.
fn reach_and_spacing(c: &HairConfig) -> (f64, f64) {
    let p = &c.params;
    let reach = p.head_radius + p.segment_length * (p.nodes - 1) as f64;
    (reach, 2.6 * reach + 2.0 * 2.0 * p.head_radius) // room for the sway
}

/// What the layout needs of a run: a 3D view per method framing its head and the strands' reach
/// (further towards +x, where sway and wind carry them), seen from the front, side and above so
/// that the head's depth shows; the round-off plots on axes with a floor (stretch from 1e-17,
/// below f64's resolution of a length ratio, to 10; penetration from 0 to the margin), in tabs
/// behind the statement of their largest values where every method keeps them at round-off
/// (penetration always; stretch unless a spring or Gauss–Seidel sweeps, which leave ~1, run).
pub fn staging(c: &HairConfig) -> Staging {
    let p = &c.params;
    let (reach, spacing) = reach_and_spacing(c);
    let f = |v: f64| v as f32;
    let methods: Vec<&'static str> = c.methods.iter().map(|m| m.name()).collect();
    let mut slots = Staging::per_lane(methods.iter().enumerate().map(|(i, &m)| {
        let x = spacing * i as f64;
        (
            m,
            Framing {
                min: [f(x - 0.75 * reach), f(-reach), f(-0.85 * reach)],
                max: [f(x + 1.15 * reach), f(reach), f(1.2 * p.head_radius)],
                toward_eye: [0.1, -1.0, 0.35],
            },
        )
    }));
    slots.iter_mut().for_each(|s| s.plain = true);
    let mut plots = Staging::plots(&PLOTS, |_| methods.clone());
    let exact_lengths = c
        .methods
        .iter()
        .all(|m| *m == HairMethod::Ftl || (*m == HairMethod::Verlet && p.solver == Solver::Direct));
    for plot in &mut plots {
        (plot.range, plot.roundoff) = match plot.name {
            "log10_max_stretch" => (Some((-17.0, 1.0)), exact_lengths),
            "max_penetration" => (Some((0.0, p.margin * p.head_radius)), true),
            _ => (None, false),
        };
    }
    Staging {
        slots,
        plots,
        end_time: c.schedule().end_time(),
    }
}

/// Recorded bytes per strand node per logged 3D frame per method, LZ4 included: measured on
/// hair recordings of 500 to 2000 strands, rounded up.
pub const BYTES_PER_NODE_FRAME: f64 = 13.0;

/// The 3D part of a hair recording the default `--log-strands` keeps within [bytes], so a
/// recording stays under ~200 MB with its plots.
pub const DEFAULT_3D_BUDGET: f64 = 180e6;

/// How many strands a run draws in 3D and what its recording is expected to weigh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrandPlan {
    pub drawn: usize,
    pub strands: usize,
    pub expected_bytes: f64,
}

/// The strands drawn: `requested` (at most all), or by default as many as fit the 3D budget
/// (at least one); and the expected size.
pub fn strand_plan(c: &HairConfig, requested: Option<usize>) -> StrandPlan {
    let strands = c.params.strands;
    let frames = c.schedule().frames();
    let per_strand =
        BYTES_PER_NODE_FRAME * c.params.nodes as f64 * frames as f64 * c.methods.len() as f64;
    let drawn = match requested {
        Some(n) => n.min(strands),
        None => ((DEFAULT_3D_BUDGET / per_strand.max(1.0)) as usize).clamp(1, strands),
    };
    StrandPlan {
        drawn,
        strands,
        expected_bytes: drawn as f64 * per_strand,
    }
}

/// `drawn` strand indices spread evenly over `0..strands`, so over the head (golden-angle roots).
pub fn spread(drawn: usize, strands: usize) -> Vec<usize> {
    let n = drawn.min(strands).max(1);
    (0..n).map(|k| k * strands / n).collect()
}

/// Each method's head and strands in its slot.
#[derive(Default)]
pub struct HairDraw {
    names: Vec<&'static str>,
    offsets: Vec<glam::DVec3>,
    /// `--log-strands`: how many strands are drawn (None: the budget's default).
    requested: Option<usize>,
    /// The strands drawn, as indices.
    shown: Vec<usize>,
}

/// A recorder of hair runs, drawing `log_strands` strands in 3D (None: the default).
pub fn recorder(
    rec: RecordingStream,
    timings: bool,
    log_strands: Option<usize>,
) -> SceneRecorder<HairDraw> {
    SceneRecorder::new(
        rec,
        HairDraw {
            requested: log_strands,
            ..HairDraw::default()
        },
        timings,
    )
}

impl HairDraw {
    fn log_state(&self, rec: &RecordingStream, lane: usize, hair: &Hair) -> anyhow::Result<()> {
        let name = self.names[lane];
        let o = self.offsets[lane];
        let f = |p: glam::DVec3| (p + o).as_vec3().to_array();
        let strand = |k: usize| hair.strand(k).map(f).collect();
        let strips: Vec<Vec<[f32; 3]>> = self.shown.iter().map(|&k| strand(k)).collect();
        rec.log(
            format!("hair/{name}/strands"),
            &rerun::LineStrips3D::update_fields().with_strips(strips),
        )?;
        let roots: Vec<[f32; 3]> = self.shown.iter().map(|&k| f(hair.node(k, 0))).collect();
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
    fn start(
        &mut self,
        rec: &RecordingStream,
        scene: &HairScene,
        lanes: &[(&'static str, &HairLane)],
    ) -> anyhow::Result<()> {
        let config = &scene.config;
        let p = &config.params;
        self.names = lanes.iter().map(|l| l.0).collect();
        let plan = strand_plan(config, self.requested);
        self.shown = spread(plan.drawn, plan.strands);
        let (_, spacing) = reach_and_spacing(config);
        self.offsets = (0..self.names.len())
            .map(|i| glam::DVec3::new(spacing * i as f64, 0.0, 0.0))
            .collect();
        rec.log_static("hair", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
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
                    .with_show_labels(true),
            )?;
        }
        rec.log_static(
            "hair/about",
            &rerun::TextDocument::from_markdown(about_text(config, self.shown.len())),
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

    fn frame_bytes(&self, scene: &HairScene) -> usize {
        let p = &scene.config.params;
        p.strands * p.nodes * 12
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

    /// The statement the round-off plots stand behind: each one's largest value over the run.
    fn finish(
        &mut self,
        rec: &RecordingStream,
        scene: &HairScene,
        run: &Run<HairLane>,
    ) -> anyhow::Result<()> {
        let radius = scene.config.params.head_radius;
        let worst = |f: fn(&HairLane) -> f64| -> Vec<(&str, f64)> {
            self.names
                .iter()
                .copied()
                .zip(run.lanes.iter().map(f))
                .collect()
        };
        let text = [
            roundoff_line(
                "stretch |ℓ − ℓ0|/ℓ0",
                "",
                1.0,
                &worst(|l| l.worst.max_stretch),
            ),
            roundoff_line(
                "penetration into R(1 + margin)",
                " m",
                radius,
                &worst(|l| l.worst.max_penetration),
            ),
        ];
        rec.log_static(
            "hair/roundoff",
            &rerun::TextDocument::from_markdown(text.join("\n\n")),
        )?;
        Ok(())
    }
}

/// A relative error this small is round-off (f64's epsilon is 2.2e-16).
const ROUNDOFF: f64 = 1e-12;

/// "max stretch ≤ 2.2e-15 for every method: round-off", or each method's largest value where
/// some method's is above round-off (`scale` the quantity's size: a length for one in metres).
fn roundoff_line(what: &str, unit: &str, scale: f64, worst: &[(&str, f64)]) -> String {
    let max = worst.iter().map(|w| w.1).fold(0.0, f64::max);
    if max <= ROUNDOFF * scale {
        return format!("**max {what} ≤ {max:.1e}{unit}** for every method: round-off.");
    }
    let each: Vec<String> = worst
        .iter()
        .map(|(name, v)| format!("{name} {v:.1e}{unit}"))
        .collect();
    format!("**max {what}**: {}.", each.join(", "))
}

fn about_text(c: &HairConfig, drawn: usize) -> String {
    let p = &c.params;
    let methods: Vec<String> = (c.methods.iter())
        .map(|m| format!("| {} | {} |", m.name(), m.description()))
        .collect();
    format!(
        "# hair\n\n\
         {} strands × {} nodes (segment {} m) rooted on a head of radius {} m by a golden-angle spiral over the \
         cap; head motion `{}`; gravity {:?} m/s², wind {:?} m/s² with gusts ±{}%, damping {} 1/s; \
         verlet solver {}, {} iterations; spring stiffness k/m {:e} 1/s², damping kd/m {} 1/s; {} per frame at {} Hz; collision margin {} R.\n\n\
         Each method has its own head copy (slots side by side). Plots are per simulation frame: \
         {}.\n\n3D state {}, {} of the {} strands drawn (spread evenly over the head; every strand is \
         simulated and measured, `--log-strands` sets how many are drawn).\n\n| method | update |\n|---|---|\n{}\n",
        p.strands,
        p.nodes,
        p.segment_length,
        p.head_radius,
        format!("{:?}", p.motion).to_lowercase(),
        p.gravity.to_array(),
        p.wind.to_array(),
        100.0 * p.gust,
        p.damping,
        p.solver.name(),
        p.iterations,
        p.stiffness,
        p.spring_damping,
        crate::format::plural(c.substeps, "substep"),
        c.rate,
        p.margin,
        c.schedule()
            .series_text(&crate::scene::harness::Windows::with(&c.window)),
        c.schedule().frames_text(),
        drawn,
        p.strands,
        methods.join("\n"),
    )
}
