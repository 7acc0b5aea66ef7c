//! Real photographs with human-labelled line segments: a folder of
//! `NAME.jpg` (or `.png`, `.pgm`, …) with `NAME_gt.txt` beside each (one
//! segment a line, `x1 y1 x2 y2`), as the York Urban database with Cho et
//! al.'s ground truth comes. Reading them, running vss on them, and scoring
//! any detector's segments by the rule the project is judged by
//! (`../shared/data/README.md`):
//!
//! - every segment is sampled at steps of at most 1 px (the midpoints of
//!   `⌈length⌉` equal intervals, each weighing `length / ⌈length⌉`);
//! - a detected sample is true where some ground-truth segment within
//!   [`ANGLE_DEG`] of the detected segment's direction lies within [`DIST`]
//!   px of it (distance to the segment, ends included);
//! - a ground-truth sample is found where some detected segment within
//!   [`ANGLE_DEG`] lies within [`DIST`] px of it;
//! - recall and precision are lengths summed over all images, F their
//!   harmonic mean.
//!
//! The ground truth puts pixel (0, 0) over `[0, 1]²`; vss puts pixel
//! centres at whole coordinates, so [`read_truth`] subtracts
//! [`TRUTH_SHIFT`] from every coordinate. Detector files (`NAME.DET.seg`)
//! are in vss's convention, as `vss selftest --export` writes them.
//!
//! This rule differs from the synthetic scorer (`score.rs`: 3°, exact
//! intervals, don't-care edges) on purpose: it is the published one, and
//! the figures of other detectors on these photographs are given by it.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::compare::{CompareError, VSS, mean_times, read_segments, timed_run};
use crate::formats::imageio::{ImageKind, read_any_sized};
use crate::formats::{FormatError, FormatErrorKind as K, Location, write_bytes};
use crate::llv::pipeline::Workspace;
use crate::llv::{GreyImage, Params, Point, Segment};

/// Largest distance (px) of a sample from a matching segment.
pub const DIST: f64 = 2.0;
/// Largest direction difference (degrees) of matching segments.
pub const ANGLE_DEG: f64 = 5.0;
/// Subtracted from every ground-truth coordinate (pixel (0, 0) over
/// `[0, 1]²` → pixel centres at whole coordinates).
pub const TRUTH_SHIFT: f64 = 0.5;

/// Sums of lengths over images; [`RealTally::metrics`] pools them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RealTally {
    /// Detected length (px) and the part of it that is true.
    pub detected: f64,
    pub true_detected: f64,
    /// Ground-truth length (px) and the part of it that is found.
    pub truth: f64,
    pub found: f64,
    /// Detected segments in all.
    pub segments: usize,
    pub images: usize,
}

/// Pooled scores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RealMetrics {
    pub precision: f64,
    pub recall: f64,
    pub f: f64,
    pub detected_length: f64,
    pub truth_length: f64,
    pub segments: usize,
    pub images: usize,
}

impl RealTally {
    /// Adds one image's detected segments and ground truth (both with pixel
    /// centres at whole coordinates).
    pub fn add(&mut self, detected: &[Segment], truth: &[Segment]) {
        let (t, d) = covered(detected, truth);
        self.true_detected += t;
        self.detected += d;
        let (f, g) = covered(truth, detected);
        self.found += f;
        self.truth += g;
        self.segments += detected.len();
        self.images += 1;
    }

    pub fn metrics(&self) -> RealMetrics {
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        let precision = ratio(self.true_detected, self.detected);
        let recall = ratio(self.found, self.truth);
        let f = if precision + recall > 0.0 {
            2.0 * precision * recall / (precision + recall)
        } else {
            0.0
        };
        RealMetrics {
            precision,
            recall,
            f,
            detected_length: self.detected,
            truth_length: self.truth,
            segments: self.segments,
            images: self.images,
        }
    }
}

/// Scores one image.
pub fn score_real(detected: &[Segment], truth: &[Segment]) -> RealMetrics {
    let mut t = RealTally::default();
    t.add(detected, truth);
    t.metrics()
}

/// A segment's usable form: ends, direction (radians, mod π) and length.
#[derive(Clone, Copy)]
struct Seg {
    a: Point,
    b: Point,
    theta: f64,
    len: f64,
}

fn usable(s: &Segment) -> Option<Seg> {
    let len = s.length();
    let finite = [s.a.x, s.a.y, s.b.x, s.b.y].iter().all(|v| v.is_finite());
    (finite && len > 0.0 && len.is_finite()).then(|| Seg {
        a: s.a,
        b: s.b,
        theta: (s.b.y - s.a.y).atan2(s.b.x - s.a.x),
        len,
    })
}

fn angle_ok(t0: f64, t1: f64) -> bool {
    let d = (t0 - t1).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d).to_degrees() <= ANGLE_DEG
}

/// Distance from `p` to the segment `a b` (ends included).
fn seg_distance(p: Point, s: &Seg) -> f64 {
    let (ux, uy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let l2 = ux * ux + uy * uy;
    let t = if l2 > 0.0 {
        (((p.x - s.a.x) * ux + (p.y - s.a.y) * uy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.x - s.a.x - t * ux).hypot(p.y - s.a.y - t * uy)
}

/// The matching length of `samples`' segments against `against`, and their
/// whole length: `(matched, total)`.
fn covered(samples: &[Segment], against: &[Segment]) -> (f64, f64) {
    covered_each(samples, against)
        .into_iter()
        .fold((0.0, 0.0), |(m, t), (a, b)| (m + a, t + b))
}

/// [`covered`] per segment of `samples` (unusable ones: `(0, 0)`).
fn covered_each(samples: &[Segment], against: &[Segment]) -> Vec<(f64, f64)> {
    let tgt: Vec<Seg> = against.iter().filter_map(usable).collect();
    let grid = (!tgt.is_empty()).then(|| Grid::new(&tgt));
    samples
        .iter()
        .map(|s| {
            let Some(s) = usable(s) else {
                return (0.0, 0.0);
            };
            let Some(grid) = &grid else {
                return (0.0, s.len);
            };
            let n = s.len.ceil().max(1.0);
            let w = s.len / n;
            let mut matched = 0.0;
            for k in 0..n as usize {
                let t = (k as f64 + 0.5) / n;
                let p = Point::new(s.a.x + (s.b.x - s.a.x) * t, s.a.y + (s.b.y - s.a.y) * t);
                let hit = grid.near(p).iter().any(|&j| {
                    let o = &tgt[j as usize];
                    angle_ok(s.theta, o.theta) && seg_distance(p, o) <= DIST
                });
                if hit {
                    matched += w;
                }
            }
            (matched, s.len)
        })
        .collect()
}

/// Upper bounds (grey levels) of the contrast classes of
/// [`ByContrast`]: below 10, 10–20, 20–40, 40 and more.
pub const CONTRAST_BOUNDS: [f64; 3] = [10.0, 20.0, 40.0];

/// How far to either side of a true line its contrast is read (px).
pub const CONTRAST_REACH: f64 = 2.0;

/// A true line's contrast in `img`: the median over its samples (1 px
/// apart) of the difference of the grey levels [`CONTRAST_REACH`] px to
/// either side (nearest pixel). `None` when no sample has both sides inside.
pub fn contrast(img: &GreyImage, s: &Segment) -> Option<f64> {
    let s = usable(s)?;
    let (nx, ny) = (-(s.b.y - s.a.y) / s.len, (s.b.x - s.a.x) / s.len);
    let at = |x, y| nearest(img, x, y);
    let n = s.len.ceil().max(1.0);
    let mut d: Vec<f64> = (0..n as usize)
        .filter_map(|k| {
            let t = (k as f64 + 0.5) / n;
            let (x, y) = (s.a.x + (s.b.x - s.a.x) * t, s.a.y + (s.b.y - s.a.y) * t);
            let r = CONTRAST_REACH;
            Some((at(x + r * nx, y + r * ny)? - at(x - r * nx, y - r * ny)?).abs())
        })
        .collect();
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    Some(*d.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// The grey level of the pixel nearest `(x, y)`; `None` outside `img`.
fn nearest(img: &GreyImage, x: f64, y: f64) -> Option<f64> {
    let (x, y) = (x.round(), y.round());
    (x >= 0.0 && y >= 0.0)
        .then(|| img.get(x as usize, y as usize))
        .flatten()
        .map(f64::from)
}

/// Upper bounds (grey levels a pixel) of the edge-slope classes of
/// [`ByContrast::unmatched`]: below 2, 2–3, 3–5, 5 and more.
pub const SLOPE_BOUNDS: [f64; 3] = [2.0, FLAT_SLOPE, 5.0];

/// Below this edge slope (grey levels a pixel) a segment lies on flat
/// structure.
pub const FLAT_SLOPE: f64 = 3.0;

/// A segment's edge slope in `img`: the image's profile across it (nearest
/// pixels 1 px apart, 3 px to either side, one profile a pixel along it)
/// averaged along it, and its steepest 1-px step within 2 px of the line.
/// Averaging along the segment cancels noise and texture, which a line
/// through them does not follow. `None` when no profile lies inside.
pub fn edge_slope(img: &GreyImage, s: &Segment) -> Option<f64> {
    const R: usize = 3;
    let s = usable(s)?;
    let (nx, ny) = (-(s.b.y - s.a.y) / s.len, (s.b.x - s.a.x) / s.len);
    let mut sum = [0.0; 2 * R + 1];
    let mut count = 0usize;
    let n = s.len.ceil().max(1.0);
    let mut p = [0.0; 2 * R + 1];
    'sample: for k in 0..n as usize {
        let t = (k as f64 + 0.5) / n;
        let (x, y) = (s.a.x + (s.b.x - s.a.x) * t, s.a.y + (s.b.y - s.a.y) * t);
        for (j, v) in p.iter_mut().enumerate() {
            let o = j as f64 - R as f64;
            match nearest(img, x + o * nx, y + o * ny) {
                Some(g) => *v = g,
                None => continue 'sample,
            }
        }
        for (a, v) in sum.iter_mut().zip(&p) {
            *a += v;
        }
        count += 1;
    }
    (count > 0).then(|| {
        (1..2 * R - 1)
            .map(|j| (sum[j + 1] - sum[j]).abs())
            .fold(0.0, f64::max)
            / count as f64
    })
}

/// The class of a contrast: the index of the first bound above it.
fn contrast_class(c: f64) -> usize {
    CONTRAST_BOUNDS.iter().take_while(|&&b| c >= b).count()
}

/// Recall by the true lines' contrast, and the detected length that
/// matches no true line by the detected segment's edge slope (lengths
/// pooled over photographs). The second measures false lines on flat
/// structure: where the image's mean profile across a segment is nowhere
/// steeper than [`FLAT_SLOPE`] grey levels a pixel, the segment lies on a
/// faint cloud, faint print or shading, not on an outline a person would
/// draw. (Contrast alone cannot say so: a thin wire against the sky has
/// the same grey level on both sides. York Urban's labels leave out many
/// steep edges too, which is why only the flat class is read as false.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ByContrast {
    /// True length per class, and the part of it found.
    pub truth: [f64; 4],
    pub found: [f64; 4],
    /// Detected length matching no true line, per class of the detected
    /// segment's edge slope ([`SLOPE_BOUNDS`]).
    pub unmatched: [f64; 4],
    /// Photographs added.
    pub photos: usize,
}

impl ByContrast {
    /// Adds one photograph: its true lines with their classes (`None`: no
    /// contrast could be read) and a detector's segments.
    pub fn add(
        &mut self,
        img: &GreyImage,
        truth: &[Segment],
        classes: &[Option<usize>],
        detected: &[Segment],
    ) {
        for ((f, t), c) in covered_each(truth, detected).into_iter().zip(classes) {
            if let Some(c) = *c {
                self.found[c] += f;
                self.truth[c] += t;
            }
        }
        for ((m, t), s) in covered_each(detected, truth).into_iter().zip(detected) {
            if let Some(c) = edge_slope(img, s) {
                self.unmatched[SLOPE_BOUNDS.iter().take_while(|&&b| c >= b).count()] +=
                    (t - m).max(0.0);
            }
        }
        self.photos += 1;
    }

    /// Recall per class (`None` for a class without true lines).
    pub fn recall(&self) -> [Option<f64>; 4] {
        std::array::from_fn(|i| (self.truth[i] > 0.0).then(|| self.found[i] / self.truth[i]))
    }

    /// Unmatched detected length per photograph (px), per class.
    pub fn unmatched_per_photo(&self) -> [f64; 4] {
        let n = self.photos.max(1) as f64;
        self.unmatched.map(|u| u / n)
    }
}

/// Square cells, each listing the segments that come within [`DIST`] of
/// some point of it: a sample asks only its own cell.
struct Grid {
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    lists: Vec<Vec<u32>>,
}

impl Grid {
    fn new(segs: &[Seg]) -> Grid {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for s in segs {
            for p in [s.a, s.b] {
                x0 = x0.min(p.x);
                y0 = y0.min(p.y);
                x1 = x1.max(p.x);
                y1 = y1.max(p.y);
            }
        }
        let (x0, y0) = (x0 - DIST - 1.0, y0 - DIST - 1.0);
        let extent = (x1 - x0 + DIST + 1.0).max(y1 - y0 + DIST + 1.0);
        // At most 512 cells a side, whatever the coordinates.
        let cell = (extent / 512.0).max(4.0);
        let nx = ((x1 + DIST + 1.0 - x0) / cell).ceil() as usize + 1;
        let ny = ((y1 + DIST + 1.0 - y0) / cell).ceil() as usize + 1;
        let mut lists = vec![Vec::new(); nx * ny];
        let reach = DIST + cell * std::f64::consts::FRAC_1_SQRT_2;
        for (j, s) in segs.iter().enumerate() {
            let cx = |x: f64| (((x - x0) / cell).floor().max(0.0) as usize).min(nx - 1);
            let cy = |y: f64| (((y - y0) / cell).floor().max(0.0) as usize).min(ny - 1);
            let (lx, hx) = (cx(s.a.x.min(s.b.x) - DIST), cx(s.a.x.max(s.b.x) + DIST));
            let (ly, hy) = (cy(s.a.y.min(s.b.y) - DIST), cy(s.a.y.max(s.b.y) + DIST));
            for gy in ly..=hy {
                for gx in lx..=hx {
                    let c =
                        Point::new(x0 + (gx as f64 + 0.5) * cell, y0 + (gy as f64 + 0.5) * cell);
                    if seg_distance(c, s) <= reach {
                        lists[gy * nx + gx].push(j as u32);
                    }
                }
            }
        }
        Grid {
            x0,
            y0,
            cell,
            nx,
            ny,
            lists,
        }
    }

    fn near(&self, p: Point) -> &[u32] {
        let gx = (p.x - self.x0) / self.cell;
        let gy = (p.y - self.y0) / self.cell;
        if !(gx >= 0.0 && gy >= 0.0) {
            return &[];
        }
        let (gx, gy) = (gx as usize, gy as usize);
        if gx >= self.nx || gy >= self.ny {
            return &[];
        }
        &self.lists[gy * self.nx + gx]
    }
}

/// One photograph of a folder: its name (the file stem), image and truth.
#[derive(Clone, Debug, PartialEq)]
pub struct Photo {
    pub name: String,
    pub image: PathBuf,
    pub truth: PathBuf,
}

/// The photographs of `dir` that have a `NAME_gt.txt` beside them, by
/// name. A folder without any is an error (a test must not pass on none).
pub fn photographs(dir: &Path) -> Result<Vec<Photo>, FormatError> {
    let rd = std::fs::read_dir(dir).map_err(|e| FormatError::io(dir, "list the folder", &e))?;
    let mut out = Vec::new();
    for entry in rd.flatten() {
        let path = entry.path();
        let Some(kind) = ImageKind::of(&path) else {
            continue;
        };
        if kind == ImageKind::Img {
            continue;
        }
        let Some(name) = path.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        let truth = dir.join(format!("{name}_gt.txt"));
        if truth.is_file() {
            out.push(Photo {
                name: name.to_string(),
                image: path.clone(),
                truth,
            });
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    if out.is_empty() {
        return Err(FormatError::new(
            dir,
            Location::None,
            K::Missing,
            "no photographs with a NAME_gt.txt beside them",
        ));
    }
    Ok(out)
}

/// A ground-truth file, shifted to pixel centres at whole coordinates.
pub fn read_truth(path: &Path) -> Result<Vec<Segment>, FormatError> {
    let mut v = read_segments(path)?;
    for s in &mut v {
        for p in [&mut s.a, &mut s.b] {
            p.x -= TRUTH_SHIFT;
            p.y -= TRUTH_SHIFT;
        }
    }
    Ok(v)
}

/// A photograph as a grey image, refused from its header when the LLV
/// stage could not take it.
pub fn read_photo(path: &Path) -> Result<GreyImage, FormatError> {
    read_any_sized(path, crate::llv::image::check_stage_size).map(|(f, _)| f.image)
}

/// What [`evaluate_real`] measures: the pooled metrics, each
/// photograph's own (by name), and recall by contrast.
pub type RealEvaluation = (RealMetrics, Vec<(String, RealMetrics)>, ByContrast);

/// Runs vss on every photograph of `dir` and scores it.
pub fn evaluate_real(dir: &Path, params: &Params) -> Result<RealEvaluation, CompareError> {
    let mut ws = Workspace::new();
    let mut tally = RealTally::default();
    let mut by_contrast = ByContrast::default();
    let mut each = Vec::new();
    for p in photographs(dir)? {
        let img = read_photo(&p.image)?;
        let truth = read_truth(&p.truth)?;
        let (lines, _, _) =
            timed_run(&mut ws, &img, params, 0).map_err(|source| CompareError::Llv {
                path: p.image.clone(),
                source,
            })?;
        let mut one = RealTally::default();
        one.add(&lines, &truth);
        tally.add(&lines, &truth);
        let classes: Vec<Option<usize>> = truth
            .iter()
            .map(|s| contrast(&img, s).map(contrast_class))
            .collect();
        by_contrast.add(&img, &truth, &classes, &lines);
        each.push((p.name, one.metrics()));
    }
    Ok((tally.metrics(), each, by_contrast))
}

/// Runs vss on every photograph of `photos` (timed in-process, `runs`
/// runs after a warm-up) and writes `NAME.vss.seg` and `vss.times` in
/// `out` for [`score_dir`] (and `benches/opencv_lines.py real`).
pub fn export_real(
    photos: &Path,
    out: &Path,
    params: &Params,
    runs: usize,
) -> Result<usize, CompareError> {
    std::fs::create_dir_all(out).map_err(|e| FormatError::io(out, "create the folder", &e))?;
    let mut ws = Workspace::new();
    let mut times = String::from(
        "# photo fastest_ms median_ms runs (vss, in-process, one thread); lens edges lines connect ms of the last run\n",
    );
    let list = photographs(photos)?;
    for p in &list {
        let img = read_photo(&p.image)?;
        let (lines, fastest, median) =
            timed_run(&mut ws, &img, params, runs.max(1)).map_err(|source| CompareError::Llv {
                path: p.image.clone(),
                source,
            })?;
        super::compare::write_segments(&out.join(format!("{}.{VSS}.seg", p.name)), &lines)?;
        let t = &ws.outputs().timings;
        let ms = |us: u64| us as f64 / 1e3;
        times.push_str(&format!(
            "{} {fastest:.4} {median:.4} {} {:.3} {:.3} {:.3} {:.3}\n",
            p.name,
            runs.max(1),
            ms(t.lens_us),
            ms(t.edges_us),
            ms(t.lines_us),
            ms(t.connect_us)
        ));
    }
    write_bytes(&out.join(format!("{VSS}.times")), times.as_bytes())?;
    Ok(list.len())
}

/// One detector's scores on a folder of photographs.
#[derive(Clone, Debug, Serialize)]
pub struct RealScore {
    pub detector: String,
    pub metrics: RealMetrics,
    /// Mean over the photographs of each one's fastest and median time
    /// (ms), when the detector wrote its times.
    pub fastest_ms: Option<f64>,
    pub median_ms: Option<f64>,
    /// Recall and unmatched length by contrast in the photograph.
    pub by_contrast: ByContrast,
}

/// Scores every detector with segment files `NAME.DET.seg` in `segs` for
/// the photographs of `photos` (vss first, then by name). A detector
/// missing some photograph is an error.
pub fn score_dir(photos: &Path, segs: &Path) -> Result<Vec<RealScore>, FormatError> {
    let list = photographs(photos)?;
    let truths: Vec<Vec<Segment>> = list
        .iter()
        .map(|p| read_truth(&p.truth))
        .collect::<Result<_, _>>()?;
    // The photographs, and each true line's contrast class, read once.
    let imgs: Vec<GreyImage> = list
        .iter()
        .map(|p| read_photo(&p.image))
        .collect::<Result<_, _>>()?;
    let classes: Vec<Vec<Option<usize>>> = imgs
        .iter()
        .zip(&truths)
        .map(|(img, t)| {
            t.iter()
                .map(|s| contrast(img, s).map(contrast_class))
                .collect()
        })
        .collect();
    let mut out = Vec::new();
    for det in super::compare::detectors(segs)? {
        let mut tally = RealTally::default();
        let mut by_contrast = ByContrast::default();
        for (((p, t), c), img) in list.iter().zip(&truths).zip(&classes).zip(&imgs) {
            let path = segs.join(format!("{}.{det}.seg", p.name));
            if !path.exists() {
                return Err(FormatError::new(
                    &path,
                    Location::None,
                    K::Missing,
                    format!(
                        "{det} has segments for some photographs but not for {}; run it on every one again",
                        p.name
                    ),
                ));
            }
            let detected = read_segments(&path)?;
            tally.add(&detected, t);
            by_contrast.add(img, t, c, &detected);
        }
        let (fastest_ms, median_ms) = mean_times(segs, &det)?;
        out.push(RealScore {
            detector: det,
            metrics: tally.metrics(),
            fastest_ms,
            median_ms,
            by_contrast,
        });
    }
    Ok(out)
}

/// The scores as a table.
pub fn table(scores: &[RealScore], images: usize) -> String {
    use std::fmt::Write as _;
    let mut s = format!(
        "real photographs ({images}; 2 px, {ANGLE_DEG}°, length-based)\n{:<10} {:>9} {:>7} {:>7} {:>9} {:>11} {:>10}\n",
        "detector", "precision", "recall", "F", "segments", "fastest ms", "median ms"
    );
    let ms = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
    for d in scores {
        let m = &d.metrics;
        let _ = writeln!(
            s,
            "{:<10} {:>9.3} {:>7.3} {:>7.3} {:>9} {:>11} {:>10}",
            d.detector,
            m.precision,
            m.recall,
            m.f,
            m.segments,
            ms(d.fastest_ms),
            ms(d.median_ms)
        );
    }
    let _ = writeln!(
        s,
        "recall by the true line's contrast (grey levels 2 px to either side; share of true length)"
    );
    if let Some(d) = scores.first() {
        let all: f64 = d.by_contrast.truth.iter().sum();
        let share = d
            .by_contrast
            .truth
            .map(|t| if all > 0.0 { t / all } else { 0.0 });
        let _ = writeln!(
            s,
            "{:<10} {:>9} {:>9} {:>9} {:>9}\n{:<10} {:>9.2} {:>9.2} {:>9.2} {:>9.2}",
            "contrast",
            "< 10",
            "10-20",
            "20-40",
            ">= 40",
            "share",
            share[0],
            share[1],
            share[2],
            share[3]
        );
    }
    for d in scores {
        let r = d
            .by_contrast
            .recall()
            .map(|r| r.map_or("-".to_string(), |r| format!("{r:.3}")));
        let _ = writeln!(
            s,
            "{:<10} {:>9} {:>9} {:>9} {:>9}",
            d.detector, r[0], r[1], r[2], r[3]
        );
    }
    let _ = writeln!(
        s,
        "detected length matching no true line, by the segment's edge slope (px per photograph; grey levels a pixel; < 3: false lines on flat structure)"
    );
    let _ = writeln!(
        s,
        "{:<10} {:>9} {:>9} {:>9} {:>9}",
        "slope", "< 2", "2-3", "3-5", ">= 5"
    );
    for d in scores {
        let u = d.by_contrast.unmatched_per_photo();
        let _ = writeln!(
            s,
            "{:<10} {:>9.0} {:>9.0} {:>9.0} {:>9.0}",
            d.detector, u[0], u[1], u[2], u[3]
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(x0: f64, y0: f64, x1: f64, y1: f64) -> Segment {
        Segment::new(Point::new(x0, y0), Point::new(x1, y1))
    }

    #[test]
    fn contrast_is_the_step_across_the_line() {
        // Columns below 20 are 50, from 20 on 80: a vertical step of 30 at
        // x = 19.5, and a line along it.
        let px = (0..40 * 30)
            .map(|i| if i % 40 < 20 { 50 } else { 80 })
            .collect();
        let img = GreyImage::new(40, 30, px).unwrap();
        let c = contrast(&img, &seg(19.5, 2.0, 19.5, 27.0)).unwrap();
        assert_eq!(c, 30.0);
        assert_eq!(contrast_class(c), 2);
        // Along a flat area: none.
        assert_eq!(contrast(&img, &seg(5.0, 2.0, 5.0, 27.0)), Some(0.0));
        assert_eq!(contrast_class(9.9), 0);
        assert_eq!(contrast_class(40.0), 3);
        // Off the image: no contrast to read.
        assert_eq!(contrast(&img, &seg(100.0, 2.0, 100.0, 27.0)), None);
    }

    #[test]
    fn rule_by_hand() {
        // A true edge of 10 px; a detection along its first 5 px, 1.5 px
        // off and 3° turned: all of it true, and the edge found up to
        // about x = 6 (within 2 px of the detection's end, ends included).
        let truth = [seg(0.0, 0.0, 10.0, 0.0)];
        let t = 3f64.to_radians();
        let det = [seg(0.0, 1.5, 5.0 * t.cos(), 1.5 + 5.0 * t.sin())];
        let m = score_real(&det, &truth);
        assert!((m.precision - 1.0).abs() < 1e-9, "{m:?}");
        assert!((m.recall - 0.6).abs() < 0.011, "{m:?}");
        // 6° off: nothing matches; 2.5 px off: nothing.
        let t = 6f64.to_radians();
        let det = [seg(0.0, 0.0, 5.0 * t.cos(), 5.0 * t.sin())];
        assert_eq!(score_real(&det, &truth).precision, 0.0);
        let det = [seg(0.0, 2.5, 10.0, 2.5)];
        assert_eq!(score_real(&det, &truth).recall, 0.0);
        // Beyond the end, within 2 px of it (ends included): true.
        let det = [seg(11.0, 0.0, 11.9, 0.0)];
        assert!((score_real(&det, &truth).precision - 1.0).abs() < 1e-9);
        let det = [seg(12.5, 0.0, 13.5, 0.0)];
        assert_eq!(score_real(&det, &truth).precision, 0.0);
    }

    #[test]
    fn grid_agrees_with_every_pair() {
        // Random segments: the grid's answer is the brute-force one.
        let mut r = crate::llv::rng::SplitMix64::new(7);
        let mut mk = |n: usize| -> Vec<Segment> {
            (0..n)
                .map(|_| {
                    let (x, y) = (r.uniform() * 200.0, r.uniform() * 150.0);
                    let a = r.uniform() * std::f64::consts::PI;
                    let l = 1.0 + r.uniform() * 80.0;
                    seg(x, y, x + l * a.cos(), y + l * a.sin())
                })
                .collect()
        };
        let (d, t) = (mk(150), mk(150));
        let (m, total) = covered(&d, &t);
        let tgt: Vec<Seg> = t.iter().filter_map(usable).collect();
        let (mut bm, mut bt) = (0.0, 0.0);
        for s in d.iter().filter_map(usable) {
            let n = s.len.ceil();
            for k in 0..n as usize {
                let u = (k as f64 + 0.5) / n;
                let p = Point::new(s.a.x + (s.b.x - s.a.x) * u, s.a.y + (s.b.y - s.a.y) * u);
                if tgt
                    .iter()
                    .any(|o| angle_ok(s.theta, o.theta) && seg_distance(p, o) <= DIST)
                {
                    bm += s.len / n;
                }
                bt += s.len / n;
            }
        }
        assert!(m > 0.0);
        assert!(
            (m - bm).abs() < 1e-9 && (total - bt).abs() < 1e-9,
            "{m} {bm}"
        );
    }
}
