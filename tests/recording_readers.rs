//! The recording readers (`inspect`, `diff`, `reproduce`) under abuse: any byte string as a
//! recording is a clean "unusable file" error naming the file (exit 2) or a good read, never a
//! panic; mutated copies of a corpus of real recordings are fuzzed in-process; a stop request
//! ends a read within a second (exit 130, also during `reproduce`'s re-run); `diff` counts
//! static data in its verdict and refuses another application's recording; a hair recording
//! reproduces on any core count and with its `--log-strands`; a command line that is not UTF-8
//! is recorded losslessly.

mod common;

use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{peak_memory, physlab, record_pendulum, scratch_dir};
use physlab::cli::{Cli, Command as Sub, DiffArgs};
use physlab::error::Error;
use proptest::prelude::*;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

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
    if let Err(e) = physlab::record::inspect::read_recording(path) {
        clean_error(&e, path)?;
    }
    if let Err(e) = physlab::record::compare::read_contents(path) {
        clean_error(&e, path)?;
    }
    for (a, b) in [(good, path), (path, good)] {
        let cli = Cli {
            command: Sub::Diff(DiffArgs {
                a: a.to_path_buf(),
                b: b.to_path_buf(),
                tolerance: None,
                output: None,
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
    /// `PROPTEST_CASES=20000 cargo test --release --test recording_readers mutated`.
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

/// A recording large enough that reading it takes seconds (made once per test): about 40 MB,
/// whose diff takes about 2 s on a quiet 2-core machine with the file in the page cache (half
/// of it took 1.07 s, too short to signal inside).
fn large_recording(dir: &Path) -> PathBuf {
    let big = dir.join("big.rrd");
    let (code, _, err) = physlab(&[
        "pendulum",
        "--duration",
        "600",
        "--dt",
        "1e-4",
        "--plot-every",
        "1",
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
    assert!(
        whole > Duration::from_millis(1500),
        "diff of the large file took only {whole:?}"
    );
    // How long an uninterrupted reproduce takes (it re-runs, then compares): the signals land
    // early (re-running) and late (comparing) inside it.
    let started = Instant::now();
    let (code, _, err) = physlab(&["reproduce", s(&big)]);
    let reproducing = started.elapsed();
    assert_eq!(code, 0, "{err}");
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
        let info = physlab::record::inspect::read_recording(&out).unwrap();
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
        cmd.args(["reproduce", s(&out)]);
        if let Some(n) = threads {
            cmd.env("RAYON_NUM_THREADS", n);
        }
        let result = cmd.output().unwrap();
        let report = String::from_utf8_lossy(&result.stdout);
        assert_eq!(result.status.code(), Some(0), "{threads:?}: {report}");
        assert!(report.contains("verdict: bit-identical"), "{report}");
        assert!(report.contains("identical  /hair/summary"), "{report}");
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

/// `reproduce` streams the files: reproducing a 12 MB recording takes less than 3 MB more
/// resident memory than the run it repeats takes on its own (a run's own peak varies by about
/// 1 MB). What `diff` and `reproduce` hold while comparing is measured exactly, on the heap, in
/// `tests/stream_memory.rs`.
#[test]
fn reproduce_memory_does_not_grow_with_the_file() {
    let dir = scratch_dir("streamed-memory");
    let large = dir.join("large.rrd");
    record_pendulum(&large, "1e-4", "60");
    let size = std::fs::metadata(&large).unwrap().len();
    assert!(size > 10_000_000, "{size} B");
    let run = peak_memory(&[
        "pendulum",
        "-q",
        "--dt",
        "1e-4",
        "--plot-every",
        "1",
        "--duration",
        "60",
        "-o",
        s(&dir.join("again.rrd")),
    ]);
    let reproduce = peak_memory(&["reproduce", s(&large)]);
    assert!(
        reproduce - run < 3e6,
        "reproduce: {reproduce:.3e} B, the run alone {run:.3e} B"
    );
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
        let ours = physlab::record::compare::read_contents(&path).unwrap();
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
