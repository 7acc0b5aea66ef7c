//! The store worker: owns the open [`Session`] (and its lock) and does all
//! the disk work the console asks for — list, create, open (resume), save
//! images and outputs, record edits, read images back, export the reports —
//! reporting each result or error as a message. On quit the UI waits for it
//! to finish what is queued, so nothing the operator saw saved is lost.

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::send;
use crate::formats;
use crate::formats::img::ImgFile;
use crate::llv::lens::CameraModel;
use crate::profile::Profile;
use crate::report::{self, ImageReport};
use crate::session::manifest::TimingsRecord;
use crate::session::{OutputSet, OutputState, Session, SessionError, Step};
use crate::tui::event::{FileState, ImageState, Msg, SessionView, StoreCmd, StoreEvent};

/// The UI's handle on the store worker.
pub struct StoreHandle {
    tx: Sender<StoreCmd>,
    join: JoinHandle<()>,
}

impl StoreHandle {
    pub fn send(&self, cmd: StoreCmd) {
        let _ = self.tx.send(cmd);
    }

    /// Closes the queue and waits (at most `limit`) for the saves in it.
    pub fn finish(self, limit: Duration) {
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
    let join = std::thread::Builder::new()
        .name("vss-store".into())
        .spawn(move || Store::new(profile, ui).run(rx))?;
    Ok(StoreHandle { tx, join })
}

/// The disk side of the console; usable without a thread (tests, benches).
pub struct Store {
    profile: Profile,
    ui: Sender<Msg>,
    session: Option<Session>,
}

impl Store {
    pub fn new(profile: Profile, ui: Sender<Msg>) -> Store {
        Store {
            profile,
            ui,
            session: None,
        }
    }

    fn run(mut self, rx: Receiver<StoreCmd>) {
        self.reply(StoreEvent::Cameras(self.camera_models()));
        while let Ok(cmd) = rx.recv() {
            self.handle(cmd);
        }
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

    fn try_handle(&mut self, cmd: StoreCmd) -> Result<(), String> {
        match cmd {
            StoreCmd::List => {
                let list = self.list();
                self.reply(StoreEvent::Sessions(list));
            }
            StoreCmd::Create(name) => {
                self.session = None;
                let s = Session::create(&self.survey_dir(), &name, &self.profile)
                    .map_err(|e| format!("cannot create session {name}: {e}"))?;
                self.opened(s);
            }
            StoreCmd::Open(dir) => {
                self.session = None;
                let s = match Session::open(&dir) {
                    Ok(s) => s,
                    Err(e @ SessionError::Locked { .. }) => {
                        let stale = Session::inspect(&dir)
                            .ok()
                            .and_then(|s| s.lock_holder())
                            .is_some_and(|h| h.is_stale());
                        if !stale {
                            return Err(e.to_string());
                        }
                        send(
                            &self.ui,
                            Msg::Store(StoreEvent::Saved(format!(
                                "(took over the stale lock of {})",
                                dir.display()
                            ))),
                        );
                        Session::open_take_over(&dir).map_err(|e| e.to_string())?
                    }
                    Err(e) => return Err(e.to_string()),
                };
                self.opened(s);
            }
            StoreCmd::SaveImage {
                k,
                letter,
                camera,
                location,
                image,
            } => {
                let cdf = self.cdf_path(camera);
                let s = self.session_mut()?;
                let known = s
                    .manifest()
                    .image(k)
                    .map(|r| (r.camera, r.location, r.cdf.is_some()));
                if known.is_none_or(|(c, l, has_cdf)| {
                    c != camera || l != location || (!has_cdf && cdf.is_some())
                }) {
                    s.set_image_info(k, camera, location, cdf.as_deref())
                        .map_err(|e| e.to_string())?;
                }
                let file = s.file_name(k, Some(letter), "img");
                let stem = file.trim_end_matches(".img").to_string();
                s.save_image(k, letter, &ImgFile::new(image).with_comment(stem))
                    .map_err(|e| e.to_string())?;
                self.reply(StoreEvent::Saved(file));
                self.updated(false);
            }
            StoreCmd::SaveOutputs { k, outputs, params } => {
                let s = self.session_mut()?;
                let t = &outputs.timings;
                let set = OutputSet {
                    corrected: &outputs.corrected,
                    edges_h: Some(&outputs.edges_h),
                    edges_v: Some(&outputs.edges_v),
                    lines_raw: Some(&outputs.lines_raw),
                    lines: Some(&outputs.lines),
                    timings: TimingsRecord {
                        lens_us: t.lens_us,
                        edges_us: t.edges_us,
                        lines_us: t.lines_us,
                        connect_us: t.connect_us,
                    },
                };
                s.save_output_set(k, &set, &params)
                    .map_err(|e| e.to_string())?;
                let what = format!("outputs of image {k} (.hpo .vpo .lex .ldr)");
                self.reply(StoreEvent::Saved(what));
                self.updated(false);
            }
            StoreCmd::RecordEdit { k, what, lines } => {
                let s = self.session_mut()?;
                s.record_edit(k, &what, &lines).map_err(|e| e.to_string())?;
                let file = s.file_name(k, None, "ldr");
                self.reply(StoreEvent::Saved(format!("{file} after {what}")));
                self.updated(false);
            }
            StoreCmd::Load(k) => {
                let s = self.session_mut()?;
                let imgs = s.load_images(k).map_err(|e| e.to_string())?;
                let images = imgs.into_iter().map(|(l, f)| (l, f.image)).collect();
                let edited = s.manifest().image(k).is_some_and(|r| !r.edit.is_empty());
                let lines = if edited { s.load_lines(k).ok() } else { None };
                self.reply(StoreEvent::Images { k, images });
                if let Some(lines) = lines {
                    self.reply(StoreEvent::Lines { k, lines });
                }
            }
            StoreCmd::Redo(k) => {
                self.session_mut()?;
                self.reply(StoreEvent::Saved(format!(
                    "nothing yet: image {k}'s files are replaced as its new captures come in"
                )));
            }
            StoreCmd::Export => {
                let paths = self.export()?;
                self.reply(StoreEvent::Reports(paths));
                self.updated(false);
            }
            StoreCmd::Refresh => self.updated(true),
        }
        Ok(())
    }

    fn session_mut(&mut self) -> Result<&mut Session, String> {
        self.session
            .as_mut()
            .ok_or_else(|| "no session open: create or open one on the Survey screen".to_string())
    }

    fn opened(&mut self, s: Session) {
        let v = view(&s, false);
        self.session = Some(s);
        self.reply(StoreEvent::Opened(v));
        let list = self.list();
        self.reply(StoreEvent::Sessions(list));
    }

    fn updated(&self, check: bool) {
        if let Some(s) = &self.session {
            self.reply(StoreEvent::Updated(view(s, check)));
        }
    }

    /// Sessions under the survey folder: name, folder, checklist summary.
    fn list(&self) -> Vec<(String, PathBuf, String)> {
        let Ok(rd) = std::fs::read_dir(self.survey_dir()) else {
            return Vec::new();
        };
        let mut out: Vec<_> = rd
            .flatten()
            .filter(|e| e.path().is_dir())
            .filter_map(|e| {
                let dir = e.path();
                let s = Session::inspect(&dir).ok()?;
                let p = s.progress();
                let (done, all) = p.done();
                let busy = s
                    .lock_holder()
                    .map_or(String::new(), |h| format!(" (in use by {})", h.user));
                Some((
                    s.name().as_str().to_string(),
                    dir,
                    format!("{done}/{all} done{busy}"),
                ))
            })
            .collect();
        out.sort();
        out
    }

    /// Where sessions live: the profile's `survey.dir`. A relative one is
    /// taken from the folder the console was started in (where an operator
    /// expects their survey), not the profile's folder (which may be the
    /// installed, shared `profiles/`).
    fn survey_dir(&self) -> PathBuf {
        self.profile.survey.dir.clone()
    }

    fn cdf_path(&self, camera: u32) -> Option<PathBuf> {
        self.profile.cdf_path(camera).filter(|p| p.is_file())
    }

    fn camera_models(&self) -> Vec<Option<CameraModel>> {
        (1..=self.profile.survey.cameras.max(1))
            .map(|c| {
                let p = self.cdf_path(c)?;
                formats::cdf::read_cdf(&p).ok()?.camera_model()
            })
            .collect()
    }

    /// Writes the survey report `NAME.ps` and one `NAMEk.svg` per image
    /// with outputs.
    fn export(&mut self) -> Result<Vec<PathBuf>, String> {
        let s = self.session.as_ref().ok_or("no session open")?;
        let mut reports = Vec::new();
        for rec in &s.manifest().image {
            let k = rec.number;
            if rec.outputs.is_none() {
                continue;
            }
            reports.push(image_report(s, k)?);
        }
        if reports.is_empty() {
            return Err(
                "nothing to report yet: no image of the session has outputs (accept one first)"
                    .into(),
            );
        }
        let name = s.name().as_str().to_string();
        let mut paths = Vec::new();
        let ps = s.path(&format!("{name}.ps"));
        let text = report::ps::survey_report(&format!("Survey {name}"), &reports);
        crate::fsutil::write_atomic(&ps, text.as_bytes())
            .map_err(|e| format!("{}: {e}", ps.display()))?;
        paths.push(ps);
        for (r, rec) in reports
            .iter()
            .zip(s.manifest().image.iter().filter(|r| r.outputs.is_some()))
        {
            let svg = s.path(&format!("{name}{}.svg", rec.number));
            crate::fsutil::write_atomic(&svg, report::svg::image_svg(r).as_bytes())
                .map_err(|e| format!("{}: {e}", svg.display()))?;
            paths.push(svg);
        }
        Ok(paths)
    }
}

/// Everything the report shows of image `k`, read from the session's files.
fn image_report(s: &Session, k: u32) -> Result<ImageReport, String> {
    let greys: Vec<(String, crate::llv::GreyImage)> = s
        .load_images(k)
        .map_err(|e| e.to_string())?
        .into_iter()
        .map(|(l, f)| (s.file_name(k, Some(l), "img"), f.image))
        .collect();
    let (width, height) = greys.first().map_or((0, 0), |g| g.1.size());
    let edges = |ext: &str| formats::edgefile::read_edges(&s.path(&s.file_name(k, None, ext))).ok();
    let lines_raw = formats::lines::read_lines(&s.path(&s.file_name(k, None, "lex"))).ok();
    let lines = s.load_lines(k).ok();
    let mut notes = Vec::new();
    if let Some(o) = s.manifest().image(k).and_then(|r| r.outputs.as_ref()) {
        notes.push(format!(
            "edges H {} V {}, lines {} raw {}",
            o.counts.edges_h, o.counts.edges_v, o.counts.lines, o.counts.lines_raw
        ));
        notes.push(format!(
            "times (ms): lens {:.1} edges {:.1} lines {:.1} connect {:.1}",
            o.timings.lens_us as f64 / 1e3,
            o.timings.edges_us as f64 / 1e3,
            o.timings.lines_us as f64 / 1e3,
            o.timings.connect_us as f64 / 1e3
        ));
        for sp in crate::llv::params::PARAMS {
            if let Some(v) = o.params.get(sp.key) {
                notes.push(format!("{} = {}", sp.key, crate::tui::app::fmt_value(v)));
            }
        }
        notes.push(format!("made {} by vss {}", o.made, o.version));
    }
    Ok(ImageReport {
        title: format!("{}{k}", s.name()),
        width,
        height,
        greys,
        edges_h: edges("hpo"),
        edges_v: edges("vpo"),
        lines_raw,
        lines,
        notes,
    })
}

/// The console's picture of a session. With `check`, every file is read
/// and parsed (slower: on request only).
pub fn view(s: &Session, check: bool) -> SessionView {
    let p = s.progress();
    let images = p
        .images
        .iter()
        .map(|i| ImageState {
            k: i.number,
            camera: i.camera,
            location: i.location,
            captured: i.captured.clone(),
            outputs: i.outputs != OutputState::Missing,
            stale: matches!(i.outputs, OutputState::Stale(_)),
            edits: i.edits,
        })
        .collect();
    let next = p.next_step().map(|st| match st {
        Step::Capture { image, letter } => (image, Some(letter)),
        Step::Process { image } => (image, None),
    });
    let report = check.then(|| s.check());
    let name = s.name().as_str().to_string();
    let mut names: Vec<String> = vec![format!("{name}.ses"), format!("{name}.toml")];
    names.extend(
        s.manifest()
            .files()
            .into_iter()
            .map(|(_, f, _)| f.to_string()),
    );
    if let Ok(rd) = std::fs::read_dir(s.dir()) {
        let mut extra: Vec<String> = rd
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".ps") || n.ends_with(".svg"))
            .collect();
        extra.sort();
        names.extend(extra);
    }
    names.dedup();
    let files = names
        .into_iter()
        .map(|n| {
            let path = s.path(&n);
            let problem = report
                .as_ref()
                .and_then(|r| r.problems.iter().find(|p| p.contains(&n)).cloned());
            let (state, ok) = match (std::fs::metadata(&path), problem) {
                (Err(_), _) => ("missing".to_string(), false),
                (Ok(_), Some(p)) => (p, false),
                (Ok(m), None) => (format!("ok {:.1} KiB", m.len() as f64 / 1024.0), true),
            };
            FileState {
                name: crate::tui::text::clean(&n),
                state: crate::tui::text::clean(&state),
                ok,
            }
        })
        .collect();
    SessionView {
        name,
        dir: s.dir().to_path_buf(),
        letters: s.letters(),
        images,
        next,
        files,
    }
}
