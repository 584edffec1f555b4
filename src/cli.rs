//! The command line, as clap derive types only. Resolution and validation live in `app`.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::method::Method;

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
