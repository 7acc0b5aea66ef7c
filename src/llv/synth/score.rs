//! Scoring detected lines against true edges, with the matching rule below.
//!
//! A detected segment *supports* a true edge along the part of it that lies
//! within [`DIST`] px of the true segment (distance to the segment, not to its
//! infinite line) when the two directions differ by at most [`ANGLE_DEG`].
//! - recall: the fraction of true length covered by the supporting parts
//!   projected onto the true edges, as a union (two detections of the same
//!   stretch count once);
//! - precision: the fraction of detected length that supports some true edge
//!   (union over true edges, per detected segment);
//! - endpoint distance: for each detected segment that supports a true edge,
//!   the perpendicular distances of both its endpoints from the line of the
//!   true edge it supports most (mean and 95th percentile over all such
//!   endpoints);
//! - angle error: the direction difference (degrees) to that same true edge,
//!   averaged over those segments.

use crate::llv::{Point, Segment};

/// Largest distance (px) of a supporting part from the true edge.
pub const DIST: f64 = 2.0;
/// Largest direction difference (degrees) of a supporting segment.
pub const ANGLE_DEG: f64 = 3.0;

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
    /// Total detected length (px).
    pub detected_length: f64,
    /// Detected segments that support some true edge.
    pub supporting: usize,
    /// Detected segments in all.
    pub detected: usize,
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
}

impl Tally {
    /// Adds one image's detected lines and true edges.
    pub fn add(&mut self, detected: &[Segment], truth: &[Segment]) {
        let mut covered: Vec<Vec<(f64, f64)>> = vec![Vec::new(); truth.len()];
        for d in detected {
            let len = d.length();
            self.detected += 1;
            if !(len.is_finite() && len > 0.0) {
                continue;
            }
            self.detected_length += len;
            let mut own: Vec<(f64, f64)> = Vec::new();
            let mut best: Option<(usize, f64)> = None;
            for (ti, t) in truth.iter().enumerate() {
                let Some((s0, s1)) = support(d, t) else {
                    continue;
                };
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
            let sup = union_length(&mut own);
            self.supporting_length += sup;
            if let Some((ti, _)) = best
                && let Some(t) = truth.get(ti)
            {
                self.endpoint_dists.push(line_distance(t, d.a));
                self.endpoint_dists.push(line_distance(t, d.b));
                self.angle_errors_deg.push(angle_diff_deg(d, t));
            }
        }
        for (t, mut c) in truth.iter().zip(covered) {
            let tl = t.length();
            if tl.is_finite() {
                self.true_length += tl;
                self.covered_length += union_length(&mut c);
            }
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
    let (dl, tl) = (d.length(), t.length());
    if !(dl > 0.0 && tl > 0.0) || angle_diff_deg(d, t) > ANGLE_DEG {
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

/// `{s ∈ [s0, s1] : lo ≤ a + b s ≤ hi}`.
fn clip_linear(a: f64, b: f64, lo: f64, hi: f64, s0: f64, s1: f64) -> Option<(f64, f64)> {
    if b.abs() < 1e-12 {
        return (a >= lo && a <= hi).then_some((s0, s1));
    }
    let (x, y) = ((lo - a) / b, (hi - a) / b);
    let (x, y) = (x.min(y), x.max(y));
    let (r0, r1) = (s0.max(x), s1.min(y));
    (r0 <= r1).then_some((r0, r1))
}

/// Total length of a union of intervals (sorts them in place).
fn union_length(iv: &mut [(f64, f64)]) -> f64 {
    iv.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut cur: Option<(f64, f64)> = None;
    for &(a, b) in iv.iter() {
        match cur {
            Some((c0, c1)) if a <= c1 => cur = Some((c0, c1.max(b))),
            Some((c0, c1)) => {
                total += c1 - c0;
                cur = Some((a, b));
            }
            None => cur = Some((a, b)),
        }
    }
    if let Some((c0, c1)) = cur {
        total += c1 - c0;
    }
    total
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

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    #[test]
    fn perfect_detection_scores_one() {
        let truth = vec![seg(10.0, 10.0, 110.0, 10.0), seg(10.0, 10.0, 10.0, 60.0)];
        let m = score(&truth, &truth);
        assert!((m.recall - 1.0).abs() < 1e-12);
        assert!((m.precision - 1.0).abs() < 1e-12);
        assert!(m.endpoint_mean < 1e-12 && m.angle_mean_deg < 1e-9);
    }

    #[test]
    fn half_covered_edge_and_a_noise_line() {
        let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
        // Covers x 0..50 at 1 px off; the noise line is far away.
        let det = vec![seg(0.0, 1.0, 50.0, 1.0), seg(0.0, 30.0, 50.0, 30.0)];
        let m = score(&det, &truth);
        assert!((m.recall - 0.5).abs() < 1e-9, "{m:?}");
        assert!((m.precision - 0.5).abs() < 1e-9, "{m:?}");
        assert!((m.endpoint_mean - 1.0).abs() < 1e-9);
        assert_eq!(m.supporting, 1);
    }

    #[test]
    fn overlapping_detections_are_not_counted_twice() {
        let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
        let det = vec![seg(0.0, 0.5, 60.0, 0.5), seg(40.0, -0.5, 80.0, -0.5)];
        let m = score(&det, &truth);
        assert!((m.recall - 0.8).abs() < 1e-9, "{m:?}");
        assert!((m.precision - 1.0).abs() < 1e-9);
    }

    #[test]
    fn support_stops_two_px_beyond_the_true_end_and_at_the_angle_limit() {
        let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
        // Runs 20 px past the end: only 2 px of the overshoot supports.
        let m = score(&[seg(80.0, 0.0, 120.0, 0.0)], &truth);
        assert!((m.precision - 22.0 / 40.0).abs() < 1e-9, "{m:?}");
        assert!((m.recall - 0.2).abs() < 1e-9);
        // 4° off: no support at all; 2° off: support where within 2 px.
        let r = 50.0;
        let t4 = 4f64.to_radians();
        let off = seg(50.0, 0.0, 50.0 + r * t4.cos(), -r * t4.sin());
        assert_eq!(score(&[off], &truth).precision, 0.0);
        let t2 = 2f64.to_radians();
        let near = seg(0.0, 0.0, 100.0 * t2.cos(), -100.0 * t2.sin());
        let m = score(&[near], &truth);
        // Within 2 px while 100·sin(2°)·s/100 ≤ 2 → s ≤ 2/sin 2° ≈ 57.3.
        let expect = 2.0 / t2.sin() / 100.0;
        assert!((m.precision - expect).abs() < 1e-6, "{m:?} vs {expect}");
        assert!((m.angle_mean_deg - 2.0).abs() < 1e-9);
    }

    #[test]
    fn pooled_scores_weight_by_length() {
        let t1 = vec![seg(0.0, 0.0, 100.0, 0.0)];
        let t2 = vec![seg(0.0, 0.0, 300.0, 0.0)];
        let m = score_all(&[(t1.clone(), t1), (vec![], t2)]);
        assert!((m.recall - 0.25).abs() < 1e-9);
        assert!((m.precision - 1.0).abs() < 1e-9);
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.0);
    }
}
