//! The accuracy evaluation behind `vss selftest` and `tests/accuracy.rs`:
//! render the test scenes, run the LLV pipeline per noise level, score the
//! lines against the true edges, and repeat with whole-pixel edge positions
//! and through lens distortion and correction.
//!
//! Every scene is rendered noise-free once; each noise level adds its own
//! seeded noise to that render, so levels differ only in noise. Edges with
//! some contrast (≥ 1 grey level) but less than `min_contrast` are
//! don't-care (`score`): finding them neither helps nor costs. The yard
//! family's evaluation is in [`yard`].

use serde::Serialize;

pub mod yard;

use super::score::{Metrics, Tally};
use super::straight::Straightness;
use super::{Camera, PointLight, RenderOptions, Scene};
use crate::llv::lens::LensMap;
use crate::llv::pipeline::{self, Input};
use crate::llv::rng::mix;
use crate::llv::{EdgePoints, GreyImage, LlvError, Params, Point, Segment};

/// Contrast (grey levels) below which an edge is no edge at all, not even
/// a don't-care one.
pub const FAINT: f64 = 1.0;

/// What to evaluate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalConfig {
    /// Noise σ levels (grey levels).
    pub noise: Vec<f64>,
    pub scenes: usize,
    /// Image width and height (px).
    pub size: usize,
    pub seed: u64,
    /// Blur σ (px) of every render.
    pub blur: f64,
    /// Edges with less noise-free contrast are no true edges (grey levels).
    pub min_contrast: f64,
    /// Noise σ of the lens check's images.
    pub lens_noise: f64,
    /// The lens check multiplies each test camera's distortion by this, so
    /// that uncorrected lines are measurably bent (the test cameras' own
    /// distortion moves image corners by only 1–3 px).
    pub lens_scale: f64,
}

impl Default for EvalConfig {
    fn default() -> Self {
        EvalConfig {
            noise: vec![2.0, 5.0, 10.0],
            scenes: 12,
            size: 512,
            seed: 1,
            blur: 1.0,
            min_contrast: 10.0,
            lens_noise: 2.0,
            lens_scale: 3.0,
        }
    }
}

/// Scores at one noise level.
#[derive(Clone, Debug, Serialize)]
pub struct NoiseResult {
    pub noise: f64,
    /// The pipeline as it is (subpixel edge positions).
    pub subpixel: Metrics,
    /// The same edges rounded to whole pixels, then lines and CONNECT.
    pub whole_pixel: Metrics,
    /// RMS distance (px) of edge points from their true edges (away from
    /// the ends), with subpixel and with whole-pixel positions.
    pub point_rms_subpixel: f64,
    pub point_rms_whole_pixel: f64,
    /// Edge points per image, both directions (mean).
    pub edge_points: f64,
    /// Lines per image after CONNECT (mean).
    pub lines: f64,
}

/// The lens check: mean line-fit residual (px, length-weighted over the
/// extracted lines) of the undistorted render, of the distorted render as it
/// is, and of the distorted render after lens correction.
#[derive(Clone, Debug, Serialize)]
pub struct LensResult {
    pub residual_undistorted: f64,
    pub residual_distorted: f64,
    pub residual_corrected: f64,
    /// RMS residual (px) of the edge points along each true edge about their
    /// own fitted line (`straight.rs`): undistorted, distorted, corrected.
    pub straightness_undistorted: f64,
    pub straightness_distorted: f64,
    pub straightness_corrected: f64,
    /// True edges measured for straightness (all images).
    pub straightness_edges: usize,
    /// Scores of the corrected images' lines against the true edges.
    pub corrected: Metrics,
    /// Scores of the uncorrected distorted images' lines.
    pub uncorrected: Metrics,
}

/// The whole evaluation.
#[derive(Clone, Debug, Serialize)]
pub struct EvalReport {
    pub config: EvalConfig,
    pub levels: Vec<NoiseResult>,
    pub lens: LensResult,
}

/// One cube-family scene ready for noise: its noise-free render and truth.
pub struct Case {
    pub scene: Scene,
    pub cam: Camera,
    pub lights: Vec<PointLight>,
    pub exact: Vec<f64>,
    pub truth: Vec<Segment>,
    /// Every visible edge with some contrast; those of `truth` among them
    /// count as true (support is checked first).
    pub dont_care: Vec<Segment>,
}

fn options(cfg: &EvalConfig, noise: f64, seed: u64, distort: bool) -> RenderOptions {
    RenderOptions {
        blur_sigma: cfg.blur,
        noise_sigma: noise,
        seed,
        distort,
        ..Default::default()
    }
}

/// The scenes of `cfg`, rendered noise-free, with their truth.
pub fn cube_cases(cfg: &EvalConfig) -> Vec<Case> {
    super::test_scenes(cfg.scenes, cfg.size, cfg.size, cfg.seed)
        .into_iter()
        .map(|(scene, cam, lights)| {
            let o = options(cfg, 0.0, 0, false);
            let exact = super::render_exact(&scene, &cam, &lights, &o);
            let truth = super::true_edges(&scene, &cam, &lights, &o, cfg.min_contrast);
            let dont_care = super::true_edges(&scene, &cam, &lights, &o, FAINT);
            Case {
                scene,
                cam,
                lights,
                exact,
                truth,
                dont_care,
            }
        })
        .collect()
}

/// The image of scene `i` at noise σ `noise`, the `j`-th level of the run.
pub fn cube_image(cfg: &EvalConfig, c: &Case, i: usize, j: usize, noise: f64) -> GreyImage {
    let seed = mix(cfg.seed, 1000 + 64 * i as u64 + j as u64);
    super::finish(
        c.exact.clone(),
        c.cam.width,
        c.cam.height,
        &options(cfg, noise, seed, false),
    )
}

/// Runs the evaluation with the given LLV parameters.
pub fn evaluate(cfg: &EvalConfig, params: &Params) -> Result<EvalReport, LlvError> {
    let cases = cube_cases(cfg);
    let mut levels = Vec::new();
    for (j, &noise) in cfg.noise.iter().enumerate() {
        let (mut sub, mut whole) = (Tally::default(), Tally::default());
        let (mut points, mut nlines) = (0usize, 0usize);
        let (mut st_sub, mut st_whole) = (Straightness::default(), Straightness::default());
        for (i, c) in cases.iter().enumerate() {
            let img = cube_image(cfg, c, i, j, noise);
            let out = run_one(&img, None, params)?;
            sub.add_with(&out.lines, &c.truth, &c.dont_care);
            points += out.edges_h.points.len() + out.edges_v.points.len();
            nlines += out.lines.len();
            let wp = whole_pixel_lines(
                &out.edges_h,
                &out.edges_v,
                std::slice::from_ref(&img),
                params,
            )?;
            whole.add_with(&wp, &c.truth, &c.dont_care);
            let ident = |p: Point| p;
            st_sub.add(&c.truth, &out.edges_h, &out.edges_v, &ident);
            let (rh, rv) = (round_points(&out.edges_h), round_points(&out.edges_v));
            st_whole.add(&c.truth, &rh, &rv, &ident);
        }
        let n = cases.len().max(1) as f64;
        levels.push(NoiseResult {
            noise,
            subpixel: sub.metrics(),
            whole_pixel: whole.metrics(),
            point_rms_subpixel: st_sub.rms_to_truth(),
            point_rms_whole_pixel: st_whole.rms_to_truth(),
            edge_points: points as f64 / n,
            lines: nlines as f64 / n,
        });
    }
    let lens = lens_check(cfg, &cases, params)?;
    Ok(EvalReport {
        config: cfg.clone(),
        levels,
        lens,
    })
}

pub(crate) fn run_one(
    img: &GreyImage,
    lens: Option<&LensMap>,
    params: &Params,
) -> Result<pipeline::StageOutputs, LlvError> {
    let images = std::slice::from_ref(img);
    pipeline::run(
        &Input {
            images,
            ambient: None,
            lens,
        },
        params,
    )
}

/// Lines from edge points rounded to whole pixels: what the pipeline would
/// give without the subpixel step (llv.md §2.4). The pipeline's own run
/// from saved edge points ([`pipeline::Workspace::run_saved`]) makes them,
/// so every stage after the edges is the one `pipeline::run` uses.
pub fn whole_pixel_lines(
    h: &EdgePoints,
    v: &EdgePoints,
    images: &[GreyImage],
    params: &Params,
) -> Result<Vec<Segment>, LlvError> {
    let saved = pipeline::Saved::Edges {
        h: round_points(h),
        v: round_points(v),
    };
    let input = Input {
        images,
        ambient: None,
        lens: None,
    };
    let mut ws = pipeline::Workspace::new();
    Ok(ws.run_saved(saved, params, Some(&input))?.lines.clone())
}

/// The edge points with their positions rounded to whole pixels.
pub fn round_points(e: &EdgePoints) -> EdgePoints {
    let mut r = e.clone();
    for p in &mut r.points {
        p.x = p.x.round();
        p.y = p.y.round();
    }
    r
}

/// Length-weighted mean residual of the lines.
pub fn mean_residual(lines: &[Segment]) -> f64 {
    let (mut s, mut w) = (0.0, 0.0);
    for l in lines {
        let len = l.length();
        if len.is_finite() && l.residual.is_finite() {
            s += l.residual * len;
            w += len;
        }
    }
    if w > 0.0 { s / w } else { 0.0 }
}

fn lens_check(cfg: &EvalConfig, cases: &[Case], params: &Params) -> Result<LensResult, LlvError> {
    let (mut plain, mut dist, mut corr) = (Vec::new(), Vec::new(), Vec::new());
    let (mut t_corr, mut t_unc) = (Tally::default(), Tally::default());
    let (mut s_plain, mut s_dist, mut s_corr) = (
        Straightness::default(),
        Straightness::default(),
        Straightness::default(),
    );
    let ident = |p: Point| p;
    for (i, c) in cases.iter().enumerate() {
        let seed = mix(cfg.seed, 9000 + i as u64);
        let (w, h) = (c.cam.width, c.cam.height);
        let mut cam = c.cam.clone();
        if let Some(d) = cam.model.distortion.as_mut() {
            d.iter_mut().for_each(|k| *k *= cfg.lens_scale);
        }
        let undistorted = super::finish(
            c.exact.clone(),
            w,
            h,
            &options(cfg, cfg.lens_noise, seed, false),
        );
        let out = run_one(&undistorted, None, params)?;
        s_plain.add(&c.truth, &out.edges_h, &out.edges_v, &ident);
        plain.extend(out.lines_raw);
        let od = options(cfg, cfg.lens_noise, seed, true);
        let distorted = super::render(&c.scene, &cam, &c.lights, &od);
        let out = run_one(&distorted, None, params)?;
        t_unc.add_with(&out.lines, &c.truth, &c.dont_care);
        let through_lens = |p: Point| {
            let (x, y) = cam.model.ideal_to_observed(p.x, p.y);
            Point::new(x, y)
        };
        s_dist.add(&c.truth, &out.edges_h, &out.edges_v, &through_lens);
        dist.extend(out.lines_raw);
        let map = LensMap::new(&cam.model, w, h);
        let out = run_one(&distorted, Some(&map), params)?;
        t_corr.add_with(&out.lines, &c.truth, &c.dont_care);
        s_corr.add(&c.truth, &out.edges_h, &out.edges_v, &ident);
        corr.extend(out.lines_raw);
    }
    Ok(LensResult {
        residual_undistorted: mean_residual(&plain),
        residual_distorted: mean_residual(&dist),
        residual_corrected: mean_residual(&corr),
        straightness_undistorted: s_plain.rms(),
        straightness_distorted: s_dist.rms(),
        straightness_corrected: s_corr.rms(),
        straightness_edges: s_plain.edges(),
        corrected: t_corr.metrics(),
        uncorrected: t_unc.metrics(),
    })
}
