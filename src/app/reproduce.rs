//! `physlab reproduce FILE.rrd`: re-runs what a recording holds from its embedded configuration
//! and compares every logged value with it.

use std::collections::BTreeSet;
use std::path::Path;
use std::time::Instant;

use super::compared::{
    EntityLine, beyond, by_entity, check_output, difference_lines, identical_line, lane_names,
    physlab_made, print_lines, recorded_command, recorded_timings, tolerance, version_line,
    version_text, wall_clock,
};
use super::progress::{Budget, LARGE_BYTES, LONG_SECONDS, OverBudget};
use super::scenes::{AllFlags, SCENES, parse_scene_file, scene_named, scene_names};
use super::{Error, Plan, Replay, simulate};
use crate::cli::{ReproduceArgs, RunArgs};
use crate::format::{duration as duration_text, size as size_text};
use crate::output::TempFile;
use crate::rrd::compare::{StreamSpec, compare_files};
use crate::rrd::inspect::RecordingInfo;
use crate::rrd::read::{Messages, unusable};
use crate::shell::escaped;

/// Why the re-run failed, in words true to the cause: a stop stays an interruption, a
/// configuration this build refuses says so without the temporary file's name.
fn rerun_failed(e: anyhow::Error, file: &Path, config: &Path) -> anyhow::Error {
    if let Some(OverBudget(estimate)) = e.downcast_ref() {
        return over_limits(file, estimate).into();
    }
    if matches!(e.downcast_ref::<Error>(), Some(Error::Interrupted(_))) {
        return Error::Interrupted(format!(
            "interrupted: the re-run of {} was stopped, so nothing was compared",
            file.display()
        ))
        .into();
    }
    if let Some(Error::Usage(message)) = e.downcast_ref::<Error>()
        && message.contains(&config.display().to_string())
    {
        let message = message.replace(
            &format!("--config {}: ", config.display()),
            "its embedded configuration: ",
        );
        return Error::Usage(format!(
            "{}: its configuration does not run with this build: {}",
            file.display(),
            escaped(&message)
        ))
        .into();
    }
    e.context(format!("re-running {}", file.display()))
}

pub fn reproduce_command(args: &ReproduceArgs) -> anyhow::Result<()> {
    let tol = tolerance(args.tolerance)?;
    // Read once: everything below reads this private copy, so that the file replaced meanwhile
    // changes nothing (its configuration and its data are the same file's).
    let input = read_once(&args.file)?;
    let of_file = |e| of_the_file(e, input.path(), &args.file);
    let recorded = Recorded::read(input.path(), &args.file).map_err(of_file)?;
    // The input refused first: no folder is made for a re-run that will not happen.
    check_output(
        args.output.as_ref(),
        crate::output::Dash::Refused(
            "cannot carry the re-run: it is read back and compared, and the report is printed there; \
             give a file path",
        ),
        &[&args.file],
    )?;
    let mut replay = recorded.replay(&args.file)?;
    // Past the limits by its measured pace, as a scene's notice tells it, the re-run is stopped.
    let limit = |max| if args.allow_long { f64::INFINITY } else { max };
    replay.budget = Some(Budget {
        seconds: limit(MAX_SECONDS),
        bytes: limit(MAX_BYTES),
        say: !args.quiet,
    });
    // What the configuration alone bounds (its recording, its memory, a floor on its time) is
    // refused before anything runs.
    let expected = recorded.expected();
    if let Some(e) = &expected
        && e.over(MAX_SECONDS, MAX_BYTES)
        && !args.allow_long
    {
        return Err(over_limits(&args.file, &e.text()).into());
    }

    if !args.quiet {
        eprintln!("re-running {} …", escaped(&args.file.display().to_string()));
        // As a scene command says it of a long or large run ([`LONG_SECONDS`], [`LARGE_BYTES`]).
        if let Some(e) = expected.filter(|e| e.over(LONG_SECONDS, LARGE_BYTES)) {
            eprintln!("{}", e.text());
        }
    }
    let config = TempFile::create(
        "reproduce.toml",
        recorded.info.properties["config"].as_bytes(),
    )?;
    let scratch = TempFile::create("reproduce.rrd", b"")?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| scratch.path().to_path_buf());
    let run = RunArgs {
        config: Some(config.path().to_path_buf()),
        output: Some(output.clone()),
        quiet: true,
        timings: recorded.timings,
        ..RunArgs::default()
    };
    let plan: Plan = SCENES
        .iter()
        .filter(|s| recorded.scenes.contains(&s.name))
        .map(|s| s.flags(&AllFlags::default()))
        .collect();
    let started = Instant::now();
    simulate(plan, &run, None, &replay).map_err(|e| rerun_failed(e, &args.file, config.path()))?;
    let seconds = started.elapsed().as_secs_f64();
    let report = recorded
        .compare(input.path(), &output, tol)
        .map_err(of_file)?;
    if report.entries.is_empty() {
        return Err(nothing_to_compare(&args.file).into());
    }
    let written = args.output.as_ref().map(|_| output.as_path());
    print_lines(
        &report.lines(&recorded, seconds, written, args.verbose),
        false,
    );
    if report.differing > 0 {
        return Err(Error::Differs(format!(
            "{}: does not reproduce",
            escaped(&args.file.display().to_string())
        ))
        .into());
    }
    Ok(())
}

fn over_limits(file: &Path, what: &str) -> Error {
    Error::Usage(format!(
        "{}: {what}; reproduce re-runs at most {} min, a {} recording and {} of memory unless \
         --allow-long is given",
        file.display(),
        MAX_SECONDS / 60.0,
        size_text(MAX_BYTES),
        size_text(super::MEMORY_NOTICE_BYTES),
    ))
}

/// A re-run beyond any of these is refused unless `--allow-long`: a stranger's recording may
/// ask for hours, hundreds of GB or all the memory, and nobody typed its command.
const MAX_SECONDS: f64 = 600.0;
const MAX_BYTES: f64 = 1e9;

/// What a re-run will take, from its configuration alone ([`Bulk`]): a floor on its seconds
/// (its measured pace judges its time, [`Budget`]), its recording, its state's memory.
struct Expected {
    node_steps: f64,
    seconds: f64,
    bytes: f64,
    memory: f64,
}

impl Expected {
    /// Beyond `seconds` or `bytes`, or a state a scene command tells of.
    fn over(&self, seconds: f64, bytes: f64) -> bool {
        self.seconds > seconds || self.bytes > bytes || self.memory > super::MEMORY_NOTICE_BYTES
    }

    fn text(&self) -> String {
        format!(
            "its re-run does {:.1e} node-steps (at least about {}; more where its state \
             outgrows the CPU's caches) and writes about {} to its recording; its state takes \
             about {} of memory (from its configuration)",
            self.node_steps,
            duration_text(self.seconds),
            size_text(self.bytes),
            size_text(self.memory)
        )
    }
}

/// A recording that holds nothing the re-run could be compared with: it never verifies.
fn nothing_to_compare(file: &Path) -> Error {
    Error::Usage(format!(
        "{}: holds no data to compare (a configuration alone: the run was killed before it \
         logged anything, or the file was made so), so nothing can be reproduced",
        file.display()
    ))
}

/// Copies `file` into the temporary folder through one opened handle, after the reader's own
/// checks: the copy is all that is read after that.
fn read_once(file: &Path) -> anyhow::Result<TempFile> {
    Messages::open(file)?;
    let mut source =
        std::fs::File::open(file).map_err(|e| unusable(file, format!("cannot open it: {e}")))?;
    let copy = TempFile::create("reproduce-input.rrd", b"")?;
    let copied = std::fs::OpenOptions::new()
        .write(true)
        .open(copy.path())
        .and_then(|mut sink| std::io::copy(&mut source, &mut sink));
    copied.map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot copy it into the temporary file (TMPDIR, or /tmp when unset) {}: {}",
            file.display(),
            copy.path().display(),
            crate::output::cause(&e)
        )
    })?;
    Ok(copy)
}

/// An error the reader gave about the private copy, told of the file the user named.
fn of_the_file(e: anyhow::Error, copy: &Path, file: &Path) -> anyhow::Error {
    let (from, to) = (copy.display().to_string(), file.display().to_string());
    match e.downcast::<Error>() {
        Ok(Error::Usage(m)) => Error::Usage(m.replace(&from, &to)).into(),
        Ok(Error::Interrupted(m)) => Error::Interrupted(m.replace(&from, &to)).into(),
        Ok(other) => other.into(),
        Err(e) => anyhow::anyhow!("{}", format!("{e:#}").replace(&from, &to)),
    }
}

struct Recorded {
    info: RecordingInfo,
    scenes: Vec<&'static str>,
    timings: bool,
}

impl Recorded {
    /// Reads `copy` (of `file`, which messages name) and refuses what `reproduce` cannot re-run.
    fn read(copy: &Path, file: &Path) -> anyhow::Result<Recorded> {
        let info = physlab_made(copy)?;
        let p = |k| escaped(info.property(k)).into_owned();
        let refuse = |m: String| Err(Error::Usage(format!("{}: {m}", file.display())).into());
        let kind = info.properties.get("scenes").cloned().unwrap_or_default();
        if kind == "diff" {
            let again = recorded_command(&info);
            return refuse(format!(
                "a diff recording (of {} and {}), not a run; write it again with: {}",
                p("diff_a"),
                p("diff_b"),
                again.unwrap_or_else(|| "physlab diff A.rrd B.rrd -o D.rrd".into())
            ));
        }
        if !info.properties.contains_key("config") {
            return refuse(
                "holds no physlab configuration (recorded by a physlab older than its provenance)"
                    .into(),
            );
        }
        if kind.starts_with("study") {
            return refuse(format!(
                "a study recording ({}); reproduce re-runs scene recordings only (run its \
                 command line again: {})",
                escaped(&kind),
                recorded_command(&info).unwrap_or_else(|| "?".into())
            ));
        }
        let listed: Option<Vec<&'static str>> = (kind.split(',').filter(|s| !s.is_empty()))
            .map(|s| scene_named(s).map(|k| k.name))
            .collect();
        let scenes = match listed {
            Some(scenes) if !scenes.is_empty() => scenes,
            _ => {
                let expected = super::file::listing(&scene_names(), "and/or");
                return refuse(format!(
                    "its provenance names the scenes \"{}\"; expected {expected}",
                    escaped(&kind)
                ));
            }
        };
        if info.entities.is_empty() {
            return Err(nothing_to_compare(file).into());
        }
        let timings = recorded_timings(&info);
        Ok(Recorded {
            info,
            scenes,
            timings,
        })
    }

    /// What its re-run will take, from its configuration ([`Bulk`]); `None` when the
    /// configuration does not resolve (the re-run then says why).
    fn expected(&self) -> Option<Expected> {
        let file = parse_scene_file(&self.info.properties["config"]).ok()?;
        let mut out = Expected {
            node_steps: 0.0,
            seconds: 0.0,
            bytes: 0.0,
            memory: 0.0,
        };
        for kind in SCENES.iter().filter(|s| self.scenes.contains(&s.name)) {
            let ready = kind.as_recorded(&file).ok()?;
            let bulk = ready.bulk();
            out.node_steps += bulk.node_steps;
            out.seconds += bulk.seconds();
            out.bytes += bulk.bytes();
            out.memory = out.memory.max(ready.memory_bytes());
        }
        Some(out)
    }

    /// No end record (an older physlab, or killed): each series is compared as far as it goes.
    fn killed(&self) -> bool {
        self.info.run.is_empty()
    }

    /// Where each scene ended, as the re-run replays it: it stops at the same tick.
    fn replay(&self, file: &Path) -> Result<Replay, Error> {
        let mut replay = Replay {
            silent: true,
            ..Replay::default()
        };
        for scene in &self.scenes {
            let run = |k: &str| self.info.run.get(&format!("{scene}_{k}"));
            match run("status").map(String::as_str) {
                Some("interrupted") => {
                    let tick = run("last_tick")
                        .and_then(|t| t.parse::<u64>().ok())
                        .ok_or_else(|| {
                            Error::Usage(format!(
                                "{}: {scene} was interrupted but its last tick is not recorded",
                                file.display()
                            ))
                        })?;
                    replay.stop_after.insert(scene, tick);
                }
                Some("not run") => _ = replay.skip.insert(scene),
                _ => {}
            }
        }
        Ok(replay)
    }

    fn compare(&self, copy: &Path, rerun: &Path, tolerance: f64) -> anyhow::Result<Reproduced> {
        let (timings, killed) = (self.timings, self.killed());
        let skip = |entity: &str| wall_clock(entity, timings);
        let spec = StreamSpec {
            tolerance,
            skip: &skip,
            rename_b: None,
            cap_b: killed,
        };
        let streamed = compare_files(copy, rerun, &spec, &mut |_, _, _| Ok(()))?;
        let recorded = &streamed.index_a;
        let skipped = recorded.keys().map(|k| k.0.clone()).filter(|e| skip(e));
        // Static rows and timed rows of a series are compared apart; both count for its entity.
        let mut diffs: Vec<_> = (streamed.statics.iter().chain(&streamed.timed))
            .filter(|(key, _)| recorded.contains_key(*key))
            .map(|(key, d)| (key.clone(), d.clone()))
            .collect();
        diffs.sort_by(|x, y| x.0.cmp(&y.0));
        let only_recomputed: BTreeSet<&String> = (streamed.index_b.keys())
            .filter(|k| !recorded.contains_key(*k) && !skip(&k.0) && !killed)
            .map(|k| &k.0)
            .collect();
        let mut report = Reproduced {
            tolerance,
            skipped: skipped.collect(),
            ..Reproduced::default()
        };
        for r in by_entity(diffs) {
            let text = if r.bit_identical() {
                format!("identical ({} rows)", r.rows())
            } else if r.same() {
                report.within += 1;
                format!("within tolerance: {}", r.describe("recorded", "recomputed"))
            } else {
                report.differing += 1;
                format!("DIFFERS: {}", r.describe("recorded", "recomputed"))
            };
            let (differs, first) = (!r.same(), r.first_time());
            report.entries.push(EntityLine {
                entity: r.entity,
                differs,
                text,
                first,
            });
        }
        for e in only_recomputed {
            report.differing += 1;
            report.entries.push(EntityLine {
                entity: e.clone(),
                differs: true,
                text: "DIFFERS: only in the re-run, not in the recording".into(),
                first: i64::MAX,
            });
        }
        Ok(report)
    }
}

/// What the re-run gave against the recording, entity by entity.
#[derive(Default)]
struct Reproduced {
    tolerance: f64,
    entries: Vec<EntityLine>,
    /// Entities that differ (beyond the tolerance), and those within it but not bit-identical.
    differing: usize,
    within: usize,
    /// Entities left out: their values depend on the wall clock.
    skipped: BTreeSet<String>,
}

impl Reproduced {
    fn verdict(&self) -> String {
        let (n, tol) = (self.entries.len(), self.tolerance);
        if self.differing > 0 {
            let beyond = beyond(tol).map_or(String::new(), |b| format!(" ({b})"));
            format!(
                "verdict: DIFFERS in {} of {n} entities{beyond}",
                self.differing
            )
        } else if self.within > 0 {
            format!(
                "verdict: reproduces within --tolerance {tol} ({} of {n} entities not bit-identical)",
                self.within
            )
        } else {
            format!(
                "verdict: bit-identical ({})",
                crate::format::plural(n as u64, "entity")
            )
        }
    }

    fn lines(
        &self,
        recorded: &Recorded,
        seconds: f64,
        written: Option<&Path>,
        verbose: bool,
    ) -> Vec<String> {
        let mut out = vec![self.verdict()];
        let now = version_text(
            env!("CARGO_PKG_VERSION"),
            crate::record::GIT_COMMIT,
            crate::record::RERUN_SDK_VERSION,
        );
        let then = version_line(&recorded.info);
        if then == now {
            out.push(format!("recorded and re-run by the same build: {then}"));
        } else {
            out.push(format!("recorded by {then}"));
            out.push(format!(
                "re-run by {now}  (a different build: differences may come from it)"
            ));
        }
        for scene in &recorded.scenes {
            if let Some(ended) = recorded.info.run.get(&format!("{scene}_ended")) {
                out.push(format!("{scene}: {ended}"));
            }
        }
        if recorded.killed() {
            out.push(
                "the recording does not say where it ended: each series is compared up to its \
                 last recorded row"
                    .into(),
            );
        }
        out.push(format!("re-ran in {seconds:.1} s"));
        if let Some(path) = written {
            out.push(format!("wrote the re-run to {}", path.display()));
        }
        let shown =
            (self.entries.iter()).filter(|e| verbose || e.differs || e.text.starts_with("within"));
        let lanes = lane_names(&[&recorded.info]);
        out.extend(difference_lines(shown, &lanes, verbose));
        let identical = self.entries.len() - self.differing - self.within;
        out.extend(identical_line(identical, verbose));
        if !self.skipped.is_empty() {
            let list: Vec<&str> = self.skipped.iter().map(String::as_str).collect();
            let list = if verbose {
                format!(": {}", list.join(", "))
            } else {
                String::new()
            };
            out.push(format!(
                "skipped: {} (wall-clock timings){list}",
                crate::format::plural(self.skipped.len() as u64, "entity")
            ));
        }
        out
    }
}
