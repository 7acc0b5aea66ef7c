//! The extrinsic pose `T` (world → camera) from one view of the plate lying
//! at its known place in the cell: the plate's pose in the camera
//! ([`super::solve_pose`], the intrinsics fixed) composed with the inverse of
//! the plate's place (plate → world, from the plate file).

use nalgebra::{Matrix3, Vector3};

use super::{CalibError, Plate, View, solve_pose};
use crate::llv::lens::CameraModel;

/// The extrinsic calibration of one view.
#[derive(Clone, Debug, PartialEq)]
pub struct Extrinsic {
    /// World → camera `[R | t]` (mm).
    pub t: [[f64; 4]; 3],
    /// Reprojection error of the view (px): RMS, 95th percentile.
    pub rms: f64,
    pub p95: f64,
    /// Standard errors of the plate's pose in the camera: rotation (degrees,
    /// largest component) and translation (mm, each axis).
    pub se_rotation_deg: f64,
    pub se_translation: [f64; 3],
}

/// Solves `T` from one view of `plate` at its place.
pub fn extrinsic(view: &View, plate: &Plate, m: &CameraModel) -> Result<Extrinsic, CalibError> {
    let place = plate.place.ok_or_else(|| {
        CalibError::NoPlace(
            plate
                .source
                .as_ref()
                .map_or(plate.name.clone(), crate::text::path),
        )
    })?;
    if !plate.oriented() {
        return Err(CalibError::Symmetric(plate.name.clone()));
    }
    let (pose, rms, p95, se) = solve_pose(view, m)?;
    // camera ← plate ← world: x_c = R_pc (R_pwᵀ (x_w − o)) + t_pc.
    let r_pc = pose.rotation_matrix().into_inner();
    let r_pw = Matrix3::from_fn(|i, j| place.rotation[i][j]);
    let o = Vector3::from(place.origin);
    let r = r_pc * r_pw.transpose();
    let t = pose.translation - r * o;
    Ok(Extrinsic {
        t: std::array::from_fn(|i| [r[(i, 0)], r[(i, 1)], r[(i, 2)], t[i]]),
        rms,
        p95,
        se_rotation_deg: se[..3].iter().copied().fold(0.0, f64::max).to_degrees(),
        se_translation: [se[3], se[4], se[5]],
    })
}
