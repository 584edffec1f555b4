//! The hair command end to end: exit code, summary, recording layout, bad input.

#![cfg(feature = "rerun")]

mod common;

use common::{assert_refused, decode, physlab, scratch_dir};

#[test]
fn hair_run_writes_one_strip_entity_per_method() {
    let dir = scratch_dir("hair-e2e");
    let out = dir.join("h.rrd");
    let (code, stdout, stderr) = physlab(&[
        "hair",
        "--strands",
        "30",
        "--duration",
        "1",
        "--methods",
        "verlet,semi-implicit-euler,ftl",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let d = decode(&out);
    assert!(d.has_footer);
    for m in ["verlet", "semi-implicit-euler", "ftl"] {
        assert!(
            stdout.lines().any(|l| l.starts_with(&format!("| {m} "))),
            "row for {m}:\n{stdout}"
        );
        for part in ["strands", "head", "roots"] {
            assert!(
                d.entities.contains(&format!("/hair/{m}/{part}")),
                "missing /hair/{m}/{part}"
            );
        }
        // Wall-clock costs are only recorded with --timings.
        assert!(!d.scalars.contains_key(&format!("/hair/plots/frame_ms/{m}")));
        for q in ["max_penetration", "specific_kinetic_energy"] {
            let rows = &d.scalars[&format!("/hair/plots/{q}/{m}")];
            assert_eq!(rows.len(), 60, "{q}/{m}: one value per 60 Hz frame");
        }
        // The stretch is plotted as log10 (frames with exactly zero stretch left out): every
        // value below 10⁻¹ (the springs' bound is 10⁻², the constraints' round-off).
        let rows = &d.scalars[&format!("/hair/plots/log10_max_stretch/{m}")];
        assert!(
            (1..=60).contains(&rows.len()) && rows.iter().all(|r| r.1.is_finite() && r.1 < -1.0),
            "log10_max_stretch/{m}: {rows:?}"
        );
        // The head never swallows a node: every recorded penetration is below 1e-6 R.
        assert!(
            d.scalars[&format!("/hair/plots/max_penetration/{m}")]
                .iter()
                .all(|r| r.1 <= 1e-7)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn no_record_writes_nothing() {
    let dir = scratch_dir("hair-norec");
    let out = dir.join("h.rrd");
    let (code, _, stderr) = physlab(&[
        "hair",
        "--strands",
        "10",
        "--duration",
        "0.5",
        "--no-record",
        "-o",
        out.to_str().unwrap(),
    ]);
    // -o names a file that --no-record would not write: a contradiction, refused.
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--no-record with -o/--output"), "{stderr}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_hair_input_is_refused_with_exit_code_2() {
    let dir = scratch_dir("hair-bad");
    let out = dir.join("h.rrd");
    let cases: [(&[&str], &str); 7] = [
        (&["--strands", "0"], "--strands 0: must be between 1"),
        (&["--nodes", "1"], "--nodes 1: must be between 2"),
        (
            &["--segment-length", "0"],
            "--segment-length 0: must be between 1e-6 and 1e6",
        ),
        (&["--iterations", "0"], "--iterations 0: must be at least 1"),
        (&["--wind", "a,b"], "expected x,y,z"),
        (&["--methods", "rk4"], "unknown hair method 'rk4'"),
        (
            &[
                "--strands",
                "1000000",
                "--nodes",
                "1000",
                "--duration",
                "600",
            ],
            "node-updates per method",
        ),
    ];
    for (extra, message) in cases {
        assert_refused("hair", &out, extra, message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--dt` is the simulation step, as in every scene: in hair 1/(rate·substeps).
#[test]
fn hair_dt_is_the_simulation_step_and_sets_the_substeps() {
    let substeps = |args: &[&str]| -> (i32, Option<i64>, String) {
        let mut all = vec!["hair"];
        all.extend_from_slice(args);
        all.push("--print-config");
        let (code, toml, stderr) = physlab(&all);
        let n = toml
            .parse::<toml::Table>()
            .ok()
            .and_then(|t| t.get("hair")?.get("substeps")?.as_integer());
        (code, n, stderr)
    };
    // 1/(60 · 1/240) = 4 exactly in reals; in f64 within round-off.
    assert_eq!(substeps(&["--dt", "0.004166666666666667"]).1, Some(4));
    assert_eq!(substeps(&["--dt", "0.0041666666666667"]).1, Some(4));
    assert_eq!(substeps(&["--rate", "100", "--dt", "0.002"]).1, Some(5));
    assert_eq!(
        substeps(&["--dt", "0.008333333333333333", "--substeps", "2"]).1,
        Some(2)
    );
    assert_eq!(substeps(&[]).1, Some(1));

    // Not a whole number of substeps: refused, naming the nearest allowed steps.
    let (code, _, stderr) = substeps(&["--dt", "0.01"]);
    assert_eq!(code, 2, "{stderr}");
    for expected in [
        "--dt 0.01:",
        "1.6666666666666667 substeps",
        "0.016666666666666666 (1 substep)",
        "0.008333333333333333 (2 substeps)",
    ] {
        assert!(stderr.contains(expected), "lacks '{expected}':\n{stderr}");
    }
    // Longer than a frame: the nearest allowed is one substep.
    let (code, _, stderr) = substeps(&["--dt", "0.05"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("0.016666666666666666 (1 substep)"),
        "{stderr}"
    );
    // --dt and --substeps that disagree.
    let (code, _, stderr) = substeps(&["--dt", "0.008333333333333333", "--substeps", "3"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("--dt 0.008333333333333333 and --substeps 3 disagree")
            && stderr.contains("2 substeps per frame"),
        "{stderr}"
    );
    // A scene file follows the same rule, and its error names the file's key.
    let dir = scratch_dir("hair-dt");
    let file = dir.join("h.toml");
    std::fs::write(&file, "[hair]\ndt = 0.01\n").unwrap();
    let (code, _, stderr) = substeps(&["--config", file.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("[hair] dt = 0.01:"), "{stderr}");
    std::fs::write(&file, "[hair]\ndt = 0.008333333333333333\nsubsteps = 2\n").unwrap();
    assert_eq!(substeps(&["--config", file.to_str().unwrap()]).1, Some(2));
}

/// `physlab study hair`: every configuration measured, the CSV written with
/// one row each, the direct solver and ftl within 1e-6 and one Gauss–Seidel sweep not within
/// 1e-1 (the chain cannot carry a correction from tip to root in one sweep).
#[test]
fn study_hair_measures_the_trade() {
    let dir = scratch_dir("study-hair");
    let csv = dir.join("hair.csv");
    let (code, stdout, stderr) = physlab(&[
        "study",
        "hair",
        "--duration",
        "0.25",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("cheapest configuration"), "{stdout}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 28 + 4 + 4 + 6 + 1, "{text}");
    let stretch = |method: &str, solver: &str, it: &str, sub: &str| -> f64 {
        let r = rows
            .iter()
            .find(|r| r[0] == method && r[1] == solver && r[2] == it && r[3] == sub)
            .unwrap();
        r[5].parse().unwrap()
    };
    assert!(stretch("verlet", "direct", "2", "1") < 1e-6);
    assert!(stretch("ftl", "", "1", "1") < 1e-6);
    assert!(stretch("verlet", "gauss-seidel", "1", "1") > 1e-1);
    std::fs::remove_dir_all(&dir).unwrap();
}
