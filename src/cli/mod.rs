//! The command line, as clap derive types. Resolution and validation live in `app` and in the
//! scenes' `validate()`; the defaults `--help` shows are read from the scenes' `Default`
//! ([`command`]), never typed here.

mod scenes;
mod vector;

use std::path::PathBuf;

use clap::{Args, CommandFactory as _, Parser, Subcommand};
use serde::Serialize;

pub use scenes::{HairArgs, PendulumArgs, PendulumStart, RopeArgs, RopeBody, StepFlags};
pub use vector::{Magnitude, Vector};

use crate::integrate::Method;
use crate::scene::hair::run::HairConfig;
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;

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
    /// Re-run what a recording holds from its embedded configuration and compare every series
    /// and 3D state with it (exit 0 identical, 1 different, 2 bad input)
    Reproduce(ReproduceArgs),
    /// Compare two recordings entity by entity: configurations key by key, then every series
    Diff(DiffArgs),
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
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub plot_every: Option<u64>,

    /// Methods, comma-separated (overrides the scene file); each scene runs those it supports
    /// (`physlab methods` lists the registry's and hair's), and every scene must be left one
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<String>>,
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
    /// Worker threads for the strands, at most 4 × the cores [default: all cores]; results do
    /// not depend on it
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub threads: Option<usize>,
}

#[derive(Args, Debug, Clone)]
pub struct InspectArgs {
    /// The recording to describe
    pub file: PathBuf,
    /// Write the recording's embedded scene file here, to run the same thing again with --config
    /// (`-` for standard output; the description then goes to stderr)
    #[arg(long, value_name = "FILE.toml")]
    pub config_out: Option<PathBuf>,
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
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyKind {
    /// Error against dt, fitted order per method
    Convergence,
    /// Error against median wall time and against force evaluations; cheapest method per target
    WorkPrecision,
    /// Largest stable dt per method by bisection, against theory
    Stability,
    /// Hair: largest stretch against wall time per frame over solvers, Newton steps, sweeps,
    /// substeps and spring stiffness (200 strands; --duration, default 4 s); cheapest per target
    Hair,
    /// Energy and phase error against time over many periods (pendulum; the rope: energy),
    /// growth exponents fitted against theory (symplectic or not)
    Drift,
}

impl StudyKind {
    /// What the kind measures and prints, for its own `--help` page.
    pub fn measures(self) -> &'static str {
        match self {
            StudyKind::Convergence => {
                "Runs each method at --levels step sizes, from --dt halving each time (the \
                 adaptive methods over --rtol instead), against the scene's reference (the exact \
                 elliptic pendulum, or a converged fine-step rope), and fits each method's order \
                 from the slope of its error above the reference's floor. Prints the runs and the \
                 fitted orders; with -o, --csv or --plots also draws error against dt, log-log."
            }
            StudyKind::WorkPrecision => {
                "Runs each method over the same step sizes (the adaptive ones over --rtol), \
                 --repeats times each, and sets the error against the median wall time and \
                 against force evaluations. Prints the runs, how the adaptive methods' error \
                 follows rtol, and the cheapest run reaching each target error; with -o, --csv or \
                 --plots also draws error against cost, log-log."
            }
            StudyKind::Stability => {
                "Finds each method's largest stable step by bisection on the linearised problem \
                 (the pendulum at θ0 = 1e-12 rad from rest, or the undamped rope), each trial \
                 stepping --steps steps, and sets it against the theory's limit on ω·dt \
                 (`physlab methods`). Prints measured against theory; with -o, --csv or --plots \
                 also draws the limits."
            }
            StudyKind::Hair => {
                "Runs the hair scene (200 strands, --duration of simulated time) over its solvers, \
                 Newton steps, Gauss–Seidel sweeps, substeps and spring stiffness, and sets the \
                 largest stretch against the wall time per frame. Prints every setting and the \
                 cheapest reaching each stretch target; with -o, --csv or --plots also draws \
                 stretch against cost, log-log. Takes minutes: a progress bar shows its ETA."
            }
            StudyKind::Drift => {
                "Runs each method on the pendulum released from rest at --theta0 at step --dt \
                 for --duration (default 10⁵ periods at dt = 0.01 s; the fixed-step methods \
                 unless --methods names others), every step checked: the energy error of each \
                 step and the time of every upward crossing of θ = 0 against the closed form's. \
                 Fits how both grow with time over the run's last two decades and sets the \
                 exponents against theory (symplectic: energy bounded, phase ∝ t; others: energy \
                 ∝ t, phase ∝ t²). With --scene rope: the undamped study rope's energy error over \
                 10⁴ s at dt = 1 ms, and its shortest spring (no phase: no closed form). Prints \
                 the exponents; with -o, --csv or --plots also draws the errors against time, \
                 log-log."
            }
        }
    }
}

/// Which study kinds use each flag that only some kinds use (`-o`, `--csv` and `-q` serve
/// every kind): the refusals of the flags a kind does not use and each kind's help page read it.
pub const STUDY_FLAG_KINDS: [(&str, &[StudyKind]); 17] = {
    use StudyKind::{Convergence as C, Drift as D, Hair as H, Stability as S, WorkPrecision as W};
    const SWEEP: &[StudyKind] = &[C, W];
    const MEASURED: &[StudyKind] = &[C, W, S, D];
    [
        ("--scene", MEASURED),
        ("--config", MEASURED),
        ("--theta0", &[C, W, D]),
        ("--omega0", SWEEP),
        ("--nodes", MEASURED),
        ("--mass", MEASURED),
        ("--stiffness", MEASURED),
        ("--spring-damping", SWEEP),
        ("--air-drag", SWEEP),
        ("--duration", &[C, W, H, D]),
        ("--dt", &[C, W, D]),
        ("--levels", SWEEP),
        ("--methods", MEASURED),
        ("--rtol", &[C, W, D]),
        ("--repeats", SWEEP),
        ("--steps", &[S]),
        ("--plots", &[C, W, S, H, D]),
    ]
};

/// `physlab study KIND --help`: the study's page with only the flags that kind uses, and what
/// it measures.
fn study_kind_help(kind: StudyKind) -> clap::Command {
    use clap::ValueEnum as _;
    let name = kind
        .to_possible_value()
        .map_or(String::new(), |v| v.get_name().to_string());
    let mut cmd = command()
        .find_subcommand("study")
        .cloned()
        .unwrap_or_else(|| clap::Command::new("study"));
    for (flag, kinds) in STUDY_FLAG_KINDS {
        if kinds.contains(&kind) {
            continue;
        }
        let id = cmd
            .get_arguments()
            .find(|a| a.get_long().is_some_and(|l| format!("--{l}") == flag))
            .map(|a| a.get_id().to_string());
        if let Some(id) = id {
            cmd = cmd.mut_arg(id, |a| a.hide(true));
        }
    }
    let short = kind
        .to_possible_value()
        .and_then(|v| v.get_help().map(|h| h.to_string()))
        .unwrap_or_default();
    if kind == StudyKind::Hair {
        // The hair study's own duration, not the measured scenes'.
        let duration = crate::study::hair::DEFAULT_DURATION;
        cmd = cmd.mut_arg("duration", |a| {
            a.help(format!(
                "Simulated time of each run [s] [default: {duration}]"
            ))
        });
    }
    cmd.mut_arg("kind", |a| a.hide(true))
        .override_usage(format!("physlab study {name} [OPTIONS]"))
        .about(short.clone())
        .long_about(format!("{short}\n\n{}", kind.measures()))
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

    /// The scene [default: pendulum] (not with `hair`, which has its own)
    #[arg(long, value_enum)]
    pub scene: Option<StudyScene>,

    /// Scene parameters from a scene file (its [pendulum] or [rope] table); flags override it
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,

    /// The pendulum's start (with --scene pendulum)
    #[command(flatten)]
    pub pendulum: PendulumStart,

    /// The rope's size and material (with --scene rope)
    #[command(flatten)]
    pub rope: RopeBody,

    /// Simulated time [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,

    /// Coarsest step; each level halves it [s]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub dt: Option<f64>,

    /// Number of step sizes
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub levels: Option<u32>,

    /// Methods, comma-separated (the names are listed from the registry by `command`)
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pub methods: Option<Vec<Method>>,

    /// Relative tolerances, comma-separated (convergence and work-precision, with an adaptive
    /// method among --methods)
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        allow_negative_numbers = true
    )]
    pub rtol: Option<Vec<f64>>,

    /// Timed repeats per run for convergence and work-precision (the median wall time is kept)
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub repeats: Option<u32>,

    /// Steps each stability trial must stay bounded for
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub steps: Option<u64>,

    /// Also write one row per run as CSV (`-` for standard output; the tables then go to stderr)
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,

    /// Also write the diagrams and tables as a Rerun recording (`-` for standard output)
    #[arg(short, long, value_name = "FILE.rrd")]
    pub output: Option<PathBuf>,

    /// Write the diagrams (SVG and PNG) into this folder [default: beside -o, else beside --csv;
    /// with neither, no diagram]
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,

    /// No progress bar or long-run notice (the study prints only its tables)
    #[arg(short, long)]
    pub quiet: bool,
}

/// The command line with every scene flag's default appended to its help, read from the scene's
/// `Default` (so a default is written once, in the scene).
pub fn command() -> clap::Command {
    Cli::command()
        .mut_subcommand("pendulum", |c| {
            with_defaults(with_method_names(c), &PendulumConfig::default())
        })
        .mut_subcommand("rope", |c| {
            with_defaults(with_method_names(c), &RopeConfig::default())
        })
        .mut_subcommand("hair", |c| {
            with_defaults(with_head_motions(c), &HairConfig::default())
        })
        .mut_subcommand("study", |c| {
            with_shown_defaults(with_method_names(c), &study_defaults())
        })
}

/// `--head-motion` help listing its values, read from the scene.
fn with_head_motions(cmd: clap::Command) -> clap::Command {
    let names: Vec<&str> = crate::scene::hair::HeadMotion::ALL
        .iter()
        .map(|(name, _)| *name)
        .collect();
    cmd.mut_arg("head_motion", |a| {
        let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
        a.help(format!("{help}: one of {}", names.join(", ")))
    })
}

/// The registry's adaptive methods, the ones `--rtol` drives.
fn adaptive_names() -> String {
    Method::ALL
        .iter()
        .filter(|m| {
            matches!(
                m.info().evals_per_step,
                crate::integrate::EvalsPerStep::Adaptive(_)
            )
        })
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// `--methods` help naming every registry method, and `--rtol` help naming the adaptive ones
/// it drives, read from the registry.
fn with_method_names(cmd: clap::Command) -> clap::Command {
    let names = Method::names().collect::<Vec<_>>().join(", ");
    let adaptive = adaptive_names();
    cmd.mut_arg("methods", |a| {
        a.help(format!(
            "Methods to run, comma-separated, any of: {names} (`physlab methods` describes them)"
        ))
    })
    .mut_arg("rtol", |a| {
        let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
        a.help(format!(
            "{help}; it drives the adaptive methods: {adaptive}"
        ))
    })
}

/// Parses the process's arguments (clap prints usage errors and exits with code 2).
pub fn parse() -> Cli {
    use clap::FromArgMatches as _;
    let args = join_negative_values(std::env::args_os());
    if let Some((kind, long)) = study_help_asked(&args) {
        let mut help = study_kind_help(kind);
        let shown = if long {
            help.print_long_help()
        } else {
            help.print_help()
        };
        std::process::exit(if shown.is_ok() { 0 } else { 1 });
    }
    let matches = command().try_get_matches_from(args).unwrap_or_else(|e| {
        if let Some(message) = negative_count(&e) {
            eprintln!("error: {message}");
            std::process::exit(2);
        }
        e.exit()
    });
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

/// `physlab study KIND ... -h|--help`: the kind, and whether the long help (`--help`) is asked.
fn study_help_asked(args: &[std::ffi::OsString]) -> Option<(StudyKind, bool)> {
    use clap::ValueEnum as _;
    let words: Vec<&str> = args.iter().skip(1).filter_map(|a| a.to_str()).collect();
    let [command, kind, rest @ ..] = &words[..] else {
        return None;
    };
    let kind = (*command == "study").then(|| StudyKind::from_str(kind, false).ok())??;
    let before_dashes = rest.iter().take_while(|w| **w != "--");
    let mut asked = None;
    for w in before_dashes {
        match *w {
            "--help" => asked = Some(true),
            "-h" => asked = asked.or(Some(false)),
            _ => {}
        }
    }
    asked.map(|long| (kind, long))
}

/// A negative number given to a count or an index (`--pinned -1`), which clap reports only as
/// "invalid digit found in string": said as what is wrong, with the flag and the value.
fn negative_count(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    if e.kind() != clap::error::ErrorKind::ValueValidation {
        return None;
    }
    let (Some(ContextValue::String(arg)), Some(ContextValue::String(value))) = (
        e.get(ContextKind::InvalidArg),
        e.get(ContextKind::InvalidValue),
    ) else {
        return None;
    };
    let negative = value.starts_with('-') && value[1..].parse::<u128>().is_ok();
    let flag = arg.split_whitespace().next().unwrap_or(arg);
    negative.then(|| format!("{flag} {value}: must be a whole number ≥ 0"))
}

/// `--flag -1e-3` as `--flag=-1e-3`: a long option followed by a negative number (or a
/// comma-separated list of numbers, `--wind -1,0,0`) takes it as its value. clap reads a
/// leading `-` as a flag unless the value looks like a plain number, and `1e-3` does not to
/// it; `allow_hyphen_values` would also swallow a real flag (`--dt -o x`). Only tokens that
/// parse as numbers are joined, so every flag is still a flag.
pub fn join_negative_values(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let numeric = |s: &str| {
        s.starts_with('-')
            && s.len() > 1
            && s.split(',').all(|part| {
                let t = part.trim();
                !t.is_empty() && t.parse::<f64>().is_ok_and(f64::is_finite) && !t.starts_with("--")
            })
    };
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    let mut args = args.into_iter().peekable();
    while let Some(arg) = args.next() {
        let long_without_value = arg
            .to_str()
            .is_some_and(|a| a.starts_with("--") && a.len() > 2 && !a.contains('='));
        if long_without_value
            && let Some(next) = args.peek().and_then(|n| n.to_str())
            && numeric(next)
        {
            let mut joined = arg.clone();
            joined.push("=");
            joined.push(next);
            out.push(joined);
            args.next();
        } else {
            out.push(arg);
        }
    }
    out
}

/// The study's defaults as its help shows them, read from the scenes and the study.
fn study_defaults() -> Vec<(String, String)> {
    use crate::study::{self, Problem};
    let pendulum = Problem::Pendulum(Default::default());
    let rope = Problem::Rope(study::study_rope(false));
    let (p, r) = (
        study::default_schedule(&pendulum),
        study::default_schedule(&rope),
    );
    let pendulum_file = toml::Value::try_from(PendulumConfig::default()).ok();
    let rope_file = toml::Value::try_from(RopeConfig::default()).ok();
    let value = |file: &Option<toml::Value>, key: &str| {
        file.as_ref()
            .and_then(|f| f.get(key))
            .map_or(String::new(), show)
    };
    let stability_stiffness = study::study_rope(true).stiffness;
    vec![
        ("theta0".into(), value(&pendulum_file, "theta0")),
        ("omega0".into(), value(&pendulum_file, "omega0")),
        ("nodes".into(), value(&rope_file, "nodes")),
        ("mass".into(), value(&rope_file, "mass")),
        (
            "stiffness".into(),
            format!(
                "{} for convergence and work-precision, the scene's {stability_stiffness} for stability",
                study::STUDY_ROPE_STIFFNESS
            ),
        ),
        (
            "spring_damping".into(),
            "0, so that the theory's orders apply; the rope's convergence study also shows the scene's damping"
                .into(),
        ),
        ("air_drag".into(), "0".into()),
        ("dt".into(), format!("{} pendulum, {} rope", p.0, r.0)),
        ("duration".into(), format!("{} pendulum, {} rope", p.1, r.1)),
        ("levels".into(), study::DEFAULT_LEVELS.to_string()),
        ("methods".into(), "all of `physlab methods`".into()),
        (
            "rtol".into(),
            show(&toml::Value::Array(
                study::default_rtols()
                    .into_iter()
                    .map(toml::Value::Float)
                    .collect(),
            )),
        ),
        ("repeats".into(), study::DEFAULT_REPEATS.to_string()),
        ("steps".into(), study::DEFAULT_STABILITY_STEPS.to_string()),
    ]
}

/// Appends ` [default: VALUE]` to the help of every flag whose name is a key of `defaults`.
fn with_defaults<T: Serialize>(cmd: clap::Command, defaults: &T) -> clap::Command {
    let Ok(toml::Value::Table(table)) = toml::Value::try_from(defaults) else {
        return cmd;
    };
    let shown: Vec<(String, String)> = table.iter().map(|(k, v)| (k.clone(), show(v))).collect();
    with_shown_defaults(cmd, &shown)
}

/// Appends ` [default: VALUE]` to the help of each named flag.
fn with_shown_defaults(mut cmd: clap::Command, defaults: &[(String, String)]) -> clap::Command {
    for (key, value) in defaults {
        if !cmd.get_arguments().any(|a| a.get_id() == key.as_str()) {
            continue;
        }
        let shown = format!("[default: {value}]");
        cmd = cmd.mut_arg(key.as_str(), |a| {
            let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
            let long = a.get_long_help().map(|h| h.to_string());
            let a = a.help(format!("{help} {shown}"));
            match long {
                Some(long) => a.long_help(format!("{long} {shown}")),
                None => a,
            }
        });
    }
    cmd
}

/// A default as it is typed on the command line: 0.01, 0,-9.81,0, rk4,verlet.
fn show(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => s.clone(),
        toml::Value::Float(x) if *x != 0.0 && x.abs() < 1e-3 => format!("{x:e}"),
        toml::Value::Float(x) => format!("{x}"),
        toml::Value::Integer(n) => n.to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Array(items) => items.iter().map(show).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::join_negative_values;

    fn joined(args: &[&str]) -> Vec<String> {
        join_negative_values(args.iter().map(|a| a.into()))
            .into_iter()
            .map(|a| a.into_string().unwrap())
            .collect()
    }

    #[test]
    fn negative_numbers_after_a_long_option_are_its_value_and_flags_stay_flags() {
        assert_eq!(
            joined(&["p", "pendulum", "--theta0", "-1e-3", "--omega0", "-2.5E+1"]),
            ["p", "pendulum", "--theta0=-1e-3", "--omega0=-2.5E+1"]
        );
        assert_eq!(
            joined(&["p", "hair", "--wind", "-1,0,-3e2", "-q"]),
            ["p", "hair", "--wind=-1,0,-3e2", "-q"]
        );
        // Not numbers: left for clap (a missing value, a flag, stdout, a negative infinity).
        for args in [
            &["p", "pendulum", "--dt", "-o", "x"][..],
            &["p", "pendulum", "-o", "-"],
            &["p", "pendulum", "--dt", "--", "-1"],
            &["p", "pendulum", "--dt", "-inf"],
            &["p", "pendulum", "--dt=-1", "-1"],
        ] {
            assert_eq!(joined(args), args);
        }
    }
}
