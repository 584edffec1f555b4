//! SIGINT, SIGTERM and SIGHUP (a closed terminal) in the running and the writing phases: the
//! first ends the run with 130 and a finalised file, a second ends at once and removes what the
//! first left, and at no moment does a signal leave a broken file where a good one was, nor a
//! hidden partial file.

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{decode, physlab, scratch_dir};

const SIGNALS: [(libc::c_int, &str); 3] = [
    (libc::SIGINT, "SIGINT"),
    (libc::SIGTERM, "SIGTERM"),
    (libc::SIGHUP, "SIGHUP"),
];

/// The time a stopped run may take to end: the issue asks for a second; this bound only has to
/// tell a stop from a run of a minute on a loaded machine.
const ENDS_WITHIN: f64 = 5.0;

fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial"))
        .collect()
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn kill(child: &Child, signal: libc::c_int) {
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
}

/// Waits for the child; returns (exit code, stderr, seconds since `since`).
fn wait(child: Child, since: Instant) -> (i32, String, f64) {
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    (
        out.status.code().unwrap_or(-1),
        err,
        since.elapsed().as_secs_f64(),
    )
}

/// A run of about a minute when not stopped.
fn long_run(out: &Path) -> Vec<String> {
    ["hair", "--strands", "3000", "--duration", "60", "-q", "-o"]
        .iter()
        .map(|s| s.to_string())
        .chain([out.to_str().unwrap().to_string()])
        .collect()
}

/// Waits until the run's hidden file exists (the run is under way).
fn wait_for_partial(dir: &Path) {
    let started = Instant::now();
    while partials(dir).is_empty() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "no run started"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
}

#[test]
fn each_signal_stops_a_run_and_finalises_its_recording() {
    let dir = scratch_dir("int-first");
    for (signal, name) in SIGNALS {
        let out = dir.join(format!("{name}.rrd"));
        let args = long_run(&out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let child = spawn(&args);
        wait_for_partial(&dir);
        let sent = Instant::now();
        kill(&child, signal);
        let (code, err, took) = wait(child, sent);
        assert_eq!(code, 130, "{name}: {err}");
        assert!(err.contains("interrupted"), "{name}: {err}");
        assert!(took < ENDS_WITHIN, "{name}: took {took:.2} s");
        assert!(decode(&out).has_footer, "{name}: not finalised");
        assert!(partials(&dir).is_empty(), "{name}: {:?}", partials(&dir));
        println!("{name}: ended {took:.3} s after the signal");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_signal_ends_at_once_removes_the_partial_and_keeps_the_old_file() {
    let dir = scratch_dir("int-second");
    let out = dir.join("r.rrd");
    let (code, _, err) = physlab(&[
        "pendulum",
        "-q",
        "--duration",
        "0.5",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let before = std::fs::read(&out).unwrap();
    for (first, a) in SIGNALS {
        for (second, b) in SIGNALS {
            let args = long_run(&out);
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let child = spawn(&args);
            wait_for_partial(&dir);
            let sent = Instant::now();
            kill(&child, first);
            kill(&child, second);
            let (code, err, took) = wait(child, sent);
            assert_eq!(code, 130, "{a} then {b}: {err}");
            assert!(took < ENDS_WITHIN, "{a} then {b}: took {took:.2} s");
            assert!(
                partials(&dir).is_empty(),
                "{a} then {b}: {:?}",
                partials(&dir)
            );
            // Either the first signal's finalised recording made it in time, or the old file
            // is there byte for byte: never a broken one.
            let now = std::fs::read(&out).unwrap();
            assert!(
                now == before || decode(&out).has_footer,
                "{a} then {b}: broken file"
            );
            std::fs::write(&out, &before).unwrap();
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A study that computes for a moment and then writes its CSV, diagrams and recording, signalled
/// at a sweep of moments that cover the computing and the writing: each ends with 0 or 130, and
/// every file is either the old one byte for byte or a complete new one.
#[test]
fn a_signal_at_any_moment_of_a_study_leaves_old_or_complete_files() {
    let dir = scratch_dir("int-writing");
    let csv = dir.join("s.csv");
    let rec = dir.join("s.rrd");
    let plots = dir.join("plots");
    let args = [
        "study",
        "convergence",
        "--levels",
        "6",
        "--methods",
        "rk4,verlet",
        "--csv",
        csv.to_str().unwrap(),
        "-o",
        rec.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
    ];
    // How long a whole run takes here, to spread the signals over it.
    let started = Instant::now();
    let (code, _, err) = physlab(&args);
    assert_eq!(code, 0, "{err}");
    let whole = started.elapsed();
    let good_csv = std::fs::read(&csv).unwrap();
    let mut outcomes = [0usize; 2];
    for (i, (signal, name)) in SIGNALS.iter().cycle().take(12).enumerate() {
        std::fs::write(&csv, b"old csv").unwrap();
        std::fs::write(&rec, b"old recording").unwrap();
        let child = spawn(&args);
        std::thread::sleep(whole.mul_f64(i as f64 / 11.0));
        let sent = Instant::now();
        kill(&child, *signal);
        let (code, err, took) = wait(child, sent);
        // -1: killed by the signal itself, sent before the handlers were installed at start-up
        // (nothing written yet); the files below must hold in every case.
        assert!(
            code == 0 || code == 130 || code == -1,
            "{name} at {i}/11: {code} {err}"
        );
        assert!(took < ENDS_WITHIN, "{name}: took {took:.2} s");
        outcomes[usize::from(code != 0)] += 1;
        let c = std::fs::read(&csv).unwrap();
        assert!(
            c == b"old csv"
                || c.starts_with(&good_csv[..good_csv.iter().position(|&b| b == b'\n').unwrap()]),
            "{name} at {i}/11: a broken CSV"
        );
        let r = std::fs::read(&rec).unwrap();
        assert!(
            r == b"old recording" || decode(&rec).has_footer,
            "{name} at {i}/11: a broken recording"
        );
        for d in [&dir, &plots] {
            if d.exists() {
                assert!(
                    partials(d).is_empty(),
                    "{name} at {i}/11: {:?}",
                    partials(d)
                );
            }
        }
    }
    println!(
        "12 moments: {} ran to the end, {} stopped",
        outcomes[0], outcomes[1]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A recording written to standard output that nobody reads blocks in `write`, where the run
/// never reaches its next check: a signal still ends it, with 130 and a message saying why.
#[test]
fn a_signal_ends_a_run_blocked_writing_to_an_unread_pipe() {
    for (signal, name) in SIGNALS {
        let mut child = spawn(&["pendulum", "--duration", "1000", "-q", "-o", "-"]);
        // The pipe (64 KiB) is full within a fraction of a second; nobody reads it.
        std::thread::sleep(Duration::from_millis(1500));
        assert!(child.try_wait().unwrap().is_none(), "{name}: ended unread");
        let since = Instant::now();
        kill(&child, signal);
        let code = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status.code().unwrap_or(-1);
            }
            assert!(
                since.elapsed().as_secs_f64() < ENDS_WITHIN,
                "{name}: still blocked {ENDS_WITHIN} s after the signal"
            );
            std::thread::sleep(Duration::from_millis(10));
        };
        let took = since.elapsed().as_secs_f64();
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(code, 130, "{name}: {err}");
        assert!(
            err.contains("standard output was not being read"),
            "{name}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        eprintln!("{name}: ended {took:.2} s after the signal");
    }
}
