//! How the App takes the workers' reports: pipeline results (newest
//! generation only), device events (frames, settling and transfer
//! progress, lost and found devices, lights) and session results.

use super::{App, Modal, Pending, Phase};
use crate::llv::edit::LineEditor;
use crate::tui::event::StoreError;
use crate::tui::event::{
    Cmd, DeviceEvent, FramePurpose, ImageKey, PipelineResult, StoreCmd, StoreEvent,
};
use crate::tui::text::clean;

impl App {
    pub(super) fn on_pipeline(&mut self, r: PipelineResult) -> Vec<Cmd> {
        // An older run never overwrites a newer one.
        if r.generation <= self.tracker.shown_generation {
            return Vec::new();
        }
        let Some(cur) = self.tracker.current.as_mut() else {
            return Vec::new();
        };
        if r.image_key
            != (ImageKey {
                k: cur.k,
                version: cur.version,
            })
        {
            return Vec::new();
        }
        self.tracker.shown_generation = r.generation;
        match r.outcome {
            Ok(out) => {
                // Lines edited by hand in an earlier run of the console win
                // over the first re-run; a parameter change starts afresh.
                let lines = cur.saved_lines.take().unwrap_or_else(|| out.lines.clone());
                cur.editor = Some(LineEditor::new(lines));
                cur.edits = 0;
                cur.outputs = Some(out);
                cur.outputs_params = Some(r.params);
                cur.from_disk = false;
                cur.in_session = false;
                cur.failed = None;
                self.screens.edit.clear();
                self.ctx().pipeline_done();
            }
            Err(e) => {
                let e = e.to_string();
                cur.failed = Some(e.clone());
                self.ctx().error(format!(
                    "pipeline: {e} — the views show the last run that worked (stale)"
                ));
                self.ctx().pipeline_failed();
            }
        }
        Vec::new()
    }

    pub(super) fn on_device(&mut self, ev: DeviceEvent) -> Vec<Cmd> {
        let dev = &mut self.cell.device;
        match ev {
            DeviceEvent::Connected { grabber, relay } => {
                let (g, r) = (clean(&grabber), clean(&relay));
                let text = if dev.lost.take().is_some() {
                    format!("devices back: {g}; {r}")
                } else {
                    format!("grabber {g}; relay board {r}")
                };
                dev.connected = true;
                dev.busy = false;
                dev.grabber = g;
                dev.relay = r;
                self.ctx().info(text);
                Vec::new()
            }
            DeviceEvent::Lost { error, busy } => {
                let e = clean(&error);
                let new = dev.lost.as_deref() != Some(e.as_str());
                dev.connected = false;
                dev.lost = Some(e.clone());
                dev.busy = busy;
                dev.transfer = None;
                let word = dev.lost_word().to_ascii_lowercase();
                if new {
                    self.ctx()
                        .error(format!("device {word}: {e} — retrying; saved work is safe"));
                }
                Vec::new()
            }
            DeviceEvent::Settling { .. } => {
                dev.settling = true;
                Vec::new()
            }
            DeviceEvent::Progress { done, total } => {
                let purpose = dev.transfer.map_or(FramePurpose::Snapshot, |t| t.0);
                dev.transfer = Some((purpose, done, total));
                dev.settling = false;
                Vec::new()
            }
            DeviceEvent::Frame {
                purpose,
                camera,
                image,
                settings,
            } => {
                dev.transfer = None;
                dev.settling = false;
                match purpose {
                    FramePurpose::Survey { k, letter } => {
                        self.ctx().survey_frame(k, letter, camera, image, settings)
                    }
                    FramePurpose::Live => {
                        if self.chrome.screen == crate::tui::keymap::ScreenId::Calibrate {
                            self.screens.calibrate.frame(camera, &image);
                        }
                        self.cell.live = Some((camera, image));
                        Vec::new()
                    }
                    FramePurpose::Snapshot => {
                        let (w, h) = image.size();
                        if self.chrome.screen == crate::tui::keymap::ScreenId::Calibrate {
                            self.screens.calibrate.frame(camera, &image);
                        }
                        self.cell.live = Some((camera, image));
                        self.ctx()
                            .info(format!("grabbed a frame of camera {camera}, {w}×{h}"));
                        Vec::new()
                    }
                }
            }
            DeviceEvent::CaptureFailed { purpose, error } => {
                dev.transfer = None;
                dev.settling = false;
                let stopped = std::mem::take(&mut dev.cancelled);
                let mut ctx = self.ctx();
                if stopped {
                    // The operator's own Esc, not a fault of the cell.
                    let what = match purpose {
                        FramePurpose::Survey { letter, .. } => {
                            format!("image {} lighting {letter}", ctx.session.work.k)
                        }
                        _ => "the frame".to_string(),
                    };
                    ctx.info(format!("capture stopped (Esc): {what} not taken"));
                } else {
                    ctx.error(format!("capture failed: {}", clean(&error)));
                }
                if let FramePurpose::Survey { .. } = purpose {
                    ctx.survey_capture_failed();
                }
                Vec::new()
            }
            DeviceEvent::Lights { on, mask } => {
                dev.lights_on = on.iter().map(|s| clean(s)).collect();
                dev.mask = mask;
                Vec::new()
            }
            DeviceEvent::Note(n) => {
                self.ctx().info(clean(&n));
                Vec::new()
            }
            DeviceEvent::CameraSet { grabber, note } => {
                dev.grabber = clean(&grabber);
                self.ctx().info(clean(&note));
                Vec::new()
            }
        }
    }

    pub(super) fn on_store(&mut self, ev: StoreEvent) -> Vec<Cmd> {
        match ev {
            StoreEvent::Sessions(list) => {
                // The highlight stays on its session (by folder) when the
                // list comes again in another order or with others.
                let chosen = self
                    .session
                    .list
                    .get(self.screens.survey.selected)
                    .map(|e| e.dir.clone());
                self.session.list = list
                    .into_iter()
                    .map(|mut e| {
                        e.name = clean(&e.name);
                        e.summary = clean(&e.summary);
                        e.damaged = e.damaged.map(|d| clean(&d));
                        e
                    })
                    .collect();
                let (screens, mut ctx) = self.parts();
                let s = &mut screens.survey;
                let kept = chosen.and_then(|d| ctx.session.list.iter().position(|e| e.dir == d));
                s.selected = kept
                    .unwrap_or(s.selected)
                    .min(ctx.session.list.len().saturating_sub(1));
                // A damaged session asked for: open it now if it reads, or
                // say again why not, from the fresh listing.
                let again = s
                    .recheck
                    .as_ref()
                    .and_then(|dir| ctx.session.list.iter().position(|e| &e.dir == dir));
                match again {
                    Some(i) => {
                        s.selected = i;
                        s.open_selected(&mut ctx)
                    }
                    None => {
                        s.recheck = None;
                        Vec::new()
                    }
                }
            }
            StoreEvent::Opened(v) => {
                self.screens.survey.picking = false;
                self.screens.survey.row = None;
                let problems = v.problems();
                let read_only = v.read_only.then(|| v.name.clone());
                let mut ctx = self.ctx();
                let cmds = ctx.session_opened(v);
                if let Some(name) = read_only {
                    ctx.warn(format!(
                        "{} — session {name} is open only to look: capture, accept, edit, \
                         save and reports are refused",
                        super::READ_ONLY
                    ));
                }
                if problems > 0 {
                    ctx.error(format!(
                        "{problems} damaged or missing file(s) in this session: the checklist \
                         marks them, 5 lists them"
                    ));
                }
                cmds
            }
            StoreEvent::Updated(v) => {
                self.session.view = Some(v);
                Vec::new()
            }
            StoreEvent::Loaded(img) => self.ctx().images_loaded(*img),
            StoreEvent::Cameras(models) => {
                let models: Vec<_> = models
                    .into_iter()
                    .map(|m| m.map_err(|e| clean(&e)))
                    .collect();
                let enabled = self.tracker.params.lens.enabled;
                // One line per reason, naming its cameras: a profile that
                // names no .cdf at all gets one line, not one a camera.
                let mut problems: Vec<(Vec<String>, String)> = Vec::new();
                for (i, m) in models.iter().enumerate() {
                    if let Err(e) = m {
                        match problems.iter_mut().find(|p| p.1 == *e) {
                            Some(p) => p.0.push((i + 1).to_string()),
                            None => problems.push((vec![(i + 1).to_string()], e.clone())),
                        }
                    }
                }
                self.cell.camera_models = models;
                if enabled {
                    for (cams, why) in problems {
                        let s = if cams.len() == 1 { "" } else { "s" };
                        self.ctx().warn(format!(
                            "lens correction OFF for camera{s} {}: {why}",
                            cams.join(", ")
                        ));
                    }
                }
                Vec::new()
            }
            StoreEvent::Saved(what) => {
                self.ctx().info(format!("saved {}", clean(&what)));
                Vec::new()
            }
            StoreEvent::OutputsSaved(k) => {
                self.session.saving.retain(|&s| s != k);
                self.session.saved(k);
                self.ctx().info(format!(
                    "image {k} accepted: outputs saved (.hpo .vpo .lex .ldr)"
                ));
                Vec::new()
            }
            StoreEvent::EditSaved { k, file } => {
                // The whole line set is written: an edit that failed before
                // is in it now.
                if self.session.refused.iter().any(|r| r.k == k && r.edit) {
                    self.session.saved(k);
                }
                self.ctx().info(format!("saved {}", clean(&file)));
                Vec::new()
            }
            StoreEvent::EditNotSaved { k, error } => {
                // Counted as outputs not saved: q asks, the next-step box
                // says it, a saves the outputs with the edits.
                self.session.refuse(k, cause(&error), true);
                self.ctx().error(format!(
                    "{} — the lines on screen are not saved; the next edit, or a, writes them",
                    clean(&error.to_string())
                ));
                Vec::new()
            }
            StoreEvent::Note(what) => {
                self.ctx().info(clean(&what));
                Vec::new()
            }
            StoreEvent::Warning(what) => {
                self.ctx().warn(clean(&what));
                Vec::new()
            }
            StoreEvent::OpeningDone => {
                if !self.session.opening.is_empty() {
                    self.session.opening.remove(0);
                }
                Vec::new()
            }
            StoreEvent::Reports { paths, problems } => {
                // One message: the survey's page and how many image pages,
                // and the problems the report shows (said here, not only
                // inside the pages): those the report marks, as `vss
                // report` says them, else the damage the session's check
                // found.
                let ps = paths
                    .iter()
                    .find(|p| p.extension().is_some_and(|e| e == "ps"))
                    .or(paths.first())
                    .map(crate::text::path)
                    .unwrap_or_default();
                let svg = paths
                    .iter()
                    .filter(|p| p.extension().is_some_and(|e| e == "svg"))
                    .count();
                let problems = if problems.is_empty() {
                    self.session
                        .view
                        .as_ref()
                        .map(|v| v.problem_list())
                        .unwrap_or_default()
                } else {
                    problems.iter().map(|p| clean(p)).collect()
                };
                let text = format!("report written: {ps} and {svg} SVG page(s)");
                if problems.is_empty() {
                    self.ctx().info(text);
                } else {
                    self.ctx().warn(format!(
                        "{text} — {} problem(s) marked in it: {}",
                        problems.len(),
                        problems.join(", ")
                    ));
                }
                Vec::new()
            }
            StoreEvent::Unwritable { dir, why } => {
                let (shown, why) = (crate::text::path(&dir), clean(&why));
                let mut ctx = self.ctx();
                ctx.error(format!(
                    "session {shown} cannot be opened to work on: {why}"
                ));
                ctx.ask(
                    "The session's folder cannot be written. Open it read-only, only to look at \
                     its images, lines and files? Nothing will be saved.",
                    Pending::OpenReadOnly(dir),
                );
                Vec::new()
            }
            StoreEvent::Locked { dir, holder } => {
                let holder = clean(&holder);
                let mut ctx = self.ctx();
                ctx.error(format!(
                    "session {} is open in another console that still runs ({holder}). If \
                     that is your own console in a detached tmux or screen (an SSH drop), go \
                     back to it: `tmux attach`. Taking it over makes that console's saves fail; \
                     looking at it read-only leaves that console alone.",
                    crate::text::path(&dir)
                ));
                // Looking is the read-only open of an unwritable folder:
                // no lock written, no request made, nothing saved.
                ctx.chrome.modal = Some(Modal::Confirm {
                    question: format!(
                        "Session held by {holder}, which still runs (try `tmux attach` first). \
                         r only looks at it, read-only: nothing is saved, that console keeps \
                         it undisturbed. y takes it over: that console's saves then fail. \
                         Take it over anyway?"
                    ),
                    on_yes: Pending::TakeOver(dir.clone()),
                    on_all: None,
                    on_look: Some(Pending::OpenReadOnly(dir)),
                });
                Vec::new()
            }
            StoreEvent::Left { dir, by } => {
                self.session_left();
                self.ctx().error(format!(
                    "session {} was taken over by {} at its request: this console no longer \
                     writes it (what it had saved is on disk); choose or create a session",
                    crate::text::path(&dir),
                    clean(&by)
                ));
                Vec::new()
            }
            StoreEvent::LogFile(path) => {
                let p = crate::text::path(&path);
                self.chrome.log.set_file(path);
                self.ctx().info(format!("log file: {p}"));
                Vec::new()
            }
            StoreEvent::FrameNotSaved { k, letter, error } => {
                // The whole error for the log; the session's reason (which
                // file, why) for the checklist and the questions.
                let why = cause(&error);
                let mut ctx = self.ctx();
                ctx.error(format!(
                    "{} — image {k} is not accepted until R captures it again",
                    clean(&error.to_string())
                ));
                ctx.frame_not_saved(k, letter, why);
                Vec::new()
            }
            StoreEvent::OutputsNotSaved { k, error } => {
                self.session.saving.retain(|&s| s != k);
                self.session.refuse(k, cause(&error), false);
                let mut ctx = self.ctx();
                ctx.error(format!(
                    "{} — image {k} is not accepted; a tries again once that is put right",
                    clean(&error.to_string())
                ));
                ctx.outputs_not_saved(k);
                Vec::new()
            }
            StoreEvent::Error(e) => {
                let mut ctx = self.ctx();
                ctx.error(clean(&e.to_string()));
                if ctx.session.work.phase == Phase::Processing {
                    ctx.session.work.phase = Phase::Setup;
                }
                Vec::new()
            }
        }
    }

    /// Back to no session, on the Survey screen's session list: another
    /// console took the session over at its request.
    fn session_left(&mut self) {
        self.session.view = None;
        self.session.saving.clear();
        self.session.refused.clear();
        self.session.work.phase = Phase::NoSession;
        self.tracker.current = None;
        self.screens.survey.picking = false;
        self.screens.survey.row = None;
        self.chrome.screen = crate::tui::keymap::ScreenId::Survey;
    }

    /// The log lines written since the last call, for the log file.
    pub fn take_log_lines(&mut self) -> Option<Cmd> {
        let lines = self.chrome.log.take_unwritten();
        (!lines.is_empty()).then_some(Cmd::Store(StoreCmd::Log(lines)))
    }
}

/// The session's reason in a store error (which file, why), without what
/// was being done: for the checklist, the next-step box and the questions;
/// the whole error goes to the log.
fn cause(error: &StoreError) -> String {
    match error {
        StoreError::Session { source, .. } => clean(&source.to_string()),
        e => clean(&e.to_string()),
    }
}
