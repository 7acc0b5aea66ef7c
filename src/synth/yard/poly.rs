//! Convex polygons in the image plane and the exact area arithmetic the
//! yard renderer is built on: clipping by half-planes (Sutherland–Hodgman),
//! area and centroid (shoelace), and the difference of two convex polygons
//! as a few convex pieces.
//!
//! The renderer needs, for each pixel footprint, the exact area each facet
//! covers after the facets in front of it took their share; these three
//! operations give it without any sampling.

/// A point (ideal px).
pub type P2 = (f64, f64);

/// A half-plane `a·x + b·y + c ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl Plane {
    pub fn eval(&self, p: P2) -> f64 {
        self.a * p.0 + self.b * p.1 + self.c
    }

    fn flipped(&self) -> Plane {
        Plane {
            a: -self.a,
            b: -self.b,
            c: -self.c,
        }
    }
}

/// A convex polygon, counter-clockwise in image coordinates as stored (its
/// planes point inward), with its bounding box.
#[derive(Clone, Debug, PartialEq)]
pub struct Convex {
    pub pts: Vec<P2>,
    pub planes: Vec<Plane>,
    /// `[x0, y0, x1, y1]`.
    pub bbox: [f64; 4],
}

impl Convex {
    /// The convex polygon through `pts` (either orientation; at least three
    /// points not all on one line). `None` for a degenerate polygon.
    pub fn new(mut pts: Vec<P2>) -> Option<Convex> {
        pts.dedup_by(|a, b| (a.0 - b.0).hypot(a.1 - b.1) < 1e-9);
        if pts.len() < 3 {
            return None;
        }
        let (area, _, _) = area_centroid(&pts);
        if area.is_nan() || area.abs() <= 1e-9 {
            return None;
        }
        if area < 0.0 {
            pts.reverse();
        }
        let n = pts.len();
        let mut planes = Vec::with_capacity(n);
        for i in 0..n {
            let (p, q) = (pts[i], pts[(i + 1) % n]);
            let (dx, dy) = (q.0 - p.0, q.1 - p.1);
            let l = dx.hypot(dy);
            if l < 1e-12 {
                continue;
            }
            // Positive area (x right, y down, shoelace) means the interior
            // lies to the left of each edge direction in these coordinates.
            let (a, b) = (-dy / l, dx / l);
            planes.push(Plane {
                a,
                b,
                c: -(a * p.0 + b * p.1),
            });
        }
        // Convexity: every vertex inside every plane.
        if pts
            .iter()
            .any(|&v| planes.iter().any(|pl| pl.eval(v) < -1e-7))
        {
            return None;
        }
        let mut bbox = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
        for &(x, y) in &pts {
            bbox = [
                bbox[0].min(x),
                bbox[1].min(y),
                bbox[2].max(x),
                bbox[3].max(y),
            ];
        }
        Some(Convex { pts, planes, bbox })
    }

    /// Whether `p` is inside (or within `tol` px outside) the polygon.
    pub fn contains(&self, p: P2, tol: f64) -> bool {
        p.0 >= self.bbox[0] - tol
            && p.0 <= self.bbox[2] + tol
            && p.1 >= self.bbox[1] - tol
            && p.1 <= self.bbox[3] + tol
            && self.planes.iter().all(|pl| pl.eval(p) >= -tol)
    }

    /// The edges as `(start, end)` pairs, in order.
    pub fn edges(&self) -> impl Iterator<Item = (P2, P2)> + '_ {
        let n = self.pts.len();
        (0..n).map(move |i| (self.pts[i], self.pts[(i + 1) % n]))
    }

    /// How the polygon relates to the convex polygon `q`: `Inside` when `q`
    /// lies wholly inside it, `Outside` when some edge of it separates `q`
    /// (a sufficient test, exact for the small footprints it is used on
    /// when combined with the bounding boxes), else `Partial`.
    pub fn relation(&self, q: &[P2]) -> Relation {
        let mut all_in = true;
        for pl in &self.planes {
            let mut any_in = false;
            for &v in q {
                if pl.eval(v) >= 0.0 {
                    any_in = true;
                } else {
                    all_in = false;
                }
            }
            if !any_in {
                return Relation::Outside;
            }
        }
        if all_in {
            Relation::Inside
        } else {
            Relation::Partial
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Relation {
    Inside,
    Outside,
    Partial,
}

/// The part of polygon `poly` inside the half-plane (Sutherland–Hodgman for
/// one plane), written to `out`.
pub fn clip(poly: &[P2], pl: &Plane, out: &mut Vec<P2>) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let (ep, eq) = (pl.eval(p), pl.eval(q));
        if ep >= 0.0 {
            out.push(p);
        }
        if (ep >= 0.0) != (eq >= 0.0) {
            let t = ep / (ep - eq);
            out.push((p.0 + (q.0 - p.0) * t, p.1 + (q.1 - p.1) * t));
        }
    }
    if out.len() < 3 {
        out.clear();
    }
}

/// Signed area (positive counter-clockwise as the constructor orients) and
/// centroid of a polygon; the centroid is the vertex mean when the area
/// vanishes.
pub fn area_centroid(poly: &[P2]) -> (f64, f64, f64) {
    let n = poly.len();
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    if n == 0 {
        return (0.0, 0.0, 0.0);
    }
    // Relative to the first vertex, for precision far from the origin.
    let o = poly[0];
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let (px, py, qx, qy) = (p.0 - o.0, p.1 - o.1, q.0 - o.0, q.1 - o.1);
        let cr = px * qy - qx * py;
        a += cr;
        cx += (px + qx) * cr;
        cy += (py + qy) * cr;
    }
    if a.abs() < 1e-15 {
        let m = poly.iter().fold((0.0, 0.0), |s, p| (s.0 + p.0, s.1 + p.1));
        return (0.0, m.0 / n as f64, m.1 / n as f64);
    }
    (0.5 * a, o.0 + cx / (3.0 * a), o.1 + cy / (3.0 * a))
}

/// Splits `piece` by the convex polygon `f`: `inside` receives `piece ∩ f`
/// (possibly empty) and `outside` gets `piece \ f` appended as convex pieces
/// (one per plane of `f` that cuts it).
pub fn split(
    piece: &[P2],
    f: &Convex,
    inside: &mut Vec<P2>,
    outside: &mut Vec<Vec<P2>>,
    tmp: &mut Vec<P2>,
) {
    inside.clear();
    inside.extend_from_slice(piece);
    for pl in &f.planes {
        if inside.is_empty() {
            break;
        }
        clip(inside, &pl.flipped(), tmp);
        if !tmp.is_empty() && area_centroid(tmp).0.abs() > 1e-12 {
            outside.push(tmp.clone());
        }
        clip(inside, pl, tmp);
        std::mem::swap(inside, tmp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, s: f64) -> Vec<P2> {
        vec![(x0, y0), (x0 + s, y0), (x0 + s, y0 + s), (x0, y0 + s)]
    }

    #[test]
    fn clipping_a_square_by_a_diagonal_halves_it() {
        let sq = square(0.0, 0.0, 1.0);
        let pl = Plane {
            a: -1.0,
            b: -1.0,
            c: 1.0,
        }; // x + y ≤ 1
        let mut out = Vec::new();
        clip(&sq, &pl, &mut out);
        let (a, cx, cy) = area_centroid(&out);
        assert!((a.abs() - 0.5).abs() < 1e-12);
        assert!((cx - 1.0 / 3.0).abs() < 1e-12 && (cy - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn split_conserves_area_and_reports_relations() {
        let f = Convex::new(vec![(0.3, -1.0), (2.0, 0.4), (0.5, 2.0)]).unwrap();
        let px = square(0.0, 0.0, 1.0);
        let (mut ins, mut outs, mut tmp) = (Vec::new(), Vec::new(), Vec::new());
        split(&px, &f, &mut ins, &mut outs, &mut tmp);
        let a_in = area_centroid(&ins).0.abs();
        let a_out: f64 = outs.iter().map(|p| area_centroid(p).0.abs()).sum();
        assert!((a_in + a_out - 1.0).abs() < 1e-12, "{a_in} + {a_out}");
        assert!(a_in > 0.1 && a_out > 0.1);
        assert_eq!(f.relation(&px), Relation::Partial);
        assert_eq!(f.relation(&square(0.8, 0.4, 0.1)), Relation::Inside);
        assert_eq!(f.relation(&square(5.0, 5.0, 1.0)), Relation::Outside);
        assert!(f.contains((0.9, 0.5), 0.0) && !f.contains((0.0, 1.9), 0.0));
    }

    #[test]
    fn degenerate_and_concave_polygons_are_refused() {
        assert!(Convex::new(vec![(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]).is_none());
        assert!(Convex::new(vec![(0.0, 0.0), (1.0, 0.0)]).is_none());
        let dart = vec![(0.0, 0.0), (2.0, 1.0), (0.0, 2.0), (0.5, 1.0)];
        assert!(Convex::new(dart).is_none());
        // Either orientation gives inward planes.
        let cw = Convex::new(vec![(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]).unwrap();
        assert!(cw.contains((0.5, 0.5), 0.0));
    }
}
