//! `physlab all`, scene files, provenance and `inspect`.

#![cfg(feature = "rerun")]

mod common;

use common::{canonical_rows, physlab, scratch_dir};

/// A scene file that keeps every scene short, so the determinism test runs in seconds.
const SMALL: &str = r#"
[pendulum]
duration = 4.0

[rope]
duration = 1.0
nodes = 8

[hair]
strands = 40
duration = 1.0
"#;

#[test]
fn all_writes_three_scenes_with_provenance_that_inspect_reads_back() {
    let dir = scratch_dir("all-provenance");
    let config = dir.join("small.toml");
    std::fs::write(&config, SMALL).unwrap();
    let out = dir.join("all.rrd");
    let (code, stdout, stderr) = physlab(&[
        "all",
        "--config",
        config.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("pendulum:") && stdout.contains("rope:") && stdout.contains("hair:"));
    assert!(
        stdout.contains(" MB)"),
        "the summary prints the file size:\n{stdout}"
    );

    let (code, info, stderr) = physlab(&[
        "inspect",
        out.to_str().unwrap(),
        "--config-out",
        dir.join("again.toml").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    for expected in [
        "scenes: hair, pendulum, rope",
        "Rerun SDK 0.36.3",
        &format!("physlab {}", env!("CARGO_PKG_VERSION")),
        "footer written",
        "pendulum: complete: t = 4 s",
        "sim_time: 0.000000 s to 4.000000 s",
        "/pendulum/rk4/bob",
        "/rope/plots/max_strain/verlet",
        "/hair/ftl/strands",
        "explicit-euler diverged",
    ] {
        assert!(
            info.contains(expected),
            "inspect lacks '{expected}':\n{info}"
        );
    }
    assert!(
        !info.contains("commit unknown") && info.contains("(commit "),
        "{info}"
    );
    // The embedded scene file is complete: every parameter resolved, not just the ones given.
    let again = std::fs::read_to_string(dir.join("again.toml")).unwrap();
    for key in [
        "[pendulum]",
        "theta0 = 60.0",
        "[rope]",
        "nodes = 8",
        "[hair]",
        "strands = 40",
        "head_motion = \"tour\"",
    ] {
        assert!(again.contains(key), "embedded config lacks {key}:\n{again}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The same command twice gives the same data; so does a run from the scene file that
/// `inspect --config-out` extracts from the first recording.
#[test]
fn runs_are_deterministic_and_reproducible_from_the_embedded_config() {
    let dir = scratch_dir("all-determinism");
    let config = dir.join("small.toml");
    std::fs::write(&config, SMALL).unwrap();
    let run = |name: &str, config: &std::path::Path| {
        let out = dir.join(name);
        let (code, _, stderr) = physlab(&[
            "all",
            "--config",
            config.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        out
    };
    let a = canonical_rows(&run("a.rrd", &config));
    let b = canonical_rows(&run("b.rrd", &config));
    assert!(a.len() > 10_000, "a real recording ({} rows)", a.len());
    assert_eq!(a.len(), b.len());
    assert!(a == b, "two runs of the same command differ");

    let extracted = dir.join("extracted.toml");
    let (code, _, stderr) = physlab(&[
        "inspect",
        dir.join("a.rrd").to_str().unwrap(),
        "--config-out",
        extracted.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let c = canonical_rows(&run("c.rrd", &extracted));
    assert!(
        a == c,
        "a run from the extracted config differs from the original"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flags_override_the_scene_file_and_print_config_shows_the_result() {
    let dir = scratch_dir("config-override");
    let config = dir.join("p.toml");
    std::fs::write(&config, "[pendulum]\ndt = 0.02\ntheta0 = 30.0\n").unwrap();
    let (code, text, stderr) = physlab(&[
        "pendulum",
        "--config",
        config.to_str().unwrap(),
        "--dt",
        "0.005",
        "--print-config",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        text.contains("dt = 0.005")
            && text.contains("theta0 = 30.0")
            && text.contains("gravity = 9.81"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scene_files_and_recordings_get_clear_errors() {
    let dir = scratch_dir("bad-files");
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_string()
    };
    let typo = write("typo.toml", b"[pendulum]\ndt = 0.01\ngravty = 9.81\n");
    let (code, _, err) = physlab(&["pendulum", "--config", &typo, "--print-config"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("typo.toml") && err.contains("line 3") && err.contains("gravty"),
        "{err}"
    );
    let (code, _, err) = physlab(&["all", "--config", &write("empty.toml", b"")]);
    assert_eq!(code, 2);
    assert!(err.contains("empty"), "{err}");
    let (code, _, err) = physlab(&[
        "all",
        "--config",
        &dir.join("missing.toml").to_string_lossy(),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("missing.toml") && err.contains("cannot read"),
        "{err}"
    );

    let (code, _, err) = physlab(&["inspect", &write("text.rrd", b"hello, not a recording\n")]);
    assert_eq!(code, 2);
    assert!(err.contains("not a Rerun recording"), "{err}");
    let (code, _, err) = physlab(&["inspect", &write("empty.rrd", b"")]);
    assert_eq!(code, 2);
    assert!(err.contains("empty"), "{err}");

    // A real recording cut in half.
    let good = dir.join("good.rrd");
    let (code, _, _) = physlab(&["pendulum", "--duration", "2", "-o", good.to_str().unwrap()]);
    assert_eq!(code, 0);
    let bytes = std::fs::read(&good).unwrap();
    let (code, out, err) = physlab(&["inspect", &write("cut.rrd", &bytes[..bytes.len() / 2])]);
    assert!(
        code == 2 && err.contains("truncated") || code == 0 && out.contains("no footer"),
        "a truncated file is reported as such: code {code}\n{out}\n{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn live_viewing_options_are_checked_before_simulating() {
    let dir = scratch_dir("live");
    let out = dir.join("p.rrd");
    let (code, _, err) = physlab(&[
        "pendulum",
        "--connect",
        "not a url",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--connect not a url: not a viewer URL"),
        "{err}"
    );
    // --spawn without a `rerun` on PATH: a clear error, and nothing simulated or written.
    let result = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(["pendulum", "--spawn", "-o", out.to_str().unwrap()])
        .env("PATH", dir.to_str().unwrap())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--spawn: no `rerun` executable on PATH"),
        "{err}"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn all_fps_and_plot_every_override_every_scene() {
    let (code, text, err) = physlab(&["all", "--fps", "5", "--plot-every", "3", "--print-config"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(text.matches("fps = 5.0").count(), 3, "{text}");
    assert_eq!(text.matches("plot_every = 3").count(), 2, "{text}");
}

#[test]
fn all_methods_gives_each_scene_the_listed_methods_it_supports() {
    let (code, toml, stderr) = physlab(&["all", "--methods", "rk4,ftl,verlet", "--print-config"]);
    assert_eq!(code, 0, "{stderr}");
    let file: toml::Table = toml.parse().unwrap();
    let methods = |scene: &str| -> Vec<String> {
        file[scene]["methods"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(methods("pendulum"), ["rk4", "verlet"]);
    assert_eq!(methods("rope"), ["rk4", "verlet"]);
    assert_eq!(methods("hair"), ["ftl", "verlet"]);

    // A name no scene has: the option, the value and both scenes' allowed names.
    let (code, _, stderr) = physlab(&["all", "--methods", "rk4,ftl,nope", "--print-config"]);
    assert_eq!(code, 2, "{stderr}");
    for expected in ["--methods rk4,ftl,nope", "'nope'", "dopri5", "ftl"] {
        assert!(stderr.contains(expected), "lacks '{expected}':\n{stderr}");
    }
    // A list that leaves a scene without a method is refused by the scene's name.
    let (code, _, stderr) = physlab(&["all", "--methods", "rk4", "--print-config"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("--methods rk4") && stderr.contains("hair") && stderr.contains("ftl"),
        "{stderr}"
    );
    let (code, _, stderr) = physlab(&["all", "--methods", "ftl", "--print-config"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("the pendulum and the rope") && stderr.contains("rk4"),
        "{stderr}"
    );
}
