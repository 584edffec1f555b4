//! The hair command end to end (issue 4): exit code, summary, recording layout, bad input.

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
        for q in ["max_stretch", "max_penetration", "specific_kinetic_energy"] {
            let rows = &d.scalars[&format!("/hair/plots/{q}/{m}")];
            assert_eq!(rows.len(), 60, "{q}/{m}: one value per 60 Hz frame");
        }
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
        (&["--wind", "a,b"], "expected x,y or x,y,z"),
        (&["--methods", "rk4"], "unknown hair method 'rk4'"),
        (
            &["--strands", "1000000", "--nodes", "1000"],
            "node-updates per method",
        ),
    ];
    for (extra, message) in cases {
        assert_refused("hair", &out, extra, message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
