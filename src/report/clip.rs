//! Where the vector layers of a report may draw: the picture grown by its own
//! size on every side. Segments are clipped to that box and edge points
//! outside it are left out, so a vertex at 1e300 in a line file becomes a
//! line running off the picture, not a 300-digit number that Ghostscript
//! refuses (`/limitcheck`) and SVG viewers choke on. PostScript and SVG both
//! use this one box.
//!
//! The box is generous on purpose: both writers clip to the picture frame
//! themselves (`frame clip`, the SVG `viewBox`), so everything that shows is
//! drawn exactly as before, and the numbers written stay within [-1, 2] of
//! the unit square.

use crate::llv::{Point, Segment};

/// The drawing box of a `width × height` picture, in pixels:
/// `[-W, 2W] × [-H, 2H]` (a side of 0 counts as 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawBox {
    min: Point,
    max: Point,
}

const LEFT: u8 = 1;
const RIGHT: u8 = 2;
const TOP: u8 = 4;
const BOTTOM: u8 = 8;

impl DrawBox {
    /// The box around a picture of `width × height` pixels.
    pub fn around(width: usize, height: usize) -> DrawBox {
        let (w, h) = (width.max(1) as f64, height.max(1) as f64);
        DrawBox {
            min: Point::new(-w, -h),
            max: Point::new(2.0 * w, 2.0 * h),
        }
    }

    /// Whether `p` is inside the box (edges included); false for NaN.
    pub fn contains(&self, p: Point) -> bool {
        self.outcode(p) == 0 && p.x.is_finite() && p.y.is_finite()
    }

    fn outcode(&self, p: Point) -> u8 {
        let mut c = 0;
        if p.x < self.min.x {
            c |= LEFT;
        } else if p.x > self.max.x {
            c |= RIGHT;
        }
        if p.y < self.min.y {
            c |= TOP;
        } else if p.y > self.max.y {
            c |= BOTTOM;
        }
        c
    }

    /// The part of `s` inside the box, with its attributes and direction
    /// (`a` stays the end nearer the original `a`), or `None` when none of it
    /// is inside or a coordinate is not finite.
    ///
    /// Cohen–Sutherland: an end outside is moved onto the boundary it lies
    /// beyond, that coordinate set exactly and the other interpolated from
    /// whichever end is nearer the boundary, so a far end (1e300) does not
    /// swamp the result. Coordinates whose differences would overflow are
    /// halved first (exact in binary) and doubled back. A segment with both
    /// ends far off (beyond about 10^15 picture sizes) cannot be placed near
    /// the picture to better than f64 allows; it is still kept in the box.
    pub fn clip(&self, s: &Segment) -> Option<Segment> {
        if ![s.a.x, s.a.y, s.b.x, s.b.y].iter().all(|v| v.is_finite()) {
            return None;
        }
        let k = if (s.b.x - s.a.x).is_finite() && (s.b.y - s.a.y).is_finite() {
            1.0
        } else {
            0.5
        };
        let scale = |p: Point| Point::new(p.x * k, p.y * k);
        let bx = DrawBox {
            min: scale(self.min),
            max: scale(self.max),
        };
        let (mut a, mut b) = (scale(s.a), scale(s.b));
        // Each pass puts one end exactly on a boundary; four suffice, the
        // rest allow for rounding near a corner.
        for _ in 0..16 {
            let (ca, cb) = (bx.outcode(a), bx.outcode(b));
            if ca | cb == 0 {
                break;
            }
            if ca & cb != 0 {
                return None;
            }
            if ca != 0 {
                a = bx.onto_boundary(a, b, ca);
            } else {
                b = bx.onto_boundary(b, a, cb);
            }
        }
        let back = |p: Point| {
            Point::new(
                (p.x / k).clamp(self.min.x, self.max.x),
                (p.y / k).clamp(self.min.y, self.max.y),
            )
        };
        Some(Segment {
            a: back(a),
            b: back(b),
            ..*s
        })
    }

    /// Where the line `p`–`q` crosses the first boundary in `code` that `p`
    /// lies beyond (`q` is not beyond it, so the crossing exists).
    fn onto_boundary(&self, p: Point, q: Point, code: u8) -> Point {
        if code & (LEFT | RIGHT) != 0 {
            let x = if code & LEFT != 0 {
                self.min.x
            } else {
                self.max.x
            };
            Point::new(x, cross(p.x, p.y, q.x, q.y, x))
        } else {
            let y = if code & TOP != 0 {
                self.min.y
            } else {
                self.max.y
            };
            Point::new(cross(p.y, p.x, q.y, q.x, y), y)
        }
    }
}

/// The other coordinate where the line from `(v0, u0)` to `(v1, u1)` reaches
/// `v = vb` (`vb` between `v0` and `v1`), interpolated from the end nearer
/// to `vb`.
fn cross(v0: f64, u0: f64, v1: f64, u1: f64, vb: f64) -> f64 {
    if (vb - v0).abs() <= (vb - v1).abs() {
        u0 + (u1 - u0) * ((vb - v0) / (v1 - v0))
    } else {
        u1 + (u0 - u1) * ((vb - v1) / (v0 - v1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    fn close(p: Point, x: f64, y: f64) -> bool {
        (p.x - x).abs() < 1e-9 && (p.y - y).abs() < 1e-9
    }

    #[test]
    fn segments_inside_are_untouched() {
        let b = DrawBox::around(100, 50);
        let s = Segment {
            shadow: true,
            response: -3.0,
            ..seg(-100.0, 0.0, 200.0, 100.0)
        };
        assert_eq!(b.clip(&s), Some(s));
    }

    #[test]
    fn far_ends_are_cut_at_the_box_keeping_the_direction() {
        let b = DrawBox::around(100, 100);
        // A diagonal to 1e300 keeps running along y = x.
        let c = b.clip(&seg(50.0, 50.0, 1e300, 1e300)).unwrap();
        assert!(close(c.a, 50.0, 50.0) && close(c.b, 200.0, 200.0), "{c:?}");
        // A far end off to one side: the line through the picture is nearly
        // horizontal at y = 50, and the near end stays `b`.
        let c = b.clip(&seg(1e300, 5.0, 50.0, 50.0)).unwrap();
        assert!(close(c.a, 200.0, 50.0) && close(c.b, 50.0, 50.0), "{c:?}");
        // Ends whose difference overflows f64.
        let c = b.clip(&seg(-f64::MAX, 50.0, f64::MAX, 50.0)).unwrap();
        assert!(close(c.a, -100.0, 50.0) && close(c.b, 200.0, 50.0), "{c:?}");
        let c = b.clip(&seg(50.0, 50.0, f64::MAX, f64::MAX)).unwrap();
        assert!(close(c.a, 50.0, 50.0) && close(c.b, 200.0, 200.0), "{c:?}");
        // Both ends absurdly far: f64 cannot place the line precisely, but
        // what is drawn stays in the box.
        let c = b
            .clip(&seg(-f64::MAX, -f64::MAX, f64::MAX, f64::MAX))
            .unwrap();
        assert!(b.contains(c.a) && b.contains(c.b), "{c:?}");
        // Both ends outside, through the picture.
        let c = b.clip(&seg(-1000.0, 25.0, 1000.0, 75.0)).unwrap();
        assert!(close(c.a, -100.0, 47.5) && close(c.b, 200.0, 55.0), "{c:?}");
    }

    #[test]
    fn segments_outside_or_not_finite_are_left_out() {
        let b = DrawBox::around(100, 100);
        assert_eq!(b.clip(&seg(300.0, 0.0, 1e300, 50.0)), None);
        // Both ends outside on different sides, missing the box's corner.
        assert_eq!(b.clip(&seg(150.0, -1e6, 1e6, 150.0)), None);
        assert_eq!(b.clip(&seg(f64::NAN, 0.0, 1.0, 1.0)), None);
        assert_eq!(b.clip(&seg(f64::INFINITY, 0.0, 1.0, 1.0)), None);
    }

    #[test]
    fn contains_is_the_same_box() {
        let b = DrawBox::around(10, 20);
        assert!(b.contains(Point::new(-10.0, 40.0)));
        assert!(!b.contains(Point::new(20.5, 0.0)));
        assert!(!b.contains(Point::new(f64::NAN, 0.0)));
    }
}
