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
            with_shown_defaults(with_method_names(c), &super::study::study_defaults())
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
pub(super) fn show(value: &toml::Value) -> String {
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
