//! An Arrow message of a Rerun file, decoded as Rerun's own `re_protos` `ArrowMsg` (its payload a
//! slice of the message's bytes, not a copy), and its Arrow IPC stream decompressed with
//! `lz4_flex` into a buffer of the size the message declares, checked first against what LZ4 can
//! expand its payload to (the reader also holds it to its cap on one message).

use re_protos::common::v1alpha1::{Compression, StoreKind};
use re_protos::external::prost::{Message as _, bytes::Bytes};
use re_protos::log_msg::v1alpha1::{ArrowMsg, Encoding};

/// The store an Arrow message was logged to.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Store {
    /// A recording, not a blueprint.
    pub recording: bool,
    pub application_id: String,
    pub recording_id: String,
}

/// An Arrow message read from its bytes, not yet decompressed.
pub struct ArrowMessage {
    pub store: Store,
    message: ArrowMsg,
}

/// LZ4's block format expands a byte to at most 255 (a run of 0xFF length bytes); the slack
/// covers the literals and the last sequence.
fn lz4_max_expansion(compressed: u64) -> u64 {
    compressed.saturating_mul(255).saturating_add(1024)
}

impl ArrowMessage {
    /// Decodes an Arrow message's protobuf (`Err` says what is wrong with it).
    pub fn decode(bytes: Bytes) -> Result<Self, String> {
        let message = ArrowMsg::decode(bytes)
            .map_err(|e| format!("an Arrow message that cannot be decoded ({e})"))?;
        let id = message.store_id.clone().unwrap_or_default();
        let store = Store {
            recording: id.kind == StoreKind::Recording as i32,
            application_id: id.application_id.map(|a| a.id).unwrap_or_default(),
            recording_id: id.recording_id,
        };
        Ok(ArrowMessage { store, message })
    }

    fn lz4(&self) -> bool {
        self.message.compression == Compression::Lz4 as i32
    }

    /// The size of its Arrow IPC stream once decompressed [B], as it declares it.
    pub fn size(&self) -> u64 {
        if self.lz4() {
            self.message.uncompressed_size
        } else {
            self.message.payload.len() as u64
        }
    }

    /// Its Arrow IPC stream, decompressed (every compression but LZ4 read as none).
    pub fn ipc(self) -> Result<Vec<u8>, String> {
        let encoding = self.message.encoding;
        if encoding != Encoding::ArrowIpc as i32 {
            return Err(format!(
                "an Arrow message in an unknown encoding {encoding}"
            ));
        }
        let (lz4, size, payload) = (self.lz4(), self.size(), self.message.payload);
        if !lz4 {
            return Ok(payload.to_vec());
        }
        let n = payload.len();
        if size > lz4_max_expansion(n as u64) {
            return Err(format!(
                "an Arrow message declaring {size} bytes once decompressed from {n}"
            ));
        }
        let mut ipc = vec![0; size as usize];
        let written = lz4_flex::block::decompress_into(&payload, &mut ipc)
            .map_err(|e| format!("an Arrow message whose LZ4 data is corrupt ({e})"))?;
        if written != ipc.len() {
            return Err(format!(
                "an Arrow message declaring {size} bytes once decompressed, where its data gives \
                 {written}"
            ));
        }
        Ok(ipc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use re_protos::common::v1alpha1::{ApplicationId, StoreId};

    /// An `ArrowMsg` as Rerun writes it: store id (recording "rec" of application "app"),
    /// compression, decompressed size, encoding and payload.
    fn arrow_message(compression: Compression, declared: u64, payload: &[u8]) -> Bytes {
        let message = ArrowMsg {
            store_id: Some(StoreId {
                kind: StoreKind::Recording as i32,
                recording_id: "rec".into(),
                application_id: Some(ApplicationId { id: "app".into() }),
            }),
            compression: compression as i32,
            uncompressed_size: declared,
            encoding: Encoding::ArrowIpc as i32,
            payload: Bytes::copy_from_slice(payload),
            ..ArrowMsg::default()
        };
        message.encode_to_vec().into()
    }

    fn decoded(compression: Compression, declared: u64, payload: &[u8]) -> Result<Vec<u8>, String> {
        ArrowMessage::decode(arrow_message(compression, declared, payload))?.ipc()
    }

    #[test]
    fn an_arrow_message_gives_its_store_and_its_decompressed_stream() {
        let ipc: Vec<u8> = (0..5000u32).map(|i| (i % 7) as u8).collect();
        let lz4 = lz4_flex::block::compress(&ipc);
        for (compression, payload) in [(Compression::Lz4, &lz4), (Compression::None, &ipc)] {
            let message = ArrowMessage::decode(arrow_message(compression, 5000, payload)).unwrap();
            let store = Store {
                recording: true,
                application_id: "app".into(),
                recording_id: "rec".into(),
            };
            assert_eq!((&message.store, message.size()), (&store, 5000));
            assert_eq!(message.ipc().unwrap(), ipc);
        }
    }

    #[test]
    fn an_lz4_size_beyond_lz4s_expansion_or_its_data_is_refused() {
        let ipc = vec![3u8; 1000];
        let lz4 = lz4_flex::block::compress(&ipc);
        let why = decoded(Compression::Lz4, 1 << 40, &lz4).unwrap_err();
        assert!(
            why.contains("declaring 1099511627776 bytes once decompressed from"),
            "{why}"
        );
        // Within LZ4's reach but not what the data gives, either way.
        for declared in [1001, 999] {
            assert!(
                decoded(Compression::Lz4, declared, &lz4).is_err(),
                "{declared}"
            );
        }
        assert!(decoded(Compression::Lz4, 1000, &lz4[..lz4.len() - 1]).is_err());
    }
}
