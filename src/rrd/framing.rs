//! Rerun's file framing, read and checked message by message. Every length a file declares is
//! checked before anything is sized by it: one corrupted length would otherwise ask for up to
//! 2⁶⁴ bytes and the process would abort (an allocation failure is not a panic that
//! `catch_unwind` could turn into an error). [`Framed`] hands out whole messages only: a message
//! longer than what is left of the file ends the read there (it is where a file cut short ends
//! too), an unknown message kind is a read error naming the byte offset. An Arrow message's
//! payload is checked where it is decompressed ([`arrow_ipc`]): an LZ4 size beyond what LZ4 can
//! expand its input to, or an Arrow IPC body longer than what follows it, is refused.
//!
//! The layout (re_log_encoding 0.36): a 12-byte stream header (`RRF2`, version, options), then
//! messages, each a 16-byte header (kind: u64 LE, 0 end, 1 store info, 2 Arrow, 3 blueprint
//! activation; payload length: u64 LE) and its payload; after the end message a 32-byte stream
//! footer; then possibly another stream.

use std::io::{self, Read};

use super::arrow_message::{ArrowPayload, read_arrow_message};

/// The first four bytes of a stream header.
const STREAM_MAGIC: &[u8; 4] = b"RRF2";
const STREAM_HEADER_BYTES: u64 = 12;
const MESSAGE_HEADER_BYTES: usize = 16;
const STREAM_FOOTER_BYTES: u64 = 32;
pub const KIND_END: u64 = 0;
pub const KIND_ARROW: u64 = 2;
const KIND_LAST: u64 = 3;
/// What is kept of an end message's payload: a protobuf key and a length.
const FOOTER_HEAD_BYTES: u64 = 16;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Expect {
    StreamHeader,
    Message,
    StreamFooter,
    Done,
}

/// A Rerun file read a checked message at a time.
pub struct Framed<R> {
    inner: R,
    /// Bytes of the file not yet read from `inner`.
    remaining: u64,
    /// File offset of the next byte read from `inner`.
    offset: u64,
    expect: Expect,
    /// The frame just read; its capacity is reused for the next.
    frame: Vec<u8>,
    /// The message just read: its kind and its header's file offset.
    message: Option<(u64, u64)>,
    /// Where the read ended early: a message declaring more bytes than the file has left.
    cut: Option<Cut>,
    has_footer: bool,
    /// The Arrow message just read.
    arrow: Option<Result<ArrowPayload, String>>,
}

/// One message of the file: its kind, the file offset of its payload and, for an Arrow message,
/// its contents (the readers use no other message's).
pub struct Message {
    pub kind: u64,
    pub at: u64,
    /// An Arrow message's contents, read as they came, or what is wrong with them.
    pub arrow: Option<Result<ArrowPayload, String>>,
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
            message: None,
            arrow: None,
            cut: None,
            has_footer: false,
        }
    }

    /// Where the read stopped short of the file's end, if a length ran past it.
    pub fn cut(&self) -> Option<Cut> {
        self.cut
    }

    /// The next message, `None` at the end of the file (or where a length ran past it).
    pub fn next_message(&mut self) -> io::Result<Option<Message>> {
        self.message = None;
        while self.message.is_none() && self.expect != Expect::Done {
            self.next_frame()?;
        }
        let arrow = self.arrow.take();
        Ok(self.message.map(|(kind, at)| Message {
            kind,
            at: at + MESSAGE_HEADER_BYTES as u64,
            arrow,
        }))
    }

    /// Reads up to `n` bytes (fewer only at the end of the file) onto the frame.
    fn take(&mut self, n: u64) -> io::Result<usize> {
        let n = n.min(self.remaining);
        let start = self.frame.len();
        let n_usize = usize::try_from(n).map_err(|_| corrupt(self.offset, "a frame too large"))?;
        // Exactly: the frame is as large as the largest message, not up to twice that.
        self.frame.reserve_exact(n_usize);
        self.frame.resize(start + n_usize, 0);
        self.inner.read_exact(&mut self.frame[start..])?;
        self.remaining -= n;
        self.offset += n;
        Ok(n_usize)
    }

    /// Reads past `n` bytes of the file, holding none of them.
    fn skip(&mut self, n: u64) -> io::Result<()> {
        let skipped = io::copy(&mut (&mut self.inner).take(n), &mut io::sink())?;
        if skipped != n {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        self.remaining -= n;
        self.offset += n;
        Ok(())
    }

    /// Whether an end message with a footer holding a manifest was read: the file was
    /// finalised, not cut short.
    pub fn has_footer(&self) -> bool {
        self.has_footer
    }

    /// Loads the next frame; an empty frame is the end.
    fn next_frame(&mut self) -> io::Result<()> {
        self.frame.clear();
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
            Expect::Message => self.read_message()?,
        }
        Ok(())
    }

    fn read_message(&mut self) -> io::Result<()> {
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
        let word = |i: usize| u64::from_le_bytes(header[i..i + 8].try_into().unwrap_or([0; 8]));
        let (kind, declared) = (word(0), word(8));
        if kind > KIND_LAST {
            return Err(corrupt(
                at,
                &format!("a message header of unknown kind {kind}"),
            ));
        }
        if declared > self.remaining {
            self.cut = Some(Cut {
                at,
                declared,
                left: self.remaining,
            });
            self.expect = Expect::Done;
            return Ok(());
        }
        self.frame.extend_from_slice(&header);
        if kind == KIND_END {
            // The footer lists every chunk of the file: it grows with the file, and only whether
            // it starts with a manifest is needed, so the rest is skipped, not held.
            let head = self.take(declared.min(FOOTER_HEAD_BYTES))?;
            let payload = &self.frame[self.frame.len() - head..];
            self.has_footer |= footer_starts_with_manifest(payload, declared);
            self.skip(declared - head as u64)?;
        } else if kind == KIND_ARROW {
            self.arrow = Some(read_arrow_message(&mut self.inner, declared)?);
            self.remaining -= declared;
            self.offset += declared;
        } else {
            // The store's info and the blueprint's activation: nothing the readers use.
            self.skip(declared)?;
        }
        self.message = Some((kind, at));
        self.expect = if kind == KIND_END {
            Expect::StreamFooter
        } else {
            Expect::Message
        };
        Ok(())
    }
}

fn corrupt(at: u64, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{what} at byte {at}: the file is corrupt"),
    )
}

/// A protobuf field's value, as far as the size checks need it.
pub(super) enum Value<'a> {
    Number(u64),
    Bytes(&'a [u8]),
    Other,
}

/// A protobuf message's fields in order, read without a schema (varints and lengths only).
pub(super) fn proto_fields(message: &[u8]) -> Result<Vec<(u64, Value<'_>)>, String> {
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

/// Whether an end message of `len` bytes, of which `head` is the start, holds the file's footer
/// (`RrdFooter`) starting with a non-empty manifest (field 1) that fits in it.
fn footer_starts_with_manifest(head: &[u8], len: u64) -> bool {
    let mut rest = head;
    let (Some(key), Some(manifest)) = (varint(&mut rest), varint(&mut rest)) else {
        return false;
    };
    let used = (head.len() - rest.len()) as u64;
    key == (1 << 3 | 2) && manifest > 0 && manifest <= len - used
}

/// A protobuf varint from the front of `bytes`, which it advances.
pub(super) fn varint(bytes: &mut &[u8]) -> Option<u64> {
    read_varint(bytes).ok().flatten()
}

/// A protobuf varint read from `r`; `None` when the message ends inside it.
pub(super) fn read_varint(r: &mut impl Read) -> io::Result<Option<u64>> {
    let mut value = 0u64;
    let mut byte = [0u8];
    for i in 0..10 {
        if r.read(&mut byte)? == 0 {
            return Ok(None);
        }
        value |= u64::from(byte[0] & 0x7f) << (7 * i);
        if byte[0] & 0x80 == 0 {
            return Ok(Some(value));
        }
    }
    Ok(None)
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

    /// Each message's kind and the file offset of its payload.
    type Read = Vec<(u64, u64)>;

    fn read_all(bytes: &[u8]) -> (io::Result<Read>, Option<Cut>) {
        let mut framed = Framed::new(bytes, bytes.len() as u64);
        let mut out = Vec::new();
        let result = loop {
            match framed.next_message() {
                Ok(Some(m)) => out.push((m.kind, m.at)),
                Ok(None) => break Ok(out),
                Err(e) => break Err(e),
            }
        };
        (result, framed.cut())
    }

    #[test]
    fn messages_come_out_as_written_across_streams() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        file.extend(message(KIND_END, b"", 0));
        file.extend([7u8; 20]); // one entry: its span and checksum
        file.extend(*b"RRF2FOOT");
        file.extend(1u32.to_le_bytes());
        file.extend(header());
        file.extend(message(1, b"again!!", 7));
        let (read, cut) = read_all(&file);
        // Payloads at 12 + 16, then after 5 bytes + 16, then after the stream footer (32) and
        // a stream header (12) + 16.
        assert_eq!(read.unwrap(), vec![(1, 28), (KIND_END, 49), (1, 109)]);
        assert_eq!(cut, None);
    }

    #[test]
    fn a_length_beyond_the_file_ends_the_read_before_that_message() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        let good = file.len();
        file.extend(message(2, b"short", u64::MAX - 3));
        let (read, cut) = read_all(&file);
        assert_eq!(read.unwrap(), vec![(1, 28)]);
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
    fn a_real_footer_has_a_manifest_and_a_cut_one_has_none() {
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
        let n = end.len() as u64;
        assert!(footer_starts_with_manifest(&end[..16], n));
        // The same start in a message one byte shorter than its first manifest needs.
        let mut rest = end;
        let (_, manifest) = (varint(&mut rest), varint(&mut rest).unwrap());
        let needed = (end.len() - rest.len()) as u64 + manifest;
        assert!(footer_starts_with_manifest(&end[..16], needed));
        assert!(
            !footer_starts_with_manifest(&end[..16], needed - 1),
            "a manifest cut short"
        );
        assert!(!footer_starts_with_manifest(b"", 0));
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
