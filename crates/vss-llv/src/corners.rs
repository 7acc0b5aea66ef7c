//! Corner closing (llv.md §6, "sliding-circle endpoint merge"): line endpoints
//! stop short of the true corner where two edges come closer than the Lee
//! kernel, because there the two edges' responses overlap and the peaks fade.
//! Endpoints of different lines that lie within a radius of each other are
//! moved to the point where their lines meet, when that point is near them.
//!
//! The rule, in order:
//! 1. Only lines at least [`MIN_LENGTH_RADII`] × `radius` long take part.
//!    Endpoints of different lines closer than `radius` to each other are
//!    joined into a cluster (single linkage). A line with both endpoints in
//!    one cluster takes no part in it (moving both of its ends to one point
//!    would erase it).
//! 2. For a cluster of lines that are not all parallel (some pair differs by
//!    at least [`MIN_CORNER_ANGLE_DEG`]), the corner is the point closest, in
//!    weighted least squares, to all of their infinite lines — for two lines
//!    exactly their intersection, for a cube vertex of three edges the best
//!    compromise. Each line weighs what its position near its end is worth:
//!    the inverse variance of a least-squares line's end, `L / (4 r²)` for a
//!    line of length `L` whose points scatter `r` (its `residual`), so that a
//!    short stub inside the corner does not pull a long edge's end off it.
//!    The corner is accepted when it lies within [`MAX_VERTEX_OFFSET`]
//!    of every line of the cluster (their lines really meet there), within
//!    `radius` of every endpoint and is a *corner move* for each: outward
//!    along the line, or inward by at most [`MAX_INWARD_RADII`] × `radius` (a
//!    larger inward move is a crossing or T-junction, not a corner).
//!    Without the first test, two close parallel edges meeting a third (a
//!    plate seen edge-on against an upright) had their ends moved to a point
//!    between them, tilting both (docs/llv.md, "Measurements behind the
//!    design"). An endpoint goes to the corner itself when the corner lies
//!    within [`VERTEX_SIGMAS`] of its own line's end uncertainty (the lines
//!    agree: a cube's vertex fixes each edge's end better than the edge
//!    alone); a line that the corner would move further is sure of its own
//!    position there, and its endpoint goes to the foot of the corner on its
//!    line, so that closing the corner never tilts it.
//! 3. Otherwise the cluster falls back to pairs: every pair of endpoints of
//!    non-parallel lines within `radius`, whose intersection lies within
//!    `radius` of both and is a corner move for both, ordered by the total
//!    distance the two endpoints move (then by index, so the result is
//!    deterministic); each endpoint moves at most once.
//!
//! The radius (5 px) brings endpoints near corners closer to the true corner
//! without pairing lines of neighbouring corners (docs/llv.md, "Measurements
//! behind the design").
//!
//! Nearly parallel lines are left alone: their intersection is far away or
//! ill-defined, and joining colinear pieces is CONNECT's job (§4).
//! Attributes (response, residual, shadow) are kept.

use nalgebra::{Matrix2, Vector2};

use super::{Point, Segment};

/// Two lines whose directions differ by less than this (degrees) are treated
/// as parallel and never form a corner. 15° keeps the intersection within
/// about 4 × the endpoint gap of the endpoints (1/sin 15° ≈ 3.9), so the
/// `radius` test of the intersection is what decides, not rounding.
pub const MIN_CORNER_ANGLE_DEG: f64 = 15.0;

/// Lines shorter than this many radii take no part: over a short line the
/// direction error (noise lines, the stubs at a corner) moves the
/// intersection by more than the gap it would close.
pub const MIN_LENGTH_RADII: f64 = 2.0;

/// Largest inward move of an endpoint, in radii (see `keeps_direction`).
pub const MAX_INWARD_RADII: f64 = 0.25;

/// A cluster's least-squares point is its corner only if it lies within
/// this (px) of every line of the cluster.
pub const MAX_VERTEX_OFFSET: f64 = 1.0;

/// An endpoint moves to its cluster's corner only when the corner lies
/// within this many standard deviations of its line's end position
/// (`2 r / √L` for a line of length `L` whose points scatter `r`);
/// otherwise to the corner's foot on its line.
pub const VERTEX_SIGMAS: f64 = 5.0;

/// Least point scatter (px) assumed of a line: a line with a residual of
/// zero (made from exact points) would otherwise weigh infinitely.
const MIN_RESIDUAL: f64 = 0.05;

/// The standard deviation (px) of a line's distance at its ends, as a
/// least-squares line through about one point a pixel of scatter `r` has
/// it: `2 r / √L` (twice its offset's at the centre).
fn end_sigma(s: &Segment) -> f64 {
    2.0 * s.residual.max(MIN_RESIDUAL) / s.length().sqrt()
}

/// The foot of the perpendicular from `p` on the infinite line of `s`
/// (`p` itself for a zero-length segment).
fn on_line(s: &Segment, p: Point) -> Point {
    match normal_form(s) {
        Some((a, b, c)) => {
            let d = a * p.x + b * p.y + c;
            Point::new(p.x - d * a, p.y - d * b)
        }
        None => p,
    }
}

/// One endpoint: line index and which end (false = `a`, true = `b`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct End {
    line: usize,
    b: bool,
}

fn end_point(lines: &[Segment], e: End) -> Point {
    let s = &lines[e.line];
    if e.b { s.b } else { s.a }
}

/// Unit normal `(a, b)` and offset `c` of the infinite line through a
/// segment (`a x + b y + c = 0`); `None` for a zero-length segment.
fn normal_form(s: &Segment) -> Option<(f64, f64, f64)> {
    let (dx, dy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let len = dx.hypot(dy);
    if len.is_nan() || len <= 0.0 || !len.is_finite() {
        return None;
    }
    let (a, b) = (-dy / len, dx / len);
    Some((a, b, -(a * s.a.x + b * s.a.y)))
}

/// The acute angle between two segments' directions, in degrees (0–90).
fn angle_between_deg(s: &Segment, t: &Segment) -> f64 {
    let (ux, uy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let (vx, vy) = (t.b.x - t.a.x, t.b.y - t.a.y);
    let cross = (ux * vy - uy * vx).abs();
    let dot = (ux * vx + uy * vy).abs();
    cross.atan2(dot).to_degrees()
}

/// The point with the least sum of squared distances to the given lines,
/// each weighed by the inverse variance of its end ([`end_sigma`]); `None`
/// when the lines are (numerically) all parallel. Each line
/// `a x + b y + c = 0` (unit normal) is one row of `N p = -c`; the point
/// solves the normal equations `NᵀWN p = -NᵀWc`. For two lines the weights
/// do not matter: the point is their intersection.
fn least_squares_point(lines: &[Segment], idx: &[usize]) -> Option<Point> {
    let mut ntn = Matrix2::zeros();
    let mut ntc = Vector2::zeros();
    for &i in idx {
        let (a, b, c) = normal_form(&lines[i])?;
        let w = end_sigma(&lines[i]).powi(-2);
        if !w.is_finite() {
            return None;
        }
        let n = Vector2::new(a, b);
        ntn += w * n * n.transpose();
        ntc -= w * n * c;
    }
    let det = ntn.determinant();
    if det.is_nan() || det.abs() <= 1e-12 {
        return None;
    }
    let p = ntn.try_inverse()? * ntc;
    (p.x.is_finite() && p.y.is_finite()).then(|| Point::new(p.x, p.y))
}

/// Whether moving endpoint `e` to `p` is a corner move: outward along the
/// line (the endpoint stopped short of the corner), or inward by at most
/// [`MAX_INWARD_RADII`] × radius (a slight overshoot). A larger inward move
/// means the other line crosses this one well inside it: a crossing or a
/// T-junction, not the corner this endpoint stopped short of.
fn keeps_direction(lines: &[Segment], e: End, p: Point, radius: f64) -> bool {
    let s = &lines[e.line];
    let (fixed, moving) = if e.b { (s.a, s.b) } else { (s.b, s.a) };
    let old = (moving.x - fixed.x, moving.y - fixed.y);
    let len = old.0.hypot(old.1);
    if len <= 0.0 {
        return false;
    }
    // How far the endpoint moves outward along its line (negative: inward).
    let along = ((p.x - moving.x) * old.0 + (p.y - moving.y) * old.1) / len;
    along >= -MAX_INWARD_RADII * radius
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Reusable buffers of [`close_corners_with`], so that a warm pipeline
/// workspace closes corners without touching the heap.
#[derive(Clone, Debug, Default)]
pub struct CornerScratch {
    ends: Vec<End>,
    pts: Vec<Point>,
    /// `(cell, endpoint)` sorted: a cell's endpoints are one contiguous run,
    /// found by binary search, in place of a hash map of cells.
    by_cell: Vec<((i64, i64), usize)>,
    pairs: Vec<(usize, usize)>,
    parent: Vec<usize>,
    /// `(root, endpoint)` sorted: each cluster is one run, in root order.
    clusters: Vec<(usize, usize)>,
    /// `(root, pair)` sorted: each cluster's pairs are one run.
    by_root: Vec<(usize, (usize, usize))>,
    /// The lines as they were before any move: every cluster decides on
    /// these, so the result does not depend on the order of the clusters.
    original: Vec<Segment>,
    kept: Vec<usize>,
    idx: Vec<usize>,
    cands: Vec<(f64, usize, usize, Point)>,
    used: Vec<usize>,
}

/// Moves endpoints of different lines that lie within `radius` (px) of each
/// other to their lines' intersection, when that is within `radius` of each
/// moved endpoint (module doc for the exact rule). `radius ≤ 0` (or NaN) does
/// nothing. Lines are neither added nor removed nor reordered (the `Vec` is
/// the pipeline's contract, leaving room to drop lines a corner swallows).
/// Allocates its buffers afresh; [`close_corners_with`] reuses them.
#[allow(clippy::ptr_arg)]
pub fn close_corners(lines: &mut Vec<Segment>, radius: f64) {
    close_corners_with(lines, radius, &mut CornerScratch::default());
}

/// [`close_corners`] with reusable buffers: once they have grown to the
/// number of lines, it does not allocate.
#[allow(clippy::ptr_arg)]
pub fn close_corners_with(lines: &mut Vec<Segment>, radius: f64, s: &mut CornerScratch) {
    if radius.is_nan() || radius <= 0.0 || lines.len() < 2 {
        return;
    }
    let min_len = MIN_LENGTH_RADII * radius;
    s.ends.clear();
    s.ends.extend(
        (0..lines.len())
            .filter(|&l| lines[l].length() >= min_len)
            .flat_map(|line| [End { line, b: false }, End { line, b: true }])
            .filter(|&e| {
                let p = end_point(lines, e);
                p.x.is_finite() && p.y.is_finite()
            }),
    );
    let ends = &s.ends;
    s.pts.clear();
    s.pts.extend(ends.iter().map(|&e| end_point(lines, e)));
    let pts = &s.pts;

    // Close pairs, found through a grid of cells one radius wide so the cost
    // stays near-linear for the few hundred lines of a real image: the
    // endpoints sorted by cell, each tested against the later ones of its
    // cell and of the cells after it among its neighbours (the next in its
    // column, three in the next), whose runs only move forward. Each pair
    // is found once, as `(k, m)` with `k < m`; their order does not matter
    // (clusters do not depend on it, and the fallback sorts its candidates
    // on a unique key).
    find_pairs(ends, pts, radius, &mut s.by_cell, &mut s.pairs);
    if s.pairs.is_empty() {
        return;
    }

    // Union by smaller index: every cluster's root is its smallest endpoint.
    s.parent.clear();
    s.parent.extend(0..ends.len());
    for &(k, m) in &s.pairs {
        let (rk, rm) = (find(&mut s.parent, k), find(&mut s.parent, m));
        if rk != rm {
            s.parent[rk.max(rm)] = rk.min(rm);
        }
    }
    // The endpoints in a pair by cluster (an endpoint in none is a cluster
    // of one, which the `kept.len() < 2` test below would skip), and the
    // pairs by cluster, both in root order.
    s.clusters.clear();
    s.by_root.clear();
    for &(k, m) in &s.pairs {
        let r = find(&mut s.parent, k);
        s.clusters.extend([(r, k), (r, m)]);
        s.by_root.push((r, (k, m)));
    }
    s.clusters.sort_unstable();
    s.clusters.dedup();
    s.by_root.sort_unstable();

    s.original.clear();
    s.original.extend_from_slice(lines);
    let (mut start, mut pairs_at) = (0, 0);
    while start < s.clusters.len() {
        let root = s.clusters[start].0;
        let len = s.clusters[start..].partition_point(|&(r, _)| r == root);
        let members = &s.clusters[start..start + len];
        start += len;
        let npairs = s.by_root[pairs_at..].partition_point(|&(r, _)| r == root);
        let pairs = &s.by_root[pairs_at..pairs_at + npairs];
        pairs_at += npairs;
        // Drop stubs: lines with both ends in this cluster.
        let stub = |l: usize| members.iter().filter(|&&(_, k)| ends[k].line == l).count() > 1;
        s.kept.clear();
        s.kept.extend(
            members
                .iter()
                .map(|&(_, k)| k)
                .filter(|&k| !stub(ends[k].line)),
        );
        if s.kept.len() < 2 {
            continue;
        }
        if let Some(p) = cluster_corner(&s.original, ends, pts, &s.kept, radius, &mut s.idx) {
            for &k in &s.kept {
                let own = &s.original[ends[k].line];
                let foot = on_line(own, p);
                let agrees = p.dist(foot) <= VERTEX_SIGMAS * end_sigma(own);
                set_end(lines, ends[k], if agrees { p } else { foot });
            }
            continue;
        }
        close_pairs(
            lines,
            &s.original,
            ends,
            pts,
            &s.kept,
            pairs.iter().map(|p| p.1),
            radius,
            &mut s.cands,
            &mut s.used,
        );
    }
}

/// Into `pairs`: each pair `(k, m)`, `k < m`, of endpoints of different
/// lines at most `radius` apart, found through cells one radius wide (see
/// [`close_corners_with`]); `by_cell_buf` is scratch.
fn find_pairs(
    ends: &[End],
    pts: &[Point],
    radius: f64,
    by_cell_buf: &mut Vec<((i64, i64), usize)>,
    pairs: &mut Vec<(usize, usize)>,
) {
    let cell = |p: Point| ((p.x / radius).floor() as i64, (p.y / radius).floor() as i64);
    by_cell_buf.clear();
    by_cell_buf.extend(pts.iter().enumerate().map(|(k, &p)| (cell(p), k)));
    by_cell_buf.sort_unstable();
    let by_cell = &*by_cell_buf;
    pairs.clear();
    let (mut same_end, mut next_lo, mut next_end) = (0, 0, 0);
    for (i, &((cx, cy), k)) in by_cell.iter().enumerate() {
        let upto = |mut at: usize, last: (i64, i64)| {
            while by_cell.get(at).is_some_and(|&(c, _)| c <= last) {
                at += 1;
            }
            at
        };
        same_end = upto(same_end.max(i + 1), (cx, cy.saturating_add(1)));
        let next = match cx.checked_add(1) {
            Some(nx) => {
                let first = (nx, cy.saturating_sub(1));
                while by_cell.get(next_lo).is_some_and(|&(c, _)| c < first) {
                    next_lo += 1;
                }
                next_end = upto(next_end.max(next_lo), (nx, cy.saturating_add(1)));
                &by_cell[next_lo..next_end]
            }
            None => &[],
        };
        for &(_, m) in by_cell[i + 1..same_end].iter().chain(next) {
            let (k, m) = (k.min(m), k.max(m));
            if ends[m].line != ends[k].line && pts[k].dist(pts[m]) <= radius {
                pairs.push((k, m));
            }
        }
    }
}

fn set_end(lines: &mut [Segment], e: End, p: Point) {
    if let Some(s) = lines.get_mut(e.line) {
        if e.b {
            s.b = p;
        } else {
            s.a = p;
        }
    }
}

/// Step 2: one corner for the whole cluster, if it fits every endpoint.
/// `idx` is scratch.
fn cluster_corner(
    lines: &[Segment],
    ends: &[End],
    pts: &[Point],
    kept: &[usize],
    radius: f64,
    idx: &mut Vec<usize>,
) -> Option<Point> {
    idx.clear();
    idx.extend(kept.iter().map(|&k| ends[k].line));
    let spread = idx.iter().enumerate().any(|(n, &i)| {
        idx[n + 1..]
            .iter()
            .any(|&j| angle_between_deg(&lines[i], &lines[j]) >= MIN_CORNER_ANGLE_DEG)
    });
    if !spread {
        return None;
    }
    let p = least_squares_point(lines, idx)?;
    let on_every_line = idx.iter().all(|&i| {
        normal_form(&lines[i])
            .is_some_and(|(a, b, c)| (a * p.x + b * p.y + c).abs() <= MAX_VERTEX_OFFSET)
    });
    (on_every_line
        && kept
            .iter()
            .all(|&k| pts[k].dist(p) <= radius && keeps_direction(lines, ends[k], p, radius)))
    .then_some(p)
}

/// Step 3: pairwise intersections, cheapest first, each endpoint once.
/// `cands` and `used` are scratch.
#[allow(clippy::too_many_arguments)]
fn close_pairs(
    lines: &mut [Segment],
    original: &[Segment],
    ends: &[End],
    pts: &[Point],
    kept: &[usize],
    pairs: impl Iterator<Item = (usize, usize)>,
    radius: f64,
    cands: &mut Vec<(f64, usize, usize, Point)>,
    used: &mut Vec<usize>,
) {
    cands.clear();
    for (k, m) in pairs {
        if !kept.contains(&k) || !kept.contains(&m) {
            continue;
        }
        let (si, sj) = (&original[ends[k].line], &original[ends[m].line]);
        if angle_between_deg(si, sj) < MIN_CORNER_ANGLE_DEG {
            continue;
        }
        let Some(p) = least_squares_point(original, &[ends[k].line, ends[m].line]) else {
            continue;
        };
        let (dk, dm) = (pts[k].dist(p), pts[m].dist(p));
        if dk <= radius
            && dm <= radius
            && keeps_direction(original, ends[k], p, radius)
            && keeps_direction(original, ends[m], p, radius)
        {
            cands.push((dk + dm, k, m, p));
        }
    }
    // Each (k, m) occurs once, so the key is unique and an unstable sort
    // (which, unlike the stable one, needs no buffer) gives the same order.
    cands.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    used.clear();
    for &(_, k, m, p) in cands.iter() {
        if used.contains(&k) || used.contains(&m) {
            continue;
        }
        set_end(lines, ends[k], p);
        set_end(lines, ends[m], p);
        used.extend([k, m]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    fn close(p: Point, x: f64, y: f64) -> bool {
        p.dist(Point::new(x, y)) < 1e-9
    }

    #[test]
    fn l_corner_closes_at_the_intersection() {
        // Two edges of a square meeting at (10, 10), each stopping 2 px short.
        let mut v = vec![seg(10.0, 50.0, 10.0, 12.0), seg(12.0, 10.0, 60.0, 10.0)];
        close_corners(&mut v, 4.0);
        assert!(close(v[0].b, 10.0, 10.0), "{:?}", v[0]);
        assert!(close(v[1].a, 10.0, 10.0), "{:?}", v[1]);
        // The far ends do not move.
        assert!(close(v[0].a, 10.0, 50.0) && close(v[1].b, 60.0, 10.0));
    }

    #[test]
    fn attributes_survive() {
        let mut v = vec![seg(10.0, 50.0, 10.0, 12.0), seg(12.0, 10.0, 60.0, 10.0)];
        v[0].response = -31.5;
        v[0].residual = 0.25;
        v[1].shadow = true;
        close_corners(&mut v, 4.0);
        assert_eq!(
            (v[0].response, v[0].residual, v[1].shadow),
            (-31.5, 0.25, true)
        );
    }

    #[test]
    fn far_or_parallel_or_zero_radius_stay() {
        let orig = vec![seg(10.0, 50.0, 10.0, 12.0), seg(12.0, 10.0, 60.0, 10.0)];
        for r in [0.0, -1.0, f64::NAN, 2.0] {
            let mut v = orig.clone();
            close_corners(&mut v, r);
            assert_eq!(v, orig, "radius {r}");
        }
        // Colinear pieces with a gap: CONNECT's job, not a corner.
        let orig = vec![seg(0.0, 0.0, 20.0, 0.0), seg(22.0, 0.5, 40.0, 0.5)];
        let mut v = orig.clone();
        close_corners(&mut v, 5.0);
        assert_eq!(v, orig);
    }

    #[test]
    fn intersection_too_far_from_the_endpoints_is_refused() {
        // Endpoints 2.2 px apart, but at 20° the lines meet 6.5 px and 5.9 px
        // beyond them: refused with radius 3, accepted with radius 7.
        let t = 20f64.to_radians();
        let a = seg(0.0, 0.0, 30.0, 0.0);
        let b = seg(31.0, 2.0, 31.0 - 40.0 * t.cos(), 2.0 + 40.0 * t.sin());
        let orig = vec![a, b];
        let mut v = orig.clone();
        close_corners(&mut v, 3.0);
        assert_eq!(v, orig);
        close_corners(&mut v, 7.0);
        let x = 31.0 + 2.0 / t.tan();
        assert!(close(v[0].b, x, 0.0) && close(v[1].a, x, 0.0), "{v:?}");
    }

    #[test]
    fn a_line_crossing_well_inside_another_is_no_corner() {
        // b ends 2 px below a, but crosses a's line 4 px inside a's end: a
        // T-junction, not a corner a stopped short of.
        let orig = vec![seg(0.0, 0.0, 30.0, 0.0), seg(26.0, 2.0, 26.0, 40.0)];
        let mut v = orig.clone();
        close_corners(&mut v, 5.0);
        assert_eq!(v, orig);
        // 1 px inside (an overshoot) still closes.
        let mut v = vec![seg(0.0, 0.0, 30.0, 0.0), seg(29.0, 2.0, 29.0, 40.0)];
        close_corners(&mut v, 5.0);
        assert!(
            close(v[0].b, 29.0, 0.0) && close(v[1].a, 29.0, 0.0),
            "{v:?}"
        );
    }

    #[test]
    fn three_edges_of_a_cube_vertex_meet_in_one_point() {
        // Three edges towards (50, 50), from directions 90°, 210°, 330°, each
        // short by ~2 px and slightly off so pairwise intersections differ.
        let mk = |deg: f64, off: f64| {
            let t = deg.to_radians();
            let (c, s) = (t.cos(), -t.sin());
            let n = (-s, c);
            seg(
                50.0 + 40.0 * c + off * n.0,
                50.0 + 40.0 * s + off * n.1,
                50.0 + 2.0 * c + off * n.0,
                50.0 + 2.0 * s + off * n.1,
            )
        };
        let mut v = vec![mk(90.0, 0.2), mk(210.0, -0.1), mk(330.0, 0.0)];
        close_corners(&mut v, 5.0);
        assert!(v[0].b == v[1].b && v[1].b == v[2].b, "{v:?}");
        assert!(v[0].b.dist(Point::new(50.0, 50.0)) < 0.5, "{:?}", v[0].b);
    }

    #[test]
    fn two_close_parallel_edges_meeting_a_third_keep_their_lines() {
        // A plate seen edge-on (two horizontal edges 5 px apart) ending at
        // an upright (a vertical edge at x = 50): one cluster of three
        // ends, whose least-squares point lies between the two parallel
        // lines, 2.5 px from each. Moving their ends there would tilt both
        // lines; each end goes to its own line's intersection with the
        // upright instead.
        let mut v = vec![
            seg(10.0, 40.0, 47.0, 40.0),
            seg(10.0, 45.0, 47.5, 45.0),
            seg(50.0, 41.5, 50.0, 90.0),
        ];
        close_corners(&mut v, 5.0);
        for (s, y) in [(&v[0], 40.0), (&v[1], 45.0)] {
            assert!(
                (s.a.y - y).abs() < 1e-9 && (s.b.y - y).abs() < 1e-9,
                "the edge at y = {y} tilted: {s:?}"
            );
        }
        assert!(close(v[0].b, 50.0, 40.0), "{:?}", v[0]);
    }

    #[test]
    fn a_short_line_in_a_corner_does_not_pull_a_long_edge_off_its_line() {
        // From a yard scene at noise σ 10: a long edge and a shorter one
        // meet at a corner, and a 20 px line 7° off the long edge (the start
        // of a bevel's inner edge) ends there too. The unweighted
        // least-squares point of the three lay 0.54 px off the long edge,
        // and moving its end there tilted all 290 px of it.
        let with_residual = |mut s: Segment, r: f64| {
            s.residual = r;
            s
        };
        let long = with_residual(seg(60.9, 183.6, 204.0, 436.1), 0.5);
        let other = with_residual(seg(61.3, 182.2, 141.7, 136.6), 0.5);
        let stub = with_residual(seg(62.0, 186.8, 73.6, 202.5), 0.7);
        let mut v = vec![long, other, stub];
        close_corners(&mut v, 5.0);
        let (a, b, c) = normal_form(&long).unwrap();
        let off = |p: Point| (a * p.x + b * p.y + c).abs();
        assert!(
            off(v[0].a) < 1e-9 && off(v[0].b) < 1e-9,
            "the long edge tilted: its end is {:.3} px off its line",
            off(v[0].a)
        );
        let corner = least_squares_point(&[long, other], &[0, 1]).unwrap();
        assert!(
            v[0].a.dist(corner) < 0.2 && v[0].a != long.a,
            "the corner was not closed: {:?}",
            v[0].a
        );
        assert!(v[0].b == long.b, "the far end moved: {:?}", v[0].b);
    }

    #[test]
    fn a_stub_inside_the_corner_is_left_alone() {
        let stub = seg(11.0, 11.0, 12.0, 12.0);
        let mut v = vec![
            seg(10.0, 50.0, 10.0, 12.0),
            seg(12.0, 10.0, 60.0, 10.0),
            stub,
        ];
        close_corners(&mut v, 4.0);
        assert_eq!(v[2], stub);
        assert!(close(v[0].b, 10.0, 10.0) && close(v[1].a, 10.0, 10.0));
    }

    #[test]
    fn does_not_depend_on_line_order() {
        let v = vec![
            seg(10.0, 50.0, 10.0, 12.0),
            seg(12.0, 10.0, 60.0, 10.0),
            seg(62.0, 12.0, 62.0, 50.0),
            seg(60.0, 52.0, 12.0, 52.5),
        ];
        let mut fwd = v.clone();
        close_corners(&mut fwd, 4.0);
        let mut rev: Vec<Segment> = v.iter().rev().copied().collect();
        close_corners(&mut rev, 4.0);
        rev.reverse();
        for (x, y) in fwd.iter().zip(&rev) {
            assert!(x.a.dist(y.a) < 1e-9 && x.b.dist(y.b) < 1e-9, "{x:?} {y:?}");
        }
        // Every corner of the quadrilateral closed.
        assert!(fwd[1].b.dist(fwd[2].a) < 1e-9);
        assert!(fwd[2].b.dist(fwd[3].a) < 1e-9);
        assert!(fwd[3].b.dist(fwd[0].a) < 1e-9);
    }

    #[test]
    fn the_cell_sweep_finds_every_close_pair() {
        let mut rng = crate::rng::SplitMix64::new(7);
        let (mut by_cell, mut pairs) = (Vec::new(), Vec::new());
        let mut found = 0;
        for round in 0..30 {
            let radius = [5.0, 3.0, 0.7][round % 3];
            // Endpoints crowded into a small square (many per cell, cells
            // on both sides of 0) and a few spread far.
            let n = 40 + round * 7;
            let pts: Vec<Point> = (0..n)
                .map(|k| {
                    let span = if k % 9 == 0 { 1.0e4 } else { 20.0 };
                    Point::new(rng.range(-span, span), rng.range(-span, span))
                })
                .collect();
            let ends: Vec<End> = (0..n)
                .map(|k| End {
                    line: k / 2,
                    b: k % 2 == 1,
                })
                .collect();
            find_pairs(&ends, &pts, radius, &mut by_cell, &mut pairs);
            pairs.sort_unstable();
            let mut want = Vec::new();
            for k in 0..n {
                for m in k + 1..n {
                    if ends[k].line != ends[m].line && pts[k].dist(pts[m]) <= radius {
                        want.push((k, m));
                    }
                }
            }
            assert_eq!(pairs, want, "round {round}");
            found += want.len();
        }
        assert!(found > 1000, "{found} pairs");
    }
}
