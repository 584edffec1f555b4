//! The commands. Every simulating command goes through one pipeline ([`simulate`]): resolve the
//! scenes' parameters (defaults < preset < scene file < flags) into validated configs, open the
//! recording, run each scene through the harness with the recorder and the progress bar as its
//! observers, print the summaries, and finish (exit codes for interruption and divergence). A
//! single-scene command is `all` with one scene. Only the summaries go to stdout; the progress
//! bar goes to stderr.

mod file;
mod inspect;
mod progress;
mod reproduce;
mod study;

use std::fmt;
use std::path::PathBuf;
use std::time::Instant;

pub use crate::error::UsageError;
pub use file::SceneFile;
pub use reproduce::Differs;

use crate::cli::{AllArgs, Cli, Command, HairArgs, PendulumArgs, RopeArgs, RunArgs};
use crate::record::scene::{Draw, SceneRecorder};
use crate::record::{Destinations, Recording, SceneEnd, send_provenance};
use crate::scene::hair::HairMethod;
use crate::scene::hair::run::{HairConfig, HairScene};
use crate::scene::harness::{self, NoObserver, Observer, Run, Scene};
use crate::scene::pendulum::run::{PendulumConfig, PendulumScene};
use crate::scene::rope::run::{RopeConfig, RopeScene};
use crate::{record, report};
use progress::{Progress, WithProgress};

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Methods => {
            print!("{}", report::methods::methods_table());
            Ok(())
        }
        Command::Inspect(args) => inspect::inspect_command(&args),
        Command::Pendulum(c) => simulate(
            Plan {
                pendulum: Some(c.scene),
                ..Plan::default()
            },
            &c.run,
            &Output::Record,
            &Replay::default(),
        ),
        Command::Rope(c) => simulate(
            Plan {
                rope: Some(c.scene),
                ..Plan::default()
            },
            &c.run,
            &Output::Record,
            &Replay::default(),
        ),
        Command::Hair(c) => simulate(
            Plan {
                hair: Some(c.scene),
                ..Plan::default()
            },
            &c.run,
            &Output::Hair { threads: c.threads },
            &Replay::default(),
        ),
        Command::All(c) => simulate(all_plan(&c)?, &c.run, &Output::Record, &Replay::default()),
        Command::Reproduce(args) => reproduce::reproduce_command(&args),
        Command::Diff(args) => reproduce::diff_command(&args),
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

/// The scenes a command runs, each with its flags (not yet layered over file and defaults).
#[derive(Default)]
struct Plan {
    pendulum: Option<PendulumArgs>,
    rope: Option<RopeArgs>,
    hair: Option<HairArgs>,
}

/// `physlab all`: the three scenes; its own --fps, --plot-every and --methods override every
/// scene's. Each scene takes the listed methods it supports.
fn all_plan(c: &AllArgs) -> Result<Plan, UsageError> {
    let (registry, hair) = match &c.methods {
        Some(names) => {
            let (registry, hair) = split_methods(names)?;
            (Some(registry), Some(hair))
        }
        None => (None, None),
    };
    Ok(Plan {
        pendulum: Some(PendulumArgs {
            fps: c.fps,
            plot_every: c.plot_every,
            methods: registry.clone(),
            ..PendulumArgs::default()
        }),
        rope: Some(RopeArgs {
            fps: c.fps,
            plot_every: c.plot_every,
            methods: registry,
            ..RopeArgs::default()
        }),
        hair: Some(HairArgs {
            fps: c.fps,
            methods: hair,
            ..HairArgs::default()
        }),
    })
}

/// `all --methods`: the names the pendulum and rope take (the registry's) and those hair takes.
/// A name no scene knows, or a list that leaves a scene with none, is refused.
fn split_methods(
    names: &[String],
) -> Result<(Vec<crate::integrate::Method>, Vec<HairMethod>), UsageError> {
    use crate::integrate::Method;
    let list = names.join(",");
    let mut registry = Vec::new();
    let mut hair = Vec::new();
    for name in names {
        let r = name.parse::<Method>().ok();
        let h = name.parse::<HairMethod>().ok();
        if r.is_none() && h.is_none() {
            return Err(UsageError(format!(
                "--methods {list}: no scene has a method '{name}' (pendulum and rope: {}; hair: {})",
                Method::names().collect::<Vec<_>>().join(", "),
                hair_names()
            )));
        }
        registry.extend(r);
        hair.extend(h);
    }
    let none = |scene: &str, allowed: String| {
        UsageError(format!(
            "--methods {list}: leaves {scene} no method (allowed: {allowed})"
        ))
    };
    if registry.is_empty() {
        return Err(none(
            "the pendulum and the rope",
            Method::names().collect::<Vec<_>>().join(", "),
        ));
    }
    if hair.is_empty() {
        return Err(none("hair", hair_names()));
    }
    Ok((registry, hair))
}

fn hair_names() -> String {
    HairMethod::ALL
        .iter()
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// What happens to the run's output besides the summary.
enum Output {
    /// Record as the run options say.
    Record,
    /// Hair's worker threads (--log-strands is part of the scene: recorded, reproduced).
    Hair { threads: Option<usize> },
}

/// A re-run of a recording (`physlab reproduce`): where the recorded run stopped each scene.
#[derive(Default)]
struct Replay {
    /// Scenes that were interrupted, with the last tick they reached.
    stop_after: Vec<(String, u64)>,
    /// Scenes the recorded run never started.
    skip: Vec<String>,
    /// Print no summaries.
    silent: bool,
}

impl Replay {
    /// Whether `scene` runs, and (if so) sets where it stops.
    fn runs(&self, scene: &str) -> bool {
        let stop = self.stop_after.iter().find(|s| s.0 == scene).map(|s| s.1);
        crate::interrupt::set_stop_after(stop);
        !self.skip.iter().any(|s| s == scene)
    }
}

/// The plan's scenes, layered and validated, and the scene file that reproduces them.
struct Resolved {
    pendulum: Option<PendulumConfig>,
    rope: Option<RopeConfig>,
    hair: Option<HairConfig>,
    /// The effective parameters of every scene run, as a scene file.
    file: SceneFile,
}

/// Layers each planned scene's flags over the scene file over its defaults and validates it.
fn resolve(plan: Plan, run: &RunArgs) -> anyhow::Result<Resolved> {
    let file = match &run.config {
        Some(path) => SceneFile::load(path)?,
        None => SceneFile::default(),
    };
    let single = [
        plan.pendulum.is_some(),
        plan.rope.is_some(),
        plan.hair.is_some(),
    ]
    .iter()
    .filter(|&&p| p)
    .count()
        == 1;
    let table = |name: &str, given: bool| -> Result<(), UsageError> {
        let Some(path) = &run.config else {
            return Ok(());
        };
        if given {
            Ok(())
        } else if single {
            Err(UsageError(format!(
                "--config {}: has no [{name}] table, so nothing in it applies to this command",
                path.display()
            )))
        } else {
            eprintln!(
                "note: --config {}: no [{name}] table; {name} runs at its defaults",
                path.display()
            );
            Ok(())
        }
    };
    let mut effective = SceneFile::default();
    let mut resolved = Resolved {
        pendulum: None,
        rope: None,
        hair: None,
        file: SceneFile::default(),
    };
    if let Some(flags) = plan.pendulum {
        table("pendulum", file.pendulum.is_some())?;
        let from_file = file.pendulum.clone().unwrap_or_default();
        in_file(run, "pendulum", pendulum_config(&from_file))?;
        let args = flags.over(from_file);
        resolved.pendulum = Some(pendulum_config(&args)?);
        effective.pendulum = Some(args.over(PendulumArgs::defaults()));
    }
    if let Some(flags) = plan.rope {
        table("rope", file.rope.is_some())?;
        let from_file = file.rope.clone().unwrap_or_default();
        in_file(run, "rope", rope_config(&from_file))?;
        let args = flags.over(from_file);
        resolved.rope = Some(rope_config(&args)?);
        effective.rope = Some(args.effective());
    }
    if let Some(flags) = plan.hair {
        table("hair", file.hair.is_some())?;
        let from_file = file.hair.clone().unwrap_or_default();
        in_file(run, "hair", hair_config(&from_file))?;
        let args = flags.over(from_file);
        let config = hair_config(&args)?;
        // The file states the substeps --dt resolved to, so that it says one consistent thing.
        effective.hair = Some(HairArgs {
            substeps: Some(config.substeps),
            ..args.over(HairArgs::defaults())
        });
        resolved.hair = Some(config);
    }
    resolved.file = effective;
    Ok(resolved)
}

/// A scene file's values checked on their own, so that an error names the file, the table and
/// the key (`nodes = 1` in [rope]) rather than a flag the user never typed.
fn in_file<T>(
    run: &RunArgs,
    table: &str,
    checked: Result<T, UsageError>,
) -> Result<(), UsageError> {
    match (&run.config, checked) {
        (Some(path), Err(UsageError(message))) => {
            // Messages start with the flag and its value: "--nodes 1: must be ...".
            let (flag, rest) = message.split_once(' ').unwrap_or((&message, ""));
            let key = flag.trim_start_matches("--").replace('-', "_");
            Err(UsageError(format!(
                "--config {}: [{table}] {key} = {rest}",
                path.display()
            )))
        }
        _ => Ok(()),
    }
}

/// The pendulum's parameters (missing ones at their defaults), validated.
pub fn pendulum_config(args: &PendulumArgs) -> Result<PendulumConfig, UsageError> {
    let config = args.config();
    config.validate()?;
    Ok(config)
}

/// The rope's parameters (missing ones from the preset, if any, or the defaults), validated.
pub fn rope_config(args: &RopeArgs) -> Result<RopeConfig, UsageError> {
    let config = args.clone().effective().config();
    config.validate()?;
    Ok(config)
}

/// The hair's parameters (missing ones at their defaults), validated.
pub fn hair_config(args: &HairArgs) -> Result<HairConfig, UsageError> {
    let mut config = args.config();
    if let Some(dt) = args.dt {
        config.substeps = crate::scene::hair::run::substeps_for_dt(config.rate, dt, args.substeps)?;
    }
    config.validate()?;
    Ok(config)
}

/// The one pipeline of every simulating command.
fn simulate(plan: Plan, run: &RunArgs, output: &Output, replay: &Replay) -> anyhow::Result<()> {
    let resolved = resolve(plan, run)?;
    let text = resolved.file.to_toml()?;
    let no_record = run.no_record;
    let threads = match output {
        Output::Record => None,
        Output::Hair { threads } => *threads,
    };
    let log_strands = resolved.file.hair.as_ref().and_then(|h| h.log_strands);
    if let Some(n) = threads {
        crate::scene::params::threads(n)?;
    }
    if log_strands == Some(0) {
        return Err(UsageError(
            "--log-strands 0: must be at least 1 (--no-record draws nothing at all)".into(),
        )
        .into());
    }
    if no_record && log_strands.is_some() {
        return Err(
            UsageError("--no-record with --log-strands: --no-record draws nothing".into()).into(),
        );
    }
    refuse_contradictions(run, no_record)?;
    if run.print_config {
        print!("{text}");
        return Ok(());
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n);
    }
    let pool = pool.build()?;

    let scenes: Vec<&'static str> = [
        resolved.pendulum.as_ref().map(|_| "pendulum"),
        resolved.rope.as_ref().map(|_| "rope"),
        resolved.hair.as_ref().map(|_| "hair"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let name = if scenes.len() == 1 { scenes[0] } else { "all" };
    let started = Instant::now();
    let d = if no_record {
        Destinations::default()
    } else {
        destinations(run, name)
    };
    // The recording never replaces the scene file it was made from.
    if let (Some(out), Some(input)) = (d.written()?, &run.config) {
        crate::output::distinct(
            &[&out],
            &[("the scene file read (--config)", input.as_path())],
        )?;
    }
    let recording = if no_record {
        None
    } else {
        let framings = record::Framings {
            pendulum: resolved.pendulum.as_ref().map(record::pendulum::framing),
            rope: resolved.rope.as_ref().map(record::rope::framing),
            hair: resolved.hair.as_ref().map(record::hair::framing),
        };
        let one = (framings.pendulum.or(framings.rope)).or(framings.hair);
        let layout = match one {
            Some(framing) if scenes.len() == 1 => record::scene_layout(name, run.timings, framing),
            _ => record::all_layout(run.timings, &framings),
        };
        let application_id = match name {
            "pendulum" => "physlab-pendulum",
            "rope" => "physlab-rope",
            "hair" => "physlab-hair",
            _ => "physlab-all",
        };
        let recording = Recording::create(&d, application_id, name, layout)?;
        send_provenance(
            recording.stream(),
            &scenes.join(","),
            &text,
            &method_names(&resolved),
        )?;
        Some(recording)
    };
    let mut progress = Progress::new(run.quiet);
    let mut summaries = Vec::new();
    let mut diverged = Vec::new();
    let stream = recording.as_ref().map(|r| r.stream().clone());
    // One `frame` timeline for the whole recording: frame N at N / (the highest fps) s.
    let frame_rate = [
        resolved.pendulum.as_ref().map(|c| c.fps),
        resolved.rope.as_ref().map(|c| c.fps),
        resolved.hair.as_ref().map(|c| c.fps),
    ]
    .into_iter()
    .flatten()
    .fold(0.0, f64::max);
    // Scenes run one after another; after an interruption the remaining ones are skipped.
    let timings = run.timings;
    let mut ends: Vec<SceneEnd> = Vec::new();
    let mut collect = |ran: Ran| -> anyhow::Result<()> {
        if let Some(s) = &stream {
            record::log_summary(s, ran.end.scene, &ran.summary, &ran.end.text, timings)?;
        }
        summaries.push(ran.summary);
        diverged.extend(ran.diverged);
        ends.push(ran.end);
        Ok(())
    };
    if let Some(config) = resolved.pendulum
        && replay.runs("pendulum")
    {
        let reference_steps = config.reference_steps();
        if reference_steps > 3e7 && !run.quiet {
            // Allowed, but not instant: say what the time goes to (~0.1 µs per RK4 step).
            eprintln!(
                "pendulum: the fine-step reference takes {reference_steps:.1e} RK4 steps (about {:.0} s); Ctrl-C stops it",
                reference_steps * 1e-7
            );
        }
        let recorder = stream
            .clone()
            .map(|s| record::pendulum::recorder(s, timings).with_frame_rate(frame_rate));
        collect(run_scene(
            PendulumScene::new(config),
            recorder,
            report::pendulum::summary_text,
            &mut progress,
        )?)?;
    }
    if let Some(config) = resolved.rope
        && !crate::interrupt::requested()
        && replay.runs("rope")
    {
        let recorder = stream
            .clone()
            .map(|s| record::rope::recorder(s, timings).with_frame_rate(frame_rate));
        collect(run_scene(
            RopeScene::new(config),
            recorder,
            report::rope::summary_text,
            &mut progress,
        )?)?;
    }
    if let Some(config) = resolved.hair
        && !crate::interrupt::requested()
        && replay.runs("hair")
    {
        // Said before anything is written: how many strands are drawn, and the expected size.
        let plan = record::hair::strand_plan(&config, log_strands);
        if stream.is_some() && !run.quiet {
            eprintln!(
                "hair: drawing {} of {} strands in 3D; expected recording ≈ {:.0} MB",
                plan.drawn,
                plan.strands,
                plan.expected_bytes / 1e6
            );
        }
        let recorder = stream
            .clone()
            .map(|s| record::hair::recorder(s, timings, log_strands).with_frame_rate(frame_rate));
        // Hair spreads its strands over the pool (--threads); the results do not depend on it.
        let mut ran = pool.install(|| {
            run_scene(
                HairScene::new(config),
                recorder,
                report::hair::summary_text,
                &mut progress,
            )
        })?;
        if !no_record {
            ran.summary.push_str(&format!(
                "\n3D: {} of {} strands drawn per head (--log-strands); every strand is simulated and measured above\n",
                plan.drawn, plan.strands
            ));
        }
        let threads = pool.current_num_threads();
        collect(ran)?;
        // Printed, not recorded: the thread count is the machine's, and the results do not
        // depend on it, so a recording compares equal on any core count.
        if let Some(summary) = summaries.last_mut() {
            summary.push_str(&format!(
                "threads: {threads} (the results do not depend on it)\n"
            ));
        }
    }
    progress.finish();
    crate::interrupt::set_stop_after(None);
    if let Some(s) = &stream {
        // Scenes skipped after an interruption say so too.
        for scene in &scenes {
            if !ends.iter().any(|e| e.scene == *scene) {
                ends.push(SceneEnd {
                    scene,
                    status: "not run",
                    last_tick: 0,
                    end_time: 0.0,
                    text: "not run: the run was interrupted before this scene started".into(),
                });
            }
        }
        record::send_run_status(s, &ends)?;
    }
    drop(stream);
    if replay.silent {
        summaries.clear();
    }
    finish(recording, &d, started, &summaries, &diverged, run)
}

/// Output options that cannot hold together.
fn refuse_contradictions(run: &RunArgs, no_record: bool) -> Result<(), UsageError> {
    if run.no_save
        && let Some(path) = &run.output
    {
        return Err(UsageError(format!(
            "--no-save with -o {}: one says write no file, the other names it; drop one",
            path.display()
        )));
    }
    if run.no_save && run.connect.is_none() && !run.spawn {
        return Err(UsageError(
            "--no-save without --connect or --spawn: the run would go nowhere".into(),
        ));
    }
    if no_record {
        for (given, flag) in [
            (run.output.is_some(), "-o/--output"),
            (run.connect.is_some(), "--connect"),
            (run.spawn, "--spawn"),
            (run.no_save, "--no-save"),
            (run.timings, "--timings"),
        ] {
            if given {
                return Err(UsageError(format!(
                    "--no-record with {flag}: --no-record writes and streams nothing"
                )));
            }
        }
    }
    Ok(())
}

/// One scene's run: its summary, the lanes that diverged, where it ended.
struct Ran {
    summary: String,
    diverged: Vec<String>,
    end: SceneEnd,
}

/// Runs one scene through the harness (recording it when a recorder is given) and returns its
/// summary, the lanes that diverged and where it ended.
fn run_scene<S: Scene, D: Draw<S>>(
    mut scene: S,
    mut recorder: Option<SceneRecorder<D>>,
    summary: fn(&S, &Run<S::Lane>) -> String,
    progress: &mut Progress,
) -> anyhow::Result<Ran> {
    progress.stage(scene.name(), scene.schedule().end_time());
    let mut quiet = NoObserver;
    let inner: &mut dyn Observer<S> = match &mut recorder {
        Some(r) => r,
        None => &mut quiet,
    };
    let run = harness::run(&mut scene, &mut WithProgress { inner, progress })?;
    let schedule = scene.schedule();
    Ok(Ran {
        summary: summary(&scene, &run),
        diverged: run.diverged(scene.name()),
        end: SceneEnd {
            scene: scene.name(),
            status: if run.interrupted {
                "interrupted"
            } else {
                "complete"
            },
            last_tick: run.last_tick,
            end_time: schedule.time(run.last_tick),
            text: run.ending(&schedule),
        },
    })
}

/// Every method the recording holds, first occurrence kept (pendulum, hair, rope).
fn method_names(r: &Resolved) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Vec::new();
    let all = r
        .pendulum
        .iter()
        .flat_map(|c| c.methods.iter().map(|m| m.name()))
        .chain(
            r.hair
                .iter()
                .flat_map(|c| c.methods.iter().map(|m| m.name())),
        )
        .chain(
            r.rope
                .iter()
                .flat_map(|c| c.methods.iter().map(|m| m.name())),
        );
    for m in all {
        if !names.contains(&m) {
            names.push(m);
        }
    }
    names
}

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
    let recorded = recording.is_some();
    // A recording that cannot be written (a full disk) still shows the summaries first.
    let committed = recording.map(Recording::commit).transpose();
    // With `-o -` standard output carries the recording: the summary goes to stderr.
    if d.stdout {
        eprint!("{}", summaries.join("\n"));
    } else {
        print!("{}", summaries.join("\n"));
    }
    let bytes = committed?;
    if let Some(bytes) = bytes
        && !summaries.is_empty()
    {
        report_recording(d, bytes, started);
    } else if run.no_record {
        println!(
            "\nno recording (--no-record), {:.1} s",
            started.elapsed().as_secs_f64()
        );
    }
    if crate::interrupt::requested() {
        let kept = match &d.file {
            Some(path) if recorded => format!(
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

fn destinations(run: &RunArgs, scene: &str) -> Destinations {
    let to_stdout = run.output.as_ref().is_some_and(|p| p.as_os_str() == "-");
    Destinations {
        file: (!run.no_save && !to_stdout).then(|| {
            run.output
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("recordings/{scene}.rrd")))
        }),
        connect: run.connect.clone(),
        spawn: run.spawn,
        stdout: to_stdout,
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
        _ if d.stdout => eprintln!(
            "\nrecording written to standard output, {:.1} s",
            started.elapsed().as_secs_f64()
        ),
        _ => println!(
            "\nstreamed, no file written, {:.1} s",
            started.elapsed().as_secs_f64()
        ),
    }
}
