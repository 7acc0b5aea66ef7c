//! The LLV pipeline: lens correction → edges (both scan directions) → line
//! extraction → CONNECT (→ corner closing), with the time of each stage and
//! every intermediate result, so the console can show any stage and re-run
//! only what a parameter change affects.
//!
//! One image runs plain llv.md §2; several images of one view (or one image
//! with an ambient image) go through the photometric combination of §2.6.
//! A [`Workspace`] keeps every buffer between runs: once warmed up on one
//! image size, further runs do not grow the heap.

use std::time::Instant;

use serde::Serialize;

use super::connect::{ConnectScratch, connect_into};
use super::corners::{CornerScratch, close_corners_with};
use super::edges::{
    NoiseMap, PeakMap, PeakScratch, Response, ResponseScratch, Starts, detect_into,
    detect_unmapped_into, response_into,
};
use super::image::GreyImage;
use super::lens::{LensMap, correct_into};
use super::lines::{LineScratch, extract_into, track_into};
use super::params::{Params, Stage};
use super::photometric::{PhotoScratch, combined_response_into};
use super::refine::{RefineScratch, drop_ghosts, refine_into};
use super::{EdgePoints, LlvError, ScanDir, Segment};

mod draw;
mod lean;
mod noise;

pub use noise::noise_level;

/// Wall-clock time of each stage, in microseconds: the time its outputs
/// took to make (a stage a [`rerun`] did not repeat keeps the time of the
/// run that made it), so that a re-run's panel, manifest and report show no
/// stage as taking no time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Timings {
    pub lens_us: u64,
    pub edges_us: u64,
    pub lines_us: u64,
    pub connect_us: u64,
}

/// Everything one run produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageOutputs {
    /// The lens-corrected images, one per lighting, in input order. Empty
    /// when no correction was applied (no map, an identity map, or
    /// `lens.enabled = false`): the inputs were used as they are, uncopied.
    pub corrected: Vec<GreyImage>,
    pub response_h: Response,
    pub response_v: Response,
    /// The noise scale of each response, per tile (`edges/noise.rs`).
    pub noise_h: NoiseMap,
    pub noise_v: NoiseMap,
    pub edges_h: EdgePoints,
    pub edges_v: EdgePoints,
    /// Extracted lines: those of `edges_h` first, then those of `edges_v`.
    pub lines_raw: Vec<Segment>,
    /// After CONNECT (and corner closing), longest first.
    pub lines: Vec<Segment>,
    pub timings: Timings,
    /// The parameters these outputs were computed with.
    pub params: Params,
}

/// The input of one run: the images of one view (one per lighting, same
/// size), an optional ambient-light image, an optional lens map.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a> {
    pub images: &'a [GreyImage],
    pub ambient: Option<&'a GreyImage>,
    pub lens: Option<&'a LensMap>,
}

impl<'a> Input<'a> {
    /// One image, no ambient, no lens correction.
    pub fn single(image: &'a GreyImage) -> Self {
        Input {
            images: std::slice::from_ref(image),
            ambient: None,
            lens: None,
        }
    }
}

/// A saved stage result to run the later stages from ([`Workspace::run_saved`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Saved {
    /// Edge points of both scan directions: line extraction and CONNECT run.
    Edges { h: EdgePoints, v: EdgePoints },
    /// Extracted lines (a `.lex`): CONNECT runs.
    Lines(Vec<Segment>),
}

/// Reusable buffers for the whole pipeline, and the outputs of the last run.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    out: StageOutputs,
    ambient_corrected: GreyImage,
    /// Each scan direction's buffers.
    dir_h: DirScratch,
    dir_v: DirScratch,
    /// Line extraction from edge points alone.
    lines: LineScratch,
    connect: ConnectScratch,
    tmp: Vec<Segment>,
    corners: CornerScratch,
    refine: RefineScratch,
    align: super::lines::align::AlignScratch,
    draw: super::lines::draw::DrawScratch,
    /// Whether the last run's image was noisy (`edges.noisy_sigma`).
    noisy: bool,
    /// The rows [`noise_level`] reads the image's noise from.
    noise_rows: Vec<i16>,
    /// Whether `out` holds the results of a complete run.
    valid: bool,
    /// Free each direction's buffers after its lines ([`Workspace::lean`]).
    lean: bool,
    /// Edge points a scan direction may find ([`Workspace::limit_edge_points`]).
    edge_limit: Option<usize>,
}

impl Workspace {
    pub fn new() -> Self {
        Workspace::default()
    }

    /// For runs whose responses nobody reads (`vss llv`): the directions
    /// run in turn, each freeing its response and buffers after its lines,
    /// so one direction's are held at a time. Same results; a rerun runs all.
    pub fn lean() -> Self {
        Workspace {
            lean: true,
            ..Workspace::default()
        }
    }

    /// Stops a run whose scan direction finds more than `max` edge points,
    /// as soon as it has them ([`LlvError::TooManyEdgePoints`]): for runs
    /// that must write them to edge files, which cannot hold more, so the
    /// lines, CONNECT and the memory they take are not spent for nothing.
    pub fn limit_edge_points(mut self, max: usize) -> Self {
        self.edge_limit = Some(max);
        self
    }

    /// A workspace whose "previous run" is `prev` (for [`rerun`]).
    pub fn with_outputs(prev: StageOutputs) -> Self {
        Workspace {
            out: prev,
            valid: true,
            ..Workspace::default()
        }
    }

    /// The outputs of the last run.
    pub fn outputs(&self) -> &StageOutputs {
        &self.out
    }

    /// Moves the outputs out (the workspace's output buffers start empty again).
    pub fn take_outputs(&mut self) -> StageOutputs {
        self.valid = false;
        std::mem::take(&mut self.out)
    }

    /// Runs every stage.
    pub fn run(&mut self, input: &Input, p: &Params) -> Result<&StageOutputs, LlvError> {
        self.run_from(Stage::Lens, input, p)
    }

    /// Re-runs `from` and the stages after it, reusing the earlier stages of
    /// the last run (a full run if there is none, or it does not fit `input`).
    pub fn rerun(
        &mut self,
        from: Stage,
        input: &Input,
        p: &Params,
    ) -> Result<&StageOutputs, LlvError> {
        self.run_from(from, input, p)
    }

    fn run_from(
        &mut self,
        from: Stage,
        input: &Input,
        p: &Params,
    ) -> Result<&StageOutputs, LlvError> {
        let size = check_input(input)?;
        // The responses of a lens-corrected run with an ambient image are made
        // from the corrected ambient, which a workspace built from earlier
        // outputs alone (`with_outputs`) does not have: it corrects again.
        let ambient_ready = input.ambient.is_none()
            || self.out.corrected.is_empty()
            || self.ambient_corrected.size() == size;
        let prev_fits = self.valid
            && ambient_ready
            && self.out.edges_h.width == size.0
            && self.out.edges_h.height == size.1
            && self.out.response_h.covers(size.0, size.1);
        let from = if prev_fits { from } else { Stage::Lens };
        let prev_params = std::mem::replace(&mut self.out.params, p.clone());
        self.valid = false;
        // A stage this run does not repeat keeps the time of the run that
        // made its outputs.
        let t = &mut self.out.timings;
        for (stage, us) in [
            (Stage::Lens, &mut t.lens_us),
            (Stage::Edges, &mut t.edges_us),
            (Stage::Lines, &mut t.lines_us),
            (Stage::Connect, &mut t.connect_us),
        ] {
            if from <= stage {
                *us = 0;
            }
        }

        if from <= Stage::Lens {
            let t = Instant::now();
            self.lens(input, p)?;
            self.out.timings.lens_us = micros(t);
        }
        // The kernel's half-width for this image: one more where the image
        // is noisy (`edges.noisy_sigma`, `noise_level`), where also no line
        // under `connect.min_line_length` stays; and no orientation test of
        // the lines where it is twice as noisy (`lines/align.rs`).
        let widened;
        let p = {
            let first = if self.out.corrected.is_empty() {
                input.images.first()
            } else {
                self.out.corrected.first()
            };
            let sigma = match first {
                Some(img) if p.edges.noisy_sigma > 0.0 => {
                    noise::noise_level_with(img, &mut self.noise_rows)
                }
                _ => 0.0,
            };
            self.noisy = p.edges.noisy_sigma > 0.0 && sigma >= p.edges.noisy_sigma;
            if self.noisy {
                widened = {
                    let mut q = p.clone();
                    q.edges.half_width = (q.edges.half_width + 1).min(7);
                    // A short line's scatter, from a dozen points, says
                    // little of its direction where many noise tracks
                    // pass it by chance (`connect::long_enough`).
                    q.connect.short_line_deg = 0.0;
                    // At twice that noise the Sobel direction of a faint
                    // edge is unreliable (docs/accuracy.md): the measured
                    // noise alone guards there.
                    if sigma >= 2.0 * p.edges.noisy_sigma {
                        q.lines.min_aligned = 0.0;
                    }
                    q
                };
                &widened
            } else {
                p
            }
        };
        if from <= Stage::Lines {
            let same_response =
                from >= Stage::Edges && prev_params.edges.half_width == p.edges.half_width;
            let job = Job {
                from,
                response: !same_response,
                params: p,
                lean: self.lean && !p.lines.draw,
                edge_limit: self.edge_limit,
            };
            let parallel = p.edges.threads >= 2 && !self.lean;
            let StageOutputs {
                corrected,
                response_h,
                response_v,
                noise_h,
                noise_v,
                edges_h,
                edges_v,
                lines_raw,
                timings,
                ..
            } = &mut self.out;
            let lensed = !corrected.is_empty();
            let images: &[GreyImage] = if lensed { corrected } else { input.images };
            let ambient = if lensed {
                input.ambient.map(|_| &self.ambient_corrected)
            } else {
                input.ambient
            };
            let h = DirOut {
                dir: ScanDir::Horizontal,
                response: response_h,
                noise: noise_h,
                edges: edges_h,
                s: &mut self.dir_h,
            };
            let v = DirOut {
                dir: ScanDir::Vertical,
                response: response_v,
                noise: noise_v,
                edges: edges_v,
                s: &mut self.dir_v,
            };
            let (th, tv) = if parallel {
                std::thread::scope(|sc| {
                    let other = sc.spawn(|| job.run(images, ambient, v));
                    let here = job.run(images, ambient, h);
                    let there = other
                        .join()
                        .unwrap_or_else(|e| std::panic::resume_unwind(e));
                    Ok::<_, LlvError>((here?, there?))
                })?
            } else {
                (job.run(images, ambient, h)?, job.run(images, ambient, v)?)
            };
            // With two threads a stage takes as long as its slower direction.
            let both = |a: u64, b: u64| if parallel { a.max(b) } else { a + b };
            if from <= Stage::Edges {
                timings.edges_us = both(th.0, tv.0);
            }
            timings.lines_us = both(th.1, tv.1);
            lines_raw.clear();
            lines_raw.extend_from_slice(&self.dir_h.segs);
            lines_raw.extend_from_slice(&self.dir_v.segs);
        }
        if from <= Stage::Lines && p.lines.draw {
            self.draw_lines(p);
        }
        self.connect_on(input, p);
        self.valid = true;
        Ok(&self.out)
    }

    /// Runs the stages after a saved result (`vss llv --from-edges`, `vss
    /// session redo --from connect`, and `--from lines` for an image without
    /// frames): line extraction and CONNECT from edge points, or CONNECT
    /// alone from extracted lines. The lines are refitted on `images`' images
    /// (lens-corrected as a run of them would be) when they are given, and
    /// not at all without them. The outputs have no responses (nor edge
    /// points, from lines), so a later [`Workspace::rerun`] runs every stage.
    pub fn run_saved(
        &mut self,
        saved: Saved,
        p: &Params,
        images: Option<&Input>,
    ) -> Result<&StageOutputs, LlvError> {
        if let Some(input) = images {
            check_input(input)?;
        }
        self.valid = false;
        self.out.corrected.clear();
        self.out.response_h = Response::default();
        self.out.response_v = Response::default();
        self.out.noise_h = NoiseMap::default();
        self.out.noise_v = NoiseMap::default();
        self.out.params = p.clone();
        self.out.timings = Timings::default();
        match saved {
            Saved::Edges { h, v } => {
                self.out.edges_h = h;
                self.out.edges_v = v;
                self.extract_lines(p);
            }
            Saved::Lines(raw) => {
                self.out.edges_h = EdgePoints::default();
                self.out.edges_v = EdgePoints::default();
                self.out.lines_raw = raw;
            }
        }
        let Some(input) = images else {
            self.connect_lines(p, &[]);
            return Ok(&self.out);
        };
        let t = Instant::now();
        self.lens(input, p)?;
        let lens_us = micros(t);
        self.connect_on(input, p);
        self.out.timings.lens_us = lens_us;
        Ok(&self.out)
    }

    /// Line extraction from edge points alone.
    fn extract_lines(&mut self, p: &Params) {
        let t = Instant::now();
        extract_into(
            &self.out.edges_h,
            &p.lines,
            &mut self.out.lines_raw,
            &mut self.lines,
        );
        extract_into(&self.out.edges_v, &p.lines, &mut self.tmp, &mut self.lines);
        self.out.lines_raw.extend_from_slice(&self.tmp);
        self.out.timings.lines_us = micros(t);
    }

    /// [`Workspace::connect_lines`] with the refit on the images the lines
    /// were found on: the lens-corrected ones, or `input`'s.
    fn connect_on(&mut self, input: &Input, p: &Params) {
        let corrected = std::mem::take(&mut self.out.corrected);
        let images = if corrected.is_empty() {
            input.images
        } else {
            &corrected[..]
        };
        self.connect_lines(p, images);
        self.out.corrected = corrected;
    }

    /// CONNECT, the refit on `images` (none: no refit) and corner closing.
    fn connect_lines(&mut self, p: &Params, images: &[GreyImage]) {
        let t = Instant::now();
        connect_into(
            &self.out.lines_raw,
            &p.connect,
            &mut self.out.lines,
            &mut self.connect,
        );
        if p.connect.refine {
            refine_into(images, &mut self.out.lines, &mut self.refine);
            drop_ghosts(&mut self.out.lines, &self.refine);
        }
        super::lines::align::keep_aligned(
            images,
            &mut self.out.lines,
            p.lines.min_aligned,
            p.connect.min_line_length,
            &mut self.align,
        );
        if p.connect.corner_radius > 0.0 {
            close_corners_with(
                &mut self.out.lines,
                p.connect.corner_radius,
                &mut self.corners,
            );
        }
        self.out.timings.connect_us = micros(t);
    }

    fn lens(&mut self, input: &Input, p: &Params) -> Result<(), LlvError> {
        let map = input.lens.filter(|m| p.lens.enabled && !m.is_identity());
        let Some(map) = map else {
            self.out.corrected.clear();
            return Ok(());
        };
        self.out
            .corrected
            .resize_with(input.images.len(), GreyImage::default);
        for (img, out) in input.images.iter().zip(self.out.corrected.iter_mut()) {
            correct_into(img, map, out)?;
        }
        if let Some(amb) = input.ambient {
            correct_into(amb, map, &mut self.ambient_corrected)?;
        }
        Ok(())
    }
}

/// One scan direction's buffers: the response, the several-lightings
/// combination, the edge points and the line extractor each keep theirs,
/// so that the two directions can run on two threads.
#[derive(Clone, Debug, Default)]
struct DirScratch {
    response: ResponseScratch,
    photo: PhotoScratch,
    peaks: PeakScratch,
    /// The pixels of the edge points, where the line extractor starts,
    /// and the peaks it may follow.
    starts: Starts,
    map: PeakMap,
    lines: LineScratch,
    /// The direction's extracted lines.
    segs: Vec<Segment>,
}

/// One scan direction's outputs and buffers.
struct DirOut<'a> {
    dir: ScanDir,
    response: &'a mut Response,
    noise: &'a mut NoiseMap,
    edges: &'a mut EdgePoints,
    s: &'a mut DirScratch,
}

/// What a run does in each scan direction: from the edges (the response
/// too, unless it can be kept) or from the lines on.
#[derive(Clone, Copy)]
struct Job<'p> {
    from: Stage,
    response: bool,
    params: &'p Params,
    /// Free the response and buffers at the end (all but the lines).
    lean: bool,
    edge_limit: Option<usize>,
}

impl Job<'_> {
    /// Runs one direction; returns the microseconds of its edge stage and
    /// of its line extraction.
    fn run(
        &self,
        images: &[GreyImage],
        ambient: Option<&GreyImage>,
        o: DirOut,
    ) -> Result<(u64, u64), LlvError> {
        let p = self.params;
        if let ([img], None, true) = (images, ambient, self.lean && self.from <= Stage::Edges) {
            return self.run_lean(img, o);
        }
        let mut edges_us = 0;
        let t = Instant::now();
        if self.from <= Stage::Edges && self.response {
            let a = p.edges.half_width as usize;
            match (images, ambient) {
                ([img], None) => response_into(img, o.dir, a, o.response, &mut o.s.response)?,
                _ => combined_response_into(
                    images,
                    ambient,
                    o.dir,
                    &p.edges,
                    o.response,
                    &mut o.s.photo,
                )?,
            }
        }
        if self.from <= Stage::Edges && p.lines.draw {
            // The drawing reads no peak map.
            let s = &mut *o.s;
            let (map, starts, peaks) = (&mut s.map, &mut s.starts, &mut s.peaks);
            detect_unmapped_into(o.response, &p.edges, o.noise, map, o.edges, starts, peaks);
        } else if self.from <= Stage::Edges {
            detect_into(
                o.response,
                &p.edges,
                p.lines.track_sigmas,
                o.noise,
                &mut o.s.map,
                o.edges,
                &mut o.s.starts,
                &mut o.s.peaks,
            );
        }
        if self.from <= Stage::Edges {
            self.check_edge_count(&o)?;
            edges_us = micros(t);
        }
        let t = Instant::now();
        if p.lines.draw {
            o.s.segs.clear(); // `Workspace::draw_lines` after both directions
        } else {
            track_into(
                o.response,
                o.noise,
                &o.s.map,
                o.edges,
                &o.s.starts,
                p.edges.floor,
                p.edges.half_width as usize,
                &p.lines,
                &mut o.s.segs,
                &mut o.s.lines,
            );
        }
        if self.lean {
            *o.response = Response::default();
            let segs = std::mem::take(&mut o.s.segs);
            (*o.s, o.s.segs) = (DirScratch::default(), segs);
        }
        Ok((edges_us, micros(t)))
    }
}

fn micros(t: Instant) -> u64 {
    u64::try_from(t.elapsed().as_micros()).unwrap_or(u64::MAX)
}

/// Checks the images (at least one, ≥ 16 × 16, one size), the ambient image
/// and the lens map; returns the size.
fn check_input(input: &Input) -> Result<(usize, usize), LlvError> {
    let first = input.images.first().ok_or(LlvError::BufferSize {
        width: 0,
        height: 0,
        expected: 0,
        actual: 0,
    })?;
    first.check_stage_size()?;
    let size = first.size();
    let others = input.images.iter().chain(input.ambient);
    for img in others {
        if img.size() != size {
            return Err(LlvError::SizeMismatch {
                a: size,
                b: img.size(),
            });
        }
        if img.data().len() != size.0 * size.1 {
            return Err(LlvError::BufferSize {
                width: size.0,
                height: size.1,
                expected: size.0 * size.1,
                actual: img.data().len(),
            });
        }
    }
    if let Some(m) = input.lens
        && m.size() != size
    {
        return Err(LlvError::SizeMismatch {
            a: size,
            b: m.size(),
        });
    }
    Ok(size)
}

/// Runs the whole pipeline once (a fresh [`Workspace`]).
pub fn run(input: &Input, p: &Params) -> Result<StageOutputs, LlvError> {
    let mut ws = Workspace::new();
    ws.run(input, p)?;
    Ok(ws.take_outputs())
}

/// Re-runs `from` and later stages on the outputs of an earlier run with the
/// same input; earlier stages are taken from `prev` unchanged.
pub fn rerun(
    prev: StageOutputs,
    from: Stage,
    input: &Input,
    p: &Params,
) -> Result<StageOutputs, LlvError> {
    let mut ws = Workspace::with_outputs(prev);
    ws.rerun(from, input, p)?;
    Ok(ws.take_outputs())
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::lines::draw::tests::square;

    #[test]
    fn a_square_gives_four_lines() {
        let img = square(128, 128);
        let out = run(&Input::single(&img), &Params::default()).unwrap();
        assert!(out.corrected.is_empty());
        assert_eq!(out.lines.len(), 4, "{:#?}", out.lines);
        for l in &out.lines {
            assert!(l.length() > 40.0 && l.residual < 0.1, "{l:?}");
        }
        assert_eq!(out.params, Params::default());
    }

    /// With `lines.draw` the whole pipeline gives the square's four lines.
    #[test]
    fn a_square_gives_four_lines_when_drawn() {
        let img = square(128, 128);
        let mut p = Params::default();
        p.lines.draw = true;
        let out = run(&Input::single(&img), &p).unwrap();
        assert_eq!(out.lines.len(), 4, "{:#?}", out.lines);
        for l in &out.lines {
            assert!(l.length() > 40.0 && l.residual < 0.1, "{l:?}");
        }
    }

    #[test]
    fn rerun_matches_a_full_run() {
        let img = square(96, 80);
        let input = Input::single(&img);
        let p = Params::default();
        let first = run(&input, &p).unwrap();
        let mut q = p.clone();
        q.connect.min_line_length = 40.0;
        let again = rerun(first.clone(), Stage::Connect, &input, &q).unwrap();
        let full = run(&input, &q).unwrap();
        assert_eq!(again.lines, full.lines);
        // The edges were not run again: they keep the first run's time.
        assert_eq!(again.timings.edges_us, first.timings.edges_us);
        assert!(again.timings.edges_us > 0);
        q.edges.per_region = 3;
        let again = rerun(first, Stage::Edges, &input, &q).unwrap();
        assert_eq!(again.edges_h, run(&input, &q).unwrap().edges_h);
    }

    /// Several lightings with an ambient image and lens correction: a
    /// rerun from the edges (a new half-width) on earlier outputs once
    /// failed on the missing corrected ambient ("image sizes differ: (96,
    /// 80) and (0, 0)"); it now matches a full run, on fresh outputs and in
    /// a workspace kept between runs.
    #[test]
    fn rerun_with_lens_and_ambient_matches_a_full_run() {
        let imgs = [square(96, 80), square(96, 80)];
        let ambient = GreyImage::filled(96, 80, 30).unwrap();
        let model = crate::lens::CameraModel {
            cx: 48.0,
            cy: 40.0,
            sx: 0.01,
            sy: 0.01,
            f: 8.0,
            distortion: Some([-0.02, 0.0, 0.0, 0.0, 0.0]),
            radial: [0.0; 2],
        };
        let map = LensMap::new(&model, 96, 80);
        let input = Input {
            images: &imgs,
            ambient: Some(&ambient),
            lens: Some(&map),
        };
        let p = Params::default();
        let first = run(&input, &p).unwrap();
        assert!(!first.corrected.is_empty());
        for change in [
            |q: &mut Params| q.edges.half_width = 5,
            |q: &mut Params| q.edges.noise_factor = 6.0,
            |q: &mut Params| q.edges.per_region = 3,
        ] {
            let mut q = p.clone();
            change(&mut q);
            let full = run(&input, &q).unwrap();
            let again = rerun(first.clone(), Stage::Edges, &input, &q).unwrap();
            assert_eq!(again.lines, full.lines);
            let mut ws = Workspace::new();
            ws.run(&input, &p).unwrap();
            let kept = ws.rerun(Stage::Edges, &input, &q).unwrap();
            assert_eq!(kept.edges_h, full.edges_h);
            assert_eq!(kept.lines, full.lines);
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let img = square(32, 32);
        let small = GreyImage::filled(8, 40, 0).unwrap();
        let p = Params::default();
        assert!(run(&Input::single(&small), &p).is_err());
        let imgs = [img.clone(), square(32, 33)];
        let input = Input {
            images: &imgs,
            ambient: None,
            lens: None,
        };
        assert!(matches!(
            run(&input, &p),
            Err(LlvError::SizeMismatch { .. })
        ));
        let input = Input {
            images: &[],
            ambient: None,
            lens: None,
        };
        assert!(run(&input, &p).is_err());
        let map = LensMap::identity(16, 16);
        let input = Input {
            lens: Some(&map),
            ..Input::single(&img)
        };
        assert!(run(&input, &p).is_err());
    }

    /// A half-width outside 3–7 set around the table's check is the kernel's
    /// error, for one image and several, not a panic.
    #[test]
    fn a_bad_half_width_is_an_error() {
        let imgs = [square(32, 32), square(32, 32)];
        let mut p = Params::default();
        for a in [0, 2, 8, 1000] {
            p.edges.half_width = a;
            for n in [1, 2] {
                let input = Input {
                    images: &imgs[..n],
                    ambient: None,
                    lens: None,
                };
                assert!(
                    matches!(
                        run(&input, &p),
                        Err(LlvError::Param {
                            name: "edges.half_width",
                            ..
                        })
                    ),
                    "A = {a}, {n} images"
                );
            }
        }
    }
}
