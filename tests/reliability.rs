//! Failing politely: bad input of every kind, existing recordings left intact,
//! interruption, divergence as an exit code.

#![cfg(feature = "rerun")]

mod common;

use std::process::{Command, Stdio};
use std::time::Duration;

use common::{decode, physlab, scratch_dir};

/// (arguments, expected exit code, a fragment the one-line message must contain)
const BAD_INPUTS: &[(&[&str], i32, &str)] = &[
    // clap: unknown commands, flags and malformed values
    (&["simulate"], 2, "unrecognized subcommand"),
    (&["pendulum", "--bogus"], 2, "unexpected argument '--bogus'"),
    (&["pendulum", "--dt"], 2, "a value is required for '--dt"),
    (
        &["pendulum", "--dt", "abc"],
        2,
        "invalid value 'abc' for '--dt",
    ),
    (&["pendulum", "--methods", "rk5"], 2, "unknown method 'rk5'"),
    (
        &["pendulum", "--methods", "rk4,euler"],
        2,
        "unknown method 'euler'",
    ),
    (
        &["rope", "--nodes", "-3"],
        2,
        "--nodes -3: must be a whole number ≥ 0",
    ),
    (
        &["rope", "--nodes", "2.5"],
        2,
        "invalid value '2.5' for '--nodes",
    ),
    (
        &["rope", "--pinned", "a"],
        2,
        "invalid value 'a' for '--pinned",
    ),
    (
        &["rope", "--layout", "stacked"],
        2,
        "invalid value 'stacked' for '--layout",
    ),
    (
        &["rope", "--preset", "games202"],
        2,
        "invalid value 'games202' for '--preset",
    ),
    (&["rope", "--start", "1,2,3,4"], 2, "expected x,y,z"),
    (
        &["hair", "--head-motion", "spin"],
        2,
        "invalid value 'spin' for '--head-motion",
    ),
    (
        &["hair", "--methods", "rk4"],
        2,
        "unknown hair method 'rk4'",
    ),
    (&["hair", "--wind", "1,nan,0"], 2, "expected x,y,z"),
    // pendulum ranges
    (
        &["pendulum", "--dt", "0"],
        2,
        "--dt 0: must be a finite number > 0",
    ),
    (
        &["pendulum", "--dt", "-0.1"],
        2,
        "--dt -0.1: must be a finite number > 0",
    ),
    (
        &["pendulum", "--dt", "inf"],
        2,
        "--dt inf: must be a finite number > 0",
    ),
    (
        &["pendulum", "--duration", "0"],
        2,
        "--duration 0: must be a finite number > 0",
    ),
    (
        &["pendulum", "--dt", "2", "--duration", "1"],
        2,
        "--dt 2: must not exceed --duration 1",
    ),
    (
        &["pendulum", "--dt", "1e-12", "--duration", "100"],
        2,
        "at most 1e9 are allowed",
    ),
    (
        &["pendulum", "--fps", "0"],
        2,
        "--fps 0: must be a finite number > 0",
    ),
    (
        &["pendulum", "--gravity", "0"],
        2,
        "--gravity 0: must be between 1e-6 and 1e6 [m/s²]",
    ),
    (
        &["pendulum", "--length", "-2"],
        2,
        "--length -2: must be between 1e-6 and 1e6 [m]",
    ),
    (
        &["pendulum", "--theta0", "nan"],
        2,
        "--theta0 NaN: must be a finite angle",
    ),
    (
        &["pendulum", "--omega0", "inf"],
        2,
        "--omega0 inf: must be between -1e6 and 1e6 [rad/s]",
    ),
    (
        &["pendulum", "--verlet-damping", "1.5"],
        2,
        "--verlet-damping 1.5: must be in [0, 1)",
    ),
    (
        &["pendulum", "--plot-every", "0"],
        2,
        "--plot-every 0: must be at least 1",
    ),
    // rope ranges
    (&["rope", "--nodes", "1"], 2, "--nodes 1: must be between 2"),
    (
        &["rope", "--pinned", "0,16"],
        2,
        "--pinned 16: node index out of range",
    ),
    (&["rope", "--end", "0,0,0"], 2, "must differ from --start"),
    (
        &["rope", "--mass", "0"],
        2,
        "--mass 0: must be between 1e-6 and 1e6 [kg]",
    ),
    (
        &["rope", "--stiffness", "-1"],
        2,
        "--stiffness -1: must be between 1e-6 and 1e12 [N/m]",
    ),
    (
        &["rope", "--spring-damping", "-1"],
        2,
        "--spring-damping -1: must be between 0 and 1e6 [N·s/m]",
    ),
    (
        &["rope", "--air-drag", "nan"],
        2,
        "--air-drag NaN: must be between 0 and 1e6 [N·s/m]",
    ),
    (
        &["rope", "--newton-iterations", "0"],
        2,
        "--newton-iterations 0: must be at least 1",
    ),
    (
        &["rope", "--nodes", "1000000", "--duration", "1000"],
        2,
        "node-steps per method",
    ),
    (
        &[
            "rope",
            "--nodes",
            "9000000",
            "--duration",
            "0.01",
            "--methods",
            "explicit-euler,semi-implicit-euler,implicit-euler,midpoint,trapezoid,rk4,verlet,yoshida4,dopri5,dop853,vern9",
        ],
        2,
        "of memory, more than",
    ),
    // hair ranges
    (
        &["hair", "--strands", "0"],
        2,
        "--strands 0: must be between 1",
    ),
    (&["hair", "--nodes", "1"], 2, "--nodes 1: must be between 2"),
    (
        &["hair", "--segment-length", "0"],
        2,
        "--segment-length 0: must be between 1e-6 and 1e6",
    ),
    (
        &["hair", "--head-radius", "-1"],
        2,
        "--head-radius -1: must be between 1e-6 and 1e6",
    ),
    (
        &["hair", "--iterations", "0"],
        2,
        "--iterations 0: must be at least 1",
    ),
    (
        &["hair", "--substeps", "0"],
        2,
        "--substeps 0: must be at least 1",
    ),
    (
        &["hair", "--margin", "0.7"],
        2,
        "--margin 0.7: must be in [0, 0.5)",
    ),
    (
        &["hair", "--gust", "-1"],
        2,
        "--gust -1: must be a finite number ≥ 0",
    ),
    (
        &["hair", "--rate", "0"],
        2,
        "--rate 0: must be a finite number > 0",
    ),
    (
        &["hair", "--threads", "0"],
        2,
        "--threads 0: must be between 1 and",
    ),
    // files
    (
        &["pendulum", "--config", "/nonexistent/scene.toml"],
        2,
        "cannot read it",
    ),
    (&["inspect", "/nonexistent/run.rrd"], 2, "cannot read it"),
    (&["pendulum", "--connect", "ftp://x"], 2, "not a viewer URL"),
];

#[test]
fn every_bad_input_gets_one_clear_line_and_exit_code_2() {
    assert!(BAD_INPUTS.len() >= 40);
    let dir = scratch_dir("bad-inputs");
    let out = dir.join("r.rrd");
    for (args, code, fragment) in BAD_INPUTS {
        let mut full: Vec<&str> = args.to_vec();
        if !matches!(args[0], "inspect" | "simulate") {
            full.extend(["-o", out.to_str().unwrap()]);
        }
        let (got, _, stderr) = physlab(&full);
        assert_eq!(got, *code, "{args:?}: exit code {got}, stderr:\n{stderr}");
        assert!(
            stderr.contains(fragment),
            "{args:?}: expected '{fragment}' in:\n{stderr}"
        );
        assert!(!out.exists(), "{args:?} wrote a recording");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn folders_and_unwritable_paths_are_refused_before_simulating() {
    let dir = scratch_dir("bad-outputs");
    let (code, _, err) = physlab(&["pendulum", "-o", dir.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("is a folder"), "{err}");
    let blocked = dir.join("file");
    std::fs::write(&blocked, b"x").unwrap();
    // A path under a regular file cannot be created.
    let (code, _, err) = physlab(&["pendulum", "-o", blocked.join("r.rrd").to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("cannot create the folder"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A hair run of about 20 s writing to `out`, started in the background for a test to
/// interrupt or kill.
fn spawn_long_hair_run(out: &std::path::Path, output: fn() -> Stdio) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([
            "hair",
            "--strands",
            "3000",
            "--nodes",
            "32",
            "--duration",
            "60",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ])
        .stdout(output())
        .stderr(output())
        .spawn()
        .unwrap()
}

#[test]
fn failed_and_killed_runs_leave_an_existing_recording_byte_identical() {
    let dir = scratch_dir("keep-good");
    let good = dir.join("good.rrd");
    let (code, _, _) = physlab(&["pendulum", "--duration", "2", "-o", good.to_str().unwrap()]);
    assert_eq!(code, 0);
    let before = std::fs::read(&good).unwrap();

    // Refused input.
    let (code, _, _) = physlab(&["pendulum", "--dt", "0", "-o", good.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert_eq!(std::fs::read(&good).unwrap(), before);

    // A long run killed outright (no chance to clean up) half way.
    let mut child = spawn_long_hair_run(&good, Stdio::null);
    std::thread::sleep(Duration::from_millis(1500));
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(
        std::fs::read(&good).unwrap(),
        before,
        "the killed run touched the recording"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sigint_finalises_a_readable_recording_and_exits_130() {
    let dir = scratch_dir("sigint");
    let out = dir.join("int.rrd");
    let child = spawn_long_hair_run(&out, Stdio::piped);
    std::thread::sleep(Duration::from_millis(1500));
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let result = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("interrupted") && stderr.contains("finalised"),
        "{stderr}"
    );
    let d = decode(&out);
    assert!(d.has_footer, "the interrupted recording has its footer");
    let ke = &d.scalars["/hair/plots/specific_kinetic_energy/verlet"];
    let last = ke.last().unwrap().0 as f64 * 1e-9;
    assert!(
        ke.len() > 10 && last < 59.0,
        "holds the run up to the interruption ({} rows, last t = {last})",
        ke.len()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_sigint_ends_at_once_and_leaves_no_file_behind() {
    let dir = scratch_dir("sigint2");
    let out = dir.join("int.rrd");
    let child = spawn_long_hair_run(&out, Stdio::piped);
    std::thread::sleep(Duration::from_millis(1500));
    // SAFETY: sending signals to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let result = child.wait_with_output().unwrap();
    assert_eq!(result.status.code(), Some(130));
    // Either the first signal's finalised recording made it, or nothing: never a hidden
    // `.int.rrd.PID.partial`.
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(left.is_empty(), "stray files: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fail_on_divergence_exits_3_and_still_writes_the_recording() {
    let dir = scratch_dir("diverge");
    let out = dir.join("r.rrd");
    // Explicit Euler blows up on the default rope within a second.
    let (code, stdout, stderr) = physlab(&[
        "rope",
        "--duration",
        "1",
        "--fail-on-divergence",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 3, "{stderr}");
    assert!(stderr.contains("rope/explicit-euler"), "{stderr}");
    assert!(stdout.contains("yes, t ="), "{stdout}");
    assert!(decode(&out).has_footer);
    let (code, _, _) = physlab(&[
        "pendulum",
        "--duration",
        "1",
        "--fail-on-divergence",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "nothing diverges on the default pendulum");
    std::fs::remove_dir_all(&dir).unwrap();
}
