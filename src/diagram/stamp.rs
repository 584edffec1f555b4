//! What a diagram draws, stamped into its PNG as a text chunk (`tEXt`, PNG 1.2 §11.3.4.3), so
//! that a picture kept in the repository can be checked against what the code draws today: the
//! methods, settings and measured values, without the wall times (which no two runs share).

/// The keyword of the text chunk.
pub const KEY: &str = "physlab-data";

/// `png` with a `tEXt` chunk `key` = `text` after its header chunk. `text` is written as
/// Latin-1: characters beyond it become `?`.
pub fn with_text(png: &[u8], key: &str, text: &str) -> Vec<u8> {
    // Signature (8 bytes), then IHDR: length (4), type (4), 13 bytes of data, CRC (4).
    const AFTER_HEADER: usize = 8 + 4 + 4 + 13 + 4;
    let mut data: Vec<u8> = key.bytes().collect();
    data.push(0);
    data.extend(
        text.chars()
            .map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?')),
    );
    let mut chunk = Vec::with_capacity(data.len() + 12);
    chunk.extend_from_slice(&(data.len() as u32).to_be_bytes());
    chunk.extend_from_slice(b"tEXt");
    chunk.extend_from_slice(&data);
    chunk.extend_from_slice(&crc32(&chunk[4..]).to_be_bytes());
    let at = AFTER_HEADER.min(png.len());
    [&png[..at], &chunk, &png[at..]].concat()
}

/// The text of the `tEXt` chunk `key` in `png`, if it has one.
pub fn text(png: &[u8], key: &str) -> Option<String> {
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().ok()?) as usize;
        let kind = &png[at + 4..at + 8];
        let data = png.get(at + 8..at + 8 + len)?;
        if kind == b"tEXt" {
            let split = data.iter().position(|&b| b == 0)?;
            if &data[..split] == key.as_bytes() {
                return Some(data[split + 1..].iter().map(|&b| char::from(b)).collect());
            }
        }
        at += 12 + len;
    }
    None
}

/// CRC-32 as PNG computes it (ISO 3309, polynomial 0xEDB88320, reflected).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = u32::MAX;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CRC of "IEND" with no data is the constant every PNG ends with (AE 42 60 82), and
    /// a stamped chunk reads back.
    #[test]
    fn the_chunk_is_a_valid_png_chunk_and_reads_back() {
        assert_eq!(crc32(b"IEND"), 0xAE42_6082);
        // A signature, an IHDR chunk (13 bytes of data, CRC not checked here) and IEND.
        let png = [
            &[0x89, b'P', b'N', b'G', 13, 10, 26, 10][..],
            &[0, 0, 0, 13],
            b"IHDR",
            &[0; 13 + 4],
            &[0, 0, 0, 0],
            b"IEND",
            &[0xAE, 0x42, 0x60, 0x82],
        ]
        .concat();
        let stamped = with_text(&png, KEY, "rk4 dt=0.01 error=1e-9");
        assert_eq!(
            text(&stamped, KEY).as_deref(),
            Some("rk4 dt=0.01 error=1e-9")
        );
        assert_eq!(text(&stamped, "other"), None);
    }
}
