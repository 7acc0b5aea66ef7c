//! Closed-form starting values: a homography per view (the direct linear
//! transform with Hartley's normalisation), the intrinsics from three or more
//! of them by Zhang's method ("A flexible new technique for camera
//! calibration", PAMI 22, 2000, with zero skew), and each view's pose from
//! its homography. Distortion starts at zero; the solver refines everything.

use nalgebra::{DMatrix, Matrix3, Rotation3, SMatrix, SymmetricEigen, Vector3};

use super::model::Pose;

/// Pixel intrinsics of the pinhole: focal lengths in pixels and the centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Pinhole {
    fn k(&self) -> Matrix3<f64> {
        Matrix3::new(self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
    }
}

/// A similarity that moves points to their centroid and scales them to a
/// mean distance of √2.
fn normaliser(pts: &[[f64; 2]]) -> Matrix3<f64> {
    let n = pts.len().max(1) as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
    let d = pts
        .iter()
        .map(|p| (p[0] - mx).hypot(p[1] - my))
        .sum::<f64>()
        / n;
    let s = if d > 0.0 {
        std::f64::consts::SQRT_2 / d
    } else {
        1.0
    };
    Matrix3::new(s, 0.0, -s * mx, 0.0, s, -s * my, 0.0, 0.0, 1.0)
}

fn apply3(m: &Matrix3<f64>, p: [f64; 2]) -> [f64; 2] {
    let v = m * Vector3::new(p[0], p[1], 1.0);
    [v.x / v.z, v.y / v.z]
}

/// The eigenvector of the smallest eigenvalue of `AᵀA`.
fn null_vector(ata: DMatrix<f64>) -> Option<nalgebra::DVector<f64>> {
    let eig = SymmetricEigen::new(ata);
    let (k, _) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    Some(eig.eigenvectors.column(k).into_owned())
}

/// The homography taking plate points (mm) to image points (px), from four
/// or more correspondences.
pub fn homography(plate: &[[f64; 2]], image: &[[f64; 2]]) -> Option<Matrix3<f64>> {
    if plate.len() < 4 || plate.len() != image.len() {
        return None;
    }
    let (np, ni) = (normaliser(plate), normaliser(image));
    let mut ata = DMatrix::<f64>::zeros(9, 9);
    for (p, q) in plate.iter().zip(image) {
        let [x, y] = apply3(&np, *p);
        let [u, v] = apply3(&ni, *q);
        let rows = [
            [-x, -y, -1.0, 0.0, 0.0, 0.0, u * x, u * y, u],
            [0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, v],
        ];
        for r in rows {
            for i in 0..9 {
                for j in 0..9 {
                    ata[(i, j)] += r[i] * r[j];
                }
            }
        }
    }
    let h = null_vector(ata)?;
    let hn = Matrix3::from_row_slice(h.as_slice());
    let hm = ni.try_inverse()? * hn * np;
    let s = hm[(2, 2)];
    (s.abs() > 1e-300 && hm.iter().all(|v| v.is_finite())).then(|| hm / s)
}

/// Zhang's closed form for the pinhole from three or more homographies
/// (image points should be roughly centred and scaled; the caller passes
/// homographies to normalised pixels). `None` when the views do not
/// determine it (too few, or all alike).
pub fn pinhole(hs: &[Matrix3<f64>]) -> Option<Pinhole> {
    if hs.len() < 3 {
        return None;
    }
    let v = |h: &Matrix3<f64>, i: usize, j: usize| -> [f64; 6] {
        let (a, b) = (h.column(i), h.column(j));
        [
            a[0] * b[0],
            a[0] * b[1] + a[1] * b[0],
            a[1] * b[1],
            a[2] * b[0] + a[0] * b[2],
            a[2] * b[1] + a[1] * b[2],
            a[2] * b[2],
        ]
    };
    let mut ata = DMatrix::<f64>::zeros(6, 6);
    let mut add = |r: [f64; 6], w: f64| {
        for i in 0..6 {
            for j in 0..6 {
                ata[(i, j)] += w * r[i] * r[j];
            }
        }
    };
    for h in hs {
        let h = h / h.column(0).norm().max(1e-300);
        let v12 = v(&h, 0, 1);
        let (v11, v22) = (v(&h, 0, 0), v(&h, 1, 1));
        add(v12, 1.0);
        add(std::array::from_fn(|k| v11[k] - v22[k]), 1.0);
    }
    // Zero skew: B12 = 0.
    add([0.0, 1.0, 0.0, 0.0, 0.0, 0.0], 1e3 * hs.len() as f64);
    let mut b = null_vector(ata)?;
    if b[0] < 0.0 {
        b = -b;
    }
    let (b11, b12, b22, b13, b23, b33) = (b[0], b[1], b[2], b[3], b[4], b[5]);
    let den = b11 * b22 - b12 * b12;
    if !(b11 > 0.0 && den > 0.0) {
        return None;
    }
    let cy = (b12 * b13 - b11 * b23) / den;
    let lambda = b33 - (b13 * b13 + cy * (b12 * b13 - b11 * b23)) / b11;
    let ratio = lambda / b11;
    if ratio.is_nan() || ratio <= 0.0 {
        return None;
    }
    let fx = (lambda / b11).sqrt();
    let fy = (lambda * b11 / den).sqrt();
    let gamma = -b12 * fx * fx * fy / lambda;
    let cx = gamma * cy / fy - b13 * fx * fx / lambda;
    let p = Pinhole { fx, fy, cx, cy };
    [fx, fy, cx, cy].iter().all(|v| v.is_finite()).then_some(p)
}

/// The pose of the plate from its homography and the pinhole, `t_z > 0`.
pub fn pose(h: &Matrix3<f64>, k: &Pinhole) -> Option<Pose> {
    let m = k.k().try_inverse()? * h;
    let mut l = 1.0 / m.column(0).norm();
    if (m.column(2) * l).z < 0.0 {
        l = -l;
    }
    let r1 = m.column(0) * l;
    let r2 = m.column(1) * l;
    let r3 = r1.cross(&r2);
    let t = m.column(2) * l;
    let r = SMatrix::<f64, 3, 3>::from_columns(&[r1, r2, r3]);
    let svd = r.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut rot = u * vt;
    if rot.determinant() < 0.0 {
        rot = -rot;
    }
    Some(Pose::from_rt(&Rotation3::from_matrix_unchecked(rot), t))
}

/// The homography to pixels normalised by `n` (for [`pinhole`]).
pub fn normalised(h: &Matrix3<f64>, n: &Matrix3<f64>) -> Matrix3<f64> {
    n * h
}

/// The normalisation of pixels of an image of `w × h`: centred, unit half-width.
pub fn pixel_normaliser(w: f64, h: f64) -> Matrix3<f64> {
    let s = 2.0 / w.max(h).max(1.0);
    Matrix3::new(s, 0.0, -s * w / 2.0, 0.0, s, -s * h / 2.0, 0.0, 0.0, 1.0)
}

/// A pinhole found on normalised pixels, back in pixels.
pub fn denormalise(p: &Pinhole, n: &Matrix3<f64>) -> Pinhole {
    let s = n[(0, 0)];
    Pinhole {
        fx: p.fx / s,
        fy: p.fy / s,
        cx: (p.cx - n[(0, 2)]) / s,
        cy: (p.cy - n[(1, 2)]) / s,
    }
}

/// Image point of a plate point under a homography.
pub fn map(h: &Matrix3<f64>, p: [f64; 2]) -> [f64; 2] {
    apply3(h, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zhang_recovers_a_pinhole_from_exact_views() {
        let k = Pinhole {
            fx: 1080.0,
            fy: 1550.0,
            cx: 258.0,
            cy: 251.0,
        };
        let plate: Vec<[f64; 2]> = (0..6)
            .flat_map(|j| (0..8).map(move |i| [i as f64 * 40.0, j as f64 * 40.0]))
            .collect();
        let mut hs = Vec::new();
        let mut poses = Vec::new();
        for (a, b) in [(0.4, 0.1), (-0.3, 0.35), (0.1, -0.45), (0.25, 0.3)] {
            let r = Rotation3::new(Vector3::new(a, b, 0.2));
            let t = Vector3::new(-150.0, -100.0, 1300.0);
            let img: Vec<[f64; 2]> = plate
                .iter()
                .map(|p| {
                    let q = r * Vector3::new(p[0], p[1], 0.0) + t;
                    [k.fx * q.x / q.z + k.cx, k.fy * q.y / q.z + k.cy]
                })
                .collect();
            hs.push(homography(&plate, &img).unwrap());
            poses.push((r, t));
        }
        let n = pixel_normaliser(512.0, 512.0);
        let hn: Vec<_> = hs.iter().map(|h| normalised(h, &n)).collect();
        let got = denormalise(&pinhole(&hn).unwrap(), &n);
        for (a, b) in [
            (got.fx, k.fx),
            (got.fy, k.fy),
            (got.cx, k.cx),
            (got.cy, k.cy),
        ] {
            assert!((a - b).abs() < 1e-4 * b.abs().max(1.0), "{got:?}");
        }
        let p = pose(&hs[1], &got).unwrap();
        assert!((p.translation - poses[1].1).norm() < 1e-3, "{p:?}");
        assert!(p.rotation_matrix().angle_to(&poses[1].0) < 1e-6);
    }
}
