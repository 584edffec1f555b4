//! The edges in every phase, each tried as a class of values: Ctrl-C and SIGTERM in
//! every phase of `study` (reference, sweep, stability; both scenes) and in the pendulum's
//! fine-step reference, with the files left on disk; the step guards of those phases; hair's
//! divergence bound and its kinetic energy per unit mass; implicit Euler's root at large steps;
//! the summary's count of missed Newton solves against the event log.

#![cfg(feature = "rerun")]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{decode, physlab, scratch_dir};

/// Names of hidden partial files left in `dir`.
fn partial_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect()
}

/// Starts `physlab args`, sends `signal` after `after`, and returns (exit code, stdout, stderr,
/// seconds from the signal to the exit).
fn interrupt(args: &[&str], after: Duration, signal: libc::c_int) -> (i32, String, String, f64) {
    let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let sent = Instant::now();
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    let out = child.wait_with_output().unwrap();
    let took = sent.elapsed().as_secs_f64();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    (out.status.code().unwrap_or(-1), stdout, stderr, took)
}

/// The time a stopped run may take to end. The issue asks for a second; the runs below take a
/// minute or more when not stopped, and this bound only has to tell the two apart on a loaded
/// machine (the measured times are printed: 0.01–0.09 s when written).
const ENDS_WITHIN: f64 = 5.0;

/// Every study kind on both scenes, stopped by SIGINT or SIGTERM early (in the reference or the
/// first runs) and later (in the sweep or the bisections): each ends at once with 130, says it
/// was interrupted, shows and writes only complete rows (the CSV has as many rows as the
/// printed table), leaves no partial file, and leaves a good CSV alone when nothing was complete.
#[test]
fn a_study_stops_in_every_phase_and_keeps_what_is_complete() {
    let dir = scratch_dir("edges-study-stop");
    let csv = dir.join("s.csv");
    let good = "a good file from an earlier study\n";
    let cases: [(&[&str], u64, libc::c_int); 10] = [
        // The pendulum's fine-step reference (ω0 ≠ 0) at 16 levels takes ~15 s.
        (
            &["convergence", "--omega0", "1", "--levels", "16"],
            300,
            libc::SIGINT,
        ),
        (
            &["convergence", "--omega0", "1", "--levels", "16"],
            1500,
            libc::SIGTERM,
        ),
        // The exact reference is instant: these stop in the sweep.
        (&["convergence", "--levels", "14"], 1000, libc::SIGINT),
        (&["work-precision", "--levels", "14"], 1000, libc::SIGTERM),
        (&["stability", "--steps", "10000000"], 300, libc::SIGINT),
        (&["stability", "--steps", "1000000"], 2000, libc::SIGTERM),
        (
            &["convergence", "--scene", "rope", "--levels", "9"],
            500,
            libc::SIGINT,
        ),
        (
            &["work-precision", "--scene", "rope", "--levels", "7"],
            1500,
            libc::SIGTERM,
        ),
        (
            &["stability", "--scene", "rope", "--steps", "1000000"],
            300,
            libc::SIGINT,
        ),
        (
            &["stability", "--scene", "rope", "--steps", "30000"],
            2500,
            libc::SIGTERM,
        ),
    ];
    let mut kept_some = 0;
    for (args, after_ms, signal) in cases {
        std::fs::write(&csv, good).unwrap();
        let mut all = vec!["study"];
        all.extend_from_slice(args);
        all.extend(["-q", "--csv", csv.to_str().unwrap()]);
        let (code, stdout, stderr, took) = interrupt(&all, Duration::from_millis(after_ms), signal);
        println!("{args:?} after {after_ms} ms: ended {took:.3} s after the signal");
        assert_eq!(code, 130, "{args:?}: {stderr}");
        assert!(took < ENDS_WITHIN, "{args:?}: took {took:.1} s");
        assert!(stderr.contains("interrupted: "), "{args:?}: {stderr}");
        assert!(
            partial_files(&dir).is_empty(),
            "{args:?}: {:?}",
            partial_files(&dir)
        );
        let written = std::fs::read_to_string(&csv).unwrap();
        if stderr.contains("nothing was written") {
            assert_eq!(written, good, "{args:?}: the good CSV was touched");
            assert!(
                !stdout.contains("| "),
                "{args:?}: a table without rows\n{stdout}"
            );
        } else {
            kept_some += 1;
            // Whole: a header and one line per complete run, each with the header's columns.
            let lines: Vec<&str> = written.lines().collect();
            let columns = lines[0].split(',').count();
            assert!(lines.len() >= 2, "{args:?}: {written}");
            assert!(
                lines.iter().all(|l| l.split(',').count() == columns),
                "{args:?}: a ragged CSV\n{written}"
            );
            let done: usize = stderr
                .split("interrupted: ")
                .nth(1)
                .and_then(|s| s.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap();
            assert_eq!(lines.len() - 1, done, "{args:?}: {stderr}");
        }
    }
    assert!(kept_some >= 5, "the later stops kept rows ({kept_some})");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The pendulum's fine-step reference (a start with ω0 ≠ 0: `--omega0 1e4` takes ~3e8 RK4 steps,
/// ~30 s) stops at once on SIGINT and SIGTERM, at several ω0 and moments, and finalises a
/// readable recording in place of the good one, with no partial file.
#[test]
fn the_pendulum_reference_stops_at_once_and_finalises_the_recording() {
    let dir = scratch_dir("edges-reference-stop");
    let out = dir.join("p.rrd");
    for (omega0, after_ms, signal) in [
        ("1e4", 300, libc::SIGINT),
        ("1e4", 1500, libc::SIGTERM),
        ("-2e4", 800, libc::SIGINT),
        ("3e3", 1000, libc::SIGTERM),
    ] {
        let (code, _, stderr, took) = interrupt(
            &["pendulum", "--omega0", omega0, "-o", out.to_str().unwrap()],
            Duration::from_millis(after_ms),
            signal,
        );
        println!("--omega0 {omega0} after {after_ms} ms: ended {took:.3} s after the signal");
        assert_eq!(code, 130, "--omega0 {omega0}: {stderr}");
        assert!(took < ENDS_WITHIN, "--omega0 {omega0}: took {took:.1} s");
        assert!(stderr.contains("fine-step reference takes"), "{stderr}");
        assert!(stderr.contains("finalised"), "{stderr}");
        assert!(decode(&out).has_footer, "--omega0 {omega0}: unreadable");
        assert!(partial_files(&dir).is_empty(), "{:?}", partial_files(&dir));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every phase counts its steps up front: the pendulum's fine-step reference is refused beyond
/// 1e9 RK4 steps naming --omega0 (1e5, -1e6, 3e4 over 100 s), and the study refuses a sweep
/// that cannot finish, whatever the flag that makes it so.
#[test]
fn every_phase_refuses_what_cannot_finish_naming_the_option() {
    for (args, message) in [
        (&["pendulum", "--omega0", "1e5"][..], "--omega0 100000"),
        (
            &["pendulum", "--omega0=-1e6", "--duration", "1"],
            "--omega0 -1e6",
        ),
        (
            &["pendulum", "--omega0", "30000", "--duration", "100"],
            "--omega0 30000",
        ),
        (
            &[
                "pendulum",
                "--omega0",
                "1",
                "--theta0",
                "10",
                "--gravity",
                "1e6",
                "--length",
                "1e-6",
                "--duration",
                "1e3",
            ],
            "fine-step",
        ),
        (&["study", "convergence", "--dt", "1e-9"], "--dt 1e-9"),
        (&["study", "convergence", "--dt", "1e-300"], "--dt 1e-300"),
        (
            &["study", "convergence", "--dt", "1e-7", "--levels", "2"],
            "reference steps",
        ),
        (&["study", "work-precision", "--levels", "20"], "at most"),
        (
            &["study", "convergence", "--dt", "5"],
            "--dt 5: must not exceed --duration / 16",
        ),
        (
            &["study", "convergence", "--dt", "0.7"],
            "--dt 0.7: must not exceed",
        ),
        (&["study", "convergence", "--dt", "1e300"], "--dt 1e300"),
        (
            &[
                "study",
                "convergence",
                "--scene",
                "rope",
                "--dt",
                "1",
                "--duration",
                "1e7",
            ],
            "reference steps",
        ),
        (
            &[
                "study",
                "convergence",
                "--scene",
                "rope",
                "--levels",
                "16",
                "--nodes",
                "64",
            ],
            "node-steps",
        ),
        (
            &["study", "convergence", "--repeats", "100", "--levels", "16"],
            "--repeats 100",
        ),
        (
            &[
                "study",
                "stability",
                "--scene",
                "rope",
                "--steps",
                "10000000",
                "--nodes",
                "32",
            ],
            "--steps 10000000",
        ),
        (
            &[
                "study",
                "stability",
                "--scene",
                "rope",
                "--nodes",
                "2000",
                "--steps",
                "1000000",
            ],
            "--nodes 2000",
        ),
    ] {
        let started = Instant::now();
        let (code, _, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?} was not refused: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(
            stderr.contains("at most") || stderr.contains("must"),
            "{args:?}: {stderr}"
        );
        // Refused up front, not after growing: well under the time any of them would run.
        assert!(started.elapsed() < Duration::from_secs(5), "{args:?}");
    }
}

/// Hair states its divergence bound, stops a run whose strands the solver cannot hold
/// (|ℓ - ℓ0|/ℓ0 > 10) across a class of winds and solvers while the constrained methods go on,
/// shows "—" for a lane that failed its first frame, and reports its kinetic energy per unit
/// mass of hair, which does not grow with the strand count.
#[test]
fn hair_reports_divergence_honestly_and_its_energy_per_unit_mass() {
    let summary = |args: &[&str]| {
        let mut all = vec!["hair", "--no-record", "-q", "--duration", "1"];
        all.extend_from_slice(args);
        let (code, stdout, stderr) = physlab(&all);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        stdout
    };
    let row = |text: &str, method: &str| -> Vec<String> {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("| {method} ")))
            .unwrap_or_else(|| panic!("no {method} row:\n{text}"));
        line.split('|').map(|c| c.trim().to_string()).collect()
    };
    for wind in ["300,0,0", "1000,0,0", "0,3000,0", "1e5,0,0"] {
        let s = summary(&["--wind", wind, "--methods", "verlet,ftl"]);
        assert!(
            s.contains("divergence = a non-finite position or a stretch |ℓ - ℓ0|/ℓ0 > 10"),
            "{s}"
        );
        for m in ["verlet", "ftl"] {
            assert_eq!(row(&s, m).last().map(String::as_str), Some(""), "{wind}");
            assert!(
                row(&s, m)[11] == "no",
                "--wind {wind}: {m} {:?}",
                row(&s, m)
            );
        }
        // Gauss–Seidel's sweeps cannot hold these winds: 27-fold at 100, 267-fold at 1000.
        let s = summary(&[
            "--wind",
            wind,
            "--methods",
            "verlet",
            "--solver",
            "gauss-seidel",
        ]);
        assert!(
            row(&s, "verlet")[11].starts_with("yes"),
            "--wind {wind}: {s}"
        );
    }
    // Failing the first frame: no figures, not zeros.
    for wind in ["0,0,1e6", "1e6,0,0"] {
        // Gauss–Seidel's sweeps stretch past the bound in the first frame.
        let s = summary(&[
            "--wind",
            wind,
            "--gust",
            "0",
            "--methods",
            "verlet",
            "--solver",
            "gauss-seidel",
        ]);
        let r = row(&s, "verlet");
        assert!(r[11].starts_with("yes"), "{r:?}");
        assert_eq!(&r[7..11], ["—", "—", "—", "—"], "{r:?}");
    }
    // Per unit mass: 1, 10 and 100 strands move alike, so their KE is alike (a sum over nodes
    // would grow 100-fold).
    let ke = |strands: &str| -> f64 {
        let s = summary(&["--strands", strands, "--methods", "verlet"]);
        assert!(
            s.contains("KE = kinetic energy per unit mass of hair"),
            "{s}"
        );
        row(&s, "verlet")[10].parse().unwrap()
    };
    let (one, ten, hundred) = (ke("1"), ke("10"), ke("100"));
    for (n, k) in [(10, ten), (100, hundred)] {
        assert!(
            (0.2..5.0).contains(&(k / one)),
            "{n} strands: {k} J/kg against {one} J/kg for one strand"
        );
    }
}

/// Implicit Euler on the pendulum at dt² g/L ≥ 1 (dt = 0.6, 1, 5, 50 s) takes the root that
/// minimises the step's incremental potential: it does not diverge, its energy error stays
/// within E0 (|ΔE/E0| ≤ 1: energy only lost), and the summary says what it does.
#[test]
fn implicit_euler_at_large_steps_keeps_the_dissipative_root() {
    let dir = scratch_dir("edges-root");
    let out = dir.join("p.rrd");
    for dt in ["0.6", "1", "5", "50"] {
        let (code, stdout, stderr) = physlab(&[
            "pendulum",
            "--dt",
            dt,
            "--duration",
            "200",
            "--methods",
            "implicit-euler",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert!(
            stdout.contains("minimises the step's incremental potential"),
            "{stdout}"
        );
        let line = stdout
            .lines()
            .find(|l| l.starts_with("| implicit-euler "))
            .unwrap();
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        assert_eq!(cells.last_chunk::<2>().unwrap()[0], "no", "dt {dt}: {line}");
        let de: f64 = cells[7].parse().unwrap();
        assert!(de <= 1.0 + 1e-12, "dt {dt}: max |ΔE/E0| = {de}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The summary's "Newton missed tolerance on N steps" and the event log agree: the log has the
/// first miss and, when there are more, the total N. Tried on the rope's implicit Euler with
/// too few Newton iterations at several steps and stiffnesses, diverging lanes included.
#[test]
fn missed_newton_solves_agree_between_summary_and_event_log() {
    let dir = scratch_dir("edges-misses");
    let out = dir.join("r.rrd");
    let mut tried = 0;
    for args in [
        &["--newton-iterations", "2", "--dt", "0.3"][..],
        &["--newton-iterations", "3", "--dt", "0.1"],
        &["--newton-iterations", "4", "--dt", "1"],
        &[
            "--newton-iterations",
            "2",
            "--stiffness",
            "1e6",
            "--dt",
            "0.05",
        ],
        &["--newton-iterations", "1", "--dt", "0.3"],
    ] {
        let mut all = vec![
            "rope",
            "--methods",
            "implicit-euler",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        all.extend_from_slice(args);
        let (code, stdout, stderr) = physlab(&all);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        let summary: u64 = stdout
            .split("Newton missed tolerance on ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .map_or(0, |n| n.parse().unwrap());
        let (_, log, _) = physlab(&["inspect", out.to_str().unwrap()]);
        let firsts = log.matches("missed its Newton tolerance").count() as u64;
        let stated: u64 = log
            .lines()
            .filter(|l| l.contains(" implicit steps in all missed"))
            .filter_map(|l| l.split("implicit-euler: ").nth(1))
            .filter_map(|s| s.split(' ').next())
            .map(|n| n.parse::<u64>().unwrap())
            .sum();
        let log_count = if stated > 0 { stated } else { firsts };
        assert_eq!(
            firsts.min(1),
            u64::from(summary > 0),
            "{args:?}:\n{stdout}\n{log}"
        );
        assert_eq!(log_count, summary, "{args:?}:\n{stdout}\n{log}");
        tried += u64::from(summary > 0);
    }
    assert!(tried >= 4, "the class was tried ({tried} runs with misses)");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Values the issue does not name, from the same classes: hair's magnitudes get the physical
/// ranges the pendulum's and the rope's have (refused by name), a frame rate below one frame
/// names --rate (not an internal --dt), negative numbers in exponent form are values (written
/// --theta0=-1e-3: clap reads a separate -1e-3 as flags), and the extremes that are accepted run without a NaN or inf in the summary.
#[test]
fn hostile_values_of_every_class_are_refused_by_name_or_run_clean() {
    for (args, message) in [
        (
            &["hair", "--segment-length", "1e9"][..],
            "--segment-length 1e9: must be between",
        ),
        (
            &["hair", "--segment-length", "1e-9"],
            "--segment-length 1e-9",
        ),
        (&["hair", "--head-radius", "1e9"], "--head-radius 1e9"),
        (&["hair", "--wind", "1e7,0,0"], "--wind 1e7,0,0"),
        (&["hair", "--wind", "0,0,inf"], "--wind"),
        (&["hair", "--gust", "1e6"], "--gust 1e6"),
        (
            &["hair", "--gust", "2", "--wind", "5e5,0,0"],
            "the gusts reach",
        ),
        (&["hair", "--gravity", "0,0,-1e9"], "--gravity"),
        (&["hair", "--damping", "1e9"], "--damping 1e9"),
        (&["hair", "--stiffness", "1e300"], "--stiffness 1e300"),
        (
            &[
                "hair",
                "--methods",
                "semi-implicit-euler",
                "--segment-length",
                "1e-5",
            ],
            "the springs' default --stiffness here is k/m = 4.552e14",
        ),
        (
            &["hair", "--spring-damping", "1e300"],
            "--spring-damping 1e300",
        ),
        (
            &["hair", "--rate", "1e-3"],
            "--rate 0.001 Hz over --duration 8 s is less than one frame",
        ),
        (&["hair", "--rate", "1e12"], "--rate 1e12"),
        (
            &["pendulum", "--dt", "1e-9"],
            "--dt 1e-9 with --duration 20",
        ),
        (&["rope", "--dt", "1e-12"], "--dt 1e-12"),
    ] {
        let (code, _, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?} was not refused: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    let dir = scratch_dir("edges-hostile");
    let out = dir.join("x.rrd");
    for args in [
        &["pendulum", "--theta0=-1e-3"][..],
        &["pendulum", "--theta0=-1e-30"],
        &["pendulum", "--omega0=-1e-3", "--theta0=-2e2"],
        &[
            "pendulum",
            "--length",
            "1e-6",
            "--gravity",
            "1e6",
            "--dt",
            "1e-6",
            "--duration",
            "1e-3",
        ],
        &[
            "pendulum",
            "--length",
            "1e6",
            "--gravity",
            "1e-6",
            "--duration",
            "100",
        ],
        &["rope", "--end", "1e-9,0,0", "--duration", "0.1"],
        &["rope", "--end=-1e3,0,0", "--duration", "0.1"],
        &[
            "hair",
            "--wind",
            "1e6,0,0",
            "--gust",
            "0",
            "--duration",
            "0.2",
        ],
        &["hair", "--wind=-1e3,0,0", "--duration", "0.2"],
        &[
            "hair",
            "--nodes",
            "2",
            "--segment-length",
            "1e-6",
            "--duration",
            "0.2",
        ],
        &[
            "hair",
            "--head-radius",
            "1e-6",
            "--gravity",
            "0,0,-1e6",
            "--duration",
            "0.2",
        ],
    ] {
        let mut all = args.to_vec();
        all.extend(["-q", "-o", out.to_str().unwrap()]);
        let (code, stdout, stderr) = physlab(&all);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        let lower = stdout.to_lowercase();
        assert!(
            !lower.contains("nan") && !lower.contains("inf "),
            "{args:?}:\n{stdout}"
        );
        let d = common::decode(&out);
        for (entity, rows) in &d.scalars {
            assert!(
                rows.iter().all(|r| r.1.is_finite()),
                "{args:?}: a non-finite value in {entity}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
