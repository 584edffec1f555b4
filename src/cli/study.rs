//! `physlab study KIND`: one subcommand per kind, each with only the flags it reads (so clap
//! refuses the others), the flags several kinds share in groups. The defaults each kind's help
//! shows are read from the study and the scenes by `help::command`.

use std::path::PathBuf;

use clap::{Args, Subcommand};

use super::{PendulumStart, RopeBody, RopeLosses};
use crate::integrate::Method;

#[derive(Subcommand, Debug, Clone)]
pub enum StudyKind {
    /// Error against dt, fitted order per method
    ///
    /// Runs each method at --levels step sizes, from --dt halving each time (the adaptive
    /// methods over --rtol instead), against the scene's reference (the exact elliptic pendulum,
    /// or a converged fine-step rope), and fits each method's order from the slope of its error
    /// above the reference's floor. Prints the runs and the fitted orders; with -o, --csv or
    /// --plots also draws error against dt, log-log.
    Convergence(SweepArgs),
    /// Error against wall time and force evaluations; the cheapest method per target
    ///
    /// Runs each method over its settings (the fixed-step ones also at steps above --dt, across
    /// the samples, the compositions also --compensated; the adaptive ones over --rtol),
    /// --repeats times each, the error sampled every --sample-every. First prints per --target
    /// the cheapest run and the scene command that makes it, then how the adaptive methods'
    /// error follows rtol and every run; with -o, --csv or --plots also draws error against
    /// cost, log-log.
    WorkPrecision(WorkPrecisionArgs),
    /// Largest stable dt per method by bisection, against theory
    ///
    /// Finds each method's largest stable step by bisection on the linearised problem (the
    /// pendulum at θ0 = 1e-12 rad from rest, or the undamped rope), each trial stepping --steps
    /// steps, and sets it against the theory's limit on ω·dt (`physlab methods`). Prints
    /// measured against theory; with -o, --csv or --plots also draws the limits.
    Stability(StabilityArgs),
    /// Hair: largest stretch against wall time per frame over the solvers' settings
    ///
    /// Runs the hair scene (200 strands, --duration of simulated time) over its solvers, Newton
    /// steps, Gauss–Seidel sweeps, substeps and spring stiffness, and sets the largest stretch
    /// against the wall time per frame. Prints every setting and the cheapest reaching each
    /// stretch target; with -o, --csv or --plots also draws stretch against cost, log-log. Takes
    /// minutes: a progress bar shows its ETA.
    Hair(HairStudyArgs),
    /// Energy and phase error over many periods, their growth fitted against theory
    ///
    /// Runs each method on the pendulum released from rest at --theta0 at step --dt for
    /// --duration (default 10⁵ periods at dt = 0.01 s; the fixed-step methods unless --methods
    /// names others), every step checked: the energy error of each step and the time of every
    /// upward crossing of θ = 0 against the closed form's. Fits how both grow with time over the
    /// run's last two decades and sets the exponents against theory (symplectic: energy bounded,
    /// phase ∝ t; others: energy ∝ t, phase ∝ t²). With --scene rope: the undamped study rope's
    /// energy error over 10⁴ s at dt = 1 ms, and its shortest spring (no phase: no closed form).
    /// Prints the exponents; with -o, --csv or --plots also draws the errors against time,
    /// log-log.
    Drift(DriftArgs),
}

impl StudyKind {
    /// The kind as `physlab study KIND` spells it.
    pub fn name(&self) -> &'static str {
        match self {
            StudyKind::Convergence(_) => "convergence",
            StudyKind::WorkPrecision(_) => "work-precision",
            StudyKind::Stability(_) => "stability",
            StudyKind::Hair(_) => "hair",
            StudyKind::Drift(_) => "drift",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyScene {
    Pendulum,
    Rope,
}

/// The scene a measuring study runs (every kind but `hair`, which has its own) and its methods.
#[derive(Args, Debug, Clone, Default)]
pub struct StudySceneArgs {
    /// The scene [default: pendulum]
    #[arg(long, value_enum)]
    pub scene: Option<StudyScene>,

    /// Scene parameters from a scene file (its [pendulum] or [rope] table); flags override it
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,

    /// Methods, comma-separated (the names are listed from the registry by `command`)
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// The rope's size and material (with --scene rope)
    #[command(flatten)]
    pub rope: RopeBody,
}

/// What every study writes.
#[derive(Args, Debug, Clone, Default)]
pub struct StudyOutputs {
    /// Also write one row per run as CSV (`-` for standard output; the tables then go to stderr)
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,

    /// Also write the diagrams and tables as a Rerun recording (`-` for standard output)
    #[arg(short, long, value_name = "FILE.rrd")]
    pub output: Option<PathBuf>,

    /// Write the diagrams (SVG and PNG) into this folder [default: beside -o, else beside --csv,
    /// named after it (`-o a.rrd`: a-pendulum-convergence.png); with neither, no diagram]
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,

    /// No progress bar or long-run notice (the study prints only its tables)
    #[arg(short, long)]
    pub quiet: bool,

    /// Print the full tables, every column and digit (the CSV always holds every figure)
    /// [default: fitted to 100 columns]
    #[arg(long)]
    pub wide: bool,
}

/// `study convergence` and `study work-precision`: a sweep over halved steps and tolerances.
#[derive(Args, Debug, Clone, Default)]
pub struct SweepArgs {
    #[command(flatten)]
    pub scene: StudySceneArgs,

    /// The pendulum's start (with --scene pendulum)
    #[command(flatten)]
    pub start: PendulumStart,

    /// The rope's damping and drag (with --scene rope)
    #[command(flatten)]
    pub losses: RopeLosses,

    /// Simulated time [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Coarsest step; each level halves it [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Number of step sizes
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub levels: Option<u32>,

    /// Relative tolerances, comma-separated
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        allow_negative_numbers = true
    )]
    pub rtol: Option<Vec<f64>>,

    /// Timed repeats per run (the median wall time is kept)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub repeats: Option<u32>,

    #[command(flatten)]
    pub out: StudyOutputs,
}

/// `study work-precision`: the sweep, the target errors it answers for, its horizon and where
/// its error is sampled.
#[derive(Args, Debug, Clone, Default)]
pub struct WorkPrecisionArgs {
    #[command(flatten)]
    pub sweep: SweepArgs,

    /// Target errors, comma-separated: the first lines give the cheapest run reaching each
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        allow_negative_numbers = true
    )]
    pub target: Option<Vec<f64>>,

    /// Horizon in periods of the exact solution, instead of --duration (with --scene pendulum)
    #[arg(
        long,
        value_name = "N",
        conflicts_with = "duration",
        allow_negative_numbers = true
    )]
    pub periods: Option<f64>,

    /// Interval the error is sampled at, a multiple of --dt [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub sample_every: Option<f64>,
}

/// `study stability`: bisection on the linearised problem, trials of `--steps` steps.
#[derive(Args, Debug, Clone, Default)]
pub struct StabilityArgs {
    #[command(flatten)]
    pub scene: StudySceneArgs,

    /// Steps each stability trial must stay bounded for
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<u64>())]
    pub steps: Option<u64>,

    #[command(flatten)]
    pub out: StudyOutputs,
}

/// `study drift`: one long run per method, from rest.
#[derive(Args, Debug, Clone, Default)]
pub struct DriftArgs {
    #[command(flatten)]
    pub scene: StudySceneArgs,

    /// Release angle θ0 from straight down, from rest [degrees], 0 < |θ0| < 180 (with --scene
    /// pendulum)
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub theta0: Option<f64>,

    /// Simulated time [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Time step [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Relative tolerance (one)
    #[arg(long, value_name = "TOL", value_parser = one_tolerance, allow_negative_numbers = true)]
    pub rtol: Option<f64>,

    #[command(flatten)]
    pub losses: RopeLosses,

    #[command(flatten)]
    pub out: StudyOutputs,
}

/// `study hair`: the hair scene's defaults over its solvers' settings.
#[derive(Args, Debug, Clone, Default)]
pub struct HairStudyArgs {
    /// Simulated time of each run [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    #[command(flatten)]
    pub out: StudyOutputs,
}

/// One tolerance: the drift study runs each adaptive method at one.
fn one_tolerance(text: &str) -> Result<f64, String> {
    text.trim().parse().map_err(|_| {
        "`study drift` runs each adaptive method at one tolerance; give one number, e.g. 1e-10"
            .to_string()
    })
}
