//! The binary end to end: exit code, summary, and the recording read back
//! with Rerun's own decoder.

#![cfg(feature = "rerun")]

mod common;

use std::collections::BTreeMap;

use clap::Parser as _;
use physlab::app::config_from_flags;
use physlab::cli::{Cli, Command as Sub};
use physlab::scene::harness::{Observer, SeriesBatch, run};
use physlab::scene::pendulum::run::PendulumScene;

use common::{assert_refused, decode, physlab, scratch_dir};

/// Collects each lane's θ series, and its |θ − θref| where it has one, as the library reports
/// them.
#[derive(Default)]
struct ThetaCollector(
    BTreeMap<usize, Vec<(u64, f64)>>,
    BTreeMap<usize, Vec<(u64, f64)>>,
);
impl Observer<PendulumScene> for ThetaCollector {
    fn series(&mut self, _: &PendulumScene, lane: usize, b: &SeriesBatch) -> anyhow::Result<()> {
        let rows = self.0.entry(lane).or_default();
        rows.extend(b.ticks.iter().copied().zip(b.columns[0].iter().copied()));
        let theta_error = physlab::scene::pendulum::run::QUANTITIES
            .iter()
            .position(|q| *q == "theta_error")
            .unwrap();
        if let Some(errors) = b.columns.get(theta_error) {
            let rows = self.1.entry(lane).or_default();
            rows.extend(b.ticks.iter().copied().zip(errors.iter().copied()));
        }
        Ok(())
    }
}

#[test]
fn pendulum_run_writes_a_complete_recording_whose_theta_equals_the_simulation() {
    let dir = scratch_dir("e2e");
    let out = dir.join("sub/p.rrd");
    let args = [
        "pendulum",
        "--duration",
        "3",
        "--theta0",
        "75",
        "-o",
        out.to_str().unwrap(),
    ];
    // `physlab` also asserts that nothing panicked.
    let (code, stdout, stderr) = physlab(&args);
    assert_eq!(code, 0, "stdout:\n{stdout}\nstderr:\n{stderr}");

    let methods = [
        "explicit-euler",
        "semi-implicit-euler",
        "implicit-euler",
        "midpoint",
        "trapezoid",
        "rk4",
        "verlet",
    ];
    for lane in std::iter::once("exact").chain(methods) {
        assert!(
            stdout.lines().any(|l| l.starts_with(&format!("| {lane} "))),
            "summary row for {lane}:\n{stdout}"
        );
    }
    assert!(
        stdout.contains("T = 4.212040767") && stdout.contains("recording: "),
        "{stdout}"
    );
    // No temporary file is left beside the recording.
    let leftovers: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers, vec![std::ffi::OsString::from("p.rrd")]);

    let d = decode(&out);
    assert!(d.has_footer, "the recording is finalised with a footer");
    for lane in std::iter::once("exact").chain(methods) {
        for part in ["pivot", "rod", "bob"] {
            assert!(
                d.entities.contains(&format!("/pendulum/{lane}/{part}")),
                "missing /pendulum/{lane}/{part}"
            );
        }
        for q in ["theta", "omega", "energy", "log10_energy_error"] {
            assert!(
                d.scalars
                    .contains_key(&format!("/pendulum/plots/{q}/{lane}")),
                "missing plot {q}/{lane}"
            );
        }
        assert!(d.entities.contains(&format!("/pendulum/phase/{lane}/path")));
    }
    for m in methods {
        assert!(
            d.scalars
                .contains_key(&format!("/pendulum/plots/log10_theta_error/{m}"))
        );
        assert!(d.entities.contains(&format!("/pendulum/{m}/exact_ghost")));
    }
    assert!(d.entities.contains("/pendulum/events") && d.entities.contains("/pendulum/about"));

    // The θ series in the file equals the library's, value for value, at the same times.
    let Sub::Pendulum(parsed) = Cli::parse_from(std::iter::once("physlab").chain(args)).command
    else {
        unreachable!()
    };
    let config: physlab::scene::pendulum::run::PendulumConfig =
        config_from_flags(&parsed.scene, "pendulum").unwrap();
    let mut collected = ThetaCollector::default();
    let dt = config.dt;
    let summary = run(&mut PendulumScene::new(config), &mut collected).unwrap();
    for (lane, rows) in &collected.0 {
        let name = summary.stats[*lane].name;
        let recorded = &d.scalars[&format!("/pendulum/plots/theta/{name}")];
        assert_eq!(recorded.len(), rows.len(), "{name}: row count");
        for (&(t_ns, v), &(step, theta)) in recorded.iter().zip(rows) {
            let expected_ns = (step as f64 * dt * 1e9).round() as i64;
            assert!(
                (t_ns - expected_ns).abs() <= 1,
                "{name}: time {t_ns} ns vs step {step}"
            );
            assert_eq!(
                v.to_bits(),
                theta.to_bits(),
                "{name} at step {step}: {v} vs {theta}"
            );
        }
    }
    // The error is plotted as log10 |θ − θref|, zeros (the start) left out: value for value.
    assert_eq!(collected.1.len(), methods.len());
    for (lane, rows) in &collected.1 {
        let name = summary.stats[*lane].name;
        let recorded = &d.scalars[&format!("/pendulum/plots/log10_theta_error/{name}")];
        let expected: Vec<(u64, f64)> = rows
            .iter()
            .filter(|r| r.1 != 0.0)
            .map(|&(s, e)| (s, e.abs().log10()))
            .collect();
        assert!(expected.len() + 1 >= rows.len() && expected.len() > 100);
        assert_eq!(recorded.len(), expected.len(), "{name}: log10 row count");
        for (&(t_ns, v), &(step, log_e)) in recorded.iter().zip(&expected) {
            assert!((t_ns - (step as f64 * dt * 1e9).round() as i64).abs() <= 1);
            assert_eq!(v.to_bits(), log_e.to_bits(), "{name} at step {step}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_is_refused_with_exit_code_2_and_a_clear_message() {
    let dir = scratch_dir("bad");
    let out = dir.join("p.rrd");
    let cases: [(&[&str], &str); 6] = [
        (&["--dt", "0"], "--dt 0: must be a finite number > 0"),
        (
            &["--length", "-1"],
            "--length -1: must be between 1e-6 and 1e6 [m]",
        ),
        (
            &["--dt", "2", "--duration", "1"],
            "must not exceed --duration",
        ),
        (&["--dt", "1e-12"], "at most 1e9"),
        (&["--methods", "rk5"], "unknown method 'rk5'"),
        (
            &["--verlet-damping", "1"],
            "--verlet-damping 1: must be in [0, 1)",
        ),
    ];
    for (extra, message) in cases {
        assert_refused("pendulum", &out, extra, message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dash_output_streams_the_recording_to_stdout_and_the_summary_to_stderr() {
    let dir = scratch_dir("stdout");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(["pendulum", "--duration", "2", "-q", "-o", "-"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("| rk4 ") && stderr.contains("recording written to standard output"),
        "{stderr}"
    );
    // Standard output is the recording itself, footer included, and no file named `-` appears.
    let rrd = dir.join("piped.rrd");
    std::fs::write(&rrd, &out.stdout).unwrap();
    let d = decode(&rrd);
    assert!(d.has_footer && d.scalars.contains_key("/pendulum/plots/theta/rk4"));
    assert!(!std::path::Path::new("-").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn no_record_is_a_run_flag_of_every_scene() {
    for scene in ["pendulum", "rope"] {
        let (code, stdout, stderr) = physlab(&[scene, "--duration", "0.5", "-q", "--no-record"]);
        assert_eq!(code, 0, "{stderr}");
        assert!(stdout.contains("no recording (--no-record)"), "{stdout}");
    }
}

/// An adaptive method's own steps are shown beside the dt grid it is sampled on, and they are
/// the steps it paid for: Dormand–Prince 5(4) is FSAL, so every step tried (accepted or
/// rejected) costs 6 evaluations after the first step's extra one, and its dense output none.
#[test]
fn adaptive_methods_show_their_own_steps_and_pay_six_evaluations_each() {
    for rtol in ["1e-4", "1e-8", "1e-11"] {
        let (code, stdout, stderr) = physlab(&[
            "pendulum",
            "--methods",
            "dopri5",
            "--rtol",
            rtol,
            "--no-record",
            "-q",
        ]);
        assert_eq!(code, 0, "{stderr}");
        let row = stdout
            .lines()
            .find(|l| l.starts_with("| dopri5 "))
            .unwrap_or_else(|| panic!("no dopri5 row:\n{stdout}"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        // "2000 (own: A + R rejected)"
        let own = cells[2]
            .split("own: ")
            .nth(1)
            .unwrap_or_else(|| panic!("no own steps in '{}'", cells[2]));
        let numbers: Vec<u64> = own
            .split(|c: char| !c.is_ascii_digit())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        let (accepted, rejected) = (numbers[0], numbers[1]);
        let evals: u64 = cells[3].parse().unwrap();
        assert!(cells[2].starts_with("2000 "), "{row}");
        assert!(accepted < 2000, "its steps are not the dt grid: {row}");
        assert_eq!(evals, 6 * (accepted + rejected) + 1, "rtol {rtol}: {row}");
        assert!(stdout.contains("ns/step is per own step"), "{stdout}");
    }
}
/// `--gravity` takes the rope's and hair's vector form too; the pendulum uses its length.
#[test]
fn pendulum_gravity_takes_a_number_or_the_vector_and_uses_its_length() {
    let gravity = |args: &[&str]| -> (i32, Option<f64>, String) {
        let mut all = vec!["pendulum"];
        all.extend_from_slice(args);
        all.push("--print-config");
        let (code, toml, stderr) = physlab(&all);
        let g = toml
            .parse::<toml::Table>()
            .ok()
            .and_then(|t| t.get("pendulum")?.get("gravity")?.as_float());
        (code, g, stderr)
    };
    assert_eq!(gravity(&[]).1, Some(9.81));
    assert_eq!(gravity(&["--gravity", "1.62"]).1, Some(1.62));
    assert_eq!(gravity(&["--gravity", "0,0,-9.81"]).1, Some(9.81));
    assert_eq!(gravity(&["--gravity", "3,0,-4"]).1, Some(5.0));
    let (code, _, stderr) = gravity(&["--gravity", "3,-4"]);
    assert!(
        code == 2 && stderr.contains("expected g or x,y,z"),
        "{stderr}"
    );
    let dir = scratch_dir("pendulum-gravity");
    let file = dir.join("p.toml");
    std::fs::write(&file, "[pendulum]\ngravity = [0.0, -3.0, -4.0]\n").unwrap();
    assert_eq!(gravity(&["--config", file.to_str().unwrap()]).1, Some(5.0));
    // Bad forms are refused naming the flag and what it takes.
    let (code, _, stderr) = gravity(&["--gravity", "1,2,3,4"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("--gravity") && stderr.contains("x,y,z"),
        "{stderr}"
    );
    let (code, _, stderr) = gravity(&["--gravity", "0,0,0"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--gravity 0"), "{stderr}");
}
