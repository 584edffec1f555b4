//! `physlab diff A.rrd B.rrd`: compares two recordings, configuration first, then every series.
//! The report says the verdict first, then only what differs: the configuration keys that
//! changed, the rows one run has at times the other lacks (a changed step) as one line, and one
//! line per group of entities (a quantity or a drawing over its methods) from the earliest
//! parting on; `-v` lists every entity.

use std::collections::{BTreeMap, BTreeSet};

use super::Error;
use super::SceneFile;
use super::compared::{
    EntityLine, by_entity, check_output, config_keys, difference_lines, lane_names, physlab_made,
    single_method, tolerance, version_line,
};
use super::scenes::{AllFlags, SCENES};
use crate::cli::{DiffArgs, RunArgs};
use crate::record::Framing;
use crate::record::diff::{DiffPlan, DiffWriter};
use crate::rrd::compare::{Key, SeriesIndex, StreamSpec, compare_files, renamed};
use crate::rrd::inspect::RecordingInfo;

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
    let lanes = lane_names(&[&ia, &ib]);
    let renamed_b: BTreeSet<String> = ib.entities.iter().map(|e| renamed(e, &rename)).collect();
    let views: Vec<_> = SCENES.iter().map(|s| s.views).collect();
    let plan = DiffPlan {
        shared: ia.entities.intersection(&renamed_b).cloned().collect(),
        lanes: &lanes,
        scenes: &views,
        paired: rename.clone(),
        framings: framings(&ia),
        end_time: [&ia, &ib]
            .iter()
            .filter_map(|i| i.time_range.map(|(_, end)| end))
            .fold(0.0, f64::max),
    };
    let mut writer = args
        .output
        .as_deref()
        .map(|o| DiffWriter::create(o, &plan, &args.a, &args.b))
        .transpose()?;
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

    // What changed between the runs, key by key.
    let (ka, kb) = (config_keys(&ia), config_keys(&ib));
    let keys: BTreeSet<&String> = ka.keys().chain(kb.keys()).collect();
    let changed: Vec<String> = keys
        .into_iter()
        .filter_map(|k| match (ka.get(k), kb.get(k)) {
            (Some(x), Some(y)) if x == y => None,
            (x, y) => Some(format!(
                "{k}: {} → {}",
                x.map_or("(absent)", String::as_str),
                y.map_or("(absent)", String::as_str)
            )),
        })
        .collect();

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
    let diffs: Vec<_> = streamed
        .timed
        .iter()
        .filter(|(k, _)| shared_entity(k))
        .map(|(k, d)| (k.clone(), d.clone()))
        .collect();
    let only_a: BTreeSet<&String> = ea.difference(&eb).collect();
    let only_b: BTreeSet<&String> = eb.difference(&ea).collect();
    let reports = by_entity(diffs);

    // Per entity: whether it differs, its text, when it first parts.
    let mut entries: Vec<EntityLine> = Vec::new();
    // Entities that differ only by rows at times the other lacks, and those that also do.
    let (mut only_times, mut with_times) = (0usize, 0usize);
    let mut times_example: Option<(usize, String)> = None;
    for r in &reports {
        let statics = static_differs.get(&r.entity);
        let unpaired = r.unpaired() > 0;
        if unpaired {
            if r.values_differ() || statics.is_some() {
                with_times += 1;
            } else {
                only_times += 1;
            }
            // The entity whose row counts differ most shows what changed.
            let rows = r.diffs.iter().map(|d| (d.1.rows_a, d.1.rows_b)).max();
            if let Some((a, b)) = rows
                && times_example.as_ref().is_none_or(|e| a.abs_diff(b) > e.0)
            {
                times_example = Some((a.abs_diff(b), format!("{}: A {a}, B {b} rows", r.entity)));
            }
        }
        let differs = !r.same() || statics.is_some();
        let mut text = if !differs {
            if r.bit_identical() {
                "identical".to_string()
            } else {
                format!("within --tolerance {tol}: {}", r.describe("A", "B"))
            }
        } else if r.values_differ() || (!unpaired && !r.same()) {
            r.describe("A", "B")
        } else if unpaired {
            "differs only by rows at times the other lacks".to_string()
        } else {
            "series identical".to_string()
        };
        if let Some(components) = statics {
            text.push_str(&format!(
                " (static data differs: {})",
                components.join(", ")
            ));
        }
        entries.push(EntityLine {
            entity: r.entity.clone(),
            differs,
            text,
            first: r.first_time(),
        });
    }
    for (entity, components) in &static_differs {
        if !reports.iter().any(|r| &r.entity == entity) {
            let text = format!("static data differs: {}", components.join(", "));
            // After the series' partings: static data (summaries, about texts) follows from them.
            entries.push(EntityLine {
                entity: entity.clone(),
                differs: true,
                text,
                first: i64::MAX,
            });
        }
    }
    let differing = entries.iter().filter(|e| e.differs).count();
    let identical = ea.intersection(&eb).count() - differing;
    let shared = ea.intersection(&eb).count();

    let mut report = String::new();
    let mut line = |s: String| {
        let s = s + "\n";
        crate::output::print_beside(to_stdout, &s);
        report.push_str(&s);
    };
    let beyond = if tol > 0.0 {
        format!(" beyond --tolerance {tol}")
    } else {
        String::new()
    };
    let same = differing == 0 && only_a.is_empty() && only_b.is_empty();
    line(format!(
        "verdict: {}: {differing} of {shared} shared entities differ{beyond}; {} only in A, {} only in B",
        if same { "the same" } else { "they differ" },
        only_a.len(),
        only_b.len()
    ));
    if ka.is_empty() || kb.is_empty() {
        line("configuration: not recorded in one of them".into());
    } else if changed.is_empty() {
        line("configuration: identical".into());
    } else if changed.len() == 1 {
        line(format!("configuration: {}", changed[0]));
    } else {
        line(format!("configuration: {} keys differ", changed.len()));
        for c in &changed {
            line(format!("  {c}"));
        }
    }
    let (va, vb) = (version_line(&ia), version_line(&ib));
    if va == vb && !args.verbose {
        line(format!("built by: {va}, both"));
    } else {
        line(format!("A: {} — {va}", args.a.display()));
        line(format!("B: {} — {vb}", args.b.display()));
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
    if let Some((_, example)) = &times_example {
        line(format!(
            "times: {} entities hold rows at times the other lacks (e.g. {example}); values are \
             compared where both have a row{}",
            only_times + with_times,
            if only_times > 0 {
                format!(", and {only_times} differ by nothing else")
            } else {
                String::new()
            }
        ));
    }
    let shown: Vec<EntityLine> = entries
        .iter()
        .filter(|e| args.verbose || e.differs)
        .cloned()
        .collect();
    for l in difference_lines(&shown, &lanes, args.verbose) {
        line(l);
    }
    for e in &only_a {
        line(format!("  only in A: {e}"));
    }
    for e in &only_b {
        line(format!("  only in B: {e}"));
    }
    if !args.verbose && identical > 0 {
        line(format!(
            "identical: {} (-v lists them)",
            entities_text(identical)
        ));
    }
    if let (Some(w), Some(out)) = (writer, &args.output) {
        let n = w.finish(&report)?;
        let wrote = format!(
            "wrote {} ({n} series: B − A per plotted quantity, both runs' 3D overlaid)\n",
            out.display()
        );
        crate::output::print_beside(to_stdout, &wrote);
    }
    if !same {
        return Err(Error::Differs("the recordings differ".into()).into());
    }
    Ok(())
}

/// "1 entity", "3 entities".
pub(super) fn entities_text(n: usize) -> String {
    if n == 1 {
        "1 entity".into()
    } else {
        format!("{n} entities")
    }
}

/// Each scene's 3D framing as the recording's configuration draws it (none when it holds no
/// configuration this build runs).
fn framings(info: &RecordingInfo) -> Vec<(&'static str, Framing)> {
    let Some(text) = info.properties.get("config") else {
        return Vec::new();
    };
    let names: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
    let Ok(file) = SceneFile::parse(text, &names) else {
        return Vec::new();
    };
    SCENES
        .iter()
        .filter(|s| file.table(s.name).is_some())
        .filter_map(|s| {
            let ready = s.flags(&AllFlags::default());
            let ready = ready.resolve(&file, &RunArgs::default()).ok()?;
            // One overlay view per scene: the box around every lane's slot.
            let framing = ready
                .staging()
                .slots
                .iter()
                .map(|slot| slot.framing)
                .reduce(Framing::union)?;
            Some((s.name, framing))
        })
        .collect()
}
