//! What a calibration could be off by: the uncertainty of projection at
//! the middle and the corners of the image, propagated from the solve's
//! covariance, and the cross-validation of two calibrations from halves of
//! the views.

use super::*;

/// The five places of the image where the projection's uncertainty is
/// stated: the middle, then the corners (top-left, top-right, bottom-left,
/// bottom-right), as `(name, pixel)`.
pub fn uncertainty_points(width: usize, height: usize) -> [(&'static str, [f64; 2]); 5] {
    let (w, h) = ((width.max(1) - 1) as f64, (height.max(1) - 1) as f64);
    [
        ("middle", [w / 2.0, h / 2.0]),
        ("top-left", [0.0, 0.0]),
        ("top-right", [w, 0.0]),
        ("bottom-left", [0.0, h]),
        ("bottom-right", [w, h]),
    ]
}

/// Projects a direction (camera frame, at infinity) to the observed pixel.
pub(super) fn project_dir(m: &CameraModel, d: &Vector3<f64>) -> Option<[f64; 2]> {
    if d.z <= 1e-9 {
        return None;
    }
    let (ix, iy) = m.to_px(m.f * d.x / d.z, m.f * d.y / d.z);
    let (ox, oy) = m.ideal_to_observed_converged(ix, iy);
    (ox.is_finite() && oy.is_finite()).then_some([ox, oy])
}

/// The direction (camera frame) observed at pixel `q`.
pub(super) fn unproject(m: &CameraModel, q: [f64; 2]) -> Vector3<f64> {
    let (ix, iy) = m.observed_to_ideal(q[0], q[1]);
    let (u, v) = m.to_mm(ix, iy);
    Vector3::new(u, v, m.f).normalize()
}

/// How far the projection of a far point seen at each of
/// [`uncertainty_points`] could be off (px, 1 σ, the worst direction), from
/// the corners' noise alone, as mrcal states it: the point is fixed in the
/// frame of the plates (the mean of its directions in every view's plate
/// frame), so that a change of the intrinsics the views' poses make up for
/// does not count. Linearised: `J Σ Jᵀ` with `Σ = s² (JᵀJ)⁻¹` over every
/// parameter and `J` by central differences. Empty when the covariance
/// cannot be had.
pub(super) fn projection_uncertainty(
    fit: &Fit,
    a: &DMatrix<f64>,
    ssr: f64,
    m: usize,
    o: &Options,
) -> Vec<([f64; 2], f64)> {
    let Some(cov) = covariance(a, ssr, m) else {
        return Vec::new();
    };
    let cam = fit.camera();
    let n = fit.x.len();
    let mut out = Vec::new();
    for (_, q) in uncertainty_points(o.width, o.height) {
        let d = unproject(&cam, q);
        // The direction in each view's plate frame.
        let dk: Vec<Vector3<f64>> = (0..fit.views.len())
            .map(|k| fit.pose(k).rotation_matrix().inverse() * d)
            .collect();
        let at = |x: &DVector<f64>| -> Option<[f64; 2]> {
            let f = Fit {
                views: fit.views,
                plate: Vec::new(),
                base: fit.base,
                iv: fit.iv,
                free: fit.free.clone(),
                n_intr: fit.n_intr,
                x: x.clone(),
                rows: 0,
            };
            let cam = f.camera();
            let mean = dk
                .iter()
                .enumerate()
                .map(|(k, v)| f.pose(k).rotation_matrix() * v)
                .fold(Vector3::zeros(), |s, v| s + v);
            project_dir(&cam, &mean.normalize())
        };
        let mut j = DMatrix::zeros(2, n);
        let mut ok = true;
        for c in 0..n {
            // Translations do not move a far point.
            if c >= fit.n_intr && (c - fit.n_intr) % 6 >= 3 {
                continue;
            }
            let h = 1e-6 * fit.x[c].abs().max(1e-3);
            let mut xp = fit.x.clone();
            xp[c] += h;
            let mut xm = fit.x.clone();
            xm[c] -= h;
            match (at(&xp), at(&xm)) {
                (Some(p), Some(q)) => {
                    j[(0, c)] = (p[0] - q[0]) / (2.0 * h);
                    j[(1, c)] = (p[1] - q[1]) / (2.0 * h);
                }
                _ => ok = false,
            }
        }
        if !ok {
            continue;
        }
        let v = &j * &cov * j.transpose();
        let (a, b, c) = (v[(0, 0)], v[(0, 1)], v[(1, 1)]);
        let worst = (a + c) / 2.0 + (((a - c) / 2.0).powi(2) + b * b).sqrt();
        out.push((q, worst.max(0.0).sqrt()));
    }
    out
}

/// Two calibrations from halves of the views (alternate views), each
/// judged on the other's views.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossCheck {
    /// RMS reprojection error (px) of the views each half left out, their
    /// poses solved with the other half's intrinsics.
    pub held_out_rms: f64,
    /// RMS and largest difference (px) between the two halves' projections
    /// over a grid across the image, once the best turn between their
    /// frames is allowed for.
    pub difference_rms: f64,
    pub difference_max: f64,
}

/// [`CrossCheck`] of a set of views, when each half has at least three.
pub fn cross_validate(views: &[View], o: &Options) -> Option<CrossCheck> {
    if views.len() < 6 {
        return None;
    }
    let (a, b): (Vec<_>, Vec<_>) = views.iter().enumerate().partition(|(k, _)| k % 2 == 0);
    let a: Vec<View> = a.into_iter().map(|(_, v)| v.clone()).collect();
    let b: Vec<View> = b.into_iter().map(|(_, v)| v.clone()).collect();
    let ca = calibrate(&a, o).ok()?;
    let cb = calibrate(&b, o).ok()?;
    let mut errs = Vec::new();
    for (model, held) in [(&ca.model, &b), (&cb.model, &a)] {
        for v in held.iter() {
            let (pose, ..) = solve_pose(v, model).ok()?;
            let cam = *model;
            for c in &v.corners {
                let p = model::project(
                    &cam,
                    &pose,
                    &Vector3::new(c.corner.xy[0], c.corner.xy[1], 0.0),
                )?;
                errs.push((p.px.x - c.px[0]).hypot(p.px.y - c.px[1]));
            }
        }
    }
    // The grid: directions by A, turned onto B's frame (Kabsch), projected by B.
    let g = 8;
    let mut qs = Vec::new();
    for j in 0..=g {
        for i in 0..=g {
            qs.push([
                i as f64 / g as f64 * (o.width.max(1) - 1) as f64,
                j as f64 / g as f64 * (o.height.max(1) - 1) as f64,
            ]);
        }
    }
    let da: Vec<Vector3<f64>> = qs.iter().map(|q| unproject(&ca.model, *q)).collect();
    let db: Vec<Vector3<f64>> = qs.iter().map(|q| unproject(&cb.model, *q)).collect();
    let h = da
        .iter()
        .zip(&db)
        .fold(Matrix3::zeros(), |s, (x, y)| s + y * x.transpose());
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut rot = u * vt;
    if rot.determinant() < 0.0 {
        let mut u2 = u;
        u2.column_mut(2).neg_mut();
        rot = u2 * vt;
    }
    let mut diffs = Vec::new();
    for (q, d) in qs.iter().zip(&da) {
        let p = project_dir(&cb.model, &(rot * d))?;
        diffs.push((p[0] - q[0]).hypot(p[1] - q[1]));
    }
    Some(CrossCheck {
        held_out_rms: rms(&errs),
        difference_rms: rms(&diffs),
        difference_max: diffs.iter().copied().fold(0.0, f64::max),
    })
}
