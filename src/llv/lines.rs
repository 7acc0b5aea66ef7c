//! The line extractor (llv.md §3): follows edge points from scan line to
//! scan line, predicting the next point from the least-squares line of the
//! points found so far, and keeps the segments that are long enough and not
//! too close to the scan direction.
//!
//! The extractor works in *scan coordinates* `(u, v)`: `u` runs along the
//! scan, `v` counts scan lines. For `EdgeH` that is `(x, y)`; for `EdgeV` it
//! is `(y, x)` — "swap x and y" of §3. A line is tracked towards increasing
//! `v` (down the image for `EdgeH`, to the right for `EdgeV`).
//!
//! Settled details:
//! - points are visited in lexical order of the scan frame (scan line by scan
//!   line, then along the scan); a visited start point is marked used;
//! - templates (§3.1) are correlated with all edge points, used or not; the
//!   first template with the largest score wins, in the order
//!   `-π/2, -π/4, -3π/4, 0`. The `0` template (a line along the scan) cannot
//!   be followed across scan lines: such a start is tracked as if
//!   perpendicular and the min-scan-angle test drops it if it really runs
//!   along the scan;
//! - the prediction's slope `du/dv` is clamped to ±8 (7° from the scan);
//! - the search window is `±search_width` around the prediction on each of
//!   the next `max_gap` scan lines (`for i in 1..=max_gap` of §3, so at most
//!   `max_gap - 1` empty scan lines are bridged), nearest unused point first (ties: smaller
//!   `u`);
//! - the segment runs from the projection of its first point to that of its
//!   last; `response` is the mean signed response of its points, `residual`
//!   their RMS distance from the line.

use super::fit::LineFit;
use super::params::LineParams;
use super::{EdgePoints, Point, ScanDir, Segment};

/// Largest `|du/dv|` used for the prediction.
const MAX_SLOPE: f64 = 8.0;

/// Templates of §3.1, `[template][j + 2][i + 2]` (rows down, columns right),
/// in the order φ = 0, -π/4, -π/2, -3π/4.
const TEMPLATES: [[[u8; 5]; 5]; 4] = [
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 1, 1],
        [0, 0, 0, 2, 2],
        [0, 0, 0, 1, 1],
        [0, 0, 0, 0, 0],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 0, 1, 0, 0],
        [0, 0, 1, 2, 1],
        [0, 0, 0, 1, 2],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 1, 2, 1, 0],
        [0, 1, 2, 1, 0],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0],
        [1, 2, 1, 0, 0],
        [2, 1, 0, 0, 0],
    ],
];

/// Initial slope `du/dv` of each template.
const TEMPLATE_SLOPE: [f64; 4] = [0.0, 1.0, 0.0, -1.0];

/// Order in which tied templates are preferred.
const TEMPLATE_PREFERENCE: [usize; 4] = [2, 1, 3, 0];

/// One edge point in scan coordinates.
#[derive(Clone, Copy, Debug, Default)]
struct ScanPoint {
    u: f32,
    v: f32,
    response: f32,
}

/// Reusable buffers of the extractor.
#[derive(Clone, Debug, Default)]
pub struct LineScratch {
    points: Vec<ScanPoint>,
    /// `row_start[r]..row_start[r + 1]` are the points of scan line `r`.
    row_start: Vec<u32>,
    used: Vec<bool>,
    members: Vec<u32>,
}

/// Segments of one edge-point set (llv.md §3).
pub fn extract(e: &EdgePoints, p: &LineParams) -> Vec<Segment> {
    let mut out = Vec::new();
    extract_into(e, p, &mut out, &mut LineScratch::default());
    out
}

/// Which template fits the neighbourhood of point `si` best (§3.1).
fn template_of(s: &LineScratch, si: usize, nrows: usize) -> usize {
    let sp = s.points[si];
    let iu = sp.u.round() as i64;
    let row = sp.v.round() as i64;
    let mut score = [0u32; 4];
    for j in -2i64..=2 {
        let r = row + j;
        if r < 0 || r as usize >= nrows {
            continue;
        }
        let (lo, hi) = (s.row_start[r as usize], s.row_start[r as usize + 1]);
        for q in &s.points[lo as usize..hi as usize] {
            let i = q.u.round() as i64 - iu;
            if !(-2..=2).contains(&i) {
                continue;
            }
            for (t, sc) in score.iter_mut().enumerate() {
                *sc += u32::from(TEMPLATES[t][(j + 2) as usize][(i + 2) as usize]);
            }
        }
    }
    let mut best = TEMPLATE_PREFERENCE[0];
    for &t in &TEMPLATE_PREFERENCE[1..] {
        if score[t] > score[best] {
            best = t;
        }
    }
    best
}

/// Whether an unused point lies where any initial prediction (slope -1, 0
/// or 1) could find it on the next `max_gap` scan lines.
fn has_successor(s: &LineScratch, sp: &ScanPoint, nrows: usize, p: &LineParams) -> bool {
    let row = sp.v.round() as usize;
    (1..=p.max_gap as usize).any(|i| {
        let r = row + i;
        if r >= nrows {
            return false;
        }
        let reach = i as f64 + p.search_width;
        let (lo, hi) = (s.row_start[r] as usize, s.row_start[r + 1] as usize);
        let pts = &s.points[lo..hi];
        let first = pts.partition_point(|q| (q.u as f64) < sp.u as f64 - reach);
        pts[first..]
            .iter()
            .enumerate()
            .take_while(|(_, q)| q.u as f64 <= sp.u as f64 + reach)
            .any(|(k, _)| !s.used[lo + first + k])
    })
}

/// [`extract`] into reusable buffers; appends nothing else to `out` (it is
/// cleared first).
pub fn extract_into(e: &EdgePoints, p: &LineParams, out: &mut Vec<Segment>, s: &mut LineScratch) {
    out.clear();
    let vertical = e.dir == Some(ScanDir::Vertical);
    // Scan lines: counting sort by scan line keeps the order along the scan
    // of the lexically ordered input (and sorts EdgeV column by column).
    let row_of = |u: f32, v: f32| -> Option<usize> {
        let r = v.round();
        (u.is_finite() && v.is_finite() && (0.0..1.0e7).contains(&r)).then_some(r as usize)
    };
    let to_scan = |x: f32, y: f32| if vertical { (y, x) } else { (x, y) };
    let nrows = e
        .points
        .iter()
        .filter_map(|q| {
            let (u, v) = to_scan(q.x, q.y);
            row_of(u, v)
        })
        .max()
        .map_or(0, |r| r + 1);
    s.row_start.clear();
    s.row_start.resize(nrows + 2, 0);
    for q in &e.points {
        let (u, v) = to_scan(q.x, q.y);
        if let Some(r) = row_of(u, v) {
            s.row_start[r + 2] += 1;
        }
    }
    for r in 2..nrows + 2 {
        s.row_start[r] += s.row_start[r - 1];
    }
    let total = s.row_start[nrows + 1] as usize;
    s.points.clear();
    s.points.resize(total, ScanPoint::default());
    for q in &e.points {
        let (u, v) = to_scan(q.x, q.y);
        if let Some(r) = row_of(u, v) {
            let slot = &mut s.row_start[r + 1];
            s.points[*slot as usize] = ScanPoint {
                u,
                v,
                response: q.response,
            };
            *slot += 1;
        }
    }
    s.row_start.truncate(nrows + 1);
    // Within a scan line, order by u (the input may come from a file).
    for r in 0..nrows {
        let (lo, hi) = (s.row_start[r] as usize, s.row_start[r + 1] as usize);
        let row = &mut s.points[lo..hi];
        if !row.windows(2).all(|w| w[0].u <= w[1].u) {
            row.sort_unstable_by(|a, b| a.u.total_cmp(&b.u));
        }
    }
    s.used.clear();
    s.used.resize(total, false);

    let sw = p.search_width;
    let min_angle = p.min_scan_angle_deg.to_radians();
    for start in 0..total {
        if s.used[start] {
            continue;
        }
        s.used[start] = true;
        let sp = s.points[start];
        if !has_successor(s, &sp, nrows, p) {
            // No unused point within reach of any template's prediction: no
            // line can start here (the same result, without the templates).
            continue;
        }
        let mut slope = TEMPLATE_SLOPE[template_of(s, start, nrows)];
        let mut fit = LineFit::new();
        fit.add(Point::new(sp.u as f64, sp.v as f64));
        let mut resp_sum = sp.response as f64;
        let mut last = sp;
        s.members.clear();
        s.members.push(start as u32);
        loop {
            let row_e = last.v.round() as usize;
            let mut found = None;
            for i in 1..=p.max_gap as usize {
                let r = row_e + i;
                if r >= nrows {
                    break;
                }
                let pred = last.u as f64 + i as f64 * slope;
                let (lo, hi) = (s.row_start[r] as usize, s.row_start[r + 1] as usize);
                let row = &s.points[lo..hi];
                let first = row.partition_point(|q| (q.u as f64) < pred - sw);
                let mut best: Option<(f64, usize)> = None;
                for (k, q) in row[first..].iter().enumerate() {
                    let d = q.u as f64 - pred;
                    if d > sw {
                        break;
                    }
                    let idx = lo + first + k;
                    if s.used[idx] {
                        continue;
                    }
                    if best.is_none_or(|(bd, _)| d.abs() < bd) {
                        best = Some((d.abs(), idx));
                    }
                }
                if let Some((_, idx)) = best {
                    found = Some(idx);
                    break;
                }
            }
            let Some(idx) = found else { break };
            s.used[idx] = true;
            s.members.push(idx as u32);
            let q = s.points[idx];
            fit.add(Point::new(q.u as f64, q.v as f64));
            resp_sum += q.response as f64;
            last = q;
            if let Some((du, dv)) = fit.major_axis() {
                slope = if dv.abs() * MAX_SLOPE > du.abs() {
                    du / dv
                } else {
                    MAX_SLOPE * du.signum() * dv.signum()
                };
            }
        }
        let Some(line) = fit.line() else { continue };
        let a = line.project(Point::new(sp.u as f64, sp.v as f64));
        let b = line.project(Point::new(last.u as f64, last.v as f64));
        if a.dist(b) <= p.min_length {
            continue;
        }
        // Angle between the line and the scan direction (u axis).
        let scan_angle = line.a.abs().atan2(line.b.abs());
        if scan_angle <= min_angle {
            continue;
        }
        let swap = |q: Point| if vertical { Point::new(q.y, q.x) } else { q };
        out.push(Segment {
            a: swap(a),
            b: swap(b),
            response: resp_sum / fit.len() as f64,
            residual: fit.rms_residual(),
            shadow: false,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::EdgePoint;

    fn points(dir: ScanDir, pts: &[(f32, f32)]) -> EdgePoints {
        let mut v: Vec<EdgePoint> = pts
            .iter()
            .map(|&(x, y)| EdgePoint {
                x,
                y,
                response: 10.0,
            })
            .collect();
        v.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
        EdgePoints {
            dir: Some(dir),
            width: 200,
            height: 200,
            points: v,
        }
    }

    #[test]
    fn templates_give_the_initial_direction_in_eight_directions() {
        // Lines through the start s = (50, 50) continue below it (scan frame),
        // so 8 image directions fold into the 4 templates per scan direction.
        let cases: [(f64, f64, usize); 4] =
            [(1.0, 0.0, 0), (1.0, 1.0, 1), (0.0, 1.0, 2), (-1.0, 1.0, 3)];
        for &(du, dv, want) in &cases {
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let mut pts = Vec::new();
                for k in 0..3 {
                    let (u, v) = (50.0 + k as f64 * du, 50.0 + k as f64 * dv);
                    let (x, y) = if dir == ScanDir::Vertical {
                        (v, u)
                    } else {
                        (u, v)
                    };
                    pts.push((x as f32, y as f32));
                }
                let e = points(dir, &pts);
                let mut s = LineScratch::default();
                extract_into(&e, &LineParams::default(), &mut Vec::new(), &mut s);
                let start = s
                    .points
                    .iter()
                    .position(|q| q.u == 50.0 && q.v == 50.0)
                    .unwrap();
                let nrows = s.row_start.len() - 1;
                assert_eq!(template_of(&s, start, nrows), want, "{dir:?} ({du},{dv})");
            }
        }
    }

    #[test]
    fn a_drawn_line_is_extracted_in_every_steep_direction() {
        // Ideal points of lines at many angles, one per scan line.
        for deg in (-85..=85).step_by(5) {
            let ang = (deg as f64).to_radians();
            // Angle from the vertical for EdgeH: x = x0 + tan(ang) * y.
            if ang.abs() > 1.1 {
                continue;
            }
            let slope = ang.tan();
            let pts: Vec<(f32, f32)> = (20..120)
                .map(|y| ((100.0 + slope * (y as f64 - 20.0) + 0.3) as f32, y as f32))
                .collect();
            let e = points(ScanDir::Horizontal, &pts);
            let segs = extract(&e, &LineParams::default());
            assert_eq!(segs.len(), 1, "{deg}°: {segs:?}");
            let s = segs[0];
            assert!((s.a.y - 20.0).abs() < 1e-3 && (s.b.y - 119.0).abs() < 1e-3);
            assert!(s.residual < 1e-3);
            assert!((s.response - 10.0).abs() < 1e-9);
            // The same line scanned vertically, with x and y swapped.
            let pts: Vec<(f32, f32)> = pts.iter().map(|&(x, y)| (y, x)).collect();
            let e = points(ScanDir::Vertical, &pts);
            let segs = extract(&e, &LineParams::default());
            assert_eq!(segs.len(), 1, "V {deg}°");
            assert!((segs[0].a.x - 20.0).abs() < 1e-3);
        }
    }

    #[test]
    fn gaps_short_lines_and_scan_parallel_lines() {
        // max_gap = 3: the next point may be up to 3 rows below (2 empty
        // rows bridged), not 4.
        let mut pts: Vec<(f32, f32)> = (0..20).map(|y| (50.0, y as f32)).collect();
        pts.extend((22..40).map(|y| (50.0, y as f32)));
        pts.extend((43..60).map(|y| (50.0, y as f32)));
        let segs = extract(&points(ScanDir::Horizontal, &pts), &LineParams::default());
        assert_eq!(segs.len(), 2, "{segs:?}");
        // Too short: 8 px is not > min_length.
        let pts: Vec<(f32, f32)> = (0..9).map(|y| (50.0, y as f32)).collect();
        assert!(extract(&points(ScanDir::Horizontal, &pts), &LineParams::default()).is_empty());
        // 20° from the scan direction: one point every ~2.7 px along x.
        let pts: Vec<(f32, f32)> = (0..30).map(|y| (10.0 + y as f32 * 2.7, y as f32)).collect();
        let p = LineParams {
            search_width: 3.0,
            ..LineParams::default()
        };
        assert!(extract(&points(ScanDir::Horizontal, &pts), &p).is_empty());
        assert!(extract(&EdgePoints::default(), &p).is_empty());
    }
}
