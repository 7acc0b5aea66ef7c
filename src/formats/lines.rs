//! Line files `.lex` (as extracted) and `.ldr` (after CONNECT and edits),
//! the D3D line format of formats.md §5: vertices `index x y`, a line
//! `Faces:`, then one `start end` line per segment.
//!
//! The writer gives segment k the vertices 2k-1 and 2k and prints
//! coordinates with `%.6f`. The reader also takes CRLF, blank lines, a `.`
//! after an index (as the original documentation printed it), vertices in
//! any order and shared vertices; it refuses everything else with the line
//! and what was expected. Only the endpoints travel: response, residual and
//! the shadow flag read back as 0 / false.

use std::collections::HashMap;
use std::path::Path;

use super::{
    FormatError, FormatErrorKind as K, numbered_lines, parse_f64, read_text, shorten, write_bytes,
};
use crate::llv::{Point, Segment};

fn parse_index(tok: &str, path: &Path, n: usize, what: &str) -> Result<usize, FormatError> {
    let t = tok.strip_suffix('.').unwrap_or(tok);
    match t.parse::<usize>() {
        Ok(0) => Err(FormatError::at_line(
            path,
            n,
            K::Range,
            format!("{what} 0: vertex indices start at 1"),
        )),
        Ok(i) => Ok(i),
        Err(_) => Err(FormatError::at_line(
            path,
            n,
            K::Syntax,
            format!(
                "expected {what} (a positive whole number), found \"{}\"",
                shorten(tok)
            ),
        )),
    }
}

fn is_faces(line: &str) -> bool {
    line.eq_ignore_ascii_case("faces:")
}

/// Parses `.lex`/`.ldr` text; `path` names the file in errors.
pub fn parse_lines(text: &str, path: &Path) -> Result<Vec<Segment>, FormatError> {
    let mut vertices: HashMap<usize, (Point, usize)> = HashMap::new();
    let mut in_faces = false;
    let mut segs = Vec::new();
    let mut last_line = 0;
    for (n, line) in numbered_lines(text) {
        last_line = n;
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if !in_faces {
            if is_faces(t) {
                in_faces = true;
                continue;
            }
            let toks: Vec<&str> = t.split_whitespace().collect();
            let [i, x, y] = toks.as_slice() else {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!(
                        "expected a vertex \"index x y\" or \"Faces:\", found \"{}\"",
                        shorten(t)
                    ),
                ));
            };
            let i = parse_index(i, path, n, "a vertex index")?;
            let x = parse_f64(x, path, n, "the vertex x")?;
            let y = parse_f64(y, path, n, "the vertex y")?;
            if let Some((_, first)) = vertices.insert(i, (Point::new(x, y), n)) {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!("vertex {i} defined twice (first at line {first})"),
                ));
            }
        } else {
            let toks: Vec<&str> = t.split_whitespace().collect();
            let [a, b] = toks.as_slice() else {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!("expected \"start end\", found \"{}\"", shorten(t)),
                ));
            };
            let ia = parse_index(a, path, n, "a start vertex index")?;
            let ib = parse_index(b, path, n, "an end vertex index")?;
            let mut ends = [Point::default(); 2];
            for (end, i) in ends.iter_mut().zip([ia, ib]) {
                let Some((p, _)) = vertices.get(&i) else {
                    return Err(FormatError::at_line(
                        path,
                        n,
                        K::Range,
                        format!(
                            "vertex {i} is not defined ({} vertices before Faces:)",
                            vertices.len()
                        ),
                    ));
                };
                *end = *p;
            }
            segs.push(Segment::new(ends[0], ends[1]));
        }
    }
    if !in_faces {
        return Err(FormatError::at_line(
            path,
            last_line.max(1),
            K::Missing,
            "no \"Faces:\" line: expected the vertices, then \"Faces:\", then \"start end\" lines",
        ));
    }
    Ok(segs)
}

/// The `.lex`/`.ldr` text of a line set, exactly as formats.md §5 lays it
/// out (`%d %.6f %.6f`, `Faces:`, segment k uses vertices 2k-1 and 2k).
pub fn format_lines(segs: &[Segment]) -> String {
    let mut s = String::with_capacity(segs.len() * 64 + 8);
    for (k, seg) in segs.iter().enumerate() {
        let i = 2 * k + 1;
        s.push_str(&format!("{} {:.6} {:.6}\n", i, seg.a.x, seg.a.y));
        s.push_str(&format!("{} {:.6} {:.6}\n", i + 1, seg.b.x, seg.b.y));
    }
    s.push_str("Faces:\n");
    for k in 0..segs.len() {
        s.push_str(&format!("{} {}\n", 2 * k + 1, 2 * k + 2));
    }
    s
}

/// Reads a `.lex`/`.ldr` file.
pub fn read_lines(path: &Path) -> Result<Vec<Segment>, FormatError> {
    parse_lines(&read_text(path)?, path)
}

/// Writes a `.lex`/`.ldr` file atomically; non-finite coordinates are
/// refused (kind `Range`) and nothing is written.
pub fn write_lines(path: &Path, segs: &[Segment]) -> Result<(), FormatError> {
    write_bytes(path, encode_checked(path, segs)?.as_bytes())
}

/// The text [`write_lines`] writes, after its check (`path` names the file
/// in errors).
pub fn encode_checked(path: &Path, segs: &[Segment]) -> Result<String, FormatError> {
    if let Some(k) = segs
        .iter()
        .position(|s| ![s.a.x, s.a.y, s.b.x, s.b.y].iter().all(|v| v.is_finite()))
    {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!("segment {} has a non-finite coordinate", k + 1),
        ));
    }
    Ok(format_lines(segs))
}

/// The bounding box `(min, max)` of the endpoints, `None` for no segments.
pub fn bounding_box(segs: &[Segment]) -> Option<(Point, Point)> {
    let mut it = segs.iter().flat_map(|s| [s.a, s.b]);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| {
        (
            Point::new(lo.x.min(p.x), lo.y.min(p.y)),
            Point::new(hi.x.max(p.x), hi.y.max(p.y)),
        )
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "1 50.000000 100.000000\n2 100.000000 100.000000\n\
3 100.000000 100.000000\n4 100.000000 150.000000\nFaces:\n1 2\n3 4\n";

    #[test]
    fn spec_example_round_trips_exactly() {
        let s = parse_lines(SPEC, Path::new("test1.ldr")).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[1].b, Point::new(100.0, 150.0));
        assert_eq!(format_lines(&s), SPEC);
    }

    #[test]
    fn lenient_reader() {
        let t = "\r\n2. 1.5 2\r\n1. 0 0\r\n\r\nfaces:\r\n1. 2.\r\n2 1\r\n\r\n";
        let s = parse_lines(t, Path::new("x.lex")).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].b, Point::new(1.5, 2.0));
        assert_eq!(s[1].a, Point::new(1.5, 2.0));
    }

    #[test]
    fn strict_about_the_rest() {
        let e = parse_lines("1 0 0\n2 1 1\nFaces:\n3 x\n", Path::new("cube1.ldr")).unwrap_err();
        assert_eq!(e.location, super::super::Location::Line(4));
        let e = parse_lines("1 0 0\n2 1 1\nFaces:\n1 3\n", Path::new("c.ldr")).unwrap_err();
        assert_eq!(e.kind, K::Range);
        let e = parse_lines("1 0 0\n2 1 1\n", Path::new("c.ldr")).unwrap_err();
        assert_eq!(e.kind, K::Missing);
        let e = parse_lines("1 NaN 0\nFaces:\n", Path::new("c.ldr")).unwrap_err();
        assert_eq!(e.kind, K::Range);
    }
}
