//! Corner closing (llv.md §6). MINIMAL PLACEHOLDER written by helper `llv` so
//! the pipeline compiles; helper `issue6` owns this file and replaces it.
//!
//! Here: an endpoint moves to the intersection of its line with another line
//! when that intersection lies within `radius` of it and of one endpoint of
//! the other line (which moves too).

use super::Segment;
use super::fit::Line;

fn line_of(s: &Segment) -> Option<Line> {
    let len = s.length();
    (len > 0.0).then(|| {
        let (a, b) = (-(s.b.y - s.a.y) / len, (s.b.x - s.a.x) / len);
        Line {
            a,
            b,
            c: -(a * s.a.x + b * s.a.y),
        }
    })
}

/// Closes corners between lines whose endpoints lie within `radius` of the
/// lines' intersection.
#[allow(clippy::ptr_arg)] // the contract: issue6 may add or drop lines
pub fn close_corners(lines: &mut Vec<Segment>, radius: f64) {
    if radius.is_nan() || radius <= 0.0 {
        return;
    }
    let n = lines.len();
    for i in 0..n {
        for j in i + 1..n {
            let (Some(g1), Some(g2)) = (line_of(&lines[i]), line_of(&lines[j])) else {
                continue;
            };
            let Some(x) = g1.intersect(&g2) else { continue };
            let near = |s: &Segment| {
                if s.a.dist(x) <= s.b.dist(x) {
                    (0, s.a.dist(x))
                } else {
                    (1, s.b.dist(x))
                }
            };
            let (e1, d1) = near(&lines[i]);
            let (e2, d2) = near(&lines[j]);
            if d1 <= radius && d2 <= radius {
                for (k, e) in [(i, e1), (j, e2)] {
                    if e == 0 {
                        lines[k].a = x
                    } else {
                        lines[k].b = x
                    }
                }
            }
        }
    }
}
