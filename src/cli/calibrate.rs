//! `vss calibrate`: a camera's `.cdf` from images of a calibration plate.
//!
//! `vss calibrate --camera N --plate PLATE IMAGES… [--out camN.cdf]` finds the
//! plate in every image, solves the intrinsics (`crate::calib`), prints the
//! reprojection error per view and overall, each parameter with its standard
//! error and what makes the set of views weak, and writes `C`, `f`, `D`
//! (calibrated) and `S` (stated, from the camera's `.cdf` in the profile or
//! `--scale`) into the `.cdf`, keeping its other entries. `--extrinsic` with
//! one image of the plate at its place in the cell (the plate file's
//! `[place]`) solves `T` with the intrinsics of that `.cdf` and writes it
//! there. Whatever goes wrong, nothing is written; a replaced file is kept as
//! `camN.cdf.bak`.

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
    /// Camera number (1-based).
    #[arg(long, required_unless_present = "check_plate")]
    pub camera: Option<u32>,
    /// Calibration plate: a name from profiles/plates/ or a .toml file.
    #[arg(long, value_name = "PLATE")]
    pub plate: String,
    /// Images of the plate (.img .png .pgm .tif .bmp); one with --extrinsic.
    pub images: Vec<PathBuf>,
    /// The .cdf to write (default camN.cdf in the current folder).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Solve the pose T from one image of the plate at its place in the cell.
    #[arg(long)]
    pub extrinsic: bool,
    /// The scale S (mm per pixel), when the profile's .cdf has none.
    #[arg(long, value_name = "SX,SY", value_delimiter = ',', num_args = 2)]
    pub scale: Option<Vec<f64>>,
    /// Estimate sy (sx kept): only S's ratio can be told from images.
    #[arg(long)]
    pub estimate_scale: bool,
    /// State the centre C (px) instead of solving for it: `X,Y`, or `image`
    /// for the image's middle.
    #[arg(long, value_name = "X,Y|image")]
    pub centre: Option<String>,
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

fn read_images(paths: &[PathBuf]) -> anyhow::Result<Vec<(String, GreyImage)>> {
    paths
        .iter()
        .map(|p| {
            let f = imageio::read_any(p)?;
            Ok((p.display().to_string(), f.image))
        })
        .collect()
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let plate = Plate::load(&a.plate)?;
    if a.check_plate {
        outln!("{}: {}", plate.name, plate.describe());
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
    let cam = a.camera.context("--camera N is needed")?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("cam{cam}.cdf")));
    if a.images.is_empty() {
        bail!("no images: give the images of the plate after the options");
    }
    if a.extrinsic {
        return extrinsic(&a, &plate, &out);
    }
    let profile = g.load_profile()?;
    let (sx, sy) = match &a.scale {
        Some(s) => match s[..] {
            [x, y] if x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite() => (x, y),
            _ => bail!("--scale {s:?}: two positive numbers, mm per pixel"),
        },
        None => stated_scale(&profile, cam)?,
    };
    let images = read_images(&a.images)?;
    let (w, h) = images.first().map(|i| i.1.size()).unwrap_or_default();
    if let Some((name, img)) = images.iter().find(|i| i.1.size() != (w, h)) {
        bail!(
            "{name} is {} × {}, the first image {w} × {h}: one camera's views share a size",
            img.width(),
            img.height()
        );
    }
    let centre = match a.centre.as_deref() {
        None => None,
        Some("image") => Some([w as f64 / 2.0, h as f64 / 2.0]),
        Some(s) => {
            let v: Vec<f64> = s.split(',').filter_map(|t| t.trim().parse().ok()).collect();
            match v[..] {
                [x, y] if x.is_finite() && y.is_finite() => Some([x, y]),
                _ => bail!("--centre {s}: X,Y in pixels, or `image`"),
            }
        }
    };
    if out.exists() && !a.yes {
        bail!(
            "{} exists: --yes replaces its S, C, f and D (its other entries are kept, the old file as {}.bak), or choose another --out",
            out.display(),
            out.display()
        );
    }
    outln!("plate {}: {}", plate.name, plate.describe());
    let t0 = Instant::now();
    let found = calib::detect_all(&images, &plate);
    let detect_ms = t0.elapsed().as_secs_f64() * 1e3;
    for (name, e) in &found.refused {
        eprintln!("vss: {name}: left out: {e}");
    }
    let views: Vec<View> = found.views.iter().map(|(v, _)| v.clone()).collect();
    let t1 = Instant::now();
    let result = calib::calibrate(
        &views,
        &calib::Options {
            width: w,
            height: h,
            sx,
            sy,
            estimate_scale: a.estimate_scale,
            centre,
        },
    );
    let solve_ms = t1.elapsed().as_secs_f64() * 1e3;
    let c = result.map_err(|e| anyhow::anyhow!("{e}; nothing written"))?;
    print_calibration(&c)?;
    outln!(
        "grid detection {:.1} ms a view, solution {solve_ms:.0} ms ({} evaluations)",
        detect_ms / images.len().max(1) as f64,
        c.evaluations
    );
    for w in &c.warnings {
        outln!("warning: {w}");
    }
    let existed = out.exists();
    calib::write_intrinsics(&out, &c)?;
    if let Some(r) = &a.report {
        let ps = crate::report::calibration::document(cam, &c);
        crate::fsutil::write_atomic(r, ps.as_bytes())
            .with_context(|| format!("cannot write {}", r.display()))?;
        outln!("wrote the calibration page {}", r.display());
    }
    outln!(
        "wrote {}: C{} f D calibrated, S {}{}",
        out.display(),
        if centre.is_some() { " stated," } else { "," },
        if c.scale_estimated {
            "with sy estimated"
        } else {
            "stated"
        },
        if existed {
            format!("; the old file kept as {}.bak", out.display())
        } else {
            String::new()
        }
    );
    Ok(ExitCode::SUCCESS)
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
            out.display()
        )
    })?;
    let model = old.camera_model().with_context(|| {
        format!(
            "{} lacks S, C or f: calibrate the intrinsics first",
            out.display()
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
    calib::write_extrinsic(out, &old, &e.t)?;
    outln!(
        "wrote T into {} (its other entries kept, the old file as {}.bak)",
        out.display(),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
