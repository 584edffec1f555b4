//! The commands: resolve options into plain configs, run, record, report. Only the summaries go to
//! stdout; the progress bar goes to stderr.

mod resolve;
mod study;

use std::fmt;
use std::path::PathBuf;
use std::time::Instant;

pub use resolve::{
    MAX_HAIR_WORK, MAX_NODE_STEPS, MAX_NODES, MAX_STEPS, hair_config, hair_defaults,
    hair_effective, pendulum_config, pendulum_defaults, pendulum_effective, rope_config,
    rope_defaults, rope_effective,
};

use crate::cli::{AllArgs, Cli, Command, HairCommand, PendulumCommand, RopeCommand, RunArgs};
use crate::config::SceneFile;
use crate::method::methods_table;
use crate::progress::{Progress, WithProgress};
use crate::record::{Destinations, Recording, send_provenance};
use crate::scene::hair::run::{HairConfig, HairSummary, NoHairObserver};
use crate::scene::pendulum::run::{PendulumConfig, RunSummary};
use crate::scene::rope::run::{RopeConfig, RopeSummary};

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
        Command::Inspect(args) => crate::record::inspect::inspect_command(&args),
        Command::Pendulum(c) => pendulum(&c),
        Command::Rope(c) => rope(&c),
        Command::Hair(c) => hair(&c),
        Command::All(c) => all(&c),
        Command::Study(a) => study::study(&a),
    }
}

/// A run in which a method diverged, with --fail-on-divergence. Exit code 3.
#[derive(Debug)]
pub struct Diverged(pub String);

impl fmt::Display for Diverged {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Diverged {}

/// After a run: finalise the recording, print the summaries, then report an interruption
/// (exit 130) or, with --fail-on-divergence, a divergence (exit 3).
fn finish(
    recording: Option<Recording>,
    d: &Destinations,
    started: Instant,
    summaries: &[String],
    diverged: &[String],
    run: &RunArgs,
) -> anyhow::Result<()> {
    let bytes = match recording {
        Some(r) => Some(r.commit()?),
        None => None,
    };
    print!("{}", summaries.join("\n"));
    if let Some(bytes) = bytes {
        report_recording(d, bytes, started);
    }
    if crate::interrupt::requested() {
        let kept = match &d.file {
            Some(path) if bytes.is_some() => format!(
                "; the recording of everything so far is finalised in {}",
                path.display()
            ),
            _ => String::new(),
        };
        return Err(crate::interrupt::Interrupted(format!("interrupted{kept}")).into());
    }
    if run.fail_on_divergence && !diverged.is_empty() {
        return Err(Diverged(format!(
            "--fail-on-divergence: {} diverged",
            diverged.join(", ")
        ))
        .into());
    }
    Ok(())
}

/// The scene file named by --config, or an empty one.
fn scene_file(run: &RunArgs) -> Result<SceneFile, UsageError> {
    match &run.config {
        Some(path) => SceneFile::load(path),
        None => Ok(SceneFile::default()),
    }
}

fn destinations(run: &RunArgs, scene: &str) -> Destinations {
    Destinations {
        file: (!run.no_save).then(|| {
            run.output
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("recordings/{scene}.rrd")))
        }),
        connect: run.connect.clone(),
        spawn: run.spawn,
    }
}

fn report_recording(d: &Destinations, bytes: Option<u64>, started: Instant) {
    match (&d.file, bytes) {
        (Some(path), Some(bytes)) => println!(
            "\nrecording: {} ({:.2} MB), {:.1} s",
            path.display(),
            bytes as f64 / 1e6,
            started.elapsed().as_secs_f64()
        ),
        _ => println!(
            "\nstreamed, no file written, {:.1} s",
            started.elapsed().as_secs_f64()
        ),
    }
}

/// The scene-file text that reproduces a run: the effective parameters of each scene run.
fn config_text(
    pendulum: Option<&crate::cli::PendulumArgs>,
    rope: Option<&crate::cli::RopeArgs>,
    hair: Option<&crate::cli::HairArgs>,
) -> String {
    SceneFile {
        pendulum: pendulum.cloned(),
        rope: rope.cloned(),
        hair: hair.cloned(),
    }
    .to_toml()
}

fn pendulum(c: &PendulumCommand) -> anyhow::Result<()> {
    let file = scene_file(&c.run)?;
    let args = crate::config::layered(&[&file.pendulum.unwrap_or_default(), &c.scene]);
    let effective = pendulum_effective(&args);
    let config = pendulum_config(&args)?;
    let text = config_text(Some(&effective), None, None);
    if c.run.print_config {
        print!("{text}");
        return Ok(());
    }
    let started = Instant::now();
    let d = destinations(&c.run, "pendulum");
    let recording = Recording::create(&d, "pendulum", crate::record::pendulum::blueprint())?;
    let mut progress = Progress::new(c.run.quiet);
    let summary = record_pendulum(&recording, &config, &text, &mut progress)?;
    progress.finish();
    let diverged = pendulum_diverged(&summary);
    let text = crate::scene::pendulum::summary::summary_text(&summary);
    finish(Some(recording), &d, started, &[text], &diverged, &c.run)
}

fn pendulum_diverged(s: &RunSummary) -> Vec<String> {
    s.lanes
        .iter()
        .filter(|l| l.divergence.is_some())
        .map(|l| format!("pendulum/{}", l.name))
        .collect()
}

fn rope_diverged(s: &RopeSummary) -> Vec<String> {
    s.lanes
        .iter()
        .filter(|l| l.divergence.is_some())
        .map(|l| format!("rope/{}", l.method))
        .collect()
}

fn hair_diverged(s: &HairSummary) -> Vec<String> {
    s.lanes
        .iter()
        .filter(|l| l.divergence.is_some())
        .map(|l| format!("hair/{}", l.method.name()))
        .collect()
}

fn record_pendulum(
    recording: &Recording,
    config: &PendulumConfig,
    text: &str,
    progress: &mut Progress,
) -> anyhow::Result<RunSummary> {
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(recording.stream(), "pendulum", text, &methods)?;
    progress.stage("pendulum", config.schedule().total_steps as f64 * config.dt);
    let mut recorder = crate::record::pendulum::PendulumRecorder::new(recording.stream().clone());
    crate::scene::pendulum::run::run(
        config,
        &mut WithProgress {
            inner: &mut recorder,
            progress,
        },
    )
}

fn rope(c: &RopeCommand) -> anyhow::Result<()> {
    let file = scene_file(&c.run)?;
    let args = crate::config::layered(&[&file.rope.unwrap_or_default(), &c.scene]);
    let effective = rope_effective(&args);
    let config = rope_config(&args)?;
    let text = config_text(None, Some(&effective), None);
    if c.run.print_config {
        print!("{text}");
        return Ok(());
    }
    let started = Instant::now();
    let d = destinations(&c.run, "rope");
    let recording = Recording::create(&d, "rope", crate::record::rope::blueprint(c.run.timings))?;
    let mut progress = Progress::new(c.run.quiet);
    let summary = record_rope(&recording, &config, &text, c.run.timings, &mut progress)?;
    progress.finish();
    let diverged = rope_diverged(&summary);
    finish(
        Some(recording),
        &d,
        started,
        &[crate::scene::rope::summary::summary_text(&summary)],
        &diverged,
        &c.run,
    )
}

fn record_rope(
    recording: &Recording,
    config: &RopeConfig,
    text: &str,
    timings: bool,
    progress: &mut Progress,
) -> anyhow::Result<RopeSummary> {
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(recording.stream(), "rope", text, &methods)?;
    progress.stage("rope", config.schedule().total_steps as f64 * config.dt);
    let mut recorder =
        crate::record::rope::RopeRecorder::new(recording.stream().clone(), config.layout, timings);
    crate::scene::rope::run::run(
        config,
        &mut WithProgress {
            inner: &mut recorder,
            progress,
        },
    )
}

fn hair(c: &HairCommand) -> anyhow::Result<()> {
    let file = scene_file(&c.run)?;
    let args = crate::config::layered(&[&file.hair.unwrap_or_default(), &c.scene]);
    let effective = hair_effective(&args);
    let config = hair_config(&args)?;
    if c.threads == Some(0) {
        return Err(UsageError("--threads 0: must be at least 1".into()).into());
    }
    let text = config_text(None, None, Some(&effective));
    if c.run.print_config {
        print!("{text}");
        return Ok(());
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = c.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool.build()?;
    let started = Instant::now();
    let mut progress = Progress::new(c.run.quiet);
    if c.no_record {
        progress.stage("hair", config.duration);
        let summary = pool.install(|| {
            crate::scene::hair::run::run(
                &config,
                &mut WithProgress {
                    inner: &mut NoHairObserver,
                    progress: &mut progress,
                },
            )
        })?;
        progress.finish();
        let text = format!(
            "{}\nno recording (--no-record), {:.1} s\n",
            crate::scene::hair::summary::summary_text(&summary),
            started.elapsed().as_secs_f64()
        );
        let none = Destinations::default();
        return finish(
            None,
            &none,
            started,
            &[text],
            &hair_diverged(&summary),
            &c.run,
        );
    }
    let d = destinations(&c.run, "hair");
    let recording = Recording::create(&d, "hair", crate::record::hair::blueprint(c.run.timings))?;
    let summary =
        pool.install(|| record_hair(&recording, &config, &text, c.run.timings, &mut progress))?;
    progress.finish();
    let diverged = hair_diverged(&summary);
    let text = crate::scene::hair::summary::summary_text(&summary);
    finish(Some(recording), &d, started, &[text], &diverged, &c.run)
}

fn record_hair(
    recording: &Recording,
    config: &HairConfig,
    text: &str,
    timings: bool,
    progress: &mut Progress,
) -> anyhow::Result<HairSummary> {
    let methods: Vec<&str> = config.methods.iter().map(|m| m.name()).collect();
    send_provenance(recording.stream(), "hair", text, &methods)?;
    progress.stage("hair", config.duration);
    let mut recorder = crate::record::hair::HairRecorder::new(recording.stream().clone(), timings);
    crate::scene::hair::run::run(
        config,
        &mut WithProgress {
            inner: &mut recorder,
            progress,
        },
    )
}

/// `physlab all`: the three scenes, one after another, into one recording on one timeline.
fn all(c: &AllArgs) -> anyhow::Result<()> {
    let file = scene_file(&c.run)?;
    let (mut p_args, mut r_args, mut h_args) = (
        file.pendulum.clone().unwrap_or_default(),
        file.rope.clone().unwrap_or_default(),
        file.hair.clone().unwrap_or_default(),
    );
    // `all`'s own flags override every scene's table.
    if let Some(fps) = c.fps {
        (p_args.fps, r_args.fps, h_args.fps) = (Some(fps), Some(fps), Some(fps));
    }
    if let Some(n) = c.plot_every {
        (p_args.plot_every, r_args.plot_every) = (Some(n), Some(n));
    }
    let (p_eff, r_eff, h_eff) = (
        pendulum_effective(&p_args),
        rope_effective(&r_args),
        hair_effective(&h_args),
    );
    let (p_cfg, r_cfg, h_cfg) = (
        pendulum_config(&p_args)?,
        rope_config(&r_args)?,
        hair_config(&h_args)?,
    );
    let text = config_text(Some(&p_eff), Some(&r_eff), Some(&h_eff));
    if c.run.print_config {
        print!("{text}");
        return Ok(());
    }
    let started = Instant::now();
    let d = destinations(&c.run, "all");
    let recording = Recording::create(&d, "all", crate::record::all_blueprint(c.run.timings))?;
    let mut methods: Vec<&str> = p_cfg.methods.iter().map(|m| m.name()).collect();
    for m in h_cfg
        .methods
        .iter()
        .map(|m| m.name())
        .chain(r_cfg.methods.iter().map(|m| m.name()))
    {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    send_provenance(recording.stream(), "pendulum,rope,hair", &text, &methods)?;
    let mut progress = Progress::new(c.run.quiet);
    let rec = recording.stream().clone();

    let mut summaries = Vec::new();
    let mut diverged = Vec::new();
    // Scenes run one after another; after an interruption the remaining ones are skipped.
    progress.stage("pendulum", p_cfg.schedule().total_steps as f64 * p_cfg.dt);
    let mut pendulum = crate::record::pendulum::PendulumRecorder::new(rec.clone());
    let mut observer = WithProgress {
        inner: &mut pendulum,
        progress: &mut progress,
    };
    let p_sum = crate::scene::pendulum::run::run(&p_cfg, &mut observer)?;
    summaries.push(crate::scene::pendulum::summary::summary_text(&p_sum));
    diverged.extend(pendulum_diverged(&p_sum));
    if !crate::interrupt::requested() {
        progress.stage("rope", r_cfg.schedule().total_steps as f64 * r_cfg.dt);
        let mut rope =
            crate::record::rope::RopeRecorder::new(rec.clone(), r_cfg.layout, c.run.timings);
        let mut observer = WithProgress {
            inner: &mut rope,
            progress: &mut progress,
        };
        let r_sum = crate::scene::rope::run::run(&r_cfg, &mut observer)?;
        summaries.push(crate::scene::rope::summary::summary_text(&r_sum));
        diverged.extend(rope_diverged(&r_sum));
    }
    if !crate::interrupt::requested() {
        progress.stage("hair", h_cfg.duration);
        let mut hair = crate::record::hair::HairRecorder::new(rec.clone(), c.run.timings);
        let mut observer = WithProgress {
            inner: &mut hair,
            progress: &mut progress,
        };
        let h_sum = crate::scene::hair::run::run(&h_cfg, &mut observer)?;
        summaries.push(crate::scene::hair::summary::summary_text(&h_sum));
        diverged.extend(hair_diverged(&h_sum));
    }
    progress.finish();
    drop(rec);
    finish(Some(recording), &d, started, &summaries, &diverged, &c.run)
}
