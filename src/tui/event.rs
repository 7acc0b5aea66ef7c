//! The one channel into the UI thread (`Msg`: keys, resizes, ticks, device
//! results, pipeline results, session results) and the commands the UI sends
//! out to its workers (`Cmd`). Everything here is plain data, so the App can
//! be driven and tested without a terminal, a device or a disk.

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::crossterm::event::KeyEvent;

use crate::llv::lens::CameraModel;
use crate::llv::pipeline::StageOutputs;
use crate::llv::{GreyImage, Params, Segment};

/// Everything that can happen to the console.
#[derive(Debug)]
pub enum Msg {
    Key(KeyEvent),
    Resize(u16, u16),
    /// Regular wake-up (throttled work, blinking nothing): redraws only if
    /// something changed.
    Tick,
    Device(DeviceEvent),
    Pipeline(PipelineResult),
    Store(StoreEvent),
}

/// What a captured frame was for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FramePurpose {
    /// Survey image `k` under lighting `letter`.
    Survey { k: u32, letter: char },
    /// One frame of the live view.
    Live,
    /// A single grab from the Capture screen.
    Snapshot,
}

/// Reports of the device worker.
#[derive(Debug)]
pub enum DeviceEvent {
    /// The cell answered: a one-line description of grabber and relay board.
    Connected { grabber: String, relay: String },
    /// A device stopped answering; the worker retries on its own.
    Lost { error: String },
    /// Transfer progress of the frame under way.
    Progress { done: usize, total: usize },
    Frame {
        purpose: FramePurpose,
        camera: u32,
        image: GreyImage,
    },
    CaptureFailed {
        purpose: FramePurpose,
        error: String,
    },
    /// The lights now on (names) and the relay mask read back.
    Lights { on: Vec<String>, mask: u32 },
    /// A hardware event worth a log line.
    Note(String),
}

/// A pipeline run's result, tagged with the generation that asked for it.
#[derive(Debug)]
pub struct PipelineResult {
    pub generation: u64,
    pub image_key: ImageKey,
    pub params: Params,
    pub outcome: Result<Arc<StageOutputs>, String>,
}

/// Which set of grey images a pipeline run is about (the session's image
/// number, or 0 for a live/snapshot frame), and a counter bumped whenever the
/// grey images change, so the worker knows when it may re-run only later
/// stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageKey {
    pub k: u32,
    pub version: u64,
}

/// A session as the console shows it: a snapshot made by the store worker.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SessionView {
    pub name: String,
    pub dir: PathBuf,
    /// Lighting letters of the session, in order.
    pub letters: Vec<char>,
    pub images: Vec<ImageState>,
    /// Where the survey goes on: image number and the lighting still missing
    /// (`None` = all captured, outputs missing or done).
    pub next: Option<(u32, Option<char>)>,
    /// Every file of the session with its state.
    pub files: Vec<FileState>,
}

/// One image number of a session.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageState {
    pub k: u32,
    pub camera: u32,
    pub location: u32,
    pub captured: Vec<char>,
    pub outputs: bool,
    pub stale: bool,
    pub edits: usize,
}

/// A file of the session and how it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct FileState {
    pub name: String,
    pub state: String,
    pub ok: bool,
}

/// Reports of the store (session) worker.
#[derive(Debug)]
pub enum StoreEvent {
    /// Sessions found in the survey folder (name, folder, one-line summary).
    Sessions(Vec<(String, PathBuf, String)>),
    Opened(SessionView),
    Updated(SessionView),
    /// Grey images of an image number read back from disk (resume).
    Images {
        k: u32,
        images: Vec<(char, GreyImage)>,
    },
    /// Lines of an image read back (`.ldr`), for the editor.
    Lines {
        k: u32,
        lines: Vec<Segment>,
    },
    /// The camera models, index 0 = camera 1 (`None` where no `.cdf`).
    Cameras(Vec<Option<CameraModel>>),
    Saved(String),
    Reports(Vec<PathBuf>),
    Error(String),
}

/// Commands from the UI to its workers.
#[derive(Debug)]
pub enum Cmd {
    Device(DeviceCmd),
    Pipeline(PipelineRequest),
    Store(StoreCmd),
}

#[derive(Debug, Clone, PartialEq)]
pub enum DeviceCmd {
    /// Switch to a lighting (when given), select the camera, freeze, transfer.
    Capture {
        purpose: FramePurpose,
        camera: u32,
        lighting: Option<char>,
    },
    /// Live view on/off; on, the worker keeps sending throttled frames.
    Live {
        on: bool,
        camera: u32,
    },
    SetLight {
        relay: u32,
        on: bool,
    },
    AllOff,
    Lighting(char),
    /// Show a calibration plate in the simulated cell's view (`None`: the
    /// bare cell); a real cell ignores it, with a note.
    SimTarget(Option<crate::rig::sim::plate::PlateTarget>),
    /// Stop the transfer under way (and the live view).
    Cancel,
}

/// A request to the pipeline worker: latest wins.
#[derive(Debug, Clone)]
pub struct PipelineRequest {
    pub generation: u64,
    pub image_key: ImageKey,
    /// Lit images (one or more), and the ambient one if the lighting set has it.
    pub images: Arc<Vec<GreyImage>>,
    pub ambient: Option<Arc<GreyImage>>,
    pub camera: Option<CameraModel>,
    pub params: Params,
}

#[derive(Debug)]
pub enum StoreCmd {
    List,
    Create(String),
    Open(PathBuf),
    SaveImage {
        k: u32,
        letter: char,
        camera: u32,
        location: u32,
        image: GreyImage,
    },
    SaveOutputs {
        k: u32,
        outputs: Arc<StageOutputs>,
        params: Params,
    },
    /// A manual edit: what was done (for the session's log) and the lines after it.
    RecordEdit {
        k: u32,
        what: String,
        lines: Vec<Segment>,
    },
    /// Read the grey images and lines of an image number back.
    Load(u32),
    /// Forget the captured data of an image number before it is redone.
    Redo(u32),
    Export,
    Refresh,
}
