//! Helpers shared by the CLI tests: scratch folders and reading recordings back with Rerun's
//! own decoder.
#![allow(dead_code)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rerun::external::arrow::array::Array as _;
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

/// A path as the `&str` a command line takes (the scratch paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A scene file that keeps every scene of `all` short, so a whole run takes seconds.
pub const SMALL: &str = r#"
[pendulum]
duration = 4.0

[rope]
duration = 1.0
nodes = 8

[hair]
strands = 40
duration = 1.0
"#;

pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("physlab-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Everything the tests need from a recording: entity paths, each plot's (sim_time ns, value)
/// rows, and whether the footer (RRD manifest) was written.
pub struct Decoded {
    pub entities: BTreeSet<String>,
    pub scalars: BTreeMap<String, Vec<(i64, f64)>>,
    pub has_footer: bool,
}

pub fn decode(path: &Path) -> Decoded {
    let scalar = rerun::Scalars::descriptor_scalars().component;
    let sim_time = rerun::TimelineName::from("sim_time");
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut messages = DecoderApp::decode_lazy(file);
    let mut entities = BTreeSet::new();
    let mut scalars: BTreeMap<String, Vec<(i64, f64)>> = BTreeMap::new();
    for msg in messages.by_ref() {
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
            continue;
        };
        if !store_id.is_recording() {
            continue; // the blueprint store
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        let entity = chunk.entity_path().to_string();
        entities.insert(entity.clone());
        if chunk.is_static() || !chunk.components().contains_component(scalar) {
            continue;
        }
        let rows = scalars.entry(entity).or_default();
        for ((t, _), v) in chunk
            .iter_indices(&sim_time)
            .zip(chunk.iter_slices::<f64>(scalar))
        {
            rows.push((t.as_i64(), v[0]));
        }
    }
    let has_footer = !messages.rrd_manifests().unwrap().is_empty();
    for rows in scalars.values_mut() {
        rows.sort_by_key(|r| r.0);
    }
    Decoded {
        entities,
        scalars,
        has_footer,
    }
}

/// Runs `physlab <subcommand> -o <out> <extra>` and asserts it is refused as bad input: exit code
/// 2, `message` on stderr, no panic, and no recording written.
pub fn assert_refused(subcommand: &str, out: &Path, extra: &[&str], message: &str) {
    let result = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([subcommand, "-o", out.to_str().unwrap()])
        .args(extra)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(2), "{extra:?}: {stderr}");
    assert!(
        stderr.contains(message),
        "{extra:?}: expected '{message}' in:\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{extra:?}: {stderr}");
    assert!(
        !out.exists(),
        "{extra:?}: no recording is written for bad input"
    );
}

/// Every row of a recording's data as text, sorted: entity, component, times on each timeline,
/// value. Row and chunk ids, the blueprint and the properties (which hold the command line) are
/// left out, so two runs of the same inputs must give equal lists.
pub fn canonical_rows(path: &Path) -> Vec<String> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut rows = Vec::new();
    for msg in DecoderApp::decode_lazy(file) {
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
            continue;
        };
        if !store_id.is_recording() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        let entity = chunk.entity_path().to_string();
        if entity.starts_with("/__properties") {
            continue;
        }
        let mut timelines: Vec<_> = chunk
            .timelines()
            .iter()
            .map(|(n, c)| (n.to_string(), c.times_raw().to_vec()))
            .collect();
        timelines.sort();
        for descriptor in chunk.component_descriptors() {
            let list = chunk.components().get_array(descriptor.component).unwrap();
            for r in 0..chunk.num_rows() {
                if list.is_null(r) {
                    continue;
                }
                let times: Vec<String> = timelines
                    .iter()
                    .map(|(n, t)| format!("{n}={}", t[r]))
                    .collect();
                rows.push(format!(
                    "{entity}|{}|{}|{:?}",
                    descriptor.component,
                    times.join(","),
                    list.value(r)
                ));
            }
        }
    }
    rows.sort();
    rows
}

/// Records the default pendulum at step `dt` over `duration`, every step plotted, to `path`.
pub fn record_pendulum(path: &Path, dt: &str, duration: &str) {
    let (code, _, err) = physlab(&[
        "pendulum",
        "-q",
        "--dt",
        dt,
        "--plot-every",
        "1",
        "--duration",
        duration,
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
}

/// The hidden partial files (`.NAME.PID.partial`) in `dir`: what a write in progress leaves.
pub fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial"))
        .collect()
}

/// Starts physlab with `args`, its standard output and error piped.
pub fn spawn(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Runs physlab with `args`; returns (exit code, stdout, stderr).
pub fn physlab(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(
        !stderr.contains("panicked"),
        "physlab {args:?} panicked:\n{stderr}"
    );
    (out.status.code().unwrap_or(-1), stdout, stderr)
}

/// Every drawn 3D point of the entities under `prefix`, one row per logged row: the entity path
/// and its `Points3D` positions or its `LineStrips3D` points, as the viewer draws them.
pub fn drawn_rows(path: &Path, prefix: &str) -> Vec<(String, Vec<[f32; 3]>)> {
    let positions = rerun::Points3D::descriptor_positions().component;
    let strips = rerun::LineStrips3D::descriptor_strips().component;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut rows = Vec::new();
    for msg in DecoderApp::decode_lazy(file) {
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg.unwrap() else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        let entity = chunk.entity_path().to_string();
        if !store_id.is_recording() || !entity.starts_with(prefix) {
            continue;
        }
        for s in chunk.iter_slices::<[f32; 3]>(positions) {
            rows.push((entity.clone(), s.to_vec()));
        }
        for s in chunk.iter_slices::<&[[f32; 3]]>(strips) {
            rows.push((entity.clone(), s.concat()));
        }
    }
    rows.retain(|r| !r.1.is_empty());
    rows
}

/// Peak resident memory [B] of one `physlab` run that succeeds.
#[allow(dead_code)]
pub fn peak_memory(args: &[&str]) -> f64 {
    let (code, peak) = exit_and_peak_memory(args);
    assert_eq!(code, 0, "{args:?}");
    peak
}

/// The exit code and peak resident memory [B] of one `physlab` run, from the kernel's account
/// of that child (reaped by `wait4`, which `Child::wait` cannot ask for the usage).
#[allow(clippy::zombie_processes, dead_code)]
pub fn exit_and_peak_memory(args: &[&str]) -> (i32, f64) {
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: a zeroed rusage is valid; wait4 fills it for this child only.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    assert!(libc::WIFEXITED(status), "{args:?}: killed");
    (libc::WEXITSTATUS(status), usage.ru_maxrss as f64 * 1024.0)
}

/// Runs physlab with `args`; returns its exit code, stderr and how long it took. A run that
/// has not ended after `limit` is killed and reported as code -1.
pub fn run_within(args: &[&str], limit: Duration) -> (i32, String, Duration) {
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
            return (status.code().unwrap_or(-1), stderr, started.elapsed());
        }
        if started.elapsed() > limit {
            child.kill().unwrap();
            let _ = child.wait();
            return (-1, "killed: did not end".into(), started.elapsed());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A recording another program (or a hostile hand) made: the `physlab` properties `props`, the
/// `physlab_run` properties `run`, and (with `data`) ten rows of one pendulum series.
pub fn craft(path: &Path, app: &str, props: &[(&str, &str)], run: &[(&str, &str)], data: bool) {
    let app: &'static str = Box::leak(app.to_string().into_boxed_str());
    let rec = rerun::RecordingStreamBuilder::new(app).save(path).unwrap();
    let values = |pairs: &[(&str, &str)]| {
        pairs.iter().fold(rerun::AnyValues::default(), |v, (k, x)| {
            let key = rerun::ComponentIdentifier::try_new(*k).unwrap();
            v.with_component::<rerun::components::Text>(key, [*x])
        })
    };
    if !props.is_empty() {
        rec.send_property("physlab", &values(props)).unwrap();
    }
    if !run.is_empty() {
        rec.send_property("physlab_run", &values(run)).unwrap();
    }
    if data {
        for i in 0..10 {
            rec.set_duration_secs("sim_time", i as f64 * 0.01);
            rec.log(
                "pendulum/plots/theta/verlet",
                &rerun::Scalars::single(i as f64),
            )
            .unwrap();
        }
    }
    drop(rec);
}
