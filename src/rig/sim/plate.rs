//! The simulated cell's calibration plate: when set as the scene's target,
//! every freeze shows the plate (`crate::calib::Plate`) in front of the cell,
//! rendered through the selected camera's true lens (its `.cdf` in
//! `profiles/sim/` is the ground truth), blur and the frame's noise.
//!
//! Held ([`Mode::Held`]): the plate is where an operator would hold it for an
//! intrinsic calibration, at a pose drawn anew for each freeze from the
//! simulator's seed, the camera and the shot number: 15–45° of tilt about a
//! random axis, any turn in its plane, filling 45–80 % of the view, anywhere
//! in it, the whole grid in view. Placed ([`Mode::Placed`]): the plate lies at
//! the place its file gives in the cell, for the extrinsic calibration.
//!
//! The plate is a matte card evenly lit (light 200, squares 40 grey levels,
//! whichever lights are on); beyond its edge the cell's own scene shows.
//! Pixels that a square's side or the plate's edge crosses are area-sampled
//! on a sheared 8 × 8 grid (every sample at its own `x` and `y` offset, as
//! the synthetic renderer's 16 × 16 one), so a side's coverage is right to
//! 1/64 of a pixel in each pixel and its position, over the pixels along
//! it, to far less; 8 × 8 keeps a freeze near 0.1 s, inside the grabber's
//! reply timeout.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use super::SimOptions;
use crate::calib::Plate;
use crate::llv::rng::{SplitMix64, mix};
use crate::synth::{self, RenderOptions};

/// Grey level of the plate and of its dark squares.
pub const LIGHT: f64 = 200.0;
pub const DARK: f64 = 40.0;
/// The grid stays this far inside the image (px).
const MARGIN: f64 = 12.0;

/// Where the plate is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Held in front of the camera, a new pose at every freeze.
    Held,
    /// At its place in the cell (the plate file's `[place]`).
    Placed,
}

/// What the simulated cameras see instead of the bare cell.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateTarget {
    pub plate: Plate,
    pub mode: Mode,
}

/// A plate → camera pose `[R | t]` (mm).
pub type PoseMatrix = [[f64; 4]; 3];

impl PlateTarget {
    /// The plate's pose for camera `cam` (1-based) at freeze `shot`; `None`
    /// when there is no such camera, or (placed) the plate has no place.
    pub fn pose(&self, o: &SimOptions, cam: u32, shot: u64) -> Option<PoseMatrix> {
        let cams = super::render::cameras(o);
        let c = cams.get(usize::try_from(cam.checked_sub(1)?).ok()?)?;
        match self.mode {
            Mode::Placed => {
                let place = self.plate.place?;
                let r_pw = Matrix3::from_fn(|i, j| place.rotation[i][j]);
                let r_wc = Matrix3::from_fn(|i, j| c.pose[i][j]);
                let t_wc = Vector3::from_fn(|i, _| c.pose[i][3]);
                let r = r_wc * r_pw;
                let t = r_wc * Vector3::from(place.origin) + t_wc;
                Some(std::array::from_fn(|i| {
                    [r[(i, 0)], r[(i, 1)], r[(i, 2)], t[i]]
                }))
            }
            Mode::Held => {
                let seed = mix(o.seed ^ u64::from(cam) << 40, shot);
                Some(held_pose(&self.plate, c, seed))
            }
        }
    }

    /// The noise-free frame of camera `cam` at freeze `shot`: the plate over
    /// `background` (the cell as that camera sees it).
    pub fn render(&self, o: &SimOptions, cam: u32, shot: u64, background: &[f32]) -> Vec<f32> {
        let cams = super::render::cameras(o);
        let (Some(c), Some(pose)) = (
            cams.get(cam.saturating_sub(1) as usize),
            self.pose(o, cam, shot),
        ) else {
            return background.to_vec();
        };
        render_plate(&self.plate, c, &pose, background)
    }
}

/// Plate mm of the ray through observed pixel `(x, y)`, if it meets the
/// plate's plane in front of the camera.
fn plate_point(
    c: &synth::Camera,
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
    x: f64,
    y: f64,
) -> Option<[f64; 2]> {
    let (ix, iy) = c.model.observed_to_ideal(x, y);
    let (u, v) = c.model.to_mm(ix, iy);
    let d = Vector3::new(u / c.model.f, v / c.model.f, 1.0);
    let n = r.column(2);
    let den = n.dot(&d);
    if den.abs() < 1e-12 {
        return None;
    }
    let lambda = n.dot(t) / den;
    if lambda <= 0.0 {
        return None;
    }
    let p = r.transpose() * (d * lambda - t);
    Some([p.x, p.y])
}

/// What the plate shows at plate point `p`: `Some(grey)` on the plate,
/// `None` beyond its edge.
fn shade(plate: &Plate, p: [f64; 2]) -> Option<f64> {
    let (gw, gh) = plate.grid_size();
    let b = plate.border;
    if !(p[0] >= -b && p[0] <= gw + b && p[1] >= -b && p[1] <= gh + b) {
        return None;
    }
    let (i, j) = ((p[0] / plate.pitch).floor(), (p[1] / plate.pitch).floor());
    if i < 0.0 || j < 0.0 || i >= f64::from(plate.columns) || j >= f64::from(plate.rows) {
        return Some(LIGHT);
    }
    let (fi, fj) = (p[0] - i * plate.pitch, p[1] - j * plate.pitch);
    let inside = fi <= plate.square && fj <= plate.square;
    Some(if inside && plate.is_dark(i as u32, j as u32) {
        DARK
    } else {
        LIGHT
    })
}

/// Renders the plate at `pose` over `background` (noise-free, blurred).
pub fn render_plate(
    plate: &Plate,
    c: &synth::Camera,
    pose: &PoseMatrix,
    background: &[f32],
) -> Vec<f32> {
    let (w, h) = (c.width, c.height);
    let r = Matrix3::from_fn(|i, j| pose[i][j]);
    let t = Vector3::from_fn(|i, _| pose[i][3]);
    // A region label per pixel corner: which square or light area it is in.
    let label = |p: Option<[f64; 2]>| -> i64 {
        let Some(p) = p else { return -2 };
        match shade(plate, p) {
            None => -2,
            Some(v) if v == DARK => {
                ((p[1] / plate.pitch).floor() as i64) * 1000 + (p[0] / plate.pitch).floor() as i64
            }
            Some(_) => -1,
        }
    };
    let mut corner_labels = vec![0i64; (w + 1) * (h + 1)];
    for y in 0..=h {
        for x in 0..=w {
            corner_labels[y * (w + 1) + x] =
                label(plate_point(c, &r, &t, x as f64 - 0.5, y as f64 - 0.5));
        }
    }
    const SS: usize = 8;
    let offsets: Vec<(f64, f64)> = (0..SS * SS)
        .map(|k| {
            let (i, j) = ((k % SS) as f64, (k / SS) as f64);
            let n = SS as f64;
            ((i + (j + 0.5) / n) / n - 0.5, (j + (i + 0.5) / n) / n - 0.5)
        })
        .collect();
    let mut out = vec![0.0f64; w * h];
    for y in 0..h {
        for x in 0..w {
            let bg = f64::from(background.get(y * w + x).copied().unwrap_or(0.0));
            let l = [
                corner_labels[y * (w + 1) + x],
                corner_labels[y * (w + 1) + x + 1],
                corner_labels[(y + 1) * (w + 1) + x],
                corner_labels[(y + 1) * (w + 1) + x + 1],
            ];
            let (xf, yf) = (x as f64, y as f64);
            out[y * w + x] = if l.iter().all(|&v| v == l[0]) {
                match plate_point(c, &r, &t, xf, yf).and_then(|p| shade(plate, p)) {
                    Some(v) => v,
                    None => bg,
                }
            } else {
                let sum: f64 = offsets
                    .iter()
                    .map(|&(ox, oy)| {
                        plate_point(c, &r, &t, xf + ox, yf + oy)
                            .and_then(|p| shade(plate, p))
                            .unwrap_or(bg)
                    })
                    .sum();
                sum / offsets.len() as f64
            };
        }
    }
    let opts = RenderOptions {
        blur_sigma: super::render::BLUR,
        noise_sigma: 0.0,
        ..RenderOptions::default()
    };
    synth::finish(out, w, h, &opts)
        .data()
        .iter()
        .map(|&v| f32::from(v))
        .collect()
}

/// Whether every grid corner of `plate` at `pose` is observed inside the
/// image with a margin.
fn in_view(plate: &Plate, c: &synth::Camera, r: &Matrix3<f64>, t: &Vector3<f64>) -> bool {
    plate.corners().iter().all(|pc| {
        let q = r * Vector3::new(pc.xy[0], pc.xy[1], 0.0) + t;
        if q.z <= 0.0 {
            return false;
        }
        let (ix, iy) = c.model.to_px(c.model.f * q.x / q.z, c.model.f * q.y / q.z);
        let (x, y) = c.model.ideal_to_observed_converged(ix, iy);
        x >= MARGIN
            && y >= MARGIN
            && x <= c.width as f64 - 1.0 - MARGIN
            && y <= c.height as f64 - 1.0 - MARGIN
    })
}

fn held_pose(plate: &Plate, c: &synth::Camera, seed: u64) -> PoseMatrix {
    let mut rng = SplitMix64::new(seed);
    let m = &c.model;
    let (gw, gh) = plate.grid_size();
    let centre = Vector3::new(gw / 2.0, gh / 2.0, 0.0);
    // Seen from its printed side: x → y turns as the image's does, or the
    // other way for a plate whose origin says so.
    let flip = if plate.origin.handedness() > 0.0 {
        Matrix3::identity()
    } else {
        Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0))
    };
    let mut best = None;
    for attempt in 0..200 {
        let fill = rng.range(0.45, 0.8) * (1.0 - attempt as f64 / 300.0);
        let spin = rng.range(0.0, std::f64::consts::TAU);
        let axis_angle = rng.range(0.0, std::f64::consts::TAU);
        let tilt = rng.range(15f64, 45.0).to_radians();
        let axis = Unit::new_normalize(Vector3::new(axis_angle.cos(), axis_angle.sin(), 0.0));
        let r = Rotation3::from_axis_angle(&axis, tilt).into_inner()
            * Rotation3::from_axis_angle(&Vector3::z_axis(), spin).into_inner()
            * flip;
        // Distance at which the grid's diagonal spans `fill` of the view's.
        let diag_mm = gw.hypot(gh);
        let view = (c.width as f64 * m.sx).hypot(c.height as f64 * m.sy) / m.f;
        let z = diag_mm / (fill * view);
        // Aim the centre anywhere within the middle 60 % of the image.
        let (ax, ay) = (
            rng.range(0.2, 0.8) * c.width as f64,
            rng.range(0.2, 0.8) * c.height as f64,
        );
        let (u, v) = m.to_mm(ax, ay);
        let ray = Vector3::new(u / m.f, v / m.f, 1.0);
        let t = ray * z - r * centre;
        if in_view(plate, c, &r, &t) {
            best = Some((r, t));
            break;
        }
    }
    let (r, t) = best.unwrap_or_else(|| {
        // A plate too big to fit at any tilt tried: face-on, far enough.
        let diag_mm = gw.hypot(gh);
        let view = (c.width as f64 * m.sx).hypot(c.height as f64 * m.sy) / m.f;
        (
            flip,
            Vector3::new(0.0, 0.0, 2.0 * diag_mm / view) - flip * centre,
        )
    });
    std::array::from_fn(|i| [r[(i, 0)], r[(i, 1)], r[(i, 2)], t[i]])
}
