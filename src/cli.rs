//! The command line, as clap derive types only. Resolution and validation live in `app`.
//!
//! Each scene's parameter struct doubles as its table in a scene file (`--config FILE.toml`):
//! every field is optional, so a value can come from a flag, the file, a preset or the default,
//! in that order of precedence. Fields that say where output goes, not what is simulated, are
//! skipped in files.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use serde::{Deserialize, Serialize};

use crate::config::Vector;
use crate::method::Method;
use crate::record::rope::Layout;
use crate::scene::hair::{HairMethod, HeadMotion};

#[derive(Parser, Debug)]
#[command(
    name = "physlab",
    version,
    about = "A lab for numerical integration: physics scenes stepped by several integrators side by side, \
             recorded to Rerun .rrd files",
    after_help = "Open a recording with the Rerun viewer 0.36: `rerun recordings/all.rrd` \
                  (pip install rerun-sdk==0.36.3)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// All three scenes in one recording on one timeline (parameters from --config, a table per scene)
    All(AllArgs),
    /// Simple pendulum θ'' = -(g/L) sin θ: every method side by side against the exact solution
    Pendulum(PendulumCommand),
    /// Mass-spring rope: point masses, Hooke springs, spring damping, air drag, pinned nodes
    Rope(RopeCommand),
    /// Hair strands on a moving head: Verlet, PBD and follow-the-leader with length constraints,
    /// sphere collision and wind
    Hair(HairCommand),
    /// Measure the speed/accuracy trade and the stability limits against theory
    Study(StudyArgs),
    /// What a recording holds: provenance, scenes, methods, entity paths, time range, warnings
    Inspect(InspectArgs),
    /// Print the integrator registry: order, kind, symplecticity, force evaluations, stability
    Methods,
}

/// Where a run's output goes and how it reports; shared by every simulating command.
#[derive(Args, Debug, Clone, Default)]
pub struct RunArgs {
    /// Read parameters from a TOML scene file; flags given as well override it
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,

    /// Print the resolved parameters as TOML (a scene file) and exit without simulating
    #[arg(long)]
    pub print_config: bool,

    /// Where to write the recording (.rrd); its folder is created [default: recordings/<scene>.rrd]
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,

    /// Also stream to a running Rerun viewer [default URL: rerun+http://127.0.0.1:9876/proxy]
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = "rerun+http://127.0.0.1:9876/proxy")]
    pub connect: Option<String>,

    /// Also start a Rerun viewer (`rerun` from PATH) and stream to it
    #[arg(long)]
    pub spawn: bool,

    /// Do not write the recording file (with --connect or --spawn: stream only)
    #[arg(long)]
    pub no_save: bool,

    /// Also plot wall-clock costs (ms per frame); off by default so that a recording depends only
    /// on its inputs
    #[arg(long)]
    pub timings: bool,

    /// No progress bar
    #[arg(short, long)]
    pub quiet: bool,

    /// Exit with code 3 when any method diverged (the recording is still written), for scripts
    #[arg(long)]
    pub fail_on_divergence: bool,
}

#[derive(Args, Debug, Clone)]
pub struct AllArgs {
    #[command(flatten)]
    pub run: RunArgs,

    /// 3D frames logged per simulated second, for every scene (overrides the scene file)
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step of the pendulum and the rope (overrides the scene file)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub plot_every: Option<u64>,
}

#[derive(Args, Debug, Clone)]
pub struct PendulumCommand {
    #[command(flatten)]
    pub scene: PendulumArgs,
    #[command(flatten)]
    pub run: RunArgs,
}

#[derive(Args, Debug, Clone)]
pub struct RopeCommand {
    #[command(flatten)]
    pub scene: RopeArgs,
    #[command(flatten)]
    pub run: RunArgs,
}

#[derive(Args, Debug, Clone)]
pub struct HairCommand {
    #[command(flatten)]
    pub scene: HairArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Worker threads for the strands [default: all cores]; results do not depend on it
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Neither write nor stream a recording (throughput runs)
    #[arg(long)]
    pub no_record: bool,
}

#[derive(Args, Debug, Clone)]
pub struct InspectArgs {
    /// The recording to describe
    pub file: PathBuf,
    /// Write the recording's embedded scene file here, to run the same thing again with --config
    #[arg(long, value_name = "FILE.toml")]
    pub config_out: Option<PathBuf>,
}

#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PendulumArgs {
    /// Gravitational acceleration g [m/s²] [default: 9.81]
    #[arg(long, value_name = "M/S²", allow_negative_numbers = true)]
    pub gravity: Option<f64>,

    /// Rod length L, pivot to bob [m] [default: 3.521]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub length: Option<f64>,

    /// Initial angle θ0 from straight down [degrees] [default: 60]. Release from rest with
    /// |θ0| < 180° is compared with the exact elliptic solution; any other start with a converged
    /// fine-step one
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub theta0: Option<f64>,

    /// Initial angular velocity ω0 [rad/s] [default: 0]
    #[arg(long, value_name = "RAD/S", allow_negative_numbers = true)]
    pub omega0: Option<f64>,

    /// Time step dt [s], the same for every method [default: 0.01]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulated time [s]; the run takes round(duration / dt) steps [default: 20]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time] [default: 30]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step [default: 1, thinned further to at most 10,000 points per series]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub plot_every: Option<u64>,

    /// Methods to run, comma-separated [default: all seven]: explicit-euler, semi-implicit-euler,
    /// implicit-euler, midpoint, trapezoid, rk4, verlet
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// Verlet's damping factor d in x1 = x0 + (1-d)(x0 - x_-1) + a dt², 0 ≤ d < 1 [default: 0]
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub verlet_damping: Option<f64>,
    /// dopri5's relative tolerance per substep (the absolute one equals it) [default: 1e-6]
    #[arg(long, value_name = "TOL", allow_negative_numbers = true)]
    pub rtol: Option<f64>,
}

/// Parameter sets that reproduce a known setup; flags given with a preset override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RopePreset {
    /// GAMES101 assignment 8 (seed 003): 16 nodes from (0,200) to (-400,200), mass 1, ks 100,
    /// no spring damping or drag, gravity (0,-1), dt = 1/64 with 64 steps per frame, node 0
    /// pinned, Verlet damping 0.00005, 20 time units
    Games101,
}

#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RopeArgs {
    /// Start from a known parameter set; flags given as well override it
    #[arg(long, value_enum)]
    pub preset: Option<RopePreset>,

    /// Number of point masses, ≥ 2 [default: 16]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nodes: Option<usize>,

    /// First node's position x,y[,z] [m] [default: 0,0,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub start: Option<Vector>,

    /// Last node's position x,y[,z] [m]; nodes are spaced evenly, and that spacing is every
    /// spring's rest length [default: 4,0,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub end: Option<Vector>,

    /// Mass of each node [kg] [default: 0.1]
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,

    /// Spring stiffness ks [N/m] [default: 5000]
    #[arg(long, value_name = "N/M", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,

    /// Spring damping kd on the relative velocity along each spring [N·s/m] [default: 0.05]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Air drag ka, force -ka·v on every node [N·s/m] [default: 0.01]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub air_drag: Option<f64>,

    /// Gravitational acceleration x,y[,z] [m/s²] [default: 0,-9.81,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Indices of pinned nodes, comma-separated, e.g. 0,15 for both ends [default: 0]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub pinned: Option<Vec<usize>>,

    /// Time step [s] [default: 0.001]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulated time [s] [default: 10]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// 3D frames per simulated second [default: 30]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step [default: 5, thinned further to at most 10,000 points per series]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub plot_every: Option<u64>,

    /// Methods to run, comma-separated [default: all seven]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// Verlet's damping factor d, 0 ≤ d < 1 [default: 0; 0.00005 with --preset games101]
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub verlet_damping: Option<f64>,

    /// Newton iterations per implicit-Euler step: 1 = linearised backward Euler
    /// (Baraff–Witkin); more refine towards exact backward Euler, stopping at tolerance [default: 1]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub newton_iterations: Option<u32>,

    /// Where each method's rope is drawn [default: side-by-side]
    #[arg(long, value_enum)]
    pub layout: Option<Layout>,
    /// dopri5's relative tolerance per substep (the absolute one equals it) [default: 1e-6]
    #[arg(long, value_name = "TOL", allow_negative_numbers = true)]
    pub rtol: Option<f64>,
}

#[derive(Args, Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HairArgs {
    /// Number of strands, rooted by a golden-angle spiral over the upper head [default: 200]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub strands: Option<usize>,

    /// Nodes per strand, the root included [default: 16]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nodes: Option<usize>,

    /// Rest length of every segment [m] [default: 0.015]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub segment_length: Option<f64>,

    /// Head (sphere) radius [m] [default: 0.1]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub head_radius: Option<f64>,

    /// Scripted head path: smooth pulses that start and end at rest [default: tour]
    #[arg(long, value_enum)]
    pub head_motion: Option<HeadMotion>,

    /// Wind as an acceleration x,y[,z] on every node [m/s²], z up [default: 1,0,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub wind: Option<Vector>,

    /// Gust strength as a fraction of the wind: the wind varies by ±this, smoothly and
    /// deterministically [default: 0.5]
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub gust: Option<f64>,

    /// Gravitational acceleration x,y[,z] [m/s²], z up [default: 0,0,-9.81]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t) [default: 1]
    #[arg(long, value_name = "1/S", allow_negative_numbers = true)]
    pub damping: Option<f64>,

    /// Constraint-projection rounds per step (verlet, semi-implicit-euler; ftl needs one pass)
    /// [default: 4]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub iterations: Option<u32>,

    /// Steps per simulation frame [default: 1]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub substeps: Option<u32>,

    /// Simulation frames per simulated second [Hz] [default: 60]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub rate: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time]; plots get every frame [default: 15]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Simulated time [s] (one tour of the head takes 8 s) [default: 8]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Collision margin as a fraction of the head radius [default: 0.001]
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub margin: Option<f64>,

    /// Methods to run, comma-separated [default: verlet, semi-implicit-euler, ftl]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<HairMethod>>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyKind {
    /// Error against dt, fitted order per method
    Convergence,
    /// Error against median wall time and against force evaluations; cheapest method per target
    WorkPrecision,
    /// Largest stable dt per method by bisection, against theory
    Stability,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyScene {
    Pendulum,
    Rope,
}

#[derive(Args, Debug, Clone)]
pub struct StudyArgs {
    /// What to measure
    #[arg(value_enum)]
    pub kind: StudyKind,

    /// The scene
    #[arg(long, value_enum, default_value_t = StudyScene::Pendulum)]
    pub scene: StudyScene,

    /// Scene parameters from a scene file (its [pendulum] or [rope] table); flags override it
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,

    /// Pendulum: initial angle [degrees] [default: 60]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub theta0: Option<f64>,

    /// Pendulum: initial angular velocity [rad/s] [default: 0]
    #[arg(long, value_name = "RAD/S", allow_negative_numbers = true)]
    pub omega0: Option<f64>,

    /// Rope: nodes [default: 16]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nodes: Option<usize>,

    /// Rope: spring stiffness [N/m] [default: 100 for convergence and work-precision, the scene's 5000 for stability]
    #[arg(long, value_name = "N/M", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,

    /// Rope: node mass [kg] [default: 0.1]
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,

    /// Rope: spring damping [N·s/m] [default: 0, so that the theory's orders apply]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Rope: air drag [N·s/m] [default: 0]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub air_drag: Option<f64>,

    /// Simulated time [s] [default: 10 for the pendulum, 1 for the rope]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Coarsest step; each level halves it [s] [default: 0.02 pendulum, 0.002 rope]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Number of step sizes [default: 6]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub levels: Option<u32>,

    /// Methods, comma-separated [default: all nine]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// dopri5's tolerances for work-precision, comma-separated [default: 1e-3,1e-4,...,1e-12]
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        allow_negative_numbers = true
    )]
    pub rtol: Option<Vec<f64>>,

    /// Timed repeats per run for work-precision (the median is kept) [default: 5]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub repeats: Option<u32>,

    /// Steps each stability trial must stay bounded for [default: 2000]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub steps: Option<u64>,

    /// Also write one row per run as CSV
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,

    /// Also write the curves and tables as a Rerun recording
    #[arg(short, long, value_name = "FILE.rrd")]
    pub output: Option<PathBuf>,
}
