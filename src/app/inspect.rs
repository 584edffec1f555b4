//! `physlab inspect`: prints what a recording holds; with --config-out, writes its embedded
//! scene file.

use crate::cli::InspectArgs;
use crate::error::Error;
use crate::record::inspect::{LoggedEvent, read_recording};

pub fn inspect_command(args: &InspectArgs) -> anyhow::Result<()> {
    let info = read_recording(&args.file)?;
    let p = |k: &str| {
        info.properties
            .get(k)
            .map(String::as_str)
            .unwrap_or("(not recorded)")
    };
    println!("recording: {}", args.file.display());
    println!(
        "  written by: physlab {} (commit {}), Rerun SDK {}",
        p("physlab_version"),
        p("git_commit"),
        p("rerun_sdk_version")
    );
    println!("  command line: {}", p("command_line"));
    println!(
        "  scenes: {}",
        info.scenes().into_iter().collect::<Vec<_>>().join(", ")
    );
    println!("  methods: {}", p("methods"));
    match info.time_range {
        Some((a, b)) => println!("  sim_time: {a:.6} s to {b:.6} s"),
        None => println!("  sim_time: (no timed data)"),
    }
    println!(
        "  {} chunks, {}",
        info.chunks,
        if info.has_footer {
            "footer written"
        } else {
            "no footer: the process was killed or the file truncated"
        }
    );
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
    println!("  config:");
    for line in p("config").lines() {
        println!("    {line}");
    }
    if let Some(out) = &args.config_out {
        let config = info.properties.get("config").ok_or_else(|| {
            Error::Usage(format!(
                "{}: holds no physlab config to write",
                args.file.display()
            ))
        })?;
        std::fs::write(out, config)
            .map_err(|e| anyhow::anyhow!("--config-out {}: cannot write it: {e}", out.display()))?;
        eprintln!(
            "wrote the scene file to {} (run it again with --config {})",
            out.display(),
            out.display()
        );
    }
    Ok(())
}
