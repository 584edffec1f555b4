//! The command line, as clap derive types. Resolution and validation live in `app` and in the
//! scenes' `validate()`; the defaults `--help` shows are read from the scenes' `Default`
//! ([`command`]), never typed here.

mod help;
mod negative;
mod scenes;
mod study;
mod vector;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

pub use help::command;
pub use negative::join_negative_values;
pub use scenes::{
    HairArgs, PendulumArgs, PendulumStart, RopeArgs, RopeBody, RopeLosses, StepFlags,
};
pub use study::{
    DriftArgs, HairStudyArgs, StabilityArgs, StudyKind, StudyOutputs, StudyScene, StudySceneArgs,
    SweepArgs, WorkPrecisionArgs,
};
pub use vector::{Indices, Magnitude, Vector};

/// `physlab --version`: the version and the git commit the binary is built from (`-dirty` with
/// modified sources, `unknown` outside a git checkout).
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("PHYSLAB_GIT_COMMIT"),
    ")"
);

#[derive(Parser, Debug)]
#[command(
    name = "physlab",
    version = VERSION,
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
    Pendulum(SceneCommand<PendulumArgs>),
    /// Mass-spring rope: point masses, Hooke springs, spring damping, air drag, pinned nodes
    #[command(
        after_help = "Energy: E - E0 is the energy's change since the start, the physical loss to \
                      damping and drag included. W is the work the damping and drag dissipated, \
                      integrated with the state by each method's own stages. E + W - E0 is the \
                      energy balance, zero for the exact motion: each method's own energy error \
                      (plotted as log10 |E + W - E0| / scale), whatever the damping."
    )]
    Rope(SceneCommand<RopeArgs>),
    /// Hair strands on a moving head: Verlet, PBD and follow-the-leader with length constraints,
    /// sphere collision and wind
    Hair(HairCommand),
    /// Measure the speed/accuracy trade and the stability limits against theory
    #[command(
        subcommand,
        subcommand_value_name = "KIND",
        subcommand_help_heading = "Kinds",
        disable_help_subcommand = true
    )]
    Study(StudyKind),
    /// What a recording holds: provenance, scenes, methods, entity paths, time range, warnings
    Inspect(InspectArgs),
    /// Re-run what a recording holds from its embedded configuration and compare every series
    /// and 3D state with it (exit 0 identical, 1 different, 2 bad input)
    Reproduce(ReproduceArgs),
    /// Compare two recordings entity by entity: configurations key by key, then every series
    Diff(DiffArgs),
    /// Print the integrator registry: order, kind, symplecticity, force evaluations, stability;
    /// with a NAME, that method's update, evaluations and notes
    Methods(MethodsArgs),
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

    /// Where to write the recording (.rrd); its folder is created; `-` writes it to standard
    /// output (`physlab pendulum -o - | rerun -`) [default: recordings/<scene>.rrd]
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

    /// Neither write nor stream a recording: only the summary (throughput runs)
    #[arg(long)]
    pub no_record: bool,

    /// Also plot wall-clock costs (ms per frame); off by default so that a recording depends only
    /// on its inputs
    #[arg(long)]
    pub timings: bool,

    /// No progress bar
    #[arg(short, long)]
    pub quiet: bool,

    /// Print the summary's full table, every column and digit (the recording always holds it)
    /// [default: fitted to 100 columns]
    #[arg(long)]
    pub wide: bool,

    /// Exit with code 3 when any method diverged (the recording is still written), for scripts
    #[arg(long)]
    pub fail_on_divergence: bool,
}

#[derive(Args, Debug, Clone)]
pub struct AllArgs {
    #[command(flatten)]
    pub run: RunArgs,

    /// Time step dt [s] of every scene (overrides the scene file); in hair it is
    /// 1/(rate·substeps), so it must divide hair's frame
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Simulated time [s] of every scene (overrides the scene file)
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// 3D frames logged per simulated second, for every scene (overrides the scene file)
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub fps: Option<f64>,

    /// Plot every Nth step of the pendulum and the rope (overrides the scene file)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<u64>())]
    pub plot_every: Option<u64>,

    /// Methods, comma-separated (overrides the scene file); each scene runs those it supports
    /// (`physlab methods` lists the registry's and hair's), and every scene must be left one
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<String>>,
}

// A scene's flags and where its run goes (no doc comment: the command's own is its help).
#[derive(Args, Debug, Clone)]
pub struct SceneCommand<A: Args> {
    #[command(flatten)]
    pub scene: A,
    #[command(flatten)]
    pub run: RunArgs,
}

#[derive(Args, Debug, Clone)]
pub struct HairCommand {
    #[command(flatten)]
    pub scene: HairArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Worker threads for the strands, at most 4 × the cores [default: all cores]; results do
    /// not depend on it
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::cli::count::<usize>())]
    pub threads: Option<usize>,
}

#[derive(Args, Debug, Clone)]
pub struct MethodsArgs {
    /// A method's name (of the registry or of hair's `--methods`): its page in full
    pub name: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct InspectArgs {
    /// The recording to describe
    pub file: PathBuf,
    /// Write the recording's embedded scene file here, to run the same thing again with --config
    /// (`-` for standard output; the description then goes to stderr)
    #[arg(long, value_name = "FILE.toml")]
    pub config_out: Option<PathBuf>,
    /// Print no notes on stderr (the report is the output; accepted by every command)
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Args, Debug, Clone)]
pub struct ReproduceArgs {
    /// The recording to re-run and compare
    pub file: PathBuf,
    /// Accept differences up to this fraction of each series' largest magnitude (another CPU or
    /// compiler) [default: 0, bit-identical]
    #[arg(long, value_name = "REL", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Also write the re-run's recording here (a file: the re-run is read back to compare)
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,
    /// List every entity compared, identical ones too
    #[arg(short, long)]
    pub verbose: bool,
    /// Re-run even when the recording's configuration asks for more than 10 min, a 1 GB
    /// recording or 1 GB of memory (stated before it starts; refused without this flag)
    #[arg(long)]
    pub allow_long: bool,
    /// Print no notes on stderr (the report is the output; accepted by every command)
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Args, Debug, Clone)]
pub struct DiffArgs {
    /// The first recording (A)
    pub a: PathBuf,
    /// The second recording (B)
    pub b: PathBuf,
    /// Report the first time a series differs by more than this fraction of A's largest
    /// magnitude in that series [default: 0, any difference]
    #[arg(long, value_name = "REL", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Write a recording to read the difference at a glance: per plotted quantity B − A for
    /// every method, both runs' 3D overlaid, the configuration change and the first parting as
    /// text (`-` for standard output; the report then goes to stderr)
    #[arg(short, long, value_name = "D.rrd")]
    pub output: Option<PathBuf>,
    /// List every entity compared, identical ones too, instead of one line per group
    #[arg(short, long)]
    pub verbose: bool,
    /// Print no notes on stderr (the report is the output; accepted by every command)
    #[arg(short, long)]
    pub quiet: bool,
}

/// A count's parser: a whole number from 0 to 2^63 − 1, what a scene file holds (clap's own
/// takes up to 2^64 − 1, which the file then cannot carry); `negative::count_error` words its
/// refusals.
pub(crate) fn count<T: TryFrom<u64> + Clone + Send + Sync + 'static>()
-> clap::builder::RangedU64ValueParser<T> {
    clap::builder::RangedU64ValueParser::new().range(..=i64::MAX as u64)
}

/// Parses the process's arguments (clap prints usage errors and exits with code 2).
pub fn parse() -> Cli {
    use clap::FromArgMatches as _;
    let args = join_negative_values(std::env::args_os());
    let command = help::command();
    let matches = command
        .clone()
        .try_get_matches_from(&args)
        .unwrap_or_else(|e| {
            let message = negative::count_error(&e, &command);
            if let Some(message) = message.or_else(|| negative::not_utf8(&e, &args)) {
                eprintln!("error: {message}");
                std::process::exit(2);
            }
            help::with_takers(e, &command, &args).exit()
        });
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}
