//! `physlab reproduce` and `physlab diff`: a run reproduces itself bit-identically and altered
//! values are caught where they are, and the recording readers survive any byte string.

#![cfg(feature = "rerun")]

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::Duration;

use common::{decode, physlab, s, scratch_dir};
use physlab::rrd::compare::{SeriesDiff, StreamSpec, compare_files, time_text};
use rerun::external::arrow::array::{Array as _, Float64Array, ListArray};
use rerun::external::re_log_encoding::{DecoderApp, Encoder, EncodingOptions};
use rerun::log::{Chunk, LogMsg};

/// A small run of all three scenes (explicit Euler diverges in the rope: a lane cut short).
const ALL_SCENE: &str = "[pendulum]\nduration = 3.0\nmethods = [\"explicit-euler\", \"verlet\", \"rk4\"]\n\
                         [rope]\nduration = 3.0\n[hair]\nduration = 1.0\nstrands = 12\n";

#[test]
fn a_run_reproduces_itself_bit_identically() {
    let dir = scratch_dir("reproduce-self");
    let config = dir.join("scene.toml");
    std::fs::write(&config, ALL_SCENE).unwrap();
    let out = dir.join("all.rrd");
    let (code, _, err) = physlab(&["all", "--config", s(&config), "-q", "-o", s(&out)]);
    assert_eq!(code, 0, "{err}");
    let (code, report, err) = physlab(&["reproduce", s(&out)]);
    assert_eq!(code, 0, "{report}\n{err}");
    // The verdict first, then only what differs (nothing): under 15 lines.
    assert!(report.starts_with("verdict: bit-identical"), "{report}");
    assert!(report.lines().count() < 15, "{report}");
    assert!(!report.contains("/pendulum/plots"), "{report}");
    let (code, report, err) = physlab(&["reproduce", "-v", s(&out)]);
    assert_eq!(code, 0, "{report}\n{err}");
    for entity in [
        "/pendulum/plots/theta/verlet: identical",
        "/pendulum/rk4/bob: identical",
        "/rope/plots/max_strain/explicit-euler: identical",
        "/hair/ftl/strands: identical",
        "/pendulum/events: identical",
        "/pendulum/summary: identical",
        "/rope/summary: identical",
    ] {
        assert!(report.contains(entity), "lacks {entity:?}:\n{report}");
    }
    assert!(!report.contains("DIFFERS"), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Rewrites `src` into `dst` with the value of `entity`'s scalar at `time_ns` changed by `delta`.
fn alter(src: &Path, dst: &Path, entity: &str, time_ns: i64, delta: f64) -> f64 {
    let scalar = rerun::Scalars::descriptor_scalars().component;
    let sim_time = rerun::TimelineName::from("sim_time");
    let mut enc = Encoder::new_eager(
        rerun::external::re_build_info::CrateVersion::LOCAL,
        EncodingOptions::PROTOBUF_COMPRESSED,
        std::fs::File::create(dst).unwrap(),
    )
    .unwrap();
    let mut original = None;
    let file = std::io::BufReader::new(std::fs::File::open(src).unwrap());
    for msg in DecoderApp::decode_lazy(file) {
        let mut msg = msg.unwrap();
        if let LogMsg::ArrowMsg(store_id, arrow_msg) = &msg {
            let chunk = Chunk::from_arrow_msg(arrow_msg).unwrap();
            let row = chunk
                .timelines()
                .get(&sim_time)
                .and_then(|t| t.times_raw().iter().position(|&t| t == time_ns));
            if chunk.entity_path().to_string() == entity
                && let Some(row) = row
                && original.is_none()
            {
                let changed = chunk
                    .with_mapped_component::<std::convert::Infallible>(scalar, None, |list| {
                        let (field, offsets, values, nulls) = list.into_parts();
                        let mut v: Vec<f64> = values
                            .as_any()
                            .downcast_ref::<Float64Array>()
                            .unwrap()
                            .values()
                            .to_vec();
                        let k = offsets[row] as usize;
                        original = Some(v[k]);
                        v[k] += delta;
                        Ok(ListArray::new(
                            field,
                            offsets,
                            Arc::new(Float64Array::from(v)),
                            nulls,
                        ))
                    })
                    .unwrap();
                msg = LogMsg::ArrowMsg(store_id.clone(), changed.to_arrow_msg().unwrap());
            }
        }
        enc.append(&msg).unwrap();
    }
    enc.finish().unwrap();
    original.expect("the row to alter exists")
}

#[test]
fn an_altered_value_is_caught_at_its_entity_and_time() {
    let dir = scratch_dir("reproduce-altered");
    let good = dir.join("good.rrd");
    let (code, _, err) = physlab(&[
        "pendulum",
        "--duration",
        "3",
        "--methods",
        "rk4,verlet",
        "-q",
        "-o",
        s(&good),
    ]);
    assert_eq!(code, 0, "{err}");
    let bad = dir.join("bad.rrd");
    // θ of rk4 at t = 1.5 s (step 150 of 0.01 s), one part in 1e9 more.
    let was = alter(
        &good,
        &bad,
        "/pendulum/plots/theta/rk4",
        1_500_000_000,
        1e-9,
    );
    let (code, report, err) = physlab(&["reproduce", s(&bad)]);
    assert_eq!(code, 1, "{report}\n{err}");
    let line = report
        .lines()
        .find(|l| l.contains("DIFFERS") && l.contains("/pendulum/"))
        .unwrap_or_else(|| panic!("no DIFFERS line:\n{report}"));
    assert!(
        line.contains(
            "/pendulum/plots/theta/rk4: DIFFERS: first differs at t = 1.5 s (Scalars:scalars)"
        ),
        "{line}"
    );
    // Both values to the digits that tell them apart (a change of 1e-9 in about 1: 11 digits).
    let value = |name: &str| -> String {
        let after = line.split(&format!("{name} ")).nth(1).unwrap_or("");
        after.split([',', ';']).next().unwrap_or("").to_string()
    };
    let (recorded, recomputed) = (value("recorded"), value("recomputed"));
    for (text, expected) in [(&recorded, was + 1e-9), (&recomputed, was)] {
        let v: f64 = text
            .parse()
            .unwrap_or_else(|_| panic!("{text:?} in {line}"));
        assert!((v - expected).abs() < 1e-10, "{text} vs {expected}: {line}");
        let digits = text.chars().filter(char::is_ascii_digit).count();
        assert!(
            digits <= 12,
            "{text}: more digits than tell the values apart"
        );
    }
    assert!(report.starts_with("verdict: DIFFERS in 1 of"), "{report}");
    assert_eq!(
        report.matches("DIFFERS").count(),
        2,
        "one entity and the verdict:\n{report}"
    );
    assert!(report.contains("verdict: DIFFERS in 1 of"), "{report}");
    // The summary table is recomputed from the true values: it agrees with the recording.
    let (_, verbose, _) = physlab(&["reproduce", "-v", s(&bad)]);
    assert!(
        verbose.contains("/pendulum/summary: identical"),
        "{verbose}"
    );
    assert!(err.contains("does not reproduce"), "{err}");
    // Within a tolerance larger than the change (relative to max |θ| ≈ 1.05 rad), it passes.
    let (code, report, _) = physlab(&["reproduce", s(&bad), "--tolerance", "1e-8"]);
    assert_eq!(code, 0, "{report}");
    assert!(
        report.contains("verdict: reproduces within --tolerance"),
        "{report}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The first sampled time (in steps) where |θ_euler − θ_verlet| exceeds `tol` × max |θ_euler|,
/// from both methods' recurrences written out here: explicit Euler θ' = ω, ω' = −(g/L) sin θ
/// with the old values; velocity Verlet θ1 = θ + hω + h²a/2, ω1 = ω + h(a + a1)/2.
fn first_parting(g_over_l: f64, theta0: f64, h: f64, steps: usize, tol: f64) -> usize {
    let (mut te, mut we) = (theta0, 0.0f64);
    let (mut tv, mut wv) = (theta0, 0.0f64);
    let (mut euler, mut verlet) = (vec![te], vec![tv]);
    for _ in 0..steps {
        let a = -g_over_l * te.sin();
        te += h * we;
        we += h * a;
        let a0 = -g_over_l * tv.sin();
        tv += h * wv + 0.5 * h * h * a0;
        let a1 = -g_over_l * tv.sin();
        wv += 0.5 * h * (a0 + a1);
        euler.push(te);
        verlet.push(tv);
    }
    let scale = euler.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    (0..=steps)
        .find(|&k| (euler[k] - verlet[k]).abs() > tol * scale)
        .expect("they part")
}

#[test]
fn diff_of_euler_and_verlet_reports_their_first_parting() {
    let dir = scratch_dir("diff-parting");
    let (e, v, d) = (dir.join("e.rrd"), dir.join("v.rrd"), dir.join("d.rrd"));
    for (method, out) in [("explicit-euler", &e), ("verlet", &v)] {
        let (code, _, err) = physlab(&[
            "pendulum",
            "--methods",
            method,
            "--dt",
            "0.01",
            "--duration",
            "4",
            "--theta0",
            "60",
            "--gravity",
            "9.81",
            "--length",
            "1",
            "-q",
            "-o",
            s(out),
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let (code, report, err) = physlab(&[
        "diff",
        s(&e),
        s(&v),
        "--tolerance",
        "0.01",
        "-v",
        "-o",
        s(&d),
    ]);
    assert_eq!(code, 1, "they differ:\n{report}\n{err}");
    assert!(report.contains("pendulum.methods"), "{report}");
    assert!(
        report.contains("pairing A's lane explicit-euler with B's lane verlet"),
        "{report}"
    );
    let line = report
        .lines()
        .find(|l| l.contains("/pendulum/plots/theta/explicit-euler:"))
        .unwrap_or_else(|| panic!("no theta line:\n{report}"));
    let at = line
        .split("first differs at t = ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no parting time in {line}"));
    let k = first_parting(9.81, 60f64.to_radians(), 0.01, 400, 0.01);
    assert!(
        k > 1,
        "a parting later than the first step, so the test can fail ({k})"
    );
    assert!(
        (at - k as f64 * 0.01).abs() < 1e-9,
        "diff says they part at {at} s, the recurrences at step {k} ({} s)",
        k as f64 * 0.01
    );
    // The reference lane is the same in both runs.
    assert!(
        report.contains("/pendulum/plots/theta/exact: identical"),
        "{report}"
    );
    // The difference recording holds θ_verlet − θ_euler over time.
    let decoded = common::decode(&d);
    let dtheta = &decoded.scalars["/diff/pendulum/plots/theta/explicit-euler"];
    assert_eq!(dtheta.len(), 401);
    assert_eq!(dtheta[0].1, 0.0);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The views of a recording's blueprint: (class, origin) of each.
fn blueprint_views(path: &Path) -> Vec<(String, String)> {
    use rerun::external::re_sdk_types::blueprint::archetypes::ViewBlueprint;
    let origin = ViewBlueprint::descriptor_space_origin().component;
    let class = ViewBlueprint::descriptor_class_identifier().component;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut views = Vec::new();
    for msg in DecoderApp::decode_lazy(file) {
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
            continue;
        };
        if !store_id.is_blueprint() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        let (Some(c), Some(o)) = (
            chunk.iter_slices::<String>(class).next(),
            chunk.iter_slices::<String>(origin).next(),
        ) else {
            continue;
        };
        if let (Some(c), Some(o)) = (c.first(), o.first()) {
            views.push((c.to_string(), o.to_string()));
        }
    }
    views
}

/// A one-parameter change (`--dt 0.01` → `0.005`) reads as one change: `diff` says the verdict
/// on line 1, the configuration change on line 2, the rows at times the other run lacks as one
/// line, in under 15 lines; `reproduce` says its verdict on line 1 in under 15 lines. The
/// difference recording opens on a plot of B − A per quantity, both runs' 3D overlaid and the
/// report, holds θ_B − θ_A at the times both have, and says what wrote it.
#[test]
fn a_step_change_reads_as_one_change_and_its_diff_recording_shows_it_as_plots() {
    let dir = scratch_dir("diff-dt");
    let (a, b, d) = (dir.join("a.rrd"), dir.join("b.rrd"), dir.join("d.rrd"));
    for (dt, out) in [("0.01", &a), ("0.005", &b)] {
        let (code, _, err) = physlab(&[
            "pendulum",
            "--dt",
            dt,
            "--duration",
            "2",
            "--methods",
            "rk4,verlet,explicit-euler",
            "-q",
            "-o",
            s(out),
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let (code, report, err) = physlab(&["diff", s(&a), s(&b), "-o", s(&d)]);
    assert_eq!(code, 1, "{report}\n{err}");
    let lines: Vec<&str> = report.lines().collect();
    assert!(lines.len() < 15, "{} lines:\n{report}", lines.len());
    assert!(lines[0].starts_with("verdict: they differ"), "{report}");
    assert_eq!(
        lines[1], "configuration: pendulum.dt: 0.01 → 0.005",
        "{report}"
    );
    assert_eq!(
        lines.iter().filter(|l| l.starts_with("times: ")).count(),
        1,
        "{report}"
    );
    assert!(!report.contains("without a partner"), "{report}");
    assert!(
        report.contains("/pendulum/plots/theta/* (4 of 4 differ"),
        "{report}"
    );
    let (code, again, err) = physlab(&["reproduce", s(&a)]);
    assert_eq!(code, 0, "{again}\n{err}");
    assert!(again.lines().count() < 15, "{again}");
    assert!(again.starts_with("verdict: bit-identical"), "{again}");

    // Its views: B − A per quantity, the 3D overlay, the report.
    let views = blueprint_views(&d);
    for (class, origin) in [
        ("TimeSeries", "/diff/pendulum/plots/theta"),
        ("TimeSeries", "/diff/pendulum/plots/omega"),
        ("3D", "/diff/3d"),
        ("TextDocument", "/diff/report"),
    ] {
        assert!(
            views.iter().any(|v| v.0 == class && v.1 == origin),
            "no {class} view of {origin}: {views:?}"
        );
    }
    // θ_B − θ_A at every time of A (B has each of A's times and one between), as the two
    // recordings hold them.
    let (da, db, dd) = (decode(&a), decode(&b), decode(&d));
    for lane in ["rk4", "verlet", "explicit-euler"] {
        let theta = format!("/pendulum/plots/theta/{lane}");
        let b_at: std::collections::BTreeMap<i64, f64> =
            db.scalars[&theta].iter().copied().collect();
        let expected: Vec<(i64, f64)> = da.scalars[&theta]
            .iter()
            .filter_map(|&(t, x)| b_at.get(&t).map(|y| (t, y - x)))
            .collect();
        assert_eq!(expected.len(), 201, "{lane}: A's times in B");
        assert_eq!(dd.scalars[&format!("/diff{theta}")], expected, "{lane}");
    }
    for side in ["A", "B"] {
        let bob = format!("/diff/3d/{side}/pendulum/rk4/bob");
        assert!(dd.entities.contains(&bob), "{bob}: {:?}", dd.entities);
    }
    // Its provenance: inspect names it, reproduce refuses it with the command that wrote it.
    let (code, info, err) = physlab(&["inspect", s(&d)]);
    assert_eq!(code, 0, "{err}");
    assert!(info.contains("(a diff recording of "), "{info}");
    assert!(!info.contains("(not recorded)"), "{info}");
    let (code, _, err) = physlab(&["reproduce", s(&d)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a diff recording"), "{err}");
    assert!(
        err.contains(&format!("physlab diff {} {} -o {}", s(&a), s(&b), s(&d))),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A run long enough that its plots are aggregated and its 3D frames budgeted: Rerun's own
/// decoder reads every message of it, and `reproduce` replays it bit for bit, windows included.
#[test]
fn a_long_aggregated_run_decodes_and_reproduces() {
    let dir = scratch_dir("reproduce-long");
    let out = dir.join("long.rrd");
    let (code, summary, err) = physlab(&[
        "pendulum",
        "--duration",
        "2500",
        "--window",
        "1000:1010",
        "-q",
        "-o",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    // Its lines are wrapped to 100 columns: read as one line.
    let summary = summary.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        summary.contains("aggregated (M4) over 4096 columns"),
        "{summary}"
    );
    assert!(summary.contains("and 1000:1010 s"), "{summary}");
    assert!(summary.contains("6000 of the 75001 frames"), "{summary}");
    let decoded = decode(&out);
    assert!(decoded.has_footer);
    let theta = &decoded.scalars["/pendulum/plots/theta/verlet"];
    // Far fewer rows than the 250,001 steps, and every step of the window asked for.
    assert!(theta.len() < 60_000, "{} rows", theta.len());
    let in_window = theta
        .iter()
        .filter(|(t, _)| (1_000_000_000_000..=1_010_000_000_000).contains(t))
        .count();
    assert_eq!(in_window, 1001);
    let (code, report, err) = physlab(&["reproduce", s(&out)]);
    assert_eq!(code, 0, "{report}\n{err}");
    assert!(report.contains("verdict: bit-identical"), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_cut_short_reproduces_up_to_where_it_ended() {
    let dir = scratch_dir("reproduce-cut");
    let out = dir.join("cut.rrd");
    let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([
            "pendulum",
            "--dt",
            "1e-5",
            "--duration",
            "200",
            "--methods",
            "verlet,rk4",
            "-q",
            "-o",
            s(&out),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let result = child.wait_with_output().unwrap();
    assert_eq!(result.status.code(), Some(130));
    let (code, info, _) = physlab(&["inspect", s(&out)]);
    assert_eq!(code, 0);
    assert!(
        info.contains("pendulum: ended early: interrupted (Ctrl-C) at t = "),
        "{info}"
    );
    let (code, report, err) = physlab(&["reproduce", s(&out)]);
    assert_eq!(code, 0, "{report}\n{err}");
    assert!(report.contains("verdict: bit-identical"), "{report}");
    assert!(report.contains("interrupted (Ctrl-C)"), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The (entity, static, rows) of a recording's chunks, in file order.
fn chunk_layout(path: &Path) -> Vec<(String, bool, usize)> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    DecoderApp::decode_lazy(file)
        .filter_map(|m| match m.unwrap() {
            LogMsg::ArrowMsg(store, msg) if store.is_recording() => {
                let c = Chunk::from_arrow_msg(&msg).unwrap();
                Some((c.entity_path().to_string(), c.is_static(), c.num_rows()))
            }
            _ => None,
        })
        .collect()
}

#[test]
fn identical_runs_write_identical_chunks() {
    let dir = scratch_dir("deterministic");
    let config = dir.join("scene.toml");
    std::fs::write(&config, ALL_SCENE).unwrap();
    // Both written to the same path (the command line is part of the provenance), then moved.
    let (a, b, out) = (dir.join("a.rrd"), dir.join("b.rrd"), dir.join("run.rrd"));
    for keep in [&a, &b] {
        let (code, _, err) = physlab(&["all", "--config", s(&config), "-q", "-o", s(&out)]);
        assert_eq!(code, 0, "{err}");
        std::fs::rename(&out, keep).unwrap();
    }
    // The same chunks in the same order.
    let la = chunk_layout(&a);
    assert_eq!(la, chunk_layout(&b));
    // And Rerun's own comparison (ids aside), ordered, where its command line is installed.
    let installed = Command::new("rerun")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if installed {
        let result = Command::new("rerun")
            .args(["rrd", "compare", s(&a), s(&b)])
            .output()
            .unwrap();
        assert!(
            result.status.success(),
            "rerun rrd compare: {}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
    // Cut by size only, not by a clock: an entity's rows over time come in as few chunks as
    // 4096-row chunks allow (one more where a diverged lane is cleared).
    let mut per_entity: std::collections::BTreeMap<&str, (usize, usize)> = Default::default();
    for (e, is_static, n) in &la {
        if !is_static {
            let entry = per_entity.entry(e).or_default();
            entry.0 += 1;
            entry.1 += n;
        }
    }
    for (e, (chunks, rows)) in per_entity {
        assert!(
            chunks <= rows.div_ceil(4096) + 1,
            "{e}: {rows} rows in {chunks} chunks"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "rerun")]
mod embedded_config {
    //! A run of `all` is deterministic, and reproduces from the configuration its recording embeds.

    use crate::common::{SMALL, canonical_rows, physlab, scratch_dir};

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
}

#[cfg(feature = "rerun")]
mod readers {
    //! The recording readers (`inspect`, `diff`, `reproduce`) under abuse: any byte string as a
    //! recording is a clean "unusable file" error naming the file (exit 2) or a good read, never a
    //! panic; mutated copies of a corpus of real recordings are fuzzed in-process; a stop request
    //! ends a read within a second (exit 130, also during `reproduce`'s re-run); `diff` counts
    //! static data in its verdict and refuses another application's recording; a hair recording
    //! reproduces on any core count and with its `--log-strands`; a command line that is not UTF-8
    //! is recorded losslessly.

    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt as _;
    use std::path::{Path, PathBuf};
    use std::process::Command;

    use physlab::cli::{Cli, Command as Sub, DiffArgs};
    use physlab::error::Error;
    use proptest::prelude::*;

    use crate::common::{physlab, s, scratch_dir};

    /// The corpus: small real recordings of every kind physlab writes (see its README).
    fn corpus() -> Vec<(PathBuf, Vec<u8>)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/rrd-corpus");
        let mut files: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension() == Some(OsStr::new("rrd")))
            .map(|p| {
                let bytes = std::fs::read(&p).unwrap();
                (p, bytes)
            })
            .collect();
        files.sort();
        assert!(files.len() >= 4, "the corpus is in {}", dir.display());
        files
    }

    /// An error the readers may end with on a bad file: a usage error (exit 2) naming the file (or
    /// the other file read with it, itself refused: a corpus file cut short).
    fn clean_error(e: &anyhow::Error, path: &Path) -> Result<(), String> {
        clean_error_naming(e, &[path])
    }

    fn clean_error_naming(e: &anyhow::Error, paths: &[&Path]) -> Result<(), String> {
        let names = |m: &str| {
            paths
                .iter()
                .any(|p| m.starts_with(&format!("{}: ", p.display())))
        };
        match e.downcast_ref::<Error>() {
            Some(Error::Usage(m)) if names(m) => Ok(()),
            Some(Error::Usage(m)) => Err(format!("the error does not name the file: {m}")),
            _ => Err(format!("not a usage error (exit 2): {e:#}")),
        }
    }

    /// Runs every reader in-process on `path`: inspect's, compare's (what diff and reproduce read
    /// with), and `diff` of it against `good` both ways. Each either succeeds or ends with a clean
    /// error; a panic fails the test where it happens.
    fn read_everything(path: &Path, good: &Path) -> Result<(), String> {
        if let Err(e) = physlab::rrd::inspect::read_recording(path) {
            clean_error(&e, path)?;
        }
        if let Err(e) = physlab::rrd::compare::read_contents(path) {
            clean_error(&e, path)?;
        }
        for (a, b) in [(good, path), (path, good)] {
            let cli = Cli {
                command: Sub::Diff(DiffArgs {
                    a: a.to_path_buf(),
                    b: b.to_path_buf(),
                    tolerance: None,
                    output: None,
                    verbose: false,
                    quiet: false,
                }),
            };
            if let Err(e) = physlab::app::run(cli)
                && !matches!(e.downcast_ref::<Error>(), Some(Error::Differs(_)))
            {
                clean_error_naming(&e, &[path, good])?;
            }
        }
        Ok(())
    }

    /// One way to damage a file.
    #[derive(Clone, Debug)]
    enum Mutation {
        /// XOR bytes at (fractions of the length) with non-zero masks.
        Flip(Vec<(f64, u8)>),
        Truncate(f64),
        Insert(f64, Vec<u8>),
        Delete(f64, usize),
        /// A range copied over another place (plausible framing in the wrong spot).
        Splice(f64, f64, usize),
    }

    fn at(len: usize, fraction: f64) -> usize {
        ((len as f64 * fraction) as usize).min(len.saturating_sub(1))
    }

    impl Mutation {
        fn apply(&self, bytes: &[u8]) -> Vec<u8> {
            let mut out = bytes.to_vec();
            let n = out.len();
            match self {
                Mutation::Flip(flips) => {
                    for &(f, mask) in flips {
                        out[at(n, f)] ^= mask;
                    }
                }
                Mutation::Truncate(f) => out.truncate(at(n, *f)),
                Mutation::Insert(f, extra) => {
                    let i = at(n, *f);
                    out.splice(i..i, extra.iter().copied());
                }
                Mutation::Delete(f, len) => {
                    let i = at(n, *f);
                    out.drain(i..(i + len).min(n));
                }
                Mutation::Splice(from, to, len) => {
                    let (i, j) = (at(n, *from), at(n, *to));
                    let len = (*len).min(n - i).min(n - j);
                    let piece = bytes[i..i + len].to_vec();
                    out[j..j + len].copy_from_slice(&piece);
                }
            }
            out
        }
    }

    fn mutation() -> impl Strategy<Value = Mutation> {
        let fraction = 0.0..1.0f64;
        prop_oneof![
            4 => prop::collection::vec((fraction.clone(), 1u8..=255), 1..4).prop_map(Mutation::Flip),
            1 => fraction.clone().prop_map(Mutation::Truncate),
            1 => (fraction.clone(), prop::collection::vec(any::<u8>(), 1..64))
                .prop_map(|(f, b)| Mutation::Insert(f, b)),
            1 => (fraction.clone(), 1usize..512).prop_map(|(f, n)| Mutation::Delete(f, n)),
            1 => (fraction.clone(), fraction, 1usize..256)
                .prop_map(|(a, b, n)| Mutation::Splice(a, b, n)),
        ]
    }

    fn fuzz_cases() -> u32 {
        std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(160)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: fuzz_cases(), ..ProptestConfig::default() })]

        /// Mutated recordings: every reader ends with a clean error or a good read. A corrupted
        /// length (of a message, an LZ4 buffer, an Arrow body) would make a decoder reserve up to
        /// 2^64 bytes and abort, which no `catch_unwind` stops: `record/framing.rs` checks each
        /// against what follows it first. More cases:
        /// `PROPTEST_CASES=20000 cargo test --release --test reproduce mutated`.
        #[test]
        fn mutated_recordings_never_panic_a_reader(which in 0usize..64, m in mutation()) {
            let files = corpus();
            let (good, bytes) = &files[which % files.len()];
            let dir = scratch_dir(&format!("fuzz-{:?}", std::thread::current().id()).replace(['(', ')'], ""));
            let bad = dir.join("mutated.rrd");
            std::fs::write(&bad, m.apply(bytes)).unwrap();
            let result = read_everything(&bad, good);
            std::fs::remove_dir_all(&dir).unwrap();
            prop_assert!(result.is_ok(), "{m:?} of {}: {}", good.display(), result.unwrap_err());
        }
    }

    /// Byte strings that are not recordings at all, and the corpus cut at every kind of place: a
    /// table of cases through the binary (inspect, diff both ways, reproduce): exit 0, 1 or 2, never
    /// a panic, and an exit 2 names the file.
    #[test]
    fn damaged_files_are_refused_as_unusable_through_every_command() {
        let dir = scratch_dir("readers-damaged");
        let files = corpus();
        let good = &files[0].0;
        let mut cases: Vec<(String, Vec<u8>)> = vec![
            ("one byte".into(), vec![0]),
            ("the magic only".into(), b"RRF2".to_vec()),
            ("the stream header only".into(), files[0].1[..12].to_vec()),
            ("text".into(), b"not a recording\n".to_vec()),
            ("zeros".into(), vec![0; 4096]),
            ("0xff".into(), vec![0xff; 4096]),
        ];
        for (path, bytes) in &files {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            for k in 1..8 {
                let i = bytes.len() * k / 8;
                let mut flipped = bytes.clone();
                flipped[i] ^= 0x5a;
                cases.push((format!("{name} flipped at {i}"), flipped));
                cases.push((format!("{name} cut at {i}"), bytes[..i].to_vec()));
            }
        }
        let mut refused = 0;
        for (what, bytes) in &cases {
            let bad = dir.join("bad.rrd");
            std::fs::write(&bad, bytes).unwrap();
            for args in [
                vec!["inspect", s(&bad)],
                vec!["diff", s(good), s(&bad)],
                vec!["diff", s(&bad), s(good)],
                vec!["reproduce", s(&bad)],
            ] {
                let (code, out, err) = physlab(&args);
                assert!(
                    [0, 1, 2].contains(&code),
                    "{what}: {args:?} exit {code}:\n{out}\n{err}"
                );
                if code == 2 {
                    refused += 1;
                    assert!(
                        err.contains(&format!("{}: ", bad.display())),
                        "{what}: {args:?} names no file:\n{err}"
                    );
                }
            }
        }
        assert!(refused >= cases.len(), "most damage is refused: {refused}");
        // A truncated file says so, in one well-spaced sentence.
        let bad = dir.join("cut.rrd");
        std::fs::write(&bad, &files[0].1[..files[0].1.len() - 100]).unwrap();
        let (code, _, err) = physlab(&["reproduce", s(&bad)]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("(the writing process was killed or the file cut short"),
            "{err}"
        );
        // A FIFO is not read (it could block forever), nor a device.
        let fifo = dir.join("fifo.rrd");
        let c = std::ffi::CString::new(fifo.as_os_str().as_bytes()).unwrap();
        // SAFETY: creating a FIFO at a path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        for path in [fifo.as_path(), Path::new("/dev/zero")] {
            for args in [vec!["inspect", s(path)], vec!["reproduce", s(path)]] {
                let (code, _, err) = physlab(&args);
                assert_eq!(code, 2, "{args:?}: {err}");
                assert!(err.contains("not a regular file"), "{args:?}: {err}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Two recordings with the same timed series that differ only in static data: a summary's text,
    /// a static 3D point, a static component only one of them has. Each is a difference (exit 1).
    #[test]
    fn diff_counts_static_data_in_its_verdict() {
        let dir = scratch_dir("readers-static");
        let write = |name: &str, text: &str, point: f32, extra: bool| -> PathBuf {
            let path = dir.join(name);
            let rec = rerun::RecordingStreamBuilder::new("physlab-test")
                .save(&path)
                .unwrap();
            rec.log_static("scene/summary", &rerun::TextDocument::new(text))
                .unwrap();
            rec.log_static("scene/path", &rerun::Points3D::new([[point, 0.0, 1.0]]))
                .unwrap();
            if extra {
                rec.log_static(
                    "scene/path",
                    &rerun::Points3D::update_fields().with_radii([0.5]),
                )
                .unwrap();
            }
            for i in 0..50 {
                rec.set_duration_secs("sim_time", i as f64 * 0.01);
                rec.log("scene/plots/x", &rerun::Scalars::single(i as f64))
                    .unwrap();
            }
            drop(rec);
            path
        };
        let base = write("base.rrd", "ran: 1.0", 1.0, false);
        let same = write("same.rrd", "ran: 1.0", 1.0, false);
        let (code, out, err) = physlab(&["diff", s(&base), s(&same)]);
        assert_eq!(code, 0, "{out}\n{err}");
        for (name, text, point, extra, component) in [
            ("summary.rrd", "ran: 1.5", 1.0, false, "Text"),
            ("point.rrd", "ran: 1.0", 3.1e38, false, "positions"),
            ("extra.rrd", "ran: 1.0", 1.0, true, "radii"),
        ] {
            let other = write(name, text, point, extra);
            for (a, b) in [(&base, &other), (&other, &base)] {
                let (code, out, err) = physlab(&["diff", s(a), s(b)]);
                assert_eq!(code, 1, "{name}: {out}\n{err}");
                assert!(out.contains("static data differs"), "{name}: {out}");
                assert!(out.contains(component), "{name}: {component} in {out}");
                assert!(
                    out.contains("1 of 3 shared entities differ"),
                    "{name}: {out}"
                );
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `diff` of a recording another application wrote is refused like `reproduce` refuses it.
    #[test]
    fn diff_refuses_another_applications_recording() {
        let dir = scratch_dir("readers-other");
        let other = dir.join("other.rrd");
        let rec = rerun::RecordingStreamBuilder::new("someone_else")
            .save(&other)
            .unwrap();
        rec.log("x", &rerun::Scalars::single(1.0)).unwrap();
        drop(rec);
        let good = &corpus()[0].0;
        for args in [
            vec!["diff", s(good), s(&other)],
            vec!["diff", s(&other), s(good)],
            vec!["reproduce", s(&other)],
        ] {
            let (code, _, err) = physlab(&args);
            assert_eq!(code, 2, "{args:?}: {err}");
            assert!(
                err.contains(&format!(
                    "{}: a recording of another application",
                    other.display()
                )),
                "{args:?}: {err}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The file offset of a recording's end message: its messages' 16-byte headers (kind, length)
    /// walked from its 12-byte stream header.
    fn end_message_at(bytes: &[u8]) -> usize {
        let mut at = 12;
        loop {
            let word = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
            if word(at) == 0 {
                return at;
            }
            at += 16 + word(at + 8) as usize;
        }
    }

    /// Two recordings in one file, as `rerun rrd merge` makes (one stream holding both
    /// recordings' messages) and as `cat` makes (two streams), are never read as one: every
    /// reader refuses the file, listing the recordings found (on cfd8d4a `inspect` showed `scenes:
    /// pendulum, rope` and `reproduce` re-ran one).
    #[test]
    fn a_file_holding_two_recordings_is_refused_with_their_list() {
        let dir = scratch_dir("readers-merged");
        let files = corpus();
        let find = |name: &str| &files.iter().find(|(p, _)| p.ends_with(name)).unwrap().1;
        let (pendulum, rope) = (find("pendulum.rrd"), find("rope.rrd"));
        let merged = [&pendulum[..end_message_at(pendulum)], &rope[12..]].concat();
        let good = &files
            .iter()
            .find(|(p, _)| p.ends_with("hair.rrd"))
            .unwrap()
            .0;
        for (name, bytes) in [
            ("merged.rrd", merged),
            ("cat.rrd", [&pendulum[..], &rope[..]].concat()),
        ] {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            for args in [
                vec!["inspect", s(&path)],
                vec!["reproduce", s(&path)],
                vec!["diff", s(good), s(&path)],
                vec!["diff", s(&path), s(good)],
            ] {
                let (code, _, err) = physlab(&args);
                assert_eq!(code, 2, "{args:?}: {err}");
                let listed = format!(
                    "{}: unusable file: it holds 2 recordings (as `rerun rrd merge` makes), and \
                     physlab reads one recording a file: physlab-pendulum (recording id ",
                    path.display()
                );
                assert!(err.contains(&listed), "{args:?}: {err}");
                assert!(
                    err.contains(", physlab-rope (recording id "),
                    "{args:?}: {err}"
                );
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `reproduce -o` somewhere it cannot write says so, not that the configuration does not run.
    #[test]
    fn an_unwritable_reproduce_output_is_reported_as_such() {
        let dir = scratch_dir("readers-unwritable");
        let good = &corpus()[0].0;
        let file = dir.join("file.txt");
        std::fs::write(&file, "a file, not a folder\n").unwrap();
        for out in [file.join("re.rrd"), PathBuf::from("/proc/re.rrd")] {
            let (code, _, err) = physlab(&["reproduce", s(good), "-o", s(&out)]);
            assert_ne!(code, 0, "{err}");
            assert!(err.contains(s(&out)), "{err}");
            assert!(!err.contains("does not run with this build"), "{err}");
            assert!(!out.exists());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Runs physlab with arguments that may not be UTF-8.
    fn physlab_os(args: &[&OsStr]) -> (i32, String, String) {
        let out = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(args)
            .output()
            .unwrap();
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        (out.status.code().unwrap_or(-1), stdout, stderr)
    }

    /// File names that are not UTF-8, for a scene, for reproduce's recording and its `-o`: the runs
    /// work, and the command line is recorded so that bash gives back the same bytes.
    #[test]
    fn a_command_line_that_is_not_utf8_runs_and_is_recorded_losslessly() {
        let dir = scratch_dir("readers-bytes");
        let os = |p: &PathBuf| p.as_os_str().to_owned();
        for name in [
            &b"\xff\xfe.rrd"[..],
            b"caf\xe9 \xc3.rrd",
            b"new\nline'\\.rrd",
        ] {
            let out = dir.join(OsStr::from_bytes(name));
            let (code, _, err) = physlab_os(&[
                OsStr::new("pendulum"),
                OsStr::new("--duration"),
                OsStr::new("0.5"),
                OsStr::new("-q"),
                OsStr::new("-o"),
                &os(&out),
            ]);
            assert_eq!(code, 0, "{name:?}: {err}");
            let info = physlab::rrd::inspect::read_recording(&out).unwrap();
            let line = &info.properties["command_line"];
            assert!(!line.contains('\n'), "{line}");
            // The recorded -o argument, read back by bash, is the file's name byte for byte.
            let word = line.rsplit(" -o ").next().unwrap();
            let back = Command::new("bash")
                .arg("-c")
                .arg(format!("printf %s {word}"))
                .output()
                .unwrap();
            assert_eq!(back.stdout, out.as_os_str().as_bytes(), "{line}");
            let again = dir.join(OsStr::from_bytes(b"re\xff.rrd"));
            let (code, report, err) = physlab_os(&[
                OsStr::new("reproduce"),
                &os(&out),
                OsStr::new("-o"),
                &os(&again),
            ]);
            assert_eq!(code, 0, "{name:?}: {report}\n{err}");
            assert!(report.contains("verdict: bit-identical"), "{report}");
            assert!(again.exists());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A hair recording made on one thread reproduces on others: nothing compared depends on the
    /// thread count (the summary prints it but does not record it).
    #[test]
    fn a_hair_recording_reproduces_on_any_thread_count() {
        let dir = scratch_dir("readers-threads");
        let out = dir.join("hair.rrd");
        let (code, summary, err) = physlab(&[
            "hair",
            "--strands",
            "24",
            "--duration",
            "0.5",
            "--threads",
            "1",
            "-q",
            "-o",
            s(&out),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(summary.contains("threads: 1 "), "{summary}");
        for threads in [None, Some("3"), Some("2")] {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_physlab"));
            cmd.args(["reproduce", "-v", s(&out)]);
            if let Some(n) = threads {
                cmd.env("RAYON_NUM_THREADS", n);
            }
            let result = cmd.output().unwrap();
            let report = String::from_utf8_lossy(&result.stdout);
            assert_eq!(result.status.code(), Some(0), "{threads:?}: {report}");
            assert!(report.contains("verdict: bit-identical"), "{report}");
            assert!(report.contains("/hair/summary: identical"), "{report}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `--log-strands` is part of the recorded scene: reproduce draws the same strands, and
    /// `inspect --config-out` writes it into the scene file, which runs it again.
    #[test]
    fn log_strands_is_recorded_and_reproduced() {
        let dir = scratch_dir("readers-strands");
        let out = dir.join("hair.rrd");
        let (code, _, err) = physlab(&[
            "hair",
            "--strands",
            "16",
            "--duration",
            "0.3",
            "--log-strands",
            "3",
            "-q",
            "-o",
            s(&out),
        ]);
        assert_eq!(code, 0, "{err}");
        let (code, report, err) = physlab(&["reproduce", s(&out)]);
        assert_eq!(code, 0, "{report}\n{err}");
        assert!(report.contains("verdict: bit-identical"), "{report}");
        let toml = dir.join("scene.toml");
        let (code, _, err) = physlab(&["inspect", s(&out), "--config-out", s(&toml)]);
        assert_eq!(code, 0, "{err}");
        let text = std::fs::read_to_string(&toml).unwrap();
        assert!(text.contains("log_strands = 3"), "{text}");
        let again = dir.join("again.rrd");
        let (code, _, err) = physlab(&["hair", "--config", s(&toml), "-q", "-o", s(&again)]);
        assert_eq!(code, 0, "{err}");
        let (code, out, err) = physlab(&["diff", s(&out), s(&again)]);
        assert_eq!(code, 0, "{out}\n{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every number an Arrow value holds, element by element, depth first (struct fields in order):
    /// written here from Arrow's own accessors, apart from physlab's in-place reader.
    fn arrow_numbers(a: &dyn rerun::external::arrow::array::Array, out: &mut Vec<f64>) {
        use rerun::external::arrow::array::AsArray as _;
        use rerun::external::arrow::datatypes::{DataType, Float32Type, Float64Type, UInt32Type};
        for i in 0..a.len() {
            if a.is_null(i) && !matches!(a.data_type(), DataType::Float32 | DataType::Float64) {
                continue;
            }
            match a.data_type() {
                DataType::Float64 => out.push(a.as_primitive::<Float64Type>().value(i)),
                DataType::Float32 => out.push(a.as_primitive::<Float32Type>().value(i).into()),
                DataType::UInt32 => out.push(a.as_primitive::<UInt32Type>().value(i).into()),
                DataType::List(_) => arrow_numbers(a.as_list::<i32>().value(i).as_ref(), out),
                DataType::FixedSizeList(..) => {
                    arrow_numbers(a.as_fixed_size_list().value(i).as_ref(), out)
                }
                _ => {}
            }
        }
    }

    /// A row's time on `sim_time` (`None`: static) and its numbers.
    type TimedNumbers = (Option<i64>, Vec<f64>);

    /// physlab reads its recordings (its own framing, LZ4 and zero-copy Arrow decoding) as Rerun's
    /// own decoder does: for every recording in the corpus, every series has the same rows at the
    /// same times, and every float of every row of the float-valued components is the same, bit
    /// for bit.
    #[test]
    fn physlabs_reader_reads_what_rerun_decodes() {
        use rerun::external::arrow::array::Array as _;
        use rerun::external::re_log_encoding::DecoderApp;
        use rerun::log::{Chunk, LogMsg};
        let mut compared_values = 0;
        for (path, _) in corpus() {
            let ours = physlab::rrd::compare::read_contents(&path).unwrap();
            let mut theirs: std::collections::BTreeMap<(String, String), Vec<TimedNumbers>> =
                Default::default();
            let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
            for msg in DecoderApp::decode_lazy(file) {
                let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
                    continue;
                };
                let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
                let entity = chunk.entity_path().to_string();
                if !store_id.is_recording() || entity.starts_with("/__properties") {
                    continue;
                }
                let times = chunk
                    .timelines()
                    .get(&rerun::TimelineName::from("sim_time"))
                    .map(|c| c.times_raw().to_vec());
                for descriptor in chunk.component_descriptors() {
                    let list = chunk.components().get_array(descriptor.component).unwrap();
                    let rows = theirs
                        .entry((entity.clone(), descriptor.component.as_str().to_string()))
                        .or_default();
                    for r in (0..chunk.num_rows()).filter(|&r| !list.is_null(r)) {
                        let mut nums = Vec::new();
                        arrow_numbers(list.value(r).as_ref(), &mut nums);
                        rows.push((times.as_ref().map(|t| t[r]), nums));
                    }
                }
            }
            assert_eq!(
                ours.keys().collect::<Vec<_>>(),
                theirs.keys().collect::<Vec<_>>(),
                "{}: the series",
                path.display()
            );
            for (key, their_rows) in &mut theirs {
                their_rows.sort_by_key(|r| r.0);
                let our_rows = &ours[key];
                let at = |what: &str| format!("{} {key:?}: {what}", path.display());
                assert_eq!(our_rows.len(), their_rows.len(), "{}", at("rows"));
                for (o, (time, nums)) in our_rows.iter().zip(their_rows.iter()) {
                    assert_eq!(o.time, *time, "{}", at("time"));
                    // Components of floats only (physlab also reads integers, booleans and texts).
                    let floats = !o.nums.is_empty() && o.nums.len() == nums.len();
                    if floats {
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&o.nums), bits(nums), "{}", at("values"));
                        compared_values += nums.len();
                    }
                }
            }
            assert!(!ours.is_empty(), "{}: no series", path.display());
        }
        // The study recording holds tables (texts); the scenes' hold the floats.
        assert!(compared_values > 3000, "{compared_values} values");
    }
}

#[cfg(feature = "rerun")]
mod ctrl_c {
    //! `diff` and `reproduce` answer Ctrl-C in every phase of reading and re-running. Beside the
    //! other reader tests: its signal times are calibrated on uninterrupted runs, which the heavier
    //! signal tests of `tests/interrupt.rs` would slow while they run.

    use std::path::{Path, PathBuf};
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    use crate::common::{physlab, s, scratch_dir};

    /// A recording large enough that reading it takes seconds (made once per test): about 200
    /// MB of hair strands, whose diff takes about 2 s on a quiet 2-core machine with the file in
    /// the page cache (100 MB took 1.1 s, too short to signal inside). Hair, because a long
    /// pendulum run draws at most 6000 3D frames and stays small.
    fn large_recording(dir: &Path) -> PathBuf {
        let big = dir.join("big.rrd");
        let (code, _, err) = physlab(&[
            "hair",
            "--strands",
            "2000",
            "--log-strands",
            "2000",
            "-q",
            "-o",
            s(&big),
        ]);
        assert_eq!(code, 0, "{err}");
        big
    }

    /// Sends SIGINT after `after` and returns the exit code, stderr and how long the process took
    /// to end after the signal.
    fn interrupt(args: &[&str], after: Duration) -> (Option<i32>, String, Duration) {
        let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(after);
        let sent = Instant::now();
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
        let out = child.wait_with_output().unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
            sent.elapsed(),
        )
    }

    /// Ctrl-C while diff reads, while reproduce re-runs and while it compares: exit 130 within a
    /// second, with a message that says so (not "differ", not "does not run with this build").
    #[test]
    fn every_reading_phase_answers_ctrl_c_within_a_second() {
        let dir = scratch_dir("readers-interrupt");
        let big = large_recording(&dir);
        // How long an uninterrupted diff takes: the signals must land well inside it, so the
        // faster of two runs (the machine's load varies).
        let whole = (0..2)
            .map(|_| {
                let started = Instant::now();
                let (code, _, err) = physlab(&["diff", s(&big), s(&big)]);
                assert_eq!(code, 0, "{err}");
                started.elapsed()
            })
            .min()
            .unwrap();
        // (A 200 MB diff takes about a second on a quiet 2-core machine.)
        assert!(
            whole > Duration::from_millis(700),
            "diff of the large file took only {whole:?}"
        );
        // How long an uninterrupted reproduce takes (it re-runs, then compares): the signals land
        // early (re-running) and late (comparing) inside it.
        // The faster of two, as for diff: the first run also warms the file into the page cache
        // (reproduce copies it before reading), and a signal timed from it can come too late.
        let reproducing = (0..2)
            .map(|_| {
                let started = Instant::now();
                let (code, _, err) = physlab(&["reproduce", s(&big)]);
                assert_eq!(code, 0, "{err}");
                started.elapsed()
            })
            .min()
            .unwrap();
        let cases: [(&[&str], Duration); 4] = [
            (&["diff", s(&big), s(&big)], whole.mul_f64(0.3)),
            (&["diff", s(&big), s(&big)], whole.mul_f64(0.6)),
            (&["reproduce", s(&big)], reproducing.mul_f64(0.3)),
            (&["reproduce", s(&big)], reproducing.mul_f64(0.8)),
        ];
        for (args, after) in cases {
            let (code, err, took) = interrupt(args, after);
            assert_eq!(code, Some(130), "{args:?} after {after:?}: {err}");
            assert!(took < Duration::from_secs(1), "{args:?} took {took:?}");
            assert!(err.contains("interrupted"), "{args:?}: {err}");
            assert!(!err.contains("does not run with this build"), "{err}");
            assert!(!err.contains("differ"), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[cfg(feature = "rerun")]
mod untrusted {
    //! A recording is a stranger's file (issue 43): what it says is printed escaped, the commands
    //! physlab suggests are built by physlab and quoted, `reproduce` reads it once, a recording
    //! without data never verifies, a refused input leaves no folder behind, and a re-run that
    //! would take hours is refused before it starts.

    use std::io::{BufRead as _, BufReader};
    use std::path::Path;
    use std::process::{Command, Stdio};
    use std::time::Duration;

    use physlab::shell::{escaped, shell_word, shell_words};

    use crate::common::{craft, physlab, run_within, s, scratch_dir};

    const PENDULUM: &str = "[pendulum]\nduration = 0.1\nmethods = [\"verlet\"]\n";
    /// A line of its own that claims the recording verified, the screen cleared and the
    /// window retitled before it.
    const FORGED: &str = "ok\n\x1b[2J\x1b]0;owned\x07verdict: bit-identical (3 entities)";

    /// Every property a report prints holds escape sequences and a forged verdict: `inspect`,
    /// `reproduce` and `diff` print none of their control characters (ESC shown as `\x1b`), and
    /// no line but their own starts with `verdict:`.
    #[test]
    fn what_a_recording_says_is_printed_escaped() {
        let dir = scratch_dir("untrusted-escape");
        let bad = dir.join("bad.rrd");
        let props = [
            ("scenes", "pendulum"),
            ("config", PENDULUM),
            ("command_line", FORGED),
            ("methods", FORGED),
            ("git_commit", FORGED),
            ("physlab_version", FORGED),
            ("rerun_sdk_version", FORGED),
        ];
        let run = [("pendulum_status", "complete"), ("pendulum_ended", FORGED)];
        craft(&bad, "physlab-pendulum", &props, &run, true);
        let other = dir.join("other.rrd");
        let mut b = props;
        b[1].1 = "[pendulum]\nduration = 0.2\nmethods = [\"verlet\"]\n";
        craft(&other, "physlab-pendulum", &b, &run, true);
        for (args, verdicts) in [
            (vec!["inspect", s(&bad)], 0),
            (vec!["reproduce", s(&bad)], 1),
            (vec!["reproduce", "-v", s(&bad)], 1),
            (vec!["diff", s(&bad), s(&other)], 1),
            (vec!["diff", "-v", s(&bad), s(&other)], 1),
        ] {
            let (code, out, err) = physlab(&args);
            let all = format!("{out}{err}");
            assert!([0, 1].contains(&code), "{args:?}: {all}");
            assert!(
                !all.contains('\x1b') && !all.contains('\x07'),
                "{args:?}: {all:?}"
            );
            assert!(
                all.contains("\\x1b[2J\\x1b]0;owned\\x07verdict"),
                "{args:?}: {all}"
            );
            let claimed = all.lines().filter(|l| l.starts_with("verdict:")).count();
            assert_eq!(claimed, verdicts, "{args:?}: {all}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The lines of `text` that suggest a command.
    fn suggested(text: &str) -> Vec<String> {
        text.lines()
            .filter_map(|l| {
                ["made again by: ", "run it again with: "]
                    .iter()
                    .find_map(|m| {
                        l.split_once(m)
                            .map(|(_, c)| c.trim_end_matches(')').to_string())
                    })
            })
            .collect()
    }

    /// Recordings whose command line, scenes, file name or scene file name carry shell syntax:
    /// every command `inspect` suggests, read by bash, runs nothing of it (each payload would
    /// create a file).
    #[test]
    fn suggested_commands_run_nothing_a_recording_holds() {
        let dir = scratch_dir("untrusted-shell");
        let pwned = |k: usize| dir.join(format!("pwned{k}"));
        let scene = |scenes: String| -> Vec<(&str, String)> {
            vec![
                ("scenes", scenes),
                ("config", PENDULUM.into()),
                ("command_line", "physlab pendulum".into()),
            ]
        };
        let cases: Vec<(String, Vec<(&str, String)>)> = vec![
            (
                "diff.rrd".into(),
                vec![
                    ("scenes", "diff".into()),
                    (
                        "command_line",
                        "physlab diff a.rrd b.rrd -o d.rrd; >pwned1 #".into(),
                    ),
                ],
            ),
            ("scenes.rrd".into(), scene("pendulum $(>pwned2)".into())),
            (
                "study.rrd".into(),
                vec![
                    ("scenes", "study convergence".into()),
                    (
                        "command_line",
                        "physlab study convergence --csv $(>pwned3)".into(),
                    ),
                ],
            ),
            ("x $(>pwned4).rrd".into(), scene("pendulum".into())),
        ];
        let config = dir.join("scene $(>pwned5).toml");
        let mut shown = 0;
        for (name, props) in &cases {
            let path = dir.join(name);
            let props: Vec<(&str, &str)> = props.iter().map(|(k, v)| (*k, v.as_str())).collect();
            craft(&path, "physlab-pendulum", &props, &[], true);
            for args in [
                vec!["inspect", s(&path)],
                vec!["inspect", s(&path), "--config-out", s(&config)],
            ] {
                let (code, out, err) = physlab(&args);
                let _ = std::fs::remove_file(&config);
                assert!([0, 2].contains(&code), "{args:?}: {out}{err}");
                for command in suggested(&format!("{out}{err}")) {
                    shown += 1;
                    // Read by bash as words (`set --`): a command substitution or a `;` in
                    // them would run here. Nothing is on this PATH.
                    Command::new("/bin/bash")
                        .arg("-c")
                        .arg(format!("set -- {command}"))
                        .current_dir(&dir)
                        .env("PATH", s(&dir.join("nothing")))
                        .stderr(Stdio::null())
                        .status()
                        .unwrap();
                }
            }
        }
        for k in 1..=5 {
            assert!(!pwned(k).exists(), "payload {k} ran");
        }
        assert!(shown >= 3, "the scene recording still gets its commands");
        // A diff recording's own command line, when it is one, is still suggested, quoted anew.
        let good = dir.join("good diff.rrd");
        let line = "target/release/physlab diff a.rrd $'b c.rrd' -o d.rrd";
        craft(
            &good,
            "physlab-diff",
            &[("scenes", "diff"), ("command_line", line)],
            &[],
            true,
        );
        let (code, out, err) = physlab(&["inspect", s(&good)]);
        assert_eq!(code, 0, "{err}");
        assert!(
            out.contains("made again by: physlab diff a.rrd $'b c.rrd' -o d.rrd\n"),
            "{out}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn record(out: &Path, theta0: &str) {
        let (code, _, err) = physlab(&[
            "pendulum",
            "--duration",
            "30",
            "--theta0",
            theta0,
            "--methods",
            "rk4,verlet,dop853",
            "-q",
            "-o",
            s(out),
        ]);
        assert_eq!(code, 0, "{err}");
    }

    /// The file replaced by another run while `reproduce` re-runs it: the verdict is the first
    /// file's (read once), not a comparison of one file's configuration with the other's data.
    #[test]
    fn reproduce_reads_its_file_once() {
        let dir = scratch_dir("untrusted-once");
        let (file, other) = (dir.join("run.rrd"), dir.join("other.rrd"));
        record(&file, "30");
        record(&other, "31");
        let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["reproduce", s(&file)])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut err = BufReader::new(child.stderr.take().unwrap());
        let mut line = String::new();
        while !line.starts_with("re-running") {
            line.clear();
            assert!(err.read_line(&mut line).unwrap() > 0, "no re-run");
        }
        std::fs::rename(&other, &file).unwrap();
        let out = child.wait_with_output().unwrap();
        let report = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{report}");
        assert!(report.starts_with("verdict: bit-identical"), "{report}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A configuration without data and without an end record (and two of them) verifies
    /// nothing: refused, exit 2, not `bit-identical (0 entities)`.
    #[test]
    fn a_recording_without_data_never_verifies() {
        let dir = scratch_dir("untrusted-empty");
        let empty = dir.join("empty.rrd");
        let props = [("scenes", "pendulum"), ("config", PENDULUM)];
        craft(&empty, "physlab-pendulum", &props, &[], false);
        let (code, out, err) = physlab(&["reproduce", s(&empty)]);
        assert_eq!(code, 2, "{out}{err}");
        assert!(err.contains("holds no data to compare"), "{err}");
        assert!(!out.contains("bit-identical"), "{out}");
        let (code, out, err) = physlab(&["diff", s(&empty), s(&empty)]);
        assert_eq!(code, 2, "{out}{err}");
        assert!(err.contains("hold no data to compare"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A refused input leaves no output folder behind; another program's recording is not
    /// called physlab's.
    #[test]
    fn a_refused_input_makes_no_folder_and_another_program_is_named() {
        let dir = scratch_dir("untrusted-folders");
        let text = dir.join("text.rrd");
        std::fs::write(&text, "not a recording\n").unwrap();
        let good = dir.join("good.rrd");
        craft(
            &good,
            "physlab-pendulum",
            &[("scenes", "pendulum"), ("config", PENDULUM)],
            &[],
            true,
        );
        let made = |k: usize| dir.join(format!("made{k}"));
        let out = |k: usize| made(k).join("out").to_string_lossy().into_owned();
        for (k, args) in [
            vec!["inspect", s(&text), "--config-out"],
            vec!["diff", s(&good), s(&text), "-o"],
            vec!["reproduce", s(&text), "-o"],
        ]
        .into_iter()
        .enumerate()
        {
            let o = out(k);
            let mut args = args;
            args.push(&o);
            let (code, _, err) = physlab(&args);
            assert_eq!(code, 2, "{args:?}: {err}");
            assert!(err.contains(s(&text)), "{args:?}: {err}");
            assert!(!made(k).exists(), "{args:?} made {}", made(k).display());
        }
        let other = dir.join("other.rrd");
        craft(&other, "someone_else", &[], &[], true);
        let (code, report, err) = physlab(&["inspect", s(&other)]);
        assert_eq!(code, 0, "{err}");
        assert!(!report.contains("physlab (not recorded)"), "{report}");
        assert!(
            report.contains("written by: \"someone_else\", another application"),
            "{report}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An 11 KB recording asking for a 10^6-node rope over 200 s (hours and hundreds of GB by
    /// the direct run's pace) is refused before the re-run starts, naming its time and size.
    #[test]
    fn a_reproduce_that_would_take_hours_is_refused_up_front() {
        let dir = scratch_dir("untrusted-huge");
        let huge = dir.join("huge.rrd");
        let config =
            "[rope]\nnodes = 1000000\ndt = 0.002\nduration = 200.0\nmethods = [\"verlet\"]\n";
        craft(
            &huge,
            "physlab-rope",
            &[("scenes", "rope"), ("config", config)],
            &[],
            true,
        );
        let size = std::fs::metadata(&huge).unwrap().len();
        assert!(size < 20_000, "{size} B");
        let (code, err, took) = run_within(&["reproduce", s(&huge)], Duration::from_secs(10));
        assert_eq!(code, 2, "{err}");
        assert!(took < Duration::from_millis(800), "{took:?}");
        assert!(
            err.contains("1.0e11 node-steps (at least about 50 min") && err.contains("GB"),
            "{err}"
        );
        assert!(err.contains("--allow-long"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Runs whose cost their configuration does not tell (issue 43, F4–F6), each as
    /// (scene, configuration, a duration of hours, a duration of seconds): an adaptive method's
    /// own steps at rtol 1e-14 (about 230 a simulated second), hair's spring inner steps (3741
    /// per substep at this stiffness) and sofroniou10's 35 force evaluations a step. main judged
    /// the long ones by 30 ns a node-step and its samples: 3 s, 2 s and 5 min. The short ones
    /// take 2–3 s on a quiet machine: the estimate is stated from the pace after 0.5 s, before
    /// half the run.
    const COSTLY: [(&str, &str, f64, f64); 3] = [
        (
            "pendulum",
            "methods = [\"dopri5\"]\nrtol = 1e-14\ndt = 10.0\n",
            1e9,
            6e4,
        ),
        (
            "hair",
            "methods = [\"semi-implicit-euler\"]\nstiffness = 4e10\nstrands = 20\n",
            3600.0,
            4.0,
        ),
        (
            "rope",
            "methods = [\"sofroniou10\"]\nnodes = 1000\n",
            1e4,
            8.0,
        ),
    ];

    /// A crafted recording asking for `COSTLY[i]` over `duration`.
    fn costly(path: &Path, i: usize, duration: f64) {
        let (scene, config, _, _) = COSTLY[i];
        let config = format!("[{scene}]\n{config}duration = {duration:?}\n");
        let app = format!("physlab-{scene}");
        let app: &'static str = Box::leak(app.into_boxed_str());
        craft(
            path,
            app,
            &[("scenes", scene), ("config", &config)],
            &[],
            true,
        );
    }

    /// Each costly run of hours is refused by `reproduce` within its first seconds, naming
    /// its time (over the 10 min limit: hours, or tens of minutes on a fast machine), and leaves
    /// no `-o` behind; on main each started (its estimate: seconds).
    #[test]
    fn a_reproduce_whose_steps_cost_more_than_its_configuration_says_is_refused_at_once() {
        let dir = scratch_dir("untrusted-costly");
        for (i, (scene, _, long, _)) in COSTLY.iter().enumerate() {
            let file = dir.join(format!("{scene}.rrd"));
            costly(&file, i, *long);
            let out = dir.join(format!("{scene}-rerun.rrd"));
            let args = ["reproduce", s(&file), "-o", s(&out)];
            let (code, err, _) = run_within(&args, Duration::from_secs(15));
            assert_eq!(code, 2, "{scene}: {err}");
            let refusal = err.lines().last().unwrap_or_default();
            assert!(
                refusal.contains(&format!("{scene}: this takes about "))
                    && (refusal.contains(" h ") || refusal.contains(" min "))
                    && refusal.contains("unless --allow-long is given"),
                "{scene}: {err}"
            );
            assert!(
                !out.exists(),
                "{scene}: a refused re-run wrote {}",
                out.display()
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The estimate `reproduce` states is the run's time: each costly run of seconds, re-run,
    /// takes between half and twice what was stated at its start (the statement is rounded to
    /// the second; a loaded machine's pace varies).
    #[test]
    fn the_estimate_reproduce_states_is_the_time_its_re_run_takes() {
        let dir = scratch_dir("untrusted-estimate");
        for (i, (scene, _, _, short)) in COSTLY.iter().enumerate() {
            let file = dir.join(format!("{scene}.rrd"));
            costly(&file, i, *short);
            let (_, out, err) = physlab(&["reproduce", s(&file)]);
            let number = |text: &str, before: &str, after: &str| -> f64 {
                let from = text
                    .find(before)
                    .unwrap_or_else(|| panic!("{scene}: {text}"));
                let rest = &text[from + before.len()..];
                rest[..rest.find(after).unwrap()].parse().unwrap()
            };
            let stated = number(&err, &format!("{scene}: this takes about "), " s ");
            let took = number(&out, "re-ran in ", " s");
            let ratio = stated / took;
            eprintln!("{scene}: stated {stated} s, took {took} s");
            assert!(
                (0.5..=2.0).contains(&ratio),
                "{scene}: stated {stated} s, took {took} s"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `diff` leads with the lanes whose outcome differs (issue 41.5); `-q` is accepted by
    /// `inspect`, `reproduce` and `diff`, and a study recording is refused for what it is, not for
    /// wall-clock timings a drift study does not have (41.6).
    #[test]
    fn diff_leads_with_outcomes_and_the_readers_take_q() {
        let dir = scratch_dir("untrusted-outcomes");
        let config = "[rope]\nduration = 3.0\nmethods = [\"explicit-euler\", \"verlet\"]\n";
        let props = [
            ("scenes", "rope"),
            ("config", config),
            ("methods", "explicit-euler,verlet"),
        ];
        let ended = |e: &'static str| [("rope_status", "complete"), ("rope_ended", e)];
        let (a, b) = (dir.join("a.rrd"), dir.join("b.rrd"));
        let diverged = "complete: t = 3 s, 300 ticks; explicit-euler stopped at t = 1.25 s \
                        (tick 125): diverged";
        craft(&a, "physlab-rope", &props, &ended(diverged), true);
        craft(
            &b,
            "physlab-rope",
            &props,
            &ended("complete: t = 3 s, 300 ticks"),
            true,
        );
        let (code, out, err) = physlab(&["diff", "-q", s(&a), s(&b)]);
        assert!([0, 1].contains(&code), "{out}{err}");
        let second = out.lines().nth(1).unwrap_or_default();
        assert_eq!(
            second, "  rope explicit-euler: diverged at t = 1.25 s in A, completed in B",
            "{out}"
        );
        let (code, _, err) = physlab(&["inspect", "-q", s(&a)]);
        assert_eq!(code, 0, "{err}");
        let drift = dir.join("drift.rrd");
        let study = [
            ("scenes", "study pendulum"),
            ("config", "[pendulum]\n"),
            ("command_line", "physlab study drift"),
        ];
        craft(&drift, "physlab-study", &study, &[], true);
        let (code, _, err) = physlab(&["reproduce", "-q", s(&drift)]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("a study recording"), "{err}");
        assert!(!err.contains("wall-clock"), "{err}");
        assert!(
            err.contains("run its command line again: physlab study drift)"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every word comes back byte for byte through bash's own reading of the quoting.
    #[test]
    fn words_are_quoted_losslessly_for_bash() {
        let words: [&[u8]; 9] = [
            b"pendulum",
            b"--theta0=-30",
            b"\xff\xfe.rrd",
            b"a b",
            b"it's",
            b"back\\slash\n\ttab",
            b"",
            "\u{e9}t\u{e9} \u{7f}\u{85}".as_bytes(),
            b"$HOME;`x`\"y\"",
        ];
        for word in words {
            let quoted = shell_word(word);
            assert!(!quoted.contains('\n'), "{quoted}");
            let out = std::process::Command::new("bash")
                .arg("-c")
                .arg(format!("printf %s {quoted}"))
                .env("LC_ALL", "C")
                .output()
                .expect("bash runs");
            assert_eq!(out.stdout, word, "{quoted}");
        }
        // Read back by physlab too, word by word; text it cannot have made is refused.
        let line: Vec<String> = words.iter().map(|w| shell_word(w)).collect();
        let back = shell_words(&line.join(" ")).unwrap();
        assert_eq!(back, words.map(<[u8]>::to_vec));
        for forged in ["a; b", "$(x)", "a  b", "$'x", "`x`", "a ", "$'\\q'"] {
            assert_eq!(shell_words(forged), None, "{forged}");
        }
    }

    /// Control characters and bidirectional overrides come out as escapes; other text as it is.
    #[test]
    fn text_from_a_recording_is_shown_escaped() {
        assert_eq!(escaped("physlab 0.1 — ω"), "physlab 0.1 — ω");
        assert_eq!(
            escaped("a\x1b[2J\nverdict: ok\r\t\u{7f}\u{85}\u{202e}"),
            "a\\x1b[2J\\nverdict: ok\\r\\t\\x7f\\xc2\\x85\\xe2\\x80\\xae"
        );
    }
}

/// Compares one series of (time [ns], value) rows written to two recordings.
fn compare_series(dir: &Path, a: &[(i64, f64)], b: &[(i64, f64)], tolerance: f64) -> SeriesDiff {
    let write = |name: &str, rows: &[(i64, f64)]| {
        let path = dir.join(name);
        let rec = rerun::RecordingStreamBuilder::new("physlab-test")
            .save(&path)
            .unwrap();
        for &(t, v) in rows {
            rec.set_time("sim_time", std::time::Duration::from_nanos(t as u64));
            rec.log("x", &rerun::Scalars::single(v)).unwrap();
        }
        path
    };
    let spec = StreamSpec {
        tolerance,
        skip: &|_: &str| false,
        rename_b: None,
        cap_b: false,
    };
    let (a, b) = (write("a.rrd", a), write("b.rrd", b));
    let mut found = compare_files(&a, &b, &spec, &mut |_, _, _| Ok(())).unwrap();
    found.timed.pop_first().unwrap().1
}

#[test]
fn finds_the_first_difference_beyond_the_tolerance_and_the_largest() {
    let dir = std::env::temp_dir().join(format!("physlab-rrd-pairs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = [(0, 1.0), (10, 2.0), (20, -4.0), (30, 0.0)];
    let b = [(0, 1.0), (10, 2.0 + 1e-15), (20, -4.5), (30, 0.0)];
    let d = compare_series(&dir, &a, &b, 0.0);
    assert_eq!(d.first.as_ref().unwrap().time, Some(10));
    assert_eq!(d.largest.as_ref().unwrap().time, Some(20));
    assert_eq!(d.largest.as_ref().unwrap().abs(), 0.5);
    assert!(!d.same());
    // Relative to the series' scale 4: 1e-15 passes 1e-3, 0.5 does not.
    let d = compare_series(&dir, &a, &b, 1e-3);
    assert_eq!(d.first.as_ref().unwrap().time, Some(20));
    assert!(!compare_series(&dir, &a, &b, 0.2).bit_identical());
    assert!(compare_series(&dir, &a, &b, 0.2).same());
    // A missing row is a difference.
    assert_eq!(compare_series(&dir, &a, &b[..3], 0.0).unpaired, 1);
    assert_eq!(time_text(Some(1_460_000_000)), "t = 1.46 s");
    assert_eq!(time_text(Some(3_000_000_000)), "t = 3 s");
    assert_eq!(time_text(Some(-5)), "t = -0.000000005 s");
    std::fs::remove_dir_all(&dir).unwrap();
}
