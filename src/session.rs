//! A survey on disk. A session is a folder `DIR/NAME/` holding every file of
//! one workpiece survey under VSS names (`cube7b.img`, `cube7.ldr`, …), the
//! three-number `NAME.ses` for older tools, the manifest `NAME.toml` that the
//! console owns ([`manifest`]), and while a console writes it the lock
//! `NAME.lock` ([`lock`]).
//!
//! Every file is written atomically (temporary file, fsync, rename), data
//! files first and the manifest last, so a crash at any moment leaves every
//! file either the previous or the new complete version and a manifest that
//! names only complete files. Resuming reads the manifest and continues at
//! [`Progress::next_step`]; nothing saved is redone unless asked
//! ([`Session::redo`]).

pub mod camera;
pub mod check;
pub mod folder;
mod fresh;
pub mod input;
pub mod lock;
pub mod manifest;
pub mod outputs;
pub mod progress;
pub mod redo;
pub mod stamp;
pub mod takeover;
#[doc(hidden)]
pub mod torture;

use std::fs;
use std::path::{Path, PathBuf};

use crate::formats::names::{NameError, SessionName, VssFile};
use crate::formats::{self, FormatError, img::ImgFile, ses::Ses};
use crate::fsutil::write_atomic;
use crate::llv::{LlvError, Segment};
use crate::profile::Profile;

pub use check::CheckReport;
pub use input::{FrameRule, PipelineInput, Runner};
pub use lock::{Lock, LockInfo};
pub use manifest::Manifest;
pub use outputs::OutputSet;
pub use progress::{ImageProgress, OutputState, Progress, Step};
pub use redo::RedoSummary;

pub use manifest::FrameSettings;
use manifest::{EditRecord, GreyRecord, ImageRecord, LightingInfo, SessionInfo};

/// The largest image number a session accepts, and the most images it may
/// plan. The number goes into every file name of the image (`cube9999b.img`,
/// spec/formats.md §1) and the checklist has a line for every number up to
/// the largest, so an unbounded number (`vss grab --image 4294967295`, or a
/// hand-edited `planned_images`) would size a checklist of four billion
/// lines. A survey is a few cameras at a few locations, tens of images; four
/// digits are far beyond that and keep the per-number work (the checklist,
/// the `.cdf` copies of `vss session new`) to a few thousand steps.
pub const MAX_IMAGE_NUMBER: u32 = 9999;

/// Checks that `k` is an image number a session accepts: 1 to
/// [`MAX_IMAGE_NUMBER`].
pub fn check_image_number(k: u32) -> Result<(), SessionError> {
    if k == 0 || k > MAX_IMAGE_NUMBER {
        return Err(SessionError::BadImage(k));
    }
    Ok(())
}

/// What can go wrong with a session; every message names the file or folder
/// and says what to do.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error("{}: {source}", crate::text::path(path))]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The session's lock cannot be written because its folder cannot be
    /// (a read-only mount, no write permission): it can be looked at only.
    #[error(
        "{}: {source}: the session folder cannot be written (a read-only mount, or no write \
         permission), so nothing was changed; it can still be looked at (`vss session show`, \
         `vss session check`, `vss report`)",
        crate::text::path(path)
    )]
    Unwritable {
        path: PathBuf,
        source: std::io::Error,
    },
    // Transparent, not "{0}": with "{0}" the wrapped error was also the
    // source, and `vss` printed its message twice.
    #[error(transparent)]
    Name(#[from] NameError),
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error(transparent)]
    Llv(#[from] LlvError),
    #[error(
        "session {} already exists; open it instead (`vss session show {}`)",
        crate::text::path(dir),
        crate::text::path(dir)
    )]
    Exists { dir: PathBuf },
    #[error("{}", fresh::not_a_session(dir, manifest))]
    NotASession { dir: PathBuf, manifest: String },
    #[error("{}", locked_message(path, holder, *stale, *foreign))]
    Locked {
        path: PathBuf,
        holder: String,
        /// The holder is certainly gone: the lock can be taken over.
        stale: bool,
        /// The holder is on another host: can be taken over, with care.
        foreign: bool,
    },
    #[error(
        "session lock {} is now held by {holder}: the session was taken over, so this \
         console no longer writes it; this change was NOT saved (the session on disk is the \
         new holder's); open the session again to go on",
        crate::text::path(path)
    )]
    LockLost { path: PathBuf, holder: String },
    #[error(transparent)]
    FolderGone(#[from] lock::FolderGone),
    #[error(transparent)]
    Linked(#[from] folder::Linked),
    #[error(
        "{}{}: {message}; the manifest was left as it is: fix it by hand or restore it",
        crate::text::path(path),
        if *line > 0 { format!(":{line}") } else { String::new() }
    )]
    Manifest {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error(
        "session {} was opened read-only; open it for writing to change it",
        crate::text::path(dir)
    )]
    ReadOnly { dir: PathBuf },
    #[error("lighting {letter:?} is not one of this session's lightings ({known})")]
    UnknownLighting { letter: char, known: String },
    #[error(
        "{}: the session folder's path is {len} bytes long; with the files' names it would \
         exceed the system's limit of {} bytes: make the session in a shorter path",
        crate::text::path(dir),
        fresh::PATH_MAX
    )]
    PathTooLong { dir: PathBuf, len: usize },
    #[error("image number {0} is out of range: image numbers run from 1 to {MAX_IMAGE_NUMBER}")]
    BadImage(u32),
    #[error(
        "cannot make session {}: {source}; {}",
        crate::text::path(dir),
        match left {
            None => "nothing of it is left (what it had made is removed)".to_string(),
            Some(why) => format!("what it had made could not all be removed ({why}): remove {} by hand", crate::text::path(dir)),
        }
    )]
    NotMade {
        dir: PathBuf,
        source: Box<SessionError>,
        /// What could not be removed, or `None` when nothing made is left.
        left: Option<String>,
    },
    /// A camera the session does not have ([`Manifest::check_camera`]).
    #[error("session {session}: {what}; nothing was recorded")]
    NoCamera { session: String, what: String },
    /// Image `image`'s recorded camera description does not read, or is
    /// cut short ([`Session::image_camera`]): it is not run at all.
    #[error(
        "image {image}: its recorded camera description {} is damaged ({why}); the image \
         is not run without the lens correction it was surveyed with: put the file back, or \
         capture the image again to record the camera's description now",
        crate::text::path(path)
    )]
    CameraDamaged {
        image: u32,
        path: PathBuf,
        why: String,
    },
    #[error("image {image} of session {session}: {what}")]
    Missing {
        session: String,
        image: u32,
        what: String,
    },
}

/// Whether anything is at `path` (a dangling link too).
fn present(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok()
}

fn locked_message(path: &Path, holder: &str, stale: bool, foreign: bool) -> String {
    let what = if stale {
        "that process is gone: take the session over with --take-over".to_string()
    } else if foreign {
        "close the console there; if it is gone, take the session over with --take-over".to_string()
    } else {
        "close that console first".to_string()
    };
    format!(
        "session is in use: {} is held by {holder}; {what}",
        crate::text::path(path)
    )
}

/// An open session. Opened for writing it holds the lock until dropped;
/// opened read-only ([`Session::inspect`]) it refuses every write.
#[derive(Debug)]
pub struct Session {
    dir: PathBuf,
    name: SessionName,
    manifest: Manifest,
    lock: Option<Lock>,
}

impl Session {
    /// Makes a new session `parent/name/` for the survey `profile`
    /// describes: its lightings, its cameras, one location per camera.
    pub fn create(parent: &Path, name: &str, profile: &Profile) -> Result<Session, SessionError> {
        Self::create_with(parent, name, profile, |_| Ok(()))
    }

    /// [`Session::create`], then `setup` on the new session (recording its
    /// cameras): when any of it fails (a full disk), what was made is
    /// removed, and only that (see `session::fresh`), and the error says so.
    pub fn create_with(
        parent: &Path,
        name: &str,
        profile: &Profile,
        setup: impl FnOnce(&mut Session) -> Result<(), SessionError>,
    ) -> Result<Session, SessionError> {
        let n = SessionName::new(name)?;
        let dir = parent.join(n.as_str());
        if present(&dir.join(format!("{n}.toml"))) {
            return Err(SessionError::Exists { dir });
        }
        fresh::check_path_len(&dir, &n)?;
        let before = fresh::Before::look(&dir);
        // The session (and its lock) is dropped before its folder goes.
        let made = Self::make(dir.clone(), n, profile).and_then(|mut s| setup(&mut s).map(|()| s));
        made.map_err(|e| SessionError::NotMade {
            left: before
                .undo()
                .err()
                .map(|(p, e)| format!("{}: {e}", crate::text::path(&p))),
            dir,
            source: Box::new(e),
        })
    }

    /// Makes the folder, the lock, `.ses` and the manifest of a new session.
    fn make(dir: PathBuf, name: SessionName, profile: &Profile) -> Result<Session, SessionError> {
        let manifest_path = dir.join(format!("{name}.toml"));
        fs::create_dir_all(&dir).map_err(|source| SessionError::Io {
            path: dir.clone(),
            source,
        })?;
        // No manifest yet: a lock left by a creator that died can go.
        let lock_path = dir.join(format!("{name}.lock"));
        let lock = match Lock::acquire(&lock_path, false) {
            Err(SessionError::Locked { stale: true, .. }) => Lock::acquire(&lock_path, true)?,
            other => other?,
        };
        let now = stamp::now_rfc3339();
        let mut lighting: Vec<LightingInfo> = profile
            .lighting
            .iter()
            .map(|l| LightingInfo {
                letter: l.letter,
                on: l.on.clone(),
                note: l.note.clone(),
            })
            .collect();
        if lighting.is_empty() {
            lighting.push(LightingInfo {
                letter: 'a',
                on: profile.lights.iter().map(|l| l.name.clone()).collect(),
                note: "the lights as they are (the profile defines no lightings)".into(),
            });
        }
        let cameras = profile.survey.cameras.max(1);
        let manifest = Manifest {
            format: manifest::FORMAT,
            session: SessionInfo {
                name: name.to_string(),
                created: now.clone(),
                modified: now,
                version: env!("CARGO_PKG_VERSION").to_string(),
                profile: profile.name.clone(),
                planned_images: cameras,
                cameras,
            },
            lighting,
            image: Vec::new(),
            calibration: Vec::new(),
        };
        // Check the manifest would load back before anything depends on it.
        let text = manifest.to_toml().map_err(|e| SessionError::Manifest {
            path: manifest_path.clone(),
            line: 0,
            message: e.to_string(),
        })?;
        Manifest::parse(&text, &manifest_path)?;
        let mut s = Session {
            dir,
            name,
            manifest,
            lock: Some(lock),
        };
        s.commit()?;
        Ok(s)
    }

    /// Opens a session folder for writing; fails if another console holds it.
    pub fn open(dir: &Path) -> Result<Session, SessionError> {
        Self::open_with(dir, Some(false))
    }

    /// Opens for writing, taking over a lock whose holder is gone (or is on
    /// another host). A live holder on this host is never displaced.
    pub fn open_take_over(dir: &Path) -> Result<Session, SessionError> {
        Self::open_with(dir, Some(true))
    }

    /// Opens `parent/name` for writing if it is a session; `None` when there
    /// is none yet (and nothing is made).
    pub fn open_existing(parent: &Path, name: &str) -> Result<Option<Session>, SessionError> {
        let n = SessionName::new(name)?;
        let dir = parent.join(n.as_str());
        if present(&dir.join(format!("{n}.toml"))) {
            Self::open(&dir).map(Some)
        } else {
            Ok(None)
        }
    }

    /// Opens read-only, without the lock: for show, check and reports.
    pub fn inspect(dir: &Path) -> Result<Session, SessionError> {
        Self::open_with(dir, None)
    }

    fn open_with(dir: &Path, lock: Option<bool>) -> Result<Session, SessionError> {
        // Naming the manifest (or the .ses) means its folder.
        let is_session_file =
            dir.is_file() && dir.extension().is_some_and(|e| e == "toml" || e == "ses");
        let dir = match dir.parent() {
            Some(p) if is_session_file => {
                if p.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    p.to_path_buf()
                }
            }
            _ => dir.to_path_buf(),
        };
        let dir_name = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_default();
        let name = SessionName::new(&dir_name).map_err(|_| SessionError::NotASession {
            dir: dir.clone(),
            manifest: "NAME.toml".into(),
        })?;
        let manifest_path = dir.join(format!("{name}.toml"));
        // Anything there is read, and what it is said (a folder, a FIFO, a
        // link): only a folder without one is "not a session folder".
        if !present(&manifest_path) {
            return Err(SessionError::NotASession {
                dir,
                manifest: format!("{name}.toml"),
            });
        }
        // Lock before reading, so nobody rewrites the manifest under us.
        let lock = match lock {
            Some(take_over) => Some(Lock::acquire(&dir.join(format!("{name}.lock")), take_over)?),
            None => None,
        };
        // Bounded, and not through a link: the size is refused unread.
        let text = crate::fsutil::read_input_text(&manifest_path, manifest::MAX_LEN as u64)
            .map_err(|source| SessionError::Io {
                path: manifest_path.clone(),
                source,
            })?;
        let manifest = Manifest::parse(&text, &manifest_path)?;
        if manifest.session.name != name.as_str() {
            return Err(SessionError::Manifest {
                path: manifest_path,
                line: text
                    .lines()
                    .position(|l| l.trim_start().starts_with("name"))
                    .map_or(0, |i| i + 1),
                message: format!(
                    "the manifest names session {:?} but the folder is {:?}",
                    manifest.session.name,
                    name.as_str()
                ),
            });
        }
        let s = Session {
            dir,
            name,
            manifest,
            lock,
        };
        if s.lock.is_some() {
            s.remove_leftovers();
        }
        Ok(s)
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }
    pub fn name(&self) -> &SessionName {
        &self.name
    }
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }
    /// Records a camera calibration accepted while this session is open
    /// (the `.cdf` it wrote, when, its views and fit) in the manifest.
    pub fn record_calibration(
        &mut self,
        camera: u32,
        cdf: &Path,
        c: &crate::calib::Calibration,
    ) -> Result<(), SessionError> {
        self.writable()?;
        self.known_camera(camera)?;
        self.manifest.calibration.push(manifest::CalibrationRecord {
            camera,
            made: stamp::now_rfc3339(),
            cdf: cdf.display().to_string(),
            views: u32::try_from(c.views.len()).unwrap_or(u32::MAX),
            rms_px: c.rms,
            p95_px: c.p95,
            centre_stated: c.centre_stated,
        });
        self.commit()
    }
    /// Refuses a camera the manifest could not be read back with.
    fn known_camera(&self, camera: u32) -> Result<(), SessionError> {
        let session = self.name.to_string();
        self.manifest
            .check_camera(camera)
            .map_err(|what| SessionError::NoCamera { session, what })
    }
    /// Who holds the lock of this session right now, if anyone.
    pub fn lock_holder(&self) -> Option<LockInfo> {
        lock::read_holder(&self.lock_path())
    }

    /// The session's lock file, `NAME.lock`.
    pub fn lock_path(&self) -> PathBuf {
        self.dir.join(format!("{}.lock", self.name))
    }

    /// A checked request to release this session's lock, if one came
    /// ([`Lock::leave_requested`]); `None` when not opened for writing.
    pub fn leave_requested(&self) -> Option<Result<LockInfo, String>> {
        self.lock.as_ref()?.leave_requested()
    }
    /// The lighting letters, in order.
    pub fn letters(&self) -> Vec<char> {
        self.manifest.lighting.iter().map(|l| l.letter).collect()
    }
    /// The full path of a file of the session.
    pub fn path(&self, file: &str) -> PathBuf {
        self.dir.join(file)
    }
    /// The VSS file name of image `k` (with lighting letter for grey images).
    pub fn file_name(&self, k: u32, letter: Option<char>, ext: &str) -> String {
        VssFile {
            session: self.name.clone(),
            image: k,
            lighting: letter,
            ext: ext.to_string(),
        }
        .file_name()
    }

    /// Saves grey image `k` under lighting `letter` as `NAMEkL.img`, then
    /// records it, with no camera settings (an image not from a camera, or
    /// from the serial grabber). Returns the file's path.
    pub fn save_image(
        &mut self,
        k: u32,
        letter: char,
        img: &ImgFile,
    ) -> Result<PathBuf, SessionError> {
        self.save_frame(k, letter, img, FrameSettings::default())
    }

    /// Saves a camera's frame as grey image `k` under lighting `letter`
    /// (`NAMEkL.img`), then records it with the exposure and gain the
    /// camera had when it took the frame. `vss grab` and the console both
    /// save through here. Returns the file's path.
    pub fn save_frame(
        &mut self,
        k: u32,
        letter: char,
        img: &ImgFile,
        camera: FrameSettings,
    ) -> Result<PathBuf, SessionError> {
        self.writable()?;
        check_image_number(k)?;
        if !self.letters().contains(&letter) {
            return Err(SessionError::UnknownLighting {
                letter,
                known: self.letters().iter().collect(),
            });
        }
        let file = self.file_name(k, Some(letter), "img");
        let bytes = formats::img::encode_img(img)?;
        // Until the manifest records the new image, the old file (if any)
        // stays reachable under a temporary name, so a failed commit (a
        // full disk, a take-over) leaves the folder as it was: no file the
        // manifest does not record, no recorded file replaced.
        let path = self.path(&file);
        let kept = self.keep_old(&path)?;
        if let Err(e) = self.write_file(&file, &bytes) {
            Self::put_back(&path, kept, false);
            return Err(e);
        }
        let before = self.manifest.clone();
        let rec = GreyRecord {
            letter,
            file: file.clone(),
            hash: stamp::hash(&bytes),
            width: u32::try_from(img.image.width()).unwrap_or(u32::MAX),
            height: u32::try_from(img.image.height()).unwrap_or(u32::MAX),
            exposure_us: camera.exposure_us,
            gain_db: camera.gain_db,
            saved: stamp::now_rfc3339(),
            version: env!("CARGO_PKG_VERSION").to_string(),
        };
        let r = self.record_mut(k)?;
        r.grey.retain(|g| g.letter != letter);
        r.grey.push(rec);
        r.grey.sort_by_key(|g| g.letter);
        if k > self.manifest.session.planned_images {
            self.manifest.session.planned_images = k;
        }
        if let Err(e) = self.commit() {
            self.manifest = before;
            Self::put_back(&path, kept, true);
            return Err(e);
        }
        Self::put_back(&path, kept, false);
        Ok(path)
    }

    /// A hard link to the file at `path` under a temporary name (one the
    /// next opening removes as a leftover), or `None` when there is none.
    /// A link takes no space, so it works on a full disk.
    fn keep_old(&self, path: &Path) -> Result<Option<PathBuf>, SessionError> {
        if !path.is_file() {
            return Ok(None);
        }
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let keep = self
            .dir
            .join(format!(".{name}.tmp.{}.kept", std::process::id()));
        let _ = fs::remove_file(&keep);
        fs::hard_link(path, &keep).map_err(|source| SessionError::Io {
            path: keep.clone(),
            source,
        })?;
        Ok(Some(keep))
    }

    /// After a save: with `undo`, puts the kept old file back at `path` (or
    /// removes the new one when there was none); without, drops the kept
    /// link.
    fn put_back(path: &Path, kept: Option<PathBuf>, undo: bool) {
        match (kept, undo) {
            (Some(k), true) => {
                let _ = fs::rename(&k, path);
            }
            (Some(k), false) => {
                let _ = fs::remove_file(k);
            }
            (None, true) => {
                let _ = fs::remove_file(path);
            }
            (None, false) => {}
        }
    }

    /// Reads back the grey images of `k`, in letter order.
    pub fn load_images(&self, k: u32) -> Result<Vec<(char, ImgFile)>, SessionError> {
        let rec = self.manifest.image(k);
        rec.map_or(&[][..], |r| r.grey.as_slice())
            .iter()
            .map(|g| Ok((g.letter, input::read_frame(&self.path(&g.file), g)?)))
            .collect()
    }

    /// Records a manual edit of the lines of `k`: writes the resulting lines
    /// as the new `NAMEk.ldr`, then appends `op` to the edit log.
    pub fn record_edit(&mut self, k: u32, op: &str, lines: &[Segment]) -> Result<(), SessionError> {
        self.writable()?;
        check_image_number(k)?;
        let file = self.file_name(k, None, "ldr");
        let bytes = formats::lines::format_lines(lines).into_bytes();
        self.write_file(&file, &bytes)?;
        let r = self.record_mut(k)?;
        r.edit.push(EditRecord {
            at: stamp::now_rfc3339(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            op: formats::sanitize(op),
            lines: lines.len() as u64,
            hash: stamp::hash(&bytes),
        });
        self.commit()
    }

    /// Takes back the last manual edit of `k`: writes `lines` (the set
    /// before it) as the new `NAMEk.ldr` and drops the edit from the log,
    /// so the log holds the edits in effect and an undo is not an edit.
    pub fn undo_edit(&mut self, k: u32, lines: &[Segment]) -> Result<(), SessionError> {
        self.writable()?;
        check_image_number(k)?;
        let file = self.file_name(k, None, "ldr");
        let bytes = formats::lines::format_lines(lines).into_bytes();
        self.write_file(&file, &bytes)?;
        let r = self.record_mut(k)?;
        r.edit.pop();
        self.commit()
    }

    /// The current lines of `k` (`.ldr`), with their attributes when no
    /// manual edit changed them since the outputs were made.
    pub fn load_lines(&self, k: u32) -> Result<Vec<Segment>, SessionError> {
        let file = self.file_name(k, None, "ldr");
        let mut lines = formats::lines::read_lines(&self.path(&file))?;
        if let Some(r) = self.manifest.image(k)
            && r.edit.is_empty()
            && let Some(a) = r.outputs.as_ref().and_then(|o| o.ldr_attributes.as_ref())
        {
            a.apply(&mut lines);
        }
        Ok(lines)
    }

    /// What is done and what is left: the checklist and the resume point.
    pub fn progress(&self) -> Progress {
        progress::progress(&self.manifest)
    }

    /// Checks every file the manifest names (exists, parses, unchanged) and
    /// lists stale outputs.
    pub fn check(&self) -> CheckReport {
        check::check(self)
    }

    // ----- internals -----

    /// Opened for writing, and the lock is still this session's (not
    /// taken over since): checked before every file is written.
    fn writable(&self) -> Result<(), SessionError> {
        match &self.lock {
            None => Err(SessionError::ReadOnly {
                dir: self.dir.clone(),
            }),
            Some(l) => l.check_held(),
        }
    }

    /// The record of image `k`, made with the default camera and location
    /// (images go round the cameras, then to the next location).
    fn record_mut(&mut self, k: u32) -> Result<&mut ImageRecord, SessionError> {
        check_image_number(k)?;
        let cams = self.manifest.session.cameras.max(1);
        let pos = match self.manifest.image.binary_search_by_key(&k, |r| r.number) {
            Ok(i) => i,
            Err(i) => {
                self.manifest.image.insert(
                    i,
                    ImageRecord {
                        number: k,
                        camera: (k - 1) % cams + 1,
                        location: (k - 1) / cams + 1,
                        cdf: None,
                        grey: Vec::new(),
                        outputs: None,
                        edit: Vec::new(),
                    },
                );
                i
            }
        };
        self.manifest
            .image
            .get_mut(pos)
            .ok_or(SessionError::BadImage(k))
    }

    /// Writes one file of the session, if the session is still this
    /// writer's (checked before each file, so a displaced writer stops at
    /// its next file).
    fn write_file(&self, file: &str, bytes: &[u8]) -> Result<(), SessionError> {
        self.writable()?;
        let path = self.path(file);
        write_atomic(&path, bytes).map_err(|source| SessionError::Io { path, source })
    }

    /// Writes `.ses` (if its numbers changed) and then the manifest: always
    /// after the data files they describe.
    fn commit(&mut self) -> Result<(), SessionError> {
        self.writable()?;
        let m = &mut self.manifest;
        m.session.modified = stamp::now_rfc3339();
        m.session.version = env!("CARGO_PKG_VERSION").to_string();
        let images = m
            .image
            .iter()
            .map(|r| r.number)
            .max()
            .unwrap_or(0)
            .max(m.session.planned_images)
            .max(1);
        let ses = Ses {
            images,
            cameras: m.session.cameras.max(1),
            lightings: u32::try_from(m.lighting.len()).unwrap_or(u32::MAX).max(1),
        };
        let ses_file = format!("{}.ses", self.name);
        let ses_text = formats::ses::format_ses(&ses);
        let ses_path = self.path(&ses_file);
        let on_disk = crate::fsutil::read_input_text(&ses_path, formats::max_len(&ses_path));
        if on_disk.ok().as_deref() != Some(ses_text.as_str()) {
            self.write_file(&ses_file, ses_text.as_bytes())?;
        }
        let manifest_file = format!("{}.toml", self.name);
        let text = self
            .manifest
            .to_toml()
            .map_err(|e| SessionError::Manifest {
                path: self.path(&manifest_file),
                line: 0,
                message: format!("cannot write the manifest: {e}"),
            })?;
        manifest::check_record_sizes(&text, &self.path(&manifest_file))?;
        self.write_file(&manifest_file, text.as_bytes())
    }

    /// Removes temporary files an interrupted save left behind. Holding
    /// the lock does not make every temporary file ours: a second vss
    /// asking for the lock has its own in flight here.
    fn remove_leftovers(&self) {
        crate::fsutil::sweep_stale_temps(&self.dir);
    }

    /// Temporary files of interrupted atomic writes: those whose writer is
    /// gone. Another writer's file in flight (a second vss asking for the
    /// lock, say) is not one.
    pub fn leftovers(&self) -> Vec<PathBuf> {
        crate::fsutil::stale_temps(&self.dir)
    }
}
