//! The store worker: owns the open [`Session`] (and its lock) and does all
//! the disk work the console asks for — list (damaged sessions too),
//! create, open (resume, or take over a lock), save images and outputs,
//! record edits, read an image back, export the reports, append the log —
//! reporting each result or error as a message. On quit the UI waits for it
//! to finish what is queued, so nothing the operator saw saved is lost.
//! A session replaces the open one only once it is open (`open`): one that
//! cannot be opened leaves the open one open and held.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::send;
use crate::formats;
use crate::formats::cdf::Cdf;
use crate::formats::img::ImgFile;
use crate::llv::GreyImage;
use crate::profile::Profile;
use crate::report;
use crate::session::takeover::LEAVE_POLL;
use crate::session::{CheckReport, FrameSettings, Session, SessionError};
use crate::tui::event::{Msg, SessionView, StoreCmd, StoreError, StoreEvent};

mod list;
mod load;
mod logfile;
mod open;
mod view;

use open::Opening;

pub use view::view;

fn session_err(what: impl Into<String>) -> impl Fn(SessionError) -> StoreError {
    let what = what.into();
    move |source| StoreError::Session {
        what: what.clone(),
        source,
    }
}

/// The UI's handle on the store worker.
pub struct StoreHandle {
    tx: Sender<StoreCmd>,
    join: JoinHandle<()>,
    /// Set when the console quits: a take-over still waiting gives up
    /// rather than signal a holder for a console that is gone.
    quitting: Arc<AtomicBool>,
}

impl StoreHandle {
    pub fn send(&self, cmd: StoreCmd) {
        let _ = self.tx.send(cmd);
    }

    /// Closes the queue and waits (at most `limit`) for the saves in it.
    pub fn finish(self, limit: Duration) {
        self.quitting.store(true, Ordering::SeqCst);
        drop(self.tx);
        let end = Instant::now() + limit;
        while !self.join.is_finished() && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(10));
        }
        if self.join.is_finished() {
            let _ = self.join.join();
        }
    }
}

pub fn spawn(profile: Profile, ui: Sender<Msg>) -> std::io::Result<StoreHandle> {
    let (tx, rx) = mpsc::channel();
    let quitting = Arc::new(AtomicBool::new(false));
    let q = Arc::clone(&quitting);
    let join = std::thread::Builder::new()
        .name("vss-store".into())
        .spawn(move || {
            let mut s = Store::new(profile, ui);
            s.quitting = q;
            s.run(rx)
        })?;
    Ok(StoreHandle { tx, join, quitting })
}

/// The disk side of the console; usable without a thread (tests, benches).
pub struct Store {
    profile: Profile,
    ui: Sender<Msg>,
    session: Option<Session>,
    /// The last full check of the open session's files, kept up to date
    /// as files are rewritten.
    check: Option<CheckReport>,
    log: logfile::LogFile,
    lister: list::Lister,
    /// The open session was opened only to look: nothing is written.
    read_only: bool,
    /// What the session open only to look was last read from
    /// ([`StoreCmd::Relook`]).
    looked: Option<list::Stamp>,
    /// The console quits ([`StoreHandle::finish`]).
    quitting: Arc<AtomicBool>,
    /// Each camera's description as [`Store::cameras`] last read it (index
    /// 0 = camera 1): what the console's lens correction uses, and so what
    /// an image is recorded with.
    cdfs: Vec<Option<Cdf>>,
}

/// What a session open only to look rests on: its folder, manifest and
/// lock ([`list::stamp`], the session list's own test of a change).
fn look_stamp(s: &Session) -> list::Stamp {
    list::stamp(s.dir(), s.name().as_str())
}

impl Store {
    pub fn new(profile: Profile, ui: Sender<Msg>) -> Store {
        Store {
            profile,
            ui,
            session: None,
            check: None,
            log: logfile::LogFile::default(),
            lister: list::Lister::default(),
            read_only: false,
            looked: None,
            quitting: Arc::default(),
            cdfs: Vec::new(),
        }
    }

    fn run(mut self, rx: Receiver<StoreCmd>) {
        self.cameras();
        if let Some(p) = logfile::state_path() {
            self.use_log(p);
        }
        // Between commands, and at least every LEAVE_POLL, a request to
        // release the session's lock ([`Store::leave_if_asked`]).
        let mut checked = Instant::now();
        loop {
            match rx.recv_timeout(LEAVE_POLL) {
                Ok(cmd) => self.handle(cmd),
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if checked.elapsed() >= LEAVE_POLL {
                self.leave_if_asked();
                checked = Instant::now();
            }
        }
    }

    /// Leaves the open session when another console on this host asked
    /// for it through the session folder (`NAME.lock.leave`) and the
    /// request checks out: everything asked of the store before is saved
    /// (commands are done in order), the lock is released, and the console
    /// is told who took the session. A request that does not check out is
    /// removed and said, and the session stays.
    pub fn leave_if_asked(&mut self) {
        let Some(s) = &self.session else {
            return;
        };
        let dir = s.dir().to_path_buf();
        match s.leave_requested() {
            None => {}
            Some(Ok(asker)) => {
                self.close();
                self.reply(StoreEvent::Left {
                    dir,
                    by: asker.to_string(),
                });
                self.say_list(false);
            }
            Some(Err(why)) => self.reply(StoreEvent::Note(format!(
                "a request to leave session {} was ignored: {why}",
                crate::text::path(&dir)
            ))),
        }
    }

    /// Reads the profile's `.cdf` files, once, and reports their camera
    /// models, or why lens correction cannot use one.
    pub fn cameras(&mut self) {
        let read: Vec<_> = (1..=self.profile.survey.cameras.max(1))
            .map(|c| (c, self.profile.camera_cdf(c)))
            .collect();
        let models = read
            .iter()
            .map(|(c, r)| match r {
                Ok(Some(cdf)) => cdf.model().map_err(|why| {
                    format!("{} {why}", self.profile.cdf_shown(*c).unwrap_or_default())
                }),
                Ok(None) => Err("the profile names no .cdf for it ([survey] cdf)".into()),
                // The console names the camera itself.
                Err(crate::profile::ProfileError::Camera { source, .. }) => Err(source.to_string()),
                Err(e) => Err(e.to_string()),
            })
            .collect();
        self.cdfs = read.into_iter().map(|(_, r)| r.ok().flatten()).collect();
        self.reply(StoreEvent::Cameras(models));
    }

    /// Camera `camera`'s description as [`Store::cameras`] read it (read
    /// now by a store that never read them: a test driving it by hand).
    fn read_copy(&self, camera: u32) -> Option<Cdf> {
        if self.cdfs.is_empty() {
            return self.profile.camera_cdf(camera).ok().flatten();
        }
        camera
            .checked_sub(1)
            .and_then(|i| self.cdfs.get(i as usize))
            .cloned()
            .flatten()
    }

    /// Camera `camera`'s description as [`Store::cameras`] read it
    /// ([`Store::read_copy`]), `read`, which image `k` is recorded with; a
    /// warning when the file has changed on disk since (a hand edit, a
    /// `vss calibrate` in another terminal), because the console goes on
    /// correcting with the one it read.
    fn camera_read(&self, camera: u32, k: u32, read: Option<Cdf>) -> Option<Cdf> {
        let now = self.profile.camera_cdf(camera);
        if now.as_ref().ok().and_then(Option::as_ref) != read.as_ref() {
            let file = self.profile.cdf_shown(camera).unwrap_or_default();
            let why = match now {
                Err(e) => format!(" and cannot be read now ({e})"),
                Ok(_) => String::new(),
            };
            self.reply(StoreEvent::Warning(format!(
                "camera {camera}: {file} changed since the console read it{why}; image {k} is \
                 recorded and corrected with the description read then (quit and start the \
                 console again to use the file as it is now)"
            )));
        }
        read
    }

    /// Saves a captured frame as image `k`'s lighting `letter` (recording
    /// the image's camera, place and `.cdf` first where they are new), and
    /// gives its file name.
    fn save_frame(
        &mut self,
        k: u32,
        letter: char,
        camera: u32,
        location: u32,
        image: GreyImage,
        settings: FrameSettings,
    ) -> Result<String, StoreError> {
        // The camera's description as the console read it (built in or a
        // file), recorded as the image's NAMEk.cdf, so the image's outputs
        // and its record agree (`vss session redo` makes the same); a
        // problem with it is said on the Pipeline screen (`cameras`).
        // A frame captured into an image recorded with another description
        // (one read before a recalibration, or a damaged file), or with
        // one when the profile names none now, records this one (or none):
        // the console runs a newly captured frame with the camera as read
        // now.
        let read = self.read_copy(camera);
        let known = self.session.as_ref().and_then(|s| {
            s.manifest().image(k).map(|r| {
                let same = s.recorded_with(k, read.as_ref());
                (r.camera, r.location, same)
            })
        });
        let record = known.is_none_or(|(c, l, same)| c != camera || l != location || !same);
        let cdf = if record {
            self.camera_read(camera, k, read)
        } else {
            None
        };
        let s = self.session_mut()?;
        let what = format!("image {k} lighting {letter} NOT saved");
        if record {
            s.set_image_camera(k, camera, location, cdf.as_ref())
                .map_err(session_err(what.clone()))?;
        }
        let file = s.file_name(k, Some(letter), "img");
        let stem = file.trim_end_matches(".img").to_string();
        s.save_frame(k, letter, &ImgFile::new(image).with_comment(stem), settings)
            .map_err(session_err(what))?;
        Ok(file)
    }

    fn reply(&self, e: StoreEvent) {
        send(&self.ui, Msg::Store(e));
    }

    /// Carries out one command, reporting the result.
    pub fn handle(&mut self, cmd: StoreCmd) {
        if let Err(e) = self.try_handle(cmd) {
            self.reply(StoreEvent::Error(e));
        }
    }

    fn try_handle(&mut self, cmd: StoreCmd) -> Result<(), StoreError> {
        match cmd {
            StoreCmd::List => {
                self.lister.forget();
                self.say_list(false);
            }
            StoreCmd::Relist => self.say_list(true),
            StoreCmd::Relook => self.relook()?,
            StoreCmd::Log(lines) => {
                let path = self.log.path().map(Path::to_path_buf);
                if let Err(source) = self.log.append(&lines)
                    && let Some(path) = path
                {
                    return Err(StoreError::Log { path, source });
                }
            }
            StoreCmd::Create(name) => self.replace(Opening::Create(name)),
            StoreCmd::Open(dir) => self.replace(Opening::Open(dir)),
            StoreCmd::OpenReadOnly(dir) => self.replace(Opening::Look(dir)),
            StoreCmd::TakeOver(dir) => self.replace(Opening::TakeOver(dir)),
            StoreCmd::SaveImage {
                k,
                letter,
                camera,
                location,
                image,
                settings,
            } => match self.save_frame(k, letter, camera, location, image, settings) {
                Ok(file) => {
                    self.forget_problems(std::slice::from_ref(&file));
                    self.reply(StoreEvent::Saved(file));
                    self.updated();
                }
                Err(error) => self.reply(StoreEvent::FrameNotSaved { k, letter, error }),
            },
            StoreCmd::SaveOutputs { k, outputs, params } => {
                let s = self.session_mut()?;
                if let Err(e) = s.save_outputs(k, &outputs, &params) {
                    let error = session_err(format!("outputs of image {k} NOT saved"))(e);
                    self.reply(StoreEvent::OutputsNotSaved { k, error });
                    return Ok(());
                }
                let files: Vec<String> = ["hpo", "vpo", "lex", "ldr"]
                    .iter()
                    .map(|e| s.file_name(k, None, e))
                    .collect();
                self.forget_problems(&files);
                self.reply(StoreEvent::OutputsSaved(k));
                self.updated();
            }
            StoreCmd::RecordEdit { k, what, lines } => {
                let s = self.session_mut()?;
                if let Err(e) = s.record_edit(k, &what, &lines) {
                    let error = session_err(format!("edit of image {k} NOT saved"))(e);
                    self.reply(StoreEvent::EditNotSaved { k, error });
                    return Ok(());
                }
                let file = s.file_name(k, None, "ldr");
                self.forget_problems(std::slice::from_ref(&file));
                self.reply(StoreEvent::EditSaved { k, file });
                self.updated();
            }
            StoreCmd::UndoEdit { k, lines } => {
                let s = self.session_mut()?;
                if let Err(e) = s.undo_edit(k, &lines) {
                    let error = session_err(format!("undo of image {k} NOT saved"))(e);
                    self.reply(StoreEvent::EditNotSaved { k, error });
                    return Ok(());
                }
                let file = format!("{} (edit taken back)", s.file_name(k, None, "ldr"));
                self.reply(StoreEvent::EditSaved { k, file });
                self.updated();
            }
            StoreCmd::Load(k) => {
                let s = self.session.as_ref().ok_or(StoreError::NoSession)?;
                let img = load::image(s, k);
                self.reply(StoreEvent::Loaded(Box::new(img)));
            }
            StoreCmd::Remake(k) => {
                let fallback = self.profile.llv.clone();
                let s = self.session_mut()?;
                let params = s
                    .manifest()
                    .image(k)
                    .and_then(|r| r.outputs.as_ref())
                    .map_or(fallback, |o| o.params.clone());
                let what = format!("outputs of image {k} NOT made again");
                let summary = s
                    .redo(k, crate::llv::params::Stage::Lens, &params)
                    .map_err(session_err(what))?;
                let mut files: Vec<String> = ["hpo", "vpo", "lex", "ldr"]
                    .iter()
                    .map(|e| s.file_name(k, None, e))
                    .collect();
                files.extend(s.letters().iter().map(|l| s.file_name(k, Some(*l), "imc")));
                self.forget_problems(&files);
                self.reply(StoreEvent::Note(format!(
                    "{summary}, from its saved frames with its recorded values"
                )));
                self.updated();
                if let Some(s) = &self.session {
                    self.reply(StoreEvent::Loaded(Box::new(load::image(s, k))));
                }
            }
            StoreCmd::Redo(k) => {
                self.session_mut()?;
                self.reply(StoreEvent::Note(format!(
                    "image {k}: its files are replaced as the new captures come in"
                )));
            }
            StoreCmd::Export => {
                let written = self.export()?;
                self.reply(StoreEvent::Reports {
                    paths: written.files,
                    problems: written.problems,
                });
                self.updated();
            }
            StoreCmd::Refresh => {
                if let Some(s) = &self.session {
                    self.check = Some(s.check());
                }
                self.updated();
            }
            StoreCmd::WriteCdf {
                camera,
                calibration,
            } => {
                let path = self
                    .profile
                    .cdf_path(camera)
                    .ok_or(StoreError::NoCdf { camera })?;
                // The entries kept (T, a stated C) are those of the
                // description the camera had — the compiled-in one of the
                // built-in cell when no file is there yet.
                let old = self.profile.camera_cdf(camera).ok().flatten();
                let cdf = crate::calib::cdf_with_intrinsics(old.as_ref(), &calibration);
                let cdf_err = |source| StoreError::Cdf {
                    path: path.clone(),
                    source,
                };
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
                    && !dir.is_dir()
                {
                    std::fs::create_dir_all(dir).map_err(|e| {
                        cdf_err(formats::FormatError::io(dir, "create the folder", &e))
                    })?;
                }
                crate::calib::write_cdf_keeping(&path, &cdf).map_err(cdf_err)?;
                let recorded = match self.session.as_mut() {
                    Some(s) if self.read_only => {
                        format!("; not recorded in session {} (open only to look)", s.name())
                    }
                    Some(s) => {
                        s.record_calibration(camera, &path, &calibration)
                            .map_err(session_err(format!(
                                "camera {camera}: {} written, but not recorded in the session",
                                crate::text::path(&path)
                            )))?;
                        format!("; recorded in session {}", s.name())
                    }
                    None => String::new(),
                };
                self.reply(StoreEvent::Note(format!(
                    "camera {camera}: wrote {} (RMS {:.3} px over {} views){recorded}",
                    crate::text::path(&path),
                    calibration.rms,
                    calibration.views.len()
                )));
                self.cameras();
            }
        }
        Ok(())
    }

    /// The open session, to write; refused when it is open only to look.
    fn session_mut(&mut self) -> Result<&mut Session, StoreError> {
        let s = self.session.as_mut().ok_or(StoreError::NoSession)?;
        if self.read_only {
            return Err(StoreError::ReadOnly {
                name: s.name().to_string(),
            });
        }
        Ok(s)
    }

    /// Closes the open session (its lock released); the log goes back to
    /// the state folder.
    fn close(&mut self) {
        if self.session.take().is_some()
            && !self.read_only
            && let Some(p) = logfile::state_path()
        {
            self.use_log(p);
        }
        self.check = None;
        self.read_only = false;
        self.looked = None;
    }

    fn opened(&mut self, s: Session) {
        self.looked = self.read_only.then(|| look_stamp(&s));
        let log = s.path(&format!("{}.log", s.name()));
        let v = self.adopt(s);
        // A session open only to look keeps the state folder's log.
        if !self.read_only {
            self.use_log(log);
        }
        self.reply(StoreEvent::Opened(v));
        self.say_list(false);
    }

    fn use_log(&mut self, path: PathBuf) {
        match self.log.open(&path) {
            Ok(()) => self.reply(StoreEvent::LogFile(path)),
            Err(source) => self.reply(StoreEvent::Error(StoreError::Log { path, source })),
        }
    }

    /// The session open only to look, read again when what it rests on
    /// changed since it was last read: its checklist and files as another
    /// console left them, the console's place in it kept.
    fn relook(&mut self) -> Result<(), StoreError> {
        let (Some(s), true) = (&self.session, self.read_only) else {
            return Ok(());
        };
        let now = look_stamp(s);
        if self.looked.as_ref() == Some(&now) {
            return Ok(());
        }
        // Said once a change, whether it reads or not.
        self.looked = Some(now);
        let dir = s.dir().to_path_buf();
        let s = Session::inspect(&dir).map_err(session_err(format!(
            "cannot read {} again (the view shows it as it was)",
            crate::text::path(&dir)
        )))?;
        let v = self.adopt(s);
        self.reply(StoreEvent::Updated(v));
        Ok(())
    }

    /// Makes `s` the open session with a full check of its files, and
    /// gives the console's picture of it (opening, and reading a session
    /// open only to look again, both).
    fn adopt(&mut self, s: Session) -> SessionView {
        let check = s.check();
        let v = view(&s, Some(&check), true, self.read_only);
        self.session = Some(s);
        self.check = Some(check);
        v
    }

    fn updated(&self) {
        if let Some(s) = &self.session {
            let v = view(s, self.check.as_ref(), false, self.read_only);
            self.reply(StoreEvent::Updated(v));
        }
    }

    /// Drops what the last check found about files just written anew.
    fn forget_problems(&mut self, files: &[String]) {
        if let Some(c) = self.check.as_mut() {
            c.problems
                .retain(|p| !files.iter().any(|f| view::names_file(p, f)));
        }
    }

    /// Says the sessions of the survey folder ([`list::Lister::list`]);
    /// `if_changed`: only when they differ from the list said last.
    fn say_list(&mut self, if_changed: bool) {
        let here = self.session.as_ref().map(|s| s.dir().to_path_buf());
        let list = self.lister.list(&self.profile.survey.dir, here.as_deref());
        if self.lister.say(&list) || !if_changed {
            self.reply(StoreEvent::Sessions(list));
        }
    }

    /// Writes the survey report `NAME.ps` and one `NAMEk.svg` per image in
    /// the session folder, through the one report writer (`vss report`
    /// writes the same pages). A failure says which file on disk is old.
    fn export(&mut self) -> Result<report::survey::Written, StoreError> {
        let s = &*self.session_mut()?;
        let targets = report::survey::Targets::in_session(s);
        let ps = targets.ps.clone().unwrap_or_default();
        report::survey::write(s, None, &targets).map_err(|e| {
            // The file that failed, else the PostScript report (unless it
            // was written: the message names what was).
            let old = e
                .on_disk()
                .or_else(|| (!e.wrote_some()).then(|| report::survey::on_disk(&ps)))
                .map_or(String::new(), |o| format!("; {o}"));
            StoreError::Report {
                why: e.to_string(),
                old,
            }
        })
    }
}
