//! LZ4 block decompression in place: the compressed block lies at the tail of the buffer it
//! decompresses into, so a message costs its decompressed size and a small margin, not both
//! sizes at once. LZ4's block format allows it: with `in_place_margin` bytes past the output's
//! end its writes never overtake its reads; where a block would (it was not compressed for this
//! margin), what is left of it is moved past the output's end first.

/// Room past the decompressed size that decompressing in place needs (LZ4's
/// `LZ4_DECOMPRESS_INPLACE_MARGIN`).
pub fn in_place_margin(compressed: usize) -> usize {
    (compressed >> 8) + 32
}

/// `buf[..size]` decompressed from the LZ4 block in `buf[start..]`, `buf` then cut to `size`.
/// Where the block would overwrite its own unread input (it was not compressed for this margin),
/// what is left of it is moved past the output's end and decompressed from there.
pub fn decompress(mut buf: Vec<u8>, start: usize, size: usize) -> Result<Vec<u8>, String> {
    let mut result = decompress_in_place(&mut buf, start, 0, size);
    if let Err(InPlace::Overtakes { ip, op }) = result {
        let mut roomy = vec![0; size + (buf.len() - ip)];
        roomy[..op].copy_from_slice(&buf[..op]);
        roomy[size..].copy_from_slice(&buf[ip..]);
        buf = roomy;
        result = decompress_in_place(&mut buf, size, op, size);
    }
    match result {
        Ok(()) => {}
        Err(InPlace::Corrupt(why)) => {
            return Err(format!(
                "an Arrow message whose LZ4 data is corrupt ({why})"
            ));
        }
        Err(InPlace::Size(written)) => return Err(wrong_size(size, written)),
        Err(InPlace::Overtakes { .. }) => {
            return Err("an Arrow message whose LZ4 data overlaps its output".into());
        }
    }
    // Not shrunk to fit: the margin is under 0.4 % of it, and a shrinking reallocation of a
    // buffer this large copies it and fragments the allocator's heap.
    buf.truncate(size);
    Ok(buf)
}

fn wrong_size(size: usize, written: usize) -> String {
    format!(
        "an Arrow message declaring {size} bytes once decompressed, where its data gives {written}"
    )
}

/// Why a block could not be decompressed in place.
#[derive(Debug, PartialEq)]
enum InPlace {
    /// The next sequence would write on input not yet read: where it starts in the input, and
    /// where the output stands (nothing of it written).
    Overtakes {
        ip: usize,
        op: usize,
    },
    Corrupt(&'static str),
    /// The block gives this many bytes, not the size declared.
    Size(usize),
}

/// Decompresses the LZ4 block in `buf[ip..]` into `buf[..size]` from output position `op` on,
/// reading ahead of where it writes (`op ≤ ip` throughout). The block format: sequences of a
/// token (literal length, match length − 4, each 4 bits, 15 continued by bytes up to 255), the
/// literals, a 2-byte little-endian offset back into the output and the match copied from
/// there; the last sequence has literals only.
fn decompress_in_place(
    buf: &mut [u8],
    mut ip: usize,
    mut op: usize,
    size: usize,
) -> Result<(), InPlace> {
    use InPlace::{Corrupt, Overtakes, Size};
    let end = buf.len();
    let length = |buf: &[u8], at: &mut usize, mut n: usize| -> Result<usize, InPlace> {
        if n == 15 {
            loop {
                let b = *buf
                    .get(*at)
                    .ok_or(Corrupt("a length past the block's end"))?;
                *at += 1;
                n += usize::from(b);
                if b != 255 {
                    break;
                }
            }
        }
        Ok(n)
    };
    loop {
        // The whole sequence is read before anything of it is written.
        let sequence = ip;
        let mut at = ip;
        let token = *buf
            .get(at)
            .ok_or(Corrupt("a sequence past the block's end"))?;
        at += 1;
        let literals = length(buf, &mut at, usize::from(token >> 4))?;
        if literals > end - at {
            return Err(Corrupt("literals past the block's end"));
        }
        if op + literals > size {
            return Err(Size(op + literals));
        }
        let literals_at = at;
        at += literals;
        if at == end {
            buf.copy_within(literals_at..at, op); // op ≤ ip: a forward move
            op += literals;
            return if op == size { Ok(()) } else { Err(Size(op)) };
        }
        let offset = match buf.get(at..at + 2) {
            Some(&[lo, hi]) => usize::from(u16::from_le_bytes([lo, hi])),
            _ => return Err(Corrupt("an offset past the block's end")),
        };
        at += 2;
        let matched = length(buf, &mut at, usize::from(token & 15))? + 4;
        if offset == 0 || offset > op + literals {
            return Err(Corrupt("a match before the output's start"));
        }
        if op + literals + matched > size {
            return Err(Size(op + literals + matched));
        }
        if op + literals + matched > at {
            return Err(Overtakes { ip: sequence, op });
        }
        buf.copy_within(literals_at..literals_at + literals, op);
        op += literals;
        // A match closer than its length repeats a pattern of period `offset`: copied from
        // any multiple of `offset` back, so in non-overlapping pieces of doubling length.
        let (mut distance, mut left) = (offset, matched);
        while left > 0 {
            let n = distance.min(left);
            buf.copy_within(op - distance..op - distance + n, op);
            op += n;
            left -= n;
            distance *= 2;
        }
        ip = at;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Byte strings from runs, repeating patterns and noise mixed, of many lengths.
    fn samples() -> Vec<Vec<u8>> {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut out = vec![Vec::new(), vec![7], vec![0; 100_000]];
        for len in [1usize, 5, 12, 13, 64, 255, 256, 1000, 4096, 65_536, 200_000] {
            for kind in 0..4 {
                let v: Vec<u8> = (0..len)
                    .map(|i| match kind {
                        0 => next() as u8,
                        1 => (i % 7) as u8,
                        2 => {
                            if (i / 300) % 2 == 0 {
                                0
                            } else {
                                next() as u8
                            }
                        }
                        _ => (i as f32 * 0.001).sin().to_le_bytes()[i % 4],
                    })
                    .collect();
                out.push(v);
            }
        }
        out
    }

    #[test]
    fn in_place_lz4_gives_back_what_was_compressed() {
        let mut overtaken = 0;
        for data in samples() {
            let block = lz4_flex::block::compress(&data);
            let (size, n) = (data.len(), block.len());
            // With LZ4's margin (and with none, where the copy takes over).
            for total in [(size + in_place_margin(n)).max(n), size.max(n)] {
                let mut buf = vec![0; total];
                buf[total - n..].copy_from_slice(&block);
                let out = decompress(buf, total - n, size).unwrap();
                assert_eq!(out, data, "{size} bytes from {n}, buffer {total}");
            }
            let mut buf = vec![0; size + in_place_margin(n)];
            let start = buf.len() - n;
            buf[start..].copy_from_slice(&block);
            let mut tight = vec![0; size.max(n)];
            let tight_start = tight.len() - n;
            tight[tight_start..].copy_from_slice(&block);
            let tight_result = decompress_in_place(&mut tight, tight_start, 0, size);
            overtaken += usize::from(matches!(tight_result, Err(InPlace::Overtakes { .. })));
            assert_eq!(
                decompress_in_place(&mut buf, start, 0, size),
                Ok(()),
                "{size} with the margin"
            );
        }
        // Without the margin some blocks would overwrite their input: the path that moves the
        // rest of the block past the output ran, and gave the data back above.
        assert!(overtaken > 0);
    }

    #[test]
    fn a_corrupt_or_cut_lz4_block_is_an_error_never_a_panic() {
        for data in samples().into_iter().filter(|d| d.len() > 100) {
            let block = lz4_flex::block::compress(&data);
            for cut in [1, block.len() / 2, block.len() - 1] {
                let short = &block[..cut];
                let total = data.len() + in_place_margin(cut);
                let mut buf = vec![0; total];
                buf[total - cut..].copy_from_slice(short);
                assert!(decompress(buf, total - cut, data.len()).is_err());
            }
            for at in (0..block.len()).step_by(block.len() / 7 + 1) {
                let mut bad = block.clone();
                bad[at] ^= 0xA5;
                let total = data.len() + in_place_margin(bad.len());
                let mut buf = vec![0; total];
                buf[total - bad.len()..].copy_from_slice(&bad);
                // Either an error or some bytes of the declared size: never a panic.
                if let Ok(out) = decompress(buf, total - bad.len(), data.len()) {
                    assert_eq!(out.len(), data.len());
                }
            }
        }
    }
}
