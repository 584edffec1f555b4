//! The command line, as clap derive types only. Resolution and validation live in `app`.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::method::Method;
use crate::record::rope::Layout;
use crate::scene::hair::{HairMethod, HeadMotion};

#[derive(Parser, Debug)]
#[command(
    name = "physlab",
    version,
    about = "A lab for numerical integration: physics scenes stepped by several integrators side by side, \
             recorded to Rerun .rrd files",
    after_help = "Open a recording with the Rerun viewer 0.36: `rerun recordings/pendulum.rrd` \
                  (pip install rerun-sdk==0.36.3)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Simple pendulum θ'' = -(g/L) sin θ: every method side by side against the exact solution;
    /// writes a recording and prints a summary table
    Pendulum(PendulumArgs),
    /// Mass-spring rope: point masses, Hooke springs, spring damping, air drag, pinned nodes;
    /// every method side by side; writes a recording and prints a summary table
    Rope(RopeArgs),
    /// Hair strands on a moving head: Verlet, PBD and follow-the-leader side by side with length
    /// constraints, sphere collision and wind; writes a recording and prints a summary table
    Hair(HairArgs),
    /// Print the integrator registry: order, kind, symplecticity, force evaluations, stability
    Methods,
}

#[derive(Args, Debug, Clone)]
pub struct PendulumArgs {
    /// Gravitational acceleration g [m/s²]
    #[arg(
        long,
        default_value_t = 9.81,
        value_name = "M/S²",
        allow_negative_numbers = true
    )]
    pub gravity: f64,

    /// Rod length L, pivot to bob [m]
    #[arg(
        long,
        default_value_t = 3.521,
        value_name = "M",
        allow_negative_numbers = true
    )]
    pub length: f64,

    /// Initial angle θ0 from straight down [degrees]. Release from rest with |θ0| < 180° is
    /// compared with the exact elliptic solution; any other start with a converged fine-step one
    #[arg(
        long,
        default_value_t = 60.0,
        value_name = "DEG",
        allow_negative_numbers = true
    )]
    pub theta0: f64,

    /// Initial angular velocity ω0 [rad/s]
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "RAD/S",
        allow_negative_numbers = true
    )]
    pub omega0: f64,

    /// Time step dt [s], the same for every method
    #[arg(
        long,
        default_value_t = 0.01,
        value_name = "S",
        allow_negative_numbers = true
    )]
    pub dt: f64,

    /// Simulated time [s]; the run takes round(duration / dt) steps
    #[arg(
        long,
        default_value_t = 20.0,
        value_name = "S",
        allow_negative_numbers = true
    )]
    pub duration: f64,

    /// How often the 3D state is logged [Hz of simulated time]; plots get every step
    /// (thinned evenly beyond 10,000 points per series)
    #[arg(
        long,
        default_value_t = 30.0,
        value_name = "HZ",
        allow_negative_numbers = true
    )]
    pub fps: f64,

    /// Methods to run, comma-separated [default: all seven]: explicit-euler, semi-implicit-euler,
    /// implicit-euler, midpoint, trapezoid, rk4, verlet
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Vec<Method>,

    /// Verlet's damping factor d in x1 = x0 + (1-d)(x0 - x_-1) + a dt², 0 ≤ d < 1 [dimensionless]
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "D",
        allow_negative_numbers = true
    )]
    pub verlet_damping: f64,

    /// Where to write the recording (.rrd); its folder is created
    #[arg(
        short,
        long,
        default_value = "recordings/pendulum.rrd",
        value_name = "PATH"
    )]
    pub output: PathBuf,
}

/// Parameter sets that reproduce a known setup; flags given with a preset override it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RopePreset {
    /// GAMES101 assignment 8 (seed 003): 16 nodes from (0,200) to (-400,200), mass 1, ks 100,
    /// no spring damping or drag, gravity (0,-1), dt = 1/64 with 64 steps per frame, node 0
    /// pinned, Verlet damping 0.00005, 20 time units
    Games101,
}

/// Rope flags. Every value is optional so that a preset can fill what the user did not give;
/// the defaults below apply when neither does.
#[derive(Args, Debug, Clone)]
pub struct RopeArgs {
    /// Start from a known parameter set; flags given as well override it
    #[arg(long, value_enum)]
    pub preset: Option<RopePreset>,

    /// Number of point masses, ≥ 2 [default: 16]
    #[arg(long, value_name = "N")]
    pub nodes: Option<usize>,

    /// First node's position x,y[,z] [m] [default: 0,0,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub start: Option<String>,

    /// Last node's position x,y[,z] [m]; nodes are spaced evenly, and that spacing is every
    /// spring's rest length [default: 4,0,0]
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub end: Option<String>,

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
    pub gravity: Option<String>,

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

    /// Methods to run, comma-separated [default: all seven]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Vec<Method>,

    /// Verlet's damping factor d, 0 ≤ d < 1 [default: 0; 0.00005 with --preset games101]
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub verlet_damping: Option<f64>,

    /// Newton iterations per implicit-Euler step: 1 = linearised backward Euler
    /// (Baraff–Witkin); more refine towards exact backward Euler, stopping at tolerance [default: 1]
    #[arg(long, value_name = "N")]
    pub newton_iterations: Option<u32>,

    /// Where each method's rope is drawn
    #[arg(long, value_enum, default_value_t = Layout::SideBySide)]
    pub layout: Layout,

    /// Where to write the recording (.rrd); its folder is created
    #[arg(
        short,
        long,
        default_value = "recordings/rope.rrd",
        value_name = "PATH"
    )]
    pub output: PathBuf,
}

#[derive(Args, Debug, Clone)]
pub struct HairArgs {
    /// Number of strands, rooted by a golden-angle spiral over the upper head
    #[arg(long, default_value_t = 200, value_name = "N")]
    pub strands: usize,

    /// Nodes per strand, the root included
    #[arg(long, default_value_t = 16, value_name = "N")]
    pub nodes: usize,

    /// Rest length of every segment [m]
    #[arg(
        long,
        default_value_t = 0.015,
        value_name = "M",
        allow_negative_numbers = true
    )]
    pub segment_length: f64,

    /// Head (sphere) radius [m]
    #[arg(
        long,
        default_value_t = 0.1,
        value_name = "M",
        allow_negative_numbers = true
    )]
    pub head_radius: f64,

    /// Scripted head path: smooth pulses that start and end at rest
    #[arg(long, value_enum, default_value_t = HeadMotion::Tour)]
    pub head_motion: HeadMotion,

    /// Wind as an acceleration x,y[,z] on every node [m/s²], z up
    #[arg(
        long,
        default_value = "1,0,0",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub wind: String,

    /// Gust strength as a fraction of the wind: the wind varies by ±this, smoothly and deterministically
    #[arg(
        long,
        default_value_t = 0.5,
        value_name = "FRACTION",
        allow_negative_numbers = true
    )]
    pub gust: f64,

    /// Gravitational acceleration x,y[,z] [m/s²], z up
    #[arg(
        long,
        default_value = "0,0,-9.81",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub gravity: String,

    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t)
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "1/S",
        allow_negative_numbers = true
    )]
    pub damping: f64,

    /// Constraint-projection rounds per step (verlet, semi-implicit-euler; ftl needs one pass)
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub iterations: u32,

    /// Steps per simulation frame
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub substeps: u32,

    /// Simulation frames per simulated second [Hz]
    #[arg(
        long,
        default_value_t = 60.0,
        value_name = "HZ",
        allow_negative_numbers = true
    )]
    pub rate: f64,

    /// How often the 3D state is logged [Hz of simulated time]; plots get every frame
    #[arg(
        long,
        default_value_t = 20.0,
        value_name = "HZ",
        allow_negative_numbers = true
    )]
    pub fps: f64,

    /// Simulated time [s] (one tour of the head takes 8 s)
    #[arg(
        long,
        default_value_t = 8.0,
        value_name = "S",
        allow_negative_numbers = true
    )]
    pub duration: f64,

    /// Collision margin as a fraction of the head radius
    #[arg(
        long,
        default_value_t = 1e-3,
        value_name = "FRACTION",
        allow_negative_numbers = true
    )]
    pub margin: f64,

    /// Methods to run, comma-separated [default: verlet, semi-implicit-euler, ftl]
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Vec<HairMethod>,

    /// Worker threads for the strands [default: all cores]; results do not depend on it
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,

    /// Do not write a recording (throughput runs)
    #[arg(long)]
    pub no_record: bool,

    /// Where to write the recording (.rrd); its folder is created
    #[arg(
        short,
        long,
        default_value = "recordings/hair.rrd",
        value_name = "PATH"
    )]
    pub output: PathBuf,
}
