//! The rope command end to end: exit code, summary, recording, preset resolution.

#![cfg(feature = "rerun")]

mod common;

use clap::Parser as _;
use common::{assert_refused, decode, drawn_rows, physlab, scratch_dir};
use physlab::app::config_from_flags;
use physlab::cli::{Cli, Command as Sub};

const METHODS: [&str; 7] = [
    "explicit-euler",
    "semi-implicit-euler",
    "implicit-euler",
    "midpoint",
    "trapezoid",
    "rk4",
    "verlet",
];

#[test]
fn rope_run_writes_a_recording_with_every_method() {
    let dir = scratch_dir("rope-e2e");
    let out = dir.join("r.rrd");
    let (code, stdout, stderr) = physlab(&[
        "rope",
        "--duration",
        "2",
        "--pinned",
        "0,15",
        "--timings",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    for m in METHODS {
        assert!(
            stdout.lines().any(|l| l.starts_with(&format!("| {m} "))),
            "row for {m}:\n{stdout}"
        );
    }
    // Explicit Euler is unstable on the default rope (ω_max dt ≈ 0.45) and is stopped; the others run on.
    let euler = stdout
        .lines()
        .find(|l| l.starts_with("| explicit-euler "))
        .unwrap();
    assert!(euler.contains("yes, t ="), "{euler}");
    let d = decode(&out);
    assert!(d.has_footer);
    for m in METHODS {
        for part in ["nodes", "strip", "pinned"] {
            assert!(
                d.entities.contains(&format!("/rope/{m}/{part}")),
                "missing /rope/{m}/{part}"
            );
        }
        for q in ["energy", "log10_energy_change", "max_strain", "frame_cost"] {
            let rows = d
                .scalars
                .get(&format!("/rope/plots/{q}/{m}"))
                .unwrap_or_else(|| panic!("plot {q}/{m}"));
            assert!(
                rows.iter().all(|r| r.1.is_finite()),
                "{q}/{m} has a non-finite value"
            );
        }
    }
    assert!(d.entities.contains("/rope/events"));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn config(args: &[&str]) -> physlab::scene::rope::run::RopeConfig {
    let Sub::Rope(a) = Cli::parse_from(["physlab", "rope"].iter().chain(args)).command else {
        unreachable!()
    };
    config_from_flags(&a.scene, "rope").unwrap()
}

#[test]
fn games101_preset_reproduces_the_assignment_and_flags_override_it() {
    let c = config(&["--preset", "games101"]);
    let p = &c.params;
    assert_eq!(p.nodes, 16);
    assert_eq!(
        (p.start.to_array(), p.end.to_array()),
        ([0.0, 0.0, 200.0], [-400.0, 0.0, 200.0]),
        "the assignment's 2D x,y is x,z (z up)"
    );
    assert_eq!(
        (p.mass, p.stiffness, p.gravity.to_array(), p.pinned.clone()),
        (1.0, 100.0, [0.0, 0.0, -1.0], vec![0])
    );
    assert_eq!(c.dt, 1.0 / 64.0);
    assert_eq!(c.schedule().ticks_per_frame(), 64.0, "64 steps per frame");
    assert_eq!(c.options.verlet_damping, 0.00005);
    let c = config(&["--preset", "games101", "--stiffness", "50", "--nodes", "8"]);
    assert_eq!(
        (c.params.stiffness, c.params.nodes, c.params.mass),
        (50.0, 8, 1.0)
    );
    let c = config(&[]);
    assert_eq!(
        c.options.verlet_damping, 0.0,
        "Verlet damping is 0 outside the preset"
    );
}

#[test]
fn bad_rope_input_is_refused_with_exit_code_2() {
    let dir = scratch_dir("rope-bad");
    let out = dir.join("r.rrd");
    let cases: [(&[&str], &str); 7] = [
        (&["--nodes", "1"], "--nodes 1: must be between 2"),
        (
            &["--pinned", "0,16"],
            "--pinned 16: node index out of range; the rope has nodes 0..=15",
        ),
        (&["--end", "0,0,0"], "must differ from --start"),
        (&["--gravity", "0,x"], "expected x,y,z"),
        (
            &["--mass", "0"],
            "--mass 0: must be between 1e-6 and 1e6 [kg]",
        ),
        (
            &["--stiffness", "-5"],
            "--stiffness -5: must be between 1e-6 and 1e12 [N/m]",
        ),
        (
            &["--nodes", "100000", "--duration", "1000000"],
            "node-steps per method",
        ),
    ];
    for (extra, message) in cases {
        assert_refused("rope", &out, extra, message);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// z is up for the rope as for every scene: with gravity 0,0,-9.81 a rope laid out along x,
/// pinned at node 0, swings down into −z (its tip passes below the pin by most of its length)
/// and stays in the x–z plane. The recording draws it as simulated, no axes turned. The rope's
/// former y-up spelling 0,-9.81 is refused, not read as a sideways pull.
#[test]
fn rope_hangs_towards_minus_z() {
    let dir = scratch_dir("rope-z-up");
    let out = dir.join("r.rrd");
    let (code, stdout, stderr) = physlab(&[
        "rope",
        "--gravity",
        "0,0,-9.81",
        "--methods",
        "implicit-euler",
        "--layout",
        "overlay",
        "--duration",
        "3",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let frames: Vec<Vec<[f32; 3]>> = drawn_rows(&out, "/rope/implicit-euler/nodes")
        .into_iter()
        .map(|(_, points)| points)
        .collect();
    assert!(frames.len() >= 80, "{} frames", frames.len());
    let span = 4.0f32; // the default rope, from (0,0,0) to (4,0,0)
    let lowest_tip = frames
        .iter()
        .map(|f| f.last().unwrap()[2])
        .fold(f32::INFINITY, f32::min);
    assert!(
        lowest_tip < -0.8 * span,
        "the tip should swing well below the pin at z = 0, reached z = {lowest_tip}"
    );
    for f in &frames {
        assert_eq!(f[0], [0.0, 0.0, 0.0], "the pin stays put");
        assert!(
            f.iter().all(|p| p[1] == 0.0),
            "the rope leaves the x–z plane"
        );
        // Energy only leaves a damped rope that starts at rest and unstretched, so its centre
        // of mass never rises above the start's height z = 0.
        let mean_z = f.iter().map(|p| p[2]).sum::<f32>() / f.len() as f32;
        assert!(mean_z <= 1e-6, "the centre of mass rose to z = {mean_z}");
    }
    assert_refused(
        "rope",
        &dir.join("refused.rrd"),
        &["--gravity", "0,-9.81"],
        "expected x,y,z",
    );
    let file = dir.join("y-up.toml");
    std::fs::write(&file, "[rope]\ngravity = [0.0, -9.81]\n").unwrap();
    assert_refused(
        "rope",
        &dir.join("refused.rrd"),
        &["--config", file.to_str().unwrap()],
        "expected [x, y, z] with finite numbers, z up",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
