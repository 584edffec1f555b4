//! The edges, each tried as a class of values: out-of-range inputs refused by name,
//! contradictory output options refused, a missing viewer costing no file, scene files that do
//! not apply refused, study guards, and no figures shown for a method that failed at once.

#![cfg(feature = "rerun")]

mod common;

use common::{assert_refused, physlab, scratch_dir};

#[test]
fn magnitudes_beyond_the_physics_are_refused_by_name() {
    let dir = scratch_dir("edges-range");
    let out = dir.join("x.rrd");
    for (scene, args, message) in [
        (
            "pendulum",
            &["--length", "1e155"][..],
            "--length 1e155: must be between",
        ),
        (
            "pendulum",
            &["--length", "1e-300"],
            "--length 1e-300: must be between",
        ),
        (
            "pendulum",
            &["--gravity", "1e9"],
            "--gravity 1e9: must be between",
        ),
        (
            "pendulum",
            &["--omega0", "1e300"],
            "must be between -1e6 and 1e6",
        ),
        ("pendulum", &["--omega0=-inf"], "--omega0 -inf"),
        ("rope", &["--end", "1e300,0,0"], "--end"),
        ("rope", &["--start", "0,-1e7,0"], "within ±1e6"),
        ("rope", &["--gravity", "0,nan,0"], "expected x,y,z"),
        (
            "rope",
            &["--stiffness", "0"],
            "--stiffness 0: must be between 1e-6",
        ),
        ("rope", &["--mass", "1e9"], "--mass 1e9: must be between"),
        (
            "rope",
            &["--air-drag", "1e7"],
            "--air-drag 1e7: must be between 0",
        ),
    ] {
        assert_refused(scene, &out, args, message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn any_angle_is_the_same_pendulum_modulo_a_turn() {
    // 181° is the release from -179°, which the closed form covers; so is 541° and -539°.
    for theta0 in ["181", "541", "-539", "359999.5"] {
        let (code, stdout, stderr) = physlab(&[
            "pendulum",
            "--theta0",
            theta0,
            "--duration",
            "1",
            "--print-config",
        ]);
        assert_eq!(code, 0, "{theta0}: {stderr}");
        assert!(stdout.contains("theta0"), "{stdout}");
    }
    let dir = scratch_dir("edges-wrap");
    let out = dir.join("p.rrd");
    let (code, stdout, stderr) = physlab(&[
        "pendulum",
        "--theta0",
        "541",
        "--duration",
        "1",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("θ0 = -179°"), "{stdout}");
    assert!(stdout.contains("exact: closed form"), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn output_options_that_contradict_each_other_are_refused() {
    let dir = scratch_dir("edges-output");
    let out = dir.join("x.rrd");
    for (scene, args, message) in [
        ("pendulum", &["--no-save"][..], "--no-save with -o"),
        ("rope", &["--no-save"], "--no-save with -o"),
        ("hair", &["--no-record"], "--no-record with -o/--output"),
    ] {
        assert_refused(scene, &out, args, message);
    }
    for args in [
        &["hair", "--no-record", "--connect"][..],
        &["hair", "--no-record", "--spawn"],
        &["hair", "--no-record", "--timings"],
        &["pendulum", "--no-save"],
    ] {
        let (code, _, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: --no-"), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_viewer_costs_no_recording() {
    let dir = scratch_dir("edges-viewer");
    let out = dir.join("sub/p.rrd");
    // Nothing listens on port 1.
    let (code, _, stderr) = physlab(&[
        "pendulum",
        "--duration",
        "0.5",
        "-q",
        "--connect",
        "rerun+http://127.0.0.1:1/proxy",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("no viewer answers there; writing the file only"),
        "{stderr}"
    );
    assert!(common::decode(&out).has_footer);
    // Without a file there is nothing to keep: refused, not silently dropped.
    let (code, _, stderr) = physlab(&[
        "pendulum",
        "--duration",
        "0.5",
        "--no-save",
        "--connect",
        "rerun+http://127.0.0.1:1/proxy",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("--no-save leaves nothing to write"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scene_files_that_do_not_apply_are_refused_and_their_errors_name_the_key() {
    let dir = scratch_dir("edges-config");
    let out = dir.join("x.rrd");
    let pendulum_only = dir.join("p.toml");
    std::fs::write(&pendulum_only, "[pendulum]\ntheta0 = 30.0\n").unwrap();
    for scene in ["rope", "hair"] {
        assert_refused(
            scene,
            &out,
            &["--config", pendulum_only.to_str().unwrap()],
            &format!("has no [{scene}] table"),
        );
    }
    for (table, key, message) in [
        ("rope", "nodes = 1", "[rope] nodes = 1: must be between 2"),
        ("rope", "mass = 0.0", "[rope] mass = 0: must be between"),
        (
            "pendulum",
            "dt = -1.0",
            "[pendulum] dt = -1: must be a finite number > 0",
        ),
        (
            "hair",
            "strands = 0",
            "[hair] strands = 0: must be between 1",
        ),
    ] {
        let file = dir.join(format!("{table}.toml"));
        std::fs::write(&file, format!("[{table}]\n{key}\n")).unwrap();
        assert_refused(table, &out, &["--config", file.to_str().unwrap()], message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_study_refuses_foreign_flags_and_runs_that_cannot_fit() {
    for (args, message) in [
        (
            &["convergence", "--nodes", "9"][..],
            "--nodes is a rope parameter",
        ),
        (
            &["stability", "--stiffness", "10"],
            "--stiffness is a rope parameter",
        ),
        (
            &["convergence", "--scene", "rope", "--theta0", "10"],
            "--theta0 is a pendulum parameter",
        ),
        (
            &["convergence", "--dt", "5"],
            "must not exceed --duration / 16",
        ),
        (
            &["work-precision", "--dt", "1", "--duration", "10"],
            "must not exceed --duration / 16",
        ),
        (
            &["convergence", "--dt", "1e-9"],
            "reference steps; at most 1e9",
        ),
        (
            &["convergence", "--dt", "1e-4", "--levels", "20"],
            "reference steps; at most 1e9",
        ),
    ] {
        let mut all = vec!["study"];
        all.extend_from_slice(args);
        let (code, _, stderr) = physlab(&all);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
}

#[test]
fn the_study_takes_the_schedule_and_methods_from_the_scene_file() {
    let dir = scratch_dir("edges-study-file");
    let file = dir.join("s.toml");
    std::fs::write(
        &file,
        "[pendulum]\ndt = 0.04\nduration = 6.4\nmethods = [\"rk4\", \"verlet\"]\n",
    )
    .unwrap();
    let (code, stdout, stderr) = physlab(&[
        "study",
        "convergence",
        "--levels",
        "3",
        "--config",
        file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("sampled every 0.64 s over 6.4 s"),
        "{stdout}"
    );
    assert!(
        stdout.contains("| rk4") && stdout.contains("| verlet"),
        "{stdout}"
    );
    assert!(!stdout.contains("| midpoint"), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_method_that_fails_its_first_check_shows_no_figures() {
    let dir = scratch_dir("edges-failed");
    let out = dir.join("p.rrd");
    // dt = 5 s: every explicit method's first step already breaks the energy bound.
    let (code, stdout, stderr) = physlab(&[
        "pendulum",
        "--dt",
        "5",
        "--duration",
        "20",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let row = |name: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(&format!("| {name} ")))
            .unwrap_or_else(|| panic!("no row for {name}:\n{stdout}"))
            .to_string()
    };
    for name in ["explicit-euler", "midpoint", "verlet"] {
        let cells: Vec<String> = row(name).split('|').map(|c| c.trim().to_string()).collect();
        // | method | steps | evals | wall | ns | max θ error | max ΔE | ...
        assert_eq!(cells[2], "1", "{name}: one step taken, the one that failed");
        assert_eq!(cells[6], "—", "{name}: no θ error to show");
        assert_eq!(cells[7], "—", "{name}: no energy error to show");
        assert!(cells[10].starts_with("yes"), "{name}: {cells:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tiny_amplitudes_are_the_small_oscillations_they_are() {
    use physlab::scene::harness::{NoObserver, run};
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};
    for degrees in [1e-3, 1e-6, 1e-9, -1e-12] {
        let mut config = PendulumConfig::default();
        config.params.theta0 = f64::to_radians(degrees);
        let mut scene = PendulumScene::new(config);
        assert!(scene.initial_energy > 0.0, "{degrees}°: E0 > 0");
        let period = scene.exact_period.expect("a swing has a period");
        let small = 2.0 * std::f64::consts::PI / scene.config.params.omega_n();
        assert!(
            (period / small - 1.0).abs() < 1e-9,
            "{degrees}°: {period} vs {small}"
        );
        let r = run(&mut scene, &mut NoObserver).unwrap();
        // The exact solution's own energy error is round-off, not 1 - cos θ's cancellation; RK4's
        // real error (~6e-10 at dt = 0.01 s) stands well above it.
        let error = |name: &str| {
            let i = r.stats.iter().position(|s| s.name == name).unwrap();
            r.lanes[i].max_energy_error
        };
        assert!(
            error("exact") < 1e-13,
            "{degrees}°: exact {:e}",
            error("exact")
        );
        assert!(
            error("rk4") > 1e3 * error("exact") && error("rk4") < 1e-8,
            "{degrees}°: rk4 {:e}",
            error("rk4")
        );
    }
}

#[test]
fn steps_and_evaluations_are_counted_up_to_divergence() {
    use physlab::integrate::{EvalsPerStep, Method};
    use physlab::scene::harness::{NoObserver, run};
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};
    let mut diverged = 0;
    for dt in [0.6, 1.0, 2.0, 5.0] {
        let config = PendulumConfig {
            dt,
            duration: 20.0 * dt,
            ..PendulumConfig::default()
        };
        let r = run(&mut PendulumScene::new(config), &mut NoObserver).unwrap();
        for s in r.stats.iter().filter(|s| s.divergence.is_some()) {
            let m: Method = s.name.parse().unwrap();
            if let EvalsPerStep::Fixed(k) = m.info().evals_per_step {
                // Verlet's start costs one more evaluation.
                let start = u64::from(m == Method::Verlet);
                assert_eq!(
                    s.counts.evals,
                    s.ticks_taken() * u64::from(k) + start,
                    "{} at dt {dt}: {} steps",
                    s.name,
                    s.ticks_taken()
                );
                diverged += 1;
            }
        }
    }
    assert!(
        diverged >= 4,
        "the class was tried ({diverged} diverging lanes)"
    );
}

#[test]
fn implicit_euler_warns_when_its_step_equation_has_several_roots() {
    let dir = scratch_dir("edges-roots");
    let out = dir.join("p.rrd");
    // dt² g/L with the default g = 9.81, L = 3.521: 0.70, 1.003, 2.79, 69.7.
    for (dt, warned) in [("0.5", false), ("0.6", true), ("1", true), ("5", true)] {
        let (code, stdout, stderr) = physlab(&[
            "pendulum",
            "--dt",
            dt,
            "--duration",
            "20",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert_eq!(
            stdout.contains("has several roots"),
            warned,
            "dt {dt}:\n{stdout}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A negative value written after its flag with a space is that flag's value, in every form a
/// number takes (exponent, sign, lists), for every scene; a real flag after an option that
/// lacks its value is still a flag.
#[test]
fn negative_values_in_any_number_form_are_values() {
    for (args, expect) in [
        (&["pendulum", "--theta0", "-1e-3"][..], "θ0 = -0.001°"),
        (&["pendulum", "--omega0", "-2.5E-1"], "ω0 = -0.25 rad/s"),
        (&["pendulum", "--theta0", "-.5"], "θ0 = -0.5°"),
        (&["hair", "--wind", "-1e1,0,-2"], "wind [-10.0, 0.0, -2.0]"),
    ] {
        let mut all = args.to_vec();
        all.extend(["--duration", "0.1", "--no-record", "-q"]);
        let (code, stdout, stderr) = physlab(&all);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        assert!(
            stdout.contains(expect),
            "{args:?}: lacks '{expect}':\n{stdout}"
        );
    }
    let (code, _, stderr) = physlab(&["pendulum", "--dt", "-o", "x.rrd"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("a value is required for '--dt"), "{stderr}");
}
