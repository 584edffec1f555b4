//! The commands. Every simulating command goes through one pipeline ([`simulate`]): resolve the
//! scenes' parameters (defaults < preset < scene file < flags), open the recording, run each
//! scene with the recorder and the progress bar as its observers, print the summaries, finish.
//! A single-scene command is `all` with one scene.

mod compared;
mod diff;
mod file;
mod inspect;
mod layers;
mod progress;
mod reproduce;
mod scenes;
mod study;

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use crate::error::Error;
pub use file::{MAX_SCENE_FILE_BYTES, SceneFile};

use crate::cli::{AllArgs, Cli, Command, RunArgs};
use crate::record::scene::{Draw, SceneRecorder};
use crate::record::{Destinations, Recording, SceneEnd, send_provenance};
use crate::scene::hair::HairMethod;
use crate::scene::harness::{self, NoObserver, Observer, Run, Scene};
use crate::{record, report};
use progress::{Progress, WithProgress};
use scenes::{AllFlags, Flags, RunContext, SCENES};

/// A run whose state takes more memory than this says so before it starts.
const MEMORY_NOTICE_BYTES: f64 = 1e9;

pub fn run(cli: Cli) -> anyhow::Result<()> {
    let fresh = Replay::default();
    match cli.command {
        Command::Methods(a) => methods(a.name.as_deref()),
        Command::Inspect(args) => inspect::inspect_command(&args),
        Command::Pendulum(c) => simulate(vec![Box::new(c.scene)], &c.run, None, &fresh),
        Command::Rope(c) => simulate(vec![Box::new(c.scene)], &c.run, None, &fresh),
        Command::Hair(c) => simulate(vec![Box::new(c.scene)], &c.run, c.threads, &fresh),
        Command::All(c) => simulate(all_plan(&c)?, &c.run, None, &fresh),
        Command::Reproduce(args) => reproduce::reproduce_command(&args),
        Command::Diff(args) => diff::diff_command(&args),
        Command::Study(a) => study::study(&a),
    }
}

/// `physlab methods [NAME]`: the registry's table, or one method's page.
fn methods(name: Option<&str>) -> anyhow::Result<()> {
    use report::methods::{method_page, methods_table, page_names};
    let text = match name {
        None => methods_table(),
        Some(name) => method_page(name).ok_or_else(|| {
            Error::Usage(format!(
                "methods {name}: no method of that name (allowed: {})",
                page_names().join(", ")
            ))
        })?,
    };
    print!("{text}");
    Ok(())
}

/// The scenes a command runs, each with its flags (not yet layered over file and defaults).
type Plan = Vec<Box<dyn Flags>>;

/// `physlab all`: every scene, its own flags over every scene's.
fn all_plan(c: &AllArgs) -> Result<Plan, Error> {
    let (registry, hair) = c.methods.as_deref().map(split_methods).transpose()?.unzip();
    let all = AllFlags {
        dt: c.dt,
        duration: c.duration,
        fps: c.fps,
        plot_every: c.plot_every,
        registry,
        hair,
    };
    Ok(SCENES.iter().map(|scene| scene.flags(&all)).collect())
}

/// `all --methods`: the names the pendulum and rope take (the registry's) and those hair takes.
fn split_methods(
    names: &[String],
) -> Result<(Vec<crate::integrate::Method>, Vec<HairMethod>), Error> {
    use crate::integrate::Method;
    let list = names.join(",");
    let registry_names: Vec<&str> = Method::names().collect();
    let mut registry = Vec::new();
    let mut hair = Vec::new();
    for name in names {
        let r = name.parse::<Method>().ok();
        let h = name.parse::<HairMethod>().ok();
        if r.is_none() && h.is_none() {
            return Err(Error::Usage(format!(
                "--methods {list}: no scene has a method '{name}' (pendulum and rope: {}; hair: {})",
                registry_names.join(", "),
                HairMethod::names()
            )));
        }
        registry.extend(r);
        hair.extend(h);
    }
    let none = |scene: &str, allowed: String| {
        Err(Error::Usage(format!(
            "--methods {list}: leaves {scene} no method (allowed: {allowed})"
        )))
    };
    if registry.is_empty() {
        return none("the pendulum and the rope", registry_names.join(", "));
    }
    if hair.is_empty() {
        return none("hair", HairMethod::names());
    }
    Ok((registry, hair))
}

/// A re-run of a recording (`physlab reproduce`): where the recorded run stopped each scene.
#[derive(Default)]
struct Replay {
    /// Scenes that were interrupted, with the last tick they reached.
    stop_after: BTreeMap<&'static str, u64>,
    /// Scenes the recorded run never started.
    skip: BTreeSet<&'static str>,
    silent: bool,
    budget: Option<progress::Budget>,
}

/// The plan's scenes, layered and validated, and the scene file that reproduces them.
struct Resolved {
    scenes: Vec<Box<dyn scenes::ReadyScene>>,
    /// The effective parameters of every scene run, as a scene file.
    file: SceneFile,
}

fn resolve(plan: Plan, run: &RunArgs) -> anyhow::Result<Resolved> {
    let file = load_scene_file(run.config.as_deref())?;
    let single = plan.len() == 1;
    let mut resolved = Resolved {
        scenes: Vec::new(),
        file: SceneFile::default(),
    };
    for flags in plan {
        let name = flags.kind().name;
        if single {
            file.require(name)?;
        } else if let Some(path) = &run.config
            && file.table(name).is_none()
        {
            eprintln!(
                "note: --config {}: no [{name}] table; {name} runs at its defaults",
                path.display()
            );
        }
        let scene = flags.resolve(&file, run)?;
        resolved.file.set(name, scene.table()?);
        resolved.scenes.push(scene);
    }
    Ok(resolved)
}

/// A scene's configuration from its flags alone (over its defaults), settled and validated.
pub fn config_from_flags<C: crate::scene::params::SceneConfig>(
    flags: &(impl clap::Args + serde::Serialize),
    scene: &'static str,
) -> Result<C, Error> {
    scenes::given(flags, scene, &SceneFile::default())?.resolve()
}

fn load_scene_file(path: Option<&std::path::Path>) -> Result<SceneFile, Error> {
    match path {
        Some(path) => SceneFile::load(path, &scenes::scene_names()),
        None => Ok(SceneFile::default()),
    }
}

/// The one pipeline of every simulating command. `threads`: hair's worker threads (`physlab
/// hair --threads`), which change no result and so are neither recorded nor reproduced.
fn simulate(
    plan: Plan,
    run: &RunArgs,
    threads: Option<usize>,
    replay: &Replay,
) -> anyhow::Result<()> {
    let resolved = resolve(plan, run)?;
    let text = resolved.file.to_toml()?;
    if let Some(n) = threads {
        crate::scene::params::threads(n)?;
    }
    refuse_contradictions(run)?;
    if run.print_config {
        print!("{text}");
        return Ok(());
    }
    // 0: rayon's own choice, as without --threads.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0));
    let pool = (pool.build()).map_err(|e| {
        anyhow::anyhow!("cannot start the worker threads: no threads available (`ulimit -u`): {e}")
    })?;
    let started = Instant::now();
    let name = match resolved.scenes.as_slice() {
        [one] => one.kind().name,
        _ => "all",
    };
    let d = if run.no_record {
        Destinations::default()
    } else {
        destinations(run, name)
    };
    // The recording never replaces the scene file it was made from.
    if let Some(out) = d.written()? {
        let input = (run.config.as_deref()).map(|p| ("the scene file read (--config)", p));
        crate::output::distinct(&[&out], input.as_slice())?;
    }
    let recording = if run.no_record {
        None
    } else {
        Some(open_recording(&resolved, run, &d, name, &text)?)
    };
    let mut progress = Progress::new(run.quiet, recording.as_ref().and_then(|r| r.written()));
    progress.budget = replay.budget;
    let mut ctx = RunContext {
        stream: recording.as_ref().map(|r| r.stream().clone()),
        timings: run.timings,
        // One `frame` timeline for the whole recording: frame N at N / (the highest fps) s.
        frame_rate: resolved.scenes.iter().map(|s| s.fps()).fold(0.0, f64::max),
        quiet: run.quiet,
        progress: &mut progress,
        pool: &pool,
        stop_after: None,
    };
    let ran = run_scenes(resolved.scenes, &mut ctx, run, replay)?;
    let stream = ctx.stream.take();
    progress.finish();
    if let Some(s) = &stream {
        record::send_run_status(s, &ran.ends)?;
    }
    drop(stream);
    let summaries = if replay.silent {
        &[]
    } else {
        &ran.summaries[..]
    };
    finish(recording, &d, started, summaries, &ran.diverged, run)
}

fn open_recording(
    resolved: &Resolved,
    run: &RunArgs,
    d: &Destinations,
    name: &str,
    text: &str,
) -> anyhow::Result<Recording> {
    let (layout, application_id) = match resolved.scenes.as_slice() {
        [one] => (
            record::scene_layout(
                one.kind().views,
                run.timings,
                &one.staging(),
                &one.methods(),
            ),
            one.kind().application_id,
        ),
        all => {
            let views: Vec<_> = (all.iter())
                .map(|s| (s.kind().views, s.staging(), s.methods()))
                .collect();
            (record::all_layout(run.timings, &views), "physlab-all")
        }
    };
    let recording = Recording::create(d, application_id, name, layout)?;
    let scenes: Vec<&str> = resolved.scenes.iter().map(|s| s.kind().name).collect();
    send_provenance(
        recording.stream(),
        &scenes.join(","),
        text,
        &method_names(resolved),
    )?;
    Ok(recording)
}

/// What the scenes' runs leave (scenes not run after an interruption say so in `ends`).
struct Ended {
    summaries: Vec<String>,
    diverged: Vec<String>,
    ends: Vec<SceneEnd>,
}

/// Runs the scenes one after another; after an interruption the remaining ones are skipped.
fn run_scenes(
    scenes: Vec<Box<dyn scenes::ReadyScene>>,
    ctx: &mut RunContext,
    run: &RunArgs,
    replay: &Replay,
) -> anyhow::Result<Ended> {
    // Said up front, before any work: a step too large for a scene is most often a unit mistake.
    let warnings: Vec<Option<String>> = scenes.iter().map(|s| s.step_warning()).collect();
    if !replay.silent {
        for (scene, w) in scenes.iter().zip(&warnings) {
            if let Some(w) = w {
                let w = format!("warning: {}: {w}", scene.kind().name);
                eprintln!("{}", crate::report::table::fit_lines(&w));
            }
        }
    }
    let names: Vec<&'static str> = scenes.iter().map(|s| s.kind().name).collect();
    let mut ended = Ended {
        summaries: Vec::new(),
        diverged: Vec::new(),
        ends: Vec::new(),
    };
    for (scene, warning) in scenes.into_iter().zip(warnings) {
        let name = scene.kind().name;
        if crate::interrupt::requested() || replay.skip.contains(name) {
            continue;
        }
        ctx.stop_after = replay.stop_after.get(name).copied();
        let memory = scene.memory_bytes();
        if memory > MEMORY_NOTICE_BYTES && !run.quiet {
            // Allowed (validation refuses what does not fit), but not to be taken silently.
            let of = crate::scene::params::memory_room().map_or(String::new(), |(a, _)| {
                format!(" (of {:.1} GB available)", a / 1e9)
            });
            let gb = memory / 1e9;
            eprintln!("{name}: its state takes about {gb:.1} GB of memory{of}");
        }
        if !run.quiet && !replay.silent {
            say_floor(name, scene.bulk(), !run.no_record);
        }
        let mut ran = scene.run(ctx)?;
        if let Some(w) = warning {
            ran.append(&format!("\nwarning: {w}\n"));
        }
        if let Some(s) = &ctx.stream {
            record::log_summary(s, ran.end.scene, &ran.summary, &ran.end.text, run.timings)?;
        }
        let shown = if run.wide { ran.summary } else { ran.fitted };
        ended.summaries.push(shown + &ran.printed_only);
        ended.diverged.extend(ran.diverged);
        ended.ends.push(ran.end);
    }
    // Scenes skipped after an interruption say so too.
    for scene in names {
        if !ended.ends.iter().any(|e| e.scene == scene) {
            ended.ends.push(SceneEnd {
                scene,
                status: "not run",
                last_tick: 0,
                end_time: 0.0,
                text: "not run: the run was interrupted before this scene started".into(),
            });
        }
    }
    Ok(ended)
}

/// Says before a scene's setup what its size alone makes it take, when long or large: a state of
/// gigabytes takes seconds to build, before its pace can be judged (`Progress`).
fn say_floor(name: &str, bulk: scenes::Bulk, recorded: bool) {
    let (seconds, bytes) = (bulk.seconds(), bulk.bytes() * f64::from(recorded));
    if seconds > progress::LONG_SECONDS || bytes > progress::LARGE_BYTES {
        let (time, size) = (crate::format::duration(seconds), crate::format::size(bytes));
        let notice = format!(
            "{name}: this takes at least about {time} and writes about {size} to its recording \
             (from its {:.1e} node-steps and 3D frames, before it starts); Ctrl-C stops it",
            bulk.node_steps
        );
        eprintln!("{}", report::table::fit_lines(&notice));
    }
}

fn refuse_contradictions(run: &RunArgs) -> Result<(), Error> {
    if run.no_save
        && let Some(path) = &run.output
    {
        return Err(Error::Usage(format!(
            "--no-save with -o {}: one says write no file, the other names it; drop one",
            path.display()
        )));
    }
    if run.no_save && run.connect.is_none() && !run.spawn {
        return Err(Error::Usage(
            "--no-save without --connect or --spawn: the run would go nowhere".into(),
        ));
    }
    if run.no_record {
        for (given, flag) in [
            (run.output.is_some(), "-o/--output"),
            (run.connect.is_some(), "--connect"),
            (run.spawn, "--spawn"),
            (run.no_save, "--no-save"),
            (run.timings, "--timings"),
        ] {
            if given {
                return Err(Error::Usage(format!(
                    "--no-record with {flag}: --no-record writes and streams nothing"
                )));
            }
        }
    }
    Ok(())
}

struct Ran {
    /// The summary with its full table: recorded, and printed with --wide.
    summary: String,
    /// The summary with its table fitted to 100 columns: printed by default.
    fitted: String,
    /// Printed under the summary but not recorded: what depends on the machine, not the inputs
    /// (hair's thread count), so that a recording compares equal on any machine.
    printed_only: String,
    diverged: Vec<String>,
    end: SceneEnd,
}

impl Ran {
    fn append(&mut self, text: &str) {
        self.summary.push_str(text);
        self.fitted.push_str(text);
    }
}

impl RunContext<'_> {
    /// Runs `scene` through the harness, recorded (when a recording is made) by `recorder`, and
    /// summarised by `summary`.
    fn run<S: Scene, D: Draw<S>>(
        &mut self,
        mut scene: S,
        recorder: impl FnOnce(rerun::RecordingStream, bool) -> SceneRecorder<D>,
        summary: fn(&S, &Run<S::Lane>, bool) -> String,
    ) -> anyhow::Result<Ran> {
        let mut recorder = (self.stream.clone())
            .map(|s| recorder(s, self.timings).with_frame_rate(self.frame_rate));
        let schedule = scene.schedule();
        let end = (self.stop_after).map_or(schedule.total, |t| t.min(schedule.total));
        let progress = &mut *self.progress;
        progress.stage(scene.name(), end as f64, Some(schedule.frames()));
        let mut quiet = NoObserver;
        let inner: &mut dyn Observer<S> = match &mut recorder {
            Some(r) => r,
            None => &mut quiet,
        };
        let observer = &mut WithProgress { inner, progress };
        let run = harness::run_until(&mut scene, observer, self.stop_after)?;
        let schedule = scene.schedule();
        let mut text = String::new();
        if let (true, Some(_)) = (schedule.aggregates(), &recorder) {
            let plots = schedule.series_text(&scene.windows());
            text.push_str(&format!("\nplots: {plots}\n"));
        }
        if let (Some(gap), Some(_)) = (schedule.gap_text(), &recorder) {
            text.push_str(&format!("\n{gap}\n"));
        }
        Ok(Ran {
            summary: summary(&scene, &run, true) + &text,
            fitted: summary(&scene, &run, false) + &text,
            printed_only: String::new(),
            diverged: run.diverged(scene.name()),
            end: SceneEnd {
                scene: scene.name(),
                status: ["complete", "interrupted"][run.interrupted as usize],
                last_tick: run.last_tick,
                end_time: schedule.time(run.last_tick),
                text: run.ending(&schedule),
            },
        })
    }
}

/// Every method the recording holds, first occurrence kept, in the order the scenes run.
fn method_names(r: &Resolved) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Vec::new();
    for m in r.scenes.iter().flat_map(|s| s.methods()) {
        if !names.contains(&m) {
            names.push(m);
        }
    }
    names
}

/// After a run: finalise the recording, print the summaries, then report an interruption
/// or, with --fail-on-divergence, a divergence.
fn finish(
    mut recording: Option<Recording>,
    d: &Destinations,
    started: Instant,
    summaries: &[String],
    diverged: &[String],
    run: &RunArgs,
) -> anyhow::Result<()> {
    let recorded = recording.is_some();
    let live = recording.as_mut().map_or(Vec::new(), Recording::take_live);
    // A recording that cannot be written (a full disk) still shows the summaries first.
    let committed = recording.map(Recording::commit).transpose();
    // With `-o -` standard output carries the recording: the summary goes to stderr.
    let mut text = summaries.join("\n");
    if !run.wide {
        text = report::table::fit_lines(&text);
    }
    crate::output::print_beside(d.stdout, &text);
    let bytes = committed?;
    if let Some(bytes) = bytes
        && !summaries.is_empty()
    {
        report_recording(d, bytes, started);
    } else if run.no_record {
        let s = started.elapsed().as_secs_f64();
        println!("\nno recording (--no-record), {s:.1} s");
    }
    // The viewers take what is left once the file and the summary are out.
    live.into_iter().for_each(record::live::Live::finish);
    if crate::interrupt::requested() {
        let kept = match &d.file {
            Some(path) if recorded => format!(
                "; the recording of everything so far is finalised in {}",
                path.display()
            ),
            _ => String::new(),
        };
        return Err(Error::Interrupted(format!("interrupted{kept}")).into());
    }
    if run.fail_on_divergence && !diverged.is_empty() {
        return Err(Error::Diverged(format!(
            "--fail-on-divergence: {} diverged",
            diverged.join(", ")
        ))
        .into());
    }
    Ok(())
}

fn destinations(run: &RunArgs, scene: &str) -> Destinations {
    let to_stdout = run.output.as_ref().is_some_and(|p| p.as_os_str() == "-");
    let file = (run.output.clone()).unwrap_or_else(|| format!("recordings/{scene}.rrd").into());
    Destinations {
        file: (!run.no_save && !to_stdout).then_some(file),
        connect: run.connect.clone(),
        spawn: run.spawn,
        stdout: to_stdout,
    }
}

fn report_recording(d: &Destinations, bytes: Option<u64>, started: Instant) {
    let s = started.elapsed().as_secs_f64();
    match (&d.file, bytes) {
        (Some(path), Some(bytes)) => {
            let mb = bytes as f64 / 1e6;
            println!(
                "\nrecording: {} ({mb:.2} MB), {s:.1} s",
                crate::shell::shown(path)
            );
        }
        _ if d.stdout => eprintln!("\nrecording written to standard output, {s:.1} s"),
        _ => println!("\nstreamed, no file written, {s:.1} s"),
    }
}
