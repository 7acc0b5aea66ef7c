//! Shadow lines (llv.md §6): two images of one view, lit by two lights placed
//! close together. An object edge is where it is whatever the light; the
//! edge of a cast shadow is the light's projection of an occluding edge, so
//! when the light moves a little, the shadow edge moves (shifts, or turns
//! about the point where the shadow touches its object). Comparing the line
//! sets of the two images separates them.
//!
//! For each line `s` of the first set, the lines `t` of the second set that
//! could be the same edge are those within [`ShadowParams::max_angle_deg`] of
//! its direction that overlap at least [`ShadowParams::min_overlap`] of the
//! shorter of the two along `s`, and lie within
//! [`ShadowParams::max_shift`] of it. The displacement of such a `t` is the
//! larger of the perpendicular distances of the ends of the overlap from
//! `s`'s line (a turning shadow edge moves most at its far end).
//! - Some candidate displaced at most [`ShadowParams::stay_tolerance`]: the
//!   line **stays** — an object edge (`shadow = false`).
//! - Otherwise, some candidate displaced more: the line **moved** — a shadow
//!   edge (`shadow = true`).
//! - No candidate at all: the edge shows under one light only; nothing can be
//!   said, and the flag is left as it was.

use serde::{Deserialize, Serialize};

use super::{Point, Segment};

/// What decides that a line stayed or moved between the two images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShadowParams {
    /// A line displaced by at most this (px) stayed. Line positions from
    /// subpixel edge points repeat within a few tenths of a pixel, so 1 px
    /// leaves room for noise without taking a real shift for a stay.
    pub stay_tolerance: f64,
    /// Lines farther apart than this (px) are not the same edge. With lights
    /// "close together" shadow edges move a few pixels; 15 px is generous.
    pub max_shift: f64,
    /// Largest direction difference (degrees) of two lines that can be the
    /// same edge; a shadow edge turns a little as the light moves.
    pub max_angle_deg: f64,
    /// Least overlap along the line, as a fraction of the shorter line.
    pub min_overlap: f64,
}

impl Default for ShadowParams {
    fn default() -> Self {
        ShadowParams {
            stay_tolerance: 1.0,
            max_shift: 15.0,
            max_angle_deg: 10.0,
            min_overlap: 0.5,
        }
    }
}

/// What happened to one line of the first image in the second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Found at the same place: an object edge.
    Stayed,
    /// Found displaced: a shadow edge.
    Moved,
    /// Not found in the second image.
    Unmatched,
}

/// The lines of `a` (the first image), each with `shadow` set when it moved
/// in `b` (the second image, light moved a little) and cleared when it
/// stayed; unmatched lines keep their flag. Order and geometry are kept.
pub fn flag_shadows(a: &[Segment], b: &[Segment], p: &ShadowParams) -> Vec<Segment> {
    a.iter()
        .map(|s| {
            let mut s = *s;
            match motion(&s, b, p) {
                Motion::Stayed => s.shadow = false,
                Motion::Moved => s.shadow = true,
                Motion::Unmatched => {}
            }
            s
        })
        .collect()
}

/// Classifies one line of the first image against the second image's lines.
pub fn motion(s: &Segment, b: &[Segment], p: &ShadowParams) -> Motion {
    let mut best: Option<f64> = None;
    for t in b {
        if let Some(d) = displacement(s, t, p) {
            best = Some(best.map_or(d, |m: f64| m.min(d)));
        }
    }
    match best {
        None => Motion::Unmatched,
        Some(d) if d <= p.stay_tolerance => Motion::Stayed,
        Some(_) => Motion::Moved,
    }
}

/// The displacement of `t` relative to `s` (px) when `t` can be the same edge
/// (module doc); `None` otherwise.
fn displacement(s: &Segment, t: &Segment, p: &ShadowParams) -> Option<f64> {
    let len = s.length();
    let tlen = t.length();
    if !(len > 0.0 && tlen > 0.0) {
        return None;
    }
    let u = ((s.b.x - s.a.x) / len, (s.b.y - s.a.y) / len);
    let v = ((t.b.x - t.a.x) / tlen, (t.b.y - t.a.y) / tlen);
    let angle = (u.0 * v.1 - u.1 * v.0)
        .abs()
        .atan2((u.0 * v.0 + u.1 * v.1).abs());
    if angle.to_degrees() > p.max_angle_deg {
        return None;
    }
    // Positions along s and signed distances from s's line.
    let along = |q: Point| (q.x - s.a.x) * u.0 + (q.y - s.a.y) * u.1;
    let across = |q: Point| (q.x - s.a.x) * -u.1 + (q.y - s.a.y) * u.0;
    let (ta, tb) = (along(t.a), along(t.b));
    let (t0, t1) = (ta.min(tb), ta.max(tb));
    let (o0, o1) = (t0.max(0.0), t1.min(len));
    let overlap = o1 - o0;
    if overlap <= 0.0 || overlap < p.min_overlap * len.min(tlen) {
        return None;
    }
    // t's distance from s's line, interpolated at the two ends of the overlap.
    let (da, db) = (across(t.a), across(t.b));
    let at = |x: f64| {
        if tb == ta {
            da
        } else {
            da + (db - da) * (x - ta) / (tb - ta)
        }
    };
    let d = at(o0).abs().max(at(o1).abs());
    (d <= p.max_shift).then_some(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    #[test]
    fn staying_lines_are_edges_moving_lines_are_shadows() {
        let p = ShadowParams::default();
        let a = vec![
            seg(10.0, 10.0, 10.0, 90.0),  // object edge
            seg(50.0, 10.0, 80.0, 60.0),  // shadow edge: shifts 4 px
            seg(20.0, 95.0, 90.0, 95.0),  // shadow edge turning about (20, 95)
            seg(100.0, 5.0, 100.0, 40.0), // only under light a
        ];
        let b = vec![
            seg(10.3, 12.0, 10.2, 88.0),
            seg(54.0, 10.0, 84.0, 60.0),
            seg(20.0, 95.0, 90.0, 100.0),
        ];
        let f = flag_shadows(&a, &b, &p);
        assert_eq!(
            f.iter().map(|s| s.shadow).collect::<Vec<_>>(),
            [false, true, true, false]
        );
        assert_eq!(motion(&a[3], &b, &p), Motion::Unmatched);
        // Geometry untouched.
        for (x, y) in f.iter().zip(&a) {
            assert_eq!((x.a, x.b), (y.a, y.b));
        }
    }

    #[test]
    fn a_stayed_copy_wins_over_a_moved_neighbour() {
        // A shadow edge of b happens to run near an object edge of a: the
        // object edge is still found in place.
        let p = ShadowParams::default();
        let a = vec![seg(10.0, 10.0, 10.0, 90.0)];
        let b = vec![seg(14.0, 10.0, 14.0, 90.0), seg(10.0, 10.0, 10.0, 90.0)];
        assert!(!flag_shadows(&a, &b, &p)[0].shadow);
    }

    #[test]
    fn unrelated_lines_do_not_match() {
        let p = ShadowParams::default();
        let s = seg(10.0, 10.0, 10.0, 90.0);
        // Crossing, far, or not overlapping.
        for t in [
            seg(0.0, 50.0, 40.0, 50.0),
            seg(40.0, 10.0, 40.0, 90.0),
            seg(12.0, 120.0, 12.0, 200.0),
        ] {
            assert_eq!(motion(&s, &[t], &p), Motion::Unmatched, "{t:?}");
        }
        // Unmatched keeps an existing flag.
        let mut flagged = s;
        flagged.shadow = true;
        assert!(flag_shadows(&[flagged], &[], &p)[0].shadow);
    }
}
