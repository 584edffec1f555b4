//! `physlab reproduce` and `physlab diff` end to end: a run reproduces itself bit-identically, an
//! altered value is caught at its entity and time, Euler and Verlet part where an independent
//! computation of both recurrences says, a run cut short reproduces up to where it ended, bad
//! input is refused with exit 2, and identical runs write identical chunks.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::Duration;

use common::{physlab, scratch_dir};
use rerun::external::arrow::array::{Array as _, Float64Array, ListArray};
use rerun::external::re_log_encoding::{DecoderApp, Encoder, EncodingOptions};
use rerun::log::{Chunk, LogMsg};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

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
    assert!(report.contains("verdict: bit-identical"), "{report}");
    for entity in [
        "identical  /pendulum/plots/theta/verlet",
        "identical  /pendulum/rk4/bob",
        "identical  /rope/plots/max_strain/explicit-euler",
        "identical  /hair/ftl/strands",
        "identical  /pendulum/events",
        "identical  /pendulum/summary",
        "identical  /rope/summary",
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
        .find(|l| l.contains("DIFFERS"))
        .unwrap_or_else(|| panic!("no DIFFERS line:\n{report}"));
    assert!(
        line.contains("/pendulum/plots/theta/rk4: first differs at t = 1.5 s"),
        "{line}"
    );
    assert!(
        line.contains(&format!("recorded {:e}, recomputed {:e}", was + 1e-9, was)),
        "{line}"
    );
    assert_eq!(
        report.matches("DIFFERS").count(),
        2,
        "one entity and the verdict:\n{report}"
    );
    assert!(report.contains("verdict: DIFFERS in 1 of"), "{report}");
    // The summary table is recomputed from the true values: it agrees with the recording.
    assert!(report.contains("identical  /pendulum/summary"), "{report}");
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
    let (code, report, err) = physlab(&["diff", s(&e), s(&v), "--tolerance", "0.01", "-o", s(&d)]);
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
    let dtheta = &decoded.scalars["/diff/pendulum/plots/theta/explicit-euler/scalars"];
    assert_eq!(dtheta.len(), 401);
    assert_eq!(dtheta[0].1, 0.0);
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

#[test]
fn bad_input_is_refused_with_exit_2_naming_the_file() {
    let dir = scratch_dir("reproduce-bad");
    let text = dir.join("notes.rrd");
    std::fs::write(&text, "not a recording\n").unwrap();
    let good = dir.join("good.rrd");
    let (code, _, err) = physlab(&["pendulum", "--duration", "2", "-q", "-o", s(&good)]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.rrd");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    // A recording of another application, and a physlab-named one without a configuration.
    let other = dir.join("other.rrd");
    let bare = dir.join("bare.rrd");
    for (app, path) in [("someone_else", &other), ("physlab", &bare)] {
        let rec = rerun::RecordingStreamBuilder::new(app).save(path).unwrap();
        rec.log("x", &rerun::Scalars::single(1.0)).unwrap();
        drop(rec);
    }
    let missing = dir.join("missing.rrd");
    for (path, message) in [
        (&text, "not a Rerun recording"),
        (&truncated, "truncated"),
        (&other, "another application"),
        (&bare, "no physlab configuration"),
        (&missing, "cannot read it"),
        (&dir, "is a folder"),
    ] {
        for args in [vec!["reproduce", s(path)], vec!["diff", s(&good), s(path)]] {
            if args[0] == "diff" && path == &bare {
                continue; // diff needs no configuration: it compares the data
            }
            let (code, out, err) = physlab(&args);
            assert_eq!(code, 2, "{args:?}: {out}\n{err}");
            assert!(
                err.contains(s(path)) && err.contains(message),
                "{args:?}: expected the file and {message:?} in:\n{err}"
            );
            assert!(!err.contains("panicked"), "{err}");
        }
    }
    let (code, _, err) = physlab(&["reproduce", s(&good), "--tolerance", "-1"]);
    assert_eq!(code, 2);
    assert!(err.contains("--tolerance -1"), "{err}");
    // Writing the re-run over the recording it is compared with is refused; the file is kept.
    let (code, _, err) = physlab(&["reproduce", s(&good), "-o", s(&good)]);
    assert_eq!(code, 2);
    assert!(err.contains("is the recording being compared"), "{err}");
    assert_eq!(std::fs::read(&good).unwrap(), bytes);
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
