//! The pipeline worker: runs the LLV stages off the UI thread. Latest wins —
//! a request waiting when a newer one arrives is dropped unseen — and when
//! only parameters changed on the same images it re-runs from the first
//! affected stage (`Workspace::rerun`). Results carry the request's
//! generation so the UI never lets an older run overwrite a newer one.

use std::sync::{Arc, Condvar, Mutex};

use super::send;
use crate::llv::GreyImage;
use crate::llv::lens::{CameraModel, LensMap};
use crate::llv::params::Stage;
use crate::llv::pipeline::{Input, StageOutputs, Workspace};
use crate::tui::event::{ImageKey, Msg, PipelineRequest, PipelineResult};

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

/// What the worker keeps between runs so a parameter tweak re-runs only
/// the stages it affects: one [`Workspace`] (every buffer, the lens-corrected
/// ambient image included) and the image set it last ran on completely.
#[derive(Default)]
pub struct Engine {
    ws: Workspace,
    /// The images and camera of the workspace's last complete run, and that
    /// run's outputs as the UI got them. Cleared while a run is under way,
    /// so a failed run leaves nothing to re-run from (the next is full).
    last: Option<(ImageKey, Option<CameraModel>, Arc<StageOutputs>)>,
    lens: Option<(CameraModel, (usize, usize), Arc<LensMap>)>,
}

impl Engine {
    /// Runs (or re-runs) the stages for a request.
    pub fn process(
        &mut self,
        req: &PipelineRequest,
    ) -> Result<Arc<StageOutputs>, crate::llv::LlvError> {
        let size = req.images.first().map(GreyImage::size).unwrap_or((0, 0));
        // Before a lens map is made for the size.
        crate::llv::image::check_stage_size(size.0, size.1)?;
        let lens = match req.camera {
            Some(m) if req.params.lens.enabled && !m.is_identity() => Some(self.lens_map(m, size)),
            _ => None,
        };
        let input = Input {
            images: &req.images,
            ambient: req.ambient.as_deref(),
            lens: lens.as_deref(),
        };
        let from = match self.last.take() {
            Some((k, cam, out)) if k == req.image_key && cam == req.camera => {
                match out.params.first_changed_stage(&req.params) {
                    None => {
                        self.last = Some((k, cam, out.clone()));
                        return Ok(out);
                    }
                    Some(stage) => stage,
                }
            }
            _ => Stage::Lens,
        };
        let out = Arc::new(self.ws.rerun(from, &input, &req.params)?.clone());
        self.last = Some((req.image_key, req.camera, out.clone()));
        Ok(out)
    }

    fn lens_map(&mut self, m: CameraModel, size: (usize, usize)) -> Arc<LensMap> {
        match &self.lens {
            Some((cm, sz, map)) if *cm == m && *sz == size => map.clone(),
            _ => {
                let map = Arc::new(LensMap::new(&m, size.0, size.1));
                self.lens = Some((m, size, map.clone()));
                map
            }
        }
    }
}
