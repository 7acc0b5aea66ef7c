//! `vss selftest`: renders synthetic scenes with known edges, runs the LLV
//! pipeline with the profile's parameters and prints, per noise level,
//! recall, precision, endpoint distances and angle error — with subpixel edge
//! positions and with whole-pixel ones — and a lens-correction check.

use std::process::ExitCode;

use anyhow::Context;

use super::Global;
use crate::llv::synth::eval::{EvalConfig, EvalReport, evaluate};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Noise levels σ (grey levels), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "2,5,10")]
    pub noise: Vec<f64>,
    /// Seed of the scenes and the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scenes per noise level.
    #[arg(long, default_value_t = 12)]
    pub scenes: usize,
    /// Image width and height (px).
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    if a.size < 64 {
        anyhow::bail!(
            "--size {} is too small: the scenes need at least 64 px",
            a.size
        );
    }
    if a.scenes == 0 {
        anyhow::bail!("--scenes must be at least 1");
    }
    if let Some(n) = a.noise.iter().find(|n| !(n.is_finite() && **n >= 0.0)) {
        anyhow::bail!("--noise {n} is not a noise level (σ ≥ 0 grey levels)");
    }
    let profile = g.load_profile()?;
    let cfg = EvalConfig {
        noise: a.noise,
        scenes: a.scenes,
        size: a.size,
        seed: a.seed,
        ..Default::default()
    };
    let report = evaluate(&cfg, &profile.llv).context("running the pipeline on the scenes")?;
    if a.json {
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        out!(
            "{}",
            table(&report, g.profile.as_deref().unwrap_or("default"))
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// The report as a table for people.
pub fn table(r: &EvalReport, profile: &str) -> String {
    use std::fmt::Write;
    let c = &r.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} scenes of {}×{} px, blur σ = {}, seed {}, profile {profile}; true edges: contrast ≥ {} grey levels",
        c.scenes, c.size, c.size, c.blur, c.seed, c.min_contrast
    );
    let _ = writeln!(
        s,
        "{:>6}  {:<11} {:>6} {:>9} {:>6}  {:>13}  {:>9}  {:>6} {:>6}",
        "noise",
        "positions",
        "recall",
        "precision",
        "F",
        "endpoint px",
        "angle °",
        "points",
        "lines"
    );
    for l in &r.levels {
        for (name, m) in [("subpixel", &l.subpixel), ("whole-pixel", &l.whole_pixel)] {
            let _ = writeln!(
                s,
                "{:>6}  {:<11} {:>6.3} {:>9.3} {:>6.3}  {:>6.3} / {:<5.3}  {:>9.3}  {:>6.0} {:>6.1}",
                l.noise,
                name,
                m.recall,
                m.precision,
                m.f_score(),
                m.endpoint_mean,
                m.endpoint_p95,
                m.angle_mean_deg,
                l.edge_points,
                l.lines
            );
        }
    }
    for l in &r.levels {
        let _ = writeln!(
            s,
            "noise {}: edge points lie {:.3} px (RMS) from their true edges with subpixel positions, {:.3} px with whole pixels",
            l.noise, l.point_rms_subpixel, l.point_rms_whole_pixel
        );
    }
    let lr = &r.lens;
    let rel = if lr.residual_undistorted > 0.0 {
        100.0 * (lr.residual_corrected / lr.residual_undistorted - 1.0)
    } else {
        0.0
    };
    let _ = writeln!(
        s,
        "lens (noise σ = {}): mean line-fit residual {:.4} px undistorted, {:.4} px distorted, {:.4} px corrected ({:+.1} %)",
        c.lens_noise, lr.residual_undistorted, lr.residual_distorted, lr.residual_corrected, rel
    );
    let srel = if lr.straightness_undistorted > 0.0 {
        100.0 * (lr.straightness_corrected / lr.straightness_undistorted - 1.0)
    } else {
        0.0
    };
    let _ = writeln!(
        s,
        "lens (distortion ×{}): edge-point straightness {:.4} px undistorted, {:.4} px distorted, {:.4} px corrected ({:+.1} %, {} edges)",
        c.lens_scale,
        lr.straightness_undistorted,
        lr.straightness_distorted,
        lr.straightness_corrected,
        srel,
        lr.straightness_edges
    );
    let _ = writeln!(
        s,
        "lens: endpoint mean {:.3} px and angle {:.3}° corrected, {:.3} px and {:.3}° uncorrected",
        lr.corrected.endpoint_mean,
        lr.corrected.angle_mean_deg,
        lr.uncorrected.endpoint_mean,
        lr.uncorrected.angle_mean_deg
    );
    s
}
