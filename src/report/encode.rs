//! Small encoders the reports need: base64 (for PNG data URIs in SVG — a
//! dozen lines do not justify a crate), PNG of a grey image, and the hex
//! pixel lines of PostScript's `readhexstring`. The text encoders write
//! into an [`io::Write`] through a small buffer, so a picture's text is
//! never held whole.

use std::io::{self, Write};

use crate::llv::GreyImage;

/// Bytes of encoded text gathered before each write to the output.
const CHUNK: usize = 16 * 1024;

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648, with `=` padding).
pub fn base64(bytes: &[u8]) -> String {
    let mut out = Vec::with_capacity(bytes.len().div_ceil(3) * 4);
    // Writing into a `Vec` cannot fail; the symbols are ASCII.
    let _ = write_base64(&mut out, bytes);
    String::from_utf8_lossy(&out).into_owned()
}

/// Writes `bytes` in standard base64 (RFC 4648, with `=` padding) to `out`.
pub fn write_base64(out: &mut impl Write, bytes: &[u8]) -> io::Result<()> {
    let mut buf = Vec::with_capacity(CHUNK + 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk.first().copied().unwrap_or(0),
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sym = |shift: u32| B64[((n >> shift) & 63) as usize];
        buf.push(sym(18));
        buf.push(sym(12));
        buf.push(if chunk.len() > 1 { sym(6) } else { b'=' });
        buf.push(if chunk.len() > 2 { sym(0) } else { b'=' });
        if buf.len() >= CHUNK {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    out.write_all(&buf)
}

/// An 8-bit greyscale PNG of `img` (the validity mask is not carried: invalid
/// pixels show whatever value lens correction left there).
pub fn png_grey(img: &GreyImage) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    {
        let w = u32::try_from(img.width()).unwrap_or(u32::MAX);
        let h = u32::try_from(img.height()).unwrap_or(u32::MAX);
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header()?;
        writer.write_image_data(img.data())?;
        writer.finish()?;
    }
    Ok(out)
}

/// Writes the pixels of `img` as hex, one scan line after another, wrapped
/// at 72 characters (DSC asks for lines under 255; `readhexstring` skips the
/// newlines).
pub fn write_hex(out: &mut impl Write, img: &GreyImage) -> io::Result<()> {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut buf = Vec::with_capacity(CHUNK + 4);
    let mut col = 0;
    for &v in img.data() {
        buf.push(HEX[usize::from(v >> 4)]);
        buf.push(HEX[usize::from(v & 15)]);
        col += 2;
        if col >= 72 {
            buf.push(b'\n');
            col = 0;
        }
        if buf.len() >= CHUNK {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    if col > 0 {
        buf.push(b'\n');
    }
    out.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, enc) in cases {
            assert_eq!(base64(plain.as_bytes()), enc, "{plain:?}");
        }
        assert_eq!(base64(&[0xff, 0xfe, 0xfd]), "//79");
    }

    #[test]
    fn base64_of_more_than_a_chunk_decodes_back() {
        let bytes: Vec<u8> = (0..100_001u32).map(|i| (i * 7 % 256) as u8).collect();
        let text = base64(&bytes);
        assert_eq!(text.len(), bytes.len().div_ceil(3) * 4);
        let value = |c: u8| B64.iter().position(|&b| b == c).map(|v| v as u32);
        let mut back = Vec::new();
        for quad in text.as_bytes().chunks(4) {
            let n = quad
                .iter()
                .fold(0u32, |n, &c| (n << 6) | value(c).unwrap_or(0));
            let pad = quad.iter().filter(|&&c| c == b'=').count();
            back.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
        }
        assert_eq!(back, bytes);
    }

    #[test]
    fn png_round_trips_through_the_image_crate() {
        let img = GreyImage::new(3, 2, vec![0, 50, 100, 150, 200, 250]).unwrap();
        let bytes = png_grey(&img).unwrap();
        let back = image::load_from_memory(&bytes).unwrap().to_luma8();
        assert_eq!(back.dimensions(), (3, 2));
        assert_eq!(back.into_raw(), img.data());
    }

    #[test]
    fn hex_lines_are_short_and_complete() {
        let img = GreyImage::new(50, 1, (0..50).collect()).unwrap();
        let mut v = Vec::new();
        write_hex(&mut v, &img).unwrap();
        let s = String::from_utf8(v).unwrap();
        assert!(s.lines().all(|l| l.len() <= 72));
        let joined: String = s.lines().collect();
        assert_eq!(joined.len(), 100);
        assert!(joined.starts_with("00010203"));
    }
}
