//! The solution: starting values in closed form ([`super::zhang`]), then
//! Levenberg–Marquardt ([`super::lm`]: the normal equations summed corner
//! by corner, over `nalgebra`) on the reprojection error of every corner of
//! every view through the forward model ([`super::model`]), all intrinsics
//! and every view's pose at once; standard errors from the Jacobian at the solution
//! (`s² (JᵀJ)⁻¹`, `s²` the residual variance), and the checks that say
//! whether the set of views was good enough.
//!
//! The model: `C`, `f`, radial `k1, k2` and decentering `p1, p2` by default;
//! Weng's thin prism `s1, s2` and the radial `k3` only when asked
//! ([`Options::full_model`]: on half the real views `k3` fits their noise,
//! docs/calibration.md). In
//! Weng's model a shift `Δ` of the centre is matched to second order by
//! thin-prism-like terms and a turn of every view, because turning a pinhole
//! camera moves its image by `f α` plus exactly `α (u², uv) / f`; with the
//! thin prism free the images fix `C` only to a few pixels, without it real
//! lenses pin `C` down (docs/calibration.md). A distortion term whose
//! standard error exceeds its value is fixed at zero and the rest solved
//! again; only a weak `C`, `f` or `sy` refuses the views.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::CalibError;
use super::found::Corner;
use super::lm::{self, Normal as _};
use super::model::{self, FULL_ONLY, INTRINSIC_NAMES, N_INTRINSICS, Pose, SY};
use super::zhang;
use crate::llv::lens::CameraModel;

mod uncertainty;
use uncertainty::projection_uncertainty;
pub use uncertainty::{CrossCheck, cross_validate, uncertainty_points};

/// Below this change of depth across the plate (a fraction of its
/// distance) a view counts as parallel to the image plane (about 4° of
/// tilt for a plate half as wide as it is far).
pub const PARALLEL_DEPTH: f64 = 0.02;

/// One view's corners.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub name: String,
    pub corners: Vec<Corner>,
}

/// What the solver is given besides the views.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    pub width: usize,
    pub height: usize,
    /// The stated scale `S` (mm per pixel); with `estimate_scale`, `sx` is
    /// kept and `sy` estimated (only their ratio and `f / sx` can be told
    /// from images).
    pub sx: f64,
    pub sy: f64,
    pub estimate_scale: bool,
    /// `C` stated (px) instead of solved for.
    pub centre: Option<[f64; 2]>,
    /// Estimate Weng's thin prism (`s1, s2`) and `k3` too. Off by default: real
    /// lenses have next to none, and with it a shift of `C` is nearly
    /// matched by the other terms (docs/calibration.md).
    pub full_model: bool,
}

/// A parameter with its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub name: &'static str,
    pub value: f64,
    pub se: f64,
}

/// How well one view fits.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewFit {
    pub name: String,
    pub pose: Pose,
    /// RMS and 95th percentile of the corners' reprojection errors (px).
    pub rms: f64,
    pub p95: f64,
    /// Each corner: observed position and residual (predicted − observed).
    pub residuals: Vec<([f64; 2], [f64; 2])>,
    /// Angle between the plate's normal and the optical axis (degrees).
    pub tilt_deg: f64,
}

/// A solved calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    pub model: CameraModel,
    pub scale_estimated: bool,
    /// `C` was stated, not solved for.
    pub centre_stated: bool,
    /// The thin prism was estimated (`--model full`).
    pub full_model: bool,
    pub views: Vec<ViewFit>,
    pub rms: f64,
    pub p95: f64,
    /// The parameters solved for, with their standard errors.
    pub params: Vec<Estimate>,
    /// Distortion terms the views could not tell from zero, fixed at zero
    /// (with their value and standard error when they were let go).
    pub fixed: Vec<Estimate>,
    /// The projection's uncertainty (px, 1 σ) at the image's middle and
    /// corners ([`uncertainty_points`]).
    pub uncertainty: Vec<([f64; 2], f64)>,
    /// What makes the set of views weak, in words for the operator.
    pub warnings: Vec<String>,
    /// With `S` stated: the views' own pinhole gave `f` from `sx` and from
    /// `sy` more than 1 % apart, so `S` may not be this camera's.
    pub scale_doubted: bool,
    /// Residual evaluations the solver needed.
    pub evaluations: usize,
    pub width: usize,
    pub height: usize,
}

/// The least-squares problem: intrinsics (unless fixed) and one pose a view.
struct Fit<'a> {
    views: &'a [View],
    plate: Vec<Vec<Vector3<f64>>>,
    base: CameraModel,
    /// The intrinsics, [`INTRINSIC_NAMES`] order; those in `free` are
    /// taken from `x`.
    iv: [f64; N_INTRINSICS],
    /// Which intrinsics are solved for (none for a pose alone).
    free: Vec<usize>,
    n_intr: usize,
    x: DVector<f64>,
    rows: usize,
}

impl<'a> Fit<'a> {
    fn new(views: &'a [View], base: CameraModel, free: Vec<usize>, poses: &[Pose]) -> Fit<'a> {
        let iv = model::intrinsics_vector(&base);
        let n_intr = free.len();
        let mut x = DVector::zeros(n_intr + 6 * poses.len());
        for (k, &i) in free.iter().enumerate() {
            x[k] = iv[i];
        }
        for (k, p) in poses.iter().enumerate() {
            let o = n_intr + 6 * k;
            x.fixed_rows_mut::<3>(o).copy_from(&p.rotation);
            x.fixed_rows_mut::<3>(o + 3).copy_from(&p.translation);
        }
        let plate = views
            .iter()
            .map(|v| {
                v.corners
                    .iter()
                    .map(|c| Vector3::new(c.corner.xy[0], c.corner.xy[1], 0.0))
                    .collect()
            })
            .collect();
        let rows = views.iter().map(|v| 2 * v.corners.len()).sum();
        Fit {
            views,
            plate,
            base,
            iv,
            free,
            n_intr,
            x,
            rows,
        }
    }

    fn camera(&self) -> CameraModel {
        let mut iv = self.iv;
        for (k, &i) in self.free.iter().enumerate() {
            iv[i] = self.x[k];
        }
        model::model_from(&iv, &self.base, true)
    }

    fn pose(&self, k: usize) -> Pose {
        let o = self.n_intr + 6 * k;
        Pose {
            rotation: self.x.fixed_rows::<3>(o).into_owned(),
            translation: self.x.fixed_rows::<3>(o + 3).into_owned(),
        }
    }

    /// Calls `f(row, view, projection, observed)` for every corner.
    fn each(&self, mut f: impl FnMut(usize, usize, &model::Projection, [f64; 2])) -> Option<()> {
        let cam = self.camera();
        let mut row = 0;
        for (k, v) in self.views.iter().enumerate() {
            let pose = self.pose(k);
            for (c, x) in v.corners.iter().zip(&self.plate[k]) {
                let p = model::project(&cam, &pose, x)?;
                f(row, k, &p, c.px);
                row += 2;
            }
        }
        Some(())
    }
}

impl Fit<'_> {
    /// Every corner's residual (predicted − observed), `None` when a
    /// corner is out of the camera's view.
    fn residuals(&self) -> Option<DVector<f64>> {
        let mut r = DVector::zeros(self.rows);
        self.each(|row, _, p, obs| {
            r[row] = p.px.x - obs[0];
            r[row + 1] = p.px.y - obs[1];
        })?;
        Some(r)
    }
}

impl lm::Normal for Fit<'_> {
    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn cost(&self) -> Option<f64> {
        self.residuals().map(|r| r.norm_squared())
    }

    fn normal(&self) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let n = self.x.len();
        let ni = self.n_intr;
        let mut a = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        // One corner's row of J: its intrinsics' and its view's columns.
        let mut cols = Vec::with_capacity(ni + 6);
        let mut vals = Vec::with_capacity(ni + 6);
        self.each(|_, k, p, obs| {
            let r = [p.px.x - obs[0], p.px.y - obs[1]];
            for (row, &res) in r.iter().enumerate() {
                cols.clear();
                vals.clear();
                for (c, &i) in self.free.iter().enumerate() {
                    cols.push(c);
                    vals.push(p.d_intrinsics[(row, i)]);
                }
                for c in 0..6 {
                    cols.push(ni + 6 * k + c);
                    vals.push(p.d_pose[(row, c)]);
                }
                for (u, &cu) in cols.iter().enumerate() {
                    g[cu] += vals[u] * res;
                    for (v, &cv) in cols.iter().enumerate() {
                        a[(cu, cv)] += vals[u] * vals[v];
                    }
                }
            }
        })?;
        Some((a, g))
    }
}

/// Plate and image points of a view.
fn pairs(v: &View) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    v.corners.iter().map(|c| (c.corner.xy, c.px)).unzip()
}

/// How much the plate's depth changes across it in view of homography `h`
/// (a fraction of its depth in the middle): 0 for a plate parallel to the
/// image plane, whatever the camera.
pub fn depth_change(h: &Matrix3<f64>, plate: &[[f64; 2]]) -> f64 {
    let w = |p: &[f64; 2]| h[(2, 0)] * p[0] + h[(2, 1)] * p[1] + h[(2, 2)];
    let n = plate.len().max(1) as f64;
    let mid = [
        plate.iter().map(|p| p[0]).sum::<f64>() / n,
        plate.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    let wm = w(&mid);
    let (lo, hi) = plate
        .iter()
        .map(w)
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    ((hi - lo) / wm).abs()
}

fn percentile(mut v: Vec<f64>, q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// The parameters' covariance from `JᵀJ` over `m` residuals: `s²
/// (JᵀJ)⁻¹`, `s²` the residual variance, the inverse taken on `JᵀJ` scaled
/// to a unit diagonal so that mm, radians and 10⁻⁴ sit together.
fn covariance(a: &DMatrix<f64>, ssr: f64, m: usize) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    if m <= n {
        return None;
    }
    let d: Vec<f64> = (0..n).map(|i| a[(i, i)].max(1e-300).sqrt()).collect();
    let scaled = DMatrix::from_fn(n, n, |i, j| a[(i, j)] / (d[i] * d[j]));
    let inv = scaled.cholesky()?.inverse();
    let s2 = ssr / (m - n) as f64;
    Some(DMatrix::from_fn(n, n, |i, j| {
        s2 * inv[(i, j)] / (d[i] * d[j])
    }))
}

/// Standard errors of every parameter (the covariance's diagonal).
fn standard_errors(a: &DMatrix<f64>, ssr: f64, m: usize) -> Option<DVector<f64>> {
    let c = covariance(a, ssr, m)?;
    Some(DVector::from_fn(c.nrows(), |i, _| {
        c[(i, i)].max(0.0).sqrt()
    }))
}

/// Intrinsic calibration from three or more views.
pub fn calibrate(views: &[View], o: &Options) -> Result<Calibration, CalibError> {
    if views.len() < 3 {
        return Err(CalibError::TooFewViews {
            usable: views.len(),
        });
    }
    let mut hs = Vec::new();
    let mut depth = Vec::new();
    for v in views {
        let (pl, im) = pairs(v);
        let h = zhang::homography(&pl, &im).ok_or_else(|| CalibError::Degenerate {
            what: format!("view {}: its corners fit no homography", v.name),
        })?;
        depth.push(depth_change(&h, &pl));
        hs.push(h);
    }
    let most = depth.iter().copied().fold(0.0, f64::max);
    if most < PARALLEL_DEPTH {
        return Err(CalibError::AllParallel { depth: most });
    }
    let n = zhang::pixel_normaliser(o.width as f64, o.height as f64);
    let hn: Vec<_> = hs.iter().map(|h| zhang::normalised(h, &n)).collect();
    let pin = zhang::pinhole(&hn)
        .map(|p| zhang::denormalise(&p, &n))
        .ok_or(CalibError::Degenerate {
            what: "the views do not determine the camera: they are too alike".into(),
        })?;
    let mut warnings = Vec::new();
    let mut scale_doubted = false;
    let (f0, sy0) = if o.estimate_scale {
        (pin.fx * o.sx, pin.fx * o.sx / pin.fy)
    } else {
        let (a, b) = (pin.fx * o.sx, pin.fy * o.sy);
        if ((a - b) / (a + b)).abs() > 0.01 {
            scale_doubted = true;
            warnings.push(format!(
                "the stated scale S does not fit the images: f / sx and f / sy give {a:.3} and {b:.3} mm; check S (sy / sx is about {:.5}) or estimate it (--estimate-scale)",
                o.sy / o.sx * b / a
            ));
        }
        ((a + b) / 2.0, o.sy)
    };
    let [cx0, cy0] = o.centre.unwrap_or([pin.cx, pin.cy]);
    let mut start = CameraModel {
        cx: cx0,
        cy: cy0,
        sx: o.sx,
        sy: sy0,
        f: f0,
        distortion: Some([0.0; 5]),
        radial: [0.0; 2],
    };
    let k = zhang::Pinhole {
        fx: f0 / o.sx,
        fy: f0 / sy0,
        cx: cx0,
        cy: cy0,
    };
    let mut poses: Vec<Pose> = hs
        .iter()
        .zip(views)
        .map(|(h, v)| {
            zhang::pose(h, &k).ok_or_else(|| CalibError::Degenerate {
                what: format!("view {}: no pose fits its homography", v.name),
            })
        })
        .collect::<Result<_, _>>()?;
    let mut free: Vec<usize> = (0..N_INTRINSICS)
        .filter(|&i| match i {
            0 | 1 => o.centre.is_none(),
            SY => o.estimate_scale,
            i if FULL_ONLY.contains(&i) => o.full_model,
            _ => true,
        })
        .collect();
    let mut fixed = Vec::new();
    let mut evaluations = 0;
    let (fit, params, r, a) = loop {
        let mut fit = Fit::new(views, start, free.clone(), &poses);
        evaluations += lm::minimize(&mut fit)?.evaluations;
        let out = || CalibError::NoConvergence {
            why: "a corner left the camera's view".into(),
        };
        let r = fit.residuals().ok_or_else(out)?;
        let (a, _) = fit.normal().ok_or_else(out)?;
        let cov = covariance(&a, r.norm_squared(), r.len()).ok_or(CalibError::Degenerate {
            what: "the parameters cannot be told apart from these views".into(),
        })?;
        let iv = model::intrinsics_vector(&fit.camera());
        let params: Vec<Estimate> = free
            .iter()
            .enumerate()
            .map(|(k, &i)| Estimate {
                name: INTRINSIC_NAMES[i],
                value: iv[i],
                se: cov[(k, k)].max(0.0).sqrt(),
            })
            .collect();
        // Corners that fit no camera: said before any parameter is blamed.
        let errs: Vec<f64> = (0..r.len() / 2)
            .map(|i| r[2 * i].hypot(r[2 * i + 1]))
            .collect();
        let overall = rms(&errs);
        if overall.is_nan() || overall >= 2.0 {
            return Err(CalibError::NoConvergence {
                why: format!(
                    "the best fit leaves {overall:.2} px RMS: the corners do not fit one camera (a view whose grid was misread, or a plate file that does not match the plate)"
                ),
            });
        }
        // A distortion term the views cannot tell from zero is fixed at
        // zero and the rest solved again, the weakest first; C, f and sy
        // cannot be left out, so a weak one of them refuses the views.
        let ratio = |p: &Estimate| {
            if p.se.is_nan() {
                f64::INFINITY
            } else {
                p.se / p.value.abs()
            }
        };
        if let Some(p) = params
            .iter()
            .filter(|p| matches!(p.name, "Cx" | "Cy" | "f" | "sy"))
            .find(|p| ratio(p) >= 1.0)
        {
            return Err(CalibError::WeakParameter {
                name: p.name,
                value: p.value,
                se: p.se,
            });
        }
        let weakest = params
            .iter()
            .enumerate()
            .filter(|(_, p)| !matches!(p.name, "Cx" | "Cy" | "f" | "sy"))
            .max_by(|a, b| ratio(a.1).total_cmp(&ratio(b.1)));
        match weakest {
            Some((k, p)) if ratio(p) >= 1.0 => {
                fixed.push(*p);
                let i = free.remove(k);
                let mut iv = model::intrinsics_vector(&fit.camera());
                iv[i] = 0.0;
                start = model::model_from(&iv, &start, true);
                poses = (0..views.len()).map(|v| fit.pose(v)).collect();
            }
            _ => break (fit, params, r, a),
        }
    };
    let model = fit.camera();
    for p in &fixed {
        warnings.push(format!(
            "{} = {:.2e} had a standard error of {:.2e}, larger than itself: these views cannot tell it from zero, so it was fixed at 0 and the rest solved again",
            p.name, p.value, p.se
        ));
    }
    let mut all = Vec::new();
    let mut fits = Vec::new();
    let mut row = 0;
    for (k, v) in views.iter().enumerate() {
        let mut errs = Vec::new();
        let mut res = Vec::new();
        for c in &v.corners {
            let d = [r[row], r[row + 1]];
            row += 2;
            errs.push(d[0].hypot(d[1]));
            res.push((c.px, d));
        }
        all.extend_from_slice(&errs);
        let pose = fit.pose(k);
        let normal = pose.rotation_matrix() * Vector3::z();
        fits.push(ViewFit {
            name: v.name.clone(),
            pose,
            rms: rms(&errs),
            p95: percentile(errs, 0.95),
            residuals: res,
            tilt_deg: normal.z.abs().clamp(0.0, 1.0).acos().to_degrees(),
        });
    }
    let overall = rms(&all);
    if overall.is_nan() || overall >= 2.0 {
        return Err(CalibError::NoConvergence {
            why: format!(
                "the best fit leaves {overall:.2} px RMS: the corners do not fit one camera (a view whose grid was misread, or a plate file that does not match the plate)"
            ),
        });
    }
    let centre_se = params
        .iter()
        .filter(|p| p.name == "Cx" || p.name == "Cy")
        .map(|p| p.se)
        .fold(0.0, f64::max);
    if centre_se > CENTRE_SE {
        warnings.push(format!(
            "the centre C is known to ± {centre_se:.1} px only{}; if the centre is known (the lens's data sheet, an optical bench), state it: vss calibrate --centre X,Y, or on the Calibrate screen S (X,Y) or s (the image's middle)",
            if o.full_model {
                ": with the thin prism (s1, s2) estimated, a shift of C is matched, to second order, by the distortion terms and a turn of each view, so the images hardly tell them apart; the .cdf corrects images as well either way, but its C (and the turn of a T found with it) is that uncertain. Without --model full the thin prism is left out and real lenses pin C down"
            } else {
                ": take more views, tilted more, with the plate near the image's edges and corners"
            }
        ));
    }
    warnings.extend(weak_set(&fits, o));
    let uncertainty = projection_uncertainty(&fit, &a, r.norm_squared(), r.len(), o);
    Ok(Calibration {
        model,
        scale_estimated: o.estimate_scale,
        centre_stated: o.centre.is_some(),
        full_model: o.full_model,
        views: fits,
        rms: overall,
        p95: percentile(all, 0.95),
        params,
        fixed,
        uncertainty,
        warnings,
        scale_doubted,
        evaluations,
        width: o.width,
        height: o.height,
    })
}

/// A standard error of `C` above this (px) is worth a warning.
pub const CENTRE_SE: f64 = 0.5;

/// Views that are fewer than 8.
pub const FEW_VIEWS: usize = 8;

/// What makes a set of views weak: few, alike, or the plate always in the
/// middle of the image.
fn weak_set(fits: &[ViewFit], o: &Options) -> Vec<String> {
    let mut w = Vec::new();
    if fits.len() < FEW_VIEWS {
        w.push(format!(
            "only {} views: {FEW_VIEWS} or more, at different tilts and places, give a steadier result",
            fits.len()
        ));
    }
    let normal = |f: &ViewFit| f.pose.rotation_matrix() * Vector3::z();
    let centre = |f: &ViewFit| {
        let n = f.residuals.len().max(1) as f64;
        [
            f.residuals.iter().map(|r| r.0[0]).sum::<f64>() / n,
            f.residuals.iter().map(|r| r.0[1]).sum::<f64>() / n,
        ]
    };
    let size = o.width.max(o.height) as f64;
    let mut alike = Vec::new();
    for a in 0..fits.len() {
        for b in a + 1..fits.len() {
            let ang = normal(&fits[a]).angle(&normal(&fits[b])).to_degrees();
            let (ca, cb) = (centre(&fits[a]), centre(&fits[b]));
            if ang < 4.0 && (ca[0] - cb[0]).hypot(ca[1] - cb[1]) < 0.05 * size {
                alike.push(format!("{} and {}", fits[a].name, fits[b].name));
            }
        }
    }
    if !alike.is_empty() {
        w.push(format!(
            "views at nearly the same pose (they add little): {}",
            alike.join(", ")
        ));
    }
    let spread = fits
        .iter()
        .flat_map(|a| fits.iter().map(move |b| normal(a).angle(&normal(b))))
        .fold(0.0, f64::max)
        .to_degrees();
    if spread < 15.0 {
        w.push(format!(
            "the plate's tilt hardly changes between views (at most {spread:.0}° apart): tilt it 20–45° in different directions"
        ));
    }
    let (touched, ring) = coverage_ring(fits, o);
    if touched * 2 < ring {
        w.push(format!(
            "the plate was always near the middle: its corners reached {touched} of the {ring} cells round the image's edge; hold it near the edges and corners too, where the lens distorts most"
        ));
    }
    w
}

/// Cells of the coverage map a side.
pub const COVERAGE: usize = 5;

/// Which cells of a `COVERAGE`² grid over the image any corner fell in
/// (row-major).
pub fn coverage(points: impl Iterator<Item = [f64; 2]>, width: usize, height: usize) -> Vec<usize> {
    let mut hits = vec![0usize; COVERAGE * COVERAGE];
    for p in points {
        let cx = (p[0] / width.max(1) as f64 * COVERAGE as f64).floor();
        let cy = (p[1] / height.max(1) as f64 * COVERAGE as f64).floor();
        if cx >= 0.0 && cy >= 0.0 && (cx as usize) < COVERAGE && (cy as usize) < COVERAGE {
            hits[cy as usize * COVERAGE + cx as usize] += 1;
        }
    }
    hits
}

fn coverage_ring(fits: &[ViewFit], o: &Options) -> (usize, usize) {
    let hits = coverage(
        fits.iter().flat_map(|f| f.residuals.iter().map(|r| r.0)),
        o.width,
        o.height,
    );
    let edge = |i: usize| {
        let (x, y) = (i % COVERAGE, i / COVERAGE);
        x == 0 || y == 0 || x == COVERAGE - 1 || y == COVERAGE - 1
    };
    let ring = (0..hits.len()).filter(|&i| edge(i)).count();
    let touched = (0..hits.len()).filter(|&i| edge(i) && hits[i] > 0).count();
    (touched, ring)
}

/// A plate pose from one view with the intrinsics known: starting value from
/// the homography of the undistorted corners, then Levenberg–Marquardt on
/// the six pose parameters. Gives the pose, the RMS and 95th percentile of
/// the reprojection error, and the pose's standard errors (rotation vector
/// in radians, translation in mm).
pub fn solve_pose(view: &View, m: &CameraModel) -> Result<(Pose, f64, f64, [f64; 6]), CalibError> {
    let (pl, im) = pairs(view);
    let ideal: Vec<[f64; 2]> = im
        .iter()
        .map(|p| {
            let (x, y) = m.observed_to_ideal(p[0], p[1]);
            [x, y]
        })
        .collect();
    let h = zhang::homography(&pl, &ideal).ok_or_else(|| CalibError::Degenerate {
        what: format!("view {}: its corners fit no homography", view.name),
    })?;
    let k = zhang::Pinhole {
        fx: m.f / m.sx,
        fy: m.f / m.sy,
        cx: m.cx,
        cy: m.cy,
    };
    let pose = zhang::pose(&h, &k).ok_or_else(|| CalibError::Degenerate {
        what: format!("view {}: no pose fits its homography", view.name),
    })?;
    let views = std::slice::from_ref(view);
    let mut fit = Fit::new(views, *m, Vec::new(), &[pose]);
    lm::minimize(&mut fit)?;
    let none = || CalibError::NoConvergence {
        why: "a corner left the camera's view".into(),
    };
    let r = fit.residuals().ok_or_else(none)?;
    let (a, _) = fit.normal().ok_or_else(none)?;
    let se = standard_errors(&a, r.norm_squared(), r.len()).ok_or(CalibError::Degenerate {
        what: "the pose cannot be told from this view".into(),
    })?;
    let errs: Vec<f64> = (0..r.len() / 2)
        .map(|i| r[2 * i].hypot(r[2 * i + 1]))
        .collect();
    Ok((
        fit.pose(0),
        rms(&errs),
        percentile(errs, 0.95),
        std::array::from_fn(|i| se[i]),
    ))
}

#[cfg(test)]
mod tests;
