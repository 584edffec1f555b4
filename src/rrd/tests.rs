//! The reader on whole recordings written here with Rerun's SDK, and the comparison of two series.

use std::path::{Path, PathBuf};

use super::compare::{StreamSpec, compare_within};

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
