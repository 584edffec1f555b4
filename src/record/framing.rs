//! Rerun's file framing, checked before its decoder sees the bytes. The decoder trusts the
//! lengths a file declares: it sizes a buffer from a message header's length and an LZ4 buffer
//! from the `uncompressed_size` inside an Arrow message, so one corrupted length asks for up to
//! 2⁶⁴ bytes and the process aborts (an allocation failure is not a panic that `catch_unwind`
//! could turn into an error). [`Framed`] hands the decoder whole frames only after checking
//! them: a message longer than what is left of the file ends the read there (it is where a
//! file cut short ends too), an unknown message kind and an LZ4 size beyond what LZ4 can expand
//! its input to are read errors naming the byte offset.
//!
//! The layout (re_log_encoding 0.36): a 12-byte stream header (`RRF2`, version, options), then
//! messages, each a 16-byte header (kind: u64 LE, 0 end, 1 store info, 2 Arrow, 3 blueprint
//! activation; payload length: u64 LE) and its payload; after the end message a 32-byte stream
//! footer; then possibly another stream.

use std::cell::Cell;
use std::io::{self, BufRead, Read};
use std::rc::Rc;

/// The first four bytes of a stream header.
const STREAM_MAGIC: &[u8; 4] = b"RRF2";
const STREAM_HEADER_BYTES: u64 = 12;
const MESSAGE_HEADER_BYTES: usize = 16;
const STREAM_FOOTER_BYTES: u64 = 32;
const KIND_END: u64 = 0;
const KIND_ARROW: u64 = 2;
const KIND_LAST: u64 = 3;

/// The field numbers of `rerun.log_msg.v1alpha1.ArrowMsg` that bound its decompression.
const ARROW_COMPRESSION_FIELD: u64 = 2;
const ARROW_UNCOMPRESSED_SIZE_FIELD: u64 = 3;
const ARROW_PAYLOAD_FIELD: u64 = 5;
/// `rerun.common.v1alpha1.Compression::Lz4`; every other value is read as uncompressed.
const COMPRESSION_LZ4: u64 = 2;

/// LZ4's block format expands a byte to at most 255 (a run of 0xFF length bytes); the slack
/// covers the literals and the last sequence.
fn lz4_max_expansion(compressed: u64) -> u64 {
    compressed.saturating_mul(255).saturating_add(1024)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Expect {
    StreamHeader,
    Message,
    StreamFooter,
    Done,
}

/// A reader that serves a Rerun file to the decoder a checked frame at a time.
pub struct Framed<R> {
    inner: R,
    /// Bytes of the file not yet read from `inner`.
    remaining: u64,
    /// File offset of the next byte read from `inner`.
    offset: u64,
    expect: Expect,
    frame: Vec<u8>,
    served: usize,
    /// Where the read ended early: a message declaring more bytes than the file has left
    /// (shared, because the decoder owns this reader).
    cut: Rc<Cell<Option<Cut>>>,
}

/// A message whose declared length runs past the end of the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    /// File offset of its header.
    pub at: u64,
    pub declared: u64,
    pub left: u64,
}

impl<R: Read> Framed<R> {
    /// `len`: the file's size in bytes.
    pub fn new(inner: R, len: u64) -> Self {
        Framed {
            inner,
            remaining: len,
            offset: 0,
            expect: Expect::StreamHeader,
            frame: Vec::new(),
            served: 0,
            cut: Rc::default(),
        }
    }

    /// Where the read stopped short of the file's end, if a length ran past it.
    pub fn cut_cell(&self) -> Rc<Cell<Option<Cut>>> {
        Rc::clone(&self.cut)
    }

    /// Reads up to `n` bytes (fewer only at the end of the file) onto the frame.
    fn take(&mut self, n: u64) -> io::Result<usize> {
        let n = n.min(self.remaining);
        let start = self.frame.len();
        let n_usize = usize::try_from(n).map_err(|_| corrupt(self.offset, "a frame too large"))?;
        self.frame.resize(start + n_usize, 0);
        self.inner.read_exact(&mut self.frame[start..])?;
        self.remaining -= n;
        self.offset += n;
        Ok(n_usize)
    }

    /// Loads the next frame; an empty frame is the end.
    fn next_frame(&mut self) -> io::Result<()> {
        self.frame.clear();
        self.served = 0;
        match self.expect {
            Expect::Done => {}
            Expect::StreamHeader => {
                self.take(STREAM_HEADER_BYTES)?;
                self.expect = if self.frame.is_empty() {
                    Expect::Done
                } else {
                    Expect::Message
                };
            }
            Expect::StreamFooter => {
                let at = self.offset;
                self.take(STREAM_FOOTER_BYTES)?;
                // Its last field counts the entries before it, and the decoder sizes a list
                // by that count before reading them; 32 bytes hold one.
                if let Some(count) = self.frame.get(28..32) {
                    let count = u32::from_le_bytes(count.try_into().unwrap_or_default());
                    if count > 1 {
                        return Err(corrupt(
                            at,
                            &format!("a stream footer counting {count} entries where it holds 1"),
                        ));
                    }
                }
                self.expect = Expect::StreamHeader;
            }
            Expect::Message => self.next_message()?,
        }
        Ok(())
    }

    fn next_message(&mut self) -> io::Result<()> {
        let at = self.offset;
        if self.remaining < MESSAGE_HEADER_BYTES as u64 {
            // Cut short inside a header: the decoder sees the file end after the last message.
            self.expect = Expect::Done;
            return Ok(());
        }
        self.take(MESSAGE_HEADER_BYTES as u64)?;
        if &self.frame[..4] == STREAM_MAGIC {
            // A new stream without an end message (concatenated recordings): its header is 12
            // bytes, so the last 4 read belong to what follows.
            let extra = self.frame.split_off(STREAM_HEADER_BYTES as usize);
            let mut message = extra;
            let needed = MESSAGE_HEADER_BYTES - message.len();
            let start = message.len();
            message.resize(MESSAGE_HEADER_BYTES, 0);
            if self.remaining < needed as u64 {
                self.expect = Expect::Done;
                return Ok(());
            }
            self.inner.read_exact(&mut message[start..])?;
            self.remaining -= needed as u64;
            self.offset += needed as u64;
            return self.message_from_header(at + STREAM_HEADER_BYTES, message);
        }
        let header = std::mem::take(&mut self.frame);
        self.message_from_header(at, header)
    }

    /// Checks a message header read at `at` and loads it with its payload onto the frame.
    fn message_from_header(&mut self, at: u64, header: Vec<u8>) -> io::Result<()> {
        let prefix = self.frame.len();
        let word = |i: usize| u64::from_le_bytes(header[i..i + 8].try_into().unwrap_or([0; 8]));
        let (kind, declared) = (word(0), word(8));
        if kind > KIND_LAST {
            return Err(corrupt(
                at,
                &format!("a message header of unknown kind {kind}"),
            ));
        }
        if declared > self.remaining {
            self.cut.set(Some(Cut {
                at,
                declared,
                left: self.remaining,
            }));
            // Serve what came before (a new stream's header), then nothing more.
            self.frame.truncate(prefix);
            self.expect = Expect::Done;
            return Ok(());
        }
        self.frame.extend_from_slice(&header);
        let payload_start = self.frame.len();
        self.take(declared)?;
        let checked = match kind {
            KIND_ARROW => check_arrow_sizes(&self.frame[payload_start..]),
            KIND_END => check_footer(&self.frame[payload_start..]),
            _ => Ok(()),
        };
        checked.map_err(|why| corrupt(at + MESSAGE_HEADER_BYTES as u64, &why))?;
        self.expect = if kind == KIND_END {
            Expect::StreamFooter
        } else {
            Expect::Message
        };
        Ok(())
    }
}

impl<R: Read> Read for Framed<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(out.len());
        out[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: Read> BufRead for Framed<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        while self.served == self.frame.len() && self.expect != Expect::Done {
            self.next_frame()?;
        }
        Ok(&self.frame[self.served..])
    }

    fn consume(&mut self, n: usize) {
        self.served = (self.served + n).min(self.frame.len());
    }
}

fn corrupt(at: u64, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{what} at byte {at}: the file is corrupt"),
    )
}

/// A protobuf field's value, as far as the size checks need it.
enum Value<'a> {
    Number(u64),
    Bytes(&'a [u8]),
    Other,
}

/// A protobuf message's fields in order, read without a schema (varints and lengths only).
fn proto_fields(message: &[u8]) -> Result<Vec<(u64, Value<'_>)>, String> {
    let mut fields = Vec::new();
    let mut rest = message;
    while !rest.is_empty() {
        let key = varint(&mut rest).ok_or("a truncated field key in a message")?;
        let (field, wire) = (key >> 3, key & 7);
        let value = match wire {
            0 => Value::Number(varint(&mut rest).ok_or("a truncated number in a message")?),
            1 | 5 => {
                let n = if wire == 1 { 8 } else { 4 };
                rest = rest
                    .get(n..)
                    .ok_or("a truncated fixed-size field in a message")?;
                Value::Other
            }
            2 => {
                let len = varint(&mut rest).ok_or("a truncated length in a message")?;
                let len = usize::try_from(len)
                    .ok()
                    .filter(|&l| l <= rest.len())
                    .ok_or("a field longer than its message")?;
                let (bytes, after) = rest.split_at(len);
                rest = after;
                Value::Bytes(bytes)
            }
            _ => return Err(format!("an unknown protobuf wire type {wire}")),
        };
        fields.push((field, value));
    }
    Ok(fields)
}

/// Checks an Arrow message (`rerun.log_msg.v1alpha1.ArrowMsg`: compression 2,
/// uncompressed_size 3, payload 5) with [`check_compressed_ipc`].
fn check_arrow_sizes(message: &[u8]) -> Result<(), String> {
    check_dataframe(
        message,
        ARROW_COMPRESSION_FIELD,
        ARROW_UNCOMPRESSED_SIZE_FIELD,
        ARROW_PAYLOAD_FIELD,
    )
}

/// Checks the Arrow data in an end message, the file's footer (`RrdFooter`: manifests 1, each an
/// `RrdManifest` whose data 4 is a `DataframePart`: payload 2, compression 3,
/// uncompressed_size 4), which the readers decode for the footer's manifest. A footer that is no
/// protobuf is left for the decoder to refuse: nothing in it is then sized.
fn check_footer(message: &[u8]) -> Result<(), String> {
    let Ok(footer) = proto_fields(message) else {
        return Ok(());
    };
    for (field, manifest) in footer {
        let (1, Value::Bytes(manifest)) = (field, manifest) else {
            continue;
        };
        for (field, part) in proto_fields(manifest).unwrap_or_default() {
            if let (4, Value::Bytes(part)) = (field, part) {
                check_dataframe(part, 3, 4, 2)?;
            }
        }
    }
    Ok(())
}

/// Refuses Arrow data (a compression, a declared decompressed size and a payload, at the given
/// field numbers) whose sizes its decoders would trust into a huge allocation: a decompressed
/// size LZ4 could not produce from its payload, or an Arrow IPC message inside whose body runs
/// past the bytes that follow it (Arrow sizes that buffer from the header before reading).
/// Decompresses the payload as Rerun's decoder will.
fn check_dataframe(
    message: &[u8],
    compression_field: u64,
    uncompressed_field: u64,
    payload_field: u64,
) -> Result<(), String> {
    let (mut compression, mut uncompressed, mut payload) = (0, 0, &[][..]);
    for (field, value) in proto_fields(message)? {
        match value {
            Value::Number(n) if field == compression_field => compression = n,
            Value::Number(n) if field == uncompressed_field => uncompressed = n,
            Value::Bytes(b) if field == payload_field => payload = b,
            _ => {}
        }
    }
    if compression != COMPRESSION_LZ4 {
        return check_ipc_stream(payload);
    }
    if uncompressed > lz4_max_expansion(payload.len() as u64) {
        return Err(format!(
            "an Arrow message declaring {uncompressed} bytes once decompressed from {}",
            payload.len()
        ));
    }
    // As Rerun's decoder does: a buffer of the declared size, what LZ4 leaves unwritten zero.
    let mut ipc = vec![0; uncompressed as usize];
    match lz4_flex::block::decompress_into(payload, &mut ipc) {
        Ok(_) => check_ipc_stream(&ipc),
        // The decoder fails on it the same way, without allocating more.
        Err(_) => Ok(()),
    }
}

/// Walks an Arrow IPC stream (messages of: an optional 0xFFFFFFFF continuation marker, an i32
/// metadata length, a flatbuffer `Message`, its body), refusing a metadata length or a body
/// length longer than the bytes left, as Arrow's `MessageReader` would allocate it first.
fn check_ipc_stream(mut ipc: &[u8]) -> Result<(), String> {
    fn take_i32(ipc: &mut &[u8]) -> Option<i32> {
        let (word, rest) = ipc.split_first_chunk::<4>()?;
        *ipc = rest;
        Some(i32::from_le_bytes(*word))
    }
    loop {
        let Some(mut len) = take_i32(&mut ipc) else {
            return Ok(());
        };
        if len == -1 {
            let Some(after_marker) = take_i32(&mut ipc) else {
                return Ok(());
            };
            len = after_marker;
        }
        if len == 0 {
            return Ok(());
        }
        let meta_len = usize::try_from(len)
            .ok()
            .filter(|&l| l <= ipc.len())
            .ok_or_else(|| {
                format!(
                    "an Arrow IPC message declaring {len} bytes of metadata where {} are left",
                    ipc.len()
                )
            })?;
        let (meta, rest) = ipc.split_at(meta_len);
        let body = flatbuffer_body_length(meta).ok_or("an unreadable Arrow IPC message header")?;
        if body > rest.len() as u64 {
            return Err(format!(
                "an Arrow IPC message declaring a body of {body} bytes where {} are left",
                rest.len()
            ));
        }
        ipc = &rest[body as usize..];
    }
}

/// The `bodyLength` of a flatbuffer `org.apache.arrow.flatbuf.Message` (field 3; fields 1 and 2
/// are its header union's type and value), read as Arrow reads it: an i64 taken as usize, so a
/// negative one is huge. `None` when its offsets leave the buffer (Arrow's verifier refuses
/// that too).
fn flatbuffer_body_length(meta: &[u8]) -> Option<u64> {
    const BODY_LENGTH_SLOT: usize = 4 + 2 * 3;
    let u16_at = |i: usize| Some(u16::from_le_bytes(*meta.get(i..)?.first_chunk::<2>()?));
    let u32_at = |i: usize| Some(u32::from_le_bytes(*meta.get(i..)?.first_chunk::<4>()?));
    let table = u32_at(0)? as usize;
    let vtable = usize::try_from(table as i64 - i64::from(u32_at(table)? as i32)).ok()?;
    if usize::from(u16_at(vtable)?) < BODY_LENGTH_SLOT + 2 {
        return Some(0);
    }
    let offset = usize::from(u16_at(vtable + BODY_LENGTH_SLOT)?);
    if offset == 0 {
        return Some(0);
    }
    let bytes = meta.get(table + offset..)?.first_chunk::<8>()?;
    Some(i64::from_le_bytes(*bytes) as u64)
}

/// A protobuf varint from the front of `bytes`, which it advances.
fn varint(bytes: &mut &[u8]) -> Option<u64> {
    let mut value = 0u64;
    for (i, &b) in bytes.iter().enumerate().take(10) {
        value |= u64::from(b & 0x7f) << (7 * i);
        if b & 0x80 == 0 {
            *bytes = &bytes[i + 1..];
            return Some(value);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Vec<u8> {
        let mut h = STREAM_MAGIC.to_vec();
        h.extend_from_slice(&[0, 36, 3, 0, 1, 2, 0, 0]);
        h
    }

    fn message(kind: u64, payload: &[u8], declared: u64) -> Vec<u8> {
        let mut m = kind.to_le_bytes().to_vec();
        m.extend_from_slice(&declared.to_le_bytes());
        m.extend_from_slice(payload);
        m
    }

    fn read_all(bytes: &[u8]) -> (io::Result<Vec<u8>>, Option<Cut>) {
        let mut framed = Framed::new(bytes, bytes.len() as u64);
        let cut = framed.cut_cell();
        let mut out = Vec::new();
        let result = framed.read_to_end(&mut out).map(|_| out);
        (result, cut.get())
    }

    #[test]
    fn whole_frames_pass_through_unchanged() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        file.extend(message(KIND_END, b"", 0));
        file.extend([7u8; 20]); // one entry: its span and checksum
        file.extend(*b"RRF2FOOT");
        file.extend(1u32.to_le_bytes());
        file.extend(header());
        file.extend(message(1, b"again", 5));
        let (read, cut) = read_all(&file);
        assert_eq!(read.unwrap(), file);
        assert_eq!(cut, None);
    }

    #[test]
    fn a_length_beyond_the_file_ends_the_read_before_that_message() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        let good = file.len();
        file.extend(message(2, b"short", u64::MAX - 3));
        let (read, cut) = read_all(&file);
        assert_eq!(read.unwrap(), &file[..good]);
        assert_eq!(
            cut,
            Some(Cut {
                at: good as u64,
                declared: u64::MAX - 3,
                left: 5
            })
        );
    }

    #[test]
    fn an_unknown_kind_is_a_read_error_naming_its_offset() {
        let mut file = header();
        file.extend(message(9, b"x", 1));
        let err = read_all(&file).0.unwrap_err();
        assert!(
            err.to_string().contains("unknown kind 9 at byte 12"),
            "{err}"
        );
    }

    #[test]
    fn an_lz4_size_beyond_lz4s_expansion_is_refused() {
        // field 2 (compression) = LZ4, field 3 (varint) = 2^40, field 5 (bytes) = 4 bytes.
        let mut arrow = vec![2 << 3, 2, 3 << 3];
        let mut v = 1u64 << 40;
        while v >= 0x80 {
            arrow.push((v as u8) | 0x80);
            v >>= 7;
        }
        arrow.push(v as u8);
        arrow.extend([(5 << 3) | 2, 4, 1, 2, 3, 4]);
        assert!(check_arrow_sizes(&arrow).is_err());
        // The same message declaring 1000 bytes is within LZ4's reach.
        let ok = [2 << 3, 2, 3 << 3, 0xe8, 0x07, (5 << 3) | 2, 4, 1, 2, 3, 4];
        assert_eq!(check_arrow_sizes(&ok), Ok(()));
        let mut file = header();
        let n = arrow.len() as u64;
        file.extend(message(KIND_ARROW, &arrow, n));
        let err = read_all(&file).0.unwrap_err();
        assert!(err.to_string().contains("at byte 28"), "{err}");
    }

    #[test]
    fn an_arrow_body_longer_than_what_follows_is_refused() {
        use rerun::external::arrow::array::{Float64Array, RecordBatch};
        use rerun::external::arrow::ipc::writer::StreamWriter;
        let column = Float64Array::from(vec![1.0, 2.0, 3.0]);
        let batch = RecordBatch::try_from_iter([("x", std::sync::Arc::new(column) as _)]).unwrap();
        let mut ipc = Vec::new();
        let mut writer = StreamWriter::try_new(&mut ipc, &batch.schema()).unwrap();
        writer.write(&batch).unwrap();
        writer.finish().unwrap();
        drop(writer);
        assert_eq!(check_ipc_stream(&ipc), Ok(()), "Arrow's own stream");
        // The second message (the batch): continuation, length, metadata, body.
        let schema_len = i32::from_le_bytes(ipc[4..8].try_into().unwrap()) as usize;
        let batch_at = 8 + schema_len;
        let meta_len = i32::from_le_bytes(ipc[batch_at + 4..batch_at + 8].try_into().unwrap());
        let meta = batch_at + 8;
        let body = flatbuffer_body_length(&ipc[meta..meta + meta_len as usize]).unwrap();
        assert_eq!(
            body as usize,
            ipc.len() - meta - meta_len as usize - 8,
            "the body, then EOS"
        );
        let field = (meta..ipc.len() - 8)
            .find(|&i| ipc[i..i + 8] == (body as i64).to_le_bytes())
            .unwrap();
        // One byte past what follows the metadata (the body and the 8-byte end marker).
        for huge in [body as i64 + 9, 1 << 62, -1] {
            let mut bad = ipc.clone();
            bad[field..field + 8].copy_from_slice(&huge.to_le_bytes());
            let why = check_ipc_stream(&bad).unwrap_err();
            assert!(why.contains("declaring a body of"), "{why}");
        }
    }

    #[test]
    fn a_real_footer_holds_the_arrow_data_that_is_checked() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/rrd-corpus/pendulum.rrd"
        );
        let file = std::fs::read(path).unwrap();
        // The end message: the last one before the 32-byte stream footer.
        let mut at = STREAM_HEADER_BYTES as usize;
        let end = loop {
            let word = |i: usize| u64::from_le_bytes(file[i..i + 8].try_into().unwrap());
            let (kind, len) = (word(at), word(at + 8) as usize);
            let payload = &file[at + MESSAGE_HEADER_BYTES..at + MESSAGE_HEADER_BYTES + len];
            if kind == KIND_END {
                break payload;
            }
            at += MESSAGE_HEADER_BYTES + len;
        };
        let mut parts = 0;
        for (field, manifest) in proto_fields(end).unwrap() {
            let (1, Value::Bytes(manifest)) = (field, manifest) else {
                continue;
            };
            for (field, part) in proto_fields(manifest).unwrap() {
                if let (4, Value::Bytes(part)) = (field, part) {
                    let fields = proto_fields(part).unwrap();
                    assert!(
                        fields
                            .iter()
                            .any(|(f, v)| *f == 2 && matches!(v, Value::Bytes(b) if b.len() > 100))
                    );
                    parts += 1;
                }
            }
        }
        assert!(parts >= 1, "a manifest with its data");
        assert_eq!(check_footer(end), Ok(()));
    }

    #[test]
    fn a_stream_footer_counting_more_entries_than_it_holds_is_refused() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/rrd-corpus/rope.rrd"
        );
        let mut file = std::fs::read(path).unwrap();
        assert!(read_all(&file).0.is_ok());
        let n = file.len();
        assert_eq!(
            &file[n - 8..n - 4],
            b"FOOT",
            "the stream footer ends the file"
        );
        file[n - 4..].copy_from_slice(&3_000_000_000u32.to_le_bytes());
        let err = read_all(&file).0.unwrap_err().to_string();
        assert!(err.contains("counting 3000000000 entries"), "{err}");
    }

    #[test]
    fn varints_read_as_protobuf_writes_them() {
        let mut b: &[u8] = &[0xac, 0x02, 9];
        assert_eq!(varint(&mut b), Some(300));
        assert_eq!(b, &[9]);
        assert_eq!(varint(&mut &[0x80u8; 11][..]), None);
    }
}
