//! Incremental total-least-squares line fitting (llv.md §3.2) and the
//! perpendicular projection onto the fitted line (§3.3).
//!
//! The sums are kept in `f64` relative to the first point added, so that
//! image coordinates of a few thousand pixels do not cancel catastrophically
//! in `Sxx - Sx²/n`. Points may carry weights (CONNECT weights endpoints by
//! segment length); adding one is O(1).

use super::Point;

/// A line `a x + b y + c = 0` with `a² + b² = 1`. The normal is made unique:
/// `b > 0`, or `b == 0` and `a > 0` (so a vertical line is `a = 1, b = 0` and
/// a horizontal one `a = 0, b = 1`, as llv.md §3.2 writes them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl Line {
    /// Signed distance of `p` from the line.
    pub fn distance(&self, p: Point) -> f64 {
        self.a * p.x + self.b * p.y + self.c
    }

    /// The foot of the perpendicular from `p` (§3.3).
    pub fn project(&self, p: Point) -> Point {
        let d = self.distance(p);
        Point::new(p.x - self.a * d, p.y - self.b * d)
    }

    /// A unit vector along the line: the normal turned by +90° in image
    /// coordinates, `(-b, a)`.
    pub fn direction(&self) -> (f64, f64) {
        (-self.b, self.a)
    }

    /// The intersection with another line; `None` when (nearly) parallel.
    pub fn intersect(&self, o: &Line) -> Option<Point> {
        let det = self.a * o.b - self.b * o.a;
        if det.abs() < 1e-9 {
            return None;
        }
        let x = (self.b * o.c - o.b * self.c) / det;
        let y = (o.a * self.c - self.a * o.c) / det;
        (x.is_finite() && y.is_finite()).then_some(Point::new(x, y))
    }
}

/// Running sums of a (weighted) point set, centred on the first point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LineFit {
    origin: Point,
    w: f64,
    sx: f64,
    sy: f64,
    sxx: f64,
    syy: f64,
    sxy: f64,
    count: usize,
}

impl LineFit {
    pub fn new() -> Self {
        LineFit::default()
    }

    /// Adds a point of weight 1.
    pub fn add(&mut self, p: Point) {
        self.add_weighted(p, 1.0);
    }

    /// Adds a point with weight `w` (> 0; others are ignored).
    pub fn add_weighted(&mut self, p: Point, w: f64) {
        if w.is_nan() || w <= 0.0 || !p.x.is_finite() || !p.y.is_finite() {
            return;
        }
        if self.count == 0 {
            self.origin = p;
        }
        let x = p.x - self.origin.x;
        let y = p.y - self.origin.y;
        self.w += w;
        self.sx += w * x;
        self.sy += w * y;
        self.sxx += w * x * x;
        self.syy += w * y * y;
        self.sxy += w * x * y;
        self.count += 1;
    }

    /// [`LineFit::add`] of a point known to be finite (every point the line
    /// extractor files is): the same sums, without the checks.
    #[inline]
    pub fn add_finite(&mut self, p: Point) {
        debug_assert!(p.x.is_finite() && p.y.is_finite());
        if self.count == 0 {
            self.origin = p;
        }
        // `add_weighted` with `w = 1`: `1 · x` is `x` exactly.
        let x = p.x - self.origin.x;
        let y = p.y - self.origin.y;
        self.w += 1.0;
        self.sx += x;
        self.sy += y;
        self.sxx += x * x;
        self.syy += y * y;
        self.sxy += x * y;
        self.count += 1;
    }

    /// Number of points added.
    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Total weight (the point count for unweighted fits).
    pub fn weight(&self) -> f64 {
        self.w
    }

    /// The (weighted) mean of the points.
    pub fn mean(&self) -> Option<Point> {
        (self.w > 0.0).then(|| {
            Point::new(
                self.origin.x + self.sx / self.w,
                self.origin.y + self.sy / self.w,
            )
        })
    }

    /// The centred scatter matrix entries `(S'11, S'22, S'12)`.
    fn scatter(&self) -> (f64, f64, f64) {
        let n = self.w;
        (
            self.sxx - self.sx * self.sx / n,
            self.syy - self.sy * self.sy / n,
            self.sxy - self.sx * self.sy / n,
        )
    }

    /// The total-least-squares line, `None` with fewer than two distinct
    /// points. The major axis angle is `½ atan2(2 S'12, S'11 - S'22)`: no
    /// `tan`, stable at every orientation.
    pub fn line(&self) -> Option<Line> {
        if self.count < 2 || self.w <= 0.0 {
            return None;
        }
        let (s11, s22, s12) = self.scatter();
        let spread = s11 + s22;
        if spread.is_nan() || spread <= 1e-12 * (1.0 + self.w) {
            return None;
        }
        let (mut a, mut b) = if s12 == 0.0 {
            // Axis-aligned: vertical (a=1, b=0) or horizontal (a=0, b=1).
            if s11 < s22 { (1.0, 0.0) } else { (0.0, 1.0) }
        } else {
            let theta = 0.5 * (2.0 * s12).atan2(s11 - s22);
            let (sin, cos) = theta.sin_cos();
            // Direction (cos, sin) in image coordinates; normal (-sin, cos).
            (-sin, cos)
        };
        if b < 0.0 || (b == 0.0 && a < 0.0) {
            a = -a;
            b = -b;
        }
        let m = self.mean()?;
        Some(Line {
            a,
            b,
            c: -(a * m.x + b * m.y),
        })
    }

    /// An (unnormalised) vector along the fitted line, without trigonometry:
    /// the eigenvector of the largest eigenvalue of the scatter matrix, from
    /// whichever of its two closed forms is better conditioned. The line
    /// extractor calls this after every added point.
    pub fn major_axis(&self) -> Option<(f64, f64)> {
        if self.count < 2 || self.w <= 0.0 {
            return None;
        }
        let (s11, s22, s12) = self.scatter();
        axis_of(s11, s22, s12)
    }

    /// The mean and [`LineFit::major_axis`] together, with one division
    /// and one square root (the line extractor's prediction after every
    /// point it takes).
    #[inline]
    pub fn mean_and_axis(&self) -> Option<(Point, (f64, f64))> {
        if self.count < 2 || self.w <= 0.0 {
            return None;
        }
        let inv = 1.0 / self.w;
        let (mx, my) = (self.sx * inv, self.sy * inv);
        let s11 = self.sxx - self.sx * mx;
        let s22 = self.syy - self.sy * my;
        let s12 = self.sxy - self.sx * my;
        let mean = Point::new(self.origin.x + mx, self.origin.y + my);
        axis_of(s11, s22, s12).map(|v| (mean, v))
    }

    /// Projects `p` onto the fitted line (the point itself without a line).
    pub fn project(&self, p: Point) -> Point {
        self.line().map_or(p, |l| l.project(p))
    }

    /// The line's direction angle (llv.md §0 convention, in (-π/2, π/2]).
    pub fn angle(&self) -> Option<f64> {
        self.line().map(|l| {
            let (dx, dy) = l.direction();
            let ang = (-dy).atan2(dx);
            if ang <= -std::f64::consts::FRAC_PI_2 {
                ang + std::f64::consts::PI
            } else if ang > std::f64::consts::FRAC_PI_2 {
                ang - std::f64::consts::PI
            } else {
                ang
            }
        })
    }

    /// Weighted mean square perpendicular distance: the smallest eigenvalue
    /// of the scatter matrix over the weight.
    pub fn mean_square_residual(&self) -> f64 {
        if self.count < 2 || self.w <= 0.0 {
            return 0.0;
        }
        let (s11, s22, s12) = self.scatter();
        let half = 0.5 * (s11 - s22);
        let lmin = 0.5 * (s11 + s22) - half.hypot(s12);
        (lmin / self.w).max(0.0)
    }

    /// RMS perpendicular distance of the points from the fitted line (px).
    pub fn rms_residual(&self) -> f64 {
        self.mean_square_residual().sqrt()
    }
}

/// The major axis of the centred scatter matrix `[[s11, s12], [s12, s22]]`
/// (unnormalised), or none where the points are too close to one.
#[inline]
fn axis_of(s11: f64, s22: f64, s12: f64) -> Option<(f64, f64)> {
    let half = 0.5 * (s11 - s22);
    // `sqrt` of the sum rather than `hypot`: the scatter entries are far
    // from overflow, and `hypot` is a libm call the extractor made after
    // every point.
    let lmax = 0.5 * (s11 + s22) + (half * half + s12 * s12).sqrt();
    let v1 = (s12, lmax - s11);
    let v2 = (lmax - s22, s12);
    let n1 = v1.0 * v1.0 + v1.1 * v1.1;
    let n2 = v2.0 * v2.0 + v2.1 * v2.1;
    let v = if n1 >= n2 { v1 } else { v2 };
    let n = n1.max(n2);
    (n > 1e-24 * (1.0 + lmax * lmax) && n.is_finite()).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn axis_aligned_lines_follow_the_spec_normals() {
        let mut v = LineFit::new();
        for y in 0..5 {
            v.add(Point::new(3.0, y as f64));
        }
        let l = v.line().unwrap();
        assert_eq!((l.a, l.b), (1.0, 0.0));
        assert!((l.c + 3.0).abs() < 1e-12);
        let mut h = LineFit::new();
        for x in 0..5 {
            h.add(Point::new(x as f64, -2.0));
        }
        let l = h.line().unwrap();
        assert!(l.a.abs() < 1e-12 && (l.b - 1.0).abs() < 1e-12);
        assert!((l.c - 2.0).abs() < 1e-12);
        assert!(h.rms_residual() < 1e-9);
    }

    #[test]
    fn degenerate_sets_have_no_line() {
        let mut f = LineFit::new();
        assert!(f.line().is_none());
        f.add(Point::new(1.0, 1.0));
        f.add(Point::new(1.0, 1.0));
        assert!(f.line().is_none());
        assert_eq!(f.project(Point::new(5.0, 5.0)), Point::new(5.0, 5.0));
    }

    #[test]
    fn add_finite_gives_the_sums_of_add() {
        let (mut a, mut b) = (LineFit::new(), LineFit::new());
        for k in 0..50 {
            let p = Point::new(100.0 + 0.37 * k as f64, 20.0 - 1.3 * (k * k % 7) as f64);
            a.add(p);
            b.add_finite(p);
            assert_eq!(a, b);
        }
    }

    #[test]
    fn residual_of_a_noisy_band() {
        let mut f = LineFit::new();
        for i in 0..100 {
            f.add(Point::new(i as f64, 10.5));
            f.add(Point::new(i as f64, 9.5));
        }
        assert!((f.rms_residual() - 0.5).abs() < 1e-9);
    }

    proptest! {
        #[test]
        fn points_of_a_known_line_give_that_line(
            x0 in -3000.0f64..3000.0, y0 in -3000.0f64..3000.0,
            ang in -3.2f64..3.2, n in 2usize..60, step in 0.05f64..5.0,
        ) {
            let (s, c) = ang.sin_cos();
            let mut f = LineFit::new();
            for k in 0..n {
                let t = k as f64 * step;
                f.add(Point::new(x0 + t * c, y0 + t * s));
            }
            let l = f.line().unwrap();
            // The normal is perpendicular to (c, s) ...
            prop_assert!((l.a * c + l.b * s).abs() < 1e-7);
            prop_assert!(((l.a * l.a + l.b * l.b) - 1.0).abs() < 1e-12);
            // ... and every point lies on the line.
            for k in 0..n {
                let t = k as f64 * step;
                prop_assert!(l.distance(Point::new(x0 + t * c, y0 + t * s)).abs() < 1e-6);
            }
            prop_assert!(f.rms_residual() < 1e-5);
            let p = l.project(Point::new(x0 + 7.0, y0 - 3.0));
            prop_assert!(l.distance(p).abs() < 1e-7);
        }
    }
}
