//! The commands: resolve and validate options into plain configs, run, record, report.

use std::fmt;

use crate::cli::{Cli, Command, PendulumArgs};
use crate::method::{Method, MethodOptions, methods_table};
use crate::record::{FileRecording, send_provenance};
use crate::scene::pendulum::PendulumParams;
use crate::scene::pendulum::run::{PendulumConfig, run as run_pendulum};
use crate::scene::pendulum::summary::summary_text;

/// Runs longer than this many steps per method are refused: a typo in --dt should not
/// start an hours-long run.
pub const MAX_STEPS: f64 = 1e9;

/// Bad input: the option, the value and what is allowed. Exit code 2.
#[derive(Debug, Clone, PartialEq)]
pub struct UsageError(pub String);

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Methods => {
            print!("{}", methods_table());
            Ok(())
        }
        Command::Pendulum(args) => pendulum(&args),
    }
}

fn pendulum(args: &PendulumArgs) -> anyhow::Result<()> {
    let config = pendulum_config(args)?;
    let recording = FileRecording::create(
        &args.output,
        "pendulum",
        crate::record::pendulum::blueprint(),
    )?;
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(
        recording.stream(),
        "pendulum",
        &pendulum_config_toml(&config, args),
        &methods,
    )?;
    let mut recorder = crate::record::pendulum::PendulumRecorder::new(recording.stream().clone());
    let summary = run_pendulum(&config, &mut recorder)?;
    drop(recorder);
    let bytes = recording.commit()?;
    print!("{}", summary_text(&summary));
    println!(
        "\nrecording: {} ({:.2} MB)",
        args.output.display(),
        bytes as f64 / 1e6
    );
    Ok(())
}

/// Turns the pendulum flags into a validated config.
pub fn pendulum_config(args: &PendulumArgs) -> Result<PendulumConfig, UsageError> {
    positive("--gravity", args.gravity, "m/s²")?;
    positive("--length", args.length, "m")?;
    finite("--theta0", args.theta0, "degrees")?;
    finite("--omega0", args.omega0, "rad/s")?;
    positive("--dt", args.dt, "s")?;
    positive("--duration", args.duration, "s")?;
    positive("--fps", args.fps, "Hz")?;
    if args.dt > args.duration {
        return Err(UsageError(format!(
            "--dt {}: must not exceed --duration {} s",
            args.dt, args.duration
        )));
    }
    let steps = args.duration / args.dt;
    if steps > MAX_STEPS {
        return Err(UsageError(format!(
            "--dt {} with --duration {} is {steps:.2e} steps per method; at most {MAX_STEPS:.0e} are allowed \
             (raise --dt or shorten --duration)",
            args.dt, args.duration
        )));
    }
    let d = args.verlet_damping;
    if !(d.is_finite() && (0.0..1.0).contains(&d)) {
        return Err(UsageError(format!(
            "--verlet-damping {d}: must be in [0, 1)"
        )));
    }
    let mut methods: Vec<Method> = Vec::new();
    for &m in &args.methods {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    if methods.is_empty() {
        methods = Method::ALL.to_vec();
    }
    Ok(PendulumConfig {
        params: PendulumParams {
            gravity: args.gravity,
            length: args.length,
            theta0: args.theta0.to_radians(),
            omega0: args.omega0,
        },
        dt: args.dt,
        duration: args.duration,
        fps: args.fps,
        methods,
        options: MethodOptions { verlet_damping: d },
    })
}

/// The resolved configuration as TOML text, for the recording's provenance.
fn pendulum_config_toml(c: &PendulumConfig, args: &PendulumArgs) -> String {
    let methods: Vec<String> = c.methods.iter().map(|m| format!("\"{m}\"")).collect();
    format!(
        "[pendulum]\ngravity = {:?}\nlength = {:?}\ntheta0 = {:?}\nomega0 = {:?}\ndt = {:?}\nduration = {:?}\n\
         fps = {:?}\nmethods = [{}]\nverlet_damping = {:?}\noutput = {:?}\n",
        c.params.gravity,
        c.params.length,
        args.theta0,
        c.params.omega0,
        c.dt,
        c.duration,
        c.fps,
        methods.join(", "),
        c.options.verlet_damping,
        args.output.display().to_string(),
    )
}

fn finite(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number [{unit}]"
        )))
    }
}

fn positive(option: &str, value: f64, unit: &str) -> Result<(), UsageError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(UsageError(format!(
            "{option} {value}: must be a finite number > 0 [{unit}]"
        )))
    }
}
