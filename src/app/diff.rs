//! `physlab diff A.rrd B.rrd`: compares two recordings, configuration first, then every series.

use std::collections::{BTreeMap, BTreeSet};

use super::Error;
use super::compared::{
    by_entity, check_output, config_keys, physlab_made, single_method, tolerance, version_line,
};
use crate::cli::DiffArgs;
use crate::record::compare::{Key, SeriesDiff, SeriesIndex, StreamSpec, compare_files};
use crate::record::diff::DiffWriter;

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
        let s = s + "\n";
        crate::output::print_beside(to_stdout, &s);
        report.push_str(&s);
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
        let wrote = format!("wrote {n} difference series (B − A) to {}\n", out.display());
        crate::output::print_beside(to_stdout, &wrote);
    }
    if differing > 0 || !only_a.is_empty() || !only_b.is_empty() {
        return Err(Error::Differs("the recordings differ".into()).into());
    }
    Ok(())
}
