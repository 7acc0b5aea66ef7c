//! What the LLV stages get for one image of a survey, and the one runner
//! that feeds them to the pipeline. The console, `vss session redo` and
//! `vss llv` all go through here, so the same captured image gives the same
//! lines whoever runs it.
//!
//! An image is captured once per lighting configuration. [`FrameRule`]
//! decides which frames are lit and which one is the ambient frame (taken
//! with no light on, subtracted from every lit one, llv.md §2.6): the only
//! lighting with no light on, when at least one other lighting has lights
//! on. The rule is the profile's lightings (or the session's record of
//! them, made from the profile): [`FrameRule::of_profile`],
//! [`Session::frame_rule`]. A [`PipelineInput`] holds the split frames and
//! the image's camera; a [`Runner`] runs the stages on it from a given stage
//! through one reusable [`Workspace`] and keeps the lens map of the last
//! camera and size, so it belongs on the thread that runs the pipeline (the
//! console's worker, a command).

use std::sync::Arc;

use super::{OutputSet, Session, SessionError};
use crate::formats;
use crate::llv::lens::{CameraModel, LensMap};
use crate::llv::params::Stage;
use crate::llv::pipeline::{Input, Saved, StageOutputs, Workspace};
use crate::llv::{GreyImage, LlvError, Params};
use crate::profile::Profile;

/// Reads a session's grey image (`.img`) or its lens-corrected copy
/// (`.imc`) as the manifest records it: the header must give the size
/// `record` says (a grey image's `width` × `height`), not more pixels than
/// the stages take, or it is refused after 64 bytes. A file replaced by a huge one (a
/// 40000² frame is 1.6 GB) is not read into memory by the console, `session
/// redo` or `session check`.
pub fn read_frame(
    path: &std::path::Path,
    record: &super::manifest::GreyRecord,
) -> Result<formats::img::ImgFile, formats::FormatError> {
    let want = (record.width as usize, record.height as usize);
    formats::img::read_img_sized(path, |w, h| {
        if let Err(e @ LlvError::TooLarge { .. }) = crate::llv::image::check_stage_size(w, h) {
            return Err(e.to_string());
        }
        if (w, h) == want {
            Ok(())
        } else {
            Err(format!(
                "the image is {w} x {h} pixels, but the manifest records {} x {} for it; \
                 not read",
                want.0, want.1
            ))
        }
    })
}

/// Which of an image's frames are lit and which is the ambient one.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FrameRule {
    letters: Vec<char>,
    ambient: Option<char>,
}

impl FrameRule {
    /// The rule for lightings given as (letter, whether any light is on),
    /// in order.
    pub fn new(lightings: impl IntoIterator<Item = (char, bool)>) -> FrameRule {
        let all: Vec<(char, bool)> = lightings.into_iter().collect();
        let mut unlit = all.iter().filter(|(_, lit)| !lit).map(|(l, _)| *l);
        let ambient = match (unlit.next(), unlit.next()) {
            (Some(l), None) if all.iter().any(|(_, lit)| *lit) => Some(l),
            _ => None,
        };
        FrameRule {
            letters: all.iter().map(|(l, _)| *l).collect(),
            ambient,
        }
    }

    /// The rule of a profile's `[[lighting]]` list.
    pub fn of_profile(p: &Profile) -> FrameRule {
        FrameRule::new(p.lighting.iter().map(|l| (l.letter, !l.on.is_empty())))
    }

    /// The lighting letters, in order.
    pub fn letters(&self) -> &[char] {
        &self.letters
    }

    /// The letter of the ambient lighting, if the lightings have one.
    pub fn ambient(&self) -> Option<char> {
        self.ambient
    }

    /// Splits an image's frames (lighting letter, image; any order) into
    /// the lit ones in letter order and the ambient one. An ambient frame
    /// with no lit frame beside it is used as the one lit image. The
    /// camera is unset: see [`PipelineInput::with_camera`].
    pub fn split(&self, frames: impl IntoIterator<Item = (char, GreyImage)>) -> PipelineInput {
        let mut frames: Vec<(char, GreyImage)> = frames.into_iter().collect();
        frames.sort_by_key(|(l, _)| self.order(*l));
        let lit = self.lit_letters(frames.iter().map(|(l, _)| *l));
        let mut input = PipelineInput::default();
        for (l, g) in frames {
            if lit.contains(&l) {
                input.letters.push(l);
                input.images.push(g);
            } else {
                input.ambient = Some((l, g));
            }
        }
        input
    }

    /// The letters of the lit frames among the `captured` ones, in the order
    /// [`FrameRule::split`] puts their images.
    pub fn lit_letters(&self, captured: impl IntoIterator<Item = char>) -> Vec<char> {
        let mut all: Vec<char> = captured.into_iter().collect();
        all.sort_by_key(|l| self.order(*l));
        all.dedup();
        let lit: Vec<char> = all
            .iter()
            .copied()
            .filter(|l| Some(*l) != self.ambient)
            .collect();
        if lit.is_empty() { all } else { lit }
    }

    /// Letter order (the order the session names the corrected images);
    /// letters the rule does not know go last, in alphabetical order.
    fn order(&self, l: char) -> (usize, char) {
        let i = self.letters.iter().position(|x| *x == l);
        (i.unwrap_or(usize::MAX), l)
    }
}

/// The LLV input of one image: its lit frames, its ambient frame and its
/// camera.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PipelineInput {
    /// The lighting letter of each of `images`.
    pub letters: Vec<char>,
    /// The lit frames, in letter order (the order of the corrected images
    /// in [`StageOutputs::corrected`]).
    pub images: Vec<GreyImage>,
    /// The ambient frame and its letter.
    pub ambient: Option<(char, GreyImage)>,
    /// The camera model for lens correction (none: no correction).
    pub camera: Option<CameraModel>,
}

impl PipelineInput {
    /// The same frames seen by `camera`.
    pub fn with_camera(mut self, camera: Option<CameraModel>) -> PipelineInput {
        self.camera = camera;
        self
    }

    /// The size of the frames (0 × 0 without any).
    pub fn size(&self) -> (usize, usize) {
        self.images.first().map_or((0, 0), GreyImage::size)
    }

    /// The pipeline's view of this input with a lens map.
    pub fn input<'a>(&'a self, lens: Option<&'a LensMap>) -> Input<'a> {
        Input {
            images: &self.images,
            ambient: self.ambient.as_ref().map(|(_, g)| g),
            lens,
        }
    }
}

/// Runs the LLV stages on [`PipelineInput`]s through one [`Workspace`]:
/// one runner per thread that runs the pipeline. It keeps the outputs of
/// its last run, so a later run can start at a later stage, and the lens
/// map of its last camera and size.
#[derive(Debug, Default)]
pub struct Runner {
    ws: Workspace,
    lens: Option<(CameraModel, (usize, usize), Arc<LensMap>)>,
    /// The caller's key and the camera of the last complete run of
    /// [`Runner::run_changed`].
    last: Option<(u64, Option<CameraModel>)>,
}

impl Runner {
    pub fn new() -> Runner {
        Runner::default()
    }

    /// A runner for one-shot runs whose responses nobody reads (`vss llv`):
    /// one scan direction's buffers in memory at a time
    /// ([`Workspace::lean`]), the same results. Its runs write edge files,
    /// so a direction with more edge points than a file holds stops the run
    /// at once ([`Workspace::limit_edge_points`]).
    pub fn lean() -> Runner {
        Runner {
            ws: Workspace::lean().limit_edge_points(crate::formats::edgefile::MAX_POINTS),
            ..Runner::default()
        }
    }

    /// The lens map a run of `input` with `p` uses: none without a camera,
    /// with `lens.enabled = false` or for a camera that changes nothing.
    /// The size is checked first: a map is never made for an image the
    /// stages refuse, nor for a camera whose distortion folds the image.
    pub fn lens_map(
        &mut self,
        input: &PipelineInput,
        p: &Params,
    ) -> Result<Option<Arc<LensMap>>, LlvError> {
        let size = input.size();
        crate::llv::image::check_stage_size(size.0, size.1)?;
        let Some(m) = input.camera.filter(|m| p.lens.enabled && !m.is_identity()) else {
            return Ok(None);
        };
        if let Some((cm, sz, map)) = &self.lens
            && *cm == m
            && *sz == size
        {
            return Ok(Some(map.clone()));
        }
        // A distortion that folds the image (a mistyped D or K) would
        // mirror part of it onto itself: refused, not corrected.
        if let Some((x, y)) = m.fold_in(size.0, size.1) {
            return Err(LlvError::LensFolds { x, y });
        }
        let map = Arc::new(LensMap::new(&m, size.0, size.1));
        self.lens = Some((m, size, map.clone()));
        Ok(Some(map))
    }

    /// Runs `from` and every later stage on `input` with `p`. A stage after
    /// `Lens` reuses the earlier stages of this runner's last run, so it is
    /// only right when `input` is the input of that run (a full run is made
    /// when the last run does not fit its size).
    pub fn run(
        &mut self,
        input: &PipelineInput,
        from: Stage,
        p: &Params,
    ) -> Result<&StageOutputs, LlvError> {
        let map = self.lens_map(input, p)?;
        self.last = None;
        self.ws.rerun(from, &input.input(map.as_deref()), p)
    }

    /// Runs what `p` changed since the last run when `key` names the same
    /// frames as the last run (the caller's promise: a new capture gets a
    /// new key) and the camera is the same, else every stage; with nothing
    /// changed the last outputs stand. A failed run leaves nothing to run
    /// from: the next is a full run. This is how the console re-runs a
    /// parameter tweak.
    pub fn run_changed(
        &mut self,
        key: u64,
        input: &PipelineInput,
        p: &Params,
    ) -> Result<&StageOutputs, LlvError> {
        let from = match self.last.take() {
            Some(last) if last == (key, input.camera) => {
                match self.ws.outputs().params.first_changed_stage(p) {
                    None => {
                        self.last = Some(last);
                        return Ok(self.ws.outputs());
                    }
                    Some(stage) => stage,
                }
            }
            _ => Stage::Lens,
        };
        self.run(input, from, p)?;
        self.last = Some((key, input.camera));
        Ok(self.ws.outputs())
    }

    /// Runs the stages after a saved result, the lines refitted on
    /// `frames`' images when given (see [`Workspace::run_saved`]).
    pub fn run_saved(
        &mut self,
        saved: Saved,
        p: &Params,
        frames: Option<&PipelineInput>,
    ) -> Result<&StageOutputs, LlvError> {
        self.last = None;
        let Some(input) = frames else {
            return self.ws.run_saved(saved, p, None);
        };
        let map = self.lens_map(input, p)?;
        self.ws
            .run_saved(saved, p, Some(&input.input(map.as_deref())))
    }

    /// The outputs of the last run.
    pub fn outputs(&self) -> &StageOutputs {
        self.ws.outputs()
    }
}

impl Session {
    /// The frame rule of this session's lightings (recorded from the
    /// profile that made the session).
    pub fn frame_rule(&self) -> FrameRule {
        FrameRule::new(
            self.manifest
                .lighting
                .iter()
                .map(|l| (l.letter, !l.on.is_empty())),
        )
    }

    /// Image `k`'s captured frames, split by [`Session::frame_rule`], with
    /// its camera.
    pub fn pipeline_input(&self, k: u32) -> Result<PipelineInput, SessionError> {
        super::check_image_number(k)?;
        let frames = self.load_images(k)?.into_iter().map(|(l, f)| (l, f.image));
        let input = self.frame_rule().split(frames);
        if input.images.is_empty() {
            return Err(self.missing(k, "no grey image captured yet: capture it first".into()));
        }
        let camera = self.image_camera(k)?.model();
        if let (Some(m), Some(cdf)) = (&camera, self.manifest.image(k).and_then(|r| r.cdf.as_ref()))
        {
            // A camera that leaves (almost) nothing of the image is the
            // .cdf's fault: say so before a lens map is made.
            let (w, h) = input.size();
            formats::cdf::check_camera_area(m, w, h, &self.path(&cdf.file))?;
        }
        Ok(input.with_camera(camera))
    }

    /// Whether image `k` has grey frames recorded.
    pub fn has_frames(&self, k: u32) -> bool {
        self.manifest.image(k).is_some_and(|r| !r.grey.is_empty())
    }

    /// Every stage of image `k` on its frames with `params`, which it
    /// returns with the outputs.
    fn run_frames<'r>(
        &self,
        k: u32,
        params: Params,
        runner: &'r mut Runner,
    ) -> Result<(&'r StageOutputs, Params), SessionError> {
        let input = self.pipeline_input(k)?;
        let out = runner.run(&input, Stage::Lens, &params)?;
        Ok((out, params))
    }

    /// Runs image `k`'s stages from `from` with `params` through `runner`,
    /// saving nothing. From `lens` or `edges` on its frames
    /// ([`Session::pipeline_input`]). From `lines` with the lens and edge
    /// parameters the saved edges were made with: on its frames, as the
    /// console re-runs the lines (tracks follow the response's peaks below
    /// the edge threshold, which the edge files do not hold), or on its
    /// saved `.hpo` and `.vpo` when it has no frames. From `connect` on its
    /// saved `.lex`, the lines refitted on its frames when it has some.
    /// Returns the parameters the outputs stand for.
    pub fn run_stages<'r>(
        &self,
        k: u32,
        from: Stage,
        params: &Params,
        runner: &'r mut Runner,
    ) -> Result<(&'r StageOutputs, Params), SessionError> {
        super::check_image_number(k)?;
        if from <= Stage::Edges {
            return self.run_frames(k, params.clone(), runner);
        }
        let rec = self.manifest.image(k).and_then(|r| r.outputs.as_ref());
        let Some(rec) = rec else {
            return Err(self.missing(
                k,
                format!("no saved outputs to start from {from:?}: redo from edges first"),
            ));
        };
        let mut used = rec.params.clone();
        used.connect = params.connect.clone();
        let saved = if from == Stage::Lines {
            used.lines = params.lines.clone();
            if self.has_frames(k) {
                return self.run_frames(k, used, runner);
            }
            let read =
                |ext| formats::edgefile::read_edges(&self.path(&self.file_name(k, None, ext)));
            Saved::Edges {
                h: read("hpo")?,
                v: read("vpo")?,
            }
        } else {
            let mut lex = formats::lines::read_lines(&self.path(&self.file_name(k, None, "lex")))?;
            if let Some(a) = &rec.lex_attributes {
                a.apply(&mut lex);
            }
            Saved::Lines(lex)
        };
        // The refit after CONNECT reads the frames, as the console's does.
        let frames = if from == Stage::Connect && self.has_frames(k) {
            Some(self.pipeline_input(k)?)
        } else {
            None
        };
        let out = runner.run_saved(saved, &used, frames.as_ref())?;
        Ok((out, used))
    }

    /// Saves what [`Session::run_stages`] gave for a run from `from`: the
    /// files of that stage and the later ones, then the manifest record.
    pub fn save_stages(
        &mut self,
        k: u32,
        from: Stage,
        out: &StageOutputs,
        params: &Params,
    ) -> Result<(), SessionError> {
        if from <= Stage::Edges {
            return self.save_outputs(k, out, params);
        }
        let set = OutputSet {
            lines_raw: (from == Stage::Lines).then_some(out.lines_raw.as_slice()),
            lines: Some(&out.lines),
            timings: super::manifest::TimingsRecord::from(&out.timings),
            ..Default::default()
        };
        self.save_output_set(k, &set, params)
    }

    fn missing(&self, k: u32, what: String) -> SessionError {
        SessionError::Missing {
            session: self.name.to_string(),
            image: k,
            what,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(v: u8) -> GreyImage {
        GreyImage::filled(16, 16, v).unwrap()
    }

    #[test]
    fn the_one_unlit_lighting_is_ambient() {
        let r = FrameRule::new([('a', true), ('b', true), ('e', false)]);
        assert_eq!(r.ambient(), Some('e'));
        let i = r.split([('e', img(1)), ('b', img(3)), ('a', img(2))]);
        assert_eq!(i.letters, vec!['a', 'b']);
        assert_eq!(i.images, vec![img(2), img(3)]);
        assert_eq!(i.ambient, Some(('e', img(1))));
        // Only the ambient frame: it is the one image.
        let i = r.split([('e', img(1))]);
        assert_eq!((i.letters, i.ambient), (vec!['e'], None));
    }

    #[test]
    fn no_ambient_without_a_lit_lighting_or_with_two_unlit() {
        assert_eq!(FrameRule::new([('a', false)]).ambient(), None);
        assert_eq!(FrameRule::new([('a', false), ('b', false)]).ambient(), None);
        let r = FrameRule::new([('a', true), ('b', false), ('c', false)]);
        assert_eq!(r.ambient(), None);
        assert_eq!(
            r.split([('c', img(1)), ('a', img(2))]).letters,
            vec!['a', 'c']
        );
    }

    /// A bright square on a dark ground.
    fn square() -> GreyImage {
        square_at(0)
    }

    /// [`square`] moved `dx` px to the right.
    fn square_at(dx: usize) -> GreyImage {
        let mut g = GreyImage::filled(128, 128, 40).unwrap();
        for y in 30..90 {
            for x in 35 + dx..95 + dx {
                g.data_mut()[y * 128 + x] = 200;
            }
        }
        g
    }

    #[test]
    fn run_changed_reruns_what_changed_as_a_full_run_would() {
        let input = FrameRule::default().split([('a', square())]);
        let p = Params::default();
        let mut r = Runner::new();
        let first = r.run_changed(1, &input, &p).unwrap().clone();
        assert!(first.lines.len() >= 4 && first.timings.edges_us > 0);
        let mut q = p.clone();
        q.connect.corner_radius = 0.0;
        let again = r.run_changed(1, &input, &q).unwrap().clone();
        // Only CONNECT re-ran: the edges keep the first run's time.
        assert_eq!(again.timings.edges_us, first.timings.edges_us);
        let full = Runner::new().run(&input, Stage::Lens, &q).unwrap().clone();
        assert_eq!(again.lines, full.lines);
        assert_eq!(again.edges_h, full.edges_h);
        // A failed run leaves nothing to re-run from.
        let mut bad = q.clone();
        bad.edges.half_width = 99;
        assert!(r.run_changed(1, &input, &bad).is_err());
        let after = r.run_changed(1, &input, &q).unwrap();
        assert!(after.timings.edges_us > 0, "a full run after a failure");
        assert_eq!(after.lines, full.lines);
        // Another key, other frames: a full run (edges kept from key 1
        // would give key 1's lines).
        let moved = FrameRule::default().split([('a', square_at(20))]);
        let other = r.run_changed(2, &moved, &q).unwrap().clone();
        let full = Runner::new().run(&moved, Stage::Lens, &q).unwrap().clone();
        assert_eq!(other.edges_h, full.edges_h);
        assert_eq!(other.lines, full.lines);
    }
}
