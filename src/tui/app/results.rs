//! How the App takes the workers' reports: pipeline results (newest
//! generation only), device events (frames, progress, lost and found
//! devices, lights) and session results.

use super::{App, Level};
use crate::llv::edit::LineEditor;
use crate::tui::event::{
    Cmd, DeviceCmd, DeviceEvent, FramePurpose, ImageKey, PipelineResult, StoreEvent,
};
use crate::tui::text::clean;

impl App {
    pub(super) fn on_pipeline(&mut self, r: PipelineResult) -> Vec<Cmd> {
        // An older run never overwrites a newer one.
        if r.generation <= self.shown_generation {
            return Vec::new();
        }
        let Some(cur) = self.current.as_mut() else {
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
        self.shown_generation = r.generation;
        match r.outcome {
            Ok(out) => {
                // Lines edited by hand in an earlier run of the console win
                // over the first re-run; a parameter change starts afresh.
                let lines = cur.saved_lines.take().unwrap_or_else(|| out.lines.clone());
                cur.editor = Some(LineEditor::new(lines));
                cur.edits = 0;
                cur.outputs = Some(out);
                cur.outputs_params = Some(r.params);
                cur.failed = None;
                self.edit.selected.clear();
                self.pipeline_done()
            }
            Err(e) => {
                cur.failed = Some(e.clone());
                self.log.push(Level::Error, format!("pipeline: {e}"));
                self.pipeline_failed()
            }
        }
    }

    pub(super) fn on_device(&mut self, ev: DeviceEvent) -> Vec<Cmd> {
        match ev {
            DeviceEvent::Connected { grabber, relay } => {
                let (g, r) = (clean(&grabber), clean(&relay));
                if self.device.lost.take().is_some() {
                    self.log
                        .push(Level::Info, format!("devices back: {g}; {r}"));
                } else {
                    self.log
                        .push(Level::Info, format!("grabber {g}; relay board {r}"));
                }
                self.device.connected = true;
                self.device.grabber = g;
                self.device.relay = r;
                Vec::new()
            }
            DeviceEvent::Lost { error } => {
                let e = clean(&error);
                if self.device.lost.as_deref() != Some(e.as_str()) {
                    self.log.push(
                        Level::Error,
                        format!("device lost: {e} — retrying; saved work is safe"),
                    );
                }
                self.device.connected = false;
                self.device.lost = Some(e);
                self.device.transfer = None;
                Vec::new()
            }
            DeviceEvent::Progress { done, total } => {
                let purpose = self
                    .device
                    .transfer
                    .map(|t| t.0)
                    .unwrap_or(FramePurpose::Snapshot);
                self.device.transfer = Some((purpose, done, total));
                Vec::new()
            }
            DeviceEvent::Frame {
                purpose,
                camera,
                image,
            } => {
                self.device.transfer = None;
                match purpose {
                    FramePurpose::Survey { k, letter } => {
                        self.survey_frame(k, letter, camera, image)
                    }
                    FramePurpose::Live | FramePurpose::Snapshot => {
                        self.live = Some((camera, image));
                        Vec::new()
                    }
                }
            }
            DeviceEvent::CaptureFailed { purpose, error } => {
                self.device.transfer = None;
                self.log
                    .push(Level::Error, format!("capture failed: {}", clean(&error)));
                if let FramePurpose::Survey { .. } = purpose {
                    self.survey_capture_failed();
                }
                Vec::new()
            }
            DeviceEvent::Lights { on, mask } => {
                self.device.lights_on = on.iter().map(|s| clean(s)).collect();
                self.device.mask = mask;
                Vec::new()
            }
            DeviceEvent::Note(n) => {
                self.log.push(Level::Info, clean(&n));
                Vec::new()
            }
        }
    }

    /// Marks the transfer under way with its purpose (the worker's progress
    /// messages carry only numbers).
    pub(crate) fn capture(
        &mut self,
        purpose: FramePurpose,
        camera: u32,
        lighting: Option<char>,
    ) -> Cmd {
        self.device.transfer = Some((purpose, 0, 0));
        Cmd::Device(DeviceCmd::Capture {
            purpose,
            camera,
            lighting,
        })
    }

    pub(super) fn on_store(&mut self, ev: StoreEvent) -> Vec<Cmd> {
        match ev {
            StoreEvent::Sessions(list) => {
                self.sessions = list
                    .into_iter()
                    .map(|(n, p, s)| (clean(&n), p, clean(&s)))
                    .collect();
                self.survey.selected = self
                    .survey
                    .selected
                    .min(self.sessions.len().saturating_sub(1));
                Vec::new()
            }
            StoreEvent::Opened(v) => self.session_opened(v),
            StoreEvent::Updated(v) => {
                self.session = Some(v);
                Vec::new()
            }
            StoreEvent::Images { k, images } => self.images_loaded(k, images),
            StoreEvent::Lines { k, lines } => {
                if let Some(cur) = self.current.as_mut().filter(|c| c.k == k) {
                    self.log.push(
                        Level::Info,
                        format!(
                            "image {k}: {} hand-edited lines from the session",
                            lines.len()
                        ),
                    );
                    match cur.editor.as_mut() {
                        Some(_) if cur.saved_lines.is_none() && cur.outputs.is_some() => {
                            cur.editor = Some(LineEditor::new(lines));
                        }
                        _ => cur.saved_lines = Some(lines),
                    }
                }
                Vec::new()
            }
            StoreEvent::Cameras(models) => {
                self.camera_models = models;
                Vec::new()
            }
            StoreEvent::Saved(what) => {
                self.log
                    .push(Level::Info, format!("saved {}", clean(&what)));
                Vec::new()
            }
            StoreEvent::Reports(paths) => {
                for p in paths {
                    self.log.push(
                        Level::Info,
                        format!("report written: {}", clean(&p.display().to_string())),
                    );
                }
                Vec::new()
            }
            StoreEvent::Error(e) => {
                self.log.push(Level::Error, clean(&e));
                self.survey_store_error();
                Vec::new()
            }
        }
    }
}
