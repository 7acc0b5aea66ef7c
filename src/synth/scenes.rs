//! The scenes: the simulated welding cell (a workpiece of a cube, a box and an
//! L-bracket on a plate, four cameras, four lights) and seeded random views for
//! the accuracy tests.

use super::geom::{self, Polyhedron, V3};
use super::score;
use super::{Camera, PointLight, RenderOptions, Scene};
use crate::llv::lens::CameraModel;
use crate::llv::rng::{SplitMix64, mix};
use crate::llv::{Point, Segment};

/// Names of the cell's lights, in the order of [`cell_lights`] (the same as in
/// `profiles/default.toml`; "front" is the world's `-y` side).
pub const CELL_LIGHT_NAMES: [&str; 4] = ["left-front", "right-front", "left-back", "right-back"];

/// An L-shaped bracket: a base plate and an upright flush with one end, two
/// boxes of one albedo (their shared faces are coplanar, so the seam shows no
/// contrast and is no true edge).
pub fn l_bracket(
    name: &str,
    centre: V3,
    base: V3,
    upright: V3,
    yaw: f64,
    albedo: f64,
) -> Vec<Polyhedron> {
    let (s, c) = yaw.sin_cos();
    let base_box = Polyhedron::cuboid(&format!("{name}-base"), centre, base, yaw, albedo);
    // The upright stands on the base, flush with its +x end.
    let off = base[0] / 2.0 - upright[0] / 2.0;
    let up_centre = [
        centre[0] + c * off,
        centre[1] + s * off,
        centre[2] + base[2],
    ];
    let up = Polyhedron::cuboid(&format!("{name}-upright"), up_centre, upright, yaw, albedo);
    vec![base_box, up]
}

/// A floor plate of `sx × sy` mm, `thick` mm thick, top at `z = 0`.
fn plate(sx: f64, sy: f64, thick: f64, albedo: f64) -> Polyhedron {
    Polyhedron::cuboid("plate", [0.0, 0.0, -thick], [sx, sy, thick], 0.0, albedo)
}

/// A camera model for a `w × h` sensor of the cell's kind (scale factors of
/// the `.cdf` example, per 512 pixels).
fn model(w: usize, h: usize, f: f64, dc: (f64, f64), d: Option<[f64; 5]>) -> CameraModel {
    CameraModel {
        cx: w as f64 / 2.0 + dc.0,
        cy: h as f64 / 2.0 + dc.1,
        sx: 0.0112 * 512.0 / w.max(1) as f64,
        sy: 0.0078 * 512.0 / h.max(1) as f64,
        f,
        distortion: d,
        radial: [0.0; 2],
    }
}

/// Turns the camera about its viewing axis by `roll` radians.
fn rolled(pose: [[f64; 4]; 3], roll: f64) -> [[f64; 4]; 3] {
    let (s, c) = roll.sin_cos();
    let mut out = pose;
    for k in 0..4 {
        out[0][k] = c * pose[0][k] - s * pose[1][k];
        out[1][k] = s * pose[0][k] + c * pose[1][k];
    }
    out
}

/// The camera at `azimuth`/`elevation` (radians) looking at `target`, at the
/// nearest distance where every point of `fit` projects at least
/// `margin · size` from the image border.
fn fitted_camera(
    m: CameraModel,
    w: usize,
    h: usize,
    target: V3,
    (azimuth, elevation, roll): (f64, f64, f64),
    fit: &[V3],
    margin: f64,
) -> Camera {
    let dir = [
        elevation.cos() * azimuth.cos(),
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
    ];
    let at = |dist: f64| Camera {
        model: m,
        width: w,
        height: h,
        pose: rolled(
            geom::look_at(geom::add(target, geom::scale(dir, dist)), target),
            roll,
        ),
    };
    let fits = |c: &Camera| {
        fit.iter().all(|&p| {
            c.project(p).is_some_and(|q| {
                let (mx, my) = (margin * w as f64, margin * h as f64);
                q.x >= mx && q.y >= my && q.x <= w as f64 - 1.0 - mx && q.y <= h as f64 - 1.0 - my
            })
        })
    };
    let (mut near, mut far) = (100.0, 20_000.0);
    for _ in 0..50 {
        let mid = 0.5 * (near + far);
        if fits(&at(mid)) {
            far = mid;
        } else {
            near = mid;
        }
    }
    at(far)
}

/// The workpiece of the simulated cell: a cube, a box and an L-bracket on a
/// 700 × 500 mm plate.
pub fn cell_scene() -> Scene {
    let mut objects = vec![
        Polyhedron::cuboid("cube", [-120.0, 70.0, 0.0], [80.0, 80.0, 80.0], 0.35, 190.0),
        Polyhedron::cuboid("box", [70.0, -70.0, 0.0], [140.0, 70.0, 50.0], -0.2, 165.0),
    ];
    objects.extend(l_bracket(
        "bracket",
        [110.0, 90.0, 0.0],
        [120.0, 60.0, 18.0],
        [20.0, 60.0, 70.0],
        0.9,
        180.0,
    ));
    Scene {
        objects,
        plate: Some(plate(700.0, 500.0, 12.0, 85.0)),
        background: 25.0,
    }
}

/// The cell's four cameras, at the four diagonals around the workpiece, 50°
/// up, each with its own modest lens distortion (corners move 1–3 px at
/// 512²) and focal length.
pub fn cell_cameras(width: usize, height: usize) -> Vec<Camera> {
    let scene = cell_scene();
    let fit: Vec<V3> = scene.objects.iter().flat_map(|o| o.vertices()).collect();
    // Weng's folded D = (k1, g1, g2, g3, g4) of a lens with radial and
    // decentering distortion and no thin prism, as real lenses have
    // (g1 = g3 / 2, g2 = g4 / 2; docs/calibration.md).
    let dists: [[f64; 5]; 4] = [
        [-0.000527, 0.0003515, -0.000703, 0.000703, -0.001406],
        [-0.000490, 0.000170, -0.000320, 0.000340, -0.000640],
        [-0.000450, -0.000150, 0.000500, -0.000300, 0.001000],
        [-0.000420, 0.000156, 0.000216, 0.000312, 0.000432],
    ];
    let focal = [11.892729, 12.1, 11.95, 12.05];
    let centre = [(0.0, 0.0), (1.5, -1.0), (-1.0, 2.0), (2.0, 1.0)];
    (0..4)
        .map(|k| {
            let az = (45.0 + 90.0 * k as f64 - 180.0).to_radians();
            let m = model(width, height, focal[k], centre[k], Some(dists[k]));
            fitted_camera(
                m,
                width,
                height,
                [0.0, 0.0, 30.0],
                (az, 50f64.to_radians(), 0.0),
                &fit,
                0.1,
            )
        })
        .collect()
}

/// The cell's four lights at (±600, ±600, 800) mm, named by
/// [`CELL_LIGHT_NAMES`]; each alone lights the plate and every top face.
pub fn cell_lights() -> Vec<PointLight> {
    [
        (-600.0, -600.0),
        (600.0, -600.0),
        (-600.0, 600.0),
        (600.0, 600.0),
    ]
    .iter()
    .map(|&(x, y)| PointLight {
        position: [x, y, 800.0],
        intensity: 0.6,
    })
    .collect()
}

/// Smallest contrast (grey levels, default ambient) of a visible edge in a
/// test scene; edges a lighting hides (below [`HIDDEN`]) are allowed, since
/// they are no true edges.
const MIN_SCENE_CONTRAST: f64 = 30.0;
const HIDDEN: f64 = 4.0;
/// Smallest distance (px) between nearly parallel visible edges of a test
/// scene (see [`resolvable`]).
const MIN_SEPARATION: f64 = 8.0;

/// `n` seeded random views of 1–3 objects (cubes, boxes, L-brackets) on a
/// plate that fills the frame, each with a key and a fill light and a camera
/// (with lens distortion, used when rendered with `distort`) placed so the
/// objects fill most of the image. Every visible edge longer than 10 px shows
/// at least 30 grey levels of contrast under the default ambient, unless the
/// lighting hides it (< 4): a scene that breaks this is drawn again.
pub fn test_scenes(
    n: usize,
    width: usize,
    height: usize,
    seed: u64,
) -> Vec<(Scene, Camera, Vec<PointLight>)> {
    (0..n)
        .map(|i| {
            let mut rng = SplitMix64::new(mix(seed, i as u64));
            let mut last = None;
            for _ in 0..100 {
                let s = random_view(&mut rng, width, height);
                let ok = acceptable(&s);
                last = Some(s);
                if ok {
                    break;
                }
            }
            // `last` is always set: the loop runs at least once.
            last.unwrap_or_else(|| random_view(&mut rng, width, height))
        })
        .collect()
}

fn acceptable((scene, cam, lights): &(Scene, Camera, Vec<PointLight>)) -> bool {
    let o = RenderOptions::default();
    let edges = super::true_edges(scene, cam, lights, &o, HIDDEN);
    let long: Vec<&Segment> = edges.iter().filter(|e| e.length() >= 10.0).collect();
    !long.is_empty()
        && long.iter().all(|e| e.response >= MIN_SCENE_CONTRAST)
        && long
            .iter()
            .enumerate()
            .all(|(i, a)| long.iter().skip(i + 1).all(|b| resolvable(a, b)))
}

/// Whether two visible edges can be told apart by a detector whose kernel
/// spans 2A + 1 ≤ 15 px: edges within 8° of each other's direction must
/// either lie on one line (pieces of one edge split by an occlusion) or stay
/// [`MIN_SEPARATION`] px apart. This keeps out faces seen so obliquely
/// that they are a few pixels wide, and kinks of a few degrees where two
/// edges meet, which no single-scale edge detector resolves.
fn resolvable(a: &Segment, b: &Segment) -> bool {
    if score::angle_diff_deg(a, b) >= 8.0 {
        return true;
    }
    let colinear = score::line_distance(a, b.a) < 0.5 && score::line_distance(a, b.b) < 0.5;
    colinear || segment_distance(a, b) >= MIN_SEPARATION
}

/// Smallest distance between two segments (they do not cross when nearly
/// parallel, so endpoint-to-segment distances suffice).
fn segment_distance(a: &Segment, b: &Segment) -> f64 {
    let d = |s: &Segment, p: Point| {
        let (dx, dy) = (s.b.x - s.a.x, s.b.y - s.a.y);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((p.x - s.a.x) * dx + (p.y - s.a.y) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        p.dist(Point::new(s.a.x + t * dx, s.a.y + t * dy))
    };
    d(a, b.a).min(d(a, b.b)).min(d(b, a.a)).min(d(b, a.b))
}

fn random_view(rng: &mut SplitMix64, w: usize, h: usize) -> (Scene, Camera, Vec<PointLight>) {
    let count = 1 + rng.below(3);
    // Parts lie square to each other on the plate (as on a fixture), give or
    // take a few degrees; the lights are set relative to them (below).
    let base_yaw = rng.range(0.0, std::f64::consts::TAU);
    let mut objects: Vec<Polyhedron> = Vec::new();
    let mut placed: Vec<(f64, f64, f64)> = Vec::new(); // x, y, radius
    for k in 0..count {
        let kind = rng.below(3);
        let albedo = rng.range(150.0, 215.0);
        let yaw = base_yaw
            + std::f64::consts::FRAC_PI_2 * rng.below(4) as f64
            + rng.range(-6.0, 6.0f64).to_radians();
        let (size, radius) = match kind {
            0 => {
                let s = rng.range(50.0, 90.0);
                ([s, s, s], s * 0.75)
            }
            1 => {
                let s = [
                    rng.range(40.0, 120.0),
                    rng.range(40.0, 90.0),
                    rng.range(30.0, 90.0),
                ];
                (s, 0.5 * s[0].hypot(s[1]))
            }
            _ => {
                let s = [
                    rng.range(90.0, 130.0),
                    rng.range(40.0, 70.0),
                    rng.range(14.0, 24.0),
                ];
                (s, 0.5 * s[0].hypot(s[1]))
            }
        };
        // Place without overlap, as close to the others as allowed.
        let mut pos = (0.0, 0.0);
        for _ in 0..100 {
            let r = if placed.is_empty() {
                0.0
            } else {
                rng.range(60.0, 200.0)
            };
            let a = rng.range(0.0, std::f64::consts::TAU);
            let cand = (r * a.cos(), r * a.sin());
            if placed
                .iter()
                .all(|&(x, y, rr)| (x - cand.0).hypot(y - cand.1) > rr + radius + 15.0)
            {
                pos = cand;
                break;
            }
        }
        placed.push((pos.0, pos.1, radius));
        let name = format!("object{k}");
        let centre = [pos.0, pos.1, 0.0];
        match kind {
            2 => {
                let up = [rng.range(14.0, 24.0), size[1], rng.range(45.0, 90.0)];
                objects.extend(l_bracket(&name, centre, size, up, yaw, albedo));
            }
            _ => objects.push(Polyhedron::cuboid(&name, centre, size, yaw, albedo)),
        }
    }
    let fit: Vec<V3> = objects.iter().flat_map(|o| o.vertices()).collect();
    let centroid = {
        let mut c = [0.0; 3];
        for p in &fit {
            c = geom::add(c, *p);
        }
        geom::scale(c, 1.0 / fit.len().max(1) as f64)
    };
    let scene = Scene {
        objects,
        plate: Some(plate(3000.0, 3000.0, 10.0, rng.range(18.0, 28.0))),
        background: 10.0,
    };
    let d = [
        rng.range(-0.0007, -0.0003),
        rng.range(-0.0005, 0.0005),
        rng.range(-0.0012, 0.0012),
        rng.range(-0.0007, 0.0007),
        rng.range(-0.0012, 0.0012),
    ];
    let m = model(
        w,
        h,
        rng.range(11.5, 12.5),
        (rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)),
        Some(d),
    );
    let view = (
        rng.range(0.0, std::f64::consts::TAU),
        rng.range(30.0, 65.0f64).to_radians(),
        rng.range(-30.0, 30.0f64).to_radians(),
    );
    let cam = fitted_camera(m, w, h, centroid, view, &fit, 0.12);
    let key_az = base_yaw + rng.range(15.0, 25.0f64).to_radians();
    let light = |az: f64, el_deg: f64, dist: f64, intensity: f64| PointLight {
        position: geom::add(
            centroid,
            geom::scale(
                [
                    el_deg.to_radians().cos() * az.cos(),
                    el_deg.to_radians().cos() * az.sin(),
                    el_deg.to_radians().sin(),
                ],
                dist,
            ),
        ),
        intensity,
    };
    // Key, fill and rim light 120° apart, turned 20° from the parts' faces:
    // every vertical face gets direct light from one of them, and the four
    // sides of a part get four clearly different brightnesses (about 0.86,
    // 0.68, 0.53 and 0.41 of the albedo) instead of two equal ones.
    let mut lights = Vec::new();
    for (k, intensity) in [0.75, 0.42, 0.24].into_iter().enumerate() {
        lights.push(light(
            key_az + (120.0 * k as f64 + rng.range(-5.0, 5.0)).to_radians(),
            rng.range(35.0, 50.0),
            rng.range(900.0, 1200.0),
            intensity * rng.range(0.92, 1.08),
        ));
    }
    (scene, cam, lights)
}
