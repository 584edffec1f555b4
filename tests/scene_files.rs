//! Scene files that are not scene files, and tables that ask for nothing, are refused as bad
//! input (exit 2, one line naming the file and what is wrong), at once and without reading
//! more than a scene file can hold.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::scratch_dir;

/// Runs physlab with `args`; returns its exit code, stderr and how long it took. A run that
/// has not ended after `limit` is killed and reported as code -1.
fn run_within(args: &[&str], limit: Duration) -> (i32, String, Duration) {
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
            return (status.code().unwrap_or(-1), stderr, started.elapsed());
        }
        if started.elapsed() > limit {
            child.kill().unwrap();
            let _ = child.wait();
            return (-1, "killed: did not end".into(), started.elapsed());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success(), "mkfifo {}", path.display());
}

#[test]
fn a_scene_file_that_is_not_a_regular_file_of_bounded_size_is_refused_at_once() {
    let dir = scratch_dir("cli-input-files");
    let fifo = dir.join("fifo.toml");
    mkfifo(&fifo);
    let large = dir.join("large.toml");
    // A valid table padded with comments past the cap: refused for its size, not its content.
    let mut text = String::from("[pendulum]\ntheta0 = 30.0\n");
    while text.len() as u64 <= physlab::app::MAX_SCENE_FILE_BYTES {
        text.push_str("# padding padding padding padding padding padding padding padding\n");
    }
    std::fs::write(&large, &text).unwrap();
    let out = dir.join("x.rrd");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &Path, &str); 6] = [
        (
            &["pendulum", "-o", out],
            &fifo,
            "is a FIFO (named pipe), not a regular file",
        ),
        (
            &["study", "convergence"],
            &fifo,
            "is a FIFO (named pipe), not a regular file",
        ),
        (
            &["rope", "-o", out],
            Path::new("/dev/zero"),
            "is a character device, not a regular file",
        ),
        (
            &["all", "-o", out],
            Path::new("/dev/null"),
            "is a character device, not a regular file",
        ),
        (&["pendulum", "-o", out], &large, "larger than 1 MiB"),
        (&["study", "stability"], &large, "larger than 1 MiB"),
    ];
    for (args, file, message) in cases {
        let mut all = args.to_vec();
        all.extend(["--config", file.to_str().unwrap()]);
        let (code, stderr, took) = run_within(&all, Duration::from_secs(20));
        assert_eq!(code, 2, "{all:?}: {stderr}");
        assert!(
            stderr.contains(&format!("--config {}: {message}", file.display())),
            "{all:?}: {stderr}"
        );
        assert!(!stderr.contains("empty"), "{all:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{all:?}: {stderr}");
        assert!(took < Duration::from_secs(10), "{all:?} took {took:?}");
    }
    assert!(!Path::new(out).exists(), "a refused run wrote nothing");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_empty_method_list_in_a_scene_file_is_refused_like_an_empty_flag() {
    let dir = scratch_dir("cli-input-methods");
    let out = dir.join("x.rrd");
    let out = out.to_str().unwrap();
    // Every table, and the study reading the same file.
    for (command, table) in [
        (&["pendulum", "-o", out][..], "pendulum"),
        (&["rope", "-o", out], "rope"),
        (&["hair", "-o", out], "hair"),
        (&["all", "-o", out], "hair"),
        (&["study", "convergence"], "pendulum"),
        (&["study", "convergence", "--scene", "rope"], "rope"),
    ] {
        let file = dir.join(format!("{table}.toml"));
        std::fs::write(&file, format!("[{table}]\nfps = 30.0\nmethods = []\n")).unwrap();
        let mut args = command.to_vec();
        args.extend(["--config", file.to_str().unwrap()]);
        let (code, stderr, _) = run_within(&args, Duration::from_secs(60));
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains(&format!("line 3: [{table}] methods = []: lists no method")),
            "{args:?}: {stderr}"
        );
    }
    // The flag's own refusal, for comparison: the same class of input, the same exit code.
    for scene in ["pendulum", "rope", "hair"] {
        let (code, stderr, _) = run_within(
            &[scene, "-o", out, "--methods", ""],
            Duration::from_secs(60),
        );
        assert_eq!(code, 2, "{scene} --methods '': {stderr}");
    }
    assert!(!Path::new(out).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_value_of_the_wrong_type_is_reported_at_its_line_with_its_key_and_the_type_expected() {
    let dir = scratch_dir("cli-input-types");
    let out = dir.join("x.rrd");
    let out = out.to_str().unwrap();
    // Keys of flattened flag groups (theta0, nodes, mass) and plain ones, numbers, text, booleans
    // and dates; each on line 3, below a comment, so that line 1 is never right by accident.
    let cases = [
        ("rope", "nodes = 16.5", "expected usize"),
        ("rope", "mass = true", "expected f64"),
        ("rope", "dt = \"fast\"", "expected f64"),
        ("pendulum", "theta0 = \"x\"", "expected f64"),
        ("pendulum", "dt = 1979-05-27", "date"),
        ("pendulum", "omega0 = 1979-05-27T07:32:00Z", "date"),
        ("rope", "nodes = 07:32:00", "date"),
        ("hair", "strands = 2.5", "expected usize"),
        ("hair", "duration = 1979-05-27", "date"),
    ];
    for (table, line, expected) in cases {
        let file = dir.join(format!("{table}.toml"));
        std::fs::write(&file, format!("# a scene file\n[{table}]\n{line}\n")).unwrap();
        let (code, stderr, _) = run_within(
            &[table, "-o", out, "--config", file.to_str().unwrap()],
            Duration::from_secs(60),
        );
        assert_eq!(code, 2, "{line}: {stderr}");
        let key = line.split(" = ").next().unwrap();
        assert!(stderr.contains("line 3"), "{line}: {stderr}");
        assert!(!stderr.contains("line 1,"), "{line}: {stderr}");
        assert!(stderr.contains(key), "{line}: {stderr}");
        assert!(stderr.contains(expected), "{line}: {stderr}");
        if expected == "date" {
            // The type the key takes is named too, not "map".
            assert!(stderr.contains("expected "), "{line}: {stderr}");
            assert!(!stderr.contains("invalid type: map"), "{line}: {stderr}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
