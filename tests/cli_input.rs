//! Input that would be ignored or is out of any meaningful range is refused: each case is the
//! command line, exit code 2 and a fragment of the one-line message, which names the flag (or
//! the file and key), the value and what is allowed.

#![cfg(feature = "rerun")]

mod common;

use common::{peak_memory, physlab, scratch_dir};

/// Runs each case and checks its exit code 2 and message fragment.
fn refused(cases: &[(Vec<&str>, String)]) {
    for (args, message) in cases {
        let (code, stdout, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(message.as_str()), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stdout.is_empty(), "{args:?} printed {stdout}");
    }
}

/// Which study kinds use each flag, written from what each study measures (not read from the
/// code): convergence and work-precision sweep a start over halved steps (and the adaptive
/// methods over tolerances, timing repeats); stability bisects the linearised problem (no start,
/// no damping, no schedule: `--steps` per trial); hair runs the hair scene's defaults over
/// `--duration` and draws no diagram. Every flag given to a kind that does not use it is refused.
#[test]
fn every_study_flag_is_used_or_refused_by_kind() {
    const KINDS: [&str; 4] = ["convergence", "work-precision", "stability", "hair"];
    let sweep = &["convergence", "work-precision"][..];
    let measured = &["convergence", "work-precision", "stability"][..];
    let flags: [(&[&str], &[&str]); 17] = [
        (&["--scene", "rope"], measured),
        (&["--config", "s.toml"], measured),
        (&["--theta0", "10"], sweep),
        (&["--omega0", "1"], sweep),
        (&["--scene", "rope", "--nodes", "9"], measured),
        (&["--scene", "rope", "--mass", "1"], measured),
        (&["--scene", "rope", "--stiffness", "10"], measured),
        (&["--scene", "rope", "--spring-damping", "1"], sweep),
        (&["--scene", "rope", "--air-drag", "1"], sweep),
        (
            &["--duration", "5"],
            &["convergence", "work-precision", "hair"],
        ),
        (&["--dt", "0.01"], sweep),
        (&["--levels", "3"], sweep),
        (&["--methods", "rk4"], measured),
        (&["--rtol", "1e-6"], sweep),
        (&["--repeats", "2"], sweep),
        (&["--steps", "100"], &["stability"]),
        (&["--plots", "plots"], measured),
    ];
    let mut cases = Vec::new();
    for (args, users) in flags {
        let flag = *args.iter().rfind(|a| a.starts_with("--")).unwrap();
        for kind in KINDS.iter().filter(|k| !users.contains(k)) {
            // The first flag a kind does not take is the one named (`--scene` for hair).
            let named = if *kind == "hair" { args[0] } else { flag };
            let mut all = vec!["study", kind];
            all.extend_from_slice(args);
            cases.push((all, format!("{named}: `study {kind}` does not use it")));
        }
    }
    assert_eq!(
        cases.len(),
        27,
        "the table covers every flag a kind leaves out"
    );
    refused(&cases);
}

/// Tolerances with no adaptive method to take them, and empty method lists from a flag or a
/// scene file, for the study and for every scene.
#[test]
fn tolerances_without_an_adaptive_method_and_empty_method_lists_are_refused() {
    let dir = scratch_dir("cli-input-methods");
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let pendulum = file("p.toml", "[pendulum]\nmethods = []\n");
    let rope = file("r.toml", "[rope]\nmethods = []\n");
    let hair = file("h.toml", "[hair]\nmethods = []\n");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec![
                "study",
                "convergence",
                "--methods",
                "rk4,verlet",
                "--rtol",
                "1e-6",
            ],
            "--rtol: no adaptive method among --methods (rk4,verlet)".into(),
        ),
        (
            vec![
                "study",
                "work-precision",
                "--methods",
                "rk4",
                "--rtol",
                "1e-6",
            ],
            "--rtol: no adaptive method".into(),
        ),
        (
            vec!["study", "convergence", "--config", &pendulum],
            "[pendulum] methods = []: lists no method".into(),
        ),
        (
            vec!["study", "stability", "--scene", "rope", "--config", &rope],
            "[rope] methods = []: lists no method".into(),
        ),
        (
            vec!["pendulum", "--config", &pendulum, "--no-record"],
            "[pendulum] methods = []: lists no method".into(),
        ),
        (
            vec!["rope", "--config", &rope, "--no-record"],
            "[rope] methods = []: lists no method".into(),
        ),
        (
            vec!["hair", "--config", &hair, "--no-record"],
            "[hair] methods = []: lists no method".into(),
        ),
    ];
    refused(&cases);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Which methods read each method-specific scene flag, written from what each method does (not
/// read from the code): only verlet has a damping factor; only the error-controlled pairs take a
/// tolerance; only implicit Euler solves with Newton; of the hair methods only verlet has a
/// constraint solver with iterations, and only the spring methods have springs. Given without a
/// method that reads it, each flag is refused; with one, the run goes ahead. A scene file's key is
/// not refused (files state every parameter): the same value from a file runs.
#[test]
fn every_scene_flag_a_method_reads_is_refused_without_that_method() {
    let hair_run = ["--strands", "2", "--duration", "0.05"];
    let cases: [(&str, &str, &str, &str, &str); 10] = [
        (
            "pendulum",
            "--verlet-damping",
            "0.1",
            "rk4,dopri5",
            "verlet",
        ),
        ("pendulum", "--rtol", "1e-6", "rk4,verlet", "vern9"),
        ("rope", "--verlet-damping", "0.1", "rk4", "verlet"),
        ("rope", "--rtol", "1e-6", "implicit-euler", "dop853"),
        (
            "rope",
            "--newton-iterations",
            "3",
            "rk4,verlet",
            "implicit-euler",
        ),
        (
            "hair",
            "--solver",
            "gauss-seidel",
            "ftl,semi-implicit-euler",
            "verlet",
        ),
        ("hair", "--iterations", "3", "ftl,implicit-euler", "verlet"),
        (
            "hair",
            "--stiffness",
            "1e9",
            "verlet,ftl",
            "semi-implicit-euler",
        ),
        ("hair", "--stiffness", "1e9", "verlet", "implicit-euler"),
        ("hair", "--spring-damping", "10", "ftl", "implicit-euler"),
    ];
    let dir = scratch_dir("cli-input-method-flags");
    let mut refusals = Vec::new();
    for (scene, flag, value, without, with) in cases {
        let mut args = vec![scene, "--methods", without, flag, value, "--no-record"];
        if scene == "hair" {
            args.extend(hair_run);
        }
        refusals.push((args, format!("{flag}: only ")));
        let mut run = vec![scene, "--methods", with, flag, value, "--no-record", "-q"];
        run.extend(if scene == "hair" {
            &hair_run[..]
        } else {
            &["--duration", "0.5"][..]
        });
        let (code, _, stderr) = physlab(&run);
        assert_eq!(code, 0, "{run:?}: {stderr}");
        // The same value in a scene file, beside methods that do not read it, runs.
        let key = flag.trim_start_matches("--").replace('-', "_");
        let quoted = if value.parse::<f64>().is_ok() {
            value.to_string()
        } else {
            format!("\"{value}\"")
        };
        let path = dir.join(format!("{scene}-{key}.toml"));
        std::fs::write(&path, format!("[{scene}]\n{key} = {quoted}\n")).unwrap();
        let mut from_file = vec![
            scene,
            "--methods",
            without,
            "--config",
            path.to_str().unwrap(),
        ];
        from_file.extend(["--no-record", "-q"]);
        from_file.extend(if scene == "hair" {
            &hair_run[..]
        } else {
            &["--duration", "0.5"][..]
        });
        let (code, _, stderr) = physlab(&from_file);
        assert_eq!(code, 0, "{from_file:?}: {stderr}");
    }
    refused(&refusals);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Flags that set only what a recording draws are refused with --no-record, for every scene and
/// for `all`.
#[test]
fn drawing_flags_are_refused_when_nothing_is_recorded() {
    let mut cases = Vec::new();
    for scene in ["pendulum", "rope", "all"] {
        for flag in ["--fps", "--plot-every"] {
            cases.push((
                vec![scene, flag, "3", "--no-record"],
                format!("--no-record with {flag}: {flag} sets what the recording draws"),
            ));
        }
    }
    cases.push((
        vec!["hair", "--fps", "3", "--no-record"],
        "--no-record with --fps".to_string(),
    ));
    refused(&cases);
}

/// Angles beyond the stated number of turns (or not finite) are refused by their value; within
/// it any angle is accepted and wrapped.
#[test]
fn angles_are_bounded_by_a_stated_number_of_turns() {
    let mut cases = Vec::new();
    // (`-inf` is not a number clap takes after a space: it is given with `=`.)
    for (value, shown) in [
        (&["--theta0", "inf"][..], "inf"),
        (&["--theta0=-inf"], "-inf"),
        (&["--theta0", "nan"], "NaN"),
        (&["--theta0", "1e300"], "1e300"),
        (&["--theta0", "1e20"], "1e20"),
        (&["--theta0", "360001"], "360001"),
        (&["--theta0", "-360000.5"], "-360000.5"),
    ] {
        for command in [&["pendulum"][..], &["study", "convergence"]] {
            let mut all = command.to_vec();
            all.extend_from_slice(value);
            cases.push((
                all,
                format!("--theta0 {shown}: must be a finite angle within ±1000 turns"),
            ));
        }
    }
    refused(&cases);
    for value in ["360000", "-359999.99", "181", "-539"] {
        let (code, stdout, stderr) = physlab(&["pendulum", "--theta0", value, "--print-config"]);
        assert_eq!(code, 0, "{value}: {stderr}");
        let line = stdout.lines().find(|l| l.starts_with("theta0")).unwrap();
        let printed: f64 = line.split('=').nth(1).unwrap().trim().parse().unwrap();
        assert_eq!(printed, value.parse::<f64>().unwrap(), "{line}");
    }
}

/// Values in messages are shown as a person writes them: no run of hundreds of digits.
#[test]
fn tiny_and_huge_values_are_shown_in_exponent_form() {
    let mut cases = Vec::new();
    for value in ["1e-300", "1e300", "5e-15"] {
        cases.push((
            vec!["study", "work-precision", "--rtol", value],
            format!("--rtol {value}: must be between 1e-14 and 0.1"),
        ));
        cases.push((
            vec!["pendulum", "--methods", "dopri5", "--rtol", value],
            format!("--rtol {value}: must be between 1e-14 and 0.1"),
        ));
    }
    cases.push((
        vec!["pendulum", "--verlet-damping", "1e-300"],
        String::new(),
    ));
    for (args, message) in &cases[..cases.len() - 1] {
        let (code, _, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(message.as_str()), "{args:?}: {stderr}");
        assert!(!stderr.contains("00000000"), "{args:?}: {stderr}");
    }
    let (code, _, stderr) = physlab(&["pendulum", "--verlet-damping", "2e300"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--verlet-damping 2e300"), "{stderr}");
}

/// Worker threads are bounded by a stated multiple of the cores; counts and indices that cannot
/// be negative say so, naming the flag and the value.
#[test]
fn counts_are_bounded_and_negative_counts_named() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let max = 4 * cores;
    let too_many = (max + 1).to_string();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["hair", "--threads", "0", "--no-record"],
            format!("--threads 0: must be between 1 and {max} (4 × the {cores} cores here)"),
        ),
        (
            vec!["hair", "--threads", &too_many, "--no-record"],
            format!("--threads {too_many}: must be between 1 and {max}"),
        ),
        (
            vec!["hair", "--threads", "100000", "--no-record"],
            "--threads 100000: must be between 1 and".into(),
        ),
        (
            vec!["rope", "--pinned", "-1"],
            "--pinned -1: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["rope", "--pinned", "0,-3"],
            "--pinned -3: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["rope", "--nodes", "-5"],
            "--nodes -5: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["hair", "--threads", "-2"],
            "--threads -2: must be a whole number ≥ 0".into(),
        ),
        (
            vec!["study", "stability", "--steps", "-100"],
            "--steps -100: must be a whole number ≥ 0".into(),
        ),
    ];
    for (args, message) in &cases {
        let (code, _, stderr) = physlab(args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(message.as_str()), "{args:?}: {stderr}");
    }
    // At the bound the run goes ahead.
    let at_max = max.to_string();
    let (code, _, stderr) = physlab(&[
        "hair",
        "--threads",
        &at_max,
        "--strands",
        "8",
        "--duration",
        "0.1",
        "--no-record",
        "-q",
    ]);
    assert_eq!(code, 0, "{stderr}");
}

/// The rope's memory estimate (what the memory guard refuses on and what a run says up front)
/// against the peak resident memory the kernel measures, for every method alone and for the
/// default set: within 10 % of the measured growth over a 2-node run.
#[test]
fn the_ropes_memory_estimate_is_the_memory_it_takes() {
    use physlab::integrate::Method;
    use physlab::scene::rope::run::RopeConfig;
    let nodes = 400_000;
    let base = peak_memory(&[
        "rope",
        "-q",
        "--no-record",
        "--nodes",
        "2",
        "--duration",
        "0.002",
    ]);
    let default: Vec<Method> = Method::DEFAULT.to_vec();
    let mut sets: Vec<Vec<Method>> = Method::ALL.iter().map(|&m| vec![m]).collect();
    sets.push(default);
    for methods in sets {
        let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
        let list = names.join(",");
        let n = nodes.to_string();
        let measured = peak_memory(&[
            "rope",
            "-q",
            "--no-record",
            "--nodes",
            &n,
            "--duration",
            "0.002",
            "--methods",
            &list,
        ]) - base;
        let mut config = RopeConfig {
            methods,
            ..RopeConfig::default()
        };
        config.params.nodes = nodes;
        let estimate = config.memory_bytes();
        assert!(
            (estimate / measured - 1.0).abs() < 0.10,
            "{list}: estimate {estimate:.3e} B, measured {measured:.3e} B"
        );
    }
}

/// A run whose state takes more than a gigabyte says so, with the estimate, before it starts;
/// a small one does not.
#[test]
fn a_run_that_takes_a_lot_of_memory_says_so_up_front() {
    let big = [
        "rope",
        "--no-record",
        "--nodes",
        "1000000",
        "--duration",
        "0.001",
    ];
    let (code, _, stderr) = physlab(&big);
    assert_eq!(code, 0, "{stderr}");
    let notice = stderr.lines().next().unwrap_or_default();
    assert!(
        notice.starts_with("rope: its state takes about 1.3 GB of memory"),
        "{stderr}"
    );
    let (code, _, stderr) = physlab(&["rope", "--no-record", "--duration", "0.01"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("of memory"), "{stderr}");
}
