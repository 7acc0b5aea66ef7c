//! The image under work and its pipeline runs: the panel's parameter
//! values, the grey images of one image number with what the stages made
//! of them (a run's outputs, or the session's saved files), the line
//! editor, and the generation counters that keep an older run from ever
//! replacing a newer one. What is saved is always what the panel shows.

use std::sync::Arc;

use super::{CellState, Ctx, Pending};
use crate::llv::edit::LineEditor;
use crate::llv::lens::CameraModel;
use crate::llv::pipeline::StageOutputs;
use crate::llv::{GreyImage, Params, Segment};
use crate::session::camera::ImageCamera;
use crate::tui::event::{Cmd, ImageKey, PipelineRequest, StoreCmd};

/// The grey images of one image number and what the pipeline made of them.
#[derive(Debug)]
pub struct Loaded {
    pub k: u32,
    pub camera: u32,
    /// Captured frames by lighting letter, in capture order.
    pub frames: Vec<(char, GreyImage)>,
    pub version: u64,
    pub outputs: Option<Arc<StageOutputs>>,
    /// The parameters behind `outputs`.
    pub outputs_params: Option<Params>,
    /// The outputs were read from the session's files, not run.
    pub from_disk: bool,
    /// The outputs on screen are the ones the session holds (loaded, or
    /// saved since they were made); hand edits are written as they are made.
    pub in_session: bool,
    pub editor: Option<LineEditor>,
    /// Edits made in this run of the console (for the Edit screen).
    pub edits: usize,
    /// Hand-edited lines read back from the session (resume), used instead
    /// of the first pipeline result's lines.
    pub saved_lines: Option<Vec<Segment>>,
    /// Why the newest run failed (`None` after a run that worked): the
    /// outputs shown are then an older run's.
    pub failed: Option<String>,
    /// The session holds accepted outputs of this image: replacing them asks.
    pub accepted: bool,
    /// The operator said yes to changing this accepted image's lines.
    pub edit_confirmed: bool,
    /// Lightings whose saved grey image is damaged, with why.
    pub damaged: Vec<(char, String)>,
    /// Lightings captured in this run that the session could not save,
    /// with why: the image is not accepted until they are captured again.
    pub unsaved: Vec<(char, String)>,
    /// What the image runs with as the session records it, or why it
    /// cannot run ([`crate::tui::event::LoadedImage::camera`]); `None` for
    /// an image with a frame captured in this run, which runs with the
    /// profile's camera as the console read it (and is recorded so).
    pub recorded_camera: Option<Result<ImageCamera, String>>,
}

impl Loaded {
    pub fn new(k: u32, camera: u32) -> Loaded {
        Loaded {
            k,
            camera,
            frames: Vec::new(),
            version: 0,
            outputs: None,
            outputs_params: None,
            from_disk: false,
            in_session: false,
            editor: None,
            edits: 0,
            saved_lines: None,
            failed: None,
            accepted: false,
            edit_confirmed: false,
            damaged: Vec::new(),
            unsaved: Vec::new(),
            recorded_camera: None,
        }
    }

    /// The camera model lens correction uses on this image: the one the
    /// session says it runs with, so that a re-run here makes what `vss
    /// session redo` makes (after a recalibration too), else the profile's
    /// camera as the console read it. None where either gives none
    /// ([`Loaded::lens_problem`] says why).
    pub fn camera_model(&self, cell: &CellState) -> Option<CameraModel> {
        match &self.recorded_camera {
            Some(recorded) => recorded.as_ref().ok().and_then(ImageCamera::model),
            None => cell.camera_model(self.camera),
        }
    }

    /// Why this image is not run at all: its recorded camera description
    /// is damaged, in the words `vss session redo` refuses it with.
    pub fn camera_refused(&self) -> Option<&str> {
        self.recorded_camera
            .as_ref()?
            .as_ref()
            .err()
            .map(String::as_str)
    }

    /// Why lens correction has no camera model for this image, in words
    /// for the Pipeline panel (`None` when it has one, or while the store
    /// has not read the profile's cameras).
    pub fn lens_problem(&self, cell: &CellState) -> Option<String> {
        let k = self.k;
        match &self.recorded_camera {
            Some(Ok(c)) => c.problem(k),
            Some(Err(why)) => Some(why.clone()),
            None => cell
                .camera_problem(self.camera)
                .map(|why| format!("camera {}: {why}", self.camera)),
        }
    }

    /// The letters of the lightings the session could not save (`unsaved`).
    /// The lightings not saved, in words: `lighting d`, `lightings d and e`.
    pub fn unsaved_letters(&self) -> String {
        lightings(&self.unsaved.iter().map(|d| d.0).collect::<Vec<_>>())
    }

    /// The frame of lighting `letter`.
    pub fn frame(&self, letter: char) -> Option<&GreyImage> {
        self.frames.iter().find(|f| f.0 == letter).map(|f| &f.1)
    }

    /// The lightings of `letters` it has no frame of.
    pub fn missing(&self, letters: &[char]) -> Vec<char> {
        letters
            .iter()
            .copied()
            .filter(|l| self.frame(*l).is_none())
            .collect()
    }

    /// The outputs on screen are the session's and were made with `params`
    /// (the panel's): saved (a save asked, such as Ctrl-S on the Pipeline
    /// screen, counts until it fails), so accepting saves nothing. What `a`
    /// does and what the next-step box says both follow it.
    pub fn saved_with(&self, params: &crate::llv::Params) -> bool {
        self.in_session && self.outputs_params.as_ref() == Some(params)
    }

    /// The lines as they stand (edited, or the run's).
    pub fn lines(&self) -> Option<&[Segment]> {
        match (&self.editor, &self.outputs) {
            (Some(e), _) => Some(e.lines()),
            (None, Some(o)) => Some(&o.lines),
            (None, None) => None,
        }
    }
}

#[derive(Debug)]
pub struct Tracker {
    /// The panel's values: every run asks for these.
    pub params: Params,
    /// The profile's values, to mark the ones the operator changed.
    pub profile_params: Params,
    pub current: Option<Loaded>,
    /// Generation of the newest pipeline request, and of the result shown.
    pub generation: u64,
    pub shown_generation: u64,
    version_counter: u64,
}

impl Tracker {
    pub fn new(params: Params) -> Tracker {
        Tracker {
            profile_params: params.clone(),
            params,
            current: None,
            generation: 0,
            shown_generation: 0,
            version_counter: 0,
        }
    }

    /// The panel's values that differ from the profile's, as
    /// `key value` in panel order: what the next capture or run will use
    /// that the profile does not say.
    pub fn changed(&self) -> Vec<String> {
        crate::llv::params::PARAMS
            .iter()
            .filter_map(|sp| {
                let v = self.params.get(sp.key)?;
                (Some(v) != self.profile_params.get(sp.key))
                    .then(|| format!("{} {}", sp.key, crate::llv::params::fmt_value(v)))
            })
            .collect()
    }

    pub fn next_version(&mut self) -> u64 {
        self.version_counter += 1;
        self.version_counter
    }

    /// Whether a pipeline run is still out.
    pub fn busy(&self) -> bool {
        self.generation > self.shown_generation && self.current.is_some()
    }

    /// The size of the image the Pipeline and Edit previews show.
    pub fn preview_size(&self) -> Option<(usize, usize)> {
        let c = self.current.as_ref()?;
        c.frames.first().map(|(_, g)| g.size())
    }

    /// Why the outputs on screen are not those of the panel's values (a run
    /// still out, the newest run failed, other values), for view titles;
    /// `None` when they are.
    pub fn stale(&self) -> Option<&'static str> {
        let cur = self.current.as_ref()?;
        if cur.failed.is_some() {
            Some("stale: last run failed")
        } else if self.busy() {
            Some("stale: running")
        } else if cur.outputs.is_some() && cur.outputs_params.as_ref() != Some(&self.params) {
            Some("stale: other values")
        } else {
            None
        }
    }

    /// A pipeline request for the current image (`None` when there is none):
    /// its frames split by the profile's rule, as the session code splits
    /// them. Whether the image may run at all is [`Ctx::run_current`]'s.
    fn request(&mut self, cell: &super::CellState) -> Option<Cmd> {
        let cur = self.current.as_ref()?;
        if cur.frames.is_empty() {
            return None;
        }
        let camera = cur.camera_model(cell);
        // A copy of the frames per request, as before: keeping one with the
        // image would hold every frame twice for the whole survey.
        let input = Arc::new(
            cell.rule
                .split(cur.frames.iter().cloned())
                .with_camera(camera),
        );
        let (k, version) = (cur.k, cur.version);
        self.generation += 1;
        Some(Cmd::Pipeline(PipelineRequest {
            generation: self.generation,
            image_key: ImageKey { k, version },
            input,
            params: self.params.clone(),
        }))
    }
}

impl Ctx<'_> {
    /// Takes new parameter values and re-runs the pipeline on the current image.
    pub fn set_params(&mut self, p: Params) -> Vec<Cmd> {
        self.tracker.params = p;
        self.run_current().into_iter().collect()
    }

    /// A run of the current image (`Tracker::request`), or none. An image
    /// whose recorded camera description is damaged is not run: said, in
    /// the words `vss session redo` refuses it with, and nothing is made
    /// that the console could save.
    pub fn run_current(&mut self) -> Option<Cmd> {
        let Some(why) = self
            .tracker
            .current
            .as_ref()
            .and_then(Loaded::camera_refused)
            .map(str::to_string)
        else {
            return self.tracker.request(self.cell);
        };
        if let Some(cur) = self.tracker.current.as_mut()
            && !cur.frames.is_empty()
        {
            cur.failed = Some(why.clone());
        }
        self.error(format!("not run: {why}"));
        self.pipeline_failed();
        None
    }

    /// Puts parameter `key` (every one with `None`) back to the profile's
    /// value, says what changed, and re-runs the current image.
    pub fn reset_params(&mut self, key: Option<&'static str>) -> Vec<Cmd> {
        let mut p = self.tracker.params.clone();
        match key {
            Some(k) => {
                if let Some(v) = self.tracker.profile_params.get(k)
                    && p.set(k, v).is_err()
                {
                    return Vec::new();
                }
            }
            None => p = self.tracker.profile_params.clone(),
        }
        if p == self.tracker.params {
            match key {
                Some(k) => self.info(format!("{k} is at the profile's value already")),
                None => self.info("every parameter is at the profile's value already"),
            }
            return Vec::new();
        }
        let fmt = crate::llv::params::fmt_value;
        let moved: Vec<String> = crate::llv::params::PARAMS
            .iter()
            .filter_map(|sp| {
                let (old, new) = (self.tracker.params.get(sp.key)?, p.get(sp.key)?);
                (old != new).then(|| format!("{} {} → {}", sp.key, fmt(old), fmt(new)))
            })
            .collect();
        self.info(format!(
            "back to the profile's values: {}",
            moved.join(", ")
        ));
        self.set_params(p)
    }

    /// Makes the panel show the values image `k` was made with (recorded
    /// in the session), saying so, before it is run again or captured
    /// again: what an image was made with is never decided by values
    /// tuned on another. Returns whether the panel changed.
    pub fn use_recorded_params(&mut self, k: u32) -> bool {
        let Some(p) = self.session.image(k).and_then(|i| i.params.clone()) else {
            return false;
        };
        if p == self.tracker.params {
            return false;
        }
        self.tracker.params = p;
        let changed = self.tracker.changed();
        self.info(format!(
            "image {k}: the panel now shows the values image {k} was made with{} — D (Survey) \
             or d/D (Pipeline) go back to the profile's",
            if changed.is_empty() {
                " (the profile's)".to_string()
            } else {
                format!(": {}", changed.join(", "))
            }
        ));
        true
    }

    /// Resuming at image `k`, whose capture was cut short (a dropped SSH
    /// connection) before it was run, so it has no values of its own: the
    /// panel takes those of the survey's newest outputs, as it does when
    /// the next image has no frames (that image is loaded), not the
    /// profile's, so that a tuned value is not lost with the console.
    pub fn resume_with_the_survey_s_values(&mut self, k: u32) {
        if self.session.image(k).is_none_or(|i| i.params.is_some()) {
            return;
        }
        let newest = self.session.view.as_ref().and_then(|v| {
            v.images
                .iter()
                .filter(|i| i.params.is_some())
                .map(|i| i.k)
                .max()
        });
        if let Some(j) = newest {
            self.use_recorded_params(j);
        }
    }

    /// The commands that save the outputs on screen, or `None` (said in the
    /// log, or asked first) when there is nothing to save, they were not
    /// made with the panel's values, or they would replace accepted outputs
    /// and `confirmed` is false.
    pub fn save_outputs(&mut self, confirmed: bool) -> Option<Vec<Cmd>> {
        let busy = self.tracker.busy();
        let Some(cur) = self.tracker.current.as_ref() else {
            self.warn("nothing to save: no image processed yet");
            return None;
        };
        if let Some(why) = cur.camera_refused() {
            self.error(format!("not saved: {why}"));
            return None;
        }
        let (Some(out), Some(params)) = (cur.outputs.clone(), cur.outputs_params.clone()) else {
            self.warn("nothing to save: the pipeline has not finished");
            return None;
        };
        if let Some(e) = cur.failed.clone() {
            self.error(format!(
                "not saved: the last run failed ({e}); the outputs on screen were made with \
                 other values than the panel's — change a value to run again"
            ));
            return None;
        }
        if params != self.tracker.params || busy {
            self.warn(
                "not saved: the outputs on screen were not made with the panel's values yet \
                 (a run is still out) — try again when it has finished",
            );
            return None;
        }
        if self.session.view.is_none() {
            self.warn("no session open: outputs are not saved");
            return None;
        }
        let k = cur.k;
        if cur.accepted && !confirmed {
            self.ask(
                format!(
                    "Image {k} is accepted. Replace its saved outputs (.hpo .vpo .lex .ldr, \
                     and the hand edits in its .ldr) with the ones on screen?"
                ),
                Pending::SaveOutputs,
            );
            return None;
        }
        // A new .ldr replaces the edited one and clears the session's edit
        // log, so manual edits made since are recorded again on top.
        let edited = cur
            .editor
            .as_ref()
            .map(|e| e.lines().to_vec())
            .filter(|l| *l != out.lines);
        let mut cmds = vec![Cmd::Store(StoreCmd::SaveOutputs {
            k,
            outputs: out,
            params,
        })];
        if let Some(lines) = edited {
            cmds.push(Cmd::Store(StoreCmd::RecordEdit {
                k,
                what: "manual edits kept over the new outputs".into(),
                lines,
            }));
        }
        if let Some(c) = self.tracker.current.as_mut() {
            c.accepted = true;
            c.in_session = true;
        }
        Some(cmds)
    }
}

/// Lighting letters in words: `lighting b`, `lightings d and e`,
/// `lightings a, b and c` (a run of letters read as a word: "lighting de");
/// empty for none.
pub fn lightings(letters: &[char]) -> String {
    match letters {
        [] => String::new(),
        [l] => format!("lighting {l}"),
        [init @ .., last] => {
            let init: Vec<String> = init.iter().map(char::to_string).collect();
            format!("lightings {} and {last}", init.join(", "))
        }
    }
}
