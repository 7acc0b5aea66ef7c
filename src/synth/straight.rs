//! Straightness of the detected edge points along each true edge: the
//! lens-correction check.
//!
//! The residual of the pipeline's own lines is dominated by points near
//! corners and other edges (the kernel sees both), which hides the small bend
//! a lens gives a long edge. Here, for every true edge of at least
//! [`MIN_EDGE`] px, the edge points within [`NEAR`] px of the edge *as it
//! appears in the image* (through the lens when the image is distorted) and
//! more than [`END`] px from its ends are fitted with a total-least-squares
//! line; the RMS distance of those points from it is the edge's residual.
//! Straight edges seen through a distorting lens bend, and their residual
//! grows; lens correction should bring it back.

use crate::llv::{EdgePoints, Point, Segment};

/// Shortest true edge measured (px).
pub const MIN_EDGE: f64 = 40.0;
/// Points farther than this from the (possibly bent) edge are not its own.
pub const NEAR: f64 = 1.5;
/// Points this close to an end of the edge are left out (corners).
pub const END: f64 = 8.0;

/// Sums for the pooled mean residual.
#[derive(Clone, Debug, Default)]
pub struct Straightness {
    sum_sq: f64,
    /// Σ squared distance of the points from the true edge itself.
    sum_sq_true: f64,
    points: usize,
    edges: usize,
}

impl Straightness {
    /// Adds the edges of one image. `to_image` maps ideal pixels to the
    /// image's own pixels (identity for undistorted or corrected images).
    pub fn add(
        &mut self,
        truth: &[Segment],
        h: &EdgePoints,
        v: &EdgePoints,
        to_image: &dyn Fn(Point) -> Point,
    ) {
        for t in truth {
            let len = t.length();
            if len.is_nan() || len < MIN_EDGE {
                continue;
            }
            // Near-vertical edges from the horizontal scan, the others from
            // the vertical scan: each scan measures across its edges.
            let steep = (t.b.y - t.a.y).abs() >= (t.b.x - t.a.x).abs();
            let pts = if steep { &h.points } else { &v.points };
            let n = (len.ceil() as usize).max(2);
            let curve: Vec<Point> = (0..=n)
                .map(|k| {
                    let u = k as f64 / n as f64;
                    to_image(Point::new(
                        t.a.x + u * (t.b.x - t.a.x),
                        t.a.y + u * (t.b.y - t.a.y),
                    ))
                })
                .collect();
            let (lo, hi) = bbox(&curve, NEAR);
            let inner = END / len;
            let mut own: Vec<Point> = Vec::new();
            let mut true_sq = 0.0;
            for p in pts {
                let p = Point::new(p.x as f64, p.y as f64);
                if p.x < lo.x || p.y < lo.y || p.x > hi.x || p.y > hi.y {
                    continue;
                }
                if let Some((d, u)) = near_curve(&curve, p)
                    && u > inner
                    && u < 1.0 - inner
                {
                    own.push(p);
                    true_sq += d * d;
                }
            }
            if own.len() >= 10 {
                self.sum_sq += tls_sum_sq(&own);
                self.sum_sq_true += true_sq;
                self.points += own.len();
                self.edges += 1;
            }
        }
    }

    /// RMS residual (px) over all measured points.
    pub fn rms(&self) -> f64 {
        if self.points > 0 {
            (self.sum_sq / self.points as f64).sqrt()
        } else {
            0.0
        }
    }

    /// RMS distance (px) of the measured points from their true edges (as
    /// seen in the image): the accuracy of single edge points.
    pub fn rms_to_truth(&self) -> f64 {
        if self.points > 0 {
            (self.sum_sq_true / self.points as f64).sqrt()
        } else {
            0.0
        }
    }

    pub fn edges(&self) -> usize {
        self.edges
    }
}

fn bbox(c: &[Point], pad: f64) -> (Point, Point) {
    let mut lo = Point::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point::new(-f64::INFINITY, -f64::INFINITY);
    for p in c {
        lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (
        Point::new(lo.x - pad, lo.y - pad),
        Point::new(hi.x + pad, hi.y + pad),
    )
}

/// The distance of `p` from the polyline and its curve parameter (0–1),
/// when it lies within [`NEAR`] of it.
fn near_curve(c: &[Point], p: Point) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    let n = c.len().saturating_sub(1).max(1) as f64;
    for (k, w) in c.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((p.x - a.x) * dx + (p.y - a.y) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = p.dist(Point::new(a.x + t * dx, a.y + t * dy));
        if d <= NEAR && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, (k as f64 + t) / n));
        }
    }
    best
}

/// Sum of squared perpendicular distances from the TLS line of the points:
/// the smaller eigenvalue of the scatter matrix.
fn tls_sum_sq(p: &[Point]) -> f64 {
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.x).sum::<f64>() / n,
        p.iter().map(|q| q.y).sum::<f64>() / n,
    );
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for q in p {
        let (x, y) = (q.x - mx, q.y - my);
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    let tr = sxx + syy;
    let det = sxx * syy - sxy * sxy;
    (0.5 * tr - (0.25 * tr * tr - det).max(0.0).sqrt()).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::{EdgePoint, ScanDir};

    fn pts(dir: ScanDir, p: &[(f64, f64)]) -> EdgePoints {
        EdgePoints {
            dir: Some(dir),
            width: 200,
            height: 200,
            points: p
                .iter()
                .map(|&(x, y)| EdgePoint {
                    x: x as f32,
                    y: y as f32,
                    response: 10.0,
                })
                .collect(),
        }
    }

    #[test]
    fn bent_points_have_a_larger_residual_than_straight_ones() {
        let t = [Segment::new(
            Point::new(50.0, 10.0),
            Point::new(50.0, 150.0),
        )];
        let v = pts(ScanDir::Vertical, &[]);
        // Straight points with ±0.1 px alternation.
        let s: Vec<(f64, f64)> = (10..=150)
            .map(|y| (50.0 + if y % 2 == 0 { 0.1 } else { -0.1 }, y as f64))
            .collect();
        let mut a = Straightness::default();
        a.add(&t, &pts(ScanDir::Horizontal, &s), &v, &|p| p);
        assert!((a.rms() - 0.1).abs() < 0.01, "{}", a.rms());
        assert!(
            (a.rms_to_truth() - 0.1).abs() < 1e-4,
            "{}",
            a.rms_to_truth()
        );
        // Bent by a parabola of 1 px sagitta.
        let bend = |p: Point| {
            let u = (p.y - 80.0) / 70.0;
            Point::new(p.x + 1.0 - u * u, p.y)
        };
        let b_pts: Vec<(f64, f64)> = (10..=150)
            .map(|y| {
                let q = bend(Point::new(50.0, y as f64));
                (q.x, q.y)
            })
            .collect();
        let mut b = Straightness::default();
        b.add(&t, &pts(ScanDir::Horizontal, &b_pts), &v, &bend);
        assert!(b.rms() > 0.2, "{}", b.rms());
        assert_eq!(b.edges(), 1);
    }
}
