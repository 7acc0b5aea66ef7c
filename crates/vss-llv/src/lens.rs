//! Lens correction (spec/lens.md): Weng's camera model with the radial
//! and the folded decentering/thin-prism terms, in millimetres on the image
//! plane. Beside the spec's one radial term `k1` (`.cdf` `D`), the model has
//! the `r⁴` and `r⁶` terms `k2, k3` (`.cdf` `K`, zero when absent): a real
//! lens's radial distortion is not one power of `r` (docs/calibration.md).
//!
//! The undistortion map ([`LensMap`]: for every pixel of the corrected image,
//! where it was observed) depends only on the camera and the image size, so
//! it is computed once and reused for every image and lighting; [`correct`]
//! then resamples with bilinear interpolation. Pixels whose source falls
//! outside the grabbed image (or touches an invalid pixel) come out invalid.

use serde::{Deserialize, Serialize};

use super::LlvError;
use super::image::GreyImage;

mod map;
mod resample;

pub use map::LensMap;

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
    /// The higher radial terms `(k2, k3)` of `r⁴` and `r⁶` (`.cdf` `K`;
    /// zeros when the file has none). They apply only with `distortion`.
    #[serde(default)]
    pub radial: [f64; 2],
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
        let [k2, k3] = self.radial;
        let r2 = u * u + v * v;
        let k = k1 * r2 + (k2 + k3 * r2) * r2 * r2;
        let du = (g1 + g3) * u * u + g4 * u * v + g1 * v * v + k * u;
        let dv = g2 * u * u + g3 * u * v + (g2 + g4) * v * v + k * v;
        (du, dv)
    }

    /// The derivatives of [`delta`](Self::delta) at `(u, v)`: by `(u, v)`
    /// (`[[∂δu/∂u, ∂δu/∂v], [∂δv/∂u, ∂δv/∂v]]`) and by the coefficients
    /// `(k1, g1, g2, g3, g4, k2, k3)`, for the calibration's solver (`vss::calib`).
    pub fn delta_derivatives(&self, u: f64, v: f64) -> ([[f64; 2]; 2], [[f64; 7]; 2]) {
        let [k1, g1, g2, g3, g4] = self.distortion.unwrap_or([0.0; 5]);
        let [k2, k3] = self.radial;
        let r2 = u * u + v * v;
        let (r4, r6) = (r2 * r2, r2 * r2 * r2);
        // The radial factor k(r²) and its derivative by r².
        let k = k1 * r2 + k2 * r4 + k3 * r6;
        let dk = k1 + 2.0 * k2 * r2 + 3.0 * k3 * r4;
        let by_uv = [
            [
                2.0 * (g1 + g3) * u + g4 * v + k + 2.0 * dk * u * u,
                g4 * u + 2.0 * g1 * v + 2.0 * dk * u * v,
            ],
            [
                2.0 * g2 * u + g3 * v + 2.0 * dk * u * v,
                g3 * u + 2.0 * (g2 + g4) * v + k + 2.0 * dk * v * v,
            ],
        ];
        let by_d = [
            [u * r2, r2, 0.0, u * u, u * v, u * r4, u * r6],
            [v * r2, 0.0, r2, u * v, v * v, v * r4, v * r6],
        ];
        (by_uv, by_d)
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

    /// Where an ideal pixel position was observed, solved to convergence:
    /// Newton's method on `ud − δu(ud, vd) = u`, `vd − δv(ud, vd) = v`
    /// from `(u, v)`, until a step moves less than 1e-7 px (at most 50
    /// steps). What the calibration projects with. Where the solve fails
    /// (see [`ideal_to_observed_checked`](Self::ideal_to_observed_checked))
    /// the last iterate is returned.
    pub fn ideal_to_observed_converged(&self, x: f64, y: f64) -> (f64, f64) {
        match self.solve_observed(x, y) {
            Ok(p) | Err(p) => p,
        }
    }

    /// [`ideal_to_observed_converged`](Self::ideal_to_observed_converged),
    /// or `None` where the ideal position has no observed one: the solve
    /// does not converge, or it ends where the observed-to-ideal map folds
    /// (its Jacobian `I − ∂δ` is not positive there, so the observed image
    /// is mirrored onto itself). What [`LensMap`] uses: such pixels come out
    /// invalid instead of sampled from wherever the iteration stopped.
    /// Fixed-point steps `ud = u + δu(ud, vd)` (lens.md) diverge once
    /// `|∂δ|` exceeds 1, e.g. a wide-angle lens's corners; Newton's steps
    /// converge wherever the map is one-to-one.
    pub fn ideal_to_observed_checked(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        self.solve_observed(x, y).ok()
    }

    /// Newton's method for [`ideal_to_observed_checked`]: `Ok` converged
    /// where the map is one-to-one, else `Err` with the last finite iterate.
    fn solve_observed(&self, x: f64, y: f64) -> Result<(f64, f64), (f64, f64)> {
        let (u, v) = self.to_mm(x, y);
        let (mut ud, mut vd) = (u, v);
        let tol = 1e-7 * self.sx.abs().min(self.sy.abs());
        for _ in 0..50 {
            let (du, dv) = self.delta(ud, vd);
            let (ru, rv) = (ud - du - u, vd - dv - v);
            let ([[a, b], [c, d]], det) = self.observed_to_ideal_jacobian(ud, vd);
            // Not one-to-one here (or not a number): no step to take.
            if det.is_nan() || det <= 0.0 {
                return Err(self.to_px(ud, vd));
            }
            let (su, sv) = ((d * ru - b * rv) / det, (a * rv - c * ru) / det);
            if !(su.is_finite() && sv.is_finite()) {
                return Err(self.to_px(ud, vd));
            }
            ud -= su;
            vd -= sv;
            if su.abs().max(sv.abs()) <= tol {
                return Ok(self.to_px(ud, vd));
            }
        }
        Err(self.to_px(ud, vd))
    }

    /// The ideal position of an observed pixel position: `u = ud - δu(ud, vd)`
    /// (exact, no iteration). The synthetic cameras render distorted images
    /// with this.
    pub fn observed_to_ideal(&self, xd: f64, yd: f64) -> (f64, f64) {
        let (ud, vd) = self.to_mm(xd, yd);
        let (du, dv) = self.delta(ud, vd);
        self.to_px(ud - du, vd - dv)
    }

    /// `I − ∂δ` at `(u, v)` (mm), the Jacobian of the observed-to-ideal
    /// map, and its determinant: not positive where that map folds.
    fn observed_to_ideal_jacobian(&self, u: f64, v: f64) -> ([[f64; 2]; 2], f64) {
        let (j, _) = self.delta_derivatives(u, v);
        let m = [[1.0 - j[0][0], -j[0][1]], [-j[1][0], 1.0 - j[1][1]]];
        (m, m[0][0] * m[1][1] - m[0][1] * m[1][0])
    }

    /// The observed pixel nearest the centre `C` where this distortion
    /// folds a `width × height` image, if it does: where the Jacobian of
    /// the observed-to-ideal map (`I − ∂δ`) is not positive, two places of
    /// the scene would be seen at one pixel, which no lens does (a `D` or
    /// `K` mistyped: a digit, a sign). Checked on a grid of at most
    /// 65 × 65 points over the image, its last row and column included.
    pub fn fold_in(&self, width: usize, height: usize) -> Option<(f64, f64)> {
        if self.is_identity() || width == 0 || height == 0 {
            return None;
        }
        let points = |n: usize| {
            let step = ((n - 1) as f64 / 64.0).max(1.0);
            let count = ((n - 1) as f64 / step).round() as usize;
            (0..=count).map(move |i| (i as f64 * step).min((n - 1) as f64))
        };
        let mut nearest: Option<(f64, (f64, f64))> = None;
        for y in points(height) {
            for x in points(width) {
                let (u, v) = self.to_mm(x, y);
                let (_, det) = self.observed_to_ideal_jacobian(u, v);
                let d = (x - self.cx).hypot(y - self.cy);
                if (det.is_nan() || det <= 0.0) && nearest.is_none_or(|(n, _)| d < n) {
                    nearest = Some((d, (x, y)));
                }
            }
        }
        nearest.map(|(_, p)| p)
    }

    /// True when lens correction would change nothing.
    pub fn is_identity(&self) -> bool {
        self.distortion
            .is_none_or(|d| d.iter().chain(&self.radial).all(|&c| c == 0.0))
    }
}

/// Lens correction of `img` with `map` (which must have the image's size).
/// With an identity map the result is a copy of the image.
pub fn correct(img: &GreyImage, map: &LensMap) -> Result<GreyImage, LlvError> {
    let mut out = GreyImage::default();
    correct_into(img, map, &mut out)?;
    Ok(out)
}

/// [`correct`] into a reusable image (its pixel and mask buffers are kept).
pub fn correct_into(img: &GreyImage, map: &LensMap, out: &mut GreyImage) -> Result<(), LlvError> {
    let (w, h) = img.size();
    if map.size() != (w, h) {
        return Err(LlvError::SizeMismatch {
            a: (w, h),
            b: map.size(),
        });
    }
    let mut mask = out.take_valid_mask().unwrap_or_default();
    let mut data = std::mem::take(out).into_data();
    if map.is_identity() {
        data.clear();
        data.extend_from_slice(img.data());
        let mut o = GreyImage::new(w, h, data)?;
        if let Some(m) = img.valid_mask() {
            mask.clear();
            mask.extend_from_slice(m);
            o.set_valid_mask(Some(mask))?;
        }
        *out = o;
        return Ok(());
    }
    let n = w * h;
    // Every pixel is written below: no need to clear the old contents.
    data.resize(n, 0);
    resample::values(img.data(), map, &mut data);
    // The mask only when some pixel is invalid (its buffer is then kept in
    // the output image and reused next time).
    let any_invalid = match img.valid_mask() {
        None if map.any_outside => {
            mask.resize(n, false);
            resample::map_mask(map, &mut mask);
            true
        }
        None => false,
        Some(smask) => {
            mask.resize(n, false);
            resample::masked(smask, map, &mut mask, &mut data)
        }
    };
    let mut o = GreyImage::new(w, h, data)?;
    if any_invalid {
        o.set_valid_mask(Some(mask))?;
    }
    *out = o;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell_model() -> CameraModel {
        CameraModel {
            cx: 256.0,
            cy: 256.0,
            sx: 0.0086,
            sy: 0.0083,
            f: 8.5,
            distortion: Some([-2.0e-3, 2.0e-4, -1.5e-4, 1.0e-4, 5.0e-5]),
            radial: [3.0e-5, -2.0e-7],
        }
    }

    #[test]
    fn map_round_trips_through_the_forward_model() {
        let m = cell_model();
        let map = LensMap::new(&m, 512, 512);
        assert!(!map.is_identity());
        let mut worst = 0.0f64;
        let mut moved = 0.0f64;
        for y in (0..512).step_by(17) {
            for x in (0..512).step_by(13) {
                let (xs, ys) = map.source(x, y).unwrap();
                let (xi, yi) = m.observed_to_ideal(xs as f64, ys as f64);
                worst = worst.max((xi - x as f64).hypot(yi - y as f64));
                moved = moved.max((xs as f64 - x as f64).hypot(ys as f64 - y as f64));
            }
        }
        assert!(worst < 0.01, "round trip error {worst} px");
        assert!(
            moved > 0.5,
            "the test model should distort visibly ({moved} px)"
        );
    }

    /// A wide-angle lens: the corrected image's corners were observed 28 %
    /// nearer the centre (`k1 r²` ≈ −0.39 at the observed point), where
    /// fixed-point steps `ud = u + δu(ud, vd)` no longer converge (their
    /// factor `3 |k1| r²` exceeds 1).
    fn wide_angle_model() -> CameraModel {
        CameraModel {
            distortion: Some([-0.08, 2.0e-4, -1.5e-4, 1.0e-4, 5.0e-5]),
            radial: [0.0; 2],
            ..cell_model()
        }
    }

    #[test]
    fn a_wide_angle_lens_is_inverted_everywhere_not_only_near_the_middle() {
        let m = wide_angle_model();
        let map = LensMap::new(&m, 512, 512);
        let (mut worst, mut invalid) = (0.0f64, Vec::new());
        for y in (0..512).step_by(7) {
            for x in (0..512).step_by(7) {
                // Barrel distortion: every corrected pixel was observed
                // inside the image.
                let Some((xs, ys)) = map.source(x, y) else {
                    invalid.push((x, y));
                    continue;
                };
                let (xi, yi) = m.observed_to_ideal(xs as f64, ys as f64);
                worst = worst.max((xi - x as f64).hypot(yi - y as f64));
            }
        }
        assert!(worst < 0.01, "round trip error {worst} px");
        assert!(
            invalid.is_empty(),
            "{} pixels without a source, e.g. {:?}",
            invalid.len(),
            invalid.first()
        );
    }

    #[test]
    fn a_distortion_that_folds_the_image_is_found_where_it_folds() {
        // k1 = +0.05 mm⁻² (a digit lost from −0.0005): the observed-to-ideal
        // map turns back 2.58 mm from the centre, inside a 512² image.
        let folds = CameraModel {
            distortion: Some([0.05, 0.0, 0.0, 0.0, 0.0]),
            radial: [0.0; 2],
            ..cell_model()
        };
        let (x, y) = folds.fold_in(512, 512).expect("it folds");
        let r = folds.to_mm(x, y);
        let r = r.0.hypot(r.1);
        // Where 1 − 3 k1 r² turns negative, to the grid's spacing.
        let edge = (1.0f64 / (3.0 * 0.05)).sqrt();
        assert!((r - edge).abs() < 0.1, "folds at {r} mm, not {edge}");
        // A smaller image (its centre in the middle) stays inside the fold.
        let small = CameraModel {
            cx: 100.0,
            cy: 100.0,
            ..folds
        };
        assert_eq!(small.fold_in(200, 200), None);
        assert_eq!(cell_model().fold_in(512, 512), None);
        assert_eq!(wide_angle_model().fold_in(512, 512), None);
    }

    #[test]
    fn identity_map_holds_nothing_and_copies_the_image() {
        let m = CameraModel {
            distortion: None,
            ..cell_model()
        };
        let map = LensMap::new(&m, 64, 48);
        assert!(map.is_identity());
        assert_eq!(
            map.runs.capacity() + map.row_runs.capacity() + map.fx.capacity() + map.fy.capacity(),
            0
        );
        let img = GreyImage::new(64, 48, (0..64 * 48).map(|i| (i % 251) as u8).collect()).unwrap();
        assert_eq!(correct(&img, &map).unwrap(), img);
        assert!(correct(&img, &LensMap::identity(10, 10)).is_err());
    }

    #[test]
    fn resampling_is_bilinear_and_marks_outside_pixels_invalid() {
        // A pure shift by (0.25, 0.5) px: distortion with only a constant
        // term is not expressible, so build the map by hand.
        let (w, h) = (20usize, 16usize);
        let map = LensMap::from_sources(w, h, |x, y| (x as f64 + 0.25, y as f64 + 0.5));
        let img = GreyImage::new(
            w,
            h,
            (0..w * h)
                .map(|i| ((i % w) * 8 + (i / w) * 4) as u8)
                .collect(),
        )
        .unwrap();
        let c = correct(&img, &map).unwrap();
        // Img(x,y) = 8x + 4y is linear: bilinear sampling is exact.
        assert_eq!(c.get(3, 2), Some((8.0f32 * 3.25 + 4.0 * 2.5 + 0.5) as u8));
        assert!(!c.is_valid(w - 1, 3), "source x beyond the last column");
        assert!(!c.is_valid(4, h - 1));
        assert!(c.is_valid(w - 2, h - 2));
    }

    #[test]
    fn an_invalid_source_pixel_invalidates_exactly_the_outputs_that_touch_it() {
        // Shift by (0.25, 0.5): output (x, y) samples source x..=x+1, y..=y+1.
        let (w, h) = (45usize, 23usize);
        let map = LensMap::from_sources(w, h, |x, y| (x as f64 + 0.25, y as f64 + 0.5));
        let pixels: Vec<u8> = (0..w * h).map(|i| (i * 37 % 256) as u8).collect();
        let plain = correct(&GreyImage::new(w, h, pixels.clone()).unwrap(), &map).unwrap();
        // One invalid source pixel, then a scatter of them.
        let one: Vec<bool> = (0..w * h).map(|i| i != 7 * w + 10).collect();
        let scatter: Vec<bool> = (0..w * h).map(|i| i * 7919 % 13 != 0).collect();
        for smask in [one, scatter] {
            let mut img = GreyImage::new(w, h, pixels.clone()).unwrap();
            img.set_valid_mask(Some(smask.clone())).unwrap();
            let c = correct(&img, &map).unwrap();
            for y in 0..h {
                for x in 0..w {
                    let touched_ok = x + 1 < w
                        && y + 1 < h
                        && [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
                            .iter()
                            .all(|&(sx, sy)| smask[sy * w + sx]);
                    assert_eq!(c.is_valid(x, y), touched_ok, "output ({x}, {y})");
                    let want = if touched_ok { plain.get(x, y) } else { Some(0) };
                    assert_eq!(c.get(x, y), want, "value at ({x}, {y})");
                }
            }
        }
        // The single invalid pixel (10, 7) spoils exactly four outputs.
        let mut img = GreyImage::new(w, h, pixels).unwrap();
        img.set_valid_mask(Some((0..w * h).map(|i| i != 7 * w + 10).collect()))
            .unwrap();
        let c = correct(&img, &map).unwrap();
        let spoiled: Vec<(usize, usize)> = (0..h - 1)
            .flat_map(|y| (0..w - 1).map(move |x| (x, y)))
            .filter(|&(x, y)| !c.is_valid(x, y))
            .collect();
        assert_eq!(spoiled, [(9, 6), (10, 6), (9, 7), (10, 7)]);
    }
}
