//! CONNECT, the automatic post-processing of extracted lines (llv.md §4):
//! merges segments whose environments (oriented rectangles around them)
//! intersect and whose directions agree, until nothing merges any more, then
//! drops short segments: those under `min_line_length`, unless their points
//! fix their direction within `short_line_deg` (`long_enough`).
//!
//! Order (so the result does not depend on the input order): segments are
//! sorted by length, longest first, ties by their endpoint coordinates. Each
//! pass takes the segments in that order; a segment absorbs every later one
//! it can merge with (re-checking the later ones after each merge, since it
//! grew), and passes repeat until one merges nothing. [`merge`] itself is
//! symmetric: `merge(a, b) == merge(b, a)` exactly. The later segments a
//! segment may merge with are found through a grid ([`connect_into`]), so
//! that a photograph's thousands of lines cost about their number, not its
//! square.
//!
//! Beyond §4: a merge also needs the merged line to fit the parts about as
//! well as their own lines do ([`one_edge`]), so that two distinct
//! near-collinear edges (a plate's edge and its chamfer, stacked plates seen
//! edge-on) are not averaged into one line between them.

use super::fit::LineFit;
use super::params::ConnectParams;
use super::{Point, Segment};

mod grid;
use grid::{Grid, Seen};

/// An oriented rectangle: centre, unit direction, half-length, half-width.
#[derive(Clone, Copy, Debug)]
struct Rect {
    c: Point,
    d: (f64, f64),
    hl: f64,
    hw: f64,
}

/// Unit direction of a segment (`(1, 0)` for a degenerate one).
fn unit_dir(s: &Segment) -> (f64, f64) {
    let (dx, dy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let len = dx.hypot(dy);
    if len > 0.0 && len.is_finite() {
        (dx / len, dy / len)
    } else {
        (1.0, 0.0)
    }
}

/// The environment of a segment: `wl` beyond each end, `wd` to each side.
fn environment(s: &Segment, wl: f64, wd: f64) -> Rect {
    Rect {
        c: Point::new(0.5 * (s.a.x + s.b.x), 0.5 * (s.a.y + s.b.y)),
        d: unit_dir(s),
        hl: 0.5 * s.length() + wl,
        hw: wd,
    }
}

/// Separating-axis test of two oriented rectangles (touching counts).
fn rects_intersect(r1: &Rect, r2: &Rect) -> bool {
    let (dx, dy) = (r2.c.x - r1.c.x, r2.c.y - r1.c.y);
    let axes = [r1.d, (-r1.d.1, r1.d.0), r2.d, (-r2.d.1, r2.d.0)];
    axes.iter().all(|&(ax, ay)| {
        let radius = |r: &Rect| {
            r.hl * (r.d.0 * ax + r.d.1 * ay).abs() + r.hw * (-r.d.1 * ax + r.d.0 * ay).abs()
        };
        (dx * ax + dy * ay).abs() <= radius(r1) + radius(r2)
    })
}

/// Difference of the undirected directions of two segments, in [0, π/2].
pub fn angle_between(s1: &Segment, s2: &Segment) -> f64 {
    let (a1, a2) = (unit_dir(s1), unit_dir(s2));
    let cross = (a1.0 * a2.1 - a1.1 * a2.0).abs();
    let dot = (a1.0 * a2.0 + a1.1 * a2.1).abs();
    cross.atan2(dot)
}

/// Whether CONNECT merges two segments under `p`.
pub fn mergeable(s1: &Segment, s2: &Segment, p: &ConnectParams) -> bool {
    let max = p
        .max_angle_deg
        .to_radians()
        .clamp(0.0, std::f64::consts::FRAC_PI_2);
    let (sin_max, cos_max) = max.sin_cos();
    geo_mergeable(&Geo::of(s1, p), &Geo::of(s2, p), sin_max, cos_max)
        && one_edge(s1, s2, &merge(s1, s2))
}

/// The spread (px) a merge is allowed beyond the parts' residuals: half of
/// the smallest offset at which two parallel edges count as two.
const MIN_SPREAD: f64 = 0.25;

/// Whether `merged` is one edge rather than two distinct near-collinear
/// ones: the length-weighted RMS distance of the parts' endpoints from the
/// merged line is within the larger of the parts' own residuals plus
/// `MIN_SPREAD`. Two pieces of one edge lie on its line to within their
/// fits' errors; two parallel edges a pixel apart are half a pixel off the
/// line between them, whatever their environments and angles allow.
pub fn one_edge(s1: &Segment, s2: &Segment, merged: &Segment) -> bool {
    let len = merged.length();
    if len.is_nan() || len <= 0.0 {
        return true;
    }
    let (dx, dy) = (
        (merged.b.x - merged.a.x) / len,
        (merged.b.y - merged.a.y) / len,
    );
    let dist = |q: Point| ((q.x - merged.a.x) * dy - (q.y - merged.a.y) * dx).abs();
    let (w1, w2) = (s1.length(), s2.length());
    let w = w1 + w2;
    if w.is_nan() || w <= 0.0 {
        return true;
    }
    let sq = |a: f64, b: f64| a * a + b * b;
    let spread =
        ((w1 * sq(dist(s1.a), dist(s1.b)) + w2 * sq(dist(s2.a), dist(s2.b))) / (2.0 * w)).sqrt();
    let allowed = s1.residual.max(s2.residual) + MIN_SPREAD;
    spread.is_nan() || spread <= allowed
}

/// Whether both ends of `l` are finite: CONNECT leaves out the others.
fn finite(l: &Segment) -> bool {
    l.a.x.is_finite() && l.a.y.is_finite() && l.b.x.is_finite() && l.b.y.is_finite()
}

/// The canonical order of segments: longer first, then by coordinates.
fn order(s1: &Segment, s2: &Segment) -> std::cmp::Ordering {
    keyed_order(s1.length(), s1, s2.length(), s2)
}

/// [`order`] of segments of lengths `l1` and `l2` (sorting many, each
/// length is computed once).
fn keyed_order(l1: f64, s1: &Segment, l2: f64, s2: &Segment) -> std::cmp::Ordering {
    l2.total_cmp(&l1)
        .then(s1.a.x.total_cmp(&s2.a.x))
        .then(s1.a.y.total_cmp(&s2.a.y))
        .then(s1.b.x.total_cmp(&s2.b.x))
        .then(s1.b.y.total_cmp(&s2.b.y))
        .then(s1.response.total_cmp(&s2.response))
}

/// Sorts `keys`, pairs of a length and an index into `segs`, by
/// [`keyed_order`], ties by index: sorting the small keys rather than the
/// segments moves a quarter of the bytes.
fn sort_keys(keys: &mut [(f64, u32)], segs: &[Segment]) {
    keys.sort_unstable_by(|&(l1, i1), &(l2, i2)| {
        keyed_order(l1, &segs[i1 as usize], l2, &segs[i2 as usize]).then(i1.cmp(&i2))
    });
}

/// The length-weighted merge of two segments (§4): the total-least-squares
/// line of the four endpoints, each weighted by its segment's length, and
/// the segment between the outermost projections of the endpoints onto it.
/// It keeps the orientation of the longer segment. `response` is the
/// length-weighted mean magnitude with the longer segment's sign (the two
/// may come from different scan directions, whose signs need not agree);
/// `residual` adds the endpoints' spread about the merged line to the
/// length-weighted mean square residual; `shadow` only if both are.
pub fn merge(s1: &Segment, s2: &Segment) -> Segment {
    // Symmetry: always combine in the canonical order.
    let (l, m) = if order(s1, s2).is_le() {
        (s1, s2)
    } else {
        (s2, s1)
    };
    let (wl, wm) = (l.length(), m.length());
    let mut fit = LineFit::new();
    for (s, w) in [(l, wl), (m, wm)] {
        fit.add_weighted(s.a, w);
        fit.add_weighted(s.b, w);
    }
    let Some(line) = fit.line() else {
        return *l;
    };
    let mut d = line.direction();
    let ld = unit_dir(l);
    if d.0 * ld.0 + d.1 * ld.1 < 0.0 {
        d = (-d.0, -d.1);
    }
    let origin = fit.mean().unwrap_or(l.a);
    let t = |p: Point| (p.x - origin.x) * d.0 + (p.y - origin.y) * d.1;
    let ends = [l.a, l.b, m.a, m.b];
    let mut lo = ends[0];
    let mut hi = ends[0];
    for &p in &ends[1..] {
        if t(p) < t(lo) {
            lo = p;
        }
        if t(p) > t(hi) {
            hi = p;
        }
    }
    let wsum = wl + wm;
    let (response, residual) = if wsum > 0.0 {
        let mag = (wl * l.response.abs() + wm * m.response.abs()) / wsum;
        let sign = if l.response < 0.0 { -1.0 } else { 1.0 };
        let ms = (wl * l.residual * l.residual + wm * m.residual * m.residual) / wsum;
        (sign * mag, (ms + fit.mean_square_residual()).sqrt())
    } else {
        (l.response, l.residual)
    };
    Segment {
        a: line.project(lo),
        b: line.project(hi),
        response,
        residual,
        shadow: l.shadow && m.shadow,
    }
}

/// What the pair test needs of a segment, computed once per change.
#[derive(Clone, Copy, Debug)]
struct Geo {
    env: Rect,
    /// Axis-aligned bounds of the environment: min x, min y, max x, max y.
    bounds: [f64; 4],
    /// The direction's place on the half turn, `1 − cos θ` of its angle
    /// `θ` in `[0, π]`: increasing with `θ`, from 0 to 2, without the
    /// `atan2` (the grid's direction bins compare it with their bounds').
    turn: f64,
}

impl Geo {
    fn of(s: &Segment, p: &ConnectParams) -> Geo {
        let env = environment(s, p.wl, p.wd);
        let ex = env.hl * env.d.0.abs() + env.hw * env.d.1.abs();
        let ey = env.hl * env.d.1.abs() + env.hw * env.d.0.abs();
        Geo {
            env,
            bounds: [env.c.x - ex, env.c.y - ey, env.c.x + ex, env.c.y + ey],
            turn: if env.d.1 < 0.0 {
                1.0 + env.d.0
            } else {
                1.0 - env.d.0
            },
        }
    }
}

/// The merge test on cached geometry: bounds, then the angle (`|cross| ≤
/// tan(max)·|dot|` is `atan2(|cross|, |dot|) ≤ max` without the atan2), then
/// the separating-axis test.
fn geo_mergeable(g1: &Geo, g2: &Geo, sin_max: f64, cos_max: f64) -> bool {
    let (b1, b2) = (&g1.bounds, &g2.bounds);
    if b1[0] > b2[2] || b2[0] > b1[2] || b1[1] > b2[3] || b2[1] > b1[3] {
        return false;
    }
    let (a1, a2) = (g1.env.d, g2.env.d);
    let cross = (a1.0 * a2.1 - a1.1 * a2.0).abs();
    let dot = (a1.0 * a2.0 + a1.1 * a2.1).abs();
    cross * cos_max <= dot * sin_max && rects_intersect(&g1.env, &g2.env)
}

/// Reusable buffers of CONNECT.
#[derive(Clone, Debug, Default)]
pub struct ConnectScratch {
    segs: Vec<Segment>,
    geo: Vec<Geo>,
    alive: Vec<bool>,
    /// The pass in which each segment last changed (0: never).
    changed: Vec<u32>,
    grid: Grid,
    /// The segments that changed in the previous pass, in a grid of the
    /// same layout.
    fresh: Grid,
    seen: Seen,
    /// The candidates of the segment being grown.
    cand: Vec<u32>,
    /// Lengths of segments and their indices, for sorting.
    keyed: Vec<(f64, u32)>,
    /// The length of each segment as it came in.
    lens: Vec<f64>,
}

/// CONNECT (§4) of a line set; the result is sorted longest first.
/// With `p.enabled == false` the lines are returned unchanged.
pub fn connect(lines: &[Segment], p: &ConnectParams) -> Vec<Segment> {
    let mut out = Vec::new();
    connect_into(lines, p, &mut out, &mut ConnectScratch::default());
    out
}

/// [`connect`] into reusable buffers.
///
/// A pair is tested again in a later pass only if one of the two changed in
/// the previous pass or this one: otherwise it was already tested in the
/// same state and failed. This makes the final "nothing merges" pass cheap:
/// a segment that did not change is looked up only among those that did
/// (a second grid of them).
///
/// The pairs are found through a grid of 32-px cells: a segment is tested
/// against the later segments whose environments share a cell with its
/// own, in the order of the module doc, and after it absorbs one, against
/// those of its grown environment from the first again. That is the same
/// sequence of merges as testing every later segment (environments that
/// share no cell do not meet, and such a pair fails the test), at about
/// the cost of the pairs that are near each other: on a 2560 × 1920 photograph of 5,240 lines
/// the quadratic scan took most of the pipeline's time. Only the segments
/// in a neighbouring direction bin that pass the test's geometry are
/// gathered (each once); merging them is the test's other half.
pub fn connect_into(
    lines: &[Segment],
    p: &ConnectParams,
    out: &mut Vec<Segment>,
    s: &mut ConnectScratch,
) {
    out.clear();
    if !p.enabled {
        out.extend_from_slice(lines);
        return;
    }
    s.keyed.clear();
    s.keyed.extend(
        (0..lines.len() as u32)
            .filter(|&k| finite(&lines[k as usize]))
            .map(|k| (lines[k as usize].length(), k)),
    );
    sort_keys(&mut s.keyed, lines);
    s.segs.clear();
    s.segs.extend(s.keyed.iter().map(|k| lines[k.1 as usize]));
    s.lens.clear();
    s.lens.extend(s.keyed.iter().map(|k| k.0));
    let n = s.segs.len();
    s.geo.clear();
    s.geo.extend(s.segs.iter().map(|l| Geo::of(l, p)));
    s.alive.clear();
    s.alive.resize(n, true);
    s.changed.clear();
    s.changed.resize(n, 0);
    let max = p
        .max_angle_deg
        .to_radians()
        .clamp(0.0, std::f64::consts::FRAC_PI_2);
    let t = max.sin_cos();
    s.grid.reset(&s.geo, max);
    for (k, g) in s.geo.iter().enumerate() {
        s.grid.insert(k as u32, g);
    }
    s.grid.seal();
    s.seen.reset(n);
    let ConnectScratch {
        segs,
        geo,
        alive,
        changed,
        grid,
        fresh,
        seen,
        cand,
        ..
    } = s;
    let mut pass = 1u32;
    // The last segment in `fresh`.
    let mut fresh_last = 0;
    loop {
        if pass > 1 {
            fresh.reset_like(grid);
            fresh_last = 0;
            for k in (0..n).filter(|&k| alive[k] && changed[k] + 1 == pass) {
                fresh.insert(k as u32, &geo[k]);
                fresh_last = k;
            }
        }
        let mut merged_any = false;
        for i in 0..n {
            if !alive[i] {
                continue;
            }
            let gather = |grid: &mut Grid,
                          geo: &[Geo],
                          alive: &[bool],
                          changed: &[u32],
                          seen: &mut Seen,
                          cand: &mut Vec<u32>| {
                let gi = &geo[i];
                let pair = |k: usize| alive[k] && geo_mergeable(gi, &geo[k], t.0, t.1);
                if pass == 1 {
                    grid.after_in_order(i as u32, gi, seen, cand, pair);
                } else if changed[i] + 1 >= pass {
                    grid.after(i as u32, gi, seen, cand, pair);
                } else if i < fresh_last {
                    // Only a pair with a segment changed since the last pass
                    // can merge now: those are in `fresh`.
                    fresh.after(i as u32, gi, seen, cand, pair);
                } else {
                    cand.clear();
                }
            };
            gather(grid, geo, alive, changed, seen, cand);
            let mut c = 0;
            while let Some(&j) = cand.get(c) {
                let j = j as usize;
                let m = merge(&segs[i], &segs[j]);
                if one_edge(&segs[i], &segs[j], &m) {
                    segs[i] = m;
                    geo[i] = Geo::of(&segs[i], p);
                    changed[i] = pass;
                    alive[j] = false;
                    merged_any = true;
                    grid.insert(i as u32, &geo[i]);
                    gather(grid, geo, alive, changed, seen, cand);
                    c = 0;
                } else {
                    c += 1;
                }
            }
        }
        if !merged_any {
            break;
        }
        pass += 1;
    }
    // The segments that never merged are still in order: only those that
    // did are sorted, then the two runs are merged (the same order as
    // sorting them all, ties by index).
    let ConnectScratch {
        segs,
        alive,
        changed,
        keyed,
        lens,
        ..
    } = s;
    keyed.clear();
    keyed.extend(
        (0..n as u32)
            .filter(|&k| alive[k as usize] && changed[k as usize] > 0)
            .map(|k| (segs[k as usize].length(), k))
            .filter(|&(len, k)| long_enough(&segs[k as usize], len, p)),
    );
    sort_keys(keyed, segs);
    let mut grown = keyed.iter().peekable();
    for k in 0..n {
        let len = lens[k];
        if !alive[k] || changed[k] > 0 || !long_enough(&segs[k], len, p) {
            continue;
        }
        while let Some(&&(l, j)) = grown.peek() {
            let first = keyed_order(l, &segs[j as usize], len, &segs[k]).then(j.cmp(&(k as u32)));
            if first.is_gt() {
                break;
            }
            out.push(segs[j as usize]);
            grown.next();
        }
        out.push(segs[k]);
    }
    out.extend(grown.map(|&(_, j)| segs[j as usize]));
}

/// Whether a line of length `len` stays after CONNECT: at least
/// `min_line_length`, or shorter but with its direction sure, so that a
/// short edge the image shows clearly is kept and a short noise track is
/// not. A line's direction error is about its points' scatter (`residual`)
/// times `√12 / len^1.5` (a least-squares fit to one point a pixel);
/// under `short_line_deg` it is sure. (A merged line's residual holds its
/// parts' spread about it, [`merge`]; a residual of 0 is unknown, as for
/// lines read from a file, and proves nothing.)
fn long_enough(s: &Segment, len: f64, p: &ConnectParams) -> bool {
    len >= p.min_line_length
        || (p.short_line_deg > 0.0
            && s.residual > 0.0
            && s.residual * 12f64.sqrt() <= p.short_line_deg.to_radians() * len.powf(1.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment {
            response: 20.0,
            residual: 0.1,
            ..Segment::new(Point::new(ax, ay), Point::new(bx, by))
        }
    }

    /// A line under `min_line_length` stays when its points fix its
    /// direction within `short_line_deg`, and only then.
    #[test]
    fn a_short_line_stays_when_its_direction_is_sure() {
        let p = ConnectParams::default();
        assert!(p.min_line_length > 10.0 && p.short_line_deg > 0.0);
        // 10 px: √12 · 0.05 / 10^1.5 is 0.31° of direction error; 0.5 px
        // of scatter is 3.1°.
        let sure = Segment {
            residual: 0.05,
            ..seg(0.0, 0.0, 10.0, 0.0)
        };
        let unsure = Segment {
            residual: 0.5,
            ..seg(0.0, 50.0, 10.0, 50.0)
        };
        let unknown = Segment {
            residual: 0.0,
            ..seg(0.0, 90.0, 10.0, 90.0)
        };
        let out = connect(&[sure, unsure, unknown], &p);
        assert_eq!(out, vec![sure]);
        let off = ConnectParams {
            short_line_deg: 0.0,
            ..p
        };
        assert!(connect(&[sure], &off).is_empty());
    }

    #[test]
    fn joins_a_split_line() {
        let p = ConnectParams::default();
        let out = connect(
            &[seg(10.0, 10.0, 10.2, 60.0), seg(10.25, 65.0, 10.4, 100.0)],
            &p,
        );
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(out[0].a.dist(Point::new(10.0, 10.0)) < 0.2);
        assert!(out[0].b.dist(Point::new(10.4, 100.0)) < 0.2);
        // Too far apart along the line (gap 13 > 2 wl): not merged.
        let out = connect(
            &[seg(10.0, 10.0, 10.0, 60.0), seg(10.0, 73.0, 10.0, 100.0)],
            &p,
        );
        assert_eq!(out.len(), 2);
        // Parallel but 4 px to the side: not merged.
        let out = connect(
            &[seg(10.0, 10.0, 10.0, 60.0), seg(14.0, 20.0, 14.0, 100.0)],
            &p,
        );
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn joins_the_near_45_degree_duplicate_of_both_scans() {
        // The same diagonal found by EdgeH and EdgeV, offset by a fraction of
        // a pixel and overlapping.
        let h = Segment {
            response: 30.0,
            ..seg(20.0, 20.0, 80.0, 80.5)
        };
        let v = Segment {
            response: -28.0,
            ..seg(25.3, 24.9, 90.0, 90.2)
        };
        let out = connect(&[h, v], &ConnectParams::default());
        assert_eq!(out.len(), 1);
        assert!(out[0].length() > 95.0);
        assert!(out[0].response.abs() > 28.0 && out[0].response.abs() < 30.0);
    }

    #[test]
    fn merge_is_symmetric_and_order_does_not_matter() {
        let a = seg(0.0, 0.0, 50.0, 1.0);
        let b = seg(52.0, 1.1, 70.0, 1.5);
        assert_eq!(merge(&a, &b), merge(&b, &a));
        let lines = vec![
            a,
            b,
            seg(100.0, 100.0, 100.0, 140.0),
            seg(100.3, 144.0, 100.1, 170.0),
            Segment {
                residual: 0.3,
                ..seg(0.0, 100.0, 5.0, 100.0)
            },
        ];
        let p = ConnectParams::default();
        let out1 = connect(&lines, &p);
        let mut rev = lines.clone();
        rev.reverse();
        assert_eq!(out1, connect(&rev, &p));
        // 2 merged lines; the 5 px segment, its direction unsure, falls to
        // the length filter.
        assert_eq!(out1.len(), 2);
        assert!(connect(&[], &p).is_empty());
    }

    /// Two parallel edges a pixel apart overlap within `wd` and agree in
    /// direction, but are two edges: not merged. Two pieces of one edge
    /// with a gap are.
    #[test]
    fn distinct_parallel_edges_stay_apart() {
        let p = ConnectParams::default();
        let fitted = |mut s: Segment| {
            s.residual = 0.05;
            s
        };
        let a = fitted(seg(0.0, 0.0, 60.0, 0.0));
        let b = fitted(seg(40.0, 1.0, 100.0, 1.0));
        assert!(!mergeable(&a, &b, &p));
        assert_eq!(connect(&[a, b], &p).len(), 2);
        let c = fitted(seg(64.0, 0.1, 120.0, 0.1));
        assert!(mergeable(&a, &c, &p));
        assert_eq!(connect(&[a, c], &p).len(), 1);
    }

    #[test]
    fn angle_test_and_rectangles() {
        let p = ConnectParams::default();
        let a = seg(0.0, 0.0, 50.0, 0.0);
        // Crossing at 10°: environments intersect, angle too large.
        let b = seg(20.0, -4.0, 60.0, 3.0);
        assert!(!mergeable(&a, &b, &p));
        // Reversed orientation is the same direction.
        let c = seg(90.0, 0.5, 54.0, 0.3);
        assert!(mergeable(&a, &c, &p));
        assert!((angle_between(&a, &c) - (0.2f64 / 36.0).atan()).abs() < 1e-9);
    }

    /// The plain pair scan CONNECT's grid replaces: every later segment
    /// tested, from the first again after each merge.
    fn connect_reference(lines: &[Segment], p: &ConnectParams) -> Vec<Segment> {
        if !p.enabled {
            return lines.to_vec();
        }
        let mut segs: Vec<Segment> = lines.iter().filter(|l| finite(l)).copied().collect();
        segs.sort_unstable_by(order);
        let n = segs.len();
        let mut alive = vec![true; n];
        let (sin_max, cos_max) = p
            .max_angle_deg
            .to_radians()
            .clamp(0.0, std::f64::consts::FRAC_PI_2)
            .sin_cos();
        loop {
            let mut merged_any = false;
            for i in 0..n {
                let mut j = i + 1;
                while alive[i] && j < n {
                    let (gi, gj) = (Geo::of(&segs[i], p), Geo::of(&segs[j], p));
                    let m = merge(&segs[i], &segs[j]);
                    if alive[j]
                        && geo_mergeable(&gi, &gj, sin_max, cos_max)
                        && one_edge(&segs[i], &segs[j], &m)
                    {
                        segs[i] = m;
                        alive[j] = false;
                        merged_any = true;
                        j = i + 1;
                    } else {
                        j += 1;
                    }
                }
            }
            if !merged_any {
                break;
            }
        }
        let mut out: Vec<Segment> = segs
            .into_iter()
            .zip(alive)
            .filter(|&(l, alive)| alive && long_enough(&l, l.length(), p))
            .map(|(l, _)| l)
            .collect();
        out.sort_unstable_by(order);
        out
    }

    /// Pieces of random lines (split, jittered, some near-collinear
    /// neighbours a pixel or two off) and random short strays, over a
    /// `size`-px square moved to `origin`.
    fn scene(seed: u64, size: f64, origin: f64) -> Vec<Segment> {
        let mut rng = crate::rng::SplitMix64::new(seed);
        let mut out = Vec::new();
        for _ in 0..40 {
            let (x, y) = (rng.range(0.0, size), rng.range(0.0, size));
            let t = rng.range(0.0, std::f64::consts::PI);
            let (dx, dy) = t.sin_cos();
            let off = if rng.below(4) == 0 {
                rng.range(0.5, 2.5)
            } else {
                0.0
            };
            let mut s = rng.range(-200.0, -20.0);
            while s < rng.range(20.0, 200.0) {
                let l = rng.range(5.0, 60.0);
                let (e0, e1) = (rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
                let a = (x + s * dx - (off + e0) * dy, y + s * dy + (off + e0) * dx);
                let b = (
                    x + (s + l) * dx - (off + e1) * dy,
                    y + (s + l) * dy + (off + e1) * dx,
                );
                out.push(Segment {
                    response: rng.range(-40.0, 40.0),
                    residual: rng.range(0.0, 0.4),
                    ..Segment::new(
                        Point::new(origin + a.0, origin + a.1),
                        Point::new(origin + b.0, origin + b.1),
                    )
                });
                s += l + rng.range(0.0, 12.0);
            }
        }
        for _ in 0..60 {
            let (x, y) = (rng.range(0.0, size), rng.range(0.0, size));
            let (dx, dy) = (rng.range(-10.0, 10.0), rng.range(-10.0, 10.0));
            out.push(seg(
                origin + x,
                origin + y,
                origin + x + dx,
                origin + y + dy,
            ));
        }
        out
    }

    #[test]
    fn the_grid_merges_exactly_as_the_plain_pair_scan() {
        let mut s = ConnectScratch::default();
        let mut out = Vec::new();
        let mut merges = 0;
        for seed in 0..40 {
            // Image-sized scenes, one far off the origin, one spread so
            // wide that the grid's cells widen.
            let (size, origin) = match seed % 4 {
                0 => (2048.0, 0.0),
                1 => (512.0, 1.0e9),
                2 => (1.0e7, -5.0e6),
                _ => (512.0, 0.0),
            };
            let mut lines = scene(seed, size, origin);
            if seed % 5 == 0 {
                // A damaged line file's: lengths that overflow, a NaN.
                lines.push(seg(-1e300, 3.0, 1e300, 3.0));
                lines.push(seg(f64::NAN, 0.0, 10.0, 10.0));
            }
            for p in [
                ConnectParams::default(),
                ConnectParams {
                    wl: 30.0,
                    wd: 4.0,
                    max_angle_deg: 10.0,
                    min_line_length: 0.0,
                    ..ConnectParams::default()
                },
            ] {
                connect_into(&lines, &p, &mut out, &mut s);
                let want = connect_reference(&lines, &p);
                assert_eq!(out, want, "seed {seed}");
                if p.min_line_length == 0.0 {
                    merges += lines.len() - want.len();
                }
            }
        }
        // The scenes merge a lot: the test compares real work.
        assert!(merges > 4000, "{merges} merges");
    }
}
