//! `physlab reproduce FILE.rrd`: re-runs what a recording holds from its embedded configuration
//! and compares every logged value with it. `physlab diff A.rrd B.rrd`: compares two
//! recordings, configuration first, then every series.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::scenes::{AllFlags, SCENES};
use super::{Error, Output, Plan, Replay, simulate};
use crate::cli::{DiffArgs, ReproduceArgs, RunArgs};
use crate::record::compare::{Key, SeriesDiff, SeriesIndex, StreamSpec, compare_files, time_text};
use crate::record::diff::DiffWriter;
use crate::record::inspect::{RecordingInfo, read_recording};

/// Entities whose values depend on the wall clock, so that no re-run can match them: the
/// --timings plots, and with --timings the summaries (which then hold wall times, ns/step).
fn wall_clock(entity: &str, timings: bool) -> bool {
    entity.contains("/plots/frame_cost/") || (timings && entity.ends_with("/summary"))
}

fn tolerance(t: Option<f64>) -> Result<f64, Error> {
    match t {
        None => Ok(0.0),
        Some(t) if t.is_finite() && (0.0..1.0).contains(&t) => Ok(t),
        Some(t) => Err(Error::Usage(format!(
            "--tolerance {t}: must be a fraction in [0, 1), e.g. 1e-12"
        ))),
    }
}

/// A complete recording: one without its footer was cut off while being written (the process
/// killed, the file truncated), and its last chunks are lost.
fn complete_recording(path: &Path) -> anyhow::Result<RecordingInfo> {
    let info = read_recording(path)?;
    if !info.has_footer {
        return Err(Error::Usage(format!(
            "{}: truncated: {}, so its last data are lost; `physlab inspect` shows what it holds",
            path.display(),
            info.why_no_footer
        ))
        .into());
    }
    Ok(info)
}

/// A complete recording made by physlab (`diff` and `reproduce` compare nothing else).
fn physlab_made(path: &Path) -> anyhow::Result<RecordingInfo> {
    let info = complete_recording(path)?;
    if !info.application_id.starts_with("physlab") {
        return Err(Error::Usage(format!(
            "{}: a recording of another application ({:?}), not of physlab",
            path.display(),
            info.application_id
        ))
        .into());
    }
    Ok(info)
}

/// A physlab recording of simulated scenes, with what is needed to run it again.
fn physlab_recording(path: &Path) -> anyhow::Result<RecordingInfo> {
    let info = physlab_made(path)?;
    if !info.properties.contains_key("config") {
        return Err(Error::Usage(format!(
            "{}: holds no physlab configuration (recorded by a physlab older than its provenance)",
            path.display()
        ))
        .into());
    }
    Ok(info)
}

fn version_line(info: &RecordingInfo) -> String {
    let p = |k: &str| {
        info.properties
            .get(k)
            .map(String::as_str)
            .unwrap_or("(not recorded)")
    };
    format!(
        "physlab {} (commit {}), Rerun SDK {}",
        p("physlab_version"),
        p("git_commit"),
        p("rerun_sdk_version")
    )
}

fn this_version() -> String {
    format!(
        "physlab {} (commit {}), Rerun SDK {}",
        env!("CARGO_PKG_VERSION"),
        crate::record::GIT_COMMIT,
        crate::record::RERUN_SDK_VERSION
    )
}

/// Checks `-o` before any work (`crate::output`): never one of the inputs.
fn check_output(
    output: Option<&PathBuf>,
    dash: crate::output::Dash,
    inputs: &[&Path],
) -> anyhow::Result<Option<crate::output::Output>> {
    let Some(path) = output else {
        return Ok(None);
    };
    let out = crate::output::check("-o", path, dash)?;
    let inputs: Vec<(&str, &Path)> = inputs
        .iter()
        .map(|p| ("the recording being compared", *p))
        .collect();
    crate::output::distinct(&[&out], &inputs)?;
    Ok(Some(out))
}

/// Why the re-run failed, in words true to the cause: a stop request stays an interruption (exit
/// 130), a configuration this build refuses says so without the temporary file's name, and
/// anything else (an unwritable `-o`, a full disk) is passed on as it is.
fn rerun_failed(e: anyhow::Error, file: &Path, config: &Path) -> anyhow::Error {
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
            "{}: its configuration does not run with this build: {message}",
            file.display()
        ))
        .into();
    }
    e.context(format!("re-running {}", file.display()))
}

/// A file in the temporary folder, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    /// Fails with a message naming TMPDIR when the temporary folder cannot be written.
    fn new(name: &str) -> anyhow::Result<Self> {
        let dir = std::env::temp_dir();
        let path = dir.join(format!("physlab-{}-{name}", std::process::id()));
        std::fs::File::create(&path).map_err(|e| {
            anyhow::anyhow!(
                "the temporary folder {} (TMPDIR, or /tmp when unset) cannot be written: {}; \
                 set TMPDIR to a writable folder",
                dir.display(),
                crate::output::cause(&e)
            )
        })?;
        Ok(TempFile(path))
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// One line per entity of the comparison of its components.
struct EntityReport {
    entity: String,
    /// Components compared, their diffs.
    diffs: Vec<(String, SeriesDiff)>,
}

impl EntityReport {
    fn same(&self) -> bool {
        self.diffs.iter().all(|d| d.1.same())
    }
    fn bit_identical(&self) -> bool {
        self.diffs.iter().all(|d| d.1.bit_identical())
    }
    /// The component whose first difference comes first.
    fn first(&self) -> Option<&(String, SeriesDiff)> {
        self.diffs
            .iter()
            .filter(|d| d.1.first_time().is_some() || !d.1.same())
            .min_by_key(|d| d.1.first_time().flatten().unwrap_or(i64::MAX))
    }
    fn largest(&self) -> Option<(&str, &crate::record::compare::Difference, f64)> {
        self.diffs
            .iter()
            .filter_map(|(c, d)| d.largest.as_ref().map(|l| (c.as_str(), l, d.scale)))
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
    }
    fn rows(&self) -> usize {
        self.diffs.iter().map(|d| d.1.rows_a).max().unwrap_or(0)
    }

    /// `first at t = …: A x, B y; largest |Δ| …` with the given names for A and B.
    fn describe(&self, a: &str, b: &str) -> String {
        let mut out = String::new();
        if let Some((component, d)) = self.first() {
            match (&d.first, &d.first_other) {
                (Some(v), other)
                    if other
                        .as_ref()
                        .is_none_or(|o| o.0.is_none_or(|t| v.time.is_some_and(|vt| vt <= t))) =>
                {
                    let _ = write!(
                        out,
                        "first differs at {} ({component}): {a} {:e}, {b} {:e}",
                        time_text(v.time),
                        v.a,
                        v.b
                    );
                }
                (_, Some((t, what))) => {
                    let _ = write!(
                        out,
                        "first differs at {} ({component}): {what}",
                        time_text(*t)
                    );
                }
                _ => {
                    let _ = write!(
                        out,
                        "{component}: {} rows in {a}, {} in {b}, {} without a partner at the same time",
                        d.rows_a, d.rows_b, d.unpaired
                    );
                }
            }
        }
        if let Some((component, l, scale)) = self.largest()
            && l.abs() != 0.0
        {
            let _ = write!(
                out,
                "{}largest |Δ| = {:.3e} at {} ({component}: {a} {:e}, {b} {:e}; {:.2e} of the series' largest magnitude)",
                if out.is_empty() { "" } else { "; " },
                l.abs(),
                time_text(l.time),
                l.a,
                l.b,
                if scale > 0.0 {
                    l.abs() / scale
                } else {
                    f64::INFINITY
                }
            );
        }
        out
    }
}

/// Groups per-component comparisons by entity.
fn by_entity(diffs: Vec<((String, String), SeriesDiff)>) -> Vec<EntityReport> {
    let mut out: Vec<EntityReport> = Vec::new();
    for ((entity, component), d) in diffs {
        match out.last_mut() {
            Some(r) if r.entity == entity => r.diffs.push((component, d)),
            _ => out.push(EntityReport {
                entity,
                diffs: vec![(component, d)],
            }),
        }
    }
    out
}

pub fn reproduce_command(args: &ReproduceArgs) -> anyhow::Result<()> {
    let tol = tolerance(args.tolerance)?;
    check_output(
        args.output.as_ref(),
        crate::output::Dash::Refused(
            "cannot carry the re-run: it is read back and compared, and the report is printed there; \
             give a file path",
        ),
        &[&args.file],
    )?;
    let info = physlab_recording(&args.file)?;
    let scenes_property = info.properties.get("scenes").cloned().unwrap_or_default();
    if scenes_property.starts_with("study") {
        return Err(Error::Usage(format!(
            "{}: a study recording ({scenes_property}); its numbers include wall-clock timings, so \
             reproduce re-runs scene recordings only (run its command line again: {})",
            args.file.display(),
            info.properties
                .get("command_line")
                .map(String::as_str)
                .unwrap_or("?")
        ))
        .into());
    }
    let scenes: Vec<&str> = scenes_property
        .split(',')
        .filter(|s| !s.is_empty())
        .collect();
    let known: Vec<&str> = SCENES.iter().map(|s| s.name()).collect();
    if scenes.is_empty() || scenes.iter().any(|s| !known.contains(s)) {
        let expected = match known.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and/or {last}", rest.join(", ")),
            _ => known.join(""),
        };
        return Err(Error::Usage(format!(
            "{}: its provenance names the scenes {scenes_property:?}; expected {expected}",
            args.file.display()
        ))
        .into());
    }
    let timings = info
        .entities
        .iter()
        .any(|e| e.contains("/plots/frame_cost/"));

    println!("reproducing {}", args.file.display());
    let (then, now) = (version_line(&info), this_version());
    println!("  recorded by {then}");
    if then == now {
        println!("  re-run by the same build");
    } else {
        println!("  re-run by {now}  (a different build: differences may come from it)");
    }

    // Where each scene ended: the re-run stops at the same tick.
    let mut replay = Replay {
        silent: true,
        ..Replay::default()
    };
    let killed = info.run.is_empty();
    for scene in &scenes {
        let status = info.run.get(&format!("{scene}_status")).map(String::as_str);
        match status {
            Some("interrupted") => {
                let tick = info
                    .run
                    .get(&format!("{scene}_last_tick"))
                    .and_then(|t| t.parse::<u64>().ok())
                    .ok_or_else(|| {
                        Error::Usage(format!(
                            "{}: {scene} was interrupted but its last tick is not recorded",
                            args.file.display()
                        ))
                    })?;
                replay.stop_after.push((scene.to_string(), tick));
            }
            Some("not run") => replay.skip.push(scene.to_string()),
            _ => {}
        }
        if let Some(ended) = info.run.get(&format!("{scene}_ended")) {
            println!("  {scene}: {ended}");
        }
    }
    if killed {
        // No end record (an older physlab): compare each series as far as it goes.
        println!(
            "  the recording does not say where it ended: each series is compared up to its last \
             recorded row"
        );
    }

    let config = TempFile::new("reproduce.toml")?;
    std::fs::write(&config.0, &info.properties["config"]).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot write it: {}",
            config.0.display(),
            crate::output::cause(&e)
        )
    })?;
    let scratch = TempFile::new("reproduce.rrd")?;
    let output = args.output.clone().unwrap_or_else(|| scratch.0.clone());
    let run = RunArgs {
        config: Some(config.0.clone()),
        output: Some(output.clone()),
        quiet: true,
        timings,
        ..RunArgs::default()
    };
    let plan: Plan = SCENES
        .iter()
        .filter(|s| scenes.contains(&s.name()))
        .map(|s| s.flags(&AllFlags::default()))
        .collect();
    let started = Instant::now();
    simulate(plan, &run, &Output::Record, &replay)
        .map_err(|e| rerun_failed(e, &args.file, &config.0))?;
    println!("  re-ran in {:.1} s", started.elapsed().as_secs_f64());
    if args.output.is_some() {
        println!("  wrote the re-run to {}", output.display());
    }
    let skip = |entity: &str| wall_clock(entity, timings);
    let spec = StreamSpec {
        tolerance: tol,
        skip: &skip,
        rename_b: None,
        cap_b: killed,
    };
    let streamed = compare_files(&args.file, &output, &spec, &mut |_, _, _| Ok(()))?;
    let skipped: BTreeSet<&String> = streamed
        .index_a
        .keys()
        .map(|k| &k.0)
        .filter(|e| skip(e))
        .collect();
    // Static rows and timed rows of a series are compared apart; both count for its entity.
    let mut diffs = Vec::new();
    for (key, d) in streamed.statics.iter().chain(&streamed.timed) {
        if streamed.index_a.contains_key(key) {
            diffs.push((key.clone(), d.clone()));
        }
    }
    diffs.sort_by(|x, y| x.0.cmp(&y.0));
    let only_recomputed: BTreeSet<&String> = streamed
        .index_b
        .keys()
        .filter(|k| !streamed.index_a.contains_key(*k) && !skip(&k.0) && !killed)
        .map(|k| &k.0)
        .collect();
    let reports = by_entity(diffs);
    let mut differing = 0;
    let mut within = 0;
    for r in &reports {
        if r.bit_identical() {
            println!("  identical  {} ({} rows)", r.entity, r.rows());
        } else if r.same() {
            within += 1;
            println!(
                "  within tolerance  {}: {}",
                r.entity,
                r.describe("recorded", "recomputed")
            );
        } else {
            differing += 1;
            println!(
                "  DIFFERS    {}: {}",
                r.entity,
                r.describe("recorded", "recomputed")
            );
        }
    }
    for e in &only_recomputed {
        differing += 1;
        println!("  DIFFERS    {e}: only in the re-run, not in the recording");
    }
    for e in &skipped {
        println!("  skipped    {e} (wall-clock timings)");
    }
    let n = reports.len() + only_recomputed.len();
    if differing > 0 {
        let verdict = format!(
            "verdict: DIFFERS in {differing} of {n} entities{}",
            if tol > 0.0 {
                format!(" (beyond --tolerance {tol})")
            } else {
                String::new()
            }
        );
        println!("{verdict}");
        return Err(Error::Differs(format!("{}: does not reproduce", args.file.display())).into());
    }
    if within > 0 {
        println!(
            "verdict: reproduces within --tolerance {tol} ({within} of {n} entities not bit-identical)"
        );
    } else {
        println!("verdict: bit-identical ({n} entities)");
    }
    Ok(())
}

/// Each table's keys, flattened: `pendulum.dt` → its value in TOML.
fn config_keys(info: &RecordingInfo) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let Some(text) = info.properties.get("config") else {
        return out;
    };
    let Ok(table) = text.parse::<toml::Table>() else {
        return out;
    };
    fn walk(prefix: &str, v: &toml::Value, out: &mut BTreeMap<String, String>) {
        match v {
            toml::Value::Table(t) => {
                for (k, v) in t {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&key, v, out);
                }
            }
            other => {
                out.insert(prefix.to_string(), other.to_string());
            }
        }
    }
    walk("", &toml::Value::Table(table), &mut out);
    out
}

/// The one method of a recording that ran a single method (besides references).
fn single_method(info: &RecordingInfo) -> Option<String> {
    let methods = info.properties.get("methods")?;
    let list: Vec<&str> = methods.split(',').filter(|m| !m.is_empty()).collect();
    (list.len() == 1).then(|| list[0].to_string())
}

pub fn diff_command(args: &DiffArgs) -> anyhow::Result<()> {
    let tol = tolerance(args.tolerance)?;
    let output = check_output(
        args.output.as_ref(),
        crate::output::Dash::Binary,
        &[&args.a, &args.b],
    )?;
    // With `-o -` standard output carries the difference recording: the report goes to stderr.
    let to_stdout = output.as_ref().is_some_and(|o| o.is_stdout());
    let (ia, ib) = (physlab_made(&args.a)?, physlab_made(&args.b)?);
    // Runs of one method each: pair their lanes, so that Euler's series meet Verlet's.
    let rename = match (single_method(&ia), single_method(&ib)) {
        (Some(ma), Some(mb)) if ma != mb => Some((mb, ma)),
        _ => None,
    };
    let mut writer = args.output.as_deref().map(DiffWriter::create).transpose()?;
    let spec = StreamSpec {
        tolerance: tol,
        skip: &|_: &str| false,
        rename_b: rename.clone(),
        cap_b: false,
    };
    let streamed = compare_files(
        &args.a,
        &args.b,
        &spec,
        &mut |key, ra, rb| match &mut writer {
            Some(w) => w.pair(key, ra, rb),
            None => Ok(()),
        },
    )?;
    let mut report = String::new();
    let mut line = |s: String| {
        if to_stdout {
            eprintln!("{s}");
        } else {
            println!("{s}");
        }
        report.push_str(&s);
        report.push('\n');
    };
    line(format!("A: {} — {}", args.a.display(), version_line(&ia)));
    line(format!("B: {} — {}", args.b.display(), version_line(&ib)));

    // What changed between the runs, key by key.
    let (ka, kb) = (config_keys(&ia), config_keys(&ib));
    let keys: BTreeSet<&String> = ka.keys().chain(kb.keys()).collect();
    let changed: Vec<String> = keys
        .into_iter()
        .filter_map(|k| match (ka.get(k), kb.get(k)) {
            (Some(x), Some(y)) if x == y => None,
            (x, y) => Some(format!(
                "  {k}: {} → {}",
                x.map_or("(absent)", String::as_str),
                y.map_or("(absent)", String::as_str)
            )),
        })
        .collect();
    if ka.is_empty() || kb.is_empty() {
        line("configuration: not recorded in one of them".into());
    } else if changed.is_empty() {
        line("configuration: identical".into());
    } else {
        line(format!("configuration: {} keys differ", changed.len()));
        for c in changed {
            line(c);
        }
    }
    for (name, info) in [("A", &ia), ("B", &ib)] {
        for (k, v) in &info.run {
            if k.ends_with("_ended") && !v.starts_with("complete") {
                line(format!("{name}: {}: {v}", k.trim_end_matches("_ended")));
            }
        }
    }

    if let Some((mb, ma)) = &rename {
        line(format!(
            "pairing A's lane {ma} with B's lane {mb} (one method in each)"
        ));
    }

    // Series over time, and static data (summaries, styles, static 3D, study tables) compared
    // as it is: a component that differs or that only one of them holds makes its entity
    // differ (paired lanes' names and colours too: they are what the runs were told to be).
    let (xa, xb) = (&streamed.index_a, &streamed.index_b);
    let entities = |x: &BTreeMap<Key, SeriesIndex>| -> BTreeSet<String> {
        x.keys().map(|k| k.0.clone()).collect()
    };
    let (ea, eb) = (entities(xa), entities(xb));
    let shared_entity = |key: &(String, String)| ea.contains(&key.0) && eb.contains(&key.0);
    let mut static_differs: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (key, d) in &streamed.statics {
        if shared_entity(key) && !d.same() {
            let side = match (xa.get(key), xb.get(key)) {
                (Some(a), b) if b.is_none_or(|b| b.statics == 0) && a.statics > 0 => " (only in A)",
                (a, Some(b)) if a.is_none_or(|a| a.statics == 0) && b.statics > 0 => " (only in B)",
                _ => "",
            };
            static_differs
                .entry(key.0.clone())
                .or_default()
                .push(format!("{}{side}", key.1));
        }
    }
    let diffs: Vec<((String, String), SeriesDiff)> = streamed
        .timed
        .iter()
        .filter(|(k, _)| shared_entity(k))
        .map(|(k, d)| (k.clone(), d.clone()))
        .collect();
    let only_a: BTreeSet<&String> = ea.difference(&eb).collect();
    let only_b: BTreeSet<&String> = eb.difference(&ea).collect();
    let reports = by_entity(diffs.clone());
    let mut differing = 0;
    for r in &reports {
        let statics = static_differs.get(&r.entity);
        let mut text = if r.same() && statics.is_none() {
            if r.bit_identical() {
                "identical".to_string()
            } else {
                format!("within --tolerance {tol}: {}", r.describe("A", "B"))
            }
        } else if r.same() {
            differing += 1;
            String::from("series identical")
        } else {
            differing += 1;
            r.describe("A", "B")
        };
        if let Some(components) = statics {
            text.push_str(&format!(
                " (static data differs: {})",
                components.join(", ")
            ));
        }
        line(format!("  {}: {text}", r.entity));
    }
    for (entity, components) in &static_differs {
        if !reports.iter().any(|r| &r.entity == entity) {
            differing += 1;
            line(format!(
                "  {entity}: static data differs: {}",
                components.join(", ")
            ));
        }
    }
    for e in &only_a {
        line(format!("  only in A: {e}"));
    }
    for e in &only_b {
        line(format!("  only in B: {e}"));
    }
    line(format!(
        "{} of {} shared entities differ{}; {} only in A, {} only in B",
        differing,
        ea.intersection(&eb).count(),
        if tol > 0.0 {
            format!(" beyond --tolerance {tol}")
        } else {
            String::new()
        },
        only_a.len(),
        only_b.len()
    ));
    if let (Some(w), Some(out)) = (writer, &args.output) {
        let n = w.finish(&report)?;
        let wrote = format!("wrote {} difference series (B − A) to {}", n, out.display());
        if to_stdout {
            eprintln!("{wrote}");
        } else {
            println!("{wrote}");
        }
    }
    if differing > 0 || !only_a.is_empty() || !only_b.is_empty() {
        return Err(Error::Differs("the recordings differ".into()).into());
    }
    Ok(())
}
