//! The reader on whole recordings written here with Rerun's SDK, and the comparison of two series.

use std::path::{Path, PathBuf};

use super::compare::{SeriesDiff, StreamSpec, compare_within, time_text};

/// A recording of two series, `x` then `y` (or `y` then `x`), each `rows` rows on `sim_time`,
/// cut into chunks of 1024 rows as physlab cuts them.
fn two_series(dir: &Path, name: &str, x_first: bool, rows: i64) -> PathBuf {
    let path = dir.join(name);
    let rec = rerun::RecordingStreamBuilder::new("physlab-test")
        .batcher_config(rerun::log::ChunkBatcherConfig {
            flush_tick: std::time::Duration::MAX,
            flush_num_bytes: u64::MAX,
            flush_num_rows: 1024,
            ..rerun::log::ChunkBatcherConfig::DEFAULT
        })
        .save(&path)
        .unwrap();
    let order = if x_first { ["x", "y"] } else { ["y", "x"] };
    for entity in order {
        for t in 0..rows {
            rec.set_time("sim_time", std::time::Duration::from_nanos(t as u64));
            rec.log(entity, &rerun::Scalars::single(t as f64)).unwrap();
        }
    }
    drop(rec);
    path
}

/// Two recordings of the same series logged in different orders: every row of the first series
/// waits for its partner while the other file is read up to it. Read in the same order they
/// hold about a chunk each; in opposite orders past a cap they are refused, naming both files.
#[test]
fn chunks_waiting_beyond_the_cap_are_refused() {
    let dir = std::env::temp_dir().join(format!("physlab-rrd-waiting-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows = 50_000;
    let (xy, yx) = (
        two_series(&dir, "xy.rrd", true, rows),
        two_series(&dir, "yx.rrd", false, rows),
    );
    let spec = StreamSpec {
        tolerance: 0.0,
        skip: &|_: &str| false,
        rename_b: None,
        cap_b: false,
    };
    let cap = 256 << 10;
    let same = compare_within(&xy, &xy.clone(), &spec, &mut |_, _, _| Ok(()), cap).unwrap();
    assert!(
        same.timed
            .values()
            .all(|d| d.bit_identical() && d.paired == rows as usize)
    );
    let refused = compare_within(&xy, &yx, &spec, &mut |_, _, _| Ok(()), cap).unwrap_err();
    let why = refused.to_string();
    assert!(
        why.contains("come in so different an order") && why.contains("yx.rrd"),
        "{why}"
    );
    let whole = compare_within(&xy, &yx, &spec, &mut |_, _, _| Ok(()), 1 << 30).unwrap();
    assert!(
        whole
            .timed
            .values()
            .all(|d| d.bit_identical() && d.paired == rows as usize)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Compares one series of (time [ns], value) rows written to two recordings.
fn compare(dir: &Path, a: &[(i64, f64)], b: &[(i64, f64)], tolerance: f64) -> SeriesDiff {
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
    let mut found = compare_within(&a, &b, &spec, &mut |_, _, _| Ok(()), 1 << 30).unwrap();
    found.timed.pop_first().unwrap().1
}

#[test]
fn finds_the_first_difference_beyond_the_tolerance_and_the_largest() {
    let dir = std::env::temp_dir().join(format!("physlab-rrd-pairs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = [(0, 1.0), (10, 2.0), (20, -4.0), (30, 0.0)];
    let b = [(0, 1.0), (10, 2.0 + 1e-15), (20, -4.5), (30, 0.0)];
    let d = compare(&dir, &a, &b, 0.0);
    assert_eq!(d.first.as_ref().unwrap().time, Some(10));
    assert_eq!(d.largest.as_ref().unwrap().time, Some(20));
    assert_eq!(d.largest.as_ref().unwrap().abs(), 0.5);
    assert!(!d.same());
    // Relative to the series' scale 4: 1e-15 passes 1e-3, 0.5 does not.
    let d = compare(&dir, &a, &b, 1e-3);
    assert_eq!(d.first.as_ref().unwrap().time, Some(20));
    assert!(!compare(&dir, &a, &b, 0.2).bit_identical());
    assert!(compare(&dir, &a, &b, 0.2).same());
    // A missing row is a difference.
    assert_eq!(compare(&dir, &a, &b[..3], 0.0).unpaired, 1);
    assert_eq!(time_text(Some(1_460_000_000)), "t = 1.46 s");
    assert_eq!(time_text(Some(3_000_000_000)), "t = 3 s");
    assert_eq!(time_text(Some(-5)), "t = -0.000000005 s");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Text logged message by message is held by `inspect` (properties, events, entity names): past
/// the cap the file is refused, naming it, however small each message; under it, read whole.
#[test]
fn a_description_beyond_the_cap_is_refused() {
    let dir = std::env::temp_dir().join(format!("physlab-rrd-description-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("warnings.rrd");
    let rec = rerun::RecordingStreamBuilder::new("physlab-test")
        .save(&path)
        .unwrap();
    let warning = "w".repeat(1 << 20);
    for t in 0..8 {
        rec.set_time("sim_time", std::time::Duration::from_secs(t));
        let log = rerun::TextLog::new(warning.as_str()).with_level(rerun::TextLogLevel::WARN);
        rec.log("pendulum/events", &log).unwrap();
    }
    drop(rec);
    let refused = super::inspect::read_recording_within(&path, 4 << 20).unwrap_err();
    let why = refused.to_string();
    assert!(
        why.contains("warnings.rrd") && why.contains("more than 4 MiB"),
        "{why}"
    );
    let info = super::inspect::read_recording_within(&path, 16 << 20).unwrap();
    assert_eq!(info.events.len(), 8);
    assert!(info.events.iter().all(|e| e.text.len() == 1 << 20));
    std::fs::remove_dir_all(&dir).unwrap();
}
