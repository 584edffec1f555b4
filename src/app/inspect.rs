//! `physlab inspect`: prints what a recording holds; with --config-out, writes its embedded
//! scene file.

use crate::cli::InspectArgs;
use crate::error::Error;
use crate::rrd::inspect::{LoggedEvent, read_recording};

pub fn inspect_command(args: &InspectArgs) -> anyhow::Result<()> {
    use crate::output::{Dash, check, distinct};
    // Checked before reading: never the recording itself; `-` is standard output, and the
    // report then goes to stderr.
    let config_out = args
        .config_out
        .as_deref()
        .map(|p| check("--config-out", p, Dash::Text))
        .transpose()?;
    if let Some(o) = &config_out {
        distinct(&[o], &[("the recording inspected", &args.file)])?;
    }
    let to_stderr = config_out.as_ref().is_some_and(|o| o.is_stdout());
    macro_rules! println {
        ($($t:tt)*) => {
            if to_stderr { eprintln!($($t)*) } else { std::println!($($t)*) }
        };
    }
    let info = read_recording(&args.file)?;
    let p = |k| info.property(k);
    println!("recording: {}", args.file.display());
    let what = match p("scenes") {
        "diff" => format!(" (a diff recording of {} and {})", p("diff_a"), p("diff_b")),
        _ => String::new(),
    };
    let build = super::compared::version_line(&info);
    println!("  written by: {build}{what}");
    println!("  command line: {}", p("command_line"));
    let scene_file = args
        .config_out
        .clone()
        .filter(|o| o.as_os_str() != "-")
        .unwrap_or_else(|| "scene.toml".into());
    if let Some(again) = super::compared::remake_commands(&info, &args.file, &scene_file) {
        println!("  made again by: {again}");
    }
    println!(
        "  scenes: {}",
        info.scenes().into_iter().collect::<Vec<_>>().join(", ")
    );
    if p("scenes") != "diff" {
        println!("  methods: {}", p("methods"));
    }
    match info.time_range {
        Some((a, b)) => println!("  sim_time: {a:.6} s to {b:.6} s"),
        None => println!("  sim_time: (no timed data)"),
    }
    if info.has_footer {
        println!("  {} chunks, footer written", info.chunks);
    } else {
        println!(
            "  {} chunks, no footer: {}",
            info.chunks, info.why_no_footer
        );
    }
    let study = p("scenes").starts_with("study");
    if info.run.is_empty() && info.properties.contains_key("config") && !study {
        println!("  ended: (not recorded: killed before the end, or an older physlab)");
    }
    for scene in info.scenes() {
        if let Some(ended) = info.run.get(&format!("{scene}_ended")) {
            println!("  {scene}: {ended}");
        }
    }
    let warnings: Vec<&LoggedEvent> = info
        .events
        .iter()
        .filter(|e| e.level == "WARN" || e.level == "ERROR")
        .collect();
    println!("  warnings ({}):", warnings.len());
    for e in &warnings {
        println!("    t = {:.6} s  {}  {}", e.time, e.entity, e.text);
    }
    println!("  entities ({}):", info.entities.len());
    for e in &info.entities {
        println!("    {e}");
    }
    if p("scenes") == "diff" {
        println!("  config: none (a diff recording compares two runs; each holds its own)");
    } else {
        println!("  config:");
        for line in p("config").lines() {
            println!("    {line}");
        }
    }
    if let Some(out) = &config_out {
        let config = info.properties.get("config").ok_or_else(|| {
            Error::Usage(format!(
                "{}: holds no physlab config to write",
                args.file.display()
            ))
        })?;
        out.write(config.as_bytes())?;
        if !out.is_stdout() {
            let run = super::compared::scene_command(&info, &out.given)
                .unwrap_or_else(|| format!("--config {}", out.given.display()));
            eprintln!(
                "wrote the scene file to {} (run it again with: {run})",
                out.given.display(),
            );
        }
    }
    Ok(())
}
