//! The guided survey: choose or create a session, then per image number
//! capture every lighting, run the stages, review, accept or capture again
//! (asking first), and go on; resumes where the session's progress says.
//! Any image of the checklist can be gone back to: its saved frames,
//! outputs and lines load into the Pipeline and Edit screens.

use super::{CellState, Ctx, Loaded, Modal, Pending, PreviewNav, PromptPurpose, Tracker};
use crate::formats::names::MAX_SESSION_LEN;
use crate::llv::GreyImage;
use crate::session::FrameSettings;
use crate::tui::event::{
    Cmd, DeviceCmd, FramePurpose, ImageState, LoadedImage, SessionView, StoreCmd,
};
use crate::tui::keymap::SurveyAction;

mod retake;

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
    /// Lines shown; accept or capture again.
    Review,
    /// Every planned image is done.
    Complete,
}

/// The survey's position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    pub k: u32,
    pub camera: u32,
    pub location: u32,
    pub phase: Phase,
}

/// The Survey screen's own state.
#[derive(Clone, Debug, Default)]
pub struct SurveyScreen {
    /// The highlighted session of the list.
    pub selected: usize,
    /// The list of sessions is shown over the open session's checklist.
    pub picking: bool,
    /// The highlighted image of the checklist (`None`: the one under work).
    pub row: Option<u32>,
    pub nav: PreviewNav,
    /// A session listed as damaged that the operator asked to open: the
    /// list is read again and it opens if it now reads (it may have been
    /// mended while the console ran).
    pub recheck: Option<std::path::PathBuf>,
}

/// The rule of session names, shown before typing one.
pub const NAME_RULE: &str = "letters a-z A-Z, digits, _ and -, starting with a letter or _, at most \
     32; end with a letter: q1 would name its image 1 q11a.img, which reads as image 11 of q";

impl SurveyScreen {
    /// The checklist row the keys act on.
    pub fn row(&self, ctx_work: &Work) -> u32 {
        self.row.unwrap_or(ctx_work.k)
    }

    pub fn update(&mut self, a: SurveyAction, ctx: &mut Ctx) -> Vec<Cmd> {
        let listing = self.picking || ctx.session.view.is_none();
        if self.picking && a.on_the_image() {
            // The checklist is hidden behind the list: a key that changes an
            // image there would change what the operator cannot see.
            ctx.warn("the session list is open: Esc goes back to the checklist first");
            return Vec::new();
        }
        match a {
            SurveyAction::NewSession => {
                ctx.chrome.modal = Some(Modal::prompt(
                    "new session name:",
                    NAME_RULE,
                    String::new(),
                    MAX_SESSION_LEN,
                    PromptPurpose::SessionName,
                ));
                Vec::new()
            }
            SurveyAction::OpenPicker => {
                if ctx.session.list.is_empty() {
                    ctx.warn("no session in the survey folder yet: n creates one");
                    return Vec::new();
                }
                if ctx.session.view.is_none() {
                    // The list on screen already is the picker.
                    ctx.info("the sessions are listed here: ↑↓ chooses, Enter opens");
                    return Vec::new();
                }
                self.picking = !self.picking || ctx.session.view.is_none();
                if let Some(v) = &ctx.session.view
                    && let Some(i) = ctx.session.list.iter().position(|e| e.dir == v.dir)
                {
                    self.selected = i;
                }
                if self.picking {
                    ctx.info("choose a session: ↑↓, Enter opens it, o goes back");
                }
                Vec::new()
            }
            SurveyAction::Up | SurveyAction::Down if listing => {
                let n = ctx.session.list.len();
                if a == SurveyAction::Up {
                    self.selected = self.selected.saturating_sub(1);
                } else if self.selected + 1 < n {
                    self.selected += 1;
                }
                Vec::new()
            }
            SurveyAction::Up | SurveyAction::Down => {
                let ks = ctx.session.numbers();
                let now = self.row(&ctx.session.work);
                let pos = ks.iter().position(|&k| k == now);
                let next = match (a, pos) {
                    (SurveyAction::Up, Some(p)) => ks.get(p.saturating_sub(1)),
                    (SurveyAction::Up, None) => ks.last(),
                    (_, Some(p)) => ks.get(p + 1).or(ks.last()),
                    (_, None) => ks.first(),
                };
                self.row = next.copied();
                Vec::new()
            }
            SurveyAction::Enter if listing => self.open_selected(ctx),
            SurveyAction::Enter => {
                let row = self.row(&ctx.session.work);
                if row != ctx.session.work.k {
                    self.row = None;
                    return ctx.go_to(row);
                }
                match ctx.session.work.phase {
                    Phase::Setup => ctx.capture_next(),
                    Phase::Review => {
                        let k = ctx.session.work.k;
                        ctx.ask(
                            format!("Accept image {k} and go on to the next image?"),
                            Pending::Accept,
                        );
                        Vec::new()
                    }
                    Phase::Complete => {
                        let k = ctx.session.work.k;
                        ctx.ask(
                            format!(
                                "Every planned image is done. Start image {k}, beyond the plan?"
                            ),
                            Pending::ExtraImage(k),
                        );
                        Vec::new()
                    }
                    Phase::Capturing | Phase::Processing => {
                        ctx.info("busy with this image: wait for it, or Esc stops the capture");
                        Vec::new()
                    }
                    Phase::NoSession => Vec::new(),
                }
            }
            SurveyAction::Accept => ctx.accept(false),
            SurveyAction::ResetParams => ctx.reset_params(None),
            SurveyAction::Redo => {
                let k = self.row(&ctx.session.work);
                self.row = None;
                ctx.ask_retake(k);
                Vec::new()
            }
            SurveyAction::Camera | SurveyAction::Location => {
                let w = &mut ctx.session.work;
                if w.phase != Phase::Setup {
                    ctx.warn(
                        "camera (c) and location (p) are chosen before an image's capture \
                         starts, not while it runs or after it",
                    );
                    return Vec::new();
                }
                if a == SurveyAction::Camera {
                    w.camera = w.camera % ctx.cell.cameras + 1;
                } else {
                    w.location = w.location % 99 + 1;
                }
                let (k, c, l) = (w.k, w.camera, w.location);
                ctx.info(format!("image {k}: camera {c}, location {l}"));
                Vec::new()
            }
            SurveyAction::CancelCapture => {
                if self.picking {
                    self.picking = false;
                    return Vec::new();
                }
                if ctx.cell.device.transfer.is_none() && ctx.session.work.phase != Phase::Capturing
                {
                    self.row = None;
                    return Vec::new();
                }
                super::App::cancel_transfer(ctx)
            }
        }
    }

    pub(super) fn open_selected(&mut self, ctx: &mut Ctx) -> Vec<Cmd> {
        let Some(e) = ctx.session.list.get(self.selected).cloned() else {
            ctx.warn("no session to open: n creates one");
            return Vec::new();
        };
        if e.damaged.is_some() && self.recheck.as_deref() != Some(e.dir.as_path()) {
            // The listing may be older than a mend: read it again first.
            self.recheck = Some(e.dir);
            return vec![Cmd::Store(StoreCmd::List)];
        }
        self.recheck = None;
        if let Some(why) = &e.damaged {
            ctx.error(format!(
                "session {} cannot be opened: {why} — `vss session check {}` lists every \
                 problem; mend or move the folder, then open it again",
                e.name,
                crate::text::path(&e.dir)
            ));
            ctx.chrome.overlay = Some(super::Overlay::Message { scroll: 0 });
            return Vec::new();
        }
        if matches!(ctx.session.work.phase, Phase::Capturing | Phase::Processing) {
            ctx.warn("a capture or run is under way: wait for it before switching sessions");
            return Vec::new();
        }
        let open = ctx.session.view.as_ref();
        match open.map(|v| (v.dir == e.dir, v.read_only, v.name.clone())) {
            Some((true, false, _)) => {
                self.picking = false;
                Vec::new()
            }
            // Open here only to look: choosing it again asks for it to
            // write (its holder may have gone: an SSH drop ended it); the
            // store says whether it got it, or asks as for any held one.
            Some((true, true, _)) => {
                self.picking = false;
                ctx.info(format!(
                    "session {}: open here only to look — asking for it to write",
                    e.name
                ));
                vec![Cmd::Store(StoreCmd::Open(e.dir))]
            }
            Some((false, _, name)) => {
                let q = format!("Leave session {name} and open session {}?", e.name);
                ctx.ask(q, Pending::Switch(e.dir));
                self.picking = false;
                Vec::new()
            }
            None => {
                self.picking = false;
                vec![Cmd::Store(StoreCmd::Open(e.dir))]
            }
        }
    }
}

/// Lighting letters of the image under work not captured yet.
pub fn missing_letters(cell: &CellState, work: &Work, tracker: &Tracker) -> Vec<char> {
    match &tracker.current {
        Some(c) if c.k == work.k => c.missing(&cell.letters),
        _ => cell.letters.clone(),
    }
}

impl Ctx<'_> {
    /// Lighting letters of the survey image not captured yet.
    pub fn missing_letters(&self) -> Vec<char> {
        missing_letters(self.cell, &self.session.work, self.tracker)
    }

    /// Steps `camera` to the next one (wrapping); a live view follows it.
    /// The Capture and Calibrate screens each keep their own camera.
    pub fn next_camera(&mut self, camera: &mut u32) -> Vec<Cmd> {
        *camera = *camera % self.cell.cameras + 1;
        self.info(format!("camera {camera}"));
        if self.cell.device.live {
            return vec![Cmd::Device(DeviceCmd::Live {
                on: true,
                camera: *camera,
            })];
        }
        Vec::new()
    }

    /// Turns the live view of `camera` on, or off.
    pub fn toggle_live(&mut self, camera: u32) -> Vec<Cmd> {
        self.cell.device.live = !self.cell.device.live;
        vec![Cmd::Device(DeviceCmd::Live {
            on: self.cell.device.live,
            camera,
        })]
    }

    /// Grabs one frame of `camera` as it is lit now.
    pub fn grab(&mut self, camera: u32) -> Vec<Cmd> {
        self.info(format!("grabbing a frame of camera {camera}"));
        vec![self.capture(FramePurpose::Snapshot, camera, None)]
    }

    /// Marks the transfer under way with its purpose (the worker's progress
    /// messages carry only numbers).
    pub fn capture(&mut self, purpose: FramePurpose, camera: u32, lighting: Option<char>) -> Cmd {
        self.cell.device.transfer = Some((purpose, 0, 0));
        self.cell.device.settling = lighting.is_some();
        Cmd::Device(DeviceCmd::Capture {
            purpose,
            camera,
            lighting,
        })
    }

    pub fn capture_next(&mut self) -> Vec<Cmd> {
        if self.session.view.is_none() {
            return Vec::new();
        }
        match self.missing_letters().first() {
            Some(&letter) => {
                self.session.work.phase = Phase::Capturing;
                let (k, cam) = (self.session.work.k, self.session.work.camera);
                vec![self.capture(FramePurpose::Survey { k, letter }, cam, Some(letter))]
            }
            None => {
                self.session.work.phase = Phase::Processing;
                self.run_current().into_iter().collect()
            }
        }
    }

    pub fn survey_frame(
        &mut self,
        k: u32,
        letter: char,
        camera: u32,
        image: GreyImage,
        settings: FrameSettings,
    ) -> Vec<Cmd> {
        let version = self.tracker.next_version();
        let accepted = self.session.accepted(k);
        let cur = match &mut self.tracker.current {
            Some(c) if c.k == k => c,
            slot => {
                let mut l = Loaded::new(k, camera);
                l.accepted = accepted;
                slot.insert(l)
            }
        };
        cur.camera = camera;
        // A new frame runs with the camera as read now, which the store
        // records with the image if it was recorded with another.
        cur.recorded_camera = None;
        cur.version = version;
        cur.frames.retain(|f| f.0 != letter);
        cur.damaged.retain(|d| d.0 != letter);
        cur.unsaved.retain(|d| d.0 != letter);
        cur.frames.push((letter, image.clone()));
        // Frames newer than the outputs: those, and hand edits of them, are
        // an older capture's.
        cur.outputs = None;
        cur.outputs_params = None;
        cur.editor = None;
        cur.saved_lines = None;
        self.info(format!("image {k}: lighting {letter} captured"));
        let mut cmds = vec![Cmd::Store(StoreCmd::SaveImage {
            k,
            letter,
            camera,
            location: self.session.work.location,
            image,
            settings,
        })];
        if self.session.work.phase == Phase::Capturing && k == self.session.work.k {
            cmds.extend(self.capture_next());
        }
        cmds
    }

    pub fn survey_capture_failed(&mut self) {
        if self.session.work.phase == Phase::Capturing {
            self.session.work.phase = Phase::Setup;
        }
    }

    pub fn pipeline_done(&mut self) {
        let k = self.session.work.k;
        if self.session.work.phase == Phase::Processing
            && self.tracker.current.as_ref().is_some_and(|c| c.k == k)
        {
            self.session.work.phase = Phase::Review;
            let n = self
                .tracker
                .current
                .as_ref()
                .and_then(|c| c.lines())
                .map_or(0, <[_]>::len);
            match self.tracker.current.as_ref() {
                Some(c) if !c.unsaved.is_empty() => {
                    let msg = not_saved_message(c);
                    self.error(format!("image {k}: {n} lines, but {msg}"));
                }
                // Only looking: nothing to accept, capture, tune or edit.
                _ if self.session.read_only() => self.info(format!("image {k}: {n} lines")),
                _ => self.info(format!(
                    "image {k}: {n} lines — a accepts, R captures again, 3 tunes, 4 edits"
                )),
            }
        }
    }

    /// The session could not save image `k`'s outputs: the outputs on
    /// screen are not the session's, and a survey that went on from `k` to
    /// an image not yet begun comes back to `k` for review.
    pub fn outputs_not_saved(&mut self, k: u32) {
        let accepted = self.session.accepted(k);
        let Some(c) = self.tracker.current.as_mut().filter(|c| c.k == k) else {
            return;
        };
        c.in_session = false;
        c.accepted = accepted;
        let w = &self.session.work;
        if w.k != k && matches!(w.phase, Phase::Setup | Phase::Complete) && c.outputs.is_some() {
            self.session.work.k = k;
            self.session.work.phase = Phase::Review;
            self.follow_plan();
        }
    }

    /// The session could not save lighting `letter` of image `k`, captured
    /// in this run: the checklist marks it and the image is not accepted
    /// until it is captured again.
    pub fn frame_not_saved(&mut self, k: u32, letter: char, why: String) {
        if let Some(c) = self.tracker.current.as_mut().filter(|c| c.k == k) {
            c.unsaved.retain(|d| d.0 != letter);
            c.unsaved.push((letter, why));
        }
    }

    pub fn pipeline_failed(&mut self) {
        if self.session.work.phase == Phase::Processing {
            self.session.work.phase = Phase::Setup;
        }
    }

    /// Sets the camera and location of the image about to be captured to
    /// the ones the session has on record for it (the survey's plan, or the
    /// image being redone), as the checklist shows them; an image with no
    /// record keeps the current ones.
    fn follow_plan(&mut self) {
        let k = self.session.work.k;
        if let Some((c, l)) = self.session.image(k).map(|i| (i.camera, i.location)) {
            self.session.work.camera = c.max(1);
            self.session.work.location = l.max(1);
        }
    }

    pub fn session_opened(&mut self, v: SessionView) -> Vec<Cmd> {
        self.session.saving.clear();
        self.session.refused.clear();
        self.info(format!(
            "session {} open in {}",
            v.name,
            crate::text::path(&v.dir)
        ));
        let last = v
            .images
            .iter()
            .filter(|i| !i.captured.is_empty())
            .map(|i| i.k)
            .max();
        let (k, phase) = match v.next {
            Some((k, _)) => (k, Phase::Setup),
            None => (
                v.images.iter().map(|i| i.k).max().unwrap_or(0) + 1,
                if v.images.is_empty() {
                    Phase::Setup
                } else {
                    Phase::Complete
                },
            ),
        };
        let resume = v.images.iter().any(|i| i.k == k && !i.captured.is_empty());
        // Open only to look, nothing can be captured: the view opens on the
        // newest image with results instead (none done: the newest with
        // frames), as choosing it shows it.
        let newest =
            |f: fn(&ImageState) -> bool| v.images.iter().filter(|i| f(i)).map(|i| i.k).max();
        let look_at = v
            .read_only
            .then(|| newest(ImageState::done).or_else(|| newest(|i| !i.captured.is_empty())))
            .flatten();
        self.session.work = Work {
            k,
            camera: self.session.work.camera.max(1),
            location: self.session.work.location.max(1),
            phase,
        };
        if phase == Phase::Complete {
            let text = v.complete_text();
            let text = match text.strip_prefix("Survey complete") {
                Some(_) => "survey complete".to_string(),
                None => text,
            };
            self.info(format!(
                "{text}: 5 writes the report; ↑↓ Enter goes back to an image, \
                 Enter on no image starts image {k} beyond the plan"
            ));
        }
        self.session.view = Some(v);
        self.follow_plan();
        self.tracker.current = None;
        if let Some(d) = look_at {
            return self.go_to(d);
        }
        // The image the survey goes on with, or the last one worked on, so
        // the Pipeline and Edit screens show it at once.
        match (resume, last) {
            (true, _) => {
                self.info(format!("resuming at image {k}"));
                self.resume_with_the_survey_s_values(k);
                vec![Cmd::Store(StoreCmd::Load(k))]
            }
            (false, Some(l)) => vec![Cmd::Store(StoreCmd::Load(l))],
            (false, None) => Vec::new(),
        }
    }

    /// An image read back from the session: its good frames, and its
    /// saved outputs and lines when they are current.
    pub fn images_loaded(&mut self, img: LoadedImage) -> Vec<Cmd> {
        let k = img.k;
        let work_k = self.session.work.k;
        for (l, why) in &img.damaged {
            self.error(format!(
                "image {k} lighting {l}: {why} — R captures it again"
            ));
        }
        if img.images.is_empty() && img.damaged.is_empty() {
            return Vec::new();
        }
        if img.damaged.is_empty()
            && let Some(why) = &img.outputs_damaged
        {
            self.error(format!(
                "image {k}: its saved outputs do not read ({why}) — R makes them again from \
                 its saved frames with its recorded values"
            ));
        }
        // Run again (or captured again in part) with what the image was
        // made with, never with values tuned on another image.
        if img.saved.is_none() {
            self.use_recorded_params(k);
        }
        let version = self.tracker.next_version();
        let camera = if k == work_k {
            self.session.work.camera
        } else {
            self.session.image(k).map_or(1, |i| i.camera.max(1))
        };
        let mut l = Loaded::new(k, camera);
        l.frames = img.images;
        l.damaged = img.damaged;
        l.version = version;
        l.accepted = img.accepted;
        l.recorded_camera = img.camera;
        let complete = self.cell.letters.iter().all(|c| l.frame(*c).is_some());
        // Not run (`run_current` says why when it would be): its frames,
        // and its saved outputs, are shown.
        if !(complete && img.saved.is_none())
            && let Some(why) = l.camera_refused()
        {
            self.error(why.to_string());
        }
        let mut cmds = Vec::new();
        match img.saved {
            Some(saved) if complete => {
                if saved.params != self.tracker.params {
                    self.info(format!(
                        "image {k}: the parameter panel now shows the values its outputs were made with"
                    ));
                    self.tracker.params = saved.params.clone();
                }
                let lines = img.lines.unwrap_or_else(|| saved.outputs.lines.clone());
                l.editor = Some(crate::llv::edit::LineEditor::new(lines));
                l.outputs = Some(std::sync::Arc::new(saved.outputs));
                l.outputs_params = Some(saved.params);
                l.from_disk = true;
                l.in_session = true;
                // Nothing runs: what is shown is what the session holds.
                self.tracker.shown_generation = self.tracker.generation;
                self.tracker.current = Some(l);
                if k == work_k && self.session.work.phase == Phase::Setup {
                    self.session.work.phase = Phase::Review;
                }
                self.info(format!("image {k}: saved outputs and lines loaded"));
            }
            _ => {
                l.saved_lines = img.lines;
                self.tracker.current = Some(l);
                if complete {
                    if k == work_k && self.session.work.phase == Phase::Setup {
                        self.session.work.phase = Phase::Processing;
                    }
                    cmds.extend(self.run_current());
                }
            }
        }
        cmds
    }

    /// Makes image `k` the image under work, in Setup, with the plan's
    /// camera and location; refused (said, `false`) while a capture or a
    /// run of the image under work is out.
    pub(super) fn set_image_under_work(&mut self, k: u32) -> bool {
        if matches!(
            self.session.work.phase,
            Phase::Capturing | Phase::Processing
        ) {
            self.warn("busy with the image under work: wait for it, or Esc stops the capture");
            return false;
        }
        self.session.work.k = k;
        self.session.work.phase = Phase::Setup;
        self.follow_plan();
        true
    }

    /// Makes image `k` the one the survey works on, loading what the
    /// session holds of it.
    pub fn go_to(&mut self, k: u32) -> Vec<Cmd> {
        if !self.set_image_under_work(k) {
            return Vec::new();
        }
        let captured = self
            .session
            .image(k)
            .is_some_and(|i| !i.captured.is_empty());
        match &self.tracker.current {
            Some(c) if c.k == k && c.outputs.is_some() => {
                self.session.work.phase = Phase::Review;
                self.info(format!("image {k}: its outputs are on screen"));
                Vec::new()
            }
            _ if captured => {
                self.info(format!("image {k}: loading its frames and outputs"));
                vec![Cmd::Store(StoreCmd::Load(k))]
            }
            _ => {
                let w = &self.session.work;
                self.info(format!(
                    "image {k}: nothing captured yet — Enter captures it (camera {}, location {})",
                    w.camera, w.location
                ));
                Vec::new()
            }
        }
    }

    /// Accepts the image under review: saves its outputs when they differ
    /// from the session's (asking first when that replaces accepted ones)
    /// and goes on to the next image the survey needs.
    pub fn accept(&mut self, confirmed: bool) -> Vec<Cmd> {
        let k = self.session.work.k;
        let cur = self.tracker.current.as_ref().filter(|c| c.k == k);
        if self.session.work.phase != Phase::Review || cur.is_none() {
            self.warn("nothing to accept: capture and run an image first (Enter)");
            return Vec::new();
        }
        if let Some(c) = cur.filter(|c| !c.unsaved.is_empty()) {
            let msg = not_saved_message(c);
            self.error(format!("image {k} NOT accepted: {msg}"));
            return Vec::new();
        }
        // Outputs the session already holds (hand edits are written as they
        // are made): nothing to save, nothing to ask.
        let unchanged = cur.is_some_and(|c| c.saved_with(&self.tracker.params));
        let mut cmds = Vec::new();
        if unchanged {
            self.info(format!("image {k} accepted"));
        } else {
            if cur.is_some_and(|c| c.accepted) && !confirmed {
                self.ask(
                    format!(
                        "Image {k} is accepted. Replace its saved outputs (and the hand edits \
                         of its .ldr) with the ones on screen, and go on?"
                    ),
                    Pending::Accept,
                );
                return Vec::new();
            }
            match self.save_outputs(true) {
                Some(c) => cmds = c,
                None => return Vec::new(),
            }
            self.session.saving.push(k);
            // "accepted" is said when the store has the files.
            self.info(format!("image {k}: saving its outputs"));
        }
        self.next_image(k);
        if let Some(n) = self.session.image(self.session.work.k)
            && !n.captured.is_empty()
            && self.session.work.phase == Phase::Setup
        {
            cmds.push(Cmd::Store(StoreCmd::Load(n.k)));
        }
        cmds
    }

    /// Moves the survey on from image `done` to the first image the
    /// checklist still needs, or announces the end of the plan.
    fn next_image(&mut self, done: u32) {
        let saving = &self.session.saving;
        let next = self.session.view.as_ref().and_then(|v| {
            v.images
                .iter()
                // Accepted a moment ago, saved any moment now: not the next.
                .filter(|i| i.k != done && !saving.contains(&i.k))
                .find(|i| !(i.outputs && !i.stale && i.damaged.is_empty()))
                .map(|i| i.k)
        });
        let planned = self.session.view.as_ref().map_or(0, |v| v.images.len());
        match next {
            Some(k) => {
                self.session.work.k = k;
                self.session.work.phase = Phase::Setup;
                self.follow_plan();
            }
            None if planned > 0 => {
                let max = self.session.numbers().into_iter().max().unwrap_or(done);
                self.session.work.k = max.max(done) + 1;
                self.session.work.phase = Phase::Complete;
                let problems = self
                    .session
                    .view
                    .as_ref()
                    .map(|v| v.problem_list())
                    .unwrap_or_default();
                if problems.is_empty() {
                    self.warn(format!(
                        "survey complete: all {planned} planned images done — 5 writes the report"
                    ));
                } else {
                    self.error(format!(
                        "survey complete, {} problem(s): {} — all {planned} planned images \
                         done; R on one puts it right, 5 writes the report",
                        problems.len(),
                        problems.join(", ")
                    ));
                }
            }
            None => {
                self.session.work.k = done + 1;
                self.session.work.phase = Phase::Setup;
            }
        }
    }

    /// Starts an image beyond the plan (the operator said so).
    pub fn extra_image(&mut self, k: u32) -> Vec<Cmd> {
        self.session.work.k = k;
        self.session.work.phase = Phase::Setup;
        self.info(format!(
            "image {k}, beyond the plan: camera {} location {} — Enter captures",
            self.session.work.camera, self.session.work.location
        ));
        Vec::new()
    }
}

/// What an image with lightings the session could not save needs: which,
/// why (the first one's error) and what to do.
fn not_saved_message(c: &Loaded) -> String {
    let letters = c.unsaved_letters();
    let why = c.unsaved.first().map_or("", |d| d.1.as_str());
    format!("{letters} NOT saved ({why}); once that is put right, R captures it again")
}
