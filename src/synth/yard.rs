//! The second family of synthetic scenes: a welding yard, modelled to test
//! a line detector on what the cube family leaves out, and rendered along a
//! path that shares none of that family's approximations.
//!
//! **What it models.** Stiffened plates (flat bars on a plate, their top
//! faces 5–9 px wide), I-beams lying on the floor (flange top, flange edge,
//! web, lower flange edge: four parallel bands), T-joints (a standing plate
//! on a base plate with a rippled weld bead at its foot), stacked plates
//! (thicknesses seen edge-on: two edges 4.5–8 px apart), butt joints whose
//! long edges are near-collinear (0.4–2.5° and 0.8–3 px apart), washers
//! (polygons whose sides are too short to be true edges) with hexagon nuts,
//! and clamps astride other edges (occlusions, T-junctions). Objects overrun
//! the frame. A spot light's Gaussian falloff and cos⁴ vignetting scale all
//! contrasts; faces carry a shading gradient, a low-amplitude texture
//! (1–2.5 grey levels) and, on bare steel, specular highlights that
//! saturate. Face-to-face contrasts are drawn so that, once lit, half the
//! true edge length shows 12–30 grey levels and a fifth of all boundary
//! length is fainter than 10 (don't-care). Defocus σ is
//! 0.7–1.5 px per scene; noise is Gaussian (σ 0, 2, 5, 10) or
//! signal-dependent (shot + read). Every scene has a Weng lens
//! (`CameraModel`, corners moved 3–6 px at 512²) through which it can be
//! rendered, and the `.cdf` that corrects it.
//!
//! **Why it differs from the cube family** (`synth::render`, 3-D polyhedra):
//! - geometry: 2.5-D layers of convex facets in the image plane (no camera
//!   projection, no depth test), with the close parallel and near-collinear
//!   edges the cube family's redraw rule excludes (it keeps edges ≥ 8 px
//!   apart and ≥ 30 grey levels);
//! - sampling: the exact area of each facet in each pixel's footprint (its
//!   square, or its corners mapped through the lens), by polygon clipping,
//!   instead of 256 sheared samples with a depth test;
//! - radiance: layered grey levels under a spot light and vignetting, with
//!   texture and highlights, instead of Lambertian faces under point lights;
//! - blur: a pillbox (uniform disk) instead of a Gaussian;
//! - noise: PCG32 and Marsaglia's polar method, Gaussian or signal-dependent,
//!   instead of SplitMix64 and Box–Muller with one σ;
//! - truth: boundaries between facets with a contrast each; faint ones and
//!   those in the 8-px border band are don't-care (`score::Tally::add_with`).
//!
//! Deterministic for a seed.

mod build;
mod poly;
mod render;
mod shade;
mod truth;

pub use build::KINDS;
pub use truth::{YardTruth, truth};

use crate::formats::cdf::Cdf;
use crate::llv::GreyImage;
use crate::llv::lens::CameraModel;
use poly::Convex;
use shade::{Light, Shade};

/// One facet: a convex polygon (ideal px) and what it emits.
#[derive(Clone, Debug, PartialEq)]
pub struct Facet {
    pub poly: Convex,
    pub shade: Shade,
}

/// A yard scene: facets back to front, the light field, the defocus and the
/// lens of the camera.
#[derive(Clone, Debug, PartialEq)]
pub struct YardScene {
    pub width: usize,
    pub height: usize,
    pub facets: Vec<Facet>,
    pub light: Light,
    /// Defocus σ (px per axis; the pillbox radius is 2σ).
    pub defocus_sigma: f64,
    /// The camera's lens (ideal ↔ observed), for distorted renders.
    pub lens: CameraModel,
    /// What the scene holds (object kinds, back to front).
    pub kinds: Vec<&'static str>,
}

/// Sensor noise of a yard image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum YardNoise {
    /// Gaussian, σ grey levels, the same everywhere.
    Gauss(f64),
    /// Variance `gain · I + read²` at grey level `I`.
    Signal { gain: f64, read: f64 },
}

impl YardNoise {
    /// The signal-dependent noise of the family: σ ≈ 3.6 at grey 40, 5.4
    /// at 128, 7.1 at 230.
    pub const SIGNAL: YardNoise = YardNoise::Signal {
        gain: 0.2,
        read: 2.0,
    };
}

/// `n` scenes of `size × size` px.
pub fn yard_scenes(n: usize, size: usize, seed: u64) -> Vec<YardScene> {
    (0..n).map(|i| build::scene(i, size, seed)).collect()
}

impl YardScene {
    /// The noise-free render before defocus (unclamped grey levels), as the
    /// ideal camera or through the lens.
    pub fn render_exact(&self, distort: bool) -> Vec<f64> {
        render::render_exact(self, distort)
    }

    /// [`render_exact`](Self::render_exact) with the scene's defocus.
    pub fn render_blurred(&self, distort: bool) -> Vec<f64> {
        let exact = self.render_exact(distort);
        render::defocus(&exact, self.width, self.height, self.defocus_sigma)
    }

    /// Noise and quantisation of a [`render_blurred`](Self::render_blurred)
    /// result.
    pub fn expose(&self, blurred: &[f64], noise: YardNoise, seed: u64) -> GreyImage {
        render::expose(blurred, self.width, self.height, noise, seed)
    }

    /// The finished image.
    pub fn image(&self, noise: YardNoise, seed: u64, distort: bool) -> GreyImage {
        self.expose(&self.render_blurred(distort), noise, seed)
    }

    /// The camera description that corrects the distorted renders.
    pub fn cdf(&self) -> Cdf {
        Cdf::from_camera(&self.lens, None)
    }
}

#[cfg(test)]
mod tests;
