//! The pipeline worker: runs the LLV stages off the UI thread. Latest wins —
//! a request waiting when a newer one arrives is dropped unseen — and when
//! only parameters changed on the same images it re-runs from the first
//! affected stage (the session code's `Runner::run_changed`, as `vss
//! session redo` runs). Results carry the request's generation so the UI
//! never lets an older run overwrite a newer one.

use std::sync::{Arc, Condvar, Mutex};

use super::send;
use crate::llv::lens::CameraModel;
use crate::llv::pipeline::StageOutputs;
use crate::session::input::Runner;
use crate::tui::event::{Msg, PipelineRequest, PipelineResult};

#[derive(Default)]
struct Slot {
    request: Option<PipelineRequest>,
    closed: bool,
}

/// The UI's handle: `send` replaces any request still waiting.
pub struct PipelineHandle {
    shared: Arc<(Mutex<Slot>, Condvar)>,
}

impl PipelineHandle {
    pub fn send(&self, req: PipelineRequest) {
        let (m, cv) = &*self.shared;
        if let Ok(mut s) = m.lock() {
            s.request = Some(req);
            cv.notify_one();
        }
    }
}

impl Drop for PipelineHandle {
    fn drop(&mut self) {
        let (m, cv) = &*self.shared;
        if let Ok(mut s) = m.lock() {
            s.closed = true;
            cv.notify_one();
        }
    }
}

pub fn spawn(ui: std::sync::mpsc::Sender<Msg>) -> std::io::Result<PipelineHandle> {
    let shared = Arc::new((Mutex::new(Slot::default()), Condvar::new()));
    let theirs = shared.clone();
    std::thread::Builder::new()
        .name("vss-pipeline".into())
        .spawn(move || {
            let mut engine = Engine::default();
            while let Some(req) = next(&theirs) {
                let generation = req.generation;
                let image_key = req.image_key;
                let params = req.params.clone();
                let outcome = engine.process(&req);
                send(
                    &ui,
                    Msg::Pipeline(PipelineResult {
                        generation,
                        image_key,
                        params,
                        outcome,
                    }),
                );
            }
        })?;
    Ok(PipelineHandle { shared })
}

fn next(shared: &(Mutex<Slot>, Condvar)) -> Option<PipelineRequest> {
    let (m, cv) = shared;
    let mut s = m.lock().ok()?;
    loop {
        if let Some(r) = s.request.take() {
            return Some(r);
        }
        if s.closed {
            return None;
        }
        s = cv.wait(s).ok()?;
    }
}

/// What the worker keeps between runs: the session code's one [`Runner`]
/// (its workspace re-runs only the stages a tweak affects), and the last
/// outputs as the UI got them, handed back when nothing changed.
#[derive(Default)]
pub struct Engine {
    runner: Runner,
    last: Option<(u64, Option<CameraModel>, Arc<StageOutputs>)>,
}

impl Engine {
    /// Runs (or re-runs) the stages for a request.
    pub fn process(
        &mut self,
        req: &PipelineRequest,
    ) -> Result<Arc<StageOutputs>, crate::llv::LlvError> {
        let key = req.image_key.version;
        if let Some((k, cam, out)) = &self.last
            && *k == key
            && *cam == req.input.camera
            && out.params == req.params
        {
            return Ok(out.clone());
        }
        self.last = None;
        let out = Arc::new(
            self.runner
                .run_changed(key, &req.input, &req.params)?
                .clone(),
        );
        self.last = Some((key, req.input.camera, out.clone()));
        Ok(out)
    }
}
