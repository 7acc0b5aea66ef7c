//! The grabber's grey image `.img` (and the lens-corrected `.imc`, same
//! layout): ITEX PCplus header of 64 little-endian bytes, the comment with its
//! terminating `\0`, then one byte per pixel, row by row from the top
//! (formats.md §2).
//!
//! The comment's bytes are kept one-to-one as `char`s U+0000–U+00FF
//! (Latin-1), so any comment survives read → write byte for byte; only the
//! final `\0` is stripped. The header is checked against the file's size
//! before any pixel buffer is allocated.

use std::path::Path;

use super::{FormatError, FormatErrorKind as K, input_err, write_bytes};
use crate::llv::GreyImage;

/// Size of the ITEX header.
pub const HEADER_LEN: usize = 64;
/// Largest comment length field, terminating `\0` included.
pub const MAX_COMMENT_LEN: usize = 200;

/// A grey image with the header fields the cell keeps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImgFile {
    pub image: GreyImage,
    /// The image name, without its terminating `\0`; characters are bytes
    /// (U+0000–U+00FF). Show it only through [`super::sanitize`].
    pub comment: String,
    /// Upper-left corner of the picture on the grabber's frame.
    pub x0: u16,
    pub y0: u16,
}

impl ImgFile {
    /// An image with an empty comment at (0, 0).
    pub fn new(image: GreyImage) -> Self {
        ImgFile {
            image,
            comment: String::new(),
            x0: 0,
            y0: 0,
        }
    }

    /// With a comment (usually the file name).
    pub fn with_comment(mut self, comment: impl Into<String>) -> Self {
        self.comment = comment.into();
        self
    }
}

/// The header fields of an `.img`, as `vss info` shows them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImgHeader {
    pub comment_len: u16,
    pub width: u16,
    pub height: u16,
    pub x0: u16,
    pub y0: u16,
    pub file_type: u16,
}

impl ImgHeader {
    /// Where the pixels start.
    pub fn pixel_offset(&self) -> u64 {
        HEADER_LEN as u64 + u64::from(self.comment_len)
    }
    /// The file size this header promises.
    pub fn file_len(&self) -> u64 {
        self.pixel_offset() + u64::from(self.width) * u64::from(self.height)
    }
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
        _ => 0,
    }
}

/// Reads and checks the 64-byte header (magic, comment length, type, size
/// against `file_len`) without touching the pixels.
pub fn parse_header(bytes: &[u8], file_len: u64, path: &Path) -> Result<ImgHeader, FormatError> {
    if bytes.len() < HEADER_LEN {
        return Err(FormatError::at_byte(
            path,
            bytes.len() as u64,
            K::Truncated,
            format!(
                "file ends after {} bytes, inside the {HEADER_LEN}-byte ITEX header",
                bytes.len()
            ),
        ));
    }
    if bytes.get(0..2) != Some(b"IM") {
        return Err(FormatError::at_byte(
            path,
            0,
            K::Syntax,
            "not an ITEX .img: expected the magic \"IM\" at the start",
        ));
    }
    let h = ImgHeader {
        comment_len: u16_at(bytes, 2),
        width: u16_at(bytes, 4),
        height: u16_at(bytes, 6),
        x0: u16_at(bytes, 8),
        y0: u16_at(bytes, 10),
        file_type: u16_at(bytes, 12),
    };
    if usize::from(h.comment_len) > MAX_COMMENT_LEN {
        return Err(FormatError::at_byte(
            path,
            2,
            K::Range,
            format!(
                "comment length {} is over the limit of {MAX_COMMENT_LEN} bytes",
                h.comment_len
            ),
        ));
    }
    match h.file_type {
        0 => {}
        1 => {
            return Err(FormatError::at_byte(
                path,
                12,
                K::Unsupported,
                "compressed .img (file type 1) is not supported; save it uncompressed",
            ));
        }
        t => {
            return Err(FormatError::at_byte(
                path,
                12,
                K::Unsupported,
                format!("unknown file type {t}; expected 0 (normal)"),
            ));
        }
    }
    if h.width == 0 || h.height == 0 {
        return Err(FormatError::at_byte(
            path,
            4,
            K::Range,
            format!("image size {} × {} is empty", h.width, h.height),
        ));
    }
    if file_len != h.file_len() {
        return Err(FormatError::at_byte(
            path,
            4,
            K::SizeMismatch,
            format!(
                "header says {} × {} pixels after a {}-byte comment, which needs {} bytes, \
                 but the file has {file_len}",
                h.width,
                h.height,
                h.comment_len,
                h.file_len()
            ),
        ));
    }
    Ok(h)
}

/// Decodes an `.img` held in memory; `path` names it in errors.
pub fn parse_img(bytes: &[u8], path: &Path) -> Result<ImgFile, FormatError> {
    let h = parse_header(bytes, bytes.len() as u64, path)?;
    // Sizes are checked: every slice below is inside `bytes`.
    let start = HEADER_LEN;
    let px = start + usize::from(h.comment_len);
    let (Some(comment), Some(pixels)) = (bytes.get(start..px), bytes.get(px..)) else {
        return Err(FormatError::at_byte(
            path,
            start as u64,
            K::Truncated,
            "file ends inside the comment",
        ));
    };
    assemble(&h, comment, pixels.to_vec(), path)
}

/// An `.img` from its checked header, its comment bytes and its pixels
/// (which become the image's buffer, not copied).
fn assemble(
    h: &ImgHeader,
    comment: &[u8],
    pixels: Vec<u8>,
    path: &Path,
) -> Result<ImgFile, FormatError> {
    let px = HEADER_LEN + usize::from(h.comment_len);
    let comment = comment.strip_suffix(&[0]).unwrap_or(comment);
    let comment: String = comment.iter().map(|&b| char::from(b)).collect();
    let image = GreyImage::new(usize::from(h.width), usize::from(h.height), pixels)
        .map_err(|e| FormatError::at_byte(path, px as u64, K::SizeMismatch, e.to_string()))?;
    Ok(ImgFile {
        image,
        comment,
        x0: h.x0,
        y0: h.y0,
    })
}

/// The largest `.img` there can be: the header, a 200-byte comment and
/// 65535 × 65535 pixels.
pub fn max_file_len() -> u64 {
    HEADER_LEN as u64 + MAX_COMMENT_LEN as u64 + u64::from(u16::MAX) * u64::from(u16::MAX)
}

/// Opens an `.img` (a regular file, not through a link) and checks its
/// header against its real size; returns the header, the header's bytes and
/// the file positioned after them.
fn open_checked(path: &Path) -> Result<(ImgHeader, Vec<u8>, std::fs::File), FormatError> {
    use std::io::Read;
    let (mut f, len) =
        crate::fsutil::open_input(path, max_file_len()).map_err(|e| input_err(path, &e))?;
    let mut head = Vec::with_capacity(HEADER_LEN);
    (&mut f)
        .take(HEADER_LEN as u64)
        .read_to_end(&mut head)
        .map_err(|e| FormatError::io(path, "read", &e))?;
    let h = parse_header(&head, len, path)?;
    Ok((h, head, f))
}

/// Reads an `.img`/`.imc` file.
pub fn read_img(path: &Path) -> Result<ImgFile, FormatError> {
    read_img_sized(path, |_, _| Ok::<(), std::convert::Infallible>(()))
}

/// Reads an `.img`/`.imc` file whose size `accept(width, height)` takes:
/// the header is checked (against the file's size and by `accept`) before
/// a pixel is read, so a refused image costs 64 bytes, not its size.
pub fn read_img_sized<E: std::fmt::Display>(
    path: &Path,
    accept: impl Fn(usize, usize) -> Result<(), E>,
) -> Result<ImgFile, FormatError> {
    use std::io::Read;
    let (h, mut bytes, mut f) = open_checked(path)?;
    accept(usize::from(h.width), usize::from(h.height))
        .map_err(|m| FormatError::at_byte(path, 4, K::Range, m.to_string()))?;
    // The comment after the header; the pixels into a buffer of their own
    // that becomes the image, so they are in memory once, not twice.
    let comment_len = u64::from(h.comment_len);
    (&mut f)
        .take(comment_len)
        .read_to_end(&mut bytes)
        .map_err(|e| FormatError::io(path, "read", &e))?;
    let Some(comment) = bytes.get(HEADER_LEN..HEADER_LEN + usize::from(h.comment_len)) else {
        // The file shrank after its size was checked.
        return Err(FormatError::at_byte(
            path,
            HEADER_LEN as u64,
            K::Truncated,
            "file ends inside the comment",
        ));
    };
    let rest = h
        .file_len()
        .saturating_sub(HEADER_LEN as u64)
        .saturating_sub(comment_len);
    let mut pixels = Vec::new();
    pixels.reserve_exact(usize::try_from(rest).unwrap_or(0));
    f.take(rest)
        .read_to_end(&mut pixels)
        .map_err(|e| FormatError::io(path, "read", &e))?;
    assemble(&h, comment, pixels, path)
}

/// Reads only the header of an `.img` (for `vss info`).
pub fn read_header(path: &Path) -> Result<ImgHeader, FormatError> {
    open_checked(path).map(|(h, _, _)| h)
}

/// The grey levels of an image's pixels, as `vss info` shows them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GreyStats {
    pub lo: u8,
    pub hi: u8,
    pub mean: f64,
    /// Rows read, of [`GreyStats::rows`].
    pub rows_read: usize,
    pub rows: usize,
}

/// Images of up to this many pixels are read whole by [`read_summary`];
/// larger ones are sampled.
const SUMMARY_ALL_PIXELS: u64 = 16 << 20;
/// Rows a sampled summary reads, spread evenly from the first to the last.
const SUMMARY_ROWS: usize = 1024;

/// The header, the comment and the grey levels of an `.img`, read row by
/// row into one row's buffer: every row of an image of up to 16 Mi
/// pixels, else 1024 rows spread over it. Memory stays at one row (at
/// most 64 KiB) whatever the file's size.
pub fn read_summary(path: &Path) -> Result<(ImgHeader, String, GreyStats), FormatError> {
    use std::os::unix::fs::FileExt;
    let (h, _, f) = open_checked(path)?;
    let read_at = |buf: &mut [u8], at: u64| {
        f.read_exact_at(buf, at)
            .map_err(|e| FormatError::io(path, "read", &e))
    };
    let mut comment = vec![0u8; usize::from(h.comment_len)];
    read_at(&mut comment, HEADER_LEN as u64)?;
    let comment = comment.strip_suffix(&[0]).unwrap_or(&comment);
    let comment: String = comment.iter().map(|&b| char::from(b)).collect();
    let (w, rows) = (usize::from(h.width), usize::from(h.height));
    let all = u64::from(h.width) * u64::from(h.height) <= SUMMARY_ALL_PIXELS;
    let n = if all { rows } else { SUMMARY_ROWS.min(rows) };
    let mut row = vec![0u8; w];
    let (mut lo, mut hi, mut sum) = (u8::MAX, 0u8, 0u64);
    for i in 0..n {
        let y = if all || n < 2 {
            i
        } else {
            i * (rows - 1) / (n - 1)
        };
        read_at(&mut row, h.pixel_offset() + (y as u64) * (w as u64))?;
        for &v in &row {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += u64::from(v);
        }
    }
    let mean = sum as f64 / ((n * w).max(1)) as f64;
    Ok((
        h,
        comment,
        GreyStats {
            lo,
            hi,
            mean,
            rows_read: n,
            rows,
        },
    ))
}

/// Encodes an image as `.img` bytes. Fails (kind `Range`/`Encoding`) when the
/// image is larger than 65535 pixels a side, or the comment is longer than
/// 199 bytes or holds a character above U+00FF.
pub fn encode_img(f: &ImgFile) -> Result<Vec<u8>, FormatError> {
    let none = Path::new("<image>");
    let (w, h) = f.image.size();
    let (Ok(w16), Ok(h16)) = (u16::try_from(w), u16::try_from(h)) else {
        return Err(FormatError::new(
            none,
            super::Location::None,
            K::Range,
            format!("image of {w} × {h} pixels is too large for .img (at most 65535 a side)"),
        ));
    };
    let mut comment = Vec::with_capacity(f.comment.len() + 1);
    for c in f.comment.chars() {
        let b = u8::try_from(u32::from(c)).map_err(|_| {
            FormatError::new(
                none,
                super::Location::None,
                K::Encoding,
                format!(
                    "comment character {c:?} does not fit in one byte (.img comments are 8-bit)"
                ),
            )
        })?;
        comment.push(b);
    }
    comment.push(0);
    if comment.len() > MAX_COMMENT_LEN {
        return Err(FormatError::new(
            none,
            super::Location::None,
            K::Range,
            format!(
                "comment of {} bytes is too long (at most {} plus the terminating \\0)",
                comment.len() - 1,
                MAX_COMMENT_LEN - 1
            ),
        ));
    }
    let mut out = Vec::with_capacity(HEADER_LEN + comment.len() + w * h);
    let mut head = [0u8; HEADER_LEN];
    let fields = [
        u16::from_le_bytes(*b"IM"),
        comment.len() as u16,
        w16,
        h16,
        f.x0,
        f.y0,
        0,
    ];
    for (i, v) in fields.iter().enumerate() {
        head[2 * i..2 * i + 2].copy_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&head);
    out.extend_from_slice(&comment);
    out.extend_from_slice(f.image.data());
    Ok(out)
}

/// Writes an `.img`/`.imc` file atomically.
pub fn write_img(path: &Path, f: &ImgFile) -> Result<(), FormatError> {
    let bytes = encode_img(f).map_err(|e| FormatError {
        path: path.to_path_buf(),
        ..e
    })?;
    write_bytes(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ImgFile {
        let img = GreyImage::new(3, 2, vec![1, 2, 3, 4, 5, 6]).unwrap();
        ImgFile {
            image: img,
            comment: "cube1a".into(),
            x0: 7,
            y0: 9,
        }
    }

    #[test]
    fn layout_matches_spec() {
        let b = encode_img(&sample()).unwrap();
        assert_eq!(&b[0..2], b"IM");
        assert_eq!(u16_at(&b, 2), 7);
        assert_eq!(u16_at(&b, 4), 3);
        assert_eq!(u16_at(&b, 6), 2);
        assert_eq!(u16_at(&b, 8), 7);
        assert_eq!(u16_at(&b, 10), 9);
        assert!(b[12..64].iter().all(|&x| x == 0));
        assert_eq!(&b[64..71], b"cube1a\0");
        assert_eq!(&b[71..], &[1, 2, 3, 4, 5, 6]);
        assert_eq!(parse_img(&b, Path::new("a.img")).unwrap(), sample());
    }

    #[test]
    fn huge_header_in_small_file_is_refused() {
        let mut b = encode_img(&sample()).unwrap();
        b[4..6].copy_from_slice(&60000u16.to_le_bytes());
        b[6..8].copy_from_slice(&60000u16.to_le_bytes());
        b.resize(100, 0);
        let e = parse_img(&b, Path::new("big.img")).unwrap_err();
        assert_eq!(e.kind, K::SizeMismatch);
        assert!(e.to_string().contains("big.img: byte 4"), "{e}");
    }
}
