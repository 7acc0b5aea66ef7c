//! `vss selftest`: renders the two families of synthetic scenes with known
//! edges (cubes: polyhedra under point lights; yard: layered welding-yard
//! parts, `synth::yard`), runs the LLV pipeline with the profile's
//! parameters and prints, per family and noise level, recall, precision, F,
//! endpoint distances, angle error and the breakdowns of the scorer — for
//! the cubes also with whole-pixel positions — and a lens check per family.
//!
//! `--export DIR` writes the same images, their truth and vss's segments
//! and times for other detectors to run on; `--score DIR` scores every
//! detector found there with the same scorer (`synth::compare`).
//!
//! Real photographs (`synth::real`): `--score-real PHOTOS` runs vss
//! on every photograph with a `NAME_gt.txt` and scores it by the
//! length-based rule of the photographs' README; with `--dir DIR` it scores
//! instead every detector's `NAME.DET.seg` in DIR. `--export-real PHOTOS
//! --dir DIR` writes vss's segments and times there (for
//! `benches/opencv_lines.py real`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;

use super::Global;
use crate::synth::compare::{self, ExportConfig};
use crate::synth::eval::yard::{Level, YardConfig, YardReport, evaluate_yard};
use crate::synth::eval::{EvalConfig, EvalReport, evaluate};
use crate::synth::real;

mod tables;

pub use tables::{compare_table, table, yard_table};

/// Which family of scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Family {
    Cubes,
    Yard,
    All,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Family of scenes: cubes (polyhedra), yard (welding-yard parts) or all.
    #[arg(long, value_enum, default_value = "all")]
    pub family: Family,
    /// Noise levels σ (grey levels), comma-separated; `sd` is the yard's
    /// signal-dependent noise. Default: 2,5,10 for the cubes, 0,2,5,10,sd
    /// for the yard.
    #[arg(long, value_delimiter = ',')]
    pub noise: Option<Vec<Level>>,
    /// Seed of the scenes and the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scenes per noise level.
    #[arg(long, default_value_t = 12)]
    pub scenes: usize,
    /// Image width and height (px).
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Write the images, truth and vss's segments and times to DIR instead
    /// of printing scores (for benches/opencv_lines.py).
    #[arg(long, value_name = "DIR", conflicts_with = "score")]
    pub export: Option<PathBuf>,
    /// Timed runs of vss per image with --export.
    #[arg(long, default_value_t = 20)]
    pub runs: usize,
    /// Score every detector's segments in DIR (made by --export) instead of
    /// running the pipeline.
    #[arg(long, value_name = "DIR")]
    pub score: Option<PathBuf>,
    /// Score real photographs with NAME_gt.txt files in PHOTOS: vss run on
    /// them, or with --dir, every detector's NAME.DET.seg in DIR.
    #[arg(long, value_name = "PHOTOS", conflicts_with_all = ["score", "export", "export_real"])]
    pub score_real: Option<PathBuf>,
    /// Run vss on the photographs with NAME_gt.txt files in PHOTOS and write
    /// its segments and times to --dir (for benches/opencv_lines.py real).
    #[arg(long, value_name = "PHOTOS", conflicts_with_all = ["score", "export"], requires = "dir")]
    pub export_real: Option<PathBuf>,
    /// The folder of segment files for --score-real and --export-real.
    #[arg(long, value_name = "DIR")]
    pub dir: Option<PathBuf>,
    /// Change a parameter for this run: --set edges.half_width=3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

fn configs(a: &Args) -> (Option<EvalConfig>, Option<YardConfig>) {
    let cubes = matches!(a.family, Family::Cubes | Family::All).then(|| {
        let noise = match &a.noise {
            Some(levels) => levels
                .iter()
                .filter_map(|l| match l {
                    Level::Sigma(s) => Some(*s),
                    Level::Signal => None,
                })
                .collect(),
            None => EvalConfig::default().noise,
        };
        EvalConfig {
            noise,
            scenes: a.scenes,
            size: a.size,
            seed: a.seed,
            ..Default::default()
        }
    });
    let yard = matches!(a.family, Family::Yard | Family::All).then(|| {
        let d = YardConfig::default();
        YardConfig {
            noise: a.noise.clone().unwrap_or(d.noise),
            scenes: a.scenes,
            size: a.size,
            seed: a.seed,
            ..d
        }
    });
    // A cube run left with no level (only `sd` asked for) is no run.
    (cubes.filter(|c| !c.noise.is_empty()), yard)
}

/// The profile's parameters with the `--set` changes.
fn params(g: &Global, a: &Args) -> anyhow::Result<crate::llv::Params> {
    params_of(&g.load_profile()?, a)
}

/// `profile`'s parameters with the `--set` changes.
fn params_of(profile: &crate::profile::Profile, a: &Args) -> anyhow::Result<crate::llv::Params> {
    let mut p = profile.llv.clone();
    for s in &a.set {
        p.set_str(s).with_context(|| format!("--set {s}"))?;
    }
    p.validate()?;
    Ok(p)
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    if let Some(photos) = &a.export_real {
        let p = params(g, &a)?;
        let dir = a.dir.as_deref().context("--export-real needs --dir DIR")?;
        let n = real::export_real(photos, dir, &p, a.runs).with_context(|| {
            format!(
                "running vss on the photographs of {}",
                crate::text::path(photos)
            )
        })?;
        outln!(
            "vss on {n} photographs: segments and times written to {}",
            crate::text::path(dir)
        );
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(photos) = &a.score_real {
        let scores = match &a.dir {
            Some(dir) => real::score_dir(photos, dir)?,
            None => {
                let p = params(g, &a)?;
                let (m, _, by_contrast) = real::evaluate_real(photos, &p).with_context(|| {
                    format!(
                        "running vss on the photographs of {}",
                        crate::text::path(photos)
                    )
                })?;
                vec![real::RealScore {
                    detector: compare::VSS.into(),
                    metrics: m,
                    fastest_ms: None,
                    median_ms: None,
                    by_contrast,
                }]
            }
        };
        if a.json {
            outln!("{}", serde_json::to_string(&scores)?);
        } else {
            let n = scores.first().map_or(0, |s| s.metrics.images);
            out!("{}", real::table(&scores, n));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(dir) = &a.score {
        let scores = compare::score_dir(dir)?;
        if a.json {
            outln!("{}", serde_json::to_string(&scores)?);
        } else {
            out!("{}", compare_table(&scores));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if a.size < 64 {
        anyhow::bail!(
            "--size {} is too small: the scenes need at least 64 px",
            a.size
        );
    }
    if a.scenes == 0 {
        anyhow::bail!("--scenes must be at least 1");
    }
    let profile = g.load_profile()?;
    let llv = params_of(&profile, &a)?;
    let (cubes, yard) = configs(&a);
    let name = g.profile.as_deref().unwrap_or("default");
    if let Some(dir) = &a.export {
        let cfg = ExportConfig {
            cubes,
            yard,
            runs: a.runs,
        };
        let m = compare::export(dir, &cfg, &llv)
            .with_context(|| format!("exporting the scenes to {}", crate::text::path(dir)))?;
        for f in &m.families {
            outln!(
                "{}: {} scenes of {}×{} px at noise {} written to {}",
                f.name,
                f.scenes,
                f.size,
                f.size,
                f.levels.join(", "),
                crate::text::path(dir.join(&f.name))
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let cube_report: Option<EvalReport> = cubes
        .map(|c| evaluate(&c, &llv))
        .transpose()
        .context("running the pipeline on the cube scenes")?;
    let yard_report: Option<YardReport> = yard
        .map(|y| evaluate_yard(&y, &llv))
        .transpose()
        .context("running the pipeline on the yard scenes")?;
    if a.json {
        let mut v = match &cube_report {
            Some(r) => serde_json::to_value(r)?,
            None => serde_json::json!({}),
        };
        if let Some(obj) = v.as_object_mut() {
            if let Some(y) = &yard_report {
                obj.insert("yard".into(), serde_json::to_value(y)?);
            }
            obj.insert("profile".into(), profile.in_use().into());
        }
        outln!("{}", serde_json::to_string(&v)?);
    } else {
        if let Some(r) = &cube_report {
            out!("{}", table(r, name));
        }
        if let Some(y) = &yard_report {
            if cube_report.is_some() {
                outln!();
            }
            out!("{}", yard_table(y, name));
        }
    }
    Ok(ExitCode::SUCCESS)
}
