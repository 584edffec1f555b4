//! `physlab inspect`: prints what a recording holds; with --config-out, writes its embedded
//! scene file.

use std::path::Path;

use super::compared::{print_lines, remake_commands, scene_command, version_line};
use crate::cli::InspectArgs;
use crate::error::Error;
use crate::rrd::inspect::{LoggedEvent, RecordingInfo, read_recording};
use crate::shell::escaped;

pub fn inspect_command(args: &InspectArgs) -> anyhow::Result<()> {
    use crate::output::{Dash, check, distinct};
    let info = read_recording(&args.file)?;
    let config = info.properties.get("config");
    // The recording refused first: no folder is made for a scene file that cannot be written.
    if args.config_out.is_some() && config.is_none() {
        return Err(Error::Usage(format!(
            "{}: holds no physlab config to write",
            args.file.display()
        ))
        .into());
    }
    // Never the recording itself; `-` is standard output, and the report then goes to stderr.
    let config_out = args
        .config_out
        .as_deref()
        .map(|p| check("--config-out", p, Dash::Text))
        .transpose()?;
    if let Some(o) = &config_out {
        distinct(&[o], &[("the recording inspected", &args.file)])?;
    }
    let to_stderr = config_out.as_ref().is_some_and(|o| o.is_stdout());
    let scene_file = args
        .config_out
        .clone()
        .filter(|o| o.as_os_str() != "-")
        .unwrap_or_else(|| "scene.toml".into());
    print_lines(&described(&info, &args.file, &scene_file), to_stderr);
    if let (Some(out), Some(config)) = (&config_out, config) {
        out.write(config.as_bytes())?;
        if !out.is_stdout() {
            // Only a command that runs (a study's scene file has none of its own).
            let run = scene_command(&info, &out.given)
                .map_or(String::new(), |run| format!(" (run it again with: {run})"));
            let wrote = format!("wrote the scene file to {}{run}", out.given.display());
            print_lines(&[wrote], true);
        }
    }
    Ok(())
}

fn described(info: &RecordingInfo, file: &Path, scene_file: &Path) -> Vec<String> {
    let p = |k| info.property(k);
    let mut out = vec![format!("recording: {}", crate::shell::shown(file))];
    let what = match p("scenes") {
        "diff" => format!(" (a diff recording of {} and {})", p("diff_a"), p("diff_b")),
        _ => String::new(),
    };
    if info.application_id.starts_with("physlab") {
        out.push(format!("  written by: {}{what}", version_line(info)));
    } else if info.application_id.is_empty() {
        out.push("  written by: (no recorded data: a viewer layout, its blueprint, alone)".into());
    } else {
        out.push(format!(
            "  written by: \"{}\", another application than physlab (no physlab provenance)",
            escaped(&info.application_id)
        ));
    }
    out.push(format!("  command line: {}", p("command_line")));
    if let Some(again) = remake_commands(info, file, scene_file) {
        out.push(format!("  made again by: {again}"));
    }
    let scenes: Vec<String> = info.scenes().into_iter().collect();
    out.push(format!("  scenes: {}", scenes.join(", ")));
    if p("scenes") != "diff" {
        out.push(format!("  methods: {}", p("methods")));
    }
    out.push(match info.time_range {
        Some((a, b)) => format!("  sim_time: {a:.6} s to {b:.6} s"),
        None => "  sim_time: (no timed data)".into(),
    });
    out.push(if info.has_footer {
        format!("  {} chunks, footer written", info.chunks)
    } else {
        format!(
            "  {} chunks, no footer: {}",
            info.chunks, info.why_no_footer
        )
    });
    if let Some(why) = &info.headless {
        out.push(format!("  not a whole recording: {why}"));
    }
    let study = p("scenes").starts_with("study");
    if info.run.is_empty() && info.properties.contains_key("config") && !study {
        out.push("  ended: (not recorded: killed before the end, or an older physlab)".into());
    }
    for scene in info.scenes() {
        if let Some(ended) = info.run.get(&format!("{scene}_ended")) {
            out.push(format!("  {scene}: {ended}"));
        }
    }
    let warnings: Vec<&LoggedEvent> = (info.events.iter())
        .filter(|e| e.level == "WARN" || e.level == "ERROR")
        .collect();
    out.push(format!("  warnings ({}):", warnings.len()));
    for e in &warnings {
        out.push(format!("    t = {:.6} s  {}  {}", e.time, e.entity, e.text));
    }
    out.push(format!("  entities ({}):", info.entities.len()));
    out.extend(info.entities.iter().map(|e| format!("    {e}")));
    if p("scenes") == "diff" {
        out.push("  config: none (a diff recording compares two runs; each holds its own)".into());
    } else {
        out.push("  config:".into());
        out.extend(p("config").lines().map(|l| format!("    {l}")));
    }
    out
}
