//! Rerun's file framing, read message by message with `re_log_encoding`'s `StreamHeader` and
//! `MessageHeader`. Every length a file declares is checked before anything is sized by it: one
//! corrupted length would otherwise ask for up to 2⁶⁴ bytes and the process would abort (an
//! allocation failure is not a panic that `catch_unwind` could turn into an error). A message
//! longer than what is left of the file ends the read there, as a file cut short does. Only an
//! Arrow message's payload is held, up to the size the reader allows.
//!
//! The layout: a 12-byte stream header, messages (a 16-byte header: kind and length; the
//! payload), after the end message a 32-byte stream footer; then possibly another stream, with or
//! without the end of the one before (`cat a.rrd b.rrd`).

use std::io::{self, Read};

use re_protos::external::prost::{self, bytes::Bytes};
use rerun::external::re_log_encoding::{
    Decodable as _, MessageHeader, MessageKind, RRD_FOURCC, StreamFooter, StreamHeader,
};

const STREAM_FOOTER_BYTES: u64 = StreamFooter::ENCODED_SIZE_BYTES as u64;
/// What is kept of an end message's payload: a protobuf key and a length.
const FOOTER_HEAD_BYTES: u64 = 16;

/// A Rerun file read a checked message at a time.
pub struct Framed<R> {
    inner: R,
    /// Bytes of the file not yet read from `inner`.
    remaining: u64,
    /// File offset of the next byte read from `inner`.
    offset: u64,
    /// The longest Arrow payload held; a longer one is skipped (the reader refuses it).
    max_held: u64,
    /// The end message was read: a stream footer comes next.
    footer_next: bool,
    done: bool,
    /// Where the read ended early: a message declaring more bytes than the file has left.
    pub(super) cut: Option<Cut>,
    /// The offset of the last footer (an end message holding a manifest) no message followed:
    /// the file was finalised, not cut short.
    pub(super) footer: Option<u64>,
    /// The offset of a footer that more messages followed: a part's footer, not the file's.
    pub(super) footer_followed: Option<u64>,
    /// A store's info was read (Rerun writes it before the store's first chunk).
    pub(super) store_info_seen: bool,
}

/// One message of the file: its kind, the file offset and length of its payload and, for an
/// Arrow message within the size allowed, the payload (the readers use no other message's).
pub struct Message {
    pub kind: MessageKind,
    pub at: u64,
    pub len: u64,
    pub payload: Option<Bytes>,
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
    /// `len`: the file's size in bytes; `max_held`: the longest Arrow payload to hold.
    pub fn new(inner: R, len: u64, max_held: u64) -> Self {
        Framed {
            inner,
            remaining: len,
            offset: 0,
            max_held,
            footer_next: false,
            done: false,
            cut: None,
            footer: None,
            footer_followed: None,
            store_info_seen: false,
        }
    }

    /// The next message, `None` at the end of the file (or where a length ran past it, or a
    /// header was cut short).
    pub fn next_message(&mut self) -> io::Result<Option<Message>> {
        while !self.done {
            if std::mem::take(&mut self.footer_next) {
                self.stream_footer()?;
                continue;
            }
            let at = self.offset;
            let Some(word) = self.read_array::<4>()? else {
                break;
            };
            if word == RRD_FOURCC {
                // A stream's header: at the start, or where another stream follows.
                let Some(rest) = self.read_array::<8>()? else {
                    break;
                };
                StreamHeader::from_rrd_bytes(&[&word[..], &rest[..]].concat())
                    .and_then(|header| header.to_version_and_options())
                    .map_err(|e| {
                        corrupt(at, &format!("a stream header that is not Rerun's ({e})"))
                    })?;
                continue;
            }
            let Some(rest) = self.read_array::<12>()? else {
                break;
            };
            let header = MessageHeader::from_rrd_bytes(&[&word[..], &rest[..]].concat())
                .map_err(|e| corrupt(at, &format!("a message header that cannot be read ({e})")))?;
            if header.len > self.remaining {
                self.cut = Some(Cut {
                    at,
                    declared: header.len,
                    left: self.remaining,
                });
                break;
            }
            return self.payload(at, header).map(Some);
        }
        self.done = true;
        Ok(None)
    }

    /// Reads a message's payload (an Arrow one's within `max_held`), skipping what is not used.
    fn payload(&mut self, at: u64, header: MessageHeader) -> io::Result<Message> {
        let len = header.len;
        let mut payload = None;
        if header.kind != MessageKind::End && self.footer.is_some() {
            // A footer ends what it lists: one with more after it is not the file's.
            self.footer_followed = self.footer.take();
        }
        self.store_info_seen |= header.kind == MessageKind::SetStoreInfo;
        match header.kind {
            MessageKind::ArrowMsg if len <= self.max_held => {
                let mut bytes = vec![0; len as usize];
                self.inner.read_exact(&mut bytes)?;
                self.advance(len);
                payload = Some(Bytes::from(bytes));
            }
            MessageKind::End => {
                // The footer lists every chunk of the file: it grows with the file, and only
                // whether it starts with a manifest is needed, so the rest is skipped, not held.
                let mut head = [0; FOOTER_HEAD_BYTES as usize];
                let n = len.min(FOOTER_HEAD_BYTES);
                self.inner.read_exact(&mut head[..n as usize])?;
                self.advance(n);
                if footer_starts_with_manifest(&head[..n as usize], len) {
                    self.footer = Some(at);
                }
                self.skip(len - n)?;
                self.footer_next = true;
            }
            _ => self.skip(len)?,
        }
        Ok(Message {
            kind: header.kind,
            at: at + MessageHeader::ENCODED_SIZE_BYTES as u64,
            len,
            payload,
        })
    }

    /// The stream footer after an end message. Its last field counts the entries before it, and
    /// Rerun's decoder sizes a list by that count before reading them; 32 bytes hold one.
    fn stream_footer(&mut self) -> io::Result<()> {
        let at = self.offset;
        if self.remaining < STREAM_FOOTER_BYTES {
            return self.skip(self.remaining);
        }
        let mut footer = [0; STREAM_FOOTER_BYTES as usize];
        self.inner.read_exact(&mut footer)?;
        self.advance(STREAM_FOOTER_BYTES);
        let count = u32::from_le_bytes([footer[28], footer[29], footer[30], footer[31]]);
        if count > 1 {
            return Err(corrupt(
                at,
                &format!("a stream footer counting {count} entries where it holds 1"),
            ));
        }
        Ok(())
    }

    /// The next `N` bytes, `None` (and the read done) when fewer are left.
    fn read_array<const N: usize>(&mut self) -> io::Result<Option<[u8; N]>> {
        if self.remaining < N as u64 {
            self.done = true;
            return Ok(None);
        }
        let mut bytes = [0; N];
        self.inner.read_exact(&mut bytes)?;
        self.advance(N as u64);
        Ok(Some(bytes))
    }

    fn advance(&mut self, n: u64) {
        self.remaining -= n;
        self.offset += n;
    }

    /// Reads past `n` bytes of the file, holding none of them.
    fn skip(&mut self, n: u64) -> io::Result<()> {
        let skipped = io::copy(&mut (&mut self.inner).take(n), &mut io::sink())?;
        if skipped != n {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        self.advance(n);
        Ok(())
    }
}

fn corrupt(at: u64, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{what} at byte {at}: the file is corrupt"),
    )
}

/// Whether an end message of `len` bytes, of which `head` is the start, holds the file's footer
/// (`RrdFooter`) starting with a non-empty manifest (field 1, length-delimited) that fits in it.
/// A protobuf key is a varint, as a length is.
fn footer_starts_with_manifest(head: &[u8], len: u64) -> bool {
    let mut rest = head;
    let Ok(key) = prost::decode_length_delimiter(&mut rest) else {
        return false;
    };
    let Ok(manifest) = prost::decode_length_delimiter(&mut rest) else {
        return false;
    };
    let used = (head.len() - rest.len()) as u64;
    key == (1 << 3 | 2) && manifest > 0 && manifest as u64 <= len - used
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Vec<u8> {
        [&RRD_FOURCC[..], &[0, 36, 3, 0, 1, 2, 0, 0]].concat()
    }

    fn message(kind: u64, payload: &[u8], declared: u64) -> Vec<u8> {
        [&kind.to_le_bytes()[..], &declared.to_le_bytes(), payload].concat()
    }

    /// Each message's kind and the file offset of its payload.
    type Read = Vec<(MessageKind, u64)>;

    fn read_all(bytes: &[u8]) -> (io::Result<Read>, Option<Cut>) {
        let mut framed = Framed::new(bytes, bytes.len() as u64, u64::MAX);
        let messages = std::iter::from_fn(|| framed.next_message().transpose());
        let result = messages.map(|m| m.map(|m| (m.kind, m.at))).collect();
        (result, framed.cut)
    }

    #[test]
    fn messages_come_out_as_written_across_streams() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        file.extend(message(0, b"", 0));
        file.extend([7u8; 20]); // one entry: its span and checksum
        file.extend(*b"RRF2FOOT");
        file.extend(1u32.to_le_bytes());
        file.extend(header());
        file.extend(message(1, b"again!!", 7));
        file.extend(header()); // concatenated without an end message
        file.extend(message(2, b"arrow", 5));
        let (read, cut) = read_all(&file);
        // Payloads at 12 + 16, then after 5 bytes + 16, then after the stream footer (32) and
        // a stream header (12) + 16, then after 7 bytes, a stream header and 16.
        let store = MessageKind::SetStoreInfo;
        let expected = [
            (store, 28),
            (MessageKind::End, 49),
            (store, 109),
            (MessageKind::ArrowMsg, 144),
        ];
        assert_eq!(read.unwrap(), expected);
        assert_eq!(cut, None);
    }

    #[test]
    fn a_length_beyond_the_file_ends_the_read_before_that_message() {
        let mut file = header();
        file.extend(message(1, b"store", 5));
        let good = file.len();
        file.extend(message(2, b"short", u64::MAX - 3));
        let (read, cut) = read_all(&file);
        assert_eq!(read.unwrap(), vec![(MessageKind::SetStoreInfo, 28)]);
        let declared = u64::MAX - 3;
        assert_eq!(
            cut,
            Some(Cut {
                at: good as u64,
                declared,
                left: 5
            })
        );
    }

    #[test]
    fn an_arrow_payload_over_the_size_held_is_skipped_not_held() {
        let mut file = header();
        file.extend(message(2, b"arrow", 5));
        file.extend(message(2, b"long arrow", 10));
        let mut framed = Framed::new(&file[..], file.len() as u64, 5);
        let held = framed.next_message().unwrap().unwrap();
        assert_eq!(held.payload.as_deref(), Some(&b"arrow"[..]));
        let skipped = framed.next_message().unwrap().unwrap();
        assert_eq!(
            (skipped.kind, skipped.len, skipped.payload),
            (MessageKind::ArrowMsg, 10, None)
        );
        assert!(framed.next_message().unwrap().is_none());
    }

    #[test]
    fn an_unknown_kind_is_a_read_error_naming_its_offset() {
        let mut file = header();
        file.extend(message(9, b"x", 1));
        let err = read_all(&file).0.unwrap_err().to_string();
        assert!(
            err.contains("unknown MessageHeader kind: 9") && err.contains("at byte 12"),
            "{err}"
        );
    }

    #[test]
    fn a_real_footer_has_a_manifest_and_a_cut_one_has_none() {
        use re_protos::external::prost::Message as _;
        use re_protos::log_msg::v1alpha1::RrdFooter;
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/rrd-corpus/pendulum.rrd"
        );
        let file = std::fs::read(path).unwrap();
        // The end message: the last one before the 32-byte stream footer.
        let mut at = StreamHeader::ENCODED_SIZE_BYTES;
        let end = loop {
            let header = MessageHeader::from_rrd_bytes(&file[at..at + 16]).unwrap();
            let payload = &file[at + 16..at + 16 + header.len as usize];
            if header.kind == MessageKind::End {
                break payload;
            }
            at += 16 + header.len as usize;
        };
        let footer = RrdFooter::decode(end).unwrap();
        let manifest = footer.manifests.first().expect("a manifest").encoded_len();
        assert!(manifest > 100, "a manifest with its data");
        let n = end.len() as u64;
        assert!(footer_starts_with_manifest(&end[..16], n));
        // The same start in a message one byte shorter than its first manifest needs.
        let needed = (1 + prost::length_delimiter_len(manifest) + manifest) as u64;
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
}
