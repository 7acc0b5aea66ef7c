//! Lens correction (spec/lens.md): Weng's camera model with one radial and
//! the folded decentering/thin-prism terms, in millimetres on the image plane.
//!
//! The undistortion map and the resampling are built on [`CameraModel`].

use serde::{Deserialize, Serialize};

/// The intrinsic part of a camera description (`.cdf`): what lens correction
/// and the synthetic cameras need.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraModel {
    /// Image centre `C` (pixels).
    pub cx: f64,
    pub cy: f64,
    /// Scale factors `S` (mm per pixel).
    pub sx: f64,
    pub sy: f64,
    /// Focal length (mm).
    pub f: f64,
    /// Distortion `(k1, g1, g2, g3, g4)`; `None` when the `.cdf` says `N`
    /// (lens correction is then the identity).
    pub distortion: Option<[f64; 5]>,
}

impl CameraModel {
    /// Image-plane millimetres of pixel `(x, y)`.
    pub fn to_mm(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.cx) * self.sx, (y - self.cy) * self.sy)
    }

    /// Pixel of image-plane millimetres `(u, v)`.
    pub fn to_px(&self, u: f64, v: f64) -> (f64, f64) {
        (u / self.sx + self.cx, v / self.sy + self.cy)
    }

    /// The distortion `(δu, δv)` at `(u, v)` (mm), lens.md.
    pub fn delta(&self, u: f64, v: f64) -> (f64, f64) {
        let Some([k1, g1, g2, g3, g4]) = self.distortion else {
            return (0.0, 0.0);
        };
        let r2 = u * u + v * v;
        let du = (g1 + g3) * u * u + g4 * u * v + g1 * v * v + k1 * u * r2;
        let dv = g2 * u * u + g3 * u * v + (g2 + g4) * v * v + k1 * v * r2;
        (du, dv)
    }

    /// Where an ideal (undistorted) pixel position was observed: three
    /// fixed-point steps of `ud = u + δu(ud, vd)` (lens.md, Resampling).
    pub fn ideal_to_observed(&self, x: f64, y: f64) -> (f64, f64) {
        let (u, v) = self.to_mm(x, y);
        let (mut ud, mut vd) = (u, v);
        for _ in 0..3 {
            let (du, dv) = self.delta(ud, vd);
            ud = u + du;
            vd = v + dv;
        }
        self.to_px(ud, vd)
    }

    /// The ideal position of an observed pixel position: `u = ud - δu(ud, vd)`
    /// (exact, no iteration). The synthetic cameras render distorted images
    /// with this.
    pub fn observed_to_ideal(&self, xd: f64, yd: f64) -> (f64, f64) {
        let (ud, vd) = self.to_mm(xd, yd);
        let (du, dv) = self.delta(ud, vd);
        self.to_px(ud - du, vd - dv)
    }

    /// True when lens correction would change nothing.
    pub fn is_identity(&self) -> bool {
        self.distortion.is_none_or(|d| d.iter().all(|&c| c == 0.0))
    }
}
