//! Small encoders the reports need: base64 (for PNG data URIs in SVG — a
//! dozen lines do not justify a crate), PNG of a grey image, and the hex
//! pixel lines of PostScript's `readhexstring`.

use crate::llv::GreyImage;

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648, with `=` padding).
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk.first().copied().unwrap_or(0),
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sym = |shift: u32| char::from(B64[((n >> shift) & 63) as usize]);
        out.push(sym(18));
        out.push(sym(12));
        out.push(if chunk.len() > 1 { sym(6) } else { '=' });
        out.push(if chunk.len() > 2 { sym(0) } else { '=' });
    }
    out
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

/// Appends the pixels of `img` as hex, one scan line after another, wrapped
/// at 72 characters (DSC asks for lines under 255; `readhexstring` skips the
/// newlines).
pub fn push_hex(out: &mut String, img: &GreyImage) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut col = 0;
    for &v in img.data() {
        out.push(char::from(HEX[usize::from(v >> 4)]));
        out.push(char::from(HEX[usize::from(v & 15)]));
        col += 2;
        if col >= 72 {
            out.push('\n');
            col = 0;
        }
    }
    if col > 0 {
        out.push('\n');
    }
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
        let mut s = String::new();
        push_hex(&mut s, &img);
        assert!(s.lines().all(|l| l.len() <= 72));
        let joined: String = s.lines().collect();
        assert_eq!(joined.len(), 100);
        assert!(joined.starts_with("00010203"));
    }
}
