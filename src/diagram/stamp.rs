//! What a diagram draws, stamped into its PNG as a text chunk (`tEXt`, PNG 1.2 §11.3.4.3), so
//! that a picture kept in the repository can be checked against what the code draws today: the
//! methods, settings and measured values, without the wall times (which no two runs share).

/// The keyword of the text chunk.
pub const KEY: &str = "physlab-data";

/// An 8-bit RGB picture of `size` (width, height) encoded as PNG, with a `tEXt` chunk
/// [`KEY`] = `text` before its image data. `text` is written as Latin-1: characters beyond it
/// become `?`.
pub fn png_with_text(rgb: &[u8], size: (u32, u32), text: &str) -> anyhow::Result<Vec<u8>> {
    let mut png = Vec::new();
    let mut encoder = png::Encoder::new(&mut png, size.0, size.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let latin1 = text.chars().map(|c| if c <= 'ÿ' { c } else { '?' });
    encoder.add_text_chunk(KEY.into(), latin1.collect())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(png)
}

/// The text of the `tEXt` chunk `key` in `png`, if it has one.
pub fn text(png: &[u8], key: &str) -> Option<String> {
    let reader = png::Decoder::new(std::io::Cursor::new(png))
        .read_info()
        .ok()?;
    let chunks = &reader.info().uncompressed_latin1_text;
    Some(chunks.iter().find(|c| c.keyword == key)?.text.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stamped picture is a PNG whose chunks check (the decoder verifies every CRC), and its
    /// text reads back, a character beyond Latin-1 as `?`.
    #[test]
    fn the_chunk_is_a_valid_png_chunk_and_reads_back() {
        let rgb = [10, 20, 30, 40, 50, 60];
        let png = png_with_text(&rgb, (2, 1), "rk4 dt=0.01 error=1e-9 θ").unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(text(&png, KEY).as_deref(), Some("rk4 dt=0.01 error=1e-9 ?"));
        assert_eq!(text(&png, "other"), None);
        let mut reader = png::Decoder::new(std::io::Cursor::new(&png))
            .read_info()
            .unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut pixels).unwrap();
        assert_eq!(pixels, rgb);
    }
}
