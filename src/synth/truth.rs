//! The ground truth of a render: the visible projected edges (in ideal,
//! undistorted pixels) and the corners where they meet.
//!
//! Every 3-D edge of every polyhedron is walked in steps of ¼ pixel of its
//! projection. A point counts when it lies inside the image (at least
//! [`MARGIN`] px from the border, where the edge detector's kernel cannot
//! reach), nothing nearer hides it (ray test against all front faces), and
//! the noise-free brightness 1.5 px to either side differs by at least
//! `min_contrast` grey levels — an edge a lighting does not show is no edge of
//! that image. Runs of such points become segments; where a run starts or
//! stops between two samples, the end is found by bisection to 1e-4 of the
//! step. Runs shorter than [`MIN_PIECE`] px are dropped.

use super::geom::{self, V3};
use super::raster::{self, Prepared};
use super::{Camera, PointLight, RenderOptions, Scene};
use crate::llv::{Point, Segment};

/// Distance from the image border (observed px) inside which edges are not
/// counted: the Lee kernel (half-width ≤ 7) has no response there.
pub const MARGIN: f64 = 8.0;
/// Shorter visible pieces are dropped (px).
pub const MIN_PIECE: f64 = 6.0;
/// Offset to each side of an edge where the contrast is measured (px).
const SIDE: f64 = 1.5;

struct Walker<'a> {
    prep: Prepared<'a>,
    cam: &'a Camera,
    distort: bool,
    min_contrast: f64,
    planes: [[f64; 4]; 5],
}

impl Walker<'_> {
    fn inside(&self, x: f64, y: f64) -> bool {
        let (ox, oy) = if self.distort {
            self.cam.model.ideal_to_observed(x, y)
        } else {
            (x, y)
        };
        let (w, h) = (self.cam.width as f64, self.cam.height as f64);
        ox >= MARGIN && oy >= MARGIN && ox <= w - 1.0 - MARGIN && oy <= h - 1.0 - MARGIN
    }

    /// Whether the camera-frame point `q` (on an edge) is seen and shows
    /// enough contrast; also returns the signed contrast.
    fn good(&self, q: V3, nx: f64, ny: f64) -> Option<f64> {
        if q[2] <= 1.0 {
            return None;
        }
        let (x, y) = geom::project(&self.cam.model, q);
        if !self.inside(x, y) {
            return None;
        }
        let tol = 1e-7 * q[2] + 1e-6;
        if let Some(hit) = self.prep.hit(x, y)
            && hit.depth < q[2] - tol
        {
            return None;
        }
        let c = self.prep.value(x + SIDE * nx, y + SIDE * ny)
            - self.prep.value(x - SIDE * nx, y - SIDE * ny);
        (c.abs() >= self.min_contrast).then_some(c)
    }
}

/// The true visible edges of the image `render` gives (`synth::true_edges`),
/// in ideal (undistorted) pixels: polygon edges clipped against nearer
/// faces, silhouettes included, without the pieces whose noise-free
/// contrast is below `min_contrast` grey levels, those within [`MARGIN`] px
/// of the image border and those shorter than [`MIN_PIECE`] px.
/// `Segment.response` holds the edge's mean contrast (grey levels).
pub fn visible_edges(
    scene: &Scene,
    cam: &Camera,
    lights: &[PointLight],
    o: &RenderOptions,
    min_contrast: f64,
) -> Vec<Segment> {
    let distort = o.distort && !cam.model.is_identity();
    let (w, h) = (cam.width as f64, cam.height as f64);
    let bounds = [-8.0 - 0.1 * w, -8.0 - 0.1 * h, 1.1 * w + 8.0, 1.1 * h + 8.0];
    let walker = Walker {
        prep: Prepared::new(scene, cam, lights, o.ambient, bounds),
        cam,
        distort,
        min_contrast,
        planes: raster::frustum(cam, bounds),
    };
    let mut out = Vec::new();
    for obj in scene.objects.iter().chain(scene.plate.iter()) {
        for (a, b) in obj.edges() {
            walk_edge(&walker, a, b, &mut out);
        }
    }
    out
}

fn walk_edge(wk: &Walker, a: V3, b: V3, out: &mut Vec<Segment>) {
    let qa = geom::to_camera(&wk.cam.pose, a);
    let qb = geom::to_camera(&wk.cam.pose, b);
    // Only the part that projects near the image matters (and z > 0 keeps
    // the projection defined).
    let Some((t0, t1)) = raster::clip_segment(qa, qb, &wk.planes) else {
        return;
    };
    let at = |t: f64| geom::add(qa, geom::scale(geom::sub(qb, qa), t));
    let (pa, pb) = (
        geom::project(&wk.cam.model, at(t0)),
        geom::project(&wk.cam.model, at(t1)),
    );
    let len = (pb.0 - pa.0).hypot(pb.1 - pa.1);
    if !(len.is_finite() && len > 1e-6) {
        return;
    }
    // Unit normal in the image, pointing to one side.
    let (nx, ny) = (-(pb.1 - pa.1) / len, (pb.0 - pa.0) / len);
    let steps = ((len * 4.0).ceil() as usize).clamp(2, 1_000_000);
    let param = |s: usize| t0 + (t1 - t0) * s as f64 / steps as f64;
    let good = |t: f64| wk.good(at(t), nx, ny);
    // Bisection between a good and a bad parameter: returns the last good one.
    let refine = |mut g: f64, mut bad: f64| {
        for _ in 0..24 {
            let m = 0.5 * (g + bad);
            if good(m).is_some() {
                g = m;
            } else {
                bad = m;
            }
        }
        g
    };
    let mut run: Option<(f64, f64, usize)> = None; // start, Σcontrast, count
    let mut prev_t = t0;
    let mut prev_good = false;
    for s in 0..=steps {
        let t = param(s);
        let g = good(t);
        match (g, run.as_mut()) {
            (Some(c), Some(r)) => {
                r.1 += c;
                r.2 += 1;
            }
            (Some(c), None) => {
                let start = if s == 0 { t } else { refine(t, prev_t) };
                run = Some((start, c, 1));
            }
            (None, Some(_)) => {
                if let Some((start, sum, n)) = run.take() {
                    let end = if prev_good { refine(prev_t, t) } else { prev_t };
                    push(out, wk, at(start), at(end), sum / n as f64);
                }
            }
            (None, None) => {}
        }
        prev_good = g.is_some();
        prev_t = t;
    }
    if let Some((start, sum, n)) = run {
        push(out, wk, at(start), at(prev_t), sum / n as f64);
    }
}

fn push(out: &mut Vec<Segment>, wk: &Walker, qa: V3, qb: V3, contrast: f64) {
    let (ax, ay) = geom::project(&wk.cam.model, qa);
    let (bx, by) = geom::project(&wk.cam.model, qb);
    let s = Segment {
        a: Point::new(ax, ay),
        b: Point::new(bx, by),
        response: contrast.abs(),
        residual: 0.0,
        shadow: false,
    };
    if s.length() >= MIN_PIECE {
        out.push(s);
    }
}

/// Projected vertices (ideal px) that are seen and where at least two of the
/// given visible edges end (within 0.5 px): the corners a line finder should
/// reach.
pub fn corners(scene: &Scene, cam: &Camera, edges: &[Segment]) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::new();
    for obj in scene.objects.iter().chain(scene.plate.iter()) {
        for v in obj.vertices() {
            let q = geom::to_camera(&cam.pose, v);
            if q[2] <= 1.0 {
                continue;
            }
            let (x, y) = geom::project(&cam.model, q);
            let p = Point::new(x, y);
            let ends = edges
                .iter()
                .filter(|s| s.a.dist(p) < 0.5 || s.b.dist(p) < 0.5)
                .count();
            if ends >= 2 && !out.iter().any(|c| c.dist(p) < 0.5) {
                out.push(p);
            }
        }
    }
    out
}
