//! Camera calibration from images of a calibration plate: the intrinsics
//! (`C`, `f`, `D` of the Weng model in spec/lens.md, with `S` stated or its
//! ratio estimated) from several views, and the extrinsic pose `T` from one
//! view of the plate at its known place in the cell.
//!
//! The method, step by step:
//! - [`plate`]: the plate file — squares or checkerboard, sizes, the origin
//!   corner and the plate's place in the cell;
//! - [`detect`]: the grid found — on a squares plate with the LLV engine,
//!   corners where the fitted lines of two squares' sides cross; on a
//!   checkerboard by its inner corners (`saddle`: saddle points grown into
//!   a lattice of alternating squares, refined as `cornerSubPix`), so that
//!   frames, margins, cut-off outer squares and text round a real board do
//!   not matter;
//! - `zhang`: starting values in closed form — a homography per view,
//!   Zhang's method for the pinhole, each view's pose;
//! - `solve`: Levenberg–Marquardt on the reprojection error of every
//!   corner through the forward model (`model`: the pinhole, then the
//!   distortion of [`CameraModel`](crate::llv::lens::CameraModel), the same
//!   function lens correction inverts), standard errors from the Jacobian,
//!   distortion terms the views cannot tell from zero fixed at zero, the
//!   projection's uncertainty, a cross-validation from halves of the views,
//!   and the checks on the set of views (few, alike, the plate always in
//!   the middle);
//! - [`extrinsic`]: one view at the plate's place gives `T`, world → camera.
//!
//! The command line (`vss calibrate`) and the console call these same
//! functions, and write the result through [`write_intrinsics`] and
//! [`write_extrinsic`].

pub mod detect;
pub mod extrinsic;
pub mod found;
mod lm;
pub mod model;
pub mod plate;
mod quads;
mod saddle;
mod solve;
mod zhang;

use std::path::Path;

pub use detect::Detector;
pub use found::{Corner, DetectError, Detection};
pub use plate::{Plate, PlateError, PlateKind};
pub use solve::{
    CENTRE_SE, COVERAGE, Calibration, CrossCheck, Estimate, FEW_VIEWS, Options, PARALLEL_DEPTH,
    View, ViewFit, coverage, cross_validate, solve_pose, uncertainty_points,
};

use crate::formats::cdf::{Cdf, CdfParam, Status};

/// Why a calibration gave no result. Each says what to do.
#[derive(Debug, thiserror::Error)]
pub enum CalibError {
    #[error(
        "{usable} usable view(s) of the plate; at least 3 are needed: take more views, each with the whole plate in sight and tilted a different way"
    )]
    TooFewViews { usable: usize },
    #[error(
        "every view shows the plate nearly parallel to the image plane (its depth changes by at most {:.1} % across it), which cannot tell the focal length from the distance: tilt the plate 20–45° in a different direction in each view",
        100.0 * depth
    )]
    AllParallel { depth: f64 },
    #[error("{what}: take views with the plate tilted differently")]
    Degenerate { what: String },
    #[error(
        "the solution did not converge ({why}): check the plate file against the plate, and take sharper views"
    )]
    NoConvergence { why: String },
    #[error(
        "{name} = {value:.6e} has a standard error of {se:.3e}, larger than itself: the views do not determine it ({}); take more views, tilted more (20–45° in different directions), with the plate near the image's edges and corners",
        if matches!(*name, "Cx" | "Cy") {
            "the centre can also be stated: vss calibrate --centre X,Y or --centre image, on the Calibrate screen S or s"
        } else {
            "it cannot be left out"
        }
    )]
    WeakParameter {
        name: &'static str,
        value: f64,
        se: f64,
    },
    #[error(
        "the plate `{0}` looks the same turned round, so its origin corner cannot be told in an image: the extrinsic pose needs a plate with `origin_mark = true` (squares) or an odd number of rows + columns (checkerboard)"
    )]
    Symmetric(String),
    #[error("the plate file gives no [place] (the plate's pose in the cell): add one to {0}")]
    NoPlace(String),
    #[error(
        "the corners do not fit one camera with the stated scale S (sy / sx = {stated:.4}), but \
         do with sy / sx = {fits:.4} (RMS {rms:.3} px): these views are not from the camera S \
         belongs to (photographs of another camera?), or S is wrong: give that camera's S \
         (its .cdf, or vss calibrate --scale SX,SY), or estimate sy (vss calibrate \
         --estimate-scale)"
    )]
    ScaleMismatch { stated: f64, fits: f64, rms: f64 },
}

/// Calibrates a camera from `views` (the solver in `calib/solve.rs`). A fit
/// with `S` stated that does not converge, or whose views doubt `S` (their
/// pinhole's `f` from `sx` and from `sy` disagree), is tried once more with
/// `sy` estimated: when that fits better with another ratio, the refusal
/// says the scale is the cause ([`CalibError::ScaleMismatch`]), not a
/// misread grid or plate file. (With few views a wrong `S` can still
/// converge, to a centre far outside the image and a residual of pixels;
/// the case is in docs/calibration.md.)
pub fn calibrate(views: &[View], o: &Options) -> Result<Calibration, CalibError> {
    let stated_fit = solve::calibrate(views, o);
    let retry = !o.estimate_scale
        && match &stated_fit {
            Err(CalibError::NoConvergence { .. }) => true,
            Ok(c) => c.scale_doubted,
            Err(_) => false,
        };
    if !retry {
        return stated_fit;
    }
    let free = Options {
        estimate_scale: true,
        ..*o
    };
    let stated = o.sy / o.sx;
    let stated_worse = |rms: f64| match &stated_fit {
        Ok(c) => rms < c.rms,
        Err(_) => true,
    };
    match solve::calibrate(views, &free) {
        Ok(c) if (c.model.sy / c.model.sx / stated - 1.0).abs() > 0.01 && stated_worse(c.rms) => {
            Err(CalibError::ScaleMismatch {
                stated,
                fits: c.model.sy / c.model.sx,
                rms: c.rms,
            })
        }
        _ => stated_fit,
    }
}

/// The `.cdf` with a new intrinsic calibration: `f`, `D`, `K` calibrated (`A`),
/// `C` too unless it was stated (`S`), `S` stated or, when its ratio was
/// estimated, `A`. Every other
/// entry of `old` (its `T`, unknown names) is kept in its place.
pub fn cdf_with_intrinsics(old: Option<&Cdf>, c: &Calibration) -> Cdf {
    let m = &c.model;
    let col = |v: &[f64]| v.iter().map(|&x| vec![x]).collect::<Vec<_>>();
    let mut cdf = old.cloned().unwrap_or_default();
    let s_status = if c.scale_estimated {
        Status::Calibrated
    } else {
        Status::Stated
    };
    let d = m.distortion.unwrap_or([0.0; 5]);
    for (name, status, rows) in [
        ("S", s_status, col(&[m.sx, m.sy])),
        (
            "C",
            if c.centre_stated {
                Status::Stated
            } else {
                Status::Calibrated
            },
            col(&[m.cx, m.cy]),
        ),
        ("f", Status::Calibrated, col(&[m.f])),
        ("D", Status::Calibrated, col(&d)),
        ("K", Status::Calibrated, col(&m.radial)),
    ] {
        cdf.set(CdfParam {
            name: name.into(),
            status,
            rows,
        });
    }
    if cdf.get("T").is_none() {
        cdf.set(CdfParam {
            name: "T".into(),
            status: Status::NotAvailable,
            rows: vec![vec![0.0; 4]; 3],
        });
    }
    cdf
}

/// The `.cdf` with a new extrinsic matrix `T` (calibrated), everything else
/// kept.
pub fn cdf_with_extrinsic(old: &Cdf, t: &[[f64; 4]; 3]) -> Cdf {
    let mut cdf = old.clone();
    cdf.set(CdfParam {
        name: "T".into(),
        status: Status::Calibrated,
        rows: t.iter().map(|r| r.to_vec()).collect(),
    });
    cdf
}

/// Where the file at `path` is kept before it is replaced: `path.bak`,
/// or when that exists (an earlier backup, never overwritten)
/// `path.bak.1`, `path.bak.2`, … the first that does not.
pub fn backup_name(path: &Path) -> std::path::PathBuf {
    let mut base = path.as_os_str().to_owned();
    base.push(".bak");
    let first = std::path::PathBuf::from(&base);
    if std::fs::symlink_metadata(&first).is_err() {
        return first;
    }
    (1u32..)
        .map(|k| {
            let mut n = base.clone();
            n.push(format!(".{k}"));
            std::path::PathBuf::from(n)
        })
        .find(|p| std::fs::symlink_metadata(p).is_err())
        .unwrap_or(first)
}

/// Writes `cdf` to `path` atomically; an existing file is kept first under
/// [`backup_name`] (itself written atomically), which is returned.
pub fn write_cdf_keeping(
    path: &Path,
    cdf: &Cdf,
) -> Result<Option<std::path::PathBuf>, crate::formats::FormatError> {
    let mut kept = None;
    if path.is_file() {
        let old = crate::formats::cdf::read_cdf(path)?;
        let bak = backup_name(path);
        crate::formats::cdf::write_cdf(&bak, &old)?;
        kept = Some(bak);
    }
    crate::formats::cdf::write_cdf(path, cdf)?;
    Ok(kept)
}

/// Writes a new intrinsic calibration into the `.cdf` at `path` (kept
/// entries as [`cdf_with_intrinsics`]; the old file kept as
/// [`backup_name`] says, its name returned).
pub fn write_intrinsics(
    path: &Path,
    c: &Calibration,
) -> Result<Option<std::path::PathBuf>, crate::formats::FormatError> {
    let old = if path.is_file() {
        Some(crate::formats::cdf::read_cdf(path)?)
    } else {
        None
    };
    let cdf = cdf_with_intrinsics(old.as_ref(), c);
    write_cdf_keeping(path, &cdf)
}

/// Writes `T` into the `.cdf` at `path` (the old file kept as
/// [`backup_name`] says).
pub fn write_extrinsic(
    path: &Path,
    old: &Cdf,
    t: &[[f64; 4]; 3],
) -> Result<(Cdf, Option<std::path::PathBuf>), crate::formats::FormatError> {
    let cdf = cdf_with_extrinsic(old, t);
    let bak = write_cdf_keeping(path, &cdf)?;
    Ok((cdf, bak))
}

/// The plate found in a set of images.
#[derive(Clone, Debug, Default)]
pub struct Found {
    /// The views where the whole grid was found.
    pub views: Vec<(View, Detection)>,
    /// The others: name, and why not.
    pub refused: Vec<(String, DetectError)>,
}

/// Finds the plate in each image.
pub fn detect_all(images: &[(String, crate::llv::GreyImage)], plate: &Plate) -> Found {
    let mut det = Detector::new();
    let mut ok = Vec::new();
    let mut bad = Vec::new();
    for (name, img) in images {
        match det.detect(img, plate) {
            Ok(d) => ok.push((
                View {
                    name: name.clone(),
                    corners: d.corners.clone(),
                },
                d,
            )),
            Err(e) => bad.push((name.clone(), e)),
        }
    }
    Found {
        views: ok,
        refused: bad,
    }
}

/// The scale `S` (mm per pixel) a `.cdf` states, if it has a usable one.
pub fn scale_of(cdf: &Cdf) -> Option<(f64, f64)> {
    let s: Vec<f64> = cdf.get("S").filter(|p| p.available())?.values().collect();
    match s[..] {
        [x, y] if x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite() => Some((x, y)),
        _ => None,
    }
}

/// A number to three significant figures, in plain decimals between 0.001
/// and 10 000 (`5.52`, `0.0131`, `706`) and in powers of ten outside
/// (`1.23e-5`), never `5.5e0`.
pub fn sig3(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() {
        return format!("{x}");
    }
    if a == 0.0 {
        return "0".into();
    }
    if (1e-3..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

/// The solution in words, as the CLI prints it and the report's page shows
/// it: a header, each parameter with its standard error and unit, the terms
/// fixed at zero, then `C` when it was stated, `S` with how it was found,
/// and the projection's uncertainty across the image. `pm` is the
/// plus-minus sign (`±`, or `+-` where the font has only ASCII).
pub fn parameter_lines(c: &Calibration, pm: &str) -> Vec<String> {
    let mut t = vec!["parameter  value            standard error".to_string()];
    for p in &c.params {
        let unit = match p.name {
            "Cx" | "Cy" => " px",
            "f" => " mm",
            "sy" => " mm/px",
            _ => "",
        };
        t.push(format!(
            "{:<9}  {:<16.9} {pm} {}{unit}",
            p.name,
            p.value,
            sig3(p.se)
        ));
    }
    for p in &c.fixed {
        t.push(format!(
            "{:<9}  0 (fixed: {} {pm} {} cannot be told from 0)",
            p.name,
            sig3(p.value),
            sig3(p.se)
        ));
    }
    if !c.full_model && !c.fixed.iter().any(|p| p.name == "s1") {
        t.push("s1, s2, k3 0 (not estimated; --model full)".into());
    }
    if c.centre_stated {
        t.push(format!("C (stated) {:.3} {:.3} px", c.model.cx, c.model.cy));
    }
    let how = if c.scale_estimated {
        "sy estimated"
    } else {
        "stated"
    };
    t.push(format!("S ({how})  {} {} mm/px", c.model.sx, c.model.sy));
    if !c.uncertainty.is_empty() {
        let names = uncertainty_points(c.width, c.height);
        let parts: Vec<String> = c
            .uncertainty
            .iter()
            .map(|(q, u)| {
                let name = names.iter().find(|(_, p)| p == q).map_or("", |(n, _)| n);
                format!("{name} {}", sig3(*u))
            })
            .collect();
        t.push(format!(
            "projection uncertainty (px, 1 sigma): {}",
            parts.join(", ")
        ));
    }
    t
}
