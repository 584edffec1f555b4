//! `physlab reproduce FILE.rrd`: re-runs what a recording holds from its embedded configuration
//! and compares every logged value with it.

use std::collections::BTreeSet;
use std::path::Path;
use std::time::Instant;

use super::compared::{
    EntityLine, by_entity, check_output, difference_lines, lane_names, physlab_made,
    physlab_recording, recorded_command, recorded_timings, tolerance, version_line, version_text,
    wall_clock,
};
use super::diff::entities_text;
use super::scenes::{AllFlags, SCENES};
use super::{Error, Plan, Replay, simulate};
use crate::cli::{ReproduceArgs, RunArgs};
use crate::output::TempFile;
use crate::rrd::compare::{StreamSpec, compare_files};

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
    let info = physlab_made(&args.file)?;
    let scenes_property = info.properties.get("scenes").cloned().unwrap_or_default();
    if scenes_property == "diff" {
        return Err(Error::Usage(format!(
            "{}: a diff recording (of {} and {}), not a run; write it again with: {}",
            args.file.display(),
            info.properties.get("diff_a").map_or("?", String::as_str),
            info.properties.get("diff_b").map_or("?", String::as_str),
            recorded_command(&info).unwrap_or_else(|| "physlab diff A.rrd B.rrd -o D.rrd".into())
        ))
        .into());
    }
    let info = physlab_recording(&args.file)?;
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
    let known: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
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
    let timings = recorded_timings(&info);

    // Said before the re-run (which takes the run's time); the report comes after it, verdict
    // first.
    eprintln!("re-running {} …", args.file.display());
    let mut header: Vec<String> = Vec::new();
    let now = version_text(
        env!("CARGO_PKG_VERSION"),
        crate::record::GIT_COMMIT,
        crate::record::RERUN_SDK_VERSION,
    );
    let then = version_line(&info);
    if then == now {
        header.push(format!("recorded and re-run by the same build: {then}"));
    } else {
        header.push(format!("recorded by {then}"));
        header.push(format!(
            "re-run by {now}  (a different build: differences may come from it)"
        ));
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
            header.push(format!("{scene}: {ended}"));
        }
    }
    if killed {
        // No end record (an older physlab): compare each series as far as it goes.
        header.push(
            "the recording does not say where it ended: each series is compared up to its last \
             recorded row"
                .into(),
        );
    }

    let config = TempFile::create("reproduce.toml", info.properties["config"].as_bytes())?;
    let scratch = TempFile::create("reproduce.rrd", b"")?;
    let output = args.output.clone().unwrap_or_else(|| scratch.path().into());
    let run = RunArgs {
        config: Some(config.path().into()),
        output: Some(output.clone()),
        quiet: true,
        timings,
        ..RunArgs::default()
    };
    let plan: Plan = SCENES
        .iter()
        .filter(|s| scenes.contains(&s.name))
        .map(|s| s.flags(&AllFlags::default()))
        .collect();
    let started = Instant::now();
    simulate(plan, &run, None, &replay).map_err(|e| rerun_failed(e, &args.file, config.path()))?;
    header.push(format!(
        "re-ran in {:.1} s",
        started.elapsed().as_secs_f64()
    ));
    if args.output.is_some() {
        header.push(format!("wrote the re-run to {}", output.display()));
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
    let (mut differing, mut within) = (0, 0);
    // Per entity: whether it differs, its text, when it first parts.
    let mut entries: Vec<EntityLine> = Vec::new();
    for r in &reports {
        let text = if r.bit_identical() {
            format!("identical ({} rows)", r.rows())
        } else if r.same() {
            within += 1;
            format!("within tolerance: {}", r.describe("recorded", "recomputed"))
        } else {
            differing += 1;
            format!("DIFFERS: {}", r.describe("recorded", "recomputed"))
        };
        entries.push(EntityLine {
            entity: r.entity.clone(),
            differs: !r.same(),
            text,
            first: r.first_time(),
        });
    }
    for e in &only_recomputed {
        differing += 1;
        let text = "DIFFERS: only in the re-run, not in the recording".to_string();
        entries.push(EntityLine {
            entity: e.to_string(),
            differs: true,
            text,
            first: i64::MAX,
        });
    }
    let n = reports.len() + only_recomputed.len();
    let verdict = if differing > 0 {
        format!(
            "verdict: DIFFERS in {differing} of {n} entities{}",
            if tol > 0.0 {
                format!(" (beyond --tolerance {tol})")
            } else {
                String::new()
            }
        )
    } else if within > 0 {
        format!(
            "verdict: reproduces within --tolerance {tol} ({within} of {n} entities not bit-identical)"
        )
    } else {
        format!("verdict: bit-identical ({})", entities_text(n))
    };
    println!("{verdict}");
    for h in &header {
        println!("{h}");
    }
    let lanes = lane_names(&[&info]);
    let shown: Vec<_> = entries
        .iter()
        .filter(|e| args.verbose || e.differs || e.text.starts_with("within"))
        .cloned()
        .collect();
    for l in difference_lines(&shown, &lanes, args.verbose) {
        println!("{l}");
    }
    let identical = n - differing - within;
    if !args.verbose && identical > 0 {
        println!("identical: {} (-v lists them)", entities_text(identical));
    }
    if !skipped.is_empty() {
        println!(
            "skipped: {} (wall-clock timings){}",
            entities_text(skipped.len()),
            if args.verbose {
                format!(
                    ": {}",
                    skipped
                        .iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            } else {
                String::new()
            }
        );
    }
    if differing > 0 {
        return Err(Error::Differs(format!("{}: does not reproduce", args.file.display())).into());
    }
    Ok(())
}
