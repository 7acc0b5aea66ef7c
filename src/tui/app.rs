//! The console's state and its one update function: `App::update(Msg) ->
//! Vec<Cmd>`. No I/O here — workers do the serial link, the LLV and the
//! disk, and report back as messages — so every behaviour of the console can
//! be driven by a test through messages alone.

use std::sync::Arc;

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use super::event::{
    Cmd, DeviceCmd, FramePurpose, ImageKey, Msg, PipelineRequest, SessionView, StoreCmd,
};
use super::keymap::{self, Action, Scope, ScreenId};
use super::mode::Look;
use super::screens::{CaptureScreen, EditScreen, PipelineScreen, SessionScreen, SurveyScreen};
use super::text::clean;
use crate::llv::edit::LineEditor;
use crate::llv::lens::CameraModel;
use crate::llv::pipeline::StageOutputs;
use crate::llv::{GreyImage, Params};
use crate::profile::Profile;

mod edit;
mod log;
mod results;
mod survey;

pub use log::{Level, Log, LogEntry};
pub use survey::Phase;

/// A question or a text field over the current screen.
#[derive(Clone, Debug, PartialEq)]
pub enum Modal {
    Prompt {
        title: String,
        text: String,
        purpose: PromptPurpose,
    },
    Confirm {
        question: String,
        on_yes: Pending,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PromptPurpose {
    SessionName,
    ParamValue,
}

/// What a confirmed question does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pending {
    RedoImage(u32),
}

/// How the log pane is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogView {
    Hidden,
    Line,
    Expanded,
}

/// What the console knows of the hardware.
#[derive(Clone, Debug, Default)]
pub struct DeviceState {
    pub connected: bool,
    pub grabber: String,
    pub relay: String,
    pub lost: Option<String>,
    pub lights_on: Vec<String>,
    pub mask: u32,
    /// A frame coming in: what for, bytes done and total.
    pub transfer: Option<(FramePurpose, usize, usize)>,
    pub live: bool,
}

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
    pub editor: Option<LineEditor>,
    /// Edits not yet part of saved outputs (for the status line).
    pub edits: usize,
    /// Hand-edited lines read back from the session (resume), used instead
    /// of the first pipeline result's lines.
    pub saved_lines: Option<Vec<crate::llv::Segment>>,
    /// Why the newest run failed (`None` after a run that worked): the
    /// outputs shown are then an older run's.
    pub failed: Option<String>,
}

/// The whole console state.
pub struct App {
    pub look: Look,
    pub profile_name: String,
    /// Lighting letters of the profile, and which one is ambient (no light on).
    pub letters: Vec<char>,
    pub ambient: Option<char>,
    /// Light names and relay channels, in profile order.
    pub lights: Vec<(String, u32)>,
    /// Lighting configuration letter → names of the lights on.
    pub lighting_on: Vec<(char, Vec<String>)>,
    pub cameras: u32,
    pub camera_models: Vec<Option<CameraModel>>,
    pub params: Params,
    pub screen: ScreenId,
    pub survey: SurveyScreen,
    pub capture: CaptureScreen,
    pub pipeline: PipelineScreen,
    pub edit: EditScreen,
    pub files: SessionScreen,
    pub log: Log,
    pub log_view: LogView,
    pub help: bool,
    pub modal: Option<Modal>,
    pub device: DeviceState,
    pub session: Option<SessionView>,
    pub sessions: Vec<(String, std::path::PathBuf, String)>,
    pub current: Option<Loaded>,
    /// The latest frame of the live view or a single grab.
    pub live: Option<(u32, GreyImage)>,
    /// Survey progress: image number, camera, location, phase.
    pub work: survey::Work,
    /// Generation of the newest pipeline request, and of the result shown.
    pub generation: u64,
    pub shown_generation: u64,
    version_counter: u64,
    pub quit: bool,
}

impl App {
    pub fn new(profile: &Profile, look: Look) -> App {
        let letters: Vec<char> = profile.lighting.iter().map(|l| l.letter).collect();
        let ambient = profile
            .lighting
            .iter()
            .find(|l| l.on.is_empty())
            .map(|l| l.letter)
            .filter(|_| profile.lighting.len() > 1);
        App {
            look,
            profile_name: clean(&profile.name),
            letters,
            ambient,
            lights: profile
                .lights
                .iter()
                .map(|l| (clean(&l.name), l.relay))
                .collect(),
            lighting_on: profile
                .lighting
                .iter()
                .map(|l| (l.letter, l.on.iter().map(|s| clean(s)).collect()))
                .collect(),
            cameras: profile.survey.cameras.max(1),
            camera_models: Vec::new(),
            params: profile.llv.clone(),
            screen: ScreenId::Survey,
            survey: SurveyScreen::default(),
            capture: CaptureScreen::default(),
            pipeline: PipelineScreen::default(),
            edit: EditScreen::default(),
            files: SessionScreen::default(),
            log: Log::default(),
            log_view: LogView::Line,
            help: false,
            modal: None,
            device: DeviceState::default(),
            session: None,
            sessions: Vec::new(),
            current: None,
            live: None,
            work: survey::Work::default(),
            generation: 0,
            shown_generation: 0,
            version_counter: 0,
            quit: false,
        }
    }

    /// The commands to send when the console starts.
    pub fn start(&mut self) -> Vec<Cmd> {
        self.log
            .push(Level::Info, format!("profile {}", self.profile_name));
        vec![Cmd::Store(StoreCmd::List)]
    }

    /// Applies one message; returns the work it asks of the workers.
    pub fn update(&mut self, msg: Msg) -> Vec<Cmd> {
        match msg {
            Msg::Key(k) => self.on_key(k),
            Msg::Resize(..) | Msg::Tick => Vec::new(),
            Msg::Device(ev) => self.on_device(ev),
            Msg::Pipeline(r) => self.on_pipeline(r),
            Msg::Store(ev) => self.on_store(ev),
        }
    }

    /// The keymap scope keys go to right now.
    pub fn scope(&self) -> Scope {
        match &self.modal {
            Some(Modal::Prompt { .. }) => Scope::Prompt,
            Some(Modal::Confirm { .. }) => Scope::Confirm,
            None => Scope::Screen(self.screen),
        }
    }

    fn on_key(&mut self, key: KeyEvent) -> Vec<Cmd> {
        if key.kind != ratatui::crossterm::event::KeyEventKind::Press {
            return Vec::new();
        }
        if self.help {
            // Any key closes the help; Ctrl-C still quits.
            self.help = false;
            if keymap::lookup(Scope::Global, &key) == Some(Action::Quit)
                && key.modifiers.contains(KeyModifiers::CONTROL)
            {
                self.quit = true;
            }
            return Vec::new();
        }
        let scope = self.scope();
        if scope == Scope::Prompt {
            if let Some(a) = keymap::lookup(scope, &key) {
                return self.act(a);
            }
            if let Some(Modal::Prompt { text, .. }) = &mut self.modal {
                match key.code {
                    KeyCode::Char(c)
                        if !key.modifiers.contains(KeyModifiers::CONTROL)
                            && text.chars().count() < 64
                            && !c.is_control() =>
                    {
                        text.push(c);
                    }
                    KeyCode::Backspace => {
                        text.pop();
                    }
                    _ => {}
                }
            }
            return Vec::new();
        }
        let action = match self.screen {
            ScreenId::Survey => self.survey.handle_key(key),
            ScreenId::Capture => self.capture.handle_key(key),
            ScreenId::Pipeline => {
                let size = self.preview_size();
                self.pipeline.handle_key(key, size)
            }
            ScreenId::Edit => {
                let size = self.preview_size();
                self.edit.handle_key(key, size)
            }
            ScreenId::Session => self.files.handle_key(key),
        };
        let action = if scope == Scope::Confirm {
            keymap::lookup(scope, &key)
        } else {
            action
        };
        match action {
            Some(a) => self.act(a),
            None => Vec::new(),
        }
    }

    /// The size of the image the Pipeline and Edit previews show.
    pub fn preview_size(&self) -> Option<(usize, usize)> {
        let c = self.current.as_ref()?;
        c.frames.first().map(|(_, g)| g.size())
    }

    fn act(&mut self, a: Action) -> Vec<Cmd> {
        match a {
            Action::Quit => {
                self.quit = true;
                Vec::new()
            }
            Action::Help => {
                self.help = true;
                Vec::new()
            }
            Action::ToggleLog => {
                self.log_view = match self.log_view {
                    LogView::Hidden => LogView::Line,
                    LogView::Line => LogView::Expanded,
                    LogView::Expanded => LogView::Hidden,
                };
                Vec::new()
            }
            Action::GoTo(s) => {
                self.screen = s;
                if s == ScreenId::Session && self.session.is_some() {
                    return vec![Cmd::Store(StoreCmd::Refresh)];
                }
                Vec::new()
            }
            Action::Yes | Action::No => self.answer(a == Action::Yes),
            Action::Submit => self.submit(),
            Action::Cancel => {
                if self.modal.take().is_some() {
                    return Vec::new();
                }
                if self.screen == ScreenId::Edit {
                    self.edit.selected.clear();
                    return Vec::new();
                }
                self.device.live = false;
                vec![Cmd::Device(DeviceCmd::Cancel)]
            }
            Action::NewSession
            | Action::SelectUp
            | Action::SelectDown
            | Action::OpenSelected
            | Action::NextStep
            | Action::Accept
            | Action::Redo
            | Action::LocationNext => self.survey_action(a),
            Action::CameraNext => {
                if self.screen == ScreenId::Survey {
                    self.survey_action(a)
                } else {
                    self.capture.camera = self.capture.camera % self.cameras + 1;
                    let mut cmds = Vec::new();
                    if self.device.live {
                        cmds.push(Cmd::Device(DeviceCmd::Live {
                            on: true,
                            camera: self.capture.camera,
                        }));
                    }
                    cmds
                }
            }
            Action::ToggleLive => {
                self.device.live = !self.device.live;
                vec![Cmd::Device(DeviceCmd::Live {
                    on: self.device.live,
                    camera: self.capture.camera,
                })]
            }
            Action::Grab => vec![Cmd::Device(DeviceCmd::Capture {
                purpose: FramePurpose::Snapshot,
                camera: self.capture.camera,
                lighting: None,
            })],
            Action::LightPrev => {
                self.capture.light = self.capture.light.saturating_sub(1);
                Vec::new()
            }
            Action::LightNext => {
                if self.capture.light + 1 < self.lights.len() {
                    self.capture.light += 1;
                }
                Vec::new()
            }
            Action::LightToggle => {
                let Some((name, relay)) = self.lights.get(self.capture.light) else {
                    return Vec::new();
                };
                let on = !self.device.lights_on.contains(name);
                vec![Cmd::Device(DeviceCmd::SetLight { relay: *relay, on })]
            }
            Action::LightsOff => vec![Cmd::Device(DeviceCmd::AllOff)],
            Action::Lighting(i) => match self.letters.get(i as usize) {
                Some(&l) => vec![Cmd::Device(DeviceCmd::Lighting(l))],
                None => {
                    self.log.push(
                        Level::Warn,
                        format!(
                            "the profile has no lighting configuration {}",
                            (b'a' + i) as char
                        ),
                    );
                    Vec::new()
                }
            },
            Action::ParamInc => self.step_param(1.0),
            Action::ParamDec => self.step_param(-1.0),
            Action::ParamInc10 => self.step_param(10.0),
            Action::ParamDec10 => self.step_param(-10.0),
            Action::ParamType => {
                let key = self.pipeline.param_spec().key;
                let now = self.params.get(key).map(fmt_value).unwrap_or_default();
                self.modal = Some(Modal::Prompt {
                    title: format!("{key} ="),
                    text: now,
                    purpose: PromptPurpose::ParamValue,
                });
                Vec::new()
            }
            Action::SaveOutputs => self.save_outputs().unwrap_or_default(),
            Action::LineNext
            | Action::LinePrev
            | Action::LineNearest
            | Action::Corner
            | Action::Mark
            | Action::Connect
            | Action::Extend
            | Action::Delete
            | Action::Undo
            | Action::RedoEdit => self.edit_action(a),
            Action::Export => {
                if self.session.is_none() {
                    self.log.push(
                        Level::Warn,
                        "no session open: open or create one on the Survey screen (1)",
                    );
                    return Vec::new();
                }
                vec![Cmd::Store(StoreCmd::Export)]
            }
            Action::Refresh => vec![Cmd::Store(StoreCmd::Refresh)],
            // Preview navigation is handled by the screens themselves.
            _ => Vec::new(),
        }
    }

    fn answer(&mut self, yes: bool) -> Vec<Cmd> {
        let Some(Modal::Confirm { on_yes, .. }) = self.modal.take() else {
            return Vec::new();
        };
        if !yes {
            self.log.push(Level::Info, "nothing changed");
            return Vec::new();
        }
        match on_yes {
            Pending::RedoImage(k) => self.redo_confirmed(k),
        }
    }

    fn submit(&mut self) -> Vec<Cmd> {
        let Some(Modal::Prompt { text, purpose, .. }) = self.modal.take() else {
            return Vec::new();
        };
        match purpose {
            PromptPurpose::SessionName => {
                match crate::formats::names::SessionName::new(text.trim()) {
                    Ok(n) => vec![Cmd::Store(StoreCmd::Create(n.as_str().to_string()))],
                    Err(e) => {
                        self.log
                            .push(Level::Error, format!("session name refused: {e}"));
                        Vec::new()
                    }
                }
            }
            PromptPurpose::ParamValue => {
                let key = self.pipeline.param_spec().key;
                let mut p = self.params.clone();
                match p.set_str(&format!("{key}={}", text.trim())) {
                    Ok(()) => self.set_params(p),
                    Err(e) => {
                        self.log.push(Level::Error, e.to_string());
                        Vec::new()
                    }
                }
            }
        }
    }

    fn step_param(&mut self, steps: f64) -> Vec<Cmd> {
        let spec = self.pipeline.param_spec();
        let Some(v) = self.params.get(spec.key) else {
            return Vec::new();
        };
        let nv = match spec.kind {
            crate::llv::params::Kind::Bool => {
                if steps > 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
            _ => {
                let raw = v + steps * spec.step;
                // Keep on the step grid so repeated presses do not drift.
                let snapped = (raw / spec.step).round() * spec.step;
                snapped.clamp(spec.min, spec.max)
            }
        };
        if nv == v {
            return Vec::new();
        }
        let mut p = self.params.clone();
        match p.set(spec.key, nv) {
            Ok(()) => self.set_params(p),
            Err(e) => {
                self.log.push(Level::Error, e.to_string());
                Vec::new()
            }
        }
    }

    /// Takes new parameters and re-runs the pipeline on the current image.
    pub fn set_params(&mut self, p: Params) -> Vec<Cmd> {
        self.params = p;
        self.request_pipeline().into_iter().collect()
    }

    /// A pipeline request for the current image (`None` when there is none).
    pub fn request_pipeline(&mut self) -> Option<Cmd> {
        let cur = self.current.as_ref()?;
        if cur.frames.is_empty() {
            return None;
        }
        let ambient = self.ambient;
        let mut images = Vec::new();
        let mut amb = None;
        // Letter order, as the session names the corrected images.
        let mut frames: Vec<&(char, GreyImage)> = cur.frames.iter().collect();
        frames.sort_by_key(|(l, _)| {
            self.letters
                .iter()
                .position(|x| x == l)
                .unwrap_or(usize::MAX)
        });
        for (l, g) in frames {
            if Some(*l) == ambient {
                amb = Some(Arc::new(g.clone()));
            } else {
                images.push(g.clone());
            }
        }
        if images.is_empty() {
            // Only an ambient image: use it as the one image.
            images.extend(amb.take().map(|a| (*a).clone()));
        }
        self.generation += 1;
        let camera = self
            .camera_models
            .get(cur.camera.saturating_sub(1) as usize)
            .copied()
            .flatten();
        Some(Cmd::Pipeline(PipelineRequest {
            generation: self.generation,
            image_key: ImageKey {
                k: cur.k,
                version: cur.version,
            },
            images: Arc::new(images),
            ambient: amb,
            camera,
            params: self.params.clone(),
        }))
    }

    pub(crate) fn next_version(&mut self) -> u64 {
        self.version_counter += 1;
        self.version_counter
    }

    /// Whether a pipeline run is still out.
    pub fn pipeline_busy(&self) -> bool {
        self.generation > self.shown_generation && self.current.is_some()
    }

    /// Why the outputs on screen are not those of the panel's values (a run
    /// still out, the newest run failed, or no run yet), for view titles;
    /// `None` when they are.
    pub fn outputs_stale(&self) -> Option<&'static str> {
        let cur = self.current.as_ref()?;
        if cur.failed.is_some() {
            Some("stale: last run failed")
        } else if self.pipeline_busy() {
            Some("stale: running")
        } else if cur.outputs.is_some() && cur.outputs_params.as_ref() != Some(&self.params) {
            Some("stale: other values")
        } else {
            None
        }
    }

    /// The commands that save the outputs on screen, or `None` (said in the
    /// log) when there is nothing to save or they were not made with the
    /// panel's values: what is saved is always what the panel shows.
    pub(crate) fn save_outputs(&mut self) -> Option<Vec<Cmd>> {
        let Some(cur) = self.current.as_ref() else {
            self.log
                .push(Level::Warn, "nothing to save: no image processed yet");
            return None;
        };
        let (Some(out), Some(params)) = (cur.outputs.clone(), cur.outputs_params.clone()) else {
            self.log.push(
                Level::Warn,
                "nothing to save: the pipeline has not finished",
            );
            return None;
        };
        if let Some(e) = &cur.failed {
            let e = e.clone();
            self.log.push(
                Level::Error,
                format!(
                    "not saved: the last run failed ({e}); the outputs on screen were made \
                     with other values than the panel's — change a value to run again"
                ),
            );
            return None;
        }
        if params != self.params || self.pipeline_busy() {
            self.log.push(
                Level::Warn,
                "not saved: the outputs on screen were not made with the panel's values yet \
                 (a run is still out) — try again when it has finished",
            );
            return None;
        }
        if self.session.is_none() {
            self.log
                .push(Level::Warn, "no session open: outputs are not saved");
            return None;
        }
        // A new .ldr replaces the edited one and clears the session's edit
        // log, so manual edits made since are recorded again on top.
        let edited = cur
            .editor
            .as_ref()
            .map(|e| e.lines().to_vec())
            .filter(|l| *l != out.lines);
        let k = cur.k;
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
        Some(cmds)
    }
}

/// A parameter value as typed: integers without a fraction.
pub fn fmt_value(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e12 {
        format!("{}", v as i64)
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}
