//! Signals in studies, bisections and worker threads: a command stopped by SIGINT or SIGTERM ends within a
//! second with exit 130, and shows or writes only what ran to the end.

#![cfg(feature = "rerun")]

mod common;

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::scratch_dir;

// ---- studies and worker threads -------------------------------------------------------------

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `signal` to `child` after `after`, and returns (exit code, seconds from the signal to
/// the exit, stdout, stderr).
fn stop(child: Child, after: Duration, signal: libc::c_int) -> (Option<i32>, f64, String, String) {
    std::thread::sleep(after);
    let sent = Instant::now();
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        sent.elapsed().as_secs_f64(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The stability bisection looks at the stop flag in every trial, however large a step is: a
/// rope of 30,000 and 100,000 nodes (one RK4 or implicit step of milliseconds) stops within a
/// second of SIGINT or SIGTERM, in the first trial and later ones. The long one says up front
/// how long it would take.
#[test]
fn study_stability_on_a_large_rope_stops_within_a_second() {
    for (nodes, method, signal, after) in [
        ("30000", "rk4", libc::SIGINT, 1500),
        ("30000", "implicit-euler", libc::SIGTERM, 1500),
        ("100000", "rk4", libc::SIGINT, 3000),
        ("100000", "verlet", libc::SIGTERM, 800),
    ] {
        let child = spawn(&[
            "study",
            "stability",
            "--scene",
            "rope",
            "--nodes",
            nodes,
            "--methods",
            method,
        ]);
        let (code, waited, stdout, stderr) = stop(child, Duration::from_millis(after), signal);
        assert_eq!(code, Some(130), "{nodes} {method}: {stderr}");
        assert!(
            waited < 1.0,
            "{nodes} {method}: {waited:.2} s after the signal"
        );
        assert!(
            stderr.contains("interrupted: 0 of 1 methods' limits complete"),
            "{stderr}"
        );
        assert!(!stdout.contains(method), "no limit shown: {stdout}");
        if nodes == "100000" {
            assert!(
                stderr.starts_with("warning: this study is") && stderr.contains("minutes"),
                "{stderr}"
            );
        }
    }
}

/// A short study says nothing about time.
#[test]
fn a_short_study_gives_no_time_warning() {
    let (code, _, stderr) = common::physlab(&["study", "stability", "--methods", "rk4"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
}

/// Stopped during `study hair`: exit 130, and the table, the CSV and the recommendations hold
/// only configurations that ran to the end (each with a measured cost), never one that did not.
#[test]
fn study_hair_stopped_shows_and_writes_only_what_ran() {
    let dir = scratch_dir("interrupt-study-hair");
    let csv = dir.join("h.csv");
    for (after, signal) in [(2500, libc::SIGINT), (5000, libc::SIGTERM)] {
        let _ = std::fs::remove_file(&csv);
        let child = spawn(&["study", "hair", "--csv", csv.to_str().unwrap()]);
        let (code, waited, stdout, stderr) = stop(child, Duration::from_millis(after), signal);
        assert_eq!(code, Some(130), "{stderr}");
        assert!(waited < 1.0, "{waited:.2} s after the signal");
        let complete = stderr
            .split("interrupted: ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|n| n.parse::<usize>().ok())
            .unwrap_or_else(|| panic!("{stderr}"));
        if complete == 0 {
            assert!(stdout.is_empty() && !csv.exists(), "{stdout}");
            continue;
        }
        let text = std::fs::read_to_string(&csv).unwrap();
        let rows: Vec<Vec<&str>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        assert_eq!(rows.len(), complete, "{text}");
        // Each row ran: a measured cost, and a stretch (or a divergence, left empty).
        for r in &rows {
            let ms: f64 = r[6].parse().unwrap();
            assert!(ms > 0.0, "{text}");
            assert!(
                r[5].is_empty() || r[5].parse::<f64>().unwrap() > 0.0,
                "{text}"
            );
        }
        // The trade table shows those rows and no other; every cheapest pick is one of them
        // (its ms/frame is one the table measured).
        let (trade, cheapest) = stdout.split_once("cheapest configuration").unwrap();
        let cells =
            |line: &str| -> Vec<String> { line.split('|').map(|c| c.trim().to_string()).collect() };
        let measured: Vec<String> = trade
            .lines()
            .filter(|l| l.starts_with('|') && !l.contains("---") && !l.contains("method"))
            .map(|l| cells(l)[7].clone())
            .collect();
        assert_eq!(measured.len(), complete, "{stdout}");
        for l in cheapest.lines().filter(|l| l.contains("--methods")) {
            let ms = cells(l)[5].clone();
            assert!(measured.contains(&ms), "{l} did not run: {stdout}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// At the largest thread count allowed, a hair run still answers SIGINT and SIGTERM within a
/// second.
#[test]
fn hair_at_the_most_threads_allowed_answers_signals() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let max = (4 * cores).to_string();
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let child = spawn(&[
            "hair",
            "--threads",
            &max,
            "--duration",
            "600",
            "--no-record",
            "-q",
        ]);
        let (code, waited, _, stderr) = stop(child, Duration::from_millis(1500), signal);
        assert_eq!(code, Some(130), "{stderr}");
        assert!(waited < 1.0, "{waited:.2} s after the signal");
    }
}
