//! Edge-point files `.hpo` (horizontal scan) and `.vpo` (vertical scan),
//! which formats.md §6 leaves to us. Layout:
//!
//! ```text
//! VSSEDGE 1 H 512 512 1234\n        one ASCII header line:
//!                                   magic, version, direction H|V|-,
//!                                   width, height, point count
//! count × 12 bytes                  x, y, response: little-endian f32
//! ```
//!
//! Positions are subpixel (pixels, origin at the centre of the top-left
//! pixel), the response is the signed Lee response, so line extraction can be
//! re-run from the file alone. The file size must be exactly header + 12 ×
//! count: the count is checked against the real size before anything is
//! allocated, and every value must be finite. Width and height are at most
//! [`MAX_SIDE`], the largest an `.img` can hold; 0 means "not known".

use std::path::Path;

use super::{FormatError, FormatErrorKind as K, read_bytes, shorten, write_bytes};
use crate::llv::{EdgePoint, EdgePoints, ScanDir};

/// The magic word of the header line.
pub const MAGIC: &str = "VSSEDGE";
/// The format version this code writes and reads.
pub const VERSION: u32 = 1;
/// Longest header line accepted (a real one is under 50 bytes).
const MAX_HEADER: usize = 128;
/// Bytes per point.
pub const POINT_LEN: usize = 12;
/// Largest width or height a header may give: 65535 pixels, the most an
/// `.img` can hold (its size fields are 16-bit, formats.md §2), so every edge
/// file of a cell image fits and no header can promise a larger picture than
/// the grey images it came from.
pub const MAX_SIDE: usize = u16::MAX as usize;

fn dir_letter(d: Option<ScanDir>) -> char {
    match d {
        Some(ScanDir::Horizontal) => 'H',
        Some(ScanDir::Vertical) => 'V',
        None => '-',
    }
}

/// The header line of an edge file, without its newline.
pub fn header_line(e: &EdgePoints) -> String {
    format!(
        "{MAGIC} {VERSION} {} {} {} {}",
        dir_letter(e.dir),
        e.width,
        e.height,
        e.points.len()
    )
}

/// Encodes edge points in the `.hpo`/`.vpo` layout.
pub fn encode_edges(e: &EdgePoints) -> Vec<u8> {
    let head = header_line(e);
    let mut out = Vec::with_capacity(head.len() + 1 + e.points.len() * POINT_LEN);
    out.extend_from_slice(head.as_bytes());
    out.push(b'\n');
    for p in &e.points {
        out.extend_from_slice(&p.x.to_le_bytes());
        out.extend_from_slice(&p.y.to_le_bytes());
        out.extend_from_slice(&p.response.to_le_bytes());
    }
    out
}

/// Decodes an edge file held in memory; `path` names it in errors.
pub fn parse_edges(bytes: &[u8], path: &Path) -> Result<EdgePoints, FormatError> {
    let window = bytes.get(..MAX_HEADER.min(bytes.len())).unwrap_or(bytes);
    let Some(nl) = window.iter().position(|&b| b == b'\n') else {
        let kind = if bytes.len() < MAX_HEADER {
            K::Truncated
        } else {
            K::Syntax
        };
        return Err(FormatError::at_byte(
            path,
            window.len() as u64,
            kind,
            format!(
                "expected a header line \"{MAGIC} {VERSION} H|V width height count\" ending in a newline"
            ),
        ));
    };
    let head = window.get(..nl).unwrap_or(&[]);
    let head = std::str::from_utf8(head).map_err(|e| {
        FormatError::at_byte(
            path,
            e.valid_up_to() as u64,
            K::Encoding,
            "header line is not ASCII text",
        )
    })?;
    let head = head.strip_suffix('\r').unwrap_or(head);
    let toks: Vec<&str> = head.split_whitespace().collect();
    let syntax = |m: String| FormatError::at_byte(path, 0, K::Syntax, m);
    let [magic, version, dir, w, h, count] = toks.as_slice() else {
        return Err(syntax(format!(
            "expected \"{MAGIC} {VERSION} H|V width height count\", found \"{}\"",
            shorten(head)
        )));
    };
    if *magic != MAGIC {
        return Err(syntax(format!(
            "not an edge file: expected \"{MAGIC}\" at the start, found \"{}\"",
            shorten(magic)
        )));
    }
    if *version != "1" {
        return Err(FormatError::at_byte(
            path,
            MAGIC.len() as u64 + 1,
            K::Unsupported,
            format!(
                "edge file version \"{}\" is not supported; this program reads version {VERSION}",
                shorten(version)
            ),
        ));
    }
    let dir = match *dir {
        "H" => Some(ScanDir::Horizontal),
        "V" => Some(ScanDir::Vertical),
        "-" => None,
        d => {
            return Err(syntax(format!(
                "expected direction H, V or -, found \"{}\"",
                shorten(d)
            )));
        }
    };
    let num = |t: &str, what: &str| {
        t.parse::<usize>().map_err(|_| {
            syntax(format!(
                "expected the {what} (a whole number), found \"{}\"",
                shorten(t)
            ))
        })
    };
    let (width, height, count) = (
        num(w, "width")?,
        num(h, "height")?,
        num(count, "point count")?,
    );
    for (what, v) in [("width", width), ("height", height)] {
        if v > MAX_SIDE {
            return Err(FormatError::at_byte(
                path,
                0,
                K::Range,
                format!(
                    "header gives an image {what} of {v} pixels; at most {MAX_SIDE} (the largest .img)"
                ),
            ));
        }
    }
    let body = bytes.get(nl + 1..).unwrap_or(&[]);
    let need = (count as u64).saturating_mul(POINT_LEN as u64);
    if body.len() as u64 != need {
        let kind = if (body.len() as u64) < need {
            K::Truncated
        } else {
            K::SizeMismatch
        };
        return Err(FormatError::at_byte(
            path,
            (nl + 1) as u64,
            kind,
            format!(
                "header promises {count} points ({need} bytes after the header), but {} bytes follow",
                body.len()
            ),
        ));
    }
    let mut points = Vec::with_capacity(count);
    for (k, c) in body.chunks_exact(POINT_LEN).enumerate() {
        let f = |i: usize| {
            c.get(i * 4..i * 4 + 4)
                .and_then(|s| <[u8; 4]>::try_from(s).ok())
                .map_or(f32::NAN, f32::from_le_bytes)
        };
        let p = EdgePoint {
            x: f(0),
            y: f(1),
            response: f(2),
        };
        if !(p.x.is_finite() && p.y.is_finite() && p.response.is_finite()) {
            return Err(FormatError::at_byte(
                path,
                (nl + 1 + k * POINT_LEN) as u64,
                K::Range,
                format!("edge point {} has a non-finite value", k + 1),
            ));
        }
        points.push(p);
    }
    Ok(EdgePoints {
        dir,
        width,
        height,
        points,
    })
}

/// The largest edge file read: a header line and two points for every pixel
/// of the largest image the LLV stages take (a scan finds at most one edge
/// point a pixel per direction; two leave room for hand-made files).
pub fn max_file_len() -> u64 {
    (MAX_HEADER + 2 * POINT_LEN * crate::llv::image::MAX_PIXELS) as u64
}

/// Reads a `.hpo`/`.vpo` file.
pub fn read_edges(path: &Path) -> Result<EdgePoints, FormatError> {
    parse_edges(&read_bytes(path)?, path)
}

/// Reads only the header of an edge file (for `vss info`): direction, size
/// and count, checked against the file size.
pub fn read_edges_header(path: &Path) -> Result<EdgePoints, FormatError> {
    // The points are small; reading them all is simpler than a partial check.
    let mut e = read_edges(path)?;
    e.points = Vec::new();
    Ok(e)
}

/// Writes a `.hpo`/`.vpo` file atomically; non-finite values and a width or
/// height over [`MAX_SIDE`] (which [`read_edges`] would refuse) are refused.
pub fn write_edges(path: &Path, e: &EdgePoints) -> Result<(), FormatError> {
    if e.width > MAX_SIDE || e.height > MAX_SIDE {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!(
                "image of {} x {} pixels is too large for an edge file (at most {MAX_SIDE} a side)",
                e.width, e.height
            ),
        ));
    }
    if let Some(k) = e
        .points
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite() && p.response.is_finite()))
    {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!("edge point {} has a non-finite value", k + 1),
        ));
    }
    write_bytes(path, &encode_edges(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_layout() {
        let e = EdgePoints {
            dir: Some(ScanDir::Vertical),
            width: 64,
            height: 48,
            points: vec![
                EdgePoint {
                    x: 1.25,
                    y: 2.0,
                    response: -17.5,
                },
                EdgePoint {
                    x: 3.0,
                    y: 4.5,
                    response: 9.0,
                },
            ],
        };
        let b = encode_edges(&e);
        assert!(b.starts_with(b"VSSEDGE 1 V 64 48 2\n"));
        assert_eq!(b.len(), 20 + 24);
        assert_eq!(parse_edges(&b, Path::new("a.vpo")).unwrap(), e);
    }

    #[test]
    fn huge_count_refused_before_allocating() {
        let b = b"VSSEDGE 1 H 10 10 18446744073709551615\n\0\0\0\0";
        let e = parse_edges(b, Path::new("a.hpo")).unwrap_err();
        assert_eq!(e.kind, K::Truncated);
    }

    #[test]
    fn image_size_over_the_img_limit_refused_at_the_header() {
        let point = [1.0f32, 1.0, 10.0].map(f32::to_le_bytes).concat();
        let file = |w: &str, h: &str| {
            let mut b = format!("VSSEDGE 1 H {w} {h} 1\n").into_bytes();
            b.extend_from_slice(&point);
            parse_edges(&b, Path::new("cube1.hpo"))
        };
        for (w, h) in [
            ("65536", "10"),
            ("10", "100000"),
            ("1000000000000", "1"),
            ("18446744073709551615", "18446744073709551615"),
        ] {
            let e = file(w, h).unwrap_err();
            assert_eq!(e.kind, K::Range, "{w} x {h}");
            assert_eq!(e.location, crate::formats::Location::Byte(0));
            let text = e.to_string();
            assert!(text.starts_with("cube1.hpo: byte 0: "), "{text}");
            assert!(text.contains("at most 65535"), "{text}");
        }
        let e = file("65535", "0").unwrap();
        assert_eq!((e.width, e.height), (MAX_SIDE, 0));
        assert_eq!(e.points.len(), 1);
    }
}
