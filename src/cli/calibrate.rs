//! `vss calibrate`: a camera's `.cdf` from images of a calibration plate.
//!
//! `vss calibrate --camera N --plate PLATE IMAGES… [--out camN.cdf]` finds the
//! plate in every image, solves the intrinsics (`crate::calib`), prints the
//! reprojection error per view and overall, each parameter with its standard
//! error, the terms fixed at zero, the projection's uncertainty across the
//! image, a cross-validation (two halves of the views) and what makes the
//! set of views weak, and writes `C`, `f`, `D` (calibrated) and `S` (stated,
//! from `--scale`, the camera's `.cdf` in the profile, or the `--out` file)
//! into the `.cdf`, keeping its other entries. `--camera` may be left out
//! when `--out` names the file. `--extrinsic` with one image of the plate at
//! its place in the cell (the plate file's `[place]`) solves `T` with the
//! intrinsics of that `.cdf` and writes it there. Whatever goes wrong,
//! nothing is written; `--report` is written before the `.cdf`, so a report
//! that cannot be written leaves the `.cdf` as it was; a replaced file is
//! kept as `camN.cdf.bak` (an older backup is never overwritten: the next
//! is `.bak.1`, `.bak.2`, …).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};

use super::Global;
use crate::calib::{self, Calibration, Plate, View};
use crate::formats::{cdf, imageio};
use crate::llv::GreyImage;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Camera number (1-based); may be left out when --out names the file.
    #[arg(long)]
    pub camera: Option<u32>,
    /// Calibration plate: a name from profiles/plates/ or a .toml file.
    #[arg(long, value_name = "PLATE")]
    pub plate: String,
    /// Images of the plate (.img .png .pgm .tif .bmp .jpg); one with --extrinsic.
    pub images: Vec<PathBuf>,
    /// The .cdf to write (default camN.cdf in the current folder).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Solve the pose T from one image of the plate at its place in the cell.
    #[arg(long)]
    pub extrinsic: bool,
    /// The scale S (mm per pixel), when the profile's .cdf has none: `SX,SY`.
    #[arg(long, value_name = "SX,SY", allow_hyphen_values = true)]
    pub scale: Option<String>,
    /// Estimate sy (sx kept): only S's ratio can be told from images.
    #[arg(long)]
    pub estimate_scale: bool,
    /// State the centre C (px) instead of solving for it: `X,Y` (negative
    /// values allowed), or `image` for the image's middle.
    #[arg(long, value_name = "X,Y|image", allow_hyphen_values = true)]
    pub centre: Option<String>,
    /// The distortion model: `default` (radial k1 k2, decentering p1 p2) or
    /// `full` (also radial k3 and Weng's thin prism s1 s2, which trades off
    /// with C).
    #[arg(long, value_enum, default_value_t = Model::Default)]
    pub model: Model,
    /// Replace the intrinsics of an existing --out file.
    #[arg(long)]
    pub yes: bool,
    /// Also write the calibration page (residuals, coverage, parameters) as
    /// PostScript.
    #[arg(long, value_name = "FILE.ps")]
    pub report: Option<PathBuf>,
    /// Only check the plate file and describe it.
    #[arg(long)]
    pub check_plate: bool,
}

/// Which distortion terms are estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Model {
    /// Radial k1, k2 and decentering p1, p2 (what real lenses pin down).
    Default,
    /// Also radial k3 and the thin prism s1, s2.
    Full,
}

/// Two numbers `A,B` (spaces allowed round them).
fn pair(opt: &str, s: &str, what: &str) -> anyhow::Result<[f64; 2]> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    let nums: Option<Vec<f64>> = v.iter().map(|t| t.parse().ok()).collect();
    match nums.as_deref() {
        Some([x, y]) if x.is_finite() && y.is_finite() => Ok([*x, *y]),
        _ => bail!("{opt} {s}: {what}; nothing written"),
    }
}

fn read_images(paths: &[PathBuf]) -> anyhow::Result<Vec<(String, GreyImage)>> {
    paths
        .iter()
        .map(|p| {
            let f = imageio::read_any(p)?;
            Ok((crate::text::path(p), f.image))
        })
        .collect()
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let plate = Plate::load(&a.plate)?;
    if a.check_plate {
        outln!("{}: {}", plate.name, plate.describe());
        outln!("plate file: {}", crate::calib::plate::in_use(&a.plate));
        outln!(
            "{} corners; origin corner {}",
            plate.corners().len(),
            if plate.oriented() {
                "told apart in images"
            } else {
                "not told apart (intrinsics only)"
            }
        );
        return Ok(ExitCode::SUCCESS);
    }
    let out = match (&a.out, a.camera) {
        (Some(o), _) => o.clone(),
        (None, Some(cam)) => PathBuf::from(format!("cam{cam}.cdf")),
        (None, None) => bail!("which camera: --camera N (writes camN.cdf) or --out FILE.cdf"),
    };
    let name = match a.camera {
        Some(cam) => format!("camera {cam}"),
        None => crate::text::path(&out),
    };
    if a.images.is_empty() {
        bail!("no images: give the images of the plate after the options");
    }
    if a.extrinsic {
        return extrinsic(&a, &plate, &out);
    }
    let (sx, sy) = match &a.scale {
        Some(s) => match pair("--scale", s, "SX,SY, two positive numbers (mm per pixel)")? {
            [x, y] if x > 0.0 && y > 0.0 => (x, y),
            _ => bail!("--scale {s}: SX,SY, two positive numbers (mm per pixel); nothing written"),
        },
        None => match a.camera {
            Some(cam) => stated_scale(&g.load_profile()?, cam)?,
            None => out_scale(&out)?,
        },
    };
    let images = read_images(&a.images)?;
    let (w, h) = images.first().map(|i| i.1.size()).unwrap_or_default();
    if let Some((name, img)) = images.iter().find(|i| i.1.size() != (w, h)) {
        bail!(
            "{name} is {} × {}, the first image {w} × {h}: one camera's views share a size (a photograph resized or from another camera?); nothing written",
            img.width(),
            img.height()
        );
    }
    let centre = match a.centre.as_deref() {
        None => None,
        Some("image") => Some([w as f64 / 2.0, h as f64 / 2.0]),
        Some(s) => Some(pair("--centre", s, "X,Y in pixels, or `image`")?),
    };
    // An --out that is there (a link too, even a broken one) is read now,
    // before the work: the calibration keeps its other entries, so a
    // damaged file or a link is refused here, not after the views were
    // searched and the --report page written.
    if out.symlink_metadata().is_ok() {
        cdf::read_cdf(&out).with_context(|| {
            format!(
                "{} is there and cannot be read (the calibration keeps its other entries): mend it, or move it away; nothing written",
                crate::text::path(&out)
            )
        })?;
        if !a.yes {
            bail!(
                "{} exists: --yes replaces its S, C, f and D (its other entries are kept, the old file as {}), or choose another --out",
                crate::text::path(&out),
                crate::text::path(calib::backup_name(&out))
            );
        }
    }
    outln!(
        "plate {}: {} ({})",
        plate.name,
        plate.describe(),
        crate::calib::plate::in_use(&a.plate)
    );
    let t0 = Instant::now();
    let found = calib::detect_all(&images, &plate);
    let detect_ms = t0.elapsed().as_secs_f64() * 1e3;
    for (name, e) in &found.refused {
        errln!("vss: {name}: left out: {e}");
    }
    let views: Vec<View> = found.views.iter().map(|(v, _)| v.clone()).collect();
    let options = calib::Options {
        width: w,
        height: h,
        sx,
        sy,
        estimate_scale: a.estimate_scale,
        centre,
        full_model: a.model == Model::Full,
    };
    let t1 = Instant::now();
    let result = calib::calibrate(&views, &options);
    let solve_ms = t1.elapsed().as_secs_f64() * 1e3;
    let c = result.map_err(|e| {
        let refused = if found.refused.is_empty() {
            String::new()
        } else {
            format!(
                " ({} of {} images left out, each with its reason above)",
                found.refused.len(),
                images.len()
            )
        };
        anyhow::anyhow!("{e}{refused}; nothing written")
    })?;
    print_calibration(&c)?;
    outln!(
        "grid detection {:.1} ms a view, solution {solve_ms:.0} ms ({} evaluations)",
        detect_ms / images.len().max(1) as f64,
        c.evaluations
    );
    match calib::cross_validate(&views, &options) {
        Some(x) => outln!(
            "cross-validation (two calibrations from alternate views): held-out views RMS {:.3} px; the two differ in projection by {:.3} px RMS, {:.3} px at most",
            x.held_out_rms,
            x.difference_rms,
            x.difference_max
        ),
        None => outln!("cross-validation: needs 6 views (3 a half) that each calibrate"),
    }
    for w in &c.warnings {
        outln!("warning: {w}");
    }
    // The report first: if it cannot be written, the .cdf is left as it was.
    if let Some(r) = &a.report {
        let ps = crate::report::calibration::document_named(&name, &c);
        crate::fsutil::write_atomic(r, ps.as_bytes())
            .with_context(|| format!("cannot write {}; nothing written", crate::text::path(r)))?;
        outln!("wrote the calibration page {}", crate::text::path(r));
    }
    let bak = calib::write_intrinsics(&out, &c)?;
    outln!(
        "wrote {}: C{} f, D, K calibrated, S {}{}",
        crate::text::path(&out),
        if centre.is_some() { " stated," } else { "," },
        if c.scale_estimated {
            "with sy estimated"
        } else {
            "stated"
        },
        match bak {
            Some(b) => format!("; the old file kept as {}", crate::text::path(&b)),
            None => String::new(),
        }
    );
    Ok(ExitCode::SUCCESS)
}

/// `S` of the `.cdf` at `out` (when no camera is named).
fn out_scale(out: &Path) -> anyhow::Result<(f64, f64)> {
    let hint = "give --scale SX,SY (mm per pixel, from the camera's data sheet)";
    if !out.exists() {
        bail!(
            "{} does not exist yet, so no scale S: {hint}",
            crate::text::path(out)
        );
    }
    let c = cdf::read_cdf(out).with_context(|| format!("the scale S: {hint}"))?;
    calib::scale_of(&c)
        .with_context(|| format!("{} has no scale S: {hint}", crate::text::path(out)))
}

/// `S` of camera `cam`'s `.cdf` in the profile.
fn stated_scale(profile: &crate::profile::Profile, cam: u32) -> anyhow::Result<(f64, f64)> {
    let hint = "give --scale SX,SY (mm per pixel, from the camera's data sheet)";
    // The camera's description as the one owner serves it (a file, or the
    // built-in cell's compiled-in one).
    let Some(c) = profile
        .camera_cdf(cam)
        .with_context(|| format!("the scale S: {hint}"))?
    else {
        bail!("the profile names no .cdf for camera {cam}, so no scale S: {hint}");
    };
    let shown = profile.cdf_shown(cam).unwrap_or_default();
    calib::scale_of(&c).with_context(|| format!("{shown} has no scale S: {hint}"))
}

fn print_calibration(c: &Calibration) -> anyhow::Result<()> {
    outln!("view                          corners  RMS px  p95 px   tilt");
    for v in &c.views {
        outln!(
            "{:<30} {:>6} {:>7.3} {:>7.3} {:>5.1}°",
            short(&v.name, 30),
            v.residuals.len(),
            v.rms,
            v.p95,
            v.tilt_deg
        );
    }
    let n: usize = c.views.iter().map(|v| v.residuals.len()).sum();
    outln!(
        "overall: {n} corners in {} views, RMS {:.3} px, p95 {:.3} px",
        c.views.len(),
        c.rms,
        c.p95
    );
    for l in calib::parameter_lines(c, "±") {
        outln!("{l}");
    }
    if c.centre_stated {
        outln!("C stated, so the uncertainty of projection leaves out that of C");
    }
    Ok(())
}

fn short(s: &str, n: usize) -> String {
    let chars: Vec<char> = s.chars().collect();
    if chars.len() <= n {
        s.to_string()
    } else {
        let tail: String = chars[chars.len() - (n - 1)..].iter().collect();
        format!("…{tail}")
    }
}

fn extrinsic(a: &Args, plate: &Plate, out: &Path) -> anyhow::Result<ExitCode> {
    let [image] = &a.images[..] else {
        bail!(
            "--extrinsic takes one image of the plate at its place, not {}",
            a.images.len()
        );
    };
    let old = cdf::read_cdf(out).with_context(|| {
        format!(
            "the intrinsics: calibrate them first (vss calibrate --camera N --plate PLATE IMAGES… --out {})",
            crate::text::path(out)
        )
    })?;
    let model = old.model().map_err(|why| {
        anyhow::anyhow!(
            "{} {why}: calibrate the intrinsics first",
            crate::text::path(out)
        )
    })?;
    let imgs = read_images(std::slice::from_ref(image))?;
    let (name, img) = &imgs[0];
    let d = calib::Detector::new()
        .detect(img, plate)
        .map_err(|e| anyhow::anyhow!("{name}: {e}; nothing written"))?;
    if !d.oriented {
        bail!(
            "{name}: the plate's origin corner cannot be told in this view (a square is missing next to another corner); take the view again; nothing written"
        );
    }
    let view = View {
        name: name.clone(),
        corners: d.corners,
    };
    let e = calib::extrinsic::extrinsic(&view, plate, &model)
        .map_err(|e| anyhow::anyhow!("{e}; nothing written"))?;
    outln!(
        "plate {} at its place: {} corners, RMS {:.3} px, p95 {:.3} px",
        plate.name,
        view.corners.len(),
        e.rms,
        e.p95
    );
    outln!("T (world → camera, mm):");
    for r in &e.t {
        outln!(
            "  {:>10.6} {:>10.6} {:>10.6} {:>12.4}",
            r[0],
            r[1],
            r[2],
            r[3]
        );
    }
    outln!(
        "standard errors: rotation {:.4}°, translation {:.3} {:.3} {:.3} mm",
        e.se_rotation_deg,
        e.se_translation[0],
        e.se_translation[1],
        e.se_translation[2]
    );
    let bak = calib::write_extrinsic(out, &old, &e.t)?.1;
    outln!(
        "wrote T into {} (its other entries kept, the old file as {})",
        crate::text::path(out),
        bak.map_or("-".into(), |b| crate::text::path(&b))
    );
    Ok(ExitCode::SUCCESS)
}
