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

use super::{FormatError, FormatErrorKind as K, shorten, write_bytes};
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

/// An edge file's header line, checked against the file's size.
struct Header {
    dir: Option<ScanDir>,
    width: usize,
    height: usize,
    count: usize,
    /// Where the points start (after the newline).
    body: usize,
}

/// Parses the header line at the start of `window` (the file's first
/// bytes, at most [`MAX_HEADER`] of them) and checks the point count against
/// `file_len`, the file's whole size: nothing is allocated for the points
/// before their bytes are known to be there.
fn parse_header(window: &[u8], file_len: u64, path: &Path) -> Result<Header, FormatError> {
    let window = window.get(..MAX_HEADER.min(window.len())).unwrap_or(window);
    let bytes_len = file_len;
    let Some(nl) = window.iter().position(|&b| b == b'\n') else {
        let kind = if bytes_len < MAX_HEADER as u64 {
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
    let body_len = bytes_len.saturating_sub(nl as u64 + 1);
    let need = (count as u64).saturating_mul(POINT_LEN as u64);
    if body_len != need {
        let kind = if body_len < need {
            K::Truncated
        } else {
            K::SizeMismatch
        };
        return Err(FormatError::at_byte(
            path,
            (nl + 1) as u64,
            kind,
            format!(
                "header promises {count} points ({need} bytes after the header), but {body_len} bytes follow"
            ),
        ));
    }
    Ok(Header {
        dir,
        width,
        height,
        count,
        body: nl + 1,
    })
}

/// Appends the points in `chunk` (whole points; the first is point
/// `first`, 0-based) to `points`; a non-finite value is an error at its
/// byte (`body` is where the points start).
fn decode_points(
    chunk: &[u8],
    first: usize,
    body: usize,
    points: &mut Vec<EdgePoint>,
    path: &Path,
) -> Result<(), FormatError> {
    for (i, c) in chunk.chunks_exact(POINT_LEN).enumerate() {
        let k = first + i;
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
                (body + k * POINT_LEN) as u64,
                K::Range,
                format!("edge point {} has a non-finite value", k + 1),
            ));
        }
        points.push(p);
    }
    Ok(())
}

/// Decodes an edge file held in memory; `path` names it in errors.
pub fn parse_edges(bytes: &[u8], path: &Path) -> Result<EdgePoints, FormatError> {
    let h = parse_header(bytes, bytes.len() as u64, path)?;
    let mut points = Vec::with_capacity(h.count);
    decode_points(
        bytes.get(h.body..).unwrap_or(&[]),
        0,
        h.body,
        &mut points,
        path,
    )?;
    Ok(EdgePoints {
        dir: h.dir,
        width: h.width,
        height: h.height,
        points,
    })
}

/// The most points an edge file holds: 4 Mi, one for every sixteenth
/// pixel of the largest image the LLV stages take (a scan finds at most one
/// edge point a pixel, and edges are a small share of a picture's pixels).
/// `llv --from-edges` of two such files stays within 512 MiB (two of 8 Mi
/// points took 560 MiB, docs/reliability.md); the earlier bound, two points
/// a pixel (1.5 GiB a file), let a 600 MB file cost 2.4 GB.
pub const MAX_POINTS: usize = crate::llv::image::MAX_PIXELS / 16;

/// The largest edge file read: a header line and [`MAX_POINTS`] points.
pub fn max_file_len() -> u64 {
    (MAX_HEADER + POINT_LEN * MAX_POINTS) as u64
}

/// Reads a `.hpo`/`.vpo` file: the header first (checked against the
/// file's size), then the points in chunks straight into their vector, so
/// the file costs its points' memory once, not twice.
pub fn read_edges(path: &Path) -> Result<EdgePoints, FormatError> {
    use std::io::Read;
    let (mut f, len, h, mut rest) = open_header(path)?;
    let mut points = Vec::with_capacity(h.count);
    // Bytes already read past the header, then chunks of whole points.
    let mut buf = std::mem::take(&mut rest);
    let mut chunk = vec![0u8; 4096 * POINT_LEN];
    let mut read = h.body as u64 + buf.len() as u64;
    loop {
        let whole = buf.len() - buf.len() % POINT_LEN;
        decode_points(
            buf.get(..whole).unwrap_or(&[]),
            points.len(),
            h.body,
            &mut points,
            path,
        )?;
        buf.drain(..whole);
        if read >= len {
            break;
        }
        let n = f
            .read(&mut chunk)
            .map_err(|e| FormatError::io(path, "read", &e))?;
        if n == 0 {
            break;
        }
        read += n as u64;
        buf.extend_from_slice(chunk.get(..n).unwrap_or(&[]));
    }
    if points.len() != h.count {
        return Err(FormatError::at_byte(
            path,
            read,
            K::Truncated,
            format!(
                "the file shrank while it was read: {} of {} points",
                points.len(),
                h.count
            ),
        ));
    }
    Ok(EdgePoints {
        dir: h.dir,
        width: h.width,
        height: h.height,
        points,
    })
}

/// Opens an edge file and parses its header against the file's size;
/// returns the file (positioned after what was read), its size, the header
/// and the bytes read past the header line.
fn open_header(path: &Path) -> Result<(std::fs::File, u64, Header, Vec<u8>), FormatError> {
    use std::io::Read;
    let (mut f, len) =
        crate::fsutil::open_input(path, max_file_len()).map_err(|e| super::input_err(path, &e))?;
    let mut window = Vec::with_capacity(MAX_HEADER);
    (&mut f)
        .take(MAX_HEADER as u64)
        .read_to_end(&mut window)
        .map_err(|e| FormatError::io(path, "read", &e))?;
    let h = parse_header(&window, len, path)?;
    let rest = window.get(h.body..).unwrap_or(&[]).to_vec();
    Ok((f, len, h, rest))
}

/// Writes a `.hpo`/`.vpo` file atomically; non-finite values, a width or
/// height over [`MAX_SIDE`] and more than [`MAX_POINTS`] points (which
/// [`read_edges`] would refuse) are refused.
pub fn write_edges(path: &Path, e: &EdgePoints) -> Result<(), FormatError> {
    write_bytes(path, &encode_checked(path, e)?)
}

/// The bytes [`write_edges`] writes, after its checks (`path` names the
/// file in errors).
pub fn encode_checked(path: &Path, e: &EdgePoints) -> Result<Vec<u8>, FormatError> {
    // Nothing is written that the reader would refuse.
    if e.points.len() > MAX_POINTS {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!(
                "{} edge points are more than the {MAX_POINTS} an edge file holds",
                e.points.len()
            ),
        ));
    }
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
    Ok(encode_edges(e))
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

    /// The writer refuses what the reader would (issue 34: edge files hold
    /// at most MAX_POINTS points).
    #[test]
    fn more_points_than_a_file_holds_are_not_written() {
        let p = EdgePoint {
            x: 1.0,
            y: 1.0,
            response: 10.0,
        };
        let mut e = EdgePoints {
            dir: Some(ScanDir::Horizontal),
            width: 8192,
            height: 8192,
            points: vec![p; MAX_POINTS + 1],
        };
        let err = encode_checked(Path::new("x.hpo"), &e).unwrap_err();
        assert_eq!(err.kind, K::Range);
        assert!(err.to_string().contains("more than"), "{err}");
        e.points.truncate(MAX_POINTS);
        let b = encode_checked(Path::new("x.hpo"), &e).unwrap();
        assert!(
            b.len() as u64 <= max_file_len(),
            "the reader would refuse it"
        );
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
