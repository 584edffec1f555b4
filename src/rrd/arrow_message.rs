//! An Arrow message of a Rerun file (`rerun.log_msg.v1alpha1.ArrowMsg`) read from the file into
//! its decompressed Arrow IPC stream, holding about the decompressed size and no more: the
//! message's protobuf fields are read as they come, and an LZ4 payload is read into the tail of
//! the buffer it decompresses into and decompressed in place (LZ4's block format allows it
//! when the output has a small margin past its end: the writes never overtake the reads).
//! Every size is checked before anything is sized by it: a decompressed size LZ4 could not
//! produce from its payload, a field longer than its message, an IPC body longer than what
//! follows it.

use std::io::{self, Read};

use super::framing::{Value, proto_fields, read_varint};
use super::lz4;

/// The field numbers of `rerun.log_msg.v1alpha1.ArrowMsg` the readers use.
const ARROW_STORE_ID_FIELD: u64 = 1;
const ARROW_COMPRESSION_FIELD: u64 = 2;
const ARROW_ENCODING_FIELD: u64 = 4;
const ARROW_UNCOMPRESSED_SIZE_FIELD: u64 = 3;
const ARROW_PAYLOAD_FIELD: u64 = 5;
/// `rerun.common.v1alpha1.Compression::Lz4`; every other value is read as uncompressed.
const COMPRESSION_LZ4: u64 = 2;
/// `rerun.log_msg.v1alpha1.Encoding::ArrowIpc`, the only encoding Rerun writes.
const ENCODING_ARROW_IPC: u64 = 1;
/// `rerun.common.v1alpha1.StoreKind::Recording` (a blueprint is 2).
const STORE_KIND_RECORDING: u64 = 1;

/// LZ4's block format expands a byte to at most 255 (a run of 0xFF length bytes); the slack
/// covers the literals and the last sequence.
fn lz4_max_expansion(compressed: u64) -> u64 {
    compressed.saturating_mul(255).saturating_add(1024)
}

/// An Arrow message as the readers use it.
#[derive(Debug, PartialEq)]
pub struct ArrowPayload {
    /// Its store is a recording, not a blueprint.
    pub recording: bool,
    pub application_id: String,
    /// Its Arrow IPC stream, decompressed.
    pub ipc: Vec<u8>,
}

/// Where a payload was read: into the tail of its decompression buffer, or on its own.
enum Payload {
    InPlace { buf: Vec<u8>, start: usize },
    Plain(Vec<u8>),
}

/// Reads an Arrow message of `len` bytes from `r`: `Err` for a read error, `Ok(Err)` naming
/// what is wrong with its contents (the message is then read to its end all the same, so that
/// the file's framing stays in step).
pub fn read_arrow_message(r: &mut impl Read, len: u64) -> io::Result<Result<ArrowPayload, String>> {
    let mut r = r.take(len);
    let parsed = read_fields(&mut r);
    io::copy(&mut r, &mut io::sink())?; // what a malformed message leaves unread
    Ok(match parsed? {
        Ok(fields) => fields.finish(),
        Err(why) => Err(why),
    })
}

/// An Arrow message's fields as they were read.
#[derive(Default)]
struct Fields {
    recording: bool,
    application_id: String,
    compression: u64,
    uncompressed: Option<u64>,
    encoding: u64,
    payload: Option<Payload>,
}

fn read_fields(r: &mut io::Take<&mut impl Read>) -> io::Result<Result<Fields, String>> {
    let mut f = Fields::default();
    while r.limit() > 0 {
        let Some(key) = read_varint(r)? else {
            return Ok(Err("a truncated field key in an Arrow message".into()));
        };
        let (field, wire) = (key >> 3, key & 7);
        let n = match wire {
            0 => {
                let Some(v) = read_varint(r)? else {
                    return Ok(Err("a truncated number in an Arrow message".into()));
                };
                match field {
                    ARROW_COMPRESSION_FIELD => f.compression = v,
                    ARROW_UNCOMPRESSED_SIZE_FIELD => f.uncompressed = Some(v),
                    ARROW_ENCODING_FIELD => f.encoding = v,
                    _ => {}
                }
                continue;
            }
            1 => 8,
            5 => 4,
            2 => match read_varint(r)? {
                Some(n) if n <= r.limit() => n,
                _ => return Ok(Err("a field longer than its Arrow message".into())),
            },
            _ => return Ok(Err(format!("an unknown protobuf wire type {wire}"))),
        };
        match (field, wire) {
            (ARROW_PAYLOAD_FIELD, 2) => match read_payload(r, n, &f)? {
                Ok(payload) => f.payload = Some(payload),
                Err(why) => return Ok(Err(why)),
            },
            (ARROW_STORE_ID_FIELD, 2) => {
                let store = read_exactly(r, n)?;
                if let Err(why) = f.store(&store) {
                    return Ok(Err(why));
                }
            }
            _ => {
                io::copy(&mut r.by_ref().take(n), &mut io::sink())?;
            }
        }
    }
    Ok(Ok(f))
}

/// Reads a payload of `n` bytes: an LZ4 one whose decompressed size is known into the tail of
/// its decompression buffer, any other on its own.
fn read_payload(r: &mut impl Read, n: u64, f: &Fields) -> io::Result<Result<Payload, String>> {
    let (COMPRESSION_LZ4, Some(size)) = (f.compression, f.uncompressed) else {
        return Ok(Ok(Payload::Plain(read_exactly(r, n)?)));
    };
    if size > lz4_max_expansion(n) {
        return Ok(Err(format!(
            "an Arrow message declaring {size} bytes once decompressed from {n}"
        )));
    }
    let (size, n) = (size as usize, n as usize);
    let total = (size + lz4::in_place_margin(n)).max(n);
    let mut buf = vec![0; total];
    r.read_exact(&mut buf[total - n..])?;
    Ok(Ok(Payload::InPlace {
        buf,
        start: total - n,
    }))
}

fn read_exactly(r: &mut impl Read, n: u64) -> io::Result<Vec<u8>> {
    let mut v = vec![0; n as usize];
    r.read_exact(&mut v)?;
    Ok(v)
}

impl Fields {
    /// The store id (`rerun.common.v1alpha1.StoreId`: kind 1, application id 3 with its id 1).
    fn store(&mut self, store: &[u8]) -> Result<(), String> {
        for (field, value) in proto_fields(store)? {
            match (field, value) {
                (1, Value::Number(kind)) => self.recording = kind == STORE_KIND_RECORDING,
                (3, Value::Bytes(app)) => {
                    for (field, value) in proto_fields(app)? {
                        if let (1, Value::Bytes(id)) = (field, value) {
                            self.application_id = String::from_utf8_lossy(id).into_owned();
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The decompressed, checked IPC stream.
    fn finish(self) -> Result<ArrowPayload, String> {
        if self.encoding != ENCODING_ARROW_IPC {
            return Err(format!(
                "an Arrow message in an unknown encoding {}",
                self.encoding
            ));
        }
        let ipc = match (self.payload, self.compression) {
            (None, _) => Vec::new(),
            (Some(Payload::InPlace { buf, start }), _) => {
                let size = self.uncompressed.unwrap_or(0) as usize;
                lz4::decompress(buf, start, size)?
            }
            (Some(Payload::Plain(payload)), COMPRESSION_LZ4) => {
                // The decompressed size came after the payload (Rerun writes it before).
                let size = self.uncompressed.unwrap_or(0);
                if size > lz4_max_expansion(payload.len() as u64) {
                    return Err(format!(
                        "an Arrow message declaring {size} bytes once decompressed from {}",
                        payload.len()
                    ));
                }
                let mut ipc = vec![0; size as usize];
                let start = ipc.len();
                ipc.extend_from_slice(&payload);
                drop(payload);
                lz4::decompress(ipc, start, size as usize)?
            }
            (Some(Payload::Plain(payload)), _) => payload,
        };
        check_ipc_stream(&ipc)?;
        Ok(ArrowPayload {
            recording: self.recording,
            application_id: self.application_id,
            ipc,
        })
    }
}

/// Reads an Arrow message held whole in memory (see [`read_arrow_message`]).
#[cfg(test)]
fn arrow_ipc(message: &[u8]) -> Result<ArrowPayload, String> {
    read_arrow_message(&mut &message[..], message.len() as u64).map_err(|e| e.to_string())?
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

#[cfg(test)]
mod tests {
    use super::*;

    fn varint_bytes(mut v: u64) -> Vec<u8> {
        let mut out = Vec::new();
        while v >= 0x80 {
            out.push((v as u8) | 0x80);
            v >>= 7;
        }
        out.push(v as u8);
        out
    }

    /// An `ArrowMsg` as Rerun writes it: store id (recording, application "app"), compression,
    /// decompressed size, encoding and payload.
    fn arrow_message(compression: u64, declared: u64, payload: &[u8]) -> Vec<u8> {
        let bytes = |field: u64, b: &[u8]| {
            let mut f = varint_bytes(field << 3 | 2);
            f.extend(varint_bytes(b.len() as u64));
            f.extend_from_slice(b);
            f
        };
        let number = |field: u64, n: u64| {
            let mut f = varint_bytes(field << 3);
            f.extend(varint_bytes(n));
            f
        };
        let mut store = number(1, STORE_KIND_RECORDING);
        store.extend(bytes(2, b"rec"));
        store.extend(bytes(3, &bytes(1, b"app")));
        let mut m = bytes(ARROW_STORE_ID_FIELD, &store);
        m.extend(number(ARROW_COMPRESSION_FIELD, compression));
        m.extend(number(ARROW_UNCOMPRESSED_SIZE_FIELD, declared));
        m.extend(number(ARROW_ENCODING_FIELD, ENCODING_ARROW_IPC));
        m.extend(bytes(ARROW_PAYLOAD_FIELD, payload));
        m
    }

    fn ipc_stream() -> Vec<u8> {
        use rerun::external::arrow::array::{Float64Array, RecordBatch};
        use rerun::external::arrow::ipc::writer::StreamWriter;
        let column = Float64Array::from(vec![1.0, 2.0, 3.0]);
        let batch = RecordBatch::try_from_iter([("x", std::sync::Arc::new(column) as _)]).unwrap();
        let mut ipc = Vec::new();
        let mut writer = StreamWriter::try_new(&mut ipc, &batch.schema()).unwrap();
        writer.write(&batch).unwrap();
        writer.finish().unwrap();
        drop(writer);
        ipc
    }

    #[test]
    fn an_arrow_message_gives_its_store_and_its_decompressed_stream() {
        let ipc = ipc_stream();
        let lz4 = lz4_flex::block::compress(&ipc);
        for (compression, payload) in [(COMPRESSION_LZ4, &lz4), (0, &ipc)] {
            let decoded = arrow_ipc(&arrow_message(compression, ipc.len() as u64, payload));
            let expected = ArrowPayload {
                recording: true,
                application_id: "app".into(),
                ipc: ipc.clone(),
            };
            assert_eq!(decoded, Ok(expected));
        }
    }

    #[test]
    fn an_lz4_size_beyond_lz4s_expansion_or_its_data_is_refused() {
        let lz4 = lz4_flex::block::compress(&ipc_stream());
        let n = ipc_stream().len() as u64;
        let why = arrow_ipc(&arrow_message(COMPRESSION_LZ4, 1 << 40, &lz4)).unwrap_err();
        assert!(
            why.contains("declaring 1099511627776 bytes once decompressed from"),
            "{why}"
        );
        // Within LZ4's reach but not what the data gives, either way.
        for declared in [n + 1, n - 1] {
            assert!(arrow_ipc(&arrow_message(COMPRESSION_LZ4, declared, &lz4)).is_err());
        }
    }

    #[test]
    fn an_arrow_body_longer_than_what_follows_is_refused() {
        let ipc = ipc_stream();
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
}
