//! A run that will take long or write much says so, with its time and size, within its first
//! seconds, also when its first 3D window is the long part.

mod common;

use std::io::{BufRead as _, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{s, scratch_dir};

/// The lines `args` writes to stderr, as they come, and the child.
fn stderr_lines(args: &[&str]) -> (std::process::Child, std::sync::mpsc::Receiver<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
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
    (child, rx)
}

/// An adaptive method's own steps are in the notice (issue 43, F4): dopri5 at rtol 1e-14,
/// sampled every 100 s over 10⁹ s, says it takes hours within 3 s (main: after 23 s, the time of
/// its first block of 4096 samples), and its hours are those a short run of the same
/// configuration paces (within half to twice).
#[test]
fn an_adaptive_runs_notice_comes_at_once_with_the_hours_its_pace_gives() {
    let run = [
        "pendulum",
        "--methods",
        "dopri5",
        "--rtol",
        "1e-14",
        "--dt",
        "100",
    ];
    let started = Instant::now();
    let status = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(run)
        .args(["--duration", "2e4", "--no-record", "-q"])
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let paced_hours = started.elapsed().as_secs_f64() / 2e4 * 1e9 / 3600.0;
    let started = Instant::now();
    let (mut child, rx) = stderr_lines(&[&run[..], &["--duration", "1e9", "--no-record"]].concat());
    let notice = rx
        .iter()
        .find(|l| l.contains("this takes about"))
        .expect("a notice");
    let after = started.elapsed();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(after < Duration::from_secs(3), "{after:?}: {notice}");
    let words: Vec<&str> = notice.split(' ').collect();
    let at = words.iter().position(|w| *w == "h").expect(&notice);
    let hours: f64 =
        words[at - 1].parse::<f64>().unwrap() + words[at + 1].parse::<f64>().unwrap() / 60.0;
    let ratio = hours / paced_hours;
    assert!(
        (0.5..=2.0).contains(&ratio),
        "{notice}; a short run paces {paced_hours:.1} h"
    );
}

#[test]
fn a_long_run_whose_first_3d_window_is_the_long_part_says_so_at_once_with_its_size() {
    let dir = scratch_dir("notice");
    let out = dir.join("huge.rrd");
    // About 25 GB in its first 3D window alone; on main nothing was said for 40 s.
    let started = Instant::now();
    let (mut child, rx) = stderr_lines(&[
        "rope",
        "--nodes",
        "1000000",
        "--dt",
        "0.002",
        "--duration",
        "200",
        "--methods",
        "verlet",
        "-o",
        s(&out),
    ]);
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

/// Hair whose state takes gigabytes spends seconds building it and a second on each frame before
/// its pace can be judged: on a66978e the notice came after 3.9 s for 200,000 strands × 64 nodes
/// (1.8 GB) and not within 8 s for 10⁶ × 64. What its size alone makes it take is said before
/// the state is built.
#[test]
fn a_huge_hair_says_what_its_size_takes_before_building_its_state() {
    let dir = scratch_dir("notice-hair");
    let out = dir.join("hair.rrd");
    let started = Instant::now();
    let args = [
        "hair",
        "--strands",
        "200000",
        "--nodes",
        "64",
        "-o",
        s(&out),
    ];
    let (mut child, rx) = stderr_lines(&args);
    let mut notice = None;
    while let Ok(line) = rx.recv_timeout(Duration::from_secs(8).saturating_sub(started.elapsed())) {
        if line.contains("this takes") {
            notice = Some((line, started.elapsed()));
            break;
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let (line, after) = notice.expect("a notice within 8 s");
    assert!(after < Duration::from_secs(2), "{after:?}: {line}");
    // 200,000 × 64 nodes × 480 frames × 2 methods at 30 ns: at least about 6 min.
    assert!(
        line.contains("hair: this takes at least about ") && line.contains(" min "),
        "{line}"
    );
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
    // The notice, wrapped to 100 columns: its lines up to the one that ends it, joined.
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut first = String::new();
    for line in lines.by_ref().take(4) {
        first = format!("{first} {}", line.unwrap()).trim().to_string();
        if first.ends_with("done") {
            break;
        }
    }
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
