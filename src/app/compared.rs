//! What `reproduce` and `diff` share: reading a recording's provenance, checking `-o` and the
//! tolerance, and reporting series differences entity by entity.

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::Error;
use super::scenes::{parse_scene_file, scene_named};
use crate::format::{sig, sig_pair};
use crate::rrd::compare::{SeriesDiff, time_text};
use crate::rrd::inspect::{RecordingInfo, read_recording};
use crate::shell::{escaped, shell_path, shell_word, shell_words};

/// Entities whose values depend on the wall clock, so that no re-run can match them: the
/// --timings plots, and with --timings the summaries (which then hold wall times, ns/step).
pub(super) fn wall_clock(entity: &str, timings: bool) -> bool {
    entity.contains("/plots/frame_cost/") || (timings && entity.ends_with("/summary"))
}

/// Whether a recording was made with --timings (it holds their plots).
pub(super) fn recorded_timings(info: &RecordingInfo) -> bool {
    info.entities.iter().any(|e| wall_clock(e, false))
}

/// `beyond --tolerance T`, when one was given.
pub(super) fn beyond(tolerance: f64) -> Option<String> {
    (tolerance > 0.0).then(|| format!("beyond --tolerance {tolerance}"))
}

pub(super) fn tolerance(t: Option<f64>) -> Result<f64, Error> {
    match t {
        None => Ok(0.0),
        Some(t) if t.is_finite() && (0.0..1.0).contains(&t) => Ok(t),
        Some(t) => Err(Error::Usage(format!(
            "--tolerance {t}: must be a fraction in [0, 1), e.g. 1e-12"
        ))),
    }
}

/// A complete recording made by physlab (`diff` and `reproduce` compare nothing else): one
/// without its footer was cut off while being written, and its last chunks are lost.
pub(super) fn physlab_made(path: &Path) -> anyhow::Result<RecordingInfo> {
    let info = read_recording(path)?;
    let refused = if !info.has_footer {
        format!(
            "truncated: {}, so its last data are lost; `physlab inspect` shows what it holds",
            info.why_no_footer
        )
    } else if let Some(why) = &info.headless {
        format!("not a whole recording: {why}; `physlab inspect` shows what it holds")
    } else if info.application_id.is_empty() {
        "holds no recorded data (a viewer layout, its blueprint, alone)".into()
    } else if !info.application_id.starts_with("physlab") {
        format!(
            "a recording of another application (\"{}\"), not of physlab",
            escaped(&info.application_id)
        )
    } else {
        return Ok(info);
    };
    Err(Error::Usage(format!("{}: {refused}", path.display())).into())
}

/// The command line a diff or study recording was made with, parsed as a physlab command of
/// the recording's kind and quoted anew; `None` when it does not parse as one. Never copied as
/// it is: a recording is a stranger's text.
pub(super) fn recorded_command(info: &RecordingInfo) -> Option<String> {
    use std::os::unix::ffi::{OsStrExt as _, OsStringExt as _};
    let kind = info.properties.get("scenes")?;
    let words = shell_words(info.properties.get("command_line")?)?;
    let mut args: Vec<OsString> = vec!["physlab".into()];
    args.extend(words.into_iter().skip(1).map(OsString::from_vec));
    let parsed = crate::cli::command()
        .try_get_matches_from(crate::cli::join_negative_values(args.clone()))
        .ok()?;
    let sub = parsed.subcommand_name()?;
    let same_kind =
        (sub == "diff" && kind == "diff") || (sub == "study" && kind.starts_with("study"));
    same_kind.then(|| {
        let quoted: Vec<String> = args.iter().map(|a| shell_word(a.as_bytes())).collect();
        quoted.join(" ")
    })
}

/// The command that runs a scene recording again on its scene file `config`; `None` unless
/// every scene it names is one and its configuration parses.
pub(super) fn scene_command(info: &RecordingInfo, config: &Path) -> Option<String> {
    let listed: Vec<&'static str> = (info.properties.get("scenes")?.split(','))
        .map(|s| scene_named(s).map(|k| k.name))
        .collect::<Option<_>>()?;
    parse_scene_file(info.properties.get("config")?).ok()?;
    let subcommand = match listed[..] {
        [one] => one,
        _ => "all",
    };
    let timings = if recorded_timings(info) {
        " --timings"
    } else {
        ""
    };
    Some(format!(
        "physlab {subcommand} --config {}{timings}",
        shell_path(config)
    ))
}

/// The commands that make a recording again: a scene run's scene file written out by `inspect
/// --config-out`, then [`scene_command`]; a diff's or a study's own command line.
pub(super) fn remake_commands(info: &RecordingInfo, file: &Path, config: &Path) -> Option<String> {
    match scene_command(info, config) {
        Some(run) => Some(format!(
            "physlab inspect {} --config-out {} && {run}",
            shell_path(file),
            shell_path(config)
        )),
        None => recorded_command(info),
    }
}

pub(super) fn version_line(info: &RecordingInfo) -> String {
    let p = |k| info.property(k);
    version_text(
        p("physlab_version"),
        p("git_commit"),
        p("rerun_sdk_version"),
    )
}

/// A build: `physlab VERSION (commit C), Rerun SDK V`.
pub(super) fn version_text(physlab: &str, commit: &str, sdk: &str) -> String {
    format!("physlab {physlab} (commit {commit}), Rerun SDK {sdk}")
}

/// Checks `-o` before any work (`crate::output`): never one of the inputs.
pub(super) fn check_output(
    output: Option<&PathBuf>,
    dash: crate::output::Dash,
    inputs: &[&Path],
) -> anyhow::Result<Option<crate::output::Output>> {
    let Some(path) = output else {
        return Ok(None);
    };
    let out = crate::output::check_recording(path, dash)?;
    let inputs: Vec<(&str, &Path)> = inputs
        .iter()
        .map(|p| ("the recording being compared", *p))
        .collect();
    crate::output::distinct(&[&out], &inputs)?;
    Ok(Some(out))
}

/// Prints a report's lines on standard output (standard error when `to_stderr`), each through
/// [`escaped`]: what a recording says reaches the terminal as text, never as its commands.
pub(super) fn print_lines(lines: &[String], to_stderr: bool) {
    for line in lines {
        crate::output::print_beside(to_stderr, &format!("{}\n", escaped(line)));
    }
}

pub(super) struct EntityReport {
    pub(super) entity: String,
    pub(super) diffs: Vec<(String, SeriesDiff)>,
}

impl EntityReport {
    pub(super) fn same(&self) -> bool {
        self.diffs.iter().all(|d| d.1.same())
    }
    pub(super) fn bit_identical(&self) -> bool {
        self.diffs.iter().all(|d| d.1.bit_identical())
    }
    /// The component whose first difference comes first.
    pub(super) fn first(&self) -> Option<&(String, SeriesDiff)> {
        self.diffs
            .iter()
            .filter(|d| d.1.first_time().is_some() || !d.1.same())
            .min_by_key(|d| d.1.first_time().flatten().unwrap_or(i64::MAX))
    }
    pub(super) fn rows(&self) -> usize {
        self.diffs.iter().map(|d| d.1.rows_a).max().unwrap_or(0)
    }

    /// Rows at times the other side lacks.
    pub(super) fn unpaired(&self) -> usize {
        self.diffs.iter().map(|d| d.1.unpaired).max().unwrap_or(0)
    }

    /// Whether its values differ where both have a row (not only rows at other times).
    pub(super) fn values_differ(&self) -> bool {
        self.diffs
            .iter()
            .any(|d| d.1.first.is_some() || d.1.first_other.is_some())
    }

    /// The first time anything differs, `i64::MAX` when no paired value does.
    pub(super) fn first_time(&self) -> i64 {
        self.first()
            .and_then(|d| d.1.first_time().flatten())
            .unwrap_or(i64::MAX)
    }

    /// `first differs at t = …: A x, B y; largest |Δ| …` with the given names for A and B, the
    /// numbers to the digits that tell them apart.
    pub(super) fn describe(&self, a: &str, b: &str) -> String {
        let mut out = match self.first() {
            None => String::new(),
            Some((component, d)) => match (&d.first, &d.first_other) {
                (Some(v), other)
                    if other
                        .as_ref()
                        .is_none_or(|o| o.0.is_none_or(|t| v.time.is_some_and(|vt| vt <= t))) =>
                {
                    let (x, y) = sig_pair(v.a, v.b);
                    format!(
                        "first differs at {} ({}): {a} {x}, {b} {y}",
                        time_text(v.time),
                        value_name(component, v.index),
                    )
                }
                (_, Some((t, what))) => {
                    format!("first differs at {} ({component}): {what}", time_text(*t))
                }
                _ => format!(
                    "{component}: {} rows in {a}, {} in {b}, {} without a partner at the same time",
                    d.rows_a, d.rows_b, d.unpaired
                ),
            },
        };
        let largest = (self.diffs.iter())
            .filter_map(|(c, d)| d.largest.as_ref().map(|l| (c.as_str(), l, d.scale)))
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()));
        if let Some((component, l, scale)) = largest
            && l.abs() != 0.0
        {
            // The component named again only when it is another than the first parting's.
            let named = value_name(component, l.index);
            let named = if out.contains(&format!("({named})")) {
                String::new()
            } else {
                format!("{named}; ")
            };
            let _ = write!(
                out,
                "{}largest |Δ| {} at {} ({named}{} of the series' largest magnitude)",
                if out.is_empty() { "" } else { "; " },
                sig(l.abs(), 2),
                time_text(l.time),
                if scale > 0.0 {
                    sig(l.abs() / scale, 2)
                } else {
                    "∞".to_string()
                }
            );
        }
        out
    }
}

/// A value of a component named for a reader: a point's coordinate as `Points3D:positions x`
/// (`of point 3` when the row holds several points), another value of several by its index.
pub(super) fn value_name(component: &str, index: usize) -> String {
    let vectors = ["positions", "strips", "vectors", "origins"]
        .iter()
        .any(|c| component.ends_with(c));
    let dim = if component.contains("3D") { 3 } else { 2 };
    if vectors {
        let axis = ["x", "y", "z"][index % dim];
        match index / dim {
            0 => format!("{component} {axis}"),
            point => format!("{component} {axis} of point {point}"),
        }
    } else if index > 0 {
        format!("{component}[{index}]")
    } else {
        component.to_string()
    }
}

/// An entity's path with every method's segment (and the references') as `*`: the entities of
/// one quantity or one drawing across methods, reported as one group.
pub(super) fn entity_group(entity: &str, methods: &BTreeSet<String>) -> String {
    entity
        .split('/')
        .map(|part| if methods.contains(part) { "*" } else { part })
        .collect::<Vec<_>>()
        .join("/")
}

/// The method names of the recordings (their `methods` properties) and the references' lanes.
pub(super) fn lane_names(infos: &[&RecordingInfo]) -> BTreeSet<String> {
    let mut names: BTreeSet<String> = ["exact", "reference"].map(String::from).into();
    for info in infos {
        if let Some(m) = info.properties.get("methods") {
            names.extend(m.split(',').filter(|m| !m.is_empty()).map(String::from));
        }
    }
    names
}

/// One entity's line of a report: whether it differs, what is said of it, when it first parts
/// (`i64::MAX` when at no time).
#[derive(Clone)]
pub(super) struct EntityLine {
    pub(super) entity: String,
    pub(super) differs: bool,
    pub(super) text: String,
    pub(super) first: i64,
}

#[derive(Default)]
struct Group {
    entities: usize,
    differing: usize,
    earliest: Option<EntityLine>,
}

/// Group lines shown without `-v`: a report stays under 15 lines.
const GROUPS_SHOWN: usize = 6;

/// The lines that say what differs: with `verbose` one per entity, else one per group of
/// entities ([`entity_group`]), the earliest parting first.
pub(super) fn difference_lines<'a>(
    entries: impl Iterator<Item = &'a EntityLine>,
    methods: &BTreeSet<String>,
    verbose: bool,
) -> Vec<String> {
    if verbose {
        return entries
            .map(|e| format!("  {}: {}", e.entity, e.text))
            .collect();
    }
    let mut groups: BTreeMap<String, Group> = BTreeMap::new();
    for e in entries {
        let g = groups.entry(entity_group(&e.entity, methods)).or_default();
        g.entities += 1;
        if e.differs {
            g.differing += 1;
            if g.earliest.as_ref().is_none_or(|x| e.first < x.first) {
                g.earliest = Some(e.clone());
            }
        }
    }
    let mut differing: Vec<(String, Group, EntityLine)> = groups
        .into_iter()
        .filter_map(|(name, mut g)| g.earliest.take().map(|e| (name, g, e)))
        .collect();
    differing.sort_by_key(|g| g.2.first);
    let mut lines: Vec<String> = differing
        .iter()
        .take(GROUPS_SHOWN)
        .map(|(name, g, e)| {
            if g.entities == 1 {
                format!("  {}: {}", e.entity, e.text)
            } else {
                let lane = e.entity.rsplit('/').find(|p| methods.contains(*p));
                let which = lane.map(|l| format!(", earliest {l}")).unwrap_or_default();
                format!(
                    "  {name} ({} of {} differ{which}): {}",
                    g.differing, g.entities, e.text
                )
            }
        })
        .collect();
    if differing.len() > GROUPS_SHOWN {
        lines.push(format!(
            "  … and {} more groups (-v lists every entity)",
            differing.len() - GROUPS_SHOWN
        ));
    }
    lines
}

/// `identical: N entities (-v lists them)`, unless none is or `verbose` listed them.
pub(super) fn identical_line(identical: usize, verbose: bool) -> Option<String> {
    let n = crate::format::plural(identical as u64, "entity");
    (!verbose && identical > 0).then(|| format!("identical: {n} (-v lists them)"))
}

pub(super) fn by_entity(diffs: Vec<((String, String), SeriesDiff)>) -> Vec<EntityReport> {
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

/// Each table's keys, flattened: `pendulum.dt` → its value in TOML.
pub(super) fn config_keys(info: &RecordingInfo) -> BTreeMap<String, String> {
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
    let mut out = BTreeMap::new();
    if let Some(Ok(table)) = info.properties.get("config").map(|t| t.parse()) {
        walk("", &toml::Value::Table(table), &mut out);
    }
    out
}

/// The one method of a recording that ran a single method (besides references).
pub(super) fn single_method(info: &RecordingInfo) -> Option<String> {
    let methods = info.properties.get("methods")?;
    let list: Vec<&str> = methods.split(',').filter(|m| !m.is_empty()).collect();
    (list.len() == 1).then(|| list[0].to_string())
}
