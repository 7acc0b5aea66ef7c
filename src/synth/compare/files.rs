//! The export's text files: truth, segments and times, written by vss and
//! read back (from vss and from other detectors) with errors that name the
//! file and line.

use std::fmt::Write as _;
use std::path::Path;

use super::{content_lines, parse_point};
use crate::formats::{FormatError, FormatErrorKind as K, parse_f64, read_text, write_bytes};
use crate::llv::Segment;

pub fn write_truth(
    path: &Path,
    edges: &[Segment],
    dont_care: &[Segment],
) -> Result<(), FormatError> {
    let mut s = String::from(
        "# vss truth: kind x0 y0 x1 y1 contrast (ideal px, origin at the top-left pixel's centre)\n",
    );
    for (kind, list) in [("edge", edges), ("dontcare", dont_care)] {
        for e in list {
            let _ = writeln!(
                s,
                "{kind} {:.6} {:.6} {:.6} {:.6} {:.3}",
                e.a.x, e.a.y, e.b.x, e.b.y, e.response
            );
        }
    }
    write_bytes(path, s.as_bytes())
}

pub fn write_segments(path: &Path, segs: &[Segment]) -> Result<(), FormatError> {
    let mut s = String::from("# x0 y0 x1 y1 (px, origin at the top-left pixel's centre)\n");
    for e in segs {
        let _ = writeln!(s, "{:.6} {:.6} {:.6} {:.6}", e.a.x, e.a.y, e.b.x, e.b.y);
    }
    write_bytes(path, s.as_bytes())
}

/// A truth file: (true edges, don't-care edges).
pub fn read_truth(path: &Path) -> Result<(Vec<Segment>, Vec<Segment>), FormatError> {
    let text = read_text(path)?;
    let (mut edges, mut dc) = (Vec::new(), Vec::new());
    for (n, line) in content_lines(&text) {
        let toks: Vec<&str> = line.split_whitespace().collect();
        let (kind, rest) = toks.split_first().unwrap_or((&"", &[]));
        let list = match *kind {
            "edge" => &mut edges,
            "dontcare" => &mut dc,
            other => {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!("expected \"edge\" or \"dontcare\", found \"{other}\""),
                ));
            }
        };
        let Some((contrast, coords)) = rest.split_last() else {
            return Err(FormatError::at_line(
                path,
                n,
                K::Syntax,
                "expected x0 y0 x1 y1 contrast",
            ));
        };
        let (a, b) = parse_point(coords, path, n)?;
        let mut s = Segment::new(a, b);
        s.response = parse_f64(contrast, path, n, "a contrast")?;
        list.push(s);
    }
    Ok((edges, dc))
}

/// A detector's segments.
pub fn read_segments(path: &Path) -> Result<Vec<Segment>, FormatError> {
    let text = read_text(path)?;
    content_lines(&text)
        .map(|(n, line)| {
            let toks: Vec<&str> = line.split_whitespace().collect();
            parse_point(&toks, path, n).map(|(a, b)| Segment::new(a, b))
        })
        .collect()
}

/// A detector's `DET.times` in `dir`, if it wrote one: the mean over its
/// images of their fastest and median times (ms).
pub fn mean_times(dir: &Path, det: &str) -> Result<(Option<f64>, Option<f64>), FormatError> {
    let path = dir.join(format!("{det}.times"));
    if !path.exists() {
        return Ok((None, None));
    }
    let t = read_times(&path)?;
    let n = t.len().max(1) as f64;
    Ok((
        Some(t.iter().map(|x| x.0).sum::<f64>() / n),
        Some(t.iter().map(|x| x.1).sum::<f64>() / n),
    ))
}

/// A times file: (fastest ms, median ms) per scene.
pub fn read_times(path: &Path) -> Result<Vec<(f64, f64)>, FormatError> {
    let text = read_text(path)?;
    content_lines(&text)
        .map(|(n, line)| {
            let toks: Vec<&str> = line.split_whitespace().collect();
            match toks.as_slice() {
                [_, f, m, ..] => Ok((
                    parse_f64(f, path, n, "a time (ms)")?,
                    parse_f64(m, path, n, "a time (ms)")?,
                )),
                _ => Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    "expected: scene fastest_ms median_ms [runs]",
                )),
            }
        })
        .collect()
}
