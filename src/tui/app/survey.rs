//! The guided survey: choose or create a session, then per image number
//! capture every lighting, run the stages, review, accept or redo (asking
//! first), and go on; resumes where the session's progress says.

use super::{App, Level, Loaded, Modal, Pending, PromptPurpose};
use crate::llv::GreyImage;
use crate::tui::event::{Cmd, FramePurpose, SessionView, StoreCmd};
use crate::tui::keymap::Action;

/// Where the guided survey stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Phase {
    /// No session open yet.
    #[default]
    NoSession,
    /// Choosing camera and location for image `k`; Enter captures.
    Setup,
    /// Frames of image `k` coming in, one lighting after the other.
    Capturing,
    /// The stages run.
    Processing,
    /// Lines shown; accept or redo.
    Review,
}

/// The survey's position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    pub k: u32,
    pub camera: u32,
    pub location: u32,
    pub phase: Phase,
}

impl App {
    pub(super) fn survey_action(&mut self, a: Action) -> Vec<Cmd> {
        match a {
            Action::NewSession => {
                self.modal = Some(Modal::Prompt {
                    title: "new session name".into(),
                    text: String::new(),
                    purpose: PromptPurpose::SessionName,
                });
                Vec::new()
            }
            Action::SelectUp => {
                self.survey.selected = self.survey.selected.saturating_sub(1);
                Vec::new()
            }
            Action::SelectDown => {
                if self.survey.selected + 1 < self.sessions.len() {
                    self.survey.selected += 1;
                }
                Vec::new()
            }
            Action::OpenSelected => match self.sessions.get(self.survey.selected) {
                Some((_, dir, _)) => vec![Cmd::Store(StoreCmd::Open(dir.clone()))],
                None => {
                    self.log
                        .push(Level::Warn, "no session to open: press n to create one");
                    Vec::new()
                }
            },
            Action::NextStep => match self.work.phase {
                Phase::NoSession => self.survey_action(if self.sessions.is_empty() {
                    Action::NewSession
                } else {
                    Action::OpenSelected
                }),
                Phase::Setup => self.capture_next(),
                Phase::Review => self.survey_action(Action::Accept),
                Phase::Capturing | Phase::Processing => Vec::new(),
            },
            Action::Accept => {
                if self.work.phase != Phase::Review {
                    self.log.push(
                        Level::Warn,
                        "nothing to accept yet: capture and run the image first (Enter)",
                    );
                    return Vec::new();
                }
                let Some(cmds) = self.save_outputs() else {
                    return Vec::new();
                };
                self.log
                    .push(Level::Info, format!("image {} accepted", self.work.k));
                self.work.k += 1;
                self.work.phase = Phase::Setup;
                self.follow_plan();
                cmds
            }
            Action::Redo => {
                let k = self.work.k;
                let captured = self
                    .current
                    .as_ref()
                    .is_some_and(|c| c.k == k && !c.frames.is_empty())
                    || self
                        .session
                        .as_ref()
                        .and_then(|s| s.images.iter().find(|i| i.k == k))
                        .is_some_and(|i| !i.captured.is_empty());
                let k = if captured || k <= 1 { k } else { k - 1 };
                if self.work.phase == Phase::NoSession {
                    return Vec::new();
                }
                self.modal = Some(Modal::Confirm {
                    question: format!(
                        "Redo image {k}? Its saved grey images and outputs will be overwritten."
                    ),
                    on_yes: Pending::RedoImage(k),
                });
                Vec::new()
            }
            Action::CameraNext => {
                if matches!(self.work.phase, Phase::Setup | Phase::NoSession) {
                    self.work.camera = self.work.camera % self.cameras + 1;
                }
                Vec::new()
            }
            Action::LocationNext => {
                if matches!(self.work.phase, Phase::Setup | Phase::NoSession) {
                    self.work.location = self.work.location % 99 + 1;
                }
                Vec::new()
            }
            _ => Vec::new(),
        }
    }

    /// Lighting letters of the survey image not captured yet.
    pub fn missing_letters(&self) -> Vec<char> {
        let have: Vec<char> = match &self.current {
            Some(c) if c.k == self.work.k => c.frames.iter().map(|f| f.0).collect(),
            _ => Vec::new(),
        };
        self.letters
            .iter()
            .copied()
            .filter(|l| !have.contains(l))
            .collect()
    }

    fn capture_next(&mut self) -> Vec<Cmd> {
        if self.session.is_none() {
            return Vec::new();
        }
        match self.missing_letters().first() {
            Some(&letter) => {
                self.work.phase = Phase::Capturing;
                let k = self.work.k;
                vec![self.capture(
                    FramePurpose::Survey { k, letter },
                    self.work.camera,
                    Some(letter),
                )]
            }
            None => {
                self.work.phase = Phase::Processing;
                self.request_pipeline().into_iter().collect()
            }
        }
    }

    pub(super) fn survey_frame(
        &mut self,
        k: u32,
        letter: char,
        camera: u32,
        image: GreyImage,
    ) -> Vec<Cmd> {
        let version = self.next_version();
        let cur = match &mut self.current {
            Some(c) if c.k == k => c,
            slot => slot.insert(Loaded::new(k, camera)),
        };
        cur.camera = camera;
        cur.version = version;
        cur.frames.retain(|f| f.0 != letter);
        cur.frames.push((letter, image.clone()));
        let mut cmds = vec![Cmd::Store(StoreCmd::SaveImage {
            k,
            letter,
            camera,
            location: self.work.location,
            image,
        })];
        if self.work.phase == Phase::Capturing && k == self.work.k {
            cmds.extend(self.capture_next());
        }
        cmds
    }

    pub(super) fn survey_capture_failed(&mut self) {
        if self.work.phase == Phase::Capturing {
            self.work.phase = Phase::Setup;
        }
    }

    pub(super) fn survey_store_error(&mut self) {}

    pub(super) fn pipeline_done(&mut self) -> Vec<Cmd> {
        if self.work.phase == Phase::Processing {
            self.work.phase = Phase::Review;
            if let Some(out) = self.current.as_ref().and_then(|c| c.outputs.as_ref()) {
                self.log.push(
                    Level::Info,
                    format!(
                        "image {}: {} lines — a accepts, r redoes",
                        self.work.k,
                        out.lines.len()
                    ),
                );
            }
        }
        Vec::new()
    }

    pub(super) fn pipeline_failed(&mut self) -> Vec<Cmd> {
        if self.work.phase == Phase::Processing {
            self.work.phase = Phase::Setup;
        }
        Vec::new()
    }

    /// Sets the camera and location of the image about to be captured to
    /// the ones the session has on record for it (the survey's plan, or the
    /// image being redone), as the checklist shows them; an image with no
    /// record keeps the current ones.
    fn follow_plan(&mut self) {
        let k = self.work.k;
        if let Some(i) = self
            .session
            .as_ref()
            .and_then(|s| s.images.iter().find(|i| i.k == k))
        {
            self.work.camera = i.camera.max(1);
            self.work.location = i.location.max(1);
        }
    }

    pub(super) fn session_opened(&mut self, v: SessionView) -> Vec<Cmd> {
        self.log.push(
            Level::Info,
            format!("session {} open in {}", v.name, v.dir.display()),
        );
        let (k, resume) = match v.next {
            Some((k, _)) => (
                k,
                v.images.iter().any(|i| i.k == k && !i.captured.is_empty()),
            ),
            None => (v.images.iter().map(|i| i.k).max().unwrap_or(0) + 1, false),
        };
        self.work = Work {
            k,
            camera: self.work.camera.max(1),
            location: self.work.location.max(1),
            phase: Phase::Setup,
        };
        if resume {
            self.log.push(Level::Info, format!("resuming at image {k}"));
        }
        self.session = Some(v);
        self.follow_plan();
        self.current = None;
        if resume {
            vec![Cmd::Store(StoreCmd::Load(k))]
        } else {
            Vec::new()
        }
    }

    pub(super) fn images_loaded(&mut self, k: u32, images: Vec<(char, GreyImage)>) -> Vec<Cmd> {
        if images.is_empty() {
            return Vec::new();
        }
        let version = self.next_version();
        let camera = if k == self.work.k {
            self.work.camera
        } else {
            1
        };
        let mut l = Loaded::new(k, camera);
        l.frames = images;
        l.version = version;
        self.current = Some(l);
        if k == self.work.k && self.work.phase == Phase::Setup && self.missing_letters().is_empty()
        {
            self.work.phase = Phase::Processing;
        }
        self.request_pipeline().into_iter().collect()
    }

    pub(super) fn redo_confirmed(&mut self, k: u32) -> Vec<Cmd> {
        if self.current.as_ref().is_some_and(|c| c.k == k) {
            self.current = None;
        }
        self.work.k = k;
        self.work.phase = Phase::Setup;
        self.follow_plan();
        self.log.push(
            Level::Info,
            format!("image {k} will be captured again: Enter starts"),
        );
        vec![Cmd::Store(StoreCmd::Redo(k))]
    }
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
            editor: None,
            edits: 0,
            saved_lines: None,
            failed: None,
        }
    }
}
