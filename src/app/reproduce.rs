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
use crate::record::compare::{Contents, Row, SeriesDiff, compare, read_contents, time_text};
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
fn complete_recording(path: &Path) -> Result<RecordingInfo, Error> {
    let info = read_recording(path)?;
    if !info.has_footer {
        return Err(Error::Usage(format!(
            "{}: truncated: the file ends without its footer (the writing process was killed or the              file cut short), so its last data are lost; `physlab inspect` shows what it holds",
            path.display()
        )));
    }
    Ok(info)
}

/// A physlab recording of simulated scenes, with what is needed to run it again.
fn physlab_recording(path: &Path) -> Result<RecordingInfo, Error> {
    let info = complete_recording(path)?;
    let fail = |what: &str| Error::Usage(format!("{}: {what}", path.display()));
    if !info.application_id.starts_with("physlab") {
        return Err(fail(&format!(
            "a recording of another application ({:?}), not of physlab",
            info.application_id
        )));
    }
    if !info.properties.contains_key("config") {
        return Err(fail(
            "holds no physlab configuration (recorded by a physlab older than its provenance)",
        ));
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

/// Refuses an output that is one of the inputs: writing it would replace the recording compared.
fn not_an_input(output: Option<&PathBuf>, inputs: &[&Path]) -> Result<(), Error> {
    let Some(out) = output else {
        return Ok(());
    };
    let same = |p: &Path| match (out.canonicalize(), p.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if let Some(input) = inputs.iter().find(|p| same(p)) {
        return Err(Error::Usage(format!(
            "-o {}: is the recording being compared ({}); give another path",
            out.display(),
            input.display()
        )));
    }
    Ok(())
}

/// A file in the temporary folder, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str) -> Self {
        TempFile(std::env::temp_dir().join(format!("physlab-{}-{name}", std::process::id())))
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
    not_an_input(args.output.as_ref(), &[&args.file])?;
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
    let recorded = read_contents(&args.file)?;
    let timings = recorded.keys().any(|k| k.0.contains("/plots/frame_cost/"));

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
    let mut until: BTreeMap<String, Option<i64>> = BTreeMap::new();
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
        until.insert(scene.to_string(), None);
    }
    if killed {
        // No end record (an older physlab): compare each series as far as it goes.
        println!(
            "  the recording does not say where it ended: each series is compared up to its last \
             recorded row"
        );
    }

    let config = TempFile::new("reproduce.toml");
    std::fs::write(&config.0, &info.properties["config"])?;
    let scratch = TempFile::new("reproduce.rrd");
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
    simulate(plan, &run, &Output::Record, &replay).map_err(|e| {
        anyhow::anyhow!(
            "{}: its configuration does not run with this build: {e:#}",
            args.file.display()
        )
    })?;
    println!("  re-ran in {:.1} s", started.elapsed().as_secs_f64());
    if args.output.is_some() {
        println!("  wrote the re-run to {}", output.display());
    }
    let recomputed = read_contents(&output)?;

    let mut skipped = BTreeSet::new();
    let mut diffs = Vec::new();
    for (key, rows) in &recorded {
        if wall_clock(&key.0, timings) {
            skipped.insert(key.0.clone());
            continue;
        }
        let empty: Vec<Row> = Vec::new();
        let mine = recomputed.get(key).unwrap_or(&empty);
        let mine: &[Row] = if killed {
            &mine[..mine.len().min(rows.len())]
        } else {
            mine
        };
        diffs.push((key.clone(), compare(rows, mine, tol, None)));
    }
    let only_recomputed: BTreeSet<&String> = recomputed
        .keys()
        .filter(|k| !recorded.contains_key(*k) && !wall_clock(&k.0, timings) && !killed)
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
    not_an_input(args.output.as_ref(), &[&args.a, &args.b])?;
    let (ia, ib) = (complete_recording(&args.a)?, complete_recording(&args.b)?);
    let (ca, cb) = (read_contents(&args.a)?, read_contents(&args.b)?);
    let mut report = String::new();
    let mut line = |s: String| {
        println!("{s}");
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

    // Runs of one method each: pair their lanes, so that Euler's series meet Verlet's.
    let rename = match (single_method(&ia), single_method(&ib)) {
        (Some(ma), Some(mb)) if ma != mb => {
            line(format!(
                "pairing A's lane {ma} with B's lane {mb} (one method in each)"
            ));
            Some((mb, ma))
        }
        _ => None,
    };
    let cb: Contents = match &rename {
        None => cb,
        Some((from, to)) => cb
            .into_iter()
            .map(|((entity, component), rows)| {
                let entity = entity
                    .split('/')
                    .map(|part| if part == from { to.as_str() } else { part })
                    .collect::<Vec<_>>()
                    .join("/");
                ((entity, component), rows)
            })
            .collect(),
    };

    // Series over time; static data (styles, descriptions) only noted when it differs: paired
    // lanes have their own names and colours.
    let mut diffs = Vec::new();
    let mut static_differs: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let split = |rows: &[Row]| -> (Vec<Row>, Vec<Row>) {
        rows.iter().cloned().partition(|r| r.time.is_some())
    };
    for (key, rows) in &ca {
        if let Some(other) = cb.get(key) {
            let ((ta, sa), (tb, sb)) = (split(rows), split(other));
            if sa != sb {
                static_differs
                    .entry(key.0.clone())
                    .or_default()
                    .push(key.1.clone());
            }
            if !ta.is_empty() || !tb.is_empty() {
                diffs.push((key.clone(), compare(&ta, &tb, tol, None)));
            }
        }
    }
    let only = |x: &Contents, y: &Contents| -> BTreeSet<String> {
        x.keys()
            .filter(|k| !y.keys().any(|o| o.0 == k.0))
            .map(|k| k.0.clone())
            .collect()
    };
    let (only_a, only_b) = (only(&ca, &cb), only(&cb, &ca));
    let reports = by_entity(diffs.clone());
    let mut differing = 0;
    for r in &reports {
        let mut text = if r.same() {
            if r.bit_identical() {
                "identical".to_string()
            } else {
                format!("within --tolerance {tol}: {}", r.describe("A", "B"))
            }
        } else {
            differing += 1;
            r.describe("A", "B")
        };
        if let Some(components) = static_differs.get(&r.entity) {
            text.push_str(&format!(
                " (static data differs: {})",
                components.join(", ")
            ));
        }
        line(format!("  {}: {text}", r.entity));
    }
    for (entity, components) in &static_differs {
        if !reports.iter().any(|r| &r.entity == entity) {
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
        reports.len(),
        if tol > 0.0 {
            format!(" beyond --tolerance {tol}")
        } else {
            String::new()
        },
        only_a.len(),
        only_b.len()
    ));
    if let Some(out) = &args.output {
        let n = crate::record::diff::record_diff(out, &ca, &cb, &report)?;
        println!("wrote {} difference series (B − A) to {}", n, out.display());
    }
    if differing > 0 || !only_a.is_empty() || !only_b.is_empty() {
        return Err(Error::Differs("the recordings differ".into()).into());
    }
    Ok(())
}
