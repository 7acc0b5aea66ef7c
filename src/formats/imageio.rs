//! Grey images in any format the console meets: the cell's `.img`/`.imc`,
//! and PNG, PGM, TIFF, BMP for everything else, and JPEG photographs (read
//! only: a lossy copy of a survey image is not one). The format follows the
//! file extension.
//!
//! JPEG: a colour photograph becomes its luma by the JPEG's own weights
//! (BT.601, what the file's Y channel holds and what OpenCV's and libjpeg's
//! grey readers give), not Rec. 709 as the other formats; an EXIF
//! orientation is applied, so the lines come in the picture as every viewer
//! shows it, and a note says so; CMYK is converted through RGB; progressive
//! files decode as baseline ones; a file without its end-of-image marker
//! (truncated) is refused, and so are 12-bit, lossless and damaged files,
//! with the decoder's reason. The size is checked
//! from the header before any pixel is decoded.
//!
//! PNG is read and written with the `png` crate directly so that an `.img`'s
//! comment and upper-left corner travel in tEXt chunks (`vss.comment` — or
//! `vss.comment-hex` when it holds control characters — `vss.x0`, `vss.y0`):
//! `.img → .png → .img` gives back the same bytes. Colour and 16-bit inputs
//! become 8-bit grey; the `_noted` readers say so, for the CLI to print.
//! Decoders get an allocation limit derived from the file's size (deflate
//! cannot expand more than ~1032:1), so a small file cannot ask for gigabytes.

use std::io::Cursor;
use std::path::Path;

use super::img::{ImgFile, encode_img, parse_img};
use super::{FormatError, FormatErrorKind as K, Location, read_bytes, write_bytes};
use crate::llv::GreyImage;

/// The image formats the console reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// `.img` or `.imc` (ITEX).
    Img,
    Png,
    Pgm,
    Tiff,
    Bmp,
    /// `.jpg`, `.jpeg`: read only.
    Jpeg,
}

/// Largest decoded image we accept from a foreign format (bytes).
const MAX_DECODED: u64 = 256 << 20;

impl ImageKind {
    /// The kind of a path, from its extension (case-insensitive).
    pub fn of(path: &Path) -> Option<ImageKind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "img" | "imc" => ImageKind::Img,
            "png" => ImageKind::Png,
            "pgm" | "pnm" => ImageKind::Pgm,
            "tif" | "tiff" => ImageKind::Tiff,
            "bmp" => ImageKind::Bmp,
            "jpg" | "jpeg" => ImageKind::Jpeg,
            _ => return None,
        })
    }

    /// Whether the format keeps the comment and x0/y0.
    pub fn keeps_header(self) -> bool {
        matches!(self, ImageKind::Img | ImageKind::Png)
    }

    /// Whether vss writes the format (JPEG it only reads).
    pub fn writable(self) -> bool {
        self != ImageKind::Jpeg
    }

    fn of_or_err(path: &Path) -> Result<ImageKind, FormatError> {
        ImageKind::of(path).ok_or_else(|| {
            FormatError::new(
                path,
                Location::None,
                K::Unsupported,
                "unknown image extension; expected .img, .imc, .png, .pgm, .tif, .tiff, .bmp, .jpg or .jpeg",
            )
        })
    }
}

/// Reads a grey image in any supported format.
pub fn read_any(path: &Path) -> Result<ImgFile, FormatError> {
    read_any_noted(path).map(|(f, _)| f)
}

/// Reads a grey image and returns the notes a person should see (colour
/// reduced to grey, 16 bits reduced to 8, alpha dropped).
pub fn read_any_noted(path: &Path) -> Result<(ImgFile, Vec<String>), FormatError> {
    read_any_sized(path, |_, _| Ok::<(), std::convert::Infallible>(()))
}

/// Reads a grey image whose size `accept(width, height)` takes, checking
/// the size from the header before the pixels are read or decoded (an
/// `.img` costs its 64-byte header, a PNG its compressed bytes, when the
/// image is refused). Returns the notes as [`read_any_noted`].
pub fn read_any_sized<E: std::fmt::Display>(
    path: &Path,
    accept: impl Fn(usize, usize) -> Result<(), E>,
) -> Result<(ImgFile, Vec<String>), FormatError> {
    let kind = ImageKind::of_or_err(path)?;
    if kind == ImageKind::Img {
        return super::img::read_img_sized(path, accept).map(|f| (f, Vec::new()));
    }
    let bytes = read_bytes(path)?;
    if let Some((w, h)) = foreign_size(&bytes, kind) {
        accept(w, h)
            .map_err(|m| FormatError::new(path, Location::None, K::Range, m.to_string()))?;
    }
    decode_any(&bytes, kind, path)
}

/// The width and height a PNG, PNM, TIFF or BMP header gives, without
/// decoding the pixels; `None` when the header does not read (the decoder
/// then says why).
fn foreign_size(bytes: &[u8], kind: ImageKind) -> Option<(usize, usize)> {
    let fmt = match kind {
        ImageKind::Img => return None,
        ImageKind::Png => image::ImageFormat::Png,
        ImageKind::Pgm => image::ImageFormat::Pnm,
        ImageKind::Tiff => image::ImageFormat::Tiff,
        ImageKind::Bmp => image::ImageFormat::Bmp,
        ImageKind::Jpeg => image::ImageFormat::Jpeg,
    };
    let (w, h) = image::ImageReader::with_format(Cursor::new(bytes), fmt)
        .into_dimensions()
        .ok()?;
    Some((w as usize, h as usize))
}

/// Decodes image bytes of a given kind.
pub fn decode_any(
    bytes: &[u8],
    kind: ImageKind,
    path: &Path,
) -> Result<(ImgFile, Vec<String>), FormatError> {
    let limit = (bytes.len() as u64)
        .saturating_mul(1100)
        .saturating_add(1 << 20)
        .min(MAX_DECODED);
    match kind {
        ImageKind::Img => parse_img(bytes, path).map(|f| (f, Vec::new())),
        ImageKind::Png => decode_png(bytes, path, limit),
        ImageKind::Pgm => decode_foreign(bytes, image::ImageFormat::Pnm, path, limit),
        ImageKind::Tiff => decode_foreign(bytes, image::ImageFormat::Tiff, path, limit),
        ImageKind::Bmp => decode_foreign(bytes, image::ImageFormat::Bmp, path, limit),
        ImageKind::Jpeg => decode_jpeg(bytes, path, limit),
    }
}

/// Writes a grey image in the format of the path's extension, atomically.
/// PGM, TIFF and BMP drop the comment and x0/y0 (see [`ImageKind::keeps_header`]).
pub fn write_any(path: &Path, f: &ImgFile) -> Result<(), FormatError> {
    let kind = ImageKind::of_or_err(path)?;
    let bytes = encode_any(f, kind).map_err(|e| FormatError {
        path: path.to_path_buf(),
        ..e
    })?;
    write_bytes(path, &bytes)
}

/// Encodes a grey image in the given format.
pub fn encode_any(f: &ImgFile, kind: ImageKind) -> Result<Vec<u8>, FormatError> {
    match kind {
        ImageKind::Img => encode_img(f),
        ImageKind::Png => encode_png(f),
        ImageKind::Pgm => encode_foreign(f, image::ImageFormat::Pnm),
        ImageKind::Tiff => encode_foreign(f, image::ImageFormat::Tiff),
        ImageKind::Bmp => encode_foreign(f, image::ImageFormat::Bmp),
        ImageKind::Jpeg => Err(FormatError::new(
            Path::new("<image>"),
            Location::None,
            K::Unsupported,
            "vss reads JPEG but does not write it (lossy); write .png, .pgm, .tif or .bmp",
        )),
    }
}

fn encode_err(message: String) -> FormatError {
    FormatError::new(Path::new("<image>"), Location::None, K::Io, message)
}

fn encode_png(f: &ImgFile) -> Result<Vec<u8>, FormatError> {
    let (w, h) = f.image.size();
    let (Ok(w), Ok(h)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(encode_err("image too large for PNG".into()));
    };
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let chunk_err = |e: png::EncodingError| encode_err(format!("PNG text chunk: {e}"));
        if f.comment.chars().any(|c| u32::from(c) > 0xFF) {
            return Err(FormatError::new(
                Path::new("<image>"),
                Location::None,
                K::Encoding,
                "comment holds a character above U+00FF; .img comments are 8-bit",
            ));
        }
        if f.comment.chars().any(char::is_control) {
            let hex: String = f
                .comment
                .chars()
                .map(|c| format!("{:02x}", u32::from(c)))
                .collect();
            enc.add_text_chunk("vss.comment-hex".into(), hex)
                .map_err(chunk_err)?;
        } else {
            enc.add_text_chunk("vss.comment".into(), f.comment.clone())
                .map_err(chunk_err)?;
        }
        enc.add_text_chunk("vss.x0".into(), f.x0.to_string())
            .map_err(chunk_err)?;
        enc.add_text_chunk("vss.y0".into(), f.y0.to_string())
            .map_err(chunk_err)?;
        let mut wr = enc
            .write_header()
            .map_err(|e| encode_err(format!("PNG header: {e}")))?;
        wr.write_image_data(f.image.data())
            .map_err(|e| encode_err(format!("PNG data: {e}")))?;
        wr.finish()
            .map_err(|e| encode_err(format!("PNG end: {e}")))?;
    }
    Ok(out)
}

fn decode_png(
    bytes: &[u8],
    path: &Path,
    limit: u64,
) -> Result<(ImgFile, Vec<String>), FormatError> {
    let bad = |e: png::DecodingError| {
        let kind = match e {
            png::DecodingError::IoError(_) => K::Truncated,
            png::DecodingError::LimitsExceeded => K::Range,
            _ => K::Syntax,
        };
        FormatError::new(
            path,
            Location::None,
            kind,
            format!("not a readable PNG: {e}"),
        )
    };
    let limits = png::Limits {
        bytes: usize::try_from(limit).unwrap_or(usize::MAX),
    };
    let mut dec = png::Decoder::new_with_limits(Cursor::new(bytes), limits);
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().map_err(bad)?;
    let (w, h) = {
        let info = reader.info();
        (info.width as usize, info.height as usize)
    };
    let Some(size) = reader.output_buffer_size() else {
        return Err(FormatError::new(
            path,
            Location::None,
            K::Range,
            "PNG too large",
        ));
    };
    if size as u64 > limit {
        return Err(FormatError::new(
            path,
            Location::None,
            K::Range,
            format!(
                "PNG of {w} × {h} pixels is larger than this file can hold or than {MAX_DECODED} bytes"
            ),
        ));
    }
    let mut buf = vec![0u8; size];
    let out = reader.next_frame(&mut buf).map_err(bad)?;
    let (ct, _) = reader.output_color_type();
    let mut notes = Vec::new();
    let src = buf.get(..out.buffer_size()).unwrap_or(&buf);
    let grey = to_grey(src, w, h, out.line_size, ct, &mut notes);
    let info = reader.info();
    if info.bit_depth == png::BitDepth::Sixteen {
        notes.push("16-bit PNG reduced to 8 bits".into());
    }
    let mut comment = None;
    let (mut x0, mut y0) = (0u16, 0u16);
    for t in &info.uncompressed_latin1_text {
        match t.keyword.as_str() {
            "vss.comment" if comment.is_none() => comment = Some(t.text.clone()),
            "vss.comment-hex" => comment = unhex(&t.text),
            "vss.x0" => x0 = t.text.trim().parse().unwrap_or(0),
            "vss.y0" => y0 = t.text.trim().parse().unwrap_or(0),
            _ => {}
        }
    }
    let image = GreyImage::new(w, h, grey)
        .map_err(|e| FormatError::new(path, Location::None, K::Syntax, e.to_string()))?;
    Ok((
        ImgFile {
            image,
            comment: comment.unwrap_or_default(),
            x0,
            y0,
        },
        notes,
    ))
}

fn unhex(s: &str) -> Option<String> {
    let b = s.as_bytes();
    if !b.len().is_multiple_of(2) {
        return None;
    }
    b.chunks(2)
        .map(|p| {
            let t = std::str::from_utf8(p).ok()?;
            u8::from_str_radix(t, 16).ok().map(char::from)
        })
        .collect()
}

/// Rec. 709 luma, as the `image` crate computes it, so every format reduces
/// colour the same way.
fn luma(r: u8, g: u8, b: u8) -> u8 {
    let l = 2126 * u32::from(r) + 7152 * u32::from(g) + 722 * u32::from(b);
    ((l + 5000) / 10000).min(255) as u8
}

fn to_grey(
    src: &[u8],
    w: usize,
    h: usize,
    line: usize,
    ct: png::ColorType,
    notes: &mut Vec<String>,
) -> Vec<u8> {
    let ch = match ct {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb | png::ColorType::Indexed => 3,
        png::ColorType::Rgba => 4,
    };
    let mut coloured = false;
    if ch == 2 || ch == 4 {
        notes.push("alpha channel dropped".into());
    }
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let row = src.get(y * line..y * line + w * ch).unwrap_or(&[]);
        for px in row.chunks_exact(ch) {
            out.push(match px {
                [g] | [g, _] => *g,
                [r, g, b] | [r, g, b, _] => {
                    coloured |= r != g || g != b;
                    luma(*r, *g, *b)
                }
                _ => 0,
            });
        }
    }
    if coloured {
        notes.push("colour image converted to grey (Rec. 709 luma)".into());
    }
    out
}

fn decode_foreign(
    bytes: &[u8],
    fmt: image::ImageFormat,
    path: &Path,
    limit: u64,
) -> Result<(ImgFile, Vec<String>), FormatError> {
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(limit);
    limits.max_image_width = Some(65535);
    limits.max_image_height = Some(65535);
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), fmt);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| {
        let kind = match e {
            image::ImageError::Limits(_) => K::Range,
            image::ImageError::Unsupported(_) => K::Unsupported,
            image::ImageError::IoError(_) => K::Truncated,
            _ => K::Syntax,
        };
        FormatError::new(path, Location::None, kind, format!("cannot decode: {e}"))
    })?;
    let mut notes = Vec::new();
    let c = img.color();
    // A palette BMP of greys decodes as RGB: only real colour gets a note.
    if c.has_color() && img.to_rgb8().pixels().any(|p| p[0] != p[1] || p[1] != p[2]) {
        notes.push("colour image converted to grey (Rec. 709 luma)".into());
    }
    if c.has_alpha() {
        notes.push("alpha channel dropped".into());
    }
    if c.bytes_per_pixel() / c.channel_count().max(1) > 1 {
        notes.push("16-bit or float samples reduced to 8 bits".into());
    }
    let l = img.into_luma8();
    let (w, h) = (l.width() as usize, l.height() as usize);
    let image = GreyImage::new(w, h, l.into_raw())
        .map_err(|e| FormatError::new(path, Location::None, K::Syntax, e.to_string()))?;
    Ok((ImgFile::new(image), notes))
}

/// The JPEG's luma from its RGB, by the JPEG's own (BT.601) weights in
/// libjpeg's 16-bit fixed point.
fn jpeg_luma(r: u8, g: u8, b: u8) -> u8 {
    let l = 19_595 * u32::from(r) + 38_470 * u32::from(g) + 7_471 * u32::from(b);
    ((l + 32_768) >> 16).min(255) as u8
}

fn decode_jpeg(
    bytes: &[u8],
    path: &Path,
    limit: u64,
) -> Result<(ImgFile, Vec<String>), FormatError> {
    use image::ImageDecoder;
    use image::metadata::Orientation;
    let bad = |e: image::ImageError| {
        let kind = match e {
            image::ImageError::Limits(_) => K::Range,
            image::ImageError::Unsupported(_) => K::Unsupported,
            image::ImageError::IoError(_) => K::Truncated,
            _ => K::Syntax,
        };
        FormatError::new(
            path,
            Location::None,
            kind,
            format!("not a readable JPEG: {e}"),
        )
    };
    let mut dec = image::codecs::jpeg::JpegDecoder::new(Cursor::new(bytes)).map_err(bad)?;
    // The decoder fills a cut-off scan with grey; a photograph without its
    // end-of-image marker is refused instead of half read. The marker must
    // follow the picture's last scan: a camera's EXIF thumbnail, before
    // that scan, ends with one of its own. (Neither marker can occur inside
    // a scan's coded data, where every 0xFF byte is followed by 0x00 or a
    // restart marker.)
    let marker = |m: u8| bytes.windows(2).rposition(|w| w == [0xFF, m]);
    if marker(0xD9).is_none_or(|eoi| marker(0xDA).is_some_and(|sos| eoi < sos)) {
        return Err(FormatError::new(
            path,
            Location::None,
            K::Truncated,
            "truncated JPEG: the file ends before its end-of-image marker",
        ));
    }
    let (w, h) = dec.dimensions();
    let need = dec.total_bytes();
    if need > limit {
        return Err(FormatError::new(
            path,
            Location::None,
            K::Range,
            format!(
                "JPEG of {w} × {h} pixels ({need} bytes decoded) is larger than this file can hold or than {MAX_DECODED} bytes; refused from its header"
            ),
        ));
    }
    let orientation = dec.orientation().unwrap_or(Orientation::NoTransforms);
    let colour = dec.color_type();
    let mut img = image::DynamicImage::from_decoder(dec).map_err(bad)?;
    let mut notes = Vec::new();
    if orientation != Orientation::NoTransforms {
        img.apply_orientation(orientation);
        notes.push(format!(
            "EXIF orientation applied ({orientation:?}): lines are in the picture as it is shown, {} × {} px",
            img.width(),
            img.height()
        ));
    }
    let (w, h) = (img.width() as usize, img.height() as usize);
    let grey = match img {
        image::DynamicImage::ImageLuma8(l) => l.into_raw(),
        other => {
            let rgb = other.into_rgb8();
            if rgb.pixels().any(|p| p[0] != p[1] || p[1] != p[2]) {
                notes.push("colour JPEG converted to grey (its luma, BT.601)".into());
            }
            rgb.pixels().map(|p| jpeg_luma(p[0], p[1], p[2])).collect()
        }
    };
    if colour.has_alpha() {
        notes.push("alpha channel dropped".into());
    }
    let image = GreyImage::new(w, h, grey)
        .map_err(|e| FormatError::new(path, Location::None, K::Syntax, e.to_string()))?;
    Ok((ImgFile::new(image), notes))
}

fn encode_foreign(f: &ImgFile, fmt: image::ImageFormat) -> Result<Vec<u8>, FormatError> {
    let (w, h) = f.image.size();
    let (Ok(w), Ok(h)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(encode_err("image too large".into()));
    };
    let buf = image::GrayImage::from_raw(w, h, f.image.data().to_vec())
        .ok_or_else(|| encode_err("pixel buffer does not match the size".into()))?;
    let mut out = Cursor::new(Vec::new());
    let res = if fmt == image::ImageFormat::Pnm {
        use image::ImageEncoder;
        use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
        PnmEncoder::new(&mut out)
            .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
            .write_image(buf.as_raw(), w, h, image::ExtendedColorType::L8)
    } else {
        buf.write_to(&mut out, fmt)
    };
    res.map_err(|e| encode_err(format!("cannot encode: {e}")))?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ImgFile {
        let img = GreyImage::new(5, 3, (0..15).map(|v| v * 17).collect()).unwrap();
        ImgFile {
            image: img,
            comment: "cube1a".into(),
            x0: 12,
            y0: 34,
        }
    }

    #[test]
    fn png_keeps_comment_and_corner() {
        let f = sample();
        let b = encode_png(&f).unwrap();
        let (g, notes) = decode_png(&b, Path::new("a.png"), 1 << 20).unwrap();
        assert_eq!(g, f);
        assert!(notes.is_empty());
        let mut f2 = f.clone();
        f2.comment = "x\0y\u{1}\u{ff}".into();
        let b = encode_png(&f2).unwrap();
        assert_eq!(decode_png(&b, Path::new("a.png"), 1 << 20).unwrap().0, f2);
    }

    #[test]
    fn foreign_formats_keep_pixels() {
        let f = sample();
        for (k, fmt) in [
            (ImageKind::Pgm, image::ImageFormat::Pnm),
            (ImageKind::Tiff, image::ImageFormat::Tiff),
            (ImageKind::Bmp, image::ImageFormat::Bmp),
        ] {
            let b = encode_any(&f, k).unwrap();
            let (g, notes) = decode_foreign(&b, fmt, Path::new("x"), 1 << 20).unwrap();
            assert_eq!(g.image, f.image, "{k:?}");
            assert!(notes.is_empty(), "{k:?}: {notes:?}");
        }
    }

    #[test]
    fn colour_png_becomes_grey_with_note() {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, 2, 1);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[255, 0, 0, 10, 10, 10]).unwrap();
        }
        let (g, notes) = decode_png(&out, Path::new("c.png"), 1 << 20).unwrap();
        assert_eq!(g.image.data(), &[54, 10]);
        assert!(notes.iter().any(|n| n.contains("grey")));
    }
}
