//! Ground truth of a yard scene: every visible boundary between two facets
//! as segments (ideal px), those a detector must find and those it may find
//! or not (don't-care).
//!
//! Each facet edge is walked in ¼-px steps. A point is on a visible boundary
//! when the facet is the front one just inside the edge and the front one
//! just outside lies behind it (a facet in front whose edge coincides
//! reports that boundary itself, so no boundary is counted twice). Its
//! contrast is the difference of the two sides' smooth radiance (light field
//! included, texture left out, saturated at 255) at the point. A point is
//! - *true* when its contrast is at least `min_contrast` and it lies
//!   [`MARGIN`] px or more inside the image (and, for a distorted image,
//!   inside the observed image too);
//! - *don't-care* when it shows some contrast (≥ 1 grey level) but less, or
//!   lies in the border band, where a detector's kernel is cut;
//! - nothing otherwise (hidden, outside the image, or no contrast at all:
//!   two parts of one surface).
//!
//! Runs of points of one kind become segments, their ends found by
//! bisection; true runs shorter than [`MIN_PIECE`] px become don't-care.
//! `Segment.response` holds the run's mean contrast.

use super::poly::P2;
use super::render::Index;
use super::{Facet, YardScene};
use crate::llv::{Point, Segment};

pub use crate::synth::{TRUTH_MARGIN as MARGIN, TRUTH_MIN_PIECE as MIN_PIECE};

/// Offset (px) to each side of an edge where the front facet is looked up.
const EPS: f64 = 0.01;

/// The truth of one image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct YardTruth {
    /// Edges a detector should find (contrast in `response`).
    pub edges: Vec<Segment>,
    /// Edges that count neither for nor against a detector.
    pub dont_care: Vec<Segment>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    None,
    Care,
    DontCare,
}

struct Walker<'a> {
    scene: &'a YardScene,
    index: Index,
    lens_frame: bool,
    min_contrast: f64,
}

impl Walker<'_> {
    fn radiance(&self, f: Option<&Facet>, p: P2) -> f64 {
        match f {
            Some(f) => (self.scene.light.at(p.0, p.1) * f.shade.smooth(p.0, p.1)).min(255.0),
            None => 0.0,
        }
    }

    /// 2: in the core of the image, 1: in the border band, 0: outside.
    fn place(&self, p: P2) -> u8 {
        let (w, h) = (self.scene.width as f64, self.scene.height as f64);
        let class = |x: f64, y: f64| {
            if x >= MARGIN && y >= MARGIN && x <= w - 1.0 - MARGIN && y <= h - 1.0 - MARGIN {
                2
            } else if x >= -0.5 && y >= -0.5 && x <= w - 0.5 && y <= h - 0.5 {
                1
            } else {
                0
            }
        };
        let ideal = class(p.0, p.1);
        if self.lens_frame {
            let (ox, oy) = self.scene.lens.ideal_to_observed_converged(p.0, p.1);
            ideal.min(class(ox, oy))
        } else {
            ideal
        }
    }

    fn kind(&self, fi: usize, p: P2, n: P2) -> (Kind, f64) {
        let none = (Kind::None, 0.0);
        let place = self.place(p);
        if place == 0 {
            return none;
        }
        let facets = &self.scene.facets;
        let inside = (p.0 - EPS * n.0, p.1 - EPS * n.1);
        if self.index.top(facets, inside) != Some(fi) {
            return none;
        }
        let outside = (p.0 + EPS * n.0, p.1 + EPS * n.1);
        let other = self.index.top(facets, outside);
        if other.is_some_and(|g| g >= fi) {
            return none;
        }
        let c = (self.radiance(facets.get(fi), p)
            - self.radiance(other.and_then(|g| facets.get(g)), p))
        .abs();
        if c < 1.0 {
            none
        } else if place == 2 && c >= self.min_contrast {
            (Kind::Care, c)
        } else {
            (Kind::DontCare, c)
        }
    }
}

/// The truth of `scene` as rendered undistorted (`lens_frame` false) or, in
/// ideal coordinates, as seen through its lens and corrected (`true`: only
/// what the distorted image shows counts).
pub fn truth(scene: &YardScene, lens_frame: bool, min_contrast: f64) -> YardTruth {
    let (w, h) = (scene.width as f64, scene.height as f64);
    let mut bounds = [-1.0, -1.0, w, h];
    if lens_frame {
        let b = super::render::ideal_bounds(scene, true);
        bounds = [
            bounds[0].min(b[0]),
            bounds[1].min(b[1]),
            bounds[2].max(b[2]),
            bounds[3].max(b[3]),
        ];
    }
    let wk = Walker {
        scene,
        index: Index::new(&scene.facets, bounds),
        lens_frame,
        min_contrast,
    };
    let mut out = YardTruth::default();
    for (fi, f) in scene.facets.iter().enumerate() {
        for ((p, q), pl) in f.poly.edges().zip(&f.poly.planes) {
            // Skip edges wholly outside the region of interest.
            let (lo_x, hi_x) = (p.0.min(q.0), p.0.max(q.0));
            let (lo_y, hi_y) = (p.1.min(q.1), p.1.max(q.1));
            if hi_x < bounds[0] || lo_x > bounds[2] || hi_y < bounds[1] || lo_y > bounds[3] {
                continue;
            }
            walk(&wk, fi, p, q, (-pl.a, -pl.b), &mut out);
        }
    }
    out
}

fn walk(wk: &Walker, fi: usize, p: P2, q: P2, n: P2, out: &mut YardTruth) {
    let len = (q.0 - p.0).hypot(q.1 - p.1);
    if !(len.is_finite() && len > 1e-6) {
        return;
    }
    let at = |t: f64| (p.0 + (q.0 - p.0) * t, p.1 + (q.1 - p.1) * t);
    let kind = |t: f64| wk.kind(fi, at(t), n);
    let steps = ((len * 4.0).ceil() as usize).clamp(2, 1_000_000);
    // The last parameter of kind `k` between `good` (kind k) and `bad`.
    let refine = |mut good: f64, mut bad: f64, k: Kind| {
        for _ in 0..22 {
            let m = 0.5 * (good + bad);
            if kind(m).0 == k {
                good = m;
            } else {
                bad = m;
            }
        }
        good
    };
    let mut run: Option<(Kind, f64, f64, usize)> = None; // kind, start, Σc, n
    let mut prev_t = 0.0;
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (k, c) = kind(t);
        match run.as_mut() {
            Some(r) if r.0 == k => {
                r.2 += c;
                r.3 += 1;
                prev_t = t;
                continue;
            }
            _ => {}
        }
        if let Some((rk, start, sum, cnt)) = run.take() {
            let end = refine(prev_t, t, rk);
            emit(out, rk, at(start), at(end), sum / cnt as f64);
        }
        if k != Kind::None {
            let start = if s == 0 { t } else { refine(t, prev_t, k) };
            run = Some((k, start, c, 1));
        }
        prev_t = t;
    }
    if let Some((rk, start, sum, cnt)) = run {
        emit(out, rk, at(start), at(1.0), sum / cnt as f64);
    }
}

fn emit(out: &mut YardTruth, k: Kind, a: P2, b: P2, contrast: f64) {
    let s = Segment {
        a: Point::new(a.0, a.1),
        b: Point::new(b.0, b.1),
        response: contrast,
        residual: 0.0,
        shadow: false,
    };
    let len = s.length();
    match k {
        Kind::Care if len >= MIN_PIECE => out.edges.push(s),
        Kind::Care | Kind::DontCare if len > 0.25 => out.dont_care.push(s),
        _ => {}
    }
}
