//! `physlab diff A.rrd B.rrd`: compares two recordings, configuration first, then every series.
//! The report says the verdict first, then only what differs (`-v`: every entity).

use std::collections::{BTreeMap, BTreeSet};

use super::Error;
use super::compared::{
    EntityLine, beyond, by_entity, check_output, config_keys, difference_lines, identical_line,
    lane_names, physlab_made, print_lines, single_method, tolerance, version_line,
};
use super::scenes::{SCENES, parse_scene_file};
use crate::cli::DiffArgs;
use crate::output::Dash;
use crate::record::Framing;
use crate::record::diff::{DiffPlan, DiffWriter};
use crate::rrd::compare::{Key, SeriesIndex, StreamSpec, Streamed, compare_files, renamed};
use crate::rrd::inspect::RecordingInfo;
use crate::shell::escaped;

pub fn diff_command(args: &DiffArgs) -> anyhow::Result<()> {
    let tol = tolerance(args.tolerance)?;
    // The inputs refused first: no folder is made for a difference that will not be written.
    let (ia, ib) = (physlab_made(&args.a)?, physlab_made(&args.b)?);
    let output = check_output(args.output.as_ref(), Dash::Binary, &[&args.a, &args.b])?;
    // With `-o -` standard output carries the difference recording: the report goes to stderr.
    let to_stdout = output.as_ref().is_some_and(|o| o.is_stdout());
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
    let create = |o| DiffWriter::create(o, &plan, &args.a, &args.b);
    let mut writer = args.output.as_deref().map(create).transpose()?;
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
    let differences = Differences::new(&streamed, tol);
    if differences.is_empty() {
        return Err(Error::Usage(format!(
            "{} and {}: hold no data to compare (configurations alone), so nothing can be said \
             the same",
            args.a.display(),
            args.b.display()
        ))
        .into());
    }
    let lines = differences.lines(args, [&ia, &ib], &rename, &lanes);
    print_lines(&lines, to_stdout);
    if let (Some(w), Some(out)) = (writer, &args.output) {
        let report: String = lines.iter().map(|l| format!("{}\n", escaped(l))).collect();
        let n = w.finish(&report)?;
        print_lines(
            &[format!(
                "wrote {} ({n} series: B − A per plotted quantity, both runs' 3D overlaid)",
                crate::shell::shown(out)
            )],
            to_stdout,
        );
    }
    if !differences.same() {
        return Err(Error::Differs("the recordings differ".into()).into());
    }
    Ok(())
}

/// What differs between two recordings, entity by entity: computed in one place
/// ([`Differences::new`]), then printed ([`Differences::lines`]).
struct Differences {
    tolerance: f64,
    /// Per shared entity: whether it differs, what is said of it, when it first parts.
    entries: Vec<EntityLine>,
    only_a: BTreeSet<String>,
    only_b: BTreeSet<String>,
    shared: usize,
    /// Entities whose rows are at times the other lacks and that differ by nothing else, those
    /// that also differ otherwise, and the one whose row counts differ most.
    only_times: usize,
    with_times: usize,
    times_example: Option<(usize, String)>,
}

impl Differences {
    fn new(streamed: &Streamed, tol: f64) -> Self {
        // Static data (summaries, styles, static 3D, study tables) that differs or that only
        // one of them holds makes its entity differ (paired lanes' names and colours too: they
        // are what the runs were told to be).
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
                    (Some(a), b) if b.is_none_or(|b| b.statics == 0) && a.statics > 0 => {
                        " (only in A)"
                    }
                    (a, Some(b)) if a.is_none_or(|a| a.statics == 0) && b.statics > 0 => {
                        " (only in B)"
                    }
                    _ => "",
                };
                static_differs
                    .entry(key.0.clone())
                    .or_default()
                    .push(format!("{}{side}", key.1));
            }
        }
        let diffs: Vec<_> = (streamed.timed.iter())
            .filter(|(k, _)| shared_entity(k))
            .map(|(k, d)| (k.clone(), d.clone()))
            .collect();
        let mut out = Differences {
            tolerance: tol,
            entries: Vec::new(),
            only_a: ea.difference(&eb).cloned().collect(),
            only_b: eb.difference(&ea).cloned().collect(),
            shared: ea.intersection(&eb).count(),
            only_times: 0,
            with_times: 0,
            times_example: None,
        };
        out.add_series(by_entity(diffs), &static_differs);
        out
    }

    fn add_series(
        &mut self,
        reports: Vec<super::compared::EntityReport>,
        static_differs: &BTreeMap<String, Vec<String>>,
    ) {
        let tol = self.tolerance;
        for r in &reports {
            let statics = static_differs.get(&r.entity);
            let unpaired = r.unpaired() > 0;
            if unpaired {
                if r.values_differ() || statics.is_some() {
                    self.with_times += 1;
                } else {
                    self.only_times += 1;
                }
                // The entity whose row counts differ most shows what changed.
                let rows = r.diffs.iter().map(|d| (d.1.rows_a, d.1.rows_b)).max();
                if let Some((a, b)) = rows
                    && (self.times_example.as_ref()).is_none_or(|e| a.abs_diff(b) > e.0)
                {
                    let example = format!("{}: A {a}, B {b} rows", r.entity);
                    self.times_example = Some((a.abs_diff(b), example));
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
            self.entries.push(EntityLine {
                entity: r.entity.clone(),
                differs,
                text,
                first: r.first_time(),
            });
        }
        for (entity, components) in static_differs {
            if !reports.iter().any(|r| &r.entity == entity) {
                // After the series' partings: static data follows from them.
                self.entries.push(EntityLine {
                    entity: entity.clone(),
                    differs: true,
                    text: format!("static data differs: {}", components.join(", ")),
                    first: i64::MAX,
                });
            }
        }
    }

    fn differing(&self) -> usize {
        self.entries.iter().filter(|e| e.differs).count()
    }

    fn is_empty(&self) -> bool {
        self.shared == 0 && self.only_a.is_empty() && self.only_b.is_empty()
    }

    fn same(&self) -> bool {
        self.differing() == 0 && self.only_a.is_empty() && self.only_b.is_empty()
    }

    /// The report: the verdict, what changed between the runs, then what differs.
    fn lines(
        &self,
        args: &DiffArgs,
        [ia, ib]: [&RecordingInfo; 2],
        rename: &Option<(String, String)>,
        lanes: &BTreeSet<String>,
    ) -> Vec<String> {
        let differing = self.differing();
        let beyond = beyond(self.tolerance).map_or(String::new(), |b| format!(" {b}"));
        let mut out = vec![format!(
            "verdict: {}: {differing} of {} shared entities differ{beyond}; {} only in A, {} only in B",
            if self.same() {
                "the same"
            } else {
                "they differ"
            },
            self.shared,
            self.only_a.len(),
            self.only_b.len()
        )];
        out.extend(outcome_lines(ia, ib, rename));
        out.extend(configuration_lines(ia, ib));
        let (va, vb) = (version_line(ia), version_line(ib));
        if va == vb && !args.verbose {
            out.push(format!("built by: {va}, both"));
        } else {
            out.push(format!("A: {} — {va}", args.a.display()));
            out.push(format!("B: {} — {vb}", args.b.display()));
        }
        for (name, info) in [("A", ia), ("B", ib)] {
            for (k, v) in &info.run {
                if k.ends_with("_ended") && !v.starts_with("complete") {
                    out.push(format!("{name}: {}: {v}", k.trim_end_matches("_ended")));
                }
            }
        }
        if let Some((mb, ma)) = rename {
            out.push(format!(
                "pairing A's lane {ma} with B's lane {mb} (one method in each)"
            ));
        }
        if let Some((_, example)) = &self.times_example {
            let only = if self.only_times > 0 {
                format!(", and {} differ by nothing else", self.only_times)
            } else {
                String::new()
            };
            out.push(format!(
                "times: {} entities hold rows at times the other lacks (e.g. {example}); values \
                 are compared where both have a row{only}",
                self.only_times + self.with_times,
            ));
        }
        let shown = (self.entries.iter()).filter(|e| args.verbose || e.differs);
        out.extend(difference_lines(shown, lanes, args.verbose));
        out.extend(self.only_a.iter().map(|e| format!("  only in A: {e}")));
        out.extend(self.only_b.iter().map(|e| format!("  only in B: {e}")));
        out.extend(identical_line(self.shared - differing, args.verbose));
        out
    }
}

/// The lanes whose outcome differs, first of all: `  pendulum midpoint: diverged at t = 7.444 s
/// in A, completed in B`.
fn outcome_lines(
    ia: &RecordingInfo,
    ib: &RecordingInfo,
    rename: &Option<(String, String)>,
) -> Vec<String> {
    let (a, b) = (outcomes(ia, &None), outcomes(ib, rename));
    (a.iter())
        .filter_map(|(lane, x)| match b.get(lane) {
            Some(y) if x != y => Some(format!("  {lane}: {x} in A, {y} in B")),
            _ => None,
        })
        .collect()
}

/// How each lane of each scene ended (`scene lane` → `diverged at t = 7.444 s`, `stopped at t =
/// 3 s`, `completed`), from the run properties. B's lanes are named as paired with A's.
fn outcomes(info: &RecordingInfo, rename: &Option<(String, String)>) -> BTreeMap<String, String> {
    let methods = info.properties.get("methods").map_or("", String::as_str);
    let mut out = BTreeMap::new();
    for scene in SCENES.iter().map(|s| s.name) {
        let run = |k: &str| info.run.get(&format!("{scene}_{k}")).map(String::as_str);
        let (Some(status), ended) = (run("status"), run("ended").unwrap_or_default()) else {
            continue;
        };
        let whole = match status {
            "interrupted" => format!("stopped at t = {} s", run("end_time").unwrap_or("?")),
            _ => "completed".to_string(),
        };
        for lane in methods.split(',').filter(|m| !m.is_empty()) {
            let diverged = ended.split("; ").find_map(|part| {
                let at = part.strip_prefix(&format!("{lane} stopped at t = "))?;
                Some(format!(
                    "diverged at t = {} s",
                    at.split_once(" s (tick")?.0
                ))
            });
            let lane = renamed(lane, rename);
            out.insert(format!("{scene} {lane}"), diverged.unwrap_or(whole.clone()));
        }
    }
    out
}

fn configuration_lines(ia: &RecordingInfo, ib: &RecordingInfo) -> Vec<String> {
    let (ka, kb) = (config_keys(ia), config_keys(ib));
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
    if ka.is_empty() || kb.is_empty() {
        vec!["configuration: not recorded in one of them".into()]
    } else if changed.is_empty() {
        vec!["configuration: identical".into()]
    } else if let [one] = &changed[..] {
        vec![format!("configuration: {one}")]
    } else {
        let mut out = vec![format!("configuration: {} keys differ", changed.len())];
        out.extend(changed.iter().map(|c| format!("  {c}")));
        out
    }
}

fn framings(info: &RecordingInfo) -> Vec<(&'static str, Framing)> {
    let Some(Ok(file)) = (info.properties.get("config")).map(|t| parse_scene_file(t)) else {
        return Vec::new();
    };
    SCENES
        .iter()
        .filter(|s| file.table(s.name).is_some())
        .filter_map(|s| {
            let ready = s.as_recorded(&file).ok()?;
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
