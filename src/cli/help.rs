//! The help texts' defaults and value lists, read from the scenes' `Default`, the study and
//! the registry, so that none is typed in a flag's doc.

use clap::CommandFactory as _;
use serde::Serialize;

use super::Cli;
use crate::integrate::Method;
use crate::scene::hair::run::HairConfig;
use crate::scene::pendulum::run::PendulumConfig;
use crate::scene::rope::run::RopeConfig;

/// The command line with every scene flag's default appended to its help, read from the scene's
/// `Default` (so a default is written once, in the scene), and every study kind's from the study;
/// its help wrapped to the terminal's width, at most 100 columns (100 when not a terminal).
pub fn command() -> clap::Command {
    let cli = Cli::command()
        // The width the rest of physlab's output keeps (report::table::WIDTH).
        .max_term_width(100)
        .mut_subcommand("pendulum", |c| {
            with_defaults(with_method_names(c), &PendulumConfig::default())
        })
        .mut_subcommand("rope", |c| {
            with_defaults(with_method_names(c), &RopeConfig::default())
        })
        .mut_subcommand("hair", |c| {
            // `--head-motion` help listing its values, read from the scene.
            let motions = crate::scene::hair::HeadMotion::ALL.map(|(name, _)| name);
            let c = rewritten(c, "head_motion", |h| {
                format!("{h}: one of {}", motions.join(", "))
            });
            with_defaults(c, &HairConfig::default())
        });
    cli.mut_subcommand("study", |mut study| {
        for (kind, defaults) in study_defaults() {
            study = study.mut_subcommand(kind, |c| {
                with_shown_defaults(with_method_names(c), &defaults)
            });
        }
        study
    })
}

/// Each study kind's defaults as its help shows them, read from the scenes and the study.
fn study_defaults() -> [(&'static str, Vec<(&'static str, String)>); 5] {
    use crate::study::{self, Problem, drift};
    use std::fmt::Display;
    let p = study::default_schedule(&Problem::Pendulum(Default::default()));
    let r = study::default_schedule(&Problem::Rope(study::study_rope(false)));
    let both = |p: &dyn Display, r: &dyn Display| format!("{p} pendulum, {r} rope");
    let files = [
        toml::Value::try_from(PendulumConfig::default()),
        toml::Value::try_from(RopeConfig::default()),
    ];
    let scene = |key| {
        let value = files.iter().flatten().find_map(|f| f.get(key));
        (key, value.map_or(String::new(), show))
    };
    let body = |ks: f64| vec![scene("nodes"), scene("mass"), ("stiffness", ks.to_string())];
    let all = || ("methods", "all of `physlab methods`".to_string());
    let rtols = study::default_rtols().into_iter().map(toml::Value::Float);
    let damping = "0, so that the theory's orders apply; the rope's convergence study also shows \
                   the scene's damping";
    let sweep = [
        body(study::STUDY_ROPE_STIFFNESS),
        vec![
            scene("theta0"),
            scene("omega0"),
            ("spring_damping", damping.into()),
            ("air_drag", "0".into()),
            ("dt", both(&p.0, &r.0)),
            ("duration", both(&p.1, &r.1)),
            ("levels", study::DEFAULT_LEVELS.to_string()),
            all(),
            ("rtol", show(&toml::Value::Array(rtols.collect()))),
            ("repeats", study::DEFAULT_REPEATS.to_string()),
        ],
    ];
    let steps = ("steps", study::DEFAULT_STABILITY_STEPS.to_string());
    let stability = [body(study::study_rope(true).stiffness), vec![all(), steps]];
    // The pendulum's; a damped rope leaves out the methods its forces refuse.
    let pendulum = study::Problem::Pendulum(Default::default());
    let fixed: Vec<&str> = (drift::default_methods(&pendulum).iter())
        .map(|m| m.name())
        .collect();
    let periods = format!("{:e} periods", drift::DEFAULT_PERIODS);
    let rtol = toml::Value::Float(crate::integrate::MethodOptions::default().rtol);
    let long = [
        body(study::STUDY_ROPE_STIFFNESS),
        vec![
            scene("theta0"),
            ("dt", both(&drift::DEFAULT_DT, &drift::ROPE_DT)),
            ("duration", both(&periods, &drift::ROPE_DURATION)),
            ("methods", fixed.join(", ")),
            ("rtol", show(&rtol)),
        ],
    ];
    let hair = vec![("duration", study::hair::DEFAULT_DURATION.to_string())];
    let every = |s: &(f64, f64)| study::SAMPLE_EVERY as f64 * s.0;
    let targets = study::DEFAULT_TARGETS.map(|t| format!("{t:e}")).join(",");
    let wp_rtols = study::work_precision_rtols()
        .into_iter()
        .map(toml::Value::Float);
    let answer = vec![
        ("rtol", show(&toml::Value::Array(wp_rtols.collect()))),
        ("target", targets),
        ("sample_every", both(&every(&p), &every(&r))),
    ];
    [
        ("convergence", sweep.concat()),
        (
            "work-precision",
            (sweep.concat().into_iter())
                .filter(|d| d.0 != "rtol")
                .chain(answer)
                .collect(),
        ),
        ("stability", stability.concat()),
        ("hair", hair),
        ("drift", long.concat()),
    ]
}

/// An unknown flag that a sibling subcommand takes (`study drift --omega0`), said with the
/// subcommands that take it.
pub(super) fn with_takers(
    mut e: clap::Error,
    command: &clap::Command,
    args: &[std::ffi::OsString],
) -> clap::Error {
    use clap::error::{ContextKind, ContextValue};
    let parent = args
        .get(1)
        .and_then(|a| command.find_subcommand(a.to_str()?));
    let (clap::error::ErrorKind::UnknownArgument, Some(ContextValue::String(arg)), Some(parent)) =
        (e.kind(), e.get(ContextKind::InvalidArg), parent)
    else {
        return e;
    };
    let flag = arg.split('=').next().unwrap_or(arg).to_string();
    let takes = |c: &&clap::Command| {
        (c.get_arguments()).any(|a| a.get_long().is_some_and(|l| format!("--{l}") == flag))
    };
    let takers: Vec<String> = (parent.get_subcommands().filter(takes))
        .map(|c| format!("`{} {}`", parent.get_name(), c.get_name()))
        .collect();
    if !takers.is_empty() {
        let tip = format!("{flag} is a flag of {} only", takers.join(", "));
        e.insert(
            ContextKind::Suggested,
            ContextValue::StyledStrs(vec![tip.into()]),
        );
    }
    e
}

/// `--methods` help naming every registry method, and `--rtol` help naming the adaptive ones
/// it drives, read from the registry.
fn with_method_names(cmd: clap::Command) -> clap::Command {
    let names = Method::names().collect::<Vec<_>>().join(", ");
    let adaptive = (Method::ALL.iter().filter(|m| m.info().adaptive()))
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(", ");
    let cmd = rewritten(cmd, "methods", |_| {
        format!(
            "Methods to run, comma-separated, any of: {names} (`physlab methods` describes them)"
        )
    });
    rewritten(cmd, "rtol", |help| {
        format!("{help}; it drives the adaptive methods: {adaptive}")
    })
}

/// `cmd` with the short help of its argument `id` (if it has one) rewritten by `help`, and the
/// long help, if any, with what `help` appends.
fn rewritten(cmd: clap::Command, id: &str, help: impl Fn(&str) -> String) -> clap::Command {
    if !cmd.get_arguments().any(|a| a.get_id() == id) {
        return cmd;
    }
    cmd.mut_arg(id, |a| {
        let short = a.get_help().map(|h| h.to_string()).unwrap_or_default();
        let long = a.get_long_help().map(|h| h.to_string());
        let a = a.help(help(&short));
        match long {
            Some(long) => a.long_help(help(&long)),
            None => a,
        }
    })
}

/// Appends ` [default: VALUE]` to the help of every flag whose name is a key of `defaults`.
fn with_defaults<T: Serialize>(cmd: clap::Command, defaults: &T) -> clap::Command {
    let Ok(toml::Value::Table(table)) = toml::Value::try_from(defaults) else {
        return cmd;
    };
    let shown: Vec<(&str, String)> = table.iter().map(|(k, v)| (k.as_str(), show(v))).collect();
    with_shown_defaults(cmd, &shown)
}

/// Appends ` [default: VALUE]` to the help of each named flag.
fn with_shown_defaults(mut cmd: clap::Command, defaults: &[(&str, String)]) -> clap::Command {
    for (key, value) in defaults {
        cmd = rewritten(cmd, key, |help| format!("{help} [default: {value}]"));
    }
    cmd
}

/// A default as it is typed on the command line: 0.01, 0,-9.81,0, rk4,verlet; a list longer
/// than 30 characters with a space after each comma, so that the help can wrap it.
fn show(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => s.clone(),
        toml::Value::Float(x) if *x != 0.0 && x.abs() < 1e-3 => format!("{x:e}"),
        toml::Value::Float(x) => format!("{x}"),
        toml::Value::Integer(n) => n.to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Array(items) => {
            let items: Vec<String> = items.iter().map(show).collect();
            match items.join(",") {
                short if short.chars().count() <= 30 => short,
                _ => items.join(", "),
            }
        }
        other => other.to_string(),
    }
}
