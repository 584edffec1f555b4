//! A run that will take long or write much says so, with its time and size, within its first
//! seconds, also when its first 3D window is the long part.

mod common;

use std::io::{BufRead as _, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{s, scratch_dir};

#[test]
fn a_long_run_whose_first_3d_window_is_the_long_part_says_so_at_once_with_its_size() {
    let dir = scratch_dir("notice");
    let out = dir.join("huge.rrd");
    // About 25 GB in its first 3D window alone; on main nothing was said for 40 s.
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([
            "rope",
            "--nodes",
            "1000000",
            "--dt",
            "0.002",
            "--duration",
            "200",
        ])
        .args(["--methods", "verlet", "-o", s(&out)])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let mut notice = None;
    while let Ok(line) = rx.recv_timeout(Duration::from_secs(8).saturating_sub(started.elapsed())) {
        if line.contains("this takes about") {
            notice = Some((line, started.elapsed()));
            break;
        }
    }
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    child.wait().unwrap();
    let (line, after) = notice.expect("a notice within 8 s");
    assert!(after < Duration::from_secs(5), "{after:?}: {line}");
    // Hours, and tens of GB: both windows of 3,000 frames of 12 MB.
    assert!(
        line.contains(" h ") && line.contains(" GB to its recording"),
        "{line}"
    );
    let gb: f64 = line
        .split(" GB")
        .next()
        .unwrap()
        .rsplit(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((25.0..100.0).contains(&gb), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A study shows the scenes' progress bar with its ETA on a terminal (run in a pty by
/// `script`), and no bar when its stderr is a pipe; a study that will take long says so before
/// its first run, in the scenes' words, with its estimate. On main a study showed no bar, and
/// said nothing under a minute.
#[test]
fn a_study_shows_the_scenes_bar_on_a_terminal_and_its_time_up_front() {
    let dir = scratch_dir("study-progress");
    let exe = env!("CARGO_BIN_EXE_physlab");
    let study = "study convergence --scene rope";
    let (out, printed) = (dir.join("c"), dir.join("stdout.txt"));
    let cmd = format!("{exe} {study} -o {} > {}", s(&out), s(&printed));
    let pty = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .expect("script(1) from util-linux runs a command in a pty");
    let shown = String::from_utf8_lossy(&pty.stdout);
    assert!(pty.status.success(), "{shown}");
    assert!(
        shown.contains("study convergence [=") && shown.contains("(eta "),
        "{shown}"
    );
    let piped = Command::new(exe)
        .args(study.split(' '))
        .args(["-o", s(&out)])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&piped.stderr);
    assert!(piped.status.success(), "{stderr}");
    assert!(
        !stderr.contains("[=") && !stderr.contains("eta"),
        "{stderr}"
    );

    // About a minute and a half of rope drift (1.4e9 node-steps): said at once.
    let started = Instant::now();
    let mut child = Command::new(exe)
        .args(["study", "drift", "--scene", "rope", "-o", s(&out)])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = BufReader::new(child.stderr.take().unwrap())
        .lines()
        .next()
        .unwrap()
        .unwrap();
    let after = started.elapsed();
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    child.wait().unwrap();
    assert!(after < Duration::from_secs(3), "{after:?}: {first}");
    assert!(
        first.starts_with("study drift: this takes about ")
            && first.contains(" min ")
            && first.contains("(estimated from its 1.4e9 node-steps")
            && first.ends_with("Ctrl-C stops it and keeps what is done"),
        "{first}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
