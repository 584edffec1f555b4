//! Reading a recording that may be anything a user names: every reader (`inspect`, `diff`,
//! `reproduce`) goes through [`Messages`]. What can be checked before Arrow sees the bytes is
//! checked (`framing.rs`, `arrow_message.rs`); the decoding and what reads its chunks run under
//! `catch_unwind`, because a corrupt Arrow buffer can make them panic rather than fail; every
//! message first looks at the stop flag. A message over [`MAX_MESSAGE_BYTES`], as stored or once
//! decompressed, is refused, so reading holds at most one message's bytes and its decompressed
//! stream at once, besides the chunks a reader keeps. A file holding several recordings (`rerun
//! rrd merge` of two) is refused: its data would otherwise be read as one recording's.

use std::cell::Cell;
use std::fs::File;
use std::io::BufReader;
use std::os::unix::fs::FileExt as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Once;

use rerun::external::arrow::buffer::Buffer;
use rerun::external::arrow::ipc::reader::StreamDecoder;
use rerun::external::re_log_encoding::{MessageKind, RRD_FOURCC};
use rerun::log::Chunk;

use super::arrow_message::{ArrowMessage, Store};
use super::framing::{Cut, Framed};
use crate::error::Error;

/// The most bytes one message may take, as stored and once decompressed (256 MiB): the cap that
/// bounds what reading any file holds. physlab's own largest message, a 3D frame of a rope of the
/// most nodes it allows (10⁷), takes about 120 MB.
pub const MAX_MESSAGE_BYTES: u64 = 256 << 20;

/// The refusal of a message over [`MAX_MESSAGE_BYTES`], naming its size.
fn too_large(path: &Path, at: u64, size: u64, how: &str) -> anyhow::Error {
    unusable(
        path,
        format!(
            "the message at byte {at} takes {size} bytes{how}, more than the {MAX_MESSAGE_BYTES} \
             (256 MiB) physlab reads in one message (a cap that bounds the memory reading takes)"
        ),
    )
}

/// The error for an unusable file: its path, then what is wrong. Exit code 2.
pub fn unusable(path: &Path, what: impl std::fmt::Display) -> anyhow::Error {
    Error::Usage(format!("{}: unusable file: {what}", path.display())).into()
}

/// One chunk of a recording, with the store it was logged to.
pub struct ChunkMessage {
    /// Logged to the recording, not to its blueprint.
    pub recording: bool,
    pub application_id: String,
    pub chunk: Chunk,
    /// Its message's decompressed size [B]: about what the chunk holds.
    pub bytes: usize,
}

/// An open recording, read chunk by chunk: two can be read in step (`diff`, `reproduce`).
pub struct Messages {
    path: PathBuf,
    framed: Framed<BufReader<File>>,
    seen_any: bool,
    /// The recording the file's data was logged to (the first met).
    recording: Option<Store>,
    /// The ids of the chunks read: a chunk met again is skipped, as Rerun's store does (`cat
    /// a.rrd a.rrd` holds each twice). 16 B a chunk, a chunk taking hundreds as stored.
    chunk_ids: std::collections::HashSet<rerun::log::ChunkId>,
    /// Where the recording's first chunk was read with no store info before it: the file is
    /// not a whole recording (Rerun writes a store's info before its data).
    pub headless: Option<u64>,
}

impl Messages {
    /// Opens `path` after checking what can be checked without decoding: a missing, folder,
    /// empty, non-regular or non-rrd file is a usage error naming the file.
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        let what = |w: &str| unusable(path, w);
        let meta =
            std::fs::metadata(path).map_err(|e| unusable(path, format!("cannot read it: {e}")))?;
        if meta.is_dir() {
            return Err(what("is a folder, not a recording (.rrd)"));
        }
        if !meta.is_file() {
            return Err(what(
                "not a regular file (a device, FIFO or socket), not a recording (.rrd)",
            ));
        }
        if meta.len() == 0 {
            return Err(what("the file is empty, not a recording (.rrd)"));
        }
        let file = File::open(path).map_err(|e| unusable(path, format!("cannot open it: {e}")))?;
        let mut magic = [0u8; 4];
        // Read in place: the framing reads the file from its start.
        if file.read_exact_at(&mut magic, 0).is_err() || magic != RRD_FOURCC {
            return Err(what(
                "not a Rerun recording (.rrd): it does not start with Rerun's header",
            ));
        }
        Ok(Messages {
            path: path.to_path_buf(),
            framed: Framed::new(BufReader::new(file), meta.len(), MAX_MESSAGE_BYTES),
            seen_any: false,
            recording: None,
            chunk_ids: Default::default(),
            headless: None,
        })
    }

    /// The next chunk, `None` at the end. A corrupt or truncated message is a usage error
    /// naming the file; a stop request an `Error::Interrupted`.
    pub fn next_chunk(&mut self) -> anyhow::Result<Option<ChunkMessage>> {
        let path = self.path.as_path();
        loop {
            if crate::interrupt::requested() {
                return Err(Error::Interrupted(format!(
                    "interrupted while reading {}: nothing was compared or written",
                    path.display()
                ))
                .into());
            }
            let seen_any = self.seen_any;
            let in_file = |e: &dyn std::fmt::Display| {
                if seen_any {
                    unusable(path, format!("the recording is corrupt or truncated: {e}"))
                } else {
                    unusable(path, format!("not a Rerun recording (.rrd): {e}"))
                }
            };
            let message = self.framed.next_message().map_err(|e| in_file(&e))?;
            let Some(message) = message else {
                if !self.seen_any {
                    return Err(unusable(
                        path,
                        "not a Rerun recording (.rrd): no messages could be decoded",
                    ));
                }
                return Ok(None);
            };
            self.seen_any = true;
            if message.kind != MessageKind::ArrowMsg {
                continue; // the store's info, the blueprint's activation, the end of a stream
            }
            let at = message.at;
            let Some(bytes) = message.payload else {
                return Err(too_large(path, at, message.len, ""));
            };
            let whats_wrong = |why: String| in_file(&format!("{why} (the message at byte {at})"));
            let mut arrow = guarded(path, || ArrowMessage::decode(bytes))?.map_err(whats_wrong)?;
            if arrow.size() > MAX_MESSAGE_BYTES {
                return Err(too_large(path, at, arrow.size(), " once decompressed"));
            }
            let (store, bytes) = (std::mem::take(&mut arrow.store), arrow.size() as usize);
            one_recording(&mut self.framed, &mut self.recording, path, &store)?;
            if store.recording && !self.framed.store_info_seen {
                self.headless.get_or_insert(at);
            }
            let chunk = guarded(path, || decode_chunk(arrow.ipc()?))?.map_err(whats_wrong)?;
            if !self.chunk_ids.insert(chunk.id()) {
                continue;
            }
            return Ok(Some(ChunkMessage {
                recording: store.recording,
                application_id: store.application_id,
                chunk,
                bytes,
            }));
        }
    }

    /// Whether the file ends with Rerun's footer (a manifest): it was finalised, not cut short
    /// (call after `next_chunk` returned `None`, as for what follows).
    pub fn has_footer(&self) -> bool {
        self.framed.footer.is_some()
    }

    /// Why a file without its footer has none, in words.
    pub fn missing_footer(&self) -> String {
        match (self.framed.cut, self.framed.footer_followed) {
            (Some(Cut { at, declared, left }), _) => format!(
                "the file ends inside the message at byte {at}, which declares {declared} bytes \
                 where {left} are left (the writing process was killed or the file cut short, or \
                 the file is corrupt there)"
            ),
            (None, Some(at)) => format!(
                "the footer at byte {at} is followed by more messages and the file ends without \
                 another (a finished file and a cut one joined, or an edited file)"
            ),
            (None, None) => "the file ends without its footer (the writing process was killed or \
                             the file cut short)"
                .into(),
        }
    }

    /// Runs `f` on this file's contents, a panic in it reported as the file being unusable.
    pub fn guarded<T>(&self, f: impl FnOnce() -> T) -> anyhow::Result<T> {
        guarded(&self.path, f)
    }
}

/// Refuses a second recording in the file, naming every recording it holds (the rest of the
/// file read for them).
fn one_recording(
    framed: &mut Framed<impl std::io::Read>,
    recording: &mut Option<Store>,
    path: &Path,
    store: &Store,
) -> anyhow::Result<()> {
    if !store.recording {
        return Ok(()); // a blueprint
    }
    let first = recording.get_or_insert_with(|| store.clone()).clone();
    if first == *store {
        return Ok(());
    }
    let mut found = vec![first, store.clone()];
    while let Ok(Some(message)) = framed.next_message() {
        let decoded = message.payload.map(ArrowMessage::decode);
        if let Some(Ok(ArrowMessage { store, .. })) = decoded
            && store.recording
            && !found.contains(&store)
        {
            found.push(store);
        }
    }
    let list: Vec<String> = found
        .iter()
        .map(|s| format!("{} (recording id {})", s.application_id, s.recording_id))
        .collect();
    Err(unusable(
        path,
        format!(
            "it holds {} recordings (as `rerun rrd merge` makes), and physlab reads one \
             recording a file: {}",
            found.len(),
            list.join(", ")
        ),
    ))
}

/// Decodes `path` chunk by chunk and hands each to `each` (whose `Err` is what is wrong with
/// the file, in words). A missing, empty, non-regular, non-rrd, corrupt or truncated file is a
/// usage error naming the file; a stop request an `Error::Interrupted`. Never panics on any bytes.
/// Returns the file read to its end.
pub fn each_chunk(
    path: &Path,
    mut each: impl FnMut(ChunkMessage) -> Result<(), String>,
) -> anyhow::Result<Messages> {
    let mut messages = Messages::open(path)?;
    while let Some(chunk) = messages.next_chunk()? {
        messages
            .guarded(|| each(chunk))?
            .map_err(|e| unusable(path, e))?;
    }
    Ok(messages)
}

/// A chunk from its Arrow IPC stream, its arrays slices of `ipc` (Arrow copies one only where
/// it is misaligned). Migrates what older Rerun versions wrote, as Rerun's decoder does.
fn decode_chunk(ipc: Vec<u8>) -> Result<Chunk, String> {
    let mut buffer = Buffer::from_vec(ipc);
    let mut decoder = StreamDecoder::new();
    let mut batch = None;
    while !buffer.is_empty() && batch.is_none() {
        batch = decoder
            .decode(&mut buffer)
            .map_err(|e| format!("its Arrow data cannot be decoded ({e})"))?;
    }
    let batch = batch.ok_or("an Arrow message with no record batch")?;
    Chunk::from_chunk_record_batch(&batch).map_err(|e| format!("a chunk cannot be decoded: {e}"))
}

thread_local! {
    /// Set while this thread runs guarded decoding: its panics are reported as errors, so the
    /// default hook's message would only repeat them.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`, turning a panic into an "unusable file" error naming `path`.
fn guarded<T>(path: &Path, f: impl FnOnce() -> T) -> anyhow::Result<T> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(false));
    result.map_err(|payload| {
        let why = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no reason given".into());
        unusable(
            path,
            format!("the recording is corrupt: Rerun's decoder failed on its contents ({why})"),
        )
    })
}
