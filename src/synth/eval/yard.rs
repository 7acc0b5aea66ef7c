//! The yard family's evaluation behind `vss selftest --family yard`: render
//! each scene once, expose it at each noise level, run the pipeline, score
//! the lines with the don't-care edges and the breakdowns; then the lens
//! check: the scene rendered through its lens, corrected with its `.cdf`,
//! scored against the same truth as the undistorted render.
//!
//! Noise seeds depend on the scene and the noise level itself (not its
//! place in the list), so `--noise 5` alone gives the σ 5 images of the
//! full run.

use std::fmt;

use serde::Serialize;

use super::super::score::{Metrics, Tally};
use super::super::yard::{YardNoise, YardScene, YardTruth, truth, yard_scenes};
use super::run_one;
use crate::llv::lens::LensMap;
use crate::llv::rng::mix;
use crate::llv::{GreyImage, LlvError, Params};

/// A noise level: Gaussian σ, or the family's signal-dependent noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Level {
    Sigma(f64),
    Signal,
}

impl Level {
    /// The yard renderer's noise for this level.
    pub fn noise(self) -> YardNoise {
        match self {
            Level::Sigma(s) => YardNoise::Gauss(s),
            Level::Signal => YardNoise::SIGNAL,
        }
    }

    /// A short name for folders and tables: `s2`, `sd`.
    pub fn tag(self) -> String {
        match self {
            Level::Sigma(s) => format!("s{s}"),
            Level::Signal => "sd".into(),
        }
    }

    fn code(self) -> u64 {
        match self {
            Level::Sigma(s) => (s * 64.0).round().max(0.0) as u64,
            Level::Signal => 1 << 40,
        }
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Level::Sigma(s) => write!(f, "{s}"),
            Level::Signal => f.write_str("sd"),
        }
    }
}

/// A `--noise` value that is neither σ ≥ 0 nor `sd`.
#[derive(Debug, thiserror::Error)]
#[error("\"{0}\" is not a noise level: give σ ≥ 0 grey levels, or sd for signal-dependent noise")]
pub struct BadLevel(pub String);

impl std::str::FromStr for Level {
    type Err = BadLevel;
    fn from_str(s: &str) -> Result<Level, BadLevel> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("sd") {
            return Ok(Level::Signal);
        }
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(Level::Sigma(v)),
            _ => Err(BadLevel(t.to_string())),
        }
    }
}

impl Serialize for Level {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Level::Sigma(v) => s.serialize_f64(*v),
            Level::Signal => s.serialize_str("sd"),
        }
    }
}

/// What to evaluate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct YardConfig {
    pub noise: Vec<Level>,
    pub scenes: usize,
    pub size: usize,
    pub seed: u64,
    /// Fainter edges are don't-care (grey levels).
    pub min_contrast: f64,
    /// Noise levels of the lens check's images.
    pub lens_noise: Vec<Level>,
}

impl Default for YardConfig {
    fn default() -> Self {
        YardConfig {
            noise: vec![
                Level::Sigma(0.0),
                Level::Sigma(2.0),
                Level::Sigma(5.0),
                Level::Sigma(10.0),
                Level::Signal,
            ],
            scenes: 12,
            size: 512,
            seed: 1,
            min_contrast: 10.0,
            lens_noise: vec![Level::Sigma(0.0), Level::Sigma(2.0)],
        }
    }
}

/// Scores at one noise level.
#[derive(Clone, Debug, Serialize)]
pub struct YardLevel {
    pub noise: Level,
    pub metrics: Metrics,
    /// Edge points per image, both directions (mean).
    pub edge_points: f64,
    /// Lines per image after CONNECT (mean).
    pub lines: f64,
}

/// The lens check at one noise level: the same scenes undistorted,
/// distorted as they are, and distorted then corrected with their `.cdf`,
/// against one truth (what the distorted image shows, in ideal
/// coordinates). Noise-free, it measures the lens path alone; with noise,
/// the corrected images also gain from the bilinear resampling, which
/// averages noise.
#[derive(Clone, Debug, Serialize)]
pub struct YardLens {
    pub noise: Level,
    pub undistorted: Metrics,
    pub corrected: Metrics,
    pub uncorrected: Metrics,
    /// F corrected − F undistorted (the goal: within ±0.005).
    pub f_difference: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct YardReport {
    pub config: YardConfig,
    pub levels: Vec<YardLevel>,
    pub lens: Vec<YardLens>,
}

/// One scene ready for exposure: its defocused render and its truth.
pub struct YardCase {
    pub scene: YardScene,
    pub blurred: Vec<f64>,
    pub truth: YardTruth,
}

/// The scenes of `cfg`, rendered and with their truth.
pub fn yard_cases(cfg: &YardConfig) -> Vec<YardCase> {
    yard_scenes(cfg.scenes, cfg.size, cfg.seed)
        .into_iter()
        .map(|scene| {
            let blurred = scene.render_blurred(false);
            let truth = truth(&scene, false, cfg.min_contrast);
            YardCase {
                scene,
                blurred,
                truth,
            }
        })
        .collect()
}

/// The image of scene `i` at `level` (the seed depends on both).
pub fn yard_image(cfg: &YardConfig, case: &YardCase, i: usize, level: Level) -> GreyImage {
    let seed = mix(cfg.seed, 0x7A5D_0000 + 4096 * i as u64 + level.code());
    case.scene.expose(&case.blurred, level.noise(), seed)
}

/// Runs the evaluation with the given LLV parameters.
pub fn evaluate_yard(cfg: &YardConfig, params: &Params) -> Result<YardReport, LlvError> {
    let cases = yard_cases(cfg);
    let mut levels = Vec::new();
    for &level in &cfg.noise {
        let mut tally = Tally::default();
        let (mut points, mut lines) = (0usize, 0usize);
        for (i, c) in cases.iter().enumerate() {
            let img = yard_image(cfg, c, i, level);
            let out = run_one(&img, None, params)?;
            tally.add_with(&out.lines, &c.truth.edges, &c.truth.dont_care);
            points += out.edges_h.points.len() + out.edges_v.points.len();
            lines += out.lines.len();
        }
        let n = cases.len().max(1) as f64;
        levels.push(YardLevel {
            noise: level,
            metrics: tally.metrics(),
            edge_points: points as f64 / n,
            lines: lines as f64 / n,
        });
    }
    let lens = cfg
        .lens_noise
        .iter()
        .map(|&l| lens_check(cfg, &cases, l, params))
        .collect::<Result<_, _>>()?;
    Ok(YardReport {
        config: cfg.clone(),
        levels,
        lens,
    })
}

/// Scene `i` rendered through its lens at `level`.
pub fn yard_lens_image(cfg: &YardConfig, case: &YardCase, i: usize, level: Level) -> GreyImage {
    let seed = mix(cfg.seed, 0x1E25_0000 + 4096 * i as u64 + level.code());
    let sc = &case.scene;
    sc.expose(&sc.render_blurred(true), level.noise(), seed)
}

/// Scene `i` undistorted, with the noise of [`yard_lens_image`].
fn yard_lens_twin(cfg: &YardConfig, case: &YardCase, i: usize, level: Level) -> GreyImage {
    let seed = mix(cfg.seed, 0x1E25_0000 + 4096 * i as u64 + level.code());
    case.scene.expose(&case.blurred, level.noise(), seed)
}

fn lens_check(
    cfg: &YardConfig,
    cases: &[YardCase],
    level: Level,
    params: &Params,
) -> Result<YardLens, LlvError> {
    let (mut plain, mut corr, mut unc) = (Tally::default(), Tally::default(), Tally::default());
    for (i, c) in cases.iter().enumerate() {
        let sc = &c.scene;
        let t = truth(sc, true, cfg.min_contrast);
        let straight = yard_lens_twin(cfg, c, i, level);
        let out = run_one(&straight, None, params)?;
        plain.add_with(&out.lines, &t.edges, &t.dont_care);
        let bent = yard_lens_image(cfg, c, i, level);
        let out = run_one(&bent, None, params)?;
        unc.add_with(&out.lines, &t.edges, &t.dont_care);
        let map = LensMap::new(&sc.lens, sc.width, sc.height);
        let out = run_one(&bent, Some(&map), params)?;
        corr.add_with(&out.lines, &t.edges, &t.dont_care);
    }
    let (undistorted, corrected) = (plain.metrics(), corr.metrics());
    Ok(YardLens {
        noise: level,
        undistorted,
        corrected,
        uncorrected: unc.metrics(),
        f_difference: corrected.f_score() - undistorted.f_score(),
    })
}
