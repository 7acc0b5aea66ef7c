//! Ray casting in ideal (undistorted) pixel coordinates: which face is seen at
//! a point of the image, at what depth, and how bright it is there.
//!
//! Every face that looks at the camera is projected once (after clipping at a
//! near plane) to a convex polygon in ideal pixels; a coarse tile grid lists
//! the faces whose bounding box touches each tile, so a query tests only a
//! few polygons. Back faces are skipped: the scenes are closed polyhedra and
//! a one-sided plate seen from above, so a back face is never the nearest.

use super::geom::{self, V3};
use super::{Camera, PointLight, Scene};

/// Near clipping plane (mm in front of the camera).
const NEAR: f64 = 1.0;
/// Tile size of the acceleration grid (ideal pixels).
const TILE: f64 = 16.0;

/// A projected front face.
#[derive(Clone, Debug)]
pub struct PFace {
    /// Polygon in ideal pixels, counter-clockwise in the image's own
    /// orientation as stored in `orient`.
    pub poly: Vec<(f64, f64)>,
    pub bbox: [f64; 4],
    orient: f64,
    /// Camera-frame plane `n · X = d`.
    n_cam: V3,
    d_cam: f64,
    /// World normal and albedo for shading.
    n_world: V3,
    albedo: f64,
}

/// What a ray sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub face: usize,
    pub depth: f64,
}

/// A scene prepared for one camera and one set of lights.
pub struct Prepared<'a> {
    pub faces: Vec<PFace>,
    cam: &'a Camera,
    lights: &'a [PointLight],
    ambient: f64,
    background: f64,
    grid_x0: f64,
    grid_y0: f64,
    grid_w: usize,
    grid_h: usize,
    tiles: Vec<Vec<u32>>,
}

impl<'a> Prepared<'a> {
    /// Projects the scene; `ideal_bounds` is the region of ideal pixels the
    /// queries will fall in (outside it every face is tested).
    pub fn new(
        scene: &Scene,
        cam: &'a Camera,
        lights: &'a [PointLight],
        ambient: f64,
        ideal_bounds: [f64; 4],
    ) -> Prepared<'a> {
        let mut faces = Vec::new();
        let planes = frustum(cam, ideal_bounds);
        for obj in scene.objects.iter().chain(scene.plate.iter()) {
            for f in &obj.faces {
                let cv: Vec<V3> = f
                    .vertices
                    .iter()
                    .map(|&v| geom::to_camera(&cam.pose, v))
                    .collect();
                let Some(&v0) = cv.first() else { continue };
                let n_cam = rotate(&cam.pose, f.normal);
                let d_cam = geom::dot(n_cam, v0);
                // Front facing: the camera (origin) is on the outer side.
                if d_cam >= -1e-9 {
                    continue;
                }
                let clipped = clip(&cv, &planes);
                if clipped.len() < 3 {
                    continue;
                }
                let poly: Vec<(f64, f64)> = clipped
                    .iter()
                    .map(|&q| geom::project(&cam.model, q))
                    .collect();
                let mut area = 0.0;
                let mut bbox = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
                for (i, &(x, y)) in poly.iter().enumerate() {
                    let (x2, y2) = poly[(i + 1) % poly.len()];
                    area += x * y2 - x2 * y;
                    bbox = [
                        bbox[0].min(x),
                        bbox[1].min(y),
                        bbox[2].max(x),
                        bbox[3].max(y),
                    ];
                }
                if area.abs() < 1e-12 {
                    continue;
                }
                faces.push(PFace {
                    poly,
                    bbox,
                    orient: area.signum(),
                    n_cam,
                    d_cam,
                    n_world: f.normal,
                    albedo: obj.albedo,
                });
            }
        }
        let [x0, y0, x1, y1] = ideal_bounds;
        let grid_w = (((x1 - x0) / TILE).ceil().max(1.0) as usize).min(4096);
        let grid_h = (((y1 - y0) / TILE).ceil().max(1.0) as usize).min(4096);
        let mut tiles = vec![Vec::new(); grid_w * grid_h];
        for (i, f) in faces.iter().enumerate() {
            let tx0 = (((f.bbox[0] - x0) / TILE).floor().max(0.0) as usize).min(grid_w);
            let ty0 = (((f.bbox[1] - y0) / TILE).floor().max(0.0) as usize).min(grid_h);
            let tx1 = (((f.bbox[2] - x0) / TILE).floor() + 1.0).clamp(0.0, grid_w as f64) as usize;
            let ty1 = (((f.bbox[3] - y0) / TILE).floor() + 1.0).clamp(0.0, grid_h as f64) as usize;
            for ty in ty0..ty1 {
                for tx in tx0..tx1 {
                    tiles[ty * grid_w + tx].push(i as u32);
                }
            }
        }
        Prepared {
            faces,
            cam,
            lights,
            ambient,
            background: scene.background,
            grid_x0: x0,
            grid_y0: y0,
            grid_w,
            grid_h,
            tiles,
        }
    }

    fn candidates(&self, x: f64, y: f64) -> Option<&[u32]> {
        let tx = ((x - self.grid_x0) / TILE).floor();
        let ty = ((y - self.grid_y0) / TILE).floor();
        if tx < 0.0 || ty < 0.0 || tx >= self.grid_w as f64 || ty >= self.grid_h as f64 {
            return None;
        }
        self.tiles
            .get(ty as usize * self.grid_w + tx as usize)
            .map(|v| v.as_slice())
    }

    fn inside(f: &PFace, x: f64, y: f64) -> bool {
        if x < f.bbox[0] || x > f.bbox[2] || y < f.bbox[1] || y > f.bbox[3] {
            return false;
        }
        let n = f.poly.len();
        for i in 0..n {
            let (ax, ay) = f.poly[i];
            let (bx, by) = f.poly[(i + 1) % n];
            if ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) * f.orient < 0.0 {
                return false;
            }
        }
        true
    }

    /// Depth (camera `z`, mm) of face `f`'s plane along the ray through the
    /// ideal pixel `(x, y)`.
    pub fn depth_on(&self, f: usize, x: f64, y: f64) -> f64 {
        let Some(face) = self.faces.get(f) else {
            return f64::INFINITY;
        };
        let r = geom::ray(&self.cam.model, x, y);
        let den = geom::dot(face.n_cam, r);
        if den.abs() < 1e-15 {
            return f64::INFINITY;
        }
        face.d_cam / den
    }

    /// The nearest face at ideal pixel `(x, y)`.
    pub fn hit(&self, x: f64, y: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut test = |i: usize| {
            if let Some(f) = self.faces.get(i)
                && Self::inside(f, x, y)
            {
                let depth = self.depth_on(i, x, y);
                if depth > 0.0 && best.is_none_or(|b| depth < b.depth) {
                    best = Some(Hit { face: i, depth });
                }
            }
        };
        match self.candidates(x, y) {
            Some(c) => c.iter().for_each(|&i| test(i as usize)),
            None => (0..self.faces.len()).for_each(&mut test),
        }
        best
    }

    /// Brightness (grey levels, noise-free, not clamped) of face `f` at the
    /// point where the ray through ideal pixel `(x, y)` meets its plane.
    pub fn shade(&self, f: usize, x: f64, y: f64) -> f64 {
        let Some(face) = self.faces.get(f) else {
            return self.background;
        };
        let depth = self.depth_on(f, x, y);
        let q = geom::scale(geom::ray(&self.cam.model, x, y), depth);
        let p = geom::to_world(&self.cam.pose, q);
        face.albedo * (self.ambient + irradiance(self.lights, p, face.n_world))
    }

    /// Brightness of what is seen at ideal pixel `(x, y)`.
    pub fn value(&self, x: f64, y: f64) -> f64 {
        match self.hit(x, y) {
            Some(h) => self.shade(h.face, x, y),
            None => self.background,
        }
    }

    pub fn background(&self) -> f64 {
        self.background
    }
}

/// Irradiance from point lights on a surface point with normal `n`:
/// Lambert's cosine law with the inverse-square fall-off, normalised so that a
/// light of intensity 1 at 1 m straight above gives 1.
pub fn irradiance(lights: &[PointLight], p: V3, n: V3) -> f64 {
    lights
        .iter()
        .map(|l| {
            let d = geom::sub(l.position, p);
            let r2 = geom::dot(d, d).max(1e-6);
            let cos = geom::dot(n, d) / r2.sqrt();
            l.intensity * cos.max(0.0) * 1.0e6 / r2
        })
        .sum()
}

fn rotate(pose: &[[f64; 4]; 3], v: V3) -> V3 {
    let r = |i: usize| pose[i][0] * v[0] + pose[i][1] * v[1] + pose[i][2] * v[2];
    [r(0), r(1), r(2)]
}

/// The half-spaces `p · (x, y, z, 1) ≥ 0` (camera frame) of what projects
/// inside the ideal-pixel rectangle `[x0, y0, x1, y1]` in front of the near
/// plane: clipping to them keeps projected polygons finite and small.
pub fn frustum(cam: &Camera, b: [f64; 4]) -> [[f64; 4]; 5] {
    let m = &cam.model;
    let (fx, fy) = (m.f / m.sx, m.f / m.sy);
    [
        [0.0, 0.0, 1.0, -NEAR],
        [fx, 0.0, m.cx - b[0], 0.0],
        [-fx, 0.0, b[2] - m.cx, 0.0],
        [0.0, fy, m.cy - b[1], 0.0],
        [0.0, -fy, b[3] - m.cy, 0.0],
    ]
}

fn side(p: &[f64; 4], q: V3) -> f64 {
    p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3]
}

/// Sutherland–Hodgman against each half-space.
fn clip(poly: &[V3], planes: &[[f64; 4]]) -> Vec<V3> {
    let mut cur = poly.to_vec();
    for p in planes {
        let mut out = Vec::with_capacity(cur.len() + 1);
        for (i, &a) in cur.iter().enumerate() {
            let b = cur[(i + 1) % cur.len()];
            let (sa, sb) = (side(p, a), side(p, b));
            if sa >= 0.0 {
                out.push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                let t = sa / (sa - sb);
                out.push(geom::add(a, geom::scale(geom::sub(b, a), t)));
            }
        }
        cur = out;
        if cur.is_empty() {
            break;
        }
    }
    cur
}

/// The parameter range `[t0, t1] ⊆ [0, 1]` of the segment `a + t (b - a)`
/// inside all half-spaces (Liang–Barsky), if any.
pub fn clip_segment(a: V3, b: V3, planes: &[[f64; 4]]) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for p in planes {
        let (sa, sb) = (side(p, a), side(p, b));
        if sa < 0.0 && sb < 0.0 {
            return None;
        }
        if sa < 0.0 {
            t0 = t0.max(sa / (sa - sb));
        } else if sb < 0.0 {
            t1 = t1.min(sa / (sa - sb));
        }
    }
    (t0 < t1).then_some((t0, t1))
}
