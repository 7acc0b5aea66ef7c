//! The forward model the solver fits: a plate point through a pose `[R | t]`
//! and the pinhole to its ideal position in millimetres, then through the
//! Weng distortion to where it is observed, in pixels — with the derivatives
//! of that pixel by every parameter.
//!
//! The camera itself is [`CameraModel`], the one lens correction uses: the
//! observed position is `CameraModel::ideal_to_observed_converged`, the same
//! fixed point the correction map inverts, so a `.cdf` the solver writes
//! corrects images exactly as it was fitted. The derivatives follow from the
//! implicit equation `w = p + δ(w)` of lens.md: `dw = (I − ∂δ/∂w)⁻¹ (dp +
//! ∂δ/∂D dD)`.

use nalgebra::{Matrix2, Rotation3, SMatrix, Vector2, Vector3};

use crate::llv::lens::CameraModel;

/// Intrinsic parameters in the solver's order: `Cx, Cy, f`, the radial
/// `k1`, Weng's decentering `p1, p2` and thin prism `s1, s2`, the higher
/// radial `k2, k3` (`.cdf` `K`), then `sy` when the scale is estimated.
///
/// The `.cdf` stores Weng's folded terms (lens.md): `g1 = p1 + s1`,
/// `g2 = p2 + s2`, `g3 = 2 p1`, `g4 = 2 p2`. The solver works with the
/// unfolded ones so that the thin prism can be left out (fixed at zero)
/// without touching the decentering: see `docs/calibration.md`.
pub const INTRINSIC_NAMES: [&str; N_INTRINSICS] = [
    "Cx", "Cy", "f", "k1", "p1", "p2", "s1", "s2", "k2", "k3", "sy",
];

/// How many intrinsics the solver knows.
pub const N_INTRINSICS: usize = 11;

/// Index of `s1` in [`INTRINSIC_NAMES`] (`s2` follows it).
const S1: usize = 6;
/// Index of `k2` in [`INTRINSIC_NAMES`] (`k3` follows it).
const K2: usize = 8;
/// Index of `sy` in [`INTRINSIC_NAMES`].
pub const SY: usize = 10;

/// Indices in [`INTRINSIC_NAMES`] of the terms only the full model
/// estimates: the thin prism `s1, s2` and the radial `k3`.
pub const FULL_ONLY: [usize; 3] = [S1, S1 + 1, K2 + 1];

/// Weng's folded `D = (k1, g1, g2, g3, g4)` from `(k1, p1, p2, s1, s2)`.
pub fn fold(k1: f64, p1: f64, p2: f64, s1: f64, s2: f64) -> [f64; 5] {
    [k1, p1 + s1, p2 + s2, 2.0 * p1, 2.0 * p2]
}

/// `(k1, p1, p2, s1, s2)` from Weng's folded `D`.
pub fn unfold(d: &[f64; 5]) -> [f64; 5] {
    let (p1, p2) = (d[3] / 2.0, d[4] / 2.0);
    [d[0], p1, p2, d[1] - p1, d[2] - p2]
}

/// A view's pose: plate → camera, as a rotation vector (axis × angle, rad)
/// and a translation (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub rotation: Vector3<f64>,
    pub translation: Vector3<f64>,
}

impl Pose {
    pub fn rotation_matrix(&self) -> Rotation3<f64> {
        Rotation3::new(self.rotation)
    }

    /// `[R | t]` as the `.cdf` writes it.
    pub fn matrix(&self) -> [[f64; 4]; 3] {
        let r = self.rotation_matrix();
        std::array::from_fn(|i| [r[(i, 0)], r[(i, 1)], r[(i, 2)], self.translation[i]])
    }

    /// From a rotation matrix and a translation.
    pub fn from_rt(r: &Rotation3<f64>, t: Vector3<f64>) -> Pose {
        Pose {
            rotation: r.scaled_axis(),
            translation: t,
        }
    }

    /// The plate point in the camera frame.
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation_matrix() * x + self.translation
    }
}

/// Where a point is observed and how that moves with the parameters.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    /// Observed position (px).
    pub px: Vector2<f64>,
    /// By the intrinsics, in [`INTRINSIC_NAMES`] order.
    pub d_intrinsics: SMatrix<f64, 2, N_INTRINSICS>,
    /// By the pose: rotation vector, then translation.
    pub d_pose: SMatrix<f64, 2, 6>,
}

/// The intrinsics as the solver's vector (`sy` last).
pub fn intrinsics_vector(m: &CameraModel) -> [f64; N_INTRINSICS] {
    let d = unfold(&m.distortion.unwrap_or([0.0; 5]));
    let [k2, k3] = m.radial;
    [m.cx, m.cy, m.f, d[0], d[1], d[2], d[3], d[4], k2, k3, m.sy]
}

/// A camera from the solver's vector (`sx` kept from `base`).
pub fn model_from(v: &[f64], base: &CameraModel, estimate_sy: bool) -> CameraModel {
    let g = |i: usize| v.get(i).copied().unwrap_or(0.0);
    CameraModel {
        cx: g(0),
        cy: g(1),
        f: g(2),
        distortion: Some(fold(g(3), g(4), g(5), g(6), g(7))),
        radial: [g(K2), g(K2 + 1)],
        sx: base.sx,
        sy: if estimate_sy { g(SY) } else { base.sy },
    }
}

/// `∂(R(ω) y₀)/∂ω` with `y = R(ω) y₀` (Gallego & Yezzi, "A compact formula
/// for the derivative of a 3-D rotation in exponential coordinates", 2015).
fn d_rotation(omega: &Vector3<f64>, r: &Rotation3<f64>, y: &Vector3<f64>) -> SMatrix<f64, 3, 3> {
    let n2 = omega.norm_squared();
    let mut out = SMatrix::<f64, 3, 3>::zeros();
    for i in 0..3 {
        let e = Vector3::ith(i, 1.0);
        let col = if n2 < 1e-16 {
            e.cross(y)
        } else {
            let w = omega.cross(&(e - r * e));
            (omega.cross(y) * omega[i] + w.cross(y)) / n2
        };
        out.set_column(i, &col);
    }
    out
}

/// Projects plate point `x` (mm, plate frame) through `pose` and camera `m`.
/// `None` when the point is not in front of the camera or the distortion's
/// fixed point does not settle.
pub fn project(m: &CameraModel, pose: &Pose, x: &Vector3<f64>) -> Option<Projection> {
    let r = pose.rotation_matrix();
    let y = r * x;
    let q = y + pose.translation;
    if q.z.is_nan() || q.z <= 1e-6 {
        return None;
    }
    let p = Vector2::new(m.f * q.x / q.z, m.f * q.y / q.z);
    let (ix, iy) = m.to_px(p.x, p.y);
    let (ox, oy) = m.ideal_to_observed_converged(ix, iy);
    let (wu, wv) = m.to_mm(ox, oy);
    if !(wu.is_finite() && wv.is_finite()) {
        return None;
    }
    let (by_uv, by_d) = m.delta_derivatives(wu, wv);
    let a = Matrix2::new(
        1.0 - by_uv[0][0],
        -by_uv[0][1],
        -by_uv[1][0],
        1.0 - by_uv[1][1],
    )
    .try_inverse()?;
    // Observed mm → px.
    let to_px = Matrix2::new(1.0 / m.sx, 0.0, 0.0, 1.0 / m.sy);
    let ap = to_px * a;
    let dp_dq = SMatrix::<f64, 2, 3>::new(
        m.f / q.z,
        0.0,
        -m.f * q.x / (q.z * q.z),
        0.0,
        m.f / q.z,
        -m.f * q.y / (q.z * q.z),
    );
    let dq_dw = d_rotation(&pose.rotation, &r, &y);
    let mut d_pose = SMatrix::<f64, 2, 6>::zeros();
    d_pose
        .fixed_view_mut::<2, 3>(0, 0)
        .copy_from(&(ap * dp_dq * dq_dw));
    d_pose.fixed_view_mut::<2, 3>(0, 3).copy_from(&(ap * dp_dq));
    let mut d_intrinsics = SMatrix::<f64, 2, N_INTRINSICS>::zeros();
    d_intrinsics[(0, 0)] = 1.0;
    d_intrinsics[(1, 1)] = 1.0;
    d_intrinsics
        .fixed_view_mut::<2, 1>(0, 2)
        .copy_from(&(ap * (p / m.f)));
    // By (k1, p1, p2, s1, s2) through the folding g = fold(k1, p1, p2, s1, s2),
    // then by k2, k3.
    let jd = SMatrix::<f64, 2, 7>::from_fn(|i, j| match j {
        0 => by_d[i][0],
        1 => by_d[i][1] + 2.0 * by_d[i][3],
        2 => by_d[i][2] + 2.0 * by_d[i][4],
        3 => by_d[i][1],
        4 => by_d[i][2],
        _ => by_d[i][j],
    });
    d_intrinsics
        .fixed_view_mut::<2, 7>(0, 3)
        .copy_from(&(ap * jd));
    d_intrinsics[(1, SY)] = -wv / (m.sy * m.sy);
    Some(Projection {
        px: Vector2::new(ox, oy),
        d_intrinsics,
        d_pose,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_named_indices_name_their_terms() {
        let name = |i: usize| INTRINSIC_NAMES[i];
        assert_eq!([name(S1), name(S1 + 1)], ["s1", "s2"]);
        assert_eq!([name(K2), name(K2 + 1), name(SY)], ["k2", "k3", "sy"]);
        let full: Vec<_> = FULL_ONLY.iter().map(|&i| name(i)).collect();
        assert_eq!(full, ["s1", "s2", "k3"]);
        // The vector puts each term where its name is.
        let m = CameraModel {
            radial: [2.0, 3.0],
            sy: 4.0,
            ..camera()
        };
        let v = intrinsics_vector(&m);
        assert_eq!([v[K2], v[K2 + 1], v[SY]], [2.0, 3.0, 4.0]);
    }

    fn camera() -> CameraModel {
        CameraModel {
            cx: 257.5,
            cy: 255.0,
            sx: 0.0112,
            sy: 0.0078,
            f: 12.1,
            distortion: Some([-0.00049, -0.0002, 0.00076, 0.00034, -0.00064]),
            radial: [2.0e-5, -3.0e-7],
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let m = camera();
        let pose = Pose {
            rotation: Vector3::new(0.3, -0.2, 0.1),
            translation: Vector3::new(-80.0, 40.0, 1200.0),
        };
        let x = Vector3::new(120.0, 90.0, 0.0);
        let pr = project(&m, &pose, &x).unwrap();
        let base = intrinsics_vector(&m);
        for k in 0..N_INTRINSICS {
            let h = (base[k].abs() * 1e-6).max(1e-9);
            let mut v = base;
            v[k] += h;
            let mut v2 = base;
            v2[k] -= h;
            let a = project(&model_from(&v, &m, true), &pose, &x).unwrap().px;
            let b = project(&model_from(&v2, &m, true), &pose, &x).unwrap().px;
            let num = (a - b) / (2.0 * h);
            let an = pr.d_intrinsics.column(k);
            let tol = 1e-5 * (num.norm() + an.norm()) + 1e-9;
            assert!(
                (num - an).norm() < tol,
                "{} {num:?} {an:?}",
                INTRINSIC_NAMES[k]
            );
        }
        for k in 0..6 {
            let h = 1e-6;
            let mut p1 = pose;
            let mut p2 = pose;
            if k < 3 {
                p1.rotation[k] += h;
                p2.rotation[k] -= h;
            } else {
                p1.translation[k - 3] += h;
                p2.translation[k - 3] -= h;
            }
            let a = project(&m, &p1, &x).unwrap().px;
            let b = project(&m, &p2, &x).unwrap().px;
            let num = (a - b) / (2.0 * h);
            let an = pr.d_pose.column(k);
            assert!(
                (num - an).norm() < 1e-4 * (1.0 + an.norm()),
                "pose {k}: {num:?} {an:?}"
            );
        }
    }

    #[test]
    fn the_projection_is_the_lens_corrections_inverse() {
        // Lens correction takes an observed pixel back to the ideal one.
        let m = camera();
        let pose = Pose {
            rotation: Vector3::new(0.1, 0.2, 0.0),
            translation: Vector3::new(-150.0, -120.0, 1000.0),
        };
        let x = Vector3::new(10.0, 20.0, 0.0);
        let pr = project(&m, &pose, &x).unwrap();
        let (ix, iy) = m.observed_to_ideal(pr.px.x, pr.px.y);
        let q = pose.apply(&x);
        let (ex, ey) = m.to_px(m.f * q.x / q.z, m.f * q.y / q.z);
        assert!((ix - ex).hypot(iy - ey) < 1e-6);
    }
}
