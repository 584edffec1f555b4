//! Each scene's flags. They only parse: a flag struct serialises to the table of the values
//! given (absent ones are left out), which is layered over the scene file's table and the
//! scene's defaults by `app::layers`; the keys are the scene configuration's own.

use clap::Args;
use serde::Serialize;

use super::{Indices, Magnitude, Vector};
use crate::integrate::Method;
use crate::scene::hair::{HairMethod, HeadMotion, Solver};
use crate::scene::harness::Window;
use crate::scene::rope::run::{RopeLayout, RopePreset};

/// The pendulum's start: the flags `physlab pendulum` and `physlab study` share.
#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct PendulumStart {
    /// Initial angle θ0 from straight down [degrees], within ±1000 turns, taken into
    /// (-180°, 180°] (so 190° is -170°). A release from rest is compared with the exact elliptic
    /// solution; a start with ω0 ≠ 0, or at exactly 180°, with a fine-step RK4 one
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub theta0: Option<f64>,

    /// Initial angular velocity ω0 [rad/s]
    #[arg(long, value_name = "RAD/S", allow_negative_numbers = true)]
    pub omega0: Option<f64>,
}

/// The rope's size and material: the flags `physlab rope` and `physlab study` share.
#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct RopeBody {
    /// Number of point masses, ≥ 2
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<usize>())]
    pub nodes: Option<usize>,

    /// Mass of each node [kg]
    #[arg(long, value_name = "KG", allow_negative_numbers = true)]
    pub mass: Option<f64>,

    /// Spring stiffness ks [N/m]
    #[arg(long, value_name = "N/M", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,
}

/// The rope's losses: the flags `physlab rope` and the sweeping studies share.
#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct RopeLosses {
    /// Spring damping kd on the relative velocity along each spring [N·s/m]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Air drag ka, force -ka·v on every node [N·s/m]
    #[arg(long, value_name = "N·S/M", allow_negative_numbers = true)]
    pub air_drag: Option<f64>,
}

/// How the pendulum and the rope are stepped, sampled and drawn: the flags both take.
#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct StepFlags {
    /// Time step dt [s], the same for every method
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulated time [s]; the run takes round(duration / dt) steps
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step (beyond 10,000 plotted steps the plots are aggregated: see --window)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<u64>())]
    pub plot_every: Option<u64>,

    /// A stretch of simulated time whose every sampled step is kept when the run is long enough
    /// that its plots are aggregated, FROM:TO in seconds (negative counts back from the end,
    /// either may be empty); repeat for more. The first and last few seconds are always kept
    #[arg(long, value_name = "FROM:TO", allow_hyphen_values = true)]
    pub window: Option<Vec<Window>>,

    /// Methods to run, comma-separated (the names are listed from the registry by `cli::command`)
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// Verlet's damping factor d in x1 = x0 + (1-d)(x0 - x_-1) + a dt², 0 ≤ d < 1
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub verlet_damping: Option<f64>,

    /// Relative tolerance per substep (the absolute one equals it)
    #[arg(long, value_name = "TOL", allow_negative_numbers = true)]
    pub rtol: Option<f64>,

    /// Compensated (Kahan) summation in the composition methods' updates: round-off about
    /// |h v| / |x| times smaller per step
    #[arg(long)]
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub compensated: bool,

    /// The fixed-step methods' own step [s], when it should not be --dt: they step at S and
    /// report every dt from the quintic Hermite interpolant through x, v and a at both ends of
    /// the step that holds the sample time (samples of order min(p, 6); one more force
    /// evaluation per step, none for rkn4; a step that divides dt ends at every sample and
    /// needs neither); at least dt/4096
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub step: Option<f64>,
}

#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct PendulumArgs {
    /// Gravitational acceleration g [m/s²], or the z-up vector x,y,z the rope and hair take
    /// (e.g. 0,0,-9.81), of which the pendulum uses the length |g| (it swings in the plane of
    /// gravity; θ is measured from the direction gravity points)
    #[arg(long, value_name = "G|X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Magnitude>,

    /// Rod length L, pivot to bob [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub length: Option<f64>,

    #[command(flatten)]
    #[serde(flatten)]
    pub initial: PendulumStart,

    #[command(flatten)]
    #[serde(flatten)]
    pub step: StepFlags,
}

#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct RopeArgs {
    /// Start from a known parameter set; flags given as well override it. games101: GAMES101
    /// assignment 8 (16 nodes from 0,0,200 to -400,0,200, mass 1, ks 100, no damping or drag,
    /// gravity 0,0,-1, dt 1/64 with 64 steps per frame, node 0 pinned, Verlet damping 0.00005,
    /// 20 time units)
    #[arg(long, value_name = "PRESET")]
    pub preset: Option<RopePreset>,

    #[command(flatten)]
    #[serde(flatten)]
    pub body: RopeBody,

    #[command(flatten)]
    #[serde(flatten)]
    pub losses: RopeLosses,

    /// First node's position x,y,z [m], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub start: Option<Vector>,

    /// Last node's position x,y,z [m], z up; nodes are spaced evenly, and that spacing is every
    /// spring's rest length
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub end: Option<Vector>,

    /// Gravitational acceleration x,y,z [m/s²], z up like every scene
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Indices of pinned nodes, comma-separated, e.g. 0,15 for both ends; "" pins none
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub pinned: Option<Indices>,

    #[command(flatten)]
    #[serde(flatten)]
    pub step: StepFlags,

    /// Newton iterations per implicit-Euler step: 1 = linearised backward Euler
    /// (Baraff–Witkin), which is not unconditionally stable (it diverges on the default rope at
    /// dt = 0.3 s); more refine towards exact backward Euler, stopping at tolerance
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub newton_iterations: Option<u32>,

    /// Where each method's rope is drawn: side-by-side or overlay
    #[arg(long, value_name = "LAYOUT")]
    pub layout: Option<RopeLayout>,
}

#[derive(Args, Debug, Clone, Default, Serialize, PartialEq)]
pub struct HairArgs {
    /// Number of strands, rooted by a golden-angle spiral over the upper head
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<usize>())]
    pub strands: Option<usize>,

    /// Nodes per strand, the root included
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<usize>())]
    pub nodes: Option<usize>,

    /// Rest length of every segment [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub segment_length: Option<f64>,

    /// Head (sphere) radius [m]
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub head_radius: Option<f64>,

    /// Scripted head path: smooth pulses that start and end at rest
    #[arg(long, value_name = "MOTION")]
    pub head_motion: Option<HeadMotion>,

    /// Wind as an acceleration x,y,z on every node [m/s²], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub wind: Option<Vector>,

    /// Gust strength as a fraction of the wind: the wind varies by ±this, smoothly and
    /// deterministically
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub gust: Option<f64>,

    /// Gravitational acceleration x,y,z [m/s²], z up
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity: Option<Vector>,

    /// Velocity damping rate c [1/s]: velocities decay as exp(-c t)
    #[arg(long, value_name = "1/S", allow_negative_numbers = true)]
    pub damping: Option<f64>,

    /// How verlet solves its length constraints: direct (each strand's constraints together,
    /// Newton on the multipliers, tridiagonal, O(nodes), the tensions applied along the end-of-step
    /// segments, then an exact root-to-tip finish; holds
    /// length to round-off) or gauss-seidel (relaxation sweeps from root to tip, today's PBD, kept
    /// to measure the trade: 4 sweeps leave stretches of ~1.7 at 60 Hz)
    #[arg(long, value_name = "SOLVER")]
    pub solver: Option<Solver>,

    /// Newton steps (verlet with --solver direct) or Gauss–Seidel sweeps (verlet with --solver
    /// gauss-seidel) per step; ftl needs one pass, implicit-euler iterates to tolerance (≤ 40).
    /// Default 2: two Newton steps measure the tensions better than one, so the exact finish
    /// moves nodes less; with gauss-seidel, 2 sweeps (raise it: see `physlab study hair`)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub iterations: Option<u32>,

    /// Spring methods (semi-implicit-euler, implicit-euler): segment stiffness per unit node mass
    /// k/m [1/s²]. semi-implicit-euler takes inner steps h with h²·4k/m + 2h·4kd/m < 4 [default:
    /// the springs' wave speed ℓ0·√(k/m) at 100 × the speed the head and the pull of gravity and
    /// wind give a strand (the summary says it), at least 4e8: the stated 1e-2 stretch bound]
    #[arg(long, value_name = "1/S²", allow_negative_numbers = true)]
    pub stiffness: Option<f64>,

    /// Spring methods: damping per unit node mass kd/m [1/s] on the relative velocity along each
    /// segment (semi-implicit-euler; implicit-euler damps the stiff modes by itself)
    #[arg(long, value_name = "1/S", allow_negative_numbers = true)]
    pub spring_damping: Option<f64>,

    /// Steps per simulation frame
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub substeps: Option<u32>,

    /// Time step dt [s] of the simulation, as in every scene: sets --substeps to 1/(rate·dt),
    /// which must be a whole number [default: 1/(rate·substeps)]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulation frames per simulated second [Hz]
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub rate: Option<f64>,

    /// How often the 3D state is logged [Hz of simulated time]; plots get every frame
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// A stretch of simulated time whose every sampled step is kept when the run is long enough
    /// that its plots are aggregated, FROM:TO in seconds (negative counts back from the end,
    /// either may be empty); repeat for more. The first and last few seconds are always kept
    #[arg(long, value_name = "FROM:TO", allow_hyphen_values = true)]
    pub window: Option<Vec<Window>>,

    /// Simulated time [s] (one tour of the head takes 8 s)
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Collision margin as a fraction of the head radius
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub margin: Option<f64>,

    /// Methods to run, comma-separated: verlet, semi-implicit-euler, implicit-euler, ftl
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<HairMethod>>,

    /// Strands drawn in 3D, spread evenly over the head; every strand is still simulated and
    /// measured [default: as many as keep the 3D part of the recording under 180 MB]
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<usize>())]
    pub log_strands: Option<usize>,
}
