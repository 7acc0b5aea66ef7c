//! The one channel into the UI thread (`Msg`: keys, resizes, ticks, device
//! results, pipeline results, session results) and the commands the UI sends
//! out to its workers (`Cmd`). Everything here is plain data, so the App can
//! be driven and tested without a terminal, a device or a disk.

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::crossterm::event::{KeyEvent, MouseEvent};

use crate::llv::lens::CameraModel;
use crate::llv::pipeline::StageOutputs;
use crate::llv::{GreyImage, LlvError, Params, Segment};
use crate::session::FrameSettings;
use crate::session::input::PipelineInput;

/// Everything that can happen to the console.
#[derive(Debug)]
pub enum Msg {
    Key(KeyEvent),
    /// A click or the wheel as the terminal reports it; the shell places it
    /// on what is drawn there ([`Msg::Pointer`]) before the App sees it.
    Mouse(MouseEvent),
    /// A mouse event placed on the screen's contents.
    Pointer(Pointer),
    Resize(u16, u16),
    /// Regular wake-up (throttled work, blinking nothing): redraws only if
    /// something changed.
    Tick,
    Device(DeviceEvent),
    Pipeline(PipelineResult),
    Store(StoreEvent),
}

/// A mouse event placed on the screen's contents.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pointer {
    /// The wheel over a list: one row up or down.
    ScrollList { up: bool },
    /// The wheel over the expanded log pane or a help/message window.
    ScrollLog { up: bool },
    /// The wheel over a picture: zoom in or out.
    Zoom { zoom_in: bool },
    /// A click on checklist row `k`.
    Checklist(u32),
    /// A click on row `i` of the session list.
    SessionRow(usize),
    /// A click on row `i` of the parameter panel.
    Param(usize),
    /// A click on the picture, at image pixel `(x, y)`.
    Pixel(usize, usize),
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
    /// A device stopped answering, or (`busy`) another program holds its
    /// port; the worker retries on its own.
    Lost { error: String, busy: bool },
    /// The lights are switched and settling before the freeze.
    Settling { ms: u64 },
    /// Transfer progress of the frame under way.
    Progress { done: usize, total: usize },
    Frame {
        purpose: FramePurpose,
        camera: u32,
        image: GreyImage,
        /// The camera's exposure and gain for this frame (GenICam cameras).
        settings: FrameSettings,
    },
    CaptureFailed {
        purpose: FramePurpose,
        error: String,
    },
    /// The lights now on (names) and the relay mask read back.
    Lights { on: Vec<String>, mask: u32 },
    /// A hardware event worth a log line.
    Note(String),
    /// A camera's exposure or gain was set: the grabber's new one-line
    /// description, and what changed (for the log).
    CameraSet { grabber: String, note: String },
}

/// A pipeline run's result, tagged with the generation that asked for it.
#[derive(Debug)]
pub struct PipelineResult {
    pub generation: u64,
    pub image_key: ImageKey,
    pub params: Params,
    pub outcome: Result<Arc<StageOutputs>, LlvError>,
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
    /// Whether the files were read and checked for this view (not only
    /// the manifest).
    pub checked: bool,
    /// Opened only to look (its folder cannot be written, or another
    /// console holds it): every action that would write is refused, and
    /// nothing is written into it.
    pub read_only: bool,
}

impl SessionView {
    /// Files that are missing or do not read.
    pub fn problems(&self) -> usize {
        self.files.iter().filter(|f| !f.ok).count()
    }

    /// What is damaged, in words an operator acts on, image by image:
    /// `image 2 lighting b`, `image 4 lines`; then other files.
    pub fn problem_list(&self) -> Vec<String> {
        let mut out = Vec::new();
        for i in &self.images {
            if !i.damaged.is_empty() {
                let letters: String = i.damaged.iter().map(|d| d.0).collect();
                out.push(format!("image {} lighting {letters}", i.k));
            }
            if i.outputs_damaged.is_some() {
                out.push(format!("image {} lines", i.k));
            }
        }
        // Damage no image row accounts for (the manifest's own files).
        if out.is_empty() && self.problems() > 0 {
            out.push(format!("{} damaged file(s), listed on 5", self.problems()));
        }
        out
    }

    /// "survey complete" with what is damaged, for where the survey ends.
    pub fn complete_text(&self) -> String {
        let p = self.problem_list();
        match p.len() {
            0 => "Survey complete.".into(),
            n => format!(
                "survey complete, {n} problem{}: {}",
                if n == 1 { "" } else { "s" },
                p.join(", ")
            ),
        }
    }
}

/// A session of the survey folder, as the picker lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct SessionEntry {
    pub name: String,
    pub dir: PathBuf,
    /// `3/4 done`, and who holds it.
    pub summary: String,
    /// Why the session cannot be opened (its manifest does not read).
    pub damaged: Option<String>,
}

/// An image read back from the session.
#[derive(Debug, Default)]
pub struct LoadedImage {
    pub k: u32,
    /// The grey images that read, by lighting letter.
    pub images: Vec<(char, GreyImage)>,
    /// The lightings whose grey image does not read, with why.
    pub damaged: Vec<(char, String)>,
    /// The saved outputs, when every file reads and they are current.
    pub saved: Option<SavedOutputs>,
    /// The `.ldr` as it stands (hand edits included).
    pub lines: Option<Vec<Segment>>,
    /// The session holds accepted (current) outputs of the image.
    pub accepted: bool,
    /// Why its recorded outputs did not load (a file damaged or missing).
    pub outputs_damaged: Option<String>,
    /// What it runs with, or why it cannot run (its recorded description
    /// is damaged), as `vss session redo` runs it
    /// ([`crate::session::Session::image_camera`]); `None` for an image
    /// the session has no record of.
    pub camera: Option<Result<crate::session::camera::ImageCamera, String>>,
}

/// Outputs read from a session's files, with the values they were made with.
#[derive(Debug)]
pub struct SavedOutputs {
    pub outputs: StageOutputs,
    pub params: Params,
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
    /// Lightings whose grey image is missing or does not read, with why.
    pub damaged: Vec<(char, String)>,
    /// Why an output file (`.hpo .vpo .lex .ldr`) is missing or does not read.
    pub outputs_damaged: Option<String>,
    /// The parameter values its outputs were made with, as recorded.
    pub params: Option<Params>,
}

impl ImageState {
    /// Its outputs are there and current, and every file of it reads:
    /// what the checklist counts done.
    pub fn done(&self) -> bool {
        self.outputs && !self.stale && self.damaged.is_empty() && self.outputs_damaged.is_none()
    }
}

/// A file of the session and how it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct FileState {
    pub name: String,
    pub state: String,
    pub ok: bool,
    /// It reads, but is not what the manifest recorded (its hash differs).
    pub changed: bool,
}

/// Reports of the store (session) worker.
#[derive(Debug)]
pub enum StoreEvent {
    /// Sessions found in the survey folder, damaged ones included.
    Sessions(Vec<SessionEntry>),
    Opened(SessionView),
    Updated(SessionView),
    /// An image number read back from disk (resume, going back).
    Loaded(Box<LoadedImage>),
    /// The camera models, index 0 = camera 1, or why a camera has none
    /// (no `.cdf` named, unreadable, or lacking S, C or f).
    Cameras(Vec<Result<CameraModel, String>>),
    Saved(String),
    /// Image `k`'s outputs are saved: it is accepted (said only now, when
    /// its files are on disk, not when the save was asked for).
    OutputsSaved(u32),
    /// A note worth a log line (a stale lock taken over).
    Note(String),
    /// A warning worth a log line (a camera's `.cdf` changed on disk).
    Warning(String),
    /// The survey report is written: its files, and the problems marked in
    /// it (files it could not show), as `vss report` says them.
    Reports {
        paths: Vec<PathBuf>,
        problems: Vec<String>,
    },
    /// The session's folder cannot be written (a read-only mount, no
    /// write permission): it can be opened only to look
    /// ([`StoreCmd::OpenReadOnly`]), if the operator says so.
    Unwritable {
        dir: PathBuf,
        why: String,
    },
    /// The session is held by a console that still runs: it can be taken
    /// over ([`StoreCmd::TakeOver`]) or opened only to look
    /// ([`StoreCmd::OpenReadOnly`]), as the operator chooses.
    Locked {
        dir: PathBuf,
        holder: String,
    },
    /// The session was left at another console's request (`by` asked):
    /// what was asked of the store before is saved, the lock released.
    Left {
        dir: PathBuf,
        by: String,
    },
    /// Where the console's log file is.
    LogFile(PathBuf),
    /// A captured frame the session could not save (a link where its file
    /// goes, a full disk): the image cannot be accepted until that
    /// lighting is captured again.
    FrameNotSaved {
        k: u32,
        letter: char,
        error: StoreError,
    },
    /// Image `k`'s outputs could not be saved: it is not accepted.
    OutputsNotSaved {
        k: u32,
        error: StoreError,
    },
    /// A hand edit (or its undo) of image `k` is written to its `.ldr`
    /// (`file`, as said).
    EditSaved {
        k: u32,
        file: String,
    },
    /// A hand edit (or its undo) of image `k` could not be written: the
    /// lines on screen are not its saved outputs, as when they could not
    /// be saved at all.
    EditNotSaved {
        k: u32,
        error: StoreError,
    },
    Error(StoreError),
    /// A session asked for ([`StoreCmd::Create`], `Open`, `TakeOver`,
    /// `OpenReadOnly`) is open, or was not opened: its outcome is said
    /// before this. Until then the console refuses what would write
    /// ([`crate::tui::App::refused_here`]): the store would do it in the
    /// session it opens, not in the one on screen.
    OpeningDone,
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
    /// Multiply camera `camera`'s exposure time by `factor` (GenICam).
    Exposure {
        camera: u32,
        factor: f64,
    },
    /// Add `db` to camera `camera`'s gain (GenICam).
    Gain {
        camera: u32,
        db: f64,
    },
}

/// A request to the pipeline worker: latest wins.
#[derive(Debug, Clone)]
pub struct PipelineRequest {
    pub generation: u64,
    pub image_key: ImageKey,
    /// The image's frames split by the profile's rule, with its camera
    /// (the one input the session code and the CLI run too).
    pub input: Arc<PipelineInput>,
    pub params: Params,
}

#[derive(Debug)]
pub enum StoreCmd {
    List,
    /// The list read again while it is shown (another console or a `vss
    /// grab` may have opened, captured into or closed a session): said
    /// only when it differs from the one last said, so an unchanged list
    /// costs the screen nothing.
    Relist,
    /// Read the session open only to look again if its folder, manifest
    /// or lock changed (another console goes on surveying it): said as
    /// [`StoreEvent::Updated`], only when it changed.
    Relook,
    Create(String),
    Open(PathBuf),
    /// Open only to look, without the lock: nothing is written into the
    /// folder, every command that would write is refused.
    OpenReadOnly(PathBuf),
    /// Open, taking the lock of a console that still runs (asked first).
    TakeOver(PathBuf),
    /// Lines for the log file (the session's, or the state folder's).
    Log(Vec<String>),
    SaveImage {
        k: u32,
        letter: char,
        camera: u32,
        location: u32,
        image: GreyImage,
        /// Recorded with the image ([`crate::session::Session::save_frame`]).
        settings: FrameSettings,
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
    /// Take back the last recorded edit: the lines before it.
    UndoEdit {
        k: u32,
        lines: Vec<Segment>,
    },
    /// Read the grey images and lines of an image number back.
    Load(u32),
    /// Forget the captured data of an image number before it is redone.
    Redo(u32),
    /// Make image `k`'s outputs again from its saved frames with the
    /// values they were made with (what `vss session redo` does), then
    /// read it back.
    Remake(u32),
    Export,
    /// Re-read the session, checking every file.
    Refresh,
    /// Write a camera's calibration into the profile's `.cdf` of that
    /// camera (the old file kept as `.bak`), then report the cameras again.
    WriteCdf {
        camera: u32,
        calibration: Box<crate::calib::Calibration>,
    },
}

/// What the store worker can fail at; each says what and what to do.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("no session open: create or open one on the Survey screen (1)")]
    NoSession,
    #[error(
        "read-only: nothing will be saved — session {name} is open only to look; o opens \
         another session"
    )]
    ReadOnly { name: String },
    #[error("{what}: {source}")]
    Session {
        what: String,
        #[source]
        source: crate::session::SessionError,
    },
    #[error("report NOT written: {why}{old}")]
    Report { why: String, old: String },
    #[error(
        "log file {}: {source} — messages are still in the log pane (m)",
        crate::text::path(path)
    )]
    Log {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The holder did not let go, or was not asked
    /// ([`crate::session::takeover::TakeOverError`], whose words are the
    /// CLI's too).
    #[error(transparent)]
    TakeOver(crate::session::takeover::TakeOverError),
    #[error("the profile names no .cdf for camera {camera}: add it to [survey] cdf")]
    NoCdf { camera: u32 },
    #[error("{} NOT written: {source}", crate::text::path(path))]
    Cdf {
        path: PathBuf,
        #[source]
        source: crate::formats::FormatError,
    },
}
