//! `physlab study`'s flags, which kinds use each, and each kind's own `--help` page.

use std::path::PathBuf;

use clap::Args;

use super::{PendulumStart, RopeBody};
use crate::integrate::Method;
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;

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
    /// The kind as `physlab study KIND` spells it.
    pub fn name(self) -> String {
        use clap::ValueEnum as _;
        self.to_possible_value()
            .map_or(String::new(), |v| v.get_name().to_string())
    }

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
        ("--spring-damping", &[C, W, D]),
        ("--air-drag", &[C, W, D]),
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

/// `physlab study KIND --help`: the study's page with only the flags that kind uses, and what
/// it measures.
pub(super) fn study_kind_help(kind: StudyKind) -> clap::Command {
    use clap::ValueEnum as _;
    let name = kind.name();
    let mut cmd = super::command()
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

/// `physlab study KIND ... -h|--help`: the kind, and whether the long help (`--help`) is asked.
pub(super) fn study_help_asked(args: &[std::ffi::OsString]) -> Option<(StudyKind, bool)> {
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

/// The study's defaults as its help shows them, read from the scenes and the study.
pub(super) fn study_defaults() -> Vec<(String, String)> {
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
            .map_or(String::new(), super::help::show)
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
            super::help::show(&toml::Value::Array(
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
