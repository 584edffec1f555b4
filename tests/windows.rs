//! `--window`: every sampled step of a window is in the recording once, whatever the windows
//! (overlapping each other or the always-kept first seconds), overlaps count once toward the cap,
//! and `-0` is the end of the run. Read back from the recording, on every scene.

mod common;

use common::{decode, physlab, s, scratch_dir};

/// The recording `args` write, run to completion.
fn recorded(dir: &std::path::Path, name: &str, args: &[&str]) -> common::Decoded {
    let out = dir.join(format!("{name}.rrd"));
    let mut all = args.to_vec();
    all.extend(["-q", "-o", s(&out)]);
    let (code, _, stderr) = physlab(&all);
    assert_eq!(code, 0, "{args:?}: {stderr}");
    decode(&out)
}

/// Per plotted series: no moment twice, and the rows of `entity` between `from` and `to`
/// seconds, which must be every sampled step there (`step` seconds apart).
fn check_once_and_whole(d: &common::Decoded, entity: &str, (from, to): (f64, f64), step: f64) {
    for (e, rows) in &d.scalars {
        let mut times: Vec<i64> = rows.iter().map(|r| r.0).collect();
        times.dedup();
        assert_eq!(times.len(), rows.len(), "{e}: a step logged twice");
    }
    let rows = &d.scalars[entity];
    let ns = |t: f64| (t * 1e9).round() as i64;
    let inside = rows
        .iter()
        .filter(|r| (ns(from)..=ns(to)).contains(&r.0))
        .count();
    let every = ((to - from) / step).round() as usize + 1;
    assert_eq!(
        inside, every,
        "{entity}: every step of {from}..{to} s, once"
    );
}

#[test]
fn overlapping_windows_log_each_step_once_on_every_scene() {
    let dir = scratch_dir("windows-overlap");
    // 20,000 steps: aggregated beyond the windows. On main, t = 55 s came three times and
    // the first 10 s twice.
    let windows = [
        "--window", "50:60", "--window", "50:60", "--window", "55:58",
    ];
    let first = ["--window", "0:10"];
    let mut args = vec!["pendulum", "--dt", "0.005", "--duration", "100"];
    args.extend(windows.iter().chain(&first));
    let d = recorded(&dir, "pendulum", &args);
    check_once_and_whole(&d, "/pendulum/plots/energy/verlet", (50.0, 60.0), 0.005);
    check_once_and_whole(&d, "/pendulum/plots/energy/verlet", (0.0, 10.0), 0.005);

    let mut args = vec!["rope", "--nodes", "4", "--dt", "0.002", "--duration", "100"];
    args.extend(["--plot-every", "1", "--methods", "verlet"].iter());
    args.extend(windows.iter().chain(&first));
    let d = recorded(&dir, "rope", &args);
    check_once_and_whole(&d, "/rope/plots/energy/verlet", (50.0, 60.0), 0.002);
    check_once_and_whole(&d, "/rope/plots/energy/verlet", (0.0, 10.0), 0.002);

    // Hair ticks at 60 simulation frames a second: 12,000 over 200 s.
    let mut args = vec!["hair", "--strands", "2", "--duration", "200"];
    args.extend(["--methods", "verlet"].iter().chain(&windows).chain(&first));
    let d = recorded(&dir, "hair", &args);
    let entity = d
        .scalars
        .keys()
        .find(|e| e.starts_with("/hair/plots/") && !e.contains("log10"))
        .expect("a hair plot")
        .clone();
    check_once_and_whole(&d, &entity, (50.0, 60.0), 1.0 / 60.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn overlaps_count_once_toward_the_window_cap() {
    let dir = scratch_dir("windows-cap");
    // 80,001 rows per lane, twice over: 160,002 counted on main, past the 100,000 cap.
    let d = recorded(
        &dir,
        "p",
        &[
            "pendulum",
            "--dt",
            "0.001",
            "--duration",
            "200",
            "--methods",
            "verlet",
            "--window",
            "100:180",
            "--window",
            "100:180",
        ],
    );
    check_once_and_whole(&d, "/pendulum/plots/energy/verlet", (100.0, 180.0), 0.001);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn minus_zero_is_the_end_of_the_run() {
    let dir = scratch_dir("windows-minus-zero");
    let base = [
        "pendulum",
        "--dt",
        "0.005",
        "--duration",
        "100",
        "--methods",
        "verlet",
    ];
    // Refused on main (its end read as t = 0, before its start).
    let mut args = base.to_vec();
    args.push("--window=-5:-0");
    let d = recorded(&dir, "last", &args);
    check_once_and_whole(&d, "/pendulum/plots/energy/verlet", (95.0, 100.0), 0.005);
    // `-0:` is the end alone, not the whole run (as main read it): the middle stays aggregated.
    let mut args = base.to_vec();
    args.push("--window=-0:");
    let d = recorded(&dir, "end", &args);
    let middle = d.scalars["/pendulum/plots/energy/verlet"]
        .iter()
        .filter(|r| (30_000_000_000..=60_000_000_000).contains(&r.0))
        .count();
    assert!(middle < 3000, "{middle} of 6001 steps of 30..60 s kept");
    std::fs::remove_dir_all(&dir).unwrap();
}
