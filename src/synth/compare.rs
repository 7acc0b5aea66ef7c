//! vss beside other line detectors, on the same images and with the same
//! scorer: `vss selftest --export DIR` writes every scene of both families
//! as PGM with its truth, runs vss on each (timed in-process) and writes its
//! segments; other detectors (`benches/opencv_lines.py`, the ELSED driver)
//! add their own segment and timing files beside them; `vss selftest
//! --score DIR` scores every detector it finds there.
//!
//! Layout of `DIR`:
//! - `manifest.json`: the families, sizes, seeds and noise levels;
//! - `FAMILY/LEVEL/sNN.pgm`: scene NN at that noise (`cubes/s2`, `yard/sd`);
//! - `FAMILY/LEVEL/sNN.truth`: one edge a line, `edge x0 y0 x1 y1 contrast`
//!   or `dontcare …` (ideal px, origin at the top-left pixel's centre);
//! - `FAMILY/LEVEL/sNN.DET.seg`: detector DET's segments, `x0 y0 x1 y1` a
//!   line (`#` starts a comment), in the same coordinates;
//! - `FAMILY/LEVEL/DET.times`: `sNN fastest_ms median_ms runs` a line;
//! - `yard/lens-LEVEL/sNN.pgm`, `.cdf`, `.truth`: the yard scenes through
//!   their lens (at the lens check's noise levels), the `.cdf` that corrects
//!   them and the truth of what they show, for `vss llv --cdf`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::eval::yard::{Level, YardConfig, yard_cases, yard_image, yard_lens_image};
use super::eval::{EvalConfig, cube_cases, cube_image};
use super::score::{Metrics, Shared, Tally, percentile, shared_endpoints};
use super::yard::truth as yard_truth;
use crate::formats::imageio::write_any;
use crate::formats::img::ImgFile;
use crate::formats::{
    FormatError, FormatErrorKind as K, numbered_lines, parse_f64, read_text, write_bytes,
};
use crate::llv::pipeline::{Input, Workspace};
use crate::llv::{GreyImage, LlvError, Params, Point, Segment};

mod files;

pub use files::{mean_times, read_segments, read_times, read_truth, write_segments};

/// The name vss's own files carry.
pub const VSS: &str = "vss";

/// A failure of the export or the scoring.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error(transparent)]
    File(#[from] FormatError),
    #[error("running vss on {path}: {source}")]
    Llv { path: PathBuf, source: LlvError },
}

/// Which families to export.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportConfig {
    pub cubes: Option<EvalConfig>,
    pub yard: Option<YardConfig>,
    /// Timed runs of vss per image (the fastest and the median are kept).
    pub runs: usize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format: u32,
    pub families: Vec<FamilyEntry>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FamilyEntry {
    pub name: String,
    pub size: usize,
    pub scenes: usize,
    pub seed: u64,
    /// Level folders, in order (`s2`, `sd`, …).
    pub levels: Vec<String>,
}

/// Scene file stem: `s00`, `s01`, …
pub fn stem(i: usize) -> String {
    format!("s{i:02}")
}

fn mkdir(p: &Path) -> Result<(), FormatError> {
    std::fs::create_dir_all(p).map_err(|e| FormatError::io(p, "create the folder", &e))
}

fn write_pgm(path: &Path, img: &GreyImage) -> Result<(), FormatError> {
    write_any(path, &ImgFile::new(img.clone()))
}

/// Runs vss `runs` times on `img` with a warm workspace (one warm-up run
/// first): the last run's lines and the fastest and median times (ms).
/// `runs` = 0: one run, timed, and no warm-up.
pub(crate) fn timed_run(
    ws: &mut Workspace,
    img: &GreyImage,
    params: &Params,
    runs: usize,
) -> Result<(Vec<Segment>, f64, f64), LlvError> {
    let input = Input::single(img);
    if runs == 0 {
        let t = Instant::now();
        ws.run(&input, params)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        return Ok((ws.outputs().lines.clone(), ms, ms));
    }
    ws.run(&input, params)?; // warm-up
    let mut times = Vec::with_capacity(runs.max(1));
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        ws.run(&input, params)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let fastest = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok((ws.outputs().lines.clone(), fastest, percentile(&times, 0.5)))
}

/// One level's images with their truth, as the export writes them.
struct Shot {
    image: GreyImage,
    truth: Vec<Segment>,
    dont_care: Vec<Segment>,
}

fn export_level(
    dir: &Path,
    shots: impl Iterator<Item = Shot>,
    params: &Params,
    runs: usize,
) -> Result<(), CompareError> {
    mkdir(dir)?;
    let mut ws = Workspace::new();
    let mut times =
        String::from("# scene fastest_ms median_ms runs (vss, in-process, one thread)\n");
    for (i, s) in shots.enumerate() {
        let base = dir.join(stem(i));
        let pgm = base.with_extension("pgm");
        write_pgm(&pgm, &s.image)?;
        files::write_truth(&base.with_extension("truth"), &s.truth, &s.dont_care)?;
        let (lines, fastest, median) =
            timed_run(&mut ws, &s.image, params, runs.max(1)).map_err(|source| {
                CompareError::Llv {
                    path: pgm.clone(),
                    source,
                }
            })?;
        files::write_segments(&dir.join(format!("{}.{VSS}.seg", stem(i))), &lines)?;
        times.push_str(&format!(
            "{} {fastest:.4} {median:.4} {}\n",
            stem(i),
            runs.max(1)
        ));
    }
    write_bytes(&dir.join(format!("{VSS}.times")), times.as_bytes())?;
    Ok(())
}

/// Writes the scenes, their truth and vss's segments and times under `dir`.
pub fn export(dir: &Path, cfg: &ExportConfig, params: &Params) -> Result<Manifest, CompareError> {
    mkdir(dir)?;
    let mut families = Vec::new();
    if let Some(c) = &cfg.cubes {
        let cases = cube_cases(c);
        let mut levels = Vec::new();
        for (j, &noise) in c.noise.iter().enumerate() {
            let tag = Level::Sigma(noise).tag();
            let shots = cases.iter().enumerate().map(|(i, case)| Shot {
                image: cube_image(c, case, i, j, noise),
                truth: case.truth.clone(),
                dont_care: case.dont_care.clone(),
            });
            export_level(&dir.join("cubes").join(&tag), shots, params, cfg.runs)?;
            levels.push(tag);
        }
        families.push(FamilyEntry {
            name: "cubes".into(),
            size: c.size,
            scenes: c.scenes,
            seed: c.seed,
            levels,
        });
    }
    if let Some(y) = &cfg.yard {
        let cases = yard_cases(y);
        let mut levels = Vec::new();
        for &level in &y.noise {
            let shots = cases.iter().enumerate().map(|(i, case)| Shot {
                image: yard_image(y, case, i, level),
                truth: case.truth.edges.clone(),
                dont_care: case.truth.dont_care.clone(),
            });
            export_level(&dir.join("yard").join(level.tag()), shots, params, cfg.runs)?;
            levels.push(level.tag());
        }
        for &level in &y.lens_noise {
            let lens = dir.join("yard").join(format!("lens-{}", level.tag()));
            mkdir(&lens)?;
            for (i, case) in cases.iter().enumerate() {
                let sc = &case.scene;
                let base = lens.join(stem(i));
                write_pgm(
                    &base.with_extension("pgm"),
                    &yard_lens_image(y, case, i, level),
                )?;
                crate::formats::cdf::write_cdf(&base.with_extension("cdf"), &sc.cdf())?;
                let t = yard_truth(sc, true, y.min_contrast);
                files::write_truth(&base.with_extension("truth"), &t.edges, &t.dont_care)?;
            }
        }
        families.push(FamilyEntry {
            name: "yard".into(),
            size: y.size,
            scenes: y.scenes,
            seed: y.seed,
            levels,
        });
    }
    let manifest = Manifest {
        format: 1,
        families,
    };
    let text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
    write_bytes(&dir.join("manifest.json"), text.as_bytes())?;
    Ok(manifest)
}

/// One detector's scores at one level.
#[derive(Clone, Debug, Serialize)]
pub struct DetectorScore {
    pub detector: String,
    pub metrics: Metrics,
    pub f: f64,
    /// Mean over the scenes of each scene's fastest and median time (ms),
    /// when the detector wrote its times.
    pub fastest_ms: Option<f64>,
    pub median_ms: Option<f64>,
    /// For a detector other than vss: vss's endpoint distance (`first_*`)
    /// and this detector's (`second_*`) on the true edges both support.
    pub shared_with_vss: Option<Shared>,
}

#[derive(Clone, Debug, Serialize)]
pub struct LevelScores {
    pub level: String,
    pub detectors: Vec<DetectorScore>,
}

#[derive(Clone, Debug, Serialize)]
pub struct FamilyScores {
    pub name: String,
    pub size: usize,
    pub scenes: usize,
    pub levels: Vec<LevelScores>,
}

/// Reads `dir/manifest.json`.
pub fn read_manifest(dir: &Path) -> Result<Manifest, FormatError> {
    let path = dir.join("manifest.json");
    let text = read_text(&path)?;
    let m: Manifest = serde_json::from_str(&text).map_err(|e| {
        FormatError::at_line(
            &path,
            e.line(),
            K::Syntax,
            format!("not a vss export manifest ({e}); make one with vss selftest --export DIR"),
        )
    })?;
    if m.format != 1 {
        return Err(FormatError::new(
            &path,
            crate::formats::Location::None,
            K::Unsupported,
            format!("manifest format {} (this vss reads format 1)", m.format),
        ));
    }
    Ok(m)
}

/// The detectors with segment files in a level folder: vss first, then the
/// others by name.
pub(crate) fn detectors(dir: &Path) -> Result<Vec<String>, FormatError> {
    let rd = std::fs::read_dir(dir).map_err(|e| FormatError::io(dir, "list the folder", &e))?;
    let mut names: Vec<String> = Vec::new();
    for entry in rd.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some(rest) = name.strip_suffix(".seg")
            && let Some((_, det)) = rest.split_once('.')
            && !det.is_empty()
            && !names.iter().any(|n| n == det)
        {
            names.push(det.to_string());
        }
    }
    names.sort_by_key(|a| (a != VSS, a.to_lowercase()));
    Ok(names)
}

/// Scores every detector found under `dir` against the truth there.
pub fn score_dir(dir: &Path) -> Result<Vec<FamilyScores>, FormatError> {
    let manifest = read_manifest(dir)?;
    let mut out = Vec::new();
    for fam in &manifest.families {
        let mut levels = Vec::new();
        for tag in &fam.levels {
            let ldir = dir.join(&fam.name).join(tag);
            let truths: Vec<(Vec<Segment>, Vec<Segment>)> = (0..fam.scenes)
                .map(|i| read_truth(&ldir.join(format!("{}.truth", stem(i)))))
                .collect::<Result<_, _>>()?;
            let mut dets = Vec::new();
            let mut tallies = Vec::new();
            for det in detectors(&ldir)? {
                let mut tally = Tally::default();
                for (i, (t, dc)) in truths.iter().enumerate() {
                    let path = ldir.join(format!("{}.{det}.seg", stem(i)));
                    if !path.exists() {
                        return Err(FormatError::new(
                            &path,
                            crate::formats::Location::None,
                            K::Missing,
                            format!(
                                "{det} has segments for some scenes of {}/{tag} but not for {}; run it on every image again",
                                fam.name,
                                stem(i)
                            ),
                        ));
                    }
                    tally.add_with(&read_segments(&path)?, t, dc);
                }
                let (fastest_ms, median_ms) = mean_times(&ldir, &det)?;
                let metrics = tally.metrics();
                dets.push(DetectorScore {
                    detector: det,
                    f: metrics.f_score(),
                    metrics,
                    fastest_ms,
                    median_ms,
                    shared_with_vss: None,
                });
                tallies.push(tally);
            }
            // (`detectors` puts vss first when it is there.)
            if dets.first().is_some_and(|d| d.detector == VSS) {
                for (d, t) in dets.iter_mut().zip(&tallies).skip(1) {
                    d.shared_with_vss = Some(shared_endpoints(&tallies[0], t));
                }
            }
            levels.push(LevelScores {
                level: tag.clone(),
                detectors: dets,
            });
        }
        out.push(FamilyScores {
            name: fam.name.clone(),
            size: fam.size,
            scenes: fam.scenes,
            levels,
        });
    }
    Ok(out)
}

fn parse_point(toks: &[&str], path: &Path, n: usize) -> Result<(Point, Point), FormatError> {
    let v: Vec<f64> = toks
        .iter()
        .map(|t| parse_f64(t, path, n, "a coordinate"))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [a, b, c, d] => Ok((Point::new(*a, *b), Point::new(*c, *d))),
        _ => Err(FormatError::at_line(
            path,
            n,
            K::Syntax,
            format!("expected four numbers x0 y0 x1 y1, found {}", toks.len()),
        )),
    }
}

fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    numbered_lines(text)
        .map(|(n, l)| (n, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty())
}
