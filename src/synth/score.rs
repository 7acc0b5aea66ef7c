//! Scoring detected lines against true edges with the matching rule below,
//! don't-care edges, and the breakdowns that say where a detector loses.
//!
//! A detected segment *supports* a true edge along the part of it that lies
//! within [`DIST`] px of the true segment (distance to the segment, not to its
//! infinite line) when the two directions differ by at most [`ANGLE_DEG`].
//! - recall: the fraction of true length covered by the supporting parts
//!   projected onto the true edges, as a union (two detections of the same
//!   stretch count once);
//! - precision: the fraction of detected length that supports some true edge
//!   (union over true edges, per detected segment);
//! - don't-care edges (too faint, or in the image's border band): the part of
//!   a detected segment that supports one, by the same rule, and no true
//!   edge, is taken out of the detected length; their own length is not
//!   true length. So they count neither for nor against a detector;
//! - endpoint distance: for each detected segment that supports a true edge,
//!   the perpendicular distances of both its endpoints from the line of the
//!   true edge it supports most (mean and 95th percentile over all such
//!   endpoints);
//! - angle error: the direction difference (degrees) to that same true edge,
//!   averaged over those segments.
//!
//! Breakdowns:
//! - strong recall: recall over the true edges of contrast ≥ [`STRONG`] grey
//!   levels (a true edge's contrast is its `Segment.response`);
//! - close recall: recall over the parts of true edges that have another
//!   true edge within [`ANGLE_DEG`] of their direction at a perpendicular
//!   distance of [`CLOSE`] px (plate thicknesses seen edge-on);
//! - off-angle: the fraction of detected length that supports nothing but
//!   lies within [`DIST`] px of a true edge at a larger angle (a line tilted
//!   off its edge), plus the stretch of a segment between two close
//!   parallel true edges it runs near both of (a line bent across them).
//!
//! Between two detectors, [`shared_endpoints`] gives each one's endpoint
//! distance over only the true edges both support. The plain endpoint
//! figure of a detector that finds more faint edges includes them, and
//! faint edges have larger errors; this one compares like with like.

use crate::llv::{Point, Segment};

mod intervals;
#[cfg(test)]
mod tests;

use intervals::{clip_linear, intersection_length, normalize, union_length};

/// Largest distance (px) of a supporting part from the true edge.
pub const DIST: f64 = 2.0;
/// Largest direction difference (degrees) of a supporting segment.
pub const ANGLE_DEG: f64 = 3.0;
/// Contrast (grey levels) from which a true edge is strong.
pub const STRONG: f64 = 30.0;
/// Perpendicular distances (px) at which two parallel true edges are close.
pub const CLOSE: (f64, f64) = (4.0, 8.0);

/// The scores of one image or of several pooled.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Metrics {
    pub recall: f64,
    pub precision: f64,
    /// Mean perpendicular endpoint distance from the true line (px).
    pub endpoint_mean: f64,
    /// 95th percentile of the same (px).
    pub endpoint_p95: f64,
    /// Mean direction error of supporting segments (degrees).
    pub angle_mean_deg: f64,
    /// Total true edge length (px).
    pub true_length: f64,
    /// Total detected length (px), without what don't-care edges took.
    pub detected_length: f64,
    /// Detected segments that support some true edge.
    pub supporting: usize,
    /// Detected segments in all.
    pub detected: usize,
    /// Recall of the true edges of contrast ≥ `STRONG` (30 grey levels).
    pub recall_strong: f64,
    /// Recall of the parts of true edges with a parallel one `CLOSE` px away.
    pub recall_close: f64,
    /// Off-angle share of the detected length (see the module doc).
    pub off_angle: f64,
    /// True length of the strong edges and of the close parts (px).
    pub strong_length: f64,
    pub close_length: f64,
    /// Detected length taken out as matching don't-care edges (px).
    pub dont_care_length: f64,
}

impl Metrics {
    /// Harmonic mean of recall and precision.
    pub fn f_score(&self) -> f64 {
        let s = self.recall + self.precision;
        if s > 0.0 {
            2.0 * self.recall * self.precision / s
        } else {
            0.0
        }
    }
}

/// Running sums over several images; [`Tally::metrics`] pools them (lengths
/// add up, endpoint and angle lists are concatenated).
#[derive(Clone, Debug, Default)]
pub struct Tally {
    pub true_length: f64,
    pub covered_length: f64,
    pub detected_length: f64,
    pub supporting_length: f64,
    pub endpoint_dists: Vec<f64>,
    pub angle_errors_deg: Vec<f64>,
    pub detected: usize,
    pub strong_length: f64,
    pub strong_covered: f64,
    pub close_length: f64,
    pub close_covered: f64,
    pub off_angle_length: f64,
    pub dont_care_length: f64,
    /// Images added so far.
    pub images: usize,
    /// Per supporting segment (in the order of `angle_errors_deg`; its two
    /// endpoints are `endpoint_dists[2 k]` and `[2 k + 1]`): the image and
    /// the index of the true edge it supports most.
    pub supported: Vec<(usize, usize)>,
}

/// Endpoint distances of two detectors on the true edges both support
/// ([`shared_endpoints`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Shared {
    /// Mean endpoint distance (px) of the first detector's and the second
    /// detector's supporting segments on those edges.
    pub first_mean: f64,
    pub second_mean: f64,
    /// How many segments each has there.
    pub first_segments: usize,
    pub second_segments: usize,
    /// How many true edges both support.
    pub edges: usize,
}

/// The endpoint distance of each of two detectors, scored on the same
/// images, over only the true edges that both support: a detector that
/// finds more faint edges is not compared on edges the other did not find.
pub fn shared_endpoints(first: &Tally, second: &Tally) -> Shared {
    use std::collections::HashSet;
    let a: HashSet<(usize, usize)> = first.supported.iter().copied().collect();
    let b: HashSet<(usize, usize)> = second.supported.iter().copied().collect();
    let mean_on = |t: &Tally| {
        let (mut sum, mut n) = (0.0, 0usize);
        for (k, key) in t.supported.iter().enumerate() {
            if a.contains(key) && b.contains(key) {
                sum += t.endpoint_dists[2 * k] + t.endpoint_dists[2 * k + 1];
                n += 1;
            }
        }
        (if n > 0 { sum / (2 * n) as f64 } else { 0.0 }, n)
    };
    let (first_mean, first_segments) = mean_on(first);
    let (second_mean, second_segments) = mean_on(second);
    Shared {
        first_mean,
        second_mean,
        first_segments,
        second_segments,
        edges: a.intersection(&b).count(),
    }
}

impl Tally {
    /// Adds one image's detected lines and true edges (no don't-care edges).
    pub fn add(&mut self, detected: &[Segment], truth: &[Segment]) {
        self.add_with(detected, truth, &[]);
    }

    /// Adds one image's detected lines, true edges and don't-care edges.
    pub fn add_with(&mut self, detected: &[Segment], truth: &[Segment], dont_care: &[Segment]) {
        let mut covered: Vec<Vec<(f64, f64)>> = vec![Vec::new(); truth.len()];
        let (mut own, mut near, mut dc) = (Vec::new(), Vec::new(), Vec::new());
        let mut near_edges: Vec<usize> = Vec::new();
        for d in detected {
            let len = d.length();
            self.detected += 1;
            if !(len.is_finite() && len > 0.0) {
                continue;
            }
            own.clear();
            near.clear();
            dc.clear();
            near_edges.clear();
            let mut best: Option<(usize, f64)> = None;
            for (ti, t) in truth.iter().enumerate() {
                let Some((s0, s1)) = within(d, t) else {
                    continue;
                };
                near.push((s0, s1));
                near_edges.push(ti);
                if angle_diff_deg(d, t) > ANGLE_DEG {
                    continue;
                }
                own.push((s0, s1));
                if best.is_none_or(|(_, l)| s1 - s0 > l) {
                    best = Some((ti, s1 - s0));
                }
                // Project the supporting part onto the true edge.
                let tl = t.length();
                let (ux, uy) = ((t.b.x - t.a.x) / tl, (t.b.y - t.a.y) / tl);
                let at = |s: f64| {
                    let p = lerp(d.a, d.b, s / len);
                    ((p.x - t.a.x) * ux + (p.y - t.a.y) * uy).clamp(0.0, tl)
                };
                let (c0, c1) = (at(s0), at(s1));
                if let Some(c) = covered.get_mut(ti) {
                    c.push((c0.min(c1), c0.max(c1)));
                }
            }
            for t in dont_care {
                if let Some(iv) = support(d, t) {
                    dc.push(iv);
                }
            }
            if let Some(b) = bridge(truth, &near, &near_edges) {
                near.push(b);
            }
            let sup = union_length(&mut own);
            let mut matched: Vec<(f64, f64)> = own.iter().chain(&dc).copied().collect();
            let with_dc = union_length(&mut matched);
            let removed = with_dc - sup;
            matched.extend_from_slice(&near);
            let off = union_length(&mut matched) - with_dc;
            self.supporting_length += sup;
            self.detected_length += len - removed;
            self.dont_care_length += removed;
            self.off_angle_length += off;
            if let Some((ti, _)) = best
                && let Some(t) = truth.get(ti)
            {
                self.endpoint_dists.push(line_distance(t, d.a));
                self.endpoint_dists.push(line_distance(t, d.b));
                self.angle_errors_deg.push(angle_diff_deg(d, t));
                self.supported.push((self.images, ti));
            }
        }
        self.images += 1;
        for (ti, (t, c)) in truth.iter().zip(covered).enumerate() {
            let tl = t.length();
            if !tl.is_finite() {
                continue;
            }
            let c = normalize(c);
            let cov: f64 = c.iter().map(|(a, b)| b - a).sum();
            self.true_length += tl;
            self.covered_length += cov;
            if t.response >= STRONG {
                self.strong_length += tl;
                self.strong_covered += cov;
            }
            let close = normalize(close_parts(truth, ti));
            self.close_length += close.iter().map(|(a, b)| b - a).sum::<f64>();
            self.close_covered += intersection_length(&c, &close);
        }
    }

    /// The pooled metrics. Empty inputs give recall/precision 0.
    pub fn metrics(&self) -> Metrics {
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        let mean = |v: &[f64]| {
            if v.is_empty() {
                0.0
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        Metrics {
            recall: ratio(self.covered_length, self.true_length),
            precision: ratio(self.supporting_length, self.detected_length),
            endpoint_mean: mean(&self.endpoint_dists),
            endpoint_p95: percentile(&self.endpoint_dists, 0.95),
            angle_mean_deg: mean(&self.angle_errors_deg),
            true_length: self.true_length,
            detected_length: self.detected_length,
            supporting: self.angle_errors_deg.len(),
            detected: self.detected,
            recall_strong: ratio(self.strong_covered, self.strong_length),
            recall_close: ratio(self.close_covered, self.close_length),
            off_angle: ratio(self.off_angle_length, self.detected_length),
            strong_length: self.strong_length,
            close_length: self.close_length,
            dont_care_length: self.dont_care_length,
        }
    }
}

/// Scores one image's detected lines against its true edges.
pub fn score(detected: &[Segment], truth: &[Segment]) -> Metrics {
    let mut t = Tally::default();
    t.add(detected, truth);
    t.metrics()
}

/// Scores several images together (`(detected, truth)` per image).
pub fn score_all(cases: &[(Vec<Segment>, Vec<Segment>)]) -> Metrics {
    let mut t = Tally::default();
    for (d, tr) in cases {
        t.add(d, tr);
    }
    t.metrics()
}

fn lerp(a: Point, b: Point, t: f64) -> Point {
    Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t)
}

/// Direction difference of two segments, ignoring orientation (degrees, 0–90).
pub fn angle_diff_deg(a: &Segment, b: &Segment) -> f64 {
    let d = (a.angle() - b.angle()).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d).to_degrees()
}

/// Perpendicular distance of `p` from the infinite line through `t`.
pub fn line_distance(t: &Segment, p: Point) -> f64 {
    let l = t.length();
    if l <= 0.0 {
        return p.dist(t.a);
    }
    ((t.b.x - t.a.x) * (p.y - t.a.y) - (t.b.y - t.a.y) * (p.x - t.a.x)).abs() / l
}

/// The part `[s0, s1]` (arc length along `d` from `d.a`) of `d` that supports
/// `t`, if any.
fn support(d: &Segment, t: &Segment) -> Option<(f64, f64)> {
    if angle_diff_deg(d, t) > ANGLE_DEG {
        return None;
    }
    within(d, t)
}

/// The part of `d` within [`DIST`] of the segment `t`, at any angle.
fn within(d: &Segment, t: &Segment) -> Option<(f64, f64)> {
    let (dl, tl) = (d.length(), t.length());
    if !(dl > 0.0 && tl > 0.0) {
        return None;
    }
    // d(s) = d.a + s·e, e unit. The set {s : dist(d(s), t) ≤ DIST} is an
    // interval (distance to a segment is convex); it is the union of the
    // parts in the band beside t and in the discs at t's ends.
    let e = ((d.b.x - d.a.x) / dl, (d.b.y - d.a.y) / dl);
    let u = ((t.b.x - t.a.x) / tl, (t.b.y - t.a.y) / tl);
    let n = (-u.1, u.0);
    let r = (d.a.x - t.a.x, d.a.y - t.a.y);
    let mut lo = f64::INFINITY;
    let mut hi = -f64::INFINITY;
    // Band: 0 ≤ (r + s e)·u ≤ tl and -DIST ≤ (r + s e)·n ≤ DIST.
    let mut band = Some((0.0, dl));
    for (dir, lo_b, hi_b) in [(u, 0.0, tl), (n, -DIST, DIST)] {
        let a = r.0 * dir.0 + r.1 * dir.1;
        let b = e.0 * dir.0 + e.1 * dir.1;
        band = band.and_then(|(s0, s1)| clip_linear(a, b, lo_b, hi_b, s0, s1));
    }
    if let Some((s0, s1)) = band {
        lo = lo.min(s0);
        hi = hi.max(s1);
    }
    for c in [t.a, t.b] {
        // |d.a - c + s e|² ≤ DIST²
        let w = (d.a.x - c.x, d.a.y - c.y);
        let bq = w.0 * e.0 + w.1 * e.1;
        let cq = w.0 * w.0 + w.1 * w.1 - DIST * DIST;
        let disc = bq * bq - cq;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            let (s0, s1) = ((-bq - sq).max(0.0), (-bq + sq).min(dl));
            if s0 <= s1 {
                lo = lo.min(s0);
                hi = hi.max(s1);
            }
        }
    }
    (hi > lo).then_some((lo, hi))
}

/// Whether two true edges are a close parallel pair: within [`ANGLE_DEG`]
/// of each other, and `b`'s midpoint farther than [`DIST`] and at most
/// `CLOSE.1` px from `a`'s line.
fn close_pair(a: &Segment, b: &Segment) -> bool {
    let m = lerp(b.a, b.b, 0.5);
    let dist = line_distance(a, m);
    angle_diff_deg(a, b) <= ANGLE_DEG && dist > DIST && dist <= CLOSE.1
}

/// The stretch of a detected segment between its near parts on two close
/// parallel true edges, if it runs near such a pair.
fn bridge(truth: &[Segment], near: &[(f64, f64)], edges: &[usize]) -> Option<(f64, f64)> {
    let mut out: Option<(f64, f64)> = None;
    for (i, &ei) in edges.iter().enumerate() {
        for (j, &ej) in edges.iter().enumerate().skip(i + 1) {
            let (Some(a), Some(b)) = (truth.get(ei), truth.get(ej)) else {
                continue;
            };
            if close_pair(a, b) {
                let (p, q) = (near[i], near[j]);
                let iv = (p.0.min(q.0), p.1.max(q.1));
                out = Some(out.map_or(iv, |o| (o.0.min(iv.0), o.1.max(iv.1))));
            }
        }
    }
    out
}

/// The parts (arc length along edge `i`) of true edge `i` that have another
/// true edge within [`ANGLE_DEG`] at a perpendicular distance in [`CLOSE`].
fn close_parts(truth: &[Segment], i: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let Some(t) = truth.get(i) else {
        return out;
    };
    let tl = t.length();
    if !(tl > 0.0 && tl.is_finite()) {
        return out;
    }
    let u = ((t.b.x - t.a.x) / tl, (t.b.y - t.a.y) / tl);
    let n = (-u.1, u.0);
    let proj = |p: Point| {
        let r = (p.x - t.a.x, p.y - t.a.y);
        (r.0 * u.0 + r.1 * u.1, r.0 * n.0 + r.1 * n.1)
    };
    for (j, o) in truth.iter().enumerate() {
        if j == i || angle_diff_deg(t, o) > ANGLE_DEG || o.length().is_nan() || o.length() <= 0.0 {
            continue;
        }
        let ((sa, da), (sb, db)) = (proj(o.a), proj(o.b));
        let (s0, s1) = (sa.min(sb).max(0.0), sa.max(sb).min(tl));
        if s1 <= s0 || (sb - sa).abs() < 1e-9 {
            continue;
        }
        // Signed distance along the overlap: da + k (s - sa).
        let k = (db - da) / (sb - sa);
        let a = da - k * sa;
        for (lo, hi) in [(CLOSE.0, CLOSE.1), (-CLOSE.1, -CLOSE.0)] {
            if let Some(iv) = clip_linear(a, k, lo, hi, s0, s1) {
                out.push(iv);
            }
        }
    }
    out
}

/// The `q`-quantile (nearest rank) of the values; 0 when empty.
pub fn percentile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s: Vec<f64> = v.to_vec();
    s.sort_by(f64::total_cmp);
    let rank = ((q * s.len() as f64).ceil() as usize).clamp(1, s.len());
    s.get(rank - 1).copied().unwrap_or(0.0)
}
