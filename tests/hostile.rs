//! A hostile pass over crafted recordings (issue 43, "Must show"): inputs made here from a real
//! recording physlab writes in a temporary folder (its frames, protobuf, LZ4 and Arrow IPC
//! edited), from recordings crafted with Rerun's SDK (provenance with absurd values, control
//! characters and shell syntax in every field, two runs under one recording id, another
//! program's recording, made by the Python SDK when it is installed) and from what is no
//! recording (an empty file, a folder, a FIFO, a socket, a symlink loop, names with control
//! characters), each run through `inspect`, `diff` both ways and `reproduce`.
//!
//! Each input's expected outcome is written from what the input is, not from physlab's output:
//! a file the edit leaves whole reads as the original (`diff` the same, `reproduce`
//! bit-identical), a corrupt one is refused (exit 2, the file named, the cause in words), a
//! partial one is shown by `inspect` and refused by `diff` and `reproduce`. Every run also must
//! end within 30 s, without a panic, within the memory bound of docs/trust.md, with no control
//! character but a newline in its output, a suggested command never holding the file's text,
//! and an exit code documented for its command (`inspect` 0 or 2; 1 only for "they differ").
//! The counts by class are printed (`--nocapture`) for docs/trust.md.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use re_protos::common::v1alpha1::{Compression, StoreKind};
use re_protos::external::prost::{Message as _, bytes::Bytes};
use re_protos::log_msg::v1alpha1::ArrowMsg;

use common::{s, scratch_dir};

/// What a command should do with an input.
#[derive(Clone, Copy, Debug)]
enum Want {
    /// Exit 0 (`inspect`; `diff` against the file it was made from: the same; `reproduce`:
    /// bit-identical).
    Read,
    /// Exit 1: the data differ from what they are compared with.
    Differs,
    /// Exit 2, the file named, with these words.
    Refused(&'static str),
    /// `inspect` exit 0 showing these words.
    Shown(&'static str),
}
use Want::*;

/// One crafted input: its class, its name, the file, what `diff` compares it with (both ways),
/// and what `inspect`, `diff` and `reproduce` should do.
struct Case {
    class: &'static str,
    name: String,
    file: PathBuf,
    other: PathBuf,
    want: [Want; 3],
}

/// A payload that no command may run or echo as a command: it would create `PWNED`.
const EVIL: &str = "\x1b[2J\x1b]0;owned\x07; touch PWNED #$(touch PWNED)`touch PWNED`\nverdict: \
                    bit-identical (9 entities)";

/// The memory bound of docs/trust.md over a small file's base (about 10 MB): `inspect` holds at
/// most 0.75 GiB of one message, `diff` and `reproduce` 1.75 GiB with the waiting chunks.
const INSPECT_BOUND: f64 = 0.75 * 1073741824.0 + 64e6;
const DIFF_BOUND: f64 = 1.75 * 1073741824.0 + 64e6;

/// A recording's frames: the stream header, messages (kind, header and payload) and stream
/// footers, each with its bytes, in file order.
#[derive(Clone)]
struct Frame {
    /// `None` for a stream header or footer; else the message kind (0 end, 1 store info, 2
    /// Arrow, 3 blueprint activation).
    kind: Option<u64>,
    bytes: Vec<u8>,
}

fn frames(file: &[u8]) -> Vec<Frame> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < file.len() {
        if file[at..].starts_with(b"RRF2") {
            out.push(Frame {
                kind: None,
                bytes: file[at..at + 12].to_vec(),
            });
            at += 12;
            continue;
        }
        let kind = u64::from_le_bytes(file[at..at + 8].try_into().unwrap());
        let len = u64::from_le_bytes(file[at + 8..at + 16].try_into().unwrap()) as usize;
        out.push(Frame {
            kind: Some(kind),
            bytes: file[at..at + 16 + len].to_vec(),
        });
        at += 16 + len;
        if kind == 0 {
            out.push(Frame {
                kind: None,
                bytes: file[at..at + 32].to_vec(),
            });
            at += 32;
        }
    }
    assert_eq!(at, file.len(), "a recording as physlab writes it");
    out
}

fn join(frames: &[Frame]) -> Vec<u8> {
    frames.iter().flat_map(|f| f.bytes.clone()).collect()
}

fn arrow(frame: &Frame) -> ArrowMsg {
    ArrowMsg::decode(&frame.bytes[16..]).unwrap()
}

fn arrow_frame(message: &ArrowMsg) -> Frame {
    let payload = message.encode_to_vec();
    let mut bytes = 2u64.to_le_bytes().to_vec();
    bytes.extend((payload.len() as u64).to_le_bytes());
    bytes.extend(payload);
    Frame {
        kind: Some(2),
        bytes,
    }
}

/// The Arrow IPC stream of a message, decompressed.
fn ipc(message: &ArrowMsg) -> Vec<u8> {
    assert_eq!(message.compression, Compression::Lz4 as i32);
    lz4_flex::block::decompress(&message.payload, message.uncompressed_size as usize).unwrap()
}

/// The message with its Arrow IPC stream stored uncompressed after `edit`.
fn with_ipc(message: &ArrowMsg, edit: impl Fn(&mut Vec<u8>)) -> ArrowMsg {
    let mut stream = ipc(message);
    edit(&mut stream);
    let mut out = message.clone();
    out.compression = Compression::None as i32;
    out.uncompressed_size = stream.len() as u64;
    out.payload = Bytes::from(stream);
    out
}

/// The frames of a real recording, sorted: the indices of the recording's Arrow messages (its
/// data and provenance), of its blueprint's, and of the end message.
struct Layout {
    frames: Vec<Frame>,
    data: Vec<usize>,
    blueprint: Vec<usize>,
    end: usize,
    provenance: usize,
}

fn layout(file: &Path) -> Layout {
    let frames = frames(&std::fs::read(file).unwrap());
    let store = |f: &Frame| arrow(f).store_id.unwrap().kind;
    let arrows = || (0..frames.len()).filter(|&i| frames[i].kind == Some(2));
    let data: Vec<usize> = arrows()
        .filter(|&i| store(&frames[i]) == StoreKind::Recording as i32)
        .collect();
    let blueprint = arrows()
        .filter(|&i| store(&frames[i]) == StoreKind::Blueprint as i32)
        .collect();
    let end = frames.iter().position(|f| f.kind == Some(0)).unwrap();
    // The provenance's entity path, as the chunk's Arrow schema holds it (a flatbuffer string).
    let provenance = *(data.iter())
        .find(|&&i| contains(&ipc(&arrow(&frames[i])), b"/__properties/physlab\0"))
        .expect("the provenance chunk");
    Layout {
        frames,
        data,
        blueprint,
        end,
        provenance,
    }
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

/// Inputs made by editing the real recording `good` (and `second`, another run of its scene).
fn edited(dir: &Path, good: &Path, second: &Path) -> Vec<Case> {
    let l = layout(good);
    let f = &l.frames;
    let mut cases = Vec::new();
    let mut add = |class, name: &str, bytes: Vec<u8>, want: [Want; 3]| {
        let file = dir.join(format!("{}.rrd", name.replace([' ', '/'], "_")));
        std::fs::write(&file, bytes).unwrap();
        cases.push(Case {
            class,
            name: name.into(),
            file,
            other: good.to_path_buf(),
            want,
        });
    };
    let read = [Read, Read, Read];
    let refused = |why| [Refused(why), Refused(why), Refused(why)];
    let partial = |shown, why| [Shown(shown), Refused(why), Refused(why)];
    let offset = |i: usize| f[..i].iter().map(|f| f.bytes.len()).sum::<usize>();
    let whole = join(f);
    let (last, mid) = (*l.data.last().unwrap(), l.data[l.data.len() / 2]);

    // Frame headers.
    let mut b = whole.clone();
    b[offset(mid)] = 7;
    add(
        "frames",
        "message kind 7",
        b,
        refused("a message header that cannot be read"),
    );
    for (name, delta) in [("message length + 1", 1i64), ("message length - 1", -1)] {
        let mut b = whole.clone();
        let at = offset(mid) + 8;
        let len = u64::from_le_bytes(b[at..at + 8].try_into().unwrap());
        b[at..at + 8].copy_from_slice(&((len as i64 + delta) as u64).to_le_bytes());
        add("frames", name, b, refused("cannot be decoded"));
    }
    for (name, len) in [
        ("message length 2^63", 1u64 << 63),
        ("message length past the end", whole.len() as u64),
    ] {
        let mut b = whole.clone();
        let at = offset(last) + 8;
        b[at..at + 8].copy_from_slice(&len.to_le_bytes());
        add("frames", name, b, partial("which declares", "truncated"));
    }
    let mut b = whole.clone();
    b[9] ^= 0xff; // the stream header's serializer (2, protobuf)
    add(
        "frames",
        "stream header version",
        b,
        refused("not a Rerun recording"),
    );

    // Protobuf of an Arrow message: the payload's declared length, the store id's.
    let mut edited = f.clone();
    let payload = arrow(&f[last]).payload;
    let message = &mut edited[last].bytes;
    let at = (16..message.len())
        .find(|&i| message[i..].starts_with(&payload))
        .unwrap();
    let varint = re_protos::external::prost::length_delimiter_len(payload.len());
    let mut longer = Vec::new();
    re_protos::external::prost::encode_length_delimiter(payload.len() + 100, &mut longer).unwrap();
    assert_eq!(longer.len(), varint, "the same varint length");
    message[at - varint..at].copy_from_slice(&longer);
    add(
        "protobuf",
        "payload length + 100",
        join(&edited),
        refused("cannot be decoded"),
    );
    let mut edited = f.clone();
    edited[last].bytes[16 + 1] = 0x7f; // the store id's length
    add(
        "protobuf",
        "store id length 127",
        join(&edited),
        refused("cannot be decoded"),
    );

    // LZ4: a match at offset 0, the block cut in half, sizes it cannot give.
    let m = arrow(&f[last]);
    let mut lz4 = |name: &str, edit: &dyn Fn(&mut ArrowMsg), why| {
        let mut message = m.clone();
        edit(&mut message);
        let mut edited = f.clone();
        edited[last] = arrow_frame(&message);
        add("LZ4", name, join(&edited), refused(why));
    };
    lz4(
        "a match at offset 0",
        &|m| {
            let mut p = m.payload.to_vec();
            p[..3].copy_from_slice(&[0x0f, 0, 0]);
            m.payload = p.into();
        },
        "corrupt",
    );
    lz4(
        "block cut in half",
        &|m| m.payload = m.payload.slice(..m.payload.len() / 2),
        "corrupt",
    );
    lz4(
        "declared 2 GiB",
        &|m| m.uncompressed_size = 1 << 31,
        "256 MiB",
    );
    lz4(
        "declared 2^64 - 1",
        &|m| m.uncompressed_size = u64::MAX,
        "256 MiB",
    );
    lz4(
        "declared beyond LZ4's reach",
        &|m| m.uncompressed_size = m.payload.len() as u64 * 300,
        "once decompressed from",
    );
    lz4("declared 0", &|m| m.uncompressed_size = 0, "corrupt");
    lz4(
        "declared one byte more",
        &|m| m.uncompressed_size += 1,
        "once decompressed",
    );
    lz4(
        "LZ4 data flagged uncompressed",
        &|m| m.compression = Compression::None as i32,
        "corrupt",
    );

    // Arrow IPC, stored uncompressed: as it is, its flatbuffer root offset, cut, grown.
    let mut ipc_case = |name: &str, edit: &dyn Fn(&mut Vec<u8>), want| {
        let mut edited = f.clone();
        for &i in &l.data {
            edited[i] = arrow_frame(&with_ipc(&arrow(&f[i]), edit));
        }
        add("Arrow IPC", name, join(&edited), want);
    };
    ipc_case("stored uncompressed", &|_| {}, read);
    ipc_case(
        "metadata length 2^31 - 1",
        &|s| s[4..8].copy_from_slice(&0x7fff_ffffu32.to_le_bytes()),
        refused("corrupt"),
    );
    ipc_case(
        "flatbuffer root offset 0xffffffff",
        &|s| s[8..12].copy_from_slice(&[0xff; 4]),
        refused("corrupt"),
    );
    ipc_case(
        "stream cut in half",
        &|s| s.truncate(s.len() / 2),
        refused("corrupt"),
    );
    ipc_case(
        "entity paths holding ESC",
        &|s| {
            for at in 0..s.len() - 10 {
                if &s[at..at + 10] == b"/pendulum/" {
                    s[at + 8] = 0x1b;
                }
            }
        },
        // The provenance's configuration is text too: `[pendulum]` is untouched, so the re-run
        // is the pendulum's, and its entities are not the recording's.
        [Read, Differs, Differs],
    );

    // Truncated at every kind of boundary.
    let end = offset(l.end);
    for (name, at, want) in [
        (
            "cut inside the stream header",
            6,
            refused("no messages could be decoded"),
        ),
        (
            "cut after the stream header",
            12,
            refused("no messages could be decoded"),
        ),
        (
            "cut inside a message header",
            offset(mid) + 7,
            partial("ends without its footer", "truncated"),
        ),
        (
            "cut after a message header",
            offset(mid) + 16,
            partial("which declares", "truncated"),
        ),
        (
            "cut inside a payload",
            offset(mid) + 40,
            partial("which declares", "truncated"),
        ),
        (
            "cut before the end message",
            end,
            partial("ends without its footer", "truncated"),
        ),
        (
            "cut inside the end message",
            end + 1000,
            partial("which declares", "truncated"),
        ),
        // The footer (the end message) is whole: the stream footer only locates it.
        ("cut inside the stream footer", whole.len() - 5, read),
    ] {
        add("truncated", name, whole[..at].to_vec(), want);
    }

    // Chunks reordered or duplicated, streams repeated: read as Rerun's store reads them (a
    // chunk id met again adds nothing).
    let mut reversed = f.clone();
    for (k, &i) in l.data.iter().enumerate() {
        reversed[i] = f[l.data[l.data.len() - 1 - k]].clone();
    }
    add("order", "data chunks reversed", join(&reversed), read);
    let mut swapped = f.clone();
    for k in 0..l.blueprint.len().min(l.data.len()) {
        swapped.swap(l.blueprint[k], l.data[k]);
    }
    add(
        "order",
        "blueprint and data interleaved anew",
        join(&swapped),
        read,
    );
    let doubled: Vec<Frame> = (0..f.len())
        .flat_map(|i| vec![f[i].clone(); if l.data.contains(&i) { 2 } else { 1 }])
        .collect();
    add("order", "every data chunk twice", join(&doubled), read);
    add(
        "order",
        "the file twice (cat a a)",
        [whole.clone(), whole.clone()].concat(),
        read,
    );
    let mut header_again = f.clone();
    header_again.insert(mid, f[0].clone());
    add(
        "order",
        "a stream header mid-file",
        join(&header_again),
        read,
    );
    add(
        "order",
        "zeros after the end",
        [whole.clone(), vec![0; 100]].concat(),
        read,
    );
    add(
        "order",
        "text after the end",
        [whole.clone(), b"garbage garbage garbage!".to_vec()].concat(),
        refused("corrupt"),
    );

    // The footer mid-file, twice, missing; the store's info missing or late.
    let mut moved = f.clone();
    let footer: Vec<Frame> = moved.drain(l.end..l.end + 2).collect();
    moved.splice(mid..mid, footer.clone());
    add(
        "footer and store info",
        "footer mid-file",
        join(&moved),
        partial(
            "is followed by more messages",
            "is followed by more messages",
        ),
    );
    let mut twice = f.clone();
    twice.splice(mid..mid, footer);
    add(
        "footer and store info",
        "footer mid-file and at the end",
        join(&twice),
        read,
    );
    add(
        "footer and store info",
        "no footer",
        join(&f[..l.end]),
        partial("ends without its footer", "truncated"),
    );
    add(
        "footer and store info",
        "the file twice, the second cut",
        [whole.clone(), whole[..whole.len() / 2].to_vec()].concat(),
        partial("no footer", "truncated"),
    );
    let infos: Vec<Frame> = f.iter().filter(|f| f.kind == Some(1)).cloned().collect();
    let rest: Vec<Frame> = f.iter().filter(|f| f.kind != Some(1)).cloned().collect();
    let headless = [
        Shown("without the store info"),
        Refused("not a whole recording"),
        Refused("not a whole recording"),
    ];
    add(
        "footer and store info",
        "no store info",
        join(&rest),
        headless,
    );
    let late = [&rest[..rest.len() / 2], &infos, &rest[rest.len() / 2..]].concat();
    add(
        "footer and store info",
        "store info mid-file",
        join(&late),
        headless,
    );

    // No data: the blueprint alone.
    let blueprint: Vec<Frame> = (0..f.len())
        .filter(|i| !l.data.contains(i))
        .map(|i| f[i].clone())
        .collect();
    add(
        "no data",
        "the blueprint alone",
        join(&blueprint),
        [
            Shown("no recorded data"),
            Refused("holds no recorded data"),
            Refused("holds no recorded data"),
        ],
    );
    let mut no_provenance = f.clone();
    no_provenance.remove(l.provenance);
    add(
        "no data",
        "rows without the provenance",
        join(&no_provenance),
        [Read, Read, Refused("holds no physlab configuration")],
    );

    // Two runs in one file under one recording id (the second's ids made the first's), and
    // under two (interleaved as `rerun rrd merge` does).
    let other = std::fs::read(second).unwrap();
    let same_ids = same_recording_ids(&whole, &other);
    let two_runs = refused("two runs' provenance");
    add(
        "two runs",
        "two runs under one id, cat",
        [whole.clone(), same_ids.clone()].concat(),
        two_runs,
    );
    let mixed = interleaved(f, &frames(&same_ids));
    add(
        "two runs",
        "two runs under one id, interleaved",
        mixed,
        two_runs,
    );
    let merged = interleaved(f, &frames(&other));
    add(
        "two runs",
        "two runs, two ids, interleaved",
        merged,
        refused("holds 2 recordings"),
    );
    cases
}

/// The messages of two recordings taken in turn up to their end messages, after `a`'s stream
/// header and before `a`'s end.
fn interleaved(a: &[Frame], b: &[Frame]) -> Vec<u8> {
    let end = |f: &[Frame]| f.iter().position(|f| f.kind == Some(0)).unwrap();
    let (a_end, b_end) = (end(a), end(b));
    let mut out = vec![a[0].clone()];
    for i in 1..a_end.max(b_end) {
        out.extend(a.get(i).filter(|_| i < a_end).cloned());
        out.extend(b.get(i).filter(|_| i < b_end).cloned());
    }
    out.extend_from_slice(&a[a_end..]);
    join(&out)
}

/// `b` with each of its recording ids (`rec_` and 32 hex digits, recording then blueprint in
/// order of first appearance) replaced by `a`'s.
fn same_recording_ids(a: &[u8], b: &[u8]) -> Vec<u8> {
    let ids = |x: &[u8]| {
        let mut found: Vec<Vec<u8>> = Vec::new();
        for w in x.windows(36) {
            if w.starts_with(b"rec_")
                && w[4..].iter().all(u8::is_ascii_hexdigit)
                && !found.iter().any(|f| f == w)
            {
                found.push(w.to_vec());
            }
        }
        found
    };
    let mut out = b.to_vec();
    for (from, to) in ids(b).iter().zip(ids(a)) {
        for at in 0..out.len() - 36 {
            if out[at..at + 36] == from[..] {
                out[at..at + 36].copy_from_slice(&to);
            }
        }
    }
    out
}

/// Crafted provenance: absurd values, every string field hostile, megabyte strings.
fn provenance(dir: &Path) -> Vec<Case> {
    const PENDULUM: &str = "[pendulum]\nduration = 0.1\nmethods = [\"verlet\"]\n";
    let config = |c: &str| format!("[pendulum]\n{c}\nmethods = [\"verlet\"]\n");
    let runs = "does not run with this build";
    let cmd = "x".repeat(1 << 20);
    let configs: Vec<(&str, String, &str)> = vec![
        ("duration NaN", config("duration = nan"), runs),
        ("duration inf", config("duration = inf"), runs),
        ("duration 1e300", config("duration = 1e300"), runs),
        ("dt 0", config("dt = 0.0"), runs),
        ("dt -0.01", config("dt = -0.01"), runs),
        ("dt 1e-300", config("dt = 1e-300"), runs),
        ("nodes -5", "[rope]\nnodes = -5\n".into(), runs),
        (
            "nodes 2^63 - 1",
            "[rope]\nnodes = 9223372036854775807\n".into(),
            runs,
        ),
        ("strands 4e9", "[hair]\nstrands = 4000000000\n".into(), runs),
        (
            "an unknown method",
            "[pendulum]\nmethods = [\"x; touch PWNED\"]\n".into(),
            runs,
        ),
        ("an unknown key", config("evil = \"\\u001b[2J\""), runs),
        ("not TOML", "\u{1}\x1b[2J = = =".into(), runs),
        (
            "a megabyte",
            format!("{PENDULUM}# {}\n", "B".repeat(1 << 20)),
            "larger than 1 MiB",
        ),
    ];
    let mut cases = Vec::new();
    let mut add =
        |name: &str, app: &str, props: &[(&str, &str)], run: &[(&str, &str)], want: [Want; 3]| {
            let file = dir.join(format!("{}.rrd", name.replace([' ', '/', ';'], "_")));
            common::craft(&file, app, props, run, true);
            // `diff` compares the file with itself: whatever its provenance, its data are its own.
            let other = file.clone();
            cases.push(Case {
                class: "provenance",
                name: name.into(),
                file,
                other,
                want,
            });
        };
    for (name, config, why) in &configs {
        let scene = config
            .trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or("pendulum");
        let scene = if config.starts_with('[') {
            scene
        } else {
            "pendulum"
        };
        let props = [
            ("scenes", scene),
            ("config", config.as_str()),
            ("command_line", "physlab"),
        ];
        add(
            &format!("config: {name}"),
            &format!("physlab-{scene}"),
            &props,
            &[],
            [Read, Read, Refused(why)],
        );
    }
    let fields = [
        "command_line",
        "methods",
        "git_commit",
        "physlab_version",
        "rerun_sdk_version",
        "diff_a",
        "diff_b",
    ];
    let mut props: Vec<(&str, &str)> = fields.iter().map(|k| (*k, EVIL)).collect();
    props.extend([("scenes", "pendulum"), ("config", PENDULUM)]);
    let run = [
        ("pendulum_status", EVIL),
        ("pendulum_ended", EVIL),
        ("pendulum_last_tick", EVIL),
    ];
    // The run's status is none physlab writes: the re-run goes to the end, and 1 series of the
    // recording's 10 rows is not the pendulum's 29.
    add(
        "every field hostile",
        "physlab-pendulum",
        &props,
        &run,
        [Read, Read, Differs],
    );
    for (name, scenes) in [
        ("scenes unknown", "tornado"),
        ("scenes with shell syntax", "pendulum;touch PWNED"),
        ("scenes only commas", ",,,"),
    ] {
        let props = [("scenes", scenes), ("config", PENDULUM)];
        add(
            name,
            "physlab-pendulum",
            &props,
            &[],
            [Read, Read, Refused("its provenance names the scenes")],
        );
    }
    let diff = [
        ("scenes", "diff"),
        (
            "command_line",
            "physlab diff a.rrd b.rrd -o d.rrd; touch PWNED",
        ),
        ("diff_a", EVIL),
        ("diff_b", EVIL),
    ];
    add(
        "a diff recording, hostile",
        "physlab-diff",
        &diff,
        &[],
        [Read, Read, Refused("a diff recording")],
    );
    let study = [
        ("scenes", "study convergence;touch PWNED"),
        ("command_line", "physlab study convergence `touch PWNED`"),
        ("config", PENDULUM),
    ];
    add(
        "a study recording, hostile",
        "physlab-study",
        &study,
        &[],
        [Read, Read, Refused("a study recording")],
    );
    let base = [
        ("scenes", "pendulum"),
        ("config", PENDULUM),
        ("command_line", "physlab pendulum"),
    ];
    for (name, tick, want) in [
        ("last tick -1", "-1", Refused("last tick is not recorded")),
        ("last tick NaN", "NaN", Refused("last tick is not recorded")),
        ("last tick 2^64 - 1", "18446744073709551615", Differs),
    ] {
        let run = [
            ("pendulum_status", "interrupted"),
            ("pendulum_last_tick", tick),
        ];
        add(name, "physlab-pendulum", &base, &run, [Read, Read, want]);
    }
    let long = [
        ("scenes", "pendulum"),
        ("config", PENDULUM),
        ("command_line", cmd.as_str()),
        ("methods", cmd.as_str()),
    ];
    add(
        "a megabyte command line and methods",
        "physlab-pendulum",
        &long,
        &[],
        [Read, Read, Differs],
    );
    let other = "another application";
    add(
        "provenance in another program's recording",
        "someone_else",
        &base,
        &[],
        [Read, Refused(other), Refused(other)],
    );
    cases
}

/// Another program's recording made by Rerun's Python SDK, when `rerun-sdk` 0.36.3 is installed.
fn python_recording(dir: &Path) -> Option<Case> {
    let file = dir.join("python.rrd");
    let script = format!(
        "import rerun as rr\nassert rr.__version__ == '0.36.3'\nrr.init('my_python_app')\n\
         rr.save({:?})\nfor i in range(20):\n    rr.set_time('step', sequence=i)\n    \
         rr.log('points', rr.Points3D([[i, 0, 0]]))\n    rr.log('scalar', rr.Scalars(i * 0.5))\n",
        s(&file)
    );
    let made = Command::new("python3")
        .arg("-c")
        .arg(script)
        .stderr(Stdio::null())
        .status();
    if !made.is_ok_and(|m| m.success()) {
        eprintln!("the Python SDK (rerun-sdk 0.36.3) is not installed: its recording is not tried");
        return None;
    }
    let other = "another application (\"my_python_app\")";
    Some(Case {
        class: "another program",
        name: "Rerun's Python SDK".into(),
        file,
        other: PathBuf::new(),
        want: [
            Shown("\"my_python_app\", another application"),
            Refused(other),
            Refused(other),
        ],
    })
}

/// What is no recording: kinds of file and names.
fn not_recordings(dir: &Path, good: &Path) -> Vec<Case> {
    use std::os::unix::ffi::OsStrExt as _;
    let path = |n: &str| dir.join(n);
    std::fs::write(path("empty.rrd"), b"").unwrap();
    std::fs::create_dir(path("folder.rrd")).unwrap();
    let fifo = std::ffi::CString::new(path("fifo.rrd").as_os_str().as_bytes()).unwrap();
    // SAFETY: creating a FIFO at a path this test owns.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
    let _socket = std::os::unix::net::UnixListener::bind(path("socket.rrd")).unwrap();
    std::os::unix::fs::symlink(path("loop2.rrd"), path("loop1.rrd")).unwrap();
    std::os::unix::fs::symlink(path("loop1.rrd"), path("loop2.rrd")).unwrap();
    std::os::unix::fs::symlink(good, path("link.rrd")).unwrap();
    std::fs::copy(good, path("name \x1b[2J\x07.rrd")).unwrap();
    std::fs::write(path("bad \x1b]0;owned\x07.rrd"), b"not a recording").unwrap();
    let kinds: [(&str, PathBuf, [Want; 3]); 9] = [
        (
            "an empty file",
            path("empty.rrd"),
            [Refused("the file is empty"); 3],
        ),
        ("a folder", path("folder.rrd"), [Refused("is a folder"); 3]),
        (
            "a FIFO",
            path("fifo.rrd"),
            [Refused("not a regular file"); 3],
        ),
        (
            "a socket",
            path("socket.rrd"),
            [Refused("not a regular file"); 3],
        ),
        (
            "a symlink loop",
            path("loop1.rrd"),
            [Refused("symbolic links"); 3],
        ),
        ("a symlink to a recording", path("link.rrd"), [Read; 3]),
        (
            "a name with control characters",
            path("name \x1b[2J\x07.rrd"),
            [Read; 3],
        ),
        (
            "a bad file named with control characters",
            path("bad \x1b]0;owned\x07.rrd"),
            [Refused("not a Rerun recording"); 3],
        ),
        (
            "a /proc file (size 0, text inside)",
            "/proc/self/status".into(),
            [Refused("the file is empty"); 3],
        ),
    ];
    kinds
        .into_iter()
        .map(|(name, file, want)| Case {
            class: "no recording",
            name: name.into(),
            file,
            other: good.to_path_buf(),
            want,
        })
        .collect()
}

/// Runs physlab with `args` under a 30 s limit: exit code (-1 killed or signalled), standard
/// output and error, peak resident memory [B].
#[allow(clippy::zombie_processes)] // reaped by `wait4`, which gives its memory
fn run(args: &[&std::ffi::OsStr]) -> (i32, String, String, f64) {
    let dir = tempdir_for_output();
    let (out, err) = (dir.join("out"), dir.join("err"));
    let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    loop {
        // SAFETY: waiting for this child only; a zeroed rusage is valid.
        let pid = unsafe { libc::wait4(child.id() as i32, &mut status, libc::WNOHANG, &mut usage) };
        if pid == child.id() as i32 {
            break;
        }
        if started.elapsed() > Duration::from_secs(30) {
            // SAFETY: ending the child this test started, then reaping it.
            unsafe {
                libc::kill(child.id() as i32, libc::SIGKILL);
                libc::wait4(child.id() as i32, &mut status, 0, &mut usage);
            }
            status = -1;
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let code = if status != -1 && libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
    let result = (
        code,
        read(&out),
        read(&err),
        usage.ru_maxrss as f64 * 1024.0,
    );
    std::fs::remove_dir_all(&dir).unwrap();
    result
}

fn tempdir_for_output() -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "physlab-hostile-out-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Checks one command's run against what it should do; `Err` says how it failed.
fn check(
    case: &Case,
    command: &str,
    args: &[&std::ffi::OsStr],
    want: Want,
) -> Result<(i32, f64), String> {
    let (code, out, err, peak) = run(args);
    let all = format!("{out}{err}");
    let fail = |what: String| {
        Err(format!(
            "{} / {}: {command}: {what}\n{all}",
            case.class, case.name
        ))
    };
    let allowed: &[i32] = if command == "inspect" {
        &[0, 2]
    } else {
        &[0, 1, 2]
    };
    if !allowed.contains(&code) {
        return fail(format!("exit {code}"));
    }
    if all.contains("panicked") {
        return fail("a panic".into());
    }
    if let Some(c) = all.chars().find(|c| c.is_control() && *c != '\n') {
        return fail(format!("an unescaped control character {c:?}"));
    }
    let bound = if command == "inspect" {
        INSPECT_BOUND
    } else {
        DIFF_BOUND
    };
    if peak > bound {
        return fail(format!("peak memory {peak:.3e} B over {bound:.3e} B"));
    }
    for marker in [
        "made again by: ",
        "run it again with: ",
        "write it again with: ",
        "command line again: ",
    ] {
        if all.lines().any(|l| {
            l.split_once(marker)
                .is_some_and(|(_, c)| c.contains("PWNED"))
        }) {
            return fail(format!(
                "a suggested command holds the file's text ({marker})"
            ));
        }
    }
    let named = err.contains(&format!("{}: ", record_escaped(&case.file)));
    let ok = match want {
        Read => {
            code == 0
                && match command {
                    "diff" => out.starts_with("verdict: the same"),
                    "reproduce" => out.starts_with("verdict: bit-identical"),
                    _ => true,
                }
        }
        Differs => {
            code == 1
                && match command {
                    "diff" => out.starts_with("verdict: they differ"),
                    _ => out.starts_with("verdict: DIFFERS"),
                }
        }
        Refused(why) => code == 2 && named && err.contains(why),
        Shown(what) => code == 0 && out.contains(what),
    };
    if !ok {
        return fail(format!("expected {want:?}, exit {code}"));
    }
    Ok((code, peak))
}

fn record_escaped(path: &Path) -> String {
    physlab::shell::escaped(&path.display().to_string()).into_owned()
}

/// How many runs exited with each code.
type Codes = BTreeMap<i32, usize>;

#[test]
fn crafted_recordings_meet_their_expected_outcome_through_every_command() {
    let dir = scratch_dir("hostile");
    let (good, second) = (dir.join("good.rrd"), dir.join("second.rrd"));
    for (file, theta0) in [(&good, "60"), (&second, "30")] {
        let (code, _, err) = common::physlab(&[
            "pendulum",
            "--duration",
            "0.3",
            "--methods",
            "rk4",
            "--theta0",
            theta0,
            "-q",
            "-o",
            s(file),
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let started = Instant::now();
    let made = |sub: &str| {
        let d = dir.join(sub);
        std::fs::create_dir_all(&d).unwrap();
        d
    };
    let mut cases = edited(&made("edited"), &good, &second);
    cases.extend(provenance(&made("provenance")));
    cases.extend(python_recording(&made("python")));
    cases.extend(not_recordings(&made("kinds"), &good));

    // Three at a time: each run is a process of its own.
    let runs: Vec<(usize, usize)> = (0..cases.len())
        .flat_map(|c| (0..4).map(move |k| (c, k)))
        .collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..3 {
            scope.spawn(|| {
                loop {
                    let n = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&(c, k)) = runs.get(n) else { break };
                    let case = &cases[c];
                    let (file, other) = (case.file.as_os_str(), case.other.as_os_str());
                    let (command, args, want): (&str, Vec<&std::ffi::OsStr>, Want) = match k {
                        0 => ("inspect", vec!["inspect".as_ref(), file], case.want[0]),
                        1 => ("diff", vec!["diff".as_ref(), file, other], case.want[1]),
                        2 => ("diff", vec!["diff".as_ref(), other, file], case.want[1]),
                        _ => ("reproduce", vec!["reproduce".as_ref(), file], case.want[2]),
                    };
                    // Another program's recording has nothing to be compared with but itself.
                    let args = if other.is_empty() && k != 0 && k != 3 {
                        vec!["diff".as_ref(), file, file]
                    } else {
                        args
                    };
                    let result = check(case, command, &args, want);
                    results.lock().unwrap().push((c, k, result));
                }
            });
        }
    });
    let results = results.into_inner().unwrap();
    let failures: Vec<&String> = results.iter().filter_map(|r| r.2.as_ref().err()).collect();

    // The counts by class, for docs/trust.md: inputs, then each command's exit codes.
    let mut table: BTreeMap<&str, (usize, [Codes; 3])> = BTreeMap::new();
    let mut largest = 0.0f64;
    for case in &cases {
        table.entry(case.class).or_default().0 += 1;
    }
    for (c, k, r) in &results {
        if let Ok((code, peak)) = r {
            largest = largest.max(*peak);
            let column = [0, 1, 1, 2][*k];
            *table.get_mut(cases[*c].class).unwrap().1[column]
                .entry(*code)
                .or_default() += 1;
        }
    }
    eprintln!("| class | inputs | inspect | diff (both ways) | reproduce |");
    for (class, (n, columns)) in &table {
        let text = |m: &BTreeMap<i32, usize>| {
            m.iter()
                .map(|(code, k)| format!("{k} × {code}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        eprintln!(
            "| {class} | {n} | {} | {} | {} |",
            text(&columns[0]),
            text(&columns[1]),
            text(&columns[2])
        );
    }
    eprintln!(
        "{} inputs, {} runs in {:.1} s; the largest peak resident memory {:.0} MB",
        cases.len(),
        results.len(),
        started.elapsed().as_secs_f64(),
        largest / 1e6
    );
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures
            .iter()
            .map(|f| f.as_str())
            .collect::<Vec<_>>()
            .join("\n\n")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
