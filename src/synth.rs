//! Synthetic scenes with known edges: polyhedra (cube, box,
//! L-bracket) on a floor plate, Lambertian faces under point lights plus
//! ambient light, seen by pinhole cameras with Weng lens distortion; rendered
//! with area sampling, blur and seeded noise; plus the true visible edges, the
//! visible corners, and the scoring of detected lines against them.
//!
//! The simulated cell, the accuracy tests and `vss selftest` all
//! draw their images from here. Everything is deterministic for a seed.
//!
//! Brightness model (grey levels, before blur, noise and clamping to 0–255):
//! `albedo · (ambient + Σ_lights intensity · max(0, n·l̂) · (1 m / d)²)`, with
//! `n` the face's outward normal, `l̂` the unit vector to the light and `d`
//! the distance to it. Cast shadows are not rendered (every light reaches
//! every surface that faces it), so every image edge is a polygon edge.

pub mod compare;
pub mod eval;
mod geom;
mod raster;
pub mod real;
mod render;
mod scenes;
mod score;
pub mod straight;
mod truth;
pub mod yard;

pub use geom::{Face, Polyhedron, V3, look_at};
pub use render::{finish, render_exact};
pub use scenes::{CELL_LIGHT_NAMES, cell_cameras, cell_lights, cell_scene, l_bracket, test_scenes};
pub use score::{Metrics, Shared, Tally, score, score_all, shared_endpoints};
pub use truth::{
    MARGIN as TRUTH_MARGIN, MIN_PIECE as TRUTH_MIN_PIECE, visible_edges as true_edges,
};

use crate::llv::lens::CameraModel;
use crate::llv::{GreyImage, Point};

/// What the cameras look at: objects standing on an optional floor plate, in
/// front of a uniform background (what a ray sees when it hits nothing).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub objects: Vec<Polyhedron>,
    /// The floor plate (a thin slab whose top is `z = 0`).
    pub plate: Option<Polyhedron>,
    /// Grey level of the background beyond everything.
    pub background: f64,
}

/// A camera: intrinsics (`.cdf` S, C, f, D), pose `[R | t]` world → camera
/// (mm; camera `z` forward, `x` right, `y` down), and image size.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub model: CameraModel,
    pub width: usize,
    pub height: usize,
    pub pose: [[f64; 4]; 3],
}

impl Camera {
    /// Where the camera stands in the world (mm).
    pub fn position(&self) -> [f64; 3] {
        geom::to_world(&self.pose, [0.0, 0.0, 0.0])
    }

    /// The ideal (undistorted) pixel of a world point, if it is in front of
    /// the camera.
    pub fn project(&self, p: [f64; 3]) -> Option<Point> {
        let q = geom::to_camera(&self.pose, p);
        (q[2] > 1e-9).then(|| {
            let (x, y) = geom::project(&self.model, q);
            Point::new(x, y)
        })
    }
}

/// A point light: position (mm, world) and intensity (irradiance it gives a
/// surface facing it from 1 m away; 1 ≈ a surface of albedo `a` shows `a`).
#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    pub position: [f64; 3],
    pub intensity: f64,
}

/// How to render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Ambient irradiance (fraction of albedo seen with no light on).
    pub ambient: f64,
    /// Gaussian blur σ (px) after sampling; 0 = none.
    pub blur_sigma: f64,
    /// Gaussian sensor noise σ (grey levels); 0 = none.
    pub noise_sigma: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Render the observed (lens-distorted) image instead of the ideal one.
    pub distort: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            ambient: 0.2,
            blur_sigma: 1.0,
            noise_sigma: 0.0,
            seed: 0,
            distort: false,
        }
    }
}

/// Renders a grey image of `scene` through `cam` under `lights` (see the
/// module doc and `render.rs` for the sampling). A camera of zero size gives
/// a 1 × 1 black image.
pub fn render(scene: &Scene, cam: &Camera, lights: &[PointLight], o: &RenderOptions) -> GreyImage {
    let exact = render_exact(scene, cam, lights, o);
    finish(exact, cam.width, cam.height, o)
}

/// The true projected vertices (ideal px) where two or more of
/// [`true_edges`] meet: the corners corner closing should reach.
pub fn visible_corners(
    scene: &Scene,
    cam: &Camera,
    lights: &[PointLight],
    o: &RenderOptions,
    min_contrast: f64,
) -> Vec<Point> {
    let edges = truth::visible_edges(scene, cam, lights, o, min_contrast);
    truth::corners(scene, cam, &edges)
}

#[cfg(test)]
mod tests;
