//! The memory a run takes and says it takes: the rope's estimate (what the memory guard refuses
//! on) against the kernel's account of a run's peak, and the notice a large run gives up front;
//! the memory reading a crafted recording takes.
//!
//! In a file of its own so that this test process stays small: the kernel's peak resident memory
//! of a child (`ru_maxrss`) starts from the spawning process's own peak, which tests running
//! beside these in a larger binary would raise above a small run's.

#![cfg(feature = "rerun")]

mod common;

use common::{exit_and_peak_memory, peak_memory, physlab, record_pendulum, s, scratch_dir};

/// The rope's memory estimate (what the memory guard refuses on and what a run says up front)
/// against the peak resident memory the kernel measures, for every method alone, for the
/// default set and for a composition with --compensated: within 10 % of the measured growth over
/// a 2-node run.
#[test]
fn the_ropes_memory_estimate_is_the_memory_it_takes() {
    use physlab::integrate::Method;
    use physlab::scene::rope::run::RopeConfig;
    let nodes = 400_000;
    // Undamped, so that every method runs (the Nyström methods refuse a damped rope); damping
    // changes no storage.
    let undamped = ["--spring-damping", "0", "--air-drag", "0"];
    let base = peak_memory(
        &[
            &[
                "rope",
                "-q",
                "--no-record",
                "--nodes",
                "2",
                "--duration",
                "0.002",
            ][..],
            &undamped,
        ]
        .concat(),
    );
    let default: Vec<Method> = Method::DEFAULT.to_vec();
    let mut sets: Vec<(Vec<Method>, bool)> =
        Method::ALL.iter().map(|&m| (vec![m], false)).collect();
    sets.push((default, false));
    // Compensated summation keeps two more vectors.
    sets.push((vec![Method::KahanLi8], true));
    for (methods, compensated) in sets {
        let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
        let list = names.join(",");
        let n = nodes.to_string();
        let mut args = vec![
            "rope",
            "-q",
            "--no-record",
            "--nodes",
            &n,
            "--duration",
            "0.002",
            "--methods",
            &list,
        ];
        args.extend(undamped);
        if compensated {
            args.push("--compensated");
        }
        let measured = peak_memory(&args) - base;
        let mut config = RopeConfig {
            methods,
            ..RopeConfig::default()
        };
        config.options.compensated = compensated;
        config.params.nodes = nodes;
        let estimate = config.memory_bytes();
        assert!(
            (estimate / measured - 1.0).abs() < 0.10,
            "{list}: estimate {estimate:.3e} B, measured {measured:.3e} B"
        );
    }
}

/// A run whose state takes more than a gigabyte says so, with the estimate, before it starts;
/// a small one does not.
#[test]
fn a_run_that_takes_a_lot_of_memory_says_so_up_front() {
    let big = [
        "rope",
        "--no-record",
        "--nodes",
        "1000000",
        "--duration",
        "0.001",
    ];
    let (code, _, stderr) = physlab(&big);
    assert_eq!(code, 0, "{stderr}");
    let notice = stderr.lines().next().unwrap_or_default();
    assert!(
        notice.starts_with("rope: its state takes about 1.3 GB of memory"),
        "{stderr}"
    );
    let (code, _, stderr) = physlab(&["rope", "--no-record", "--duration", "0.01"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("of memory"), "{stderr}");
}

/// Writes an LZ4 block that decompresses to `n` zero bytes: one literal zero, then a match of
/// the byte before (offset 1) for all but the last 5 bytes, which LZ4's format keeps as
/// literals. About n / 255 bytes (LZ4's largest expansion), written a piece at a time so that
/// this test process stays small (see the file's note).
fn write_lz4_zeros(out: &mut impl std::io::Write, n: usize) -> usize {
    // Token: 1 literal, a match length of 15 + 4 or more; the literal; the offset.
    let rest = n - 1 - 5 - 4 - 15;
    let piece = [255u8; 1 << 16];
    out.write_all(&[0x1f, 0, 1, 0]).unwrap();
    for k in (0..rest / 255).step_by(piece.len()) {
        out.write_all(&piece[..piece.len().min(rest / 255 - k)])
            .unwrap();
    }
    out.write_all(&[(rest % 255) as u8, 0x50, 0, 0, 0, 0, 0])
        .unwrap(); // then 5 literals
    4 + rest / 255 + 7
}

/// A recording (Rerun's stream header, one Arrow message of physlab's pendulum store) whose
/// message decompresses to `n` zero bytes from about n / 255.
fn zeros_recording(path: &std::path::Path, n: usize) {
    use re_protos::common::v1alpha1::{ApplicationId, Compression, StoreId, StoreKind};
    use re_protos::external::prost::{self, Message as _};
    use re_protos::log_msg::v1alpha1::{ArrowMsg, Encoding};
    use std::io::Write as _;
    let payload = write_lz4_zeros(&mut std::io::sink(), n);
    // The message without its payload, then the payload's field (5, length-delimited) by hand.
    let mut message = ArrowMsg {
        store_id: Some(StoreId {
            kind: StoreKind::Recording as i32,
            recording_id: "zeros".into(),
            application_id: Some(ApplicationId {
                id: "physlab-pendulum".into(),
            }),
        }),
        compression: Compression::Lz4 as i32,
        uncompressed_size: n as u64,
        encoding: Encoding::ArrowIpc as i32,
        ..ArrowMsg::default()
    }
    .encode_to_vec();
    message.push(5 << 3 | 2);
    prost::encode_length_delimiter(payload, &mut message).unwrap();
    let corpus = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/rrd-corpus/pendulum.rrd"
    );
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut header = [0; 12]; // the stream header
    std::io::Read::read_exact(&mut std::fs::File::open(corpus).unwrap(), &mut header).unwrap();
    file.write_all(&header).unwrap();
    file.write_all(&2u64.to_le_bytes()).unwrap(); // an Arrow message
    file.write_all(&((message.len() + payload) as u64).to_le_bytes())
        .unwrap();
    file.write_all(&message).unwrap();
    write_lz4_zeros(&mut file, n);
    file.flush().unwrap();
}

/// Decompression amplification: a 4 MB recording whose one message decompresses to 1 GiB of
/// zeros took over 1 GiB to `inspect` and to `diff` on the reader without a cap (checked on
/// cfd8d4a); it is now refused before anything is sized by it, naming the size, exit 2, in
/// what reading a small recording takes. A message under the cap (200 MB of zeros, not Arrow
/// data) is read within the bound docs/trust.md states: at most twice the cap (256 MiB) over
/// the base, the message as stored and decompressed.
#[test]
fn a_message_that_decompresses_beyond_the_cap_is_refused_in_little_memory() {
    let dir = scratch_dir("memory-zeros");
    let good = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/rrd-corpus/pendulum.rrd"
    );
    let base = peak_memory(&["inspect", good]);
    let (huge, under) = (dir.join("huge.rrd"), dir.join("under.rrd"));
    zeros_recording(&huge, 1 << 30);
    zeros_recording(&under, 200_000_000);
    let mut block = Vec::new();
    write_lz4_zeros(&mut block, 100_000);
    let zeros = lz4_flex::block::decompress(&block, 100_000).unwrap();
    assert_eq!(
        (block.len(), zeros),
        (4 + 392 + 7, vec![0; 100_000]),
        "n / 255 bytes"
    );
    let mib = |b: f64| b / f64::from(1 << 20);
    for args in [
        vec!["inspect", s(&huge)],
        vec!["diff", good, s(&huge)],
        vec!["reproduce", s(&huge)],
    ] {
        let (code, peak) = exit_and_peak_memory(&args);
        assert_eq!(code, 2, "{args:?}");
        assert!(
            peak < base + 32e6,
            "{args:?}: {:.0} MiB over {:.0} MiB",
            mib(peak),
            mib(base)
        );
        let (_, _, stderr) = physlab(&args);
        assert!(
            stderr.contains("takes 1073741824 bytes once decompressed, more than the 268435456"),
            "{stderr}"
        );
    }
    for args in [vec!["inspect", s(&under)], vec!["diff", s(&under), good]] {
        let (code, peak) = exit_and_peak_memory(&args);
        assert_eq!(code, 2, "{args:?}: zeros are no Arrow data");
        let bound = base + 2.0 * f64::from(256 << 20);
        assert!(
            peak > base + 150e6,
            "{args:?}: the message was decompressed"
        );
        assert!(
            peak < bound,
            "{args:?}: {:.0} MiB over {:.0} MiB",
            mib(peak),
            mib(base)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// (Here, in a binary of its own: a child's peak resident memory starts from its parent's, and
/// the reader tests hold crafted files in memory while they run.)
/// `reproduce` streams the files: reproducing a 29 MB recording takes less than 3 MB more
/// resident memory than the run it repeats takes on its own. A run's own peak varies by
/// 10 MB and more from one try to the next (how many chunks Rerun's batcher holds when the
/// peak comes), so each side is the least of three tries. What `diff` and `reproduce` hold
/// while comparing is measured exactly, on the heap, in `tests/stream_memory.rs`.
#[test]
fn reproduce_memory_does_not_grow_with_the_file() {
    let dir = scratch_dir("streamed-memory");
    let large = dir.join("large.rrd");
    record_pendulum(&large, "1e-4", "60");
    let size = std::fs::metadata(&large).unwrap().len();
    assert!(size > 10_000_000, "{size} B");
    let again = dir.join("again.rrd");
    let least = |args: &[&str]| {
        (0..3)
            .map(|_| peak_memory(args))
            .fold(f64::INFINITY, f64::min)
    };
    let run = least(&[
        "pendulum",
        "-q",
        "--dt",
        "1e-4",
        "--plot-every",
        "1",
        "--duration",
        "60",
        "-o",
        s(&again),
    ]);
    let reproduce = least(&["reproduce", s(&large)]);
    assert!(
        reproduce - run < 3e6,
        "reproduce: {reproduce:.3e} B, the run alone {run:.3e} B, the file {size} B"
    );
}
