//! The Calibrate screen's state and keys: a camera's intrinsic calibration
//! on the cell, from live frames or from photographs in files. Each live
//! frame or grab is searched for the plate's grid; `Space` keeps the view.
//! `o` loads photographs (a folder, or files, typed): the grid is searched
//! in each and every one where it is found is kept; `n` shows them one by
//! one with the corners found, `Backspace` drops the one shown. `f` chooses
//! the plate (a built-in name or any plate file), `s` states the centre at
//! the image's middle, `S` at coordinates typed. `Enter` solves with the
//! same functions as `vss calibrate` (`crate::calib`); `a` asks, then has
//! the store worker write the camera's `.cdf` at the profile's path (the
//! old file kept as `.bak`). On the simulated cell `p` puts the plate in
//! view, at a new pose each freeze.
//!
//! Finding the grid takes about 10 ms of CPU a frame at 512² and solving a
//! dozen views about 35 ms (docs/calibration.md); both run on the UI
//! thread, between frames that come at most twice a second.

use std::path::{Path, PathBuf};

use super::{Ctx, Modal, Pending, PromptPurpose};
use crate::calib::{self, Calibration, DetectError, Detection, Detector, Plate, PlateError, View};
use crate::llv::GreyImage;
use crate::rig::sim::plate::{Mode, PlateTarget};
use crate::tui::event::{Cmd, DeviceCmd, StoreCmd};
use crate::tui::keymap::CalibrateAction;

/// The plate the console calibrates with (`profiles/plates/`).
pub const PLATE: &str = "squares";

/// The Calibrate screen's text fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Photographs to load: a folder, or files.
    Images,
    /// The plate: a built-in name or a file.
    Plate,
    /// The centre `C`: `X,Y` in pixels.
    Centre,
}

/// How the centre `C` is had.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Centre {
    Solved,
    /// Stated at the image's middle.
    Middle,
    /// Stated at these pixel coordinates.
    At([f64; 2]),
}

/// A photograph loaded from a file, and the grid found in it.
#[derive(Debug)]
pub struct Photo {
    pub name: String,
    pub image: GreyImage,
    pub found: Result<Detection, String>,
}

/// Most photographs loaded at once.
pub const MAX_PHOTOS: usize = 200;

/// Why a frame gave no grid.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    #[error(transparent)]
    Plate(#[from] PlateError),
    #[error(transparent)]
    Detect(#[from] DetectError),
}

/// The Calibrate screen's own state.
#[derive(Debug)]
pub struct CalibrateScreen {
    pub camera: u32,
    plate: Option<Plate>,
    detector: Detector,
    /// The grid in the latest frame: its camera and what was found (or why not).
    pub last: Option<(u32, Result<Detection, GridError>)>,
    /// Views kept: camera, view.
    pub kept: Vec<(u32, View)>,
    /// Image size of the views kept.
    pub size: (usize, usize),
    pub result: Option<(u32, Calibration)>,
    /// Why the last solution was refused.
    pub refused: Option<String>,
    pub centre: Centre,
    /// Whether `sy` of the scale `S` is estimated (else as stated).
    pub estimate_scale: bool,
    pub plate_shown: bool,
    /// The plate chosen: a built-in name or a file's path.
    pub plate_name: String,
    /// Photographs loaded from files, for camera `photos_camera`.
    pub photos: Vec<Photo>,
    pub photos_camera: u32,
    /// The photograph shown (instead of the live frame).
    pub shown: Option<usize>,
}

impl Default for CalibrateScreen {
    fn default() -> Self {
        CalibrateScreen {
            camera: 1,
            plate: None,
            detector: Detector::new(),
            last: None,
            kept: Vec::new(),
            size: (0, 0),
            result: None,
            refused: None,
            centre: Centre::Solved,
            estimate_scale: false,
            plate_shown: false,
            plate_name: PLATE.into(),
            photos: Vec::new(),
            photos_camera: 1,
            shown: None,
        }
    }
}

impl CalibrateScreen {
    /// The plate, read on first use.
    fn plate(&mut self) -> Result<Plate, PlateError> {
        if let Some(p) = &self.plate {
            return Ok(p.clone());
        }
        let p = Plate::load(&self.plate_name)?;
        self.plate = Some(p.clone());
        Ok(p)
    }

    /// Views kept of camera `cam`.
    pub fn views_of(&self, cam: u32) -> Vec<View> {
        self.kept
            .iter()
            .filter(|(c, _)| *c == cam)
            .map(|(_, v)| v.clone())
            .collect()
    }

    /// Whether view `name` of camera `cam` is kept.
    pub fn is_kept(&self, cam: u32, name: &str) -> bool {
        self.kept.iter().any(|(c, v)| *c == cam && v.name == name)
    }

    /// The photograph shown, if it is camera `cam`'s.
    pub fn shown_photo(&self, cam: u32) -> Option<&Photo> {
        (self.photos_camera == cam)
            .then(|| self.shown.and_then(|i| self.photos.get(i)))
            .flatten()
    }

    /// The centre to state for images of `w × h`, if any.
    pub fn centre_for(&self, w: usize, h: usize) -> Option<[f64; 2]> {
        match self.centre {
            Centre::Solved => None,
            Centre::Middle => Some([w as f64 / 2.0, h as f64 / 2.0]),
            Centre::At(c) => Some(c),
        }
    }

    /// A typed field: what to do with it, or why not (the field stays open).
    pub fn submitted(
        &mut self,
        field: Field,
        text: &str,
        ctx: &mut Ctx,
    ) -> Result<Vec<Cmd>, String> {
        match field {
            Field::Images => {
                let paths = photo_paths(text)?;
                self.load(paths, ctx);
            }
            Field::Plate => {
                let p = Plate::load(text).map_err(|e| e.to_string())?;
                ctx.info(format!(
                    "plate {}: {} ({})",
                    p.name,
                    p.describe(),
                    crate::tui::text::clean(&crate::calib::plate::in_use(text))
                ));
                self.plate_name = text.to_string();
                self.plate = Some(p);
                self.last = None;
                self.result = None;
                self.refused = None;
                // The photographs loaded are searched again for this plate.
                if !self.photos.is_empty() {
                    let paths: Vec<PathBuf> =
                        self.photos.iter().map(|p| PathBuf::from(&p.name)).collect();
                    self.load(paths, ctx);
                }
            }
            Field::Centre => {
                let v: Vec<f64> = text
                    .split(',')
                    .map(|t| t.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| format!("centre {text}: X,Y in pixels, e.g. 320.5,240"))?;
                match v[..] {
                    [x, y] if x.is_finite() && y.is_finite() => {
                        self.centre = Centre::At([x, y]);
                        self.result = None;
                        self.refused = None;
                        ctx.info(format!("centre C stated at {x}, {y} px"));
                    }
                    _ => return Err(format!("centre {text}: X,Y in pixels, e.g. 320.5,240")),
                }
            }
        }
        Ok(Vec::new())
    }

    /// Loads photographs for the camera shown: the grid searched in each,
    /// the views of that camera replaced by those where it was found.
    fn load(&mut self, paths: Vec<PathBuf>, ctx: &mut Ctx) {
        let cam = self.camera;
        let plate = match self.plate() {
            Ok(p) => p,
            Err(e) => {
                ctx.error(e.to_string());
                return;
            }
        };
        let mut photos = Vec::new();
        let mut unread = Vec::new();
        let mut size = None;
        for p in &paths {
            let name = crate::text::path(p);
            match crate::formats::imageio::read_any(p) {
                Ok(f) => {
                    let s = f.image.size();
                    if size.is_some_and(|z| z != s) {
                        let (w0, h0): (usize, usize) = size.unwrap_or_default();
                        unread.push(format!(
                            "{name}: {}×{}, the first {w0}×{h0} (one camera's views share a size)",
                            s.0, s.1
                        ));
                        continue;
                    }
                    size = Some(s);
                    let found = self
                        .detector
                        .detect(&f.image, &plate)
                        .map_err(|e| e.to_string());
                    photos.push(Photo {
                        name,
                        image: f.image,
                        found,
                    });
                }
                Err(e) => unread.push(e.to_string()),
            }
        }
        for u in &unread {
            ctx.warn(format!("not loaded: {u}"));
        }
        let Some(size) = size else {
            ctx.error("no photograph could be read");
            return;
        };
        self.kept.retain(|(c, _)| *c != cam);
        for p in &photos {
            if let Ok(d) = &p.found {
                self.kept.push((
                    cam,
                    View {
                        name: p.name.clone(),
                        corners: d.corners.clone(),
                    },
                ));
            }
        }
        let found = photos.iter().filter(|p| p.found.is_ok()).count();
        for p in photos.iter().filter(|p| p.found.is_err()) {
            if let Err(e) = &p.found {
                ctx.warn(format!("{}: {e}", short_name(&p.name)));
            }
        }
        ctx.info(format!(
            "camera {cam}: {} photographs loaded, the grid found and kept in {found}; n shows each, Backspace drops the one shown, Enter computes",
            photos.len()
        ));
        self.size = size;
        self.photos = photos;
        self.photos_camera = cam;
        self.shown = (!self.photos.is_empty()).then_some(0);
        self.result = None;
        self.refused = None;
    }

    /// A new live frame or grab: finds the grid in it.
    pub fn frame(&mut self, camera: u32, img: &GreyImage) {
        self.shown = None;
        let found = self
            .plate()
            .map_err(GridError::from)
            .and_then(|p| Ok(self.detector.detect(img, &p)?));
        self.last = Some((camera, found));
    }

    pub fn update(&mut self, a: CalibrateAction, ctx: &mut Ctx) -> Vec<Cmd> {
        let cam = self.camera;
        match a {
            CalibrateAction::Camera => ctx.next_camera(&mut self.camera),
            CalibrateAction::ToggleLive => ctx.toggle_live(cam),
            CalibrateAction::Grab => ctx.grab(cam),
            CalibrateAction::Plate => match self.plate() {
                Ok(plate) => {
                    self.plate_shown = !self.plate_shown;
                    let target = self.plate_shown.then_some(PlateTarget {
                        plate,
                        mode: Mode::Held,
                    });
                    vec![Cmd::Device(DeviceCmd::SimTarget(target))]
                }
                Err(e) => {
                    ctx.error(e.to_string());
                    Vec::new()
                }
            },
            CalibrateAction::Keep if self.shown_photo(cam).is_some() => {
                let (name, found) = match self.shown_photo(cam) {
                    Some(p) => (p.name.clone(), p.found.clone()),
                    None => return Vec::new(),
                };
                match found {
                    Ok(_) if self.is_kept(cam, &name) => {
                        ctx.info(format!("{} is kept already", short_name(&name)));
                    }
                    Ok(d) => {
                        self.kept.push((
                            cam,
                            View {
                                name: name.clone(),
                                corners: d.corners,
                            },
                        ));
                        self.result = None;
                        self.refused = None;
                        ctx.info(format!("camera {cam}: {} kept", short_name(&name)));
                    }
                    Err(e) => ctx.warn(format!("not kept: {e}")),
                }
                Vec::new()
            }
            CalibrateAction::Keep => {
                self.keep(cam, ctx);
                Vec::new()
            }
            CalibrateAction::Drop if self.shown_photo(cam).is_some() => {
                let name = self
                    .shown_photo(cam)
                    .map(|p| p.name.clone())
                    .unwrap_or_default();
                if self.is_kept(cam, &name) {
                    self.kept.retain(|(c, v)| !(*c == cam && v.name == name));
                    self.result = None;
                    self.refused = None;
                    ctx.info(format!("camera {cam}: {} dropped", short_name(&name)));
                } else {
                    ctx.info(format!("camera {cam}: {} is not kept", short_name(&name)));
                }
                Vec::new()
            }
            CalibrateAction::Drop => {
                match self.kept.iter().rposition(|(c, _)| *c == cam) {
                    Some(i) => {
                        let (_, v) = self.kept.remove(i);
                        self.result = None;
                        self.refused = None;
                        ctx.info(format!("camera {cam}: {} dropped", v.name));
                    }
                    None => ctx.info(format!("camera {cam}: no view kept")),
                }
                Vec::new()
            }
            CalibrateAction::Centre => {
                self.centre = match self.centre {
                    Centre::Solved => Centre::Middle,
                    _ => Centre::Solved,
                };
                self.result = None;
                self.refused = None;
                Vec::new()
            }
            CalibrateAction::Scale => {
                self.estimate_scale = !self.estimate_scale;
                self.result = None;
                self.refused = None;
                Vec::new()
            }
            CalibrateAction::CentreAt => {
                let offered = match self.centre {
                    Centre::At([x, y]) => format!("{x},{y}"),
                    _ => String::new(),
                };
                ctx.chrome.modal = Some(
                    Modal::prompt(
                        "centre C (px):",
                        "X,Y in pixels, e.g. 320.5,240 (negative allowed)",
                        offered,
                        64,
                        PromptPurpose::Calibrate(Field::Centre),
                    )
                    .selected(),
                );
                Vec::new()
            }
            CalibrateAction::Open => {
                ctx.chrome.modal = Some(Modal::prompt(
                    "photographs to load:",
                    "a folder (every .jpg .png .pgm .tif .bmp .img in it), or files separated by spaces",
                    String::new(),
                    4096,
                    PromptPurpose::Calibrate(Field::Images),
                ));
                Vec::new()
            }
            CalibrateAction::PlateFile => {
                ctx.chrome.modal = Some(
                    Modal::prompt(
                        "plate:",
                        "a built-in plate (squares, checkerboard) or a plate file's path (.toml)",
                        self.plate_name.clone(),
                        4096,
                        PromptPurpose::Calibrate(Field::Plate),
                    )
                    .selected(),
                );
                Vec::new()
            }
            CalibrateAction::Next => {
                if self.photos.is_empty() || self.photos_camera != cam {
                    ctx.info(format!(
                        "no photographs of camera {cam} loaded: o loads a folder or files"
                    ));
                } else {
                    let i = self.shown.map_or(0, |i| (i + 1) % self.photos.len());
                    self.shown = Some(i);
                }
                Vec::new()
            }
            CalibrateAction::Solve => {
                self.solve(cam, ctx);
                Vec::new()
            }
            CalibrateAction::Accept => self.accept(ctx),
        }
    }

    fn keep(&mut self, cam: u32, ctx: &mut Ctx) {
        let size = ctx.cell.live.as_ref().map(|(_, img)| img.size());
        match (&self.last, size) {
            (Some((c, Ok(d))), Some(size)) if *c == cam => {
                if self.kept.iter().any(|(k, _)| *k == cam) && self.size != size {
                    ctx.warn(format!(
                        "not kept: this frame is {}×{}, the views kept are {}×{}",
                        size.0, size.1, self.size.0, self.size.1
                    ));
                    return;
                }
                self.size = size;
                let n = self.views_of(cam).len() + 1;
                let view = View {
                    name: format!("view {n}"),
                    corners: d.corners.clone(),
                };
                self.kept.push((cam, view));
                self.result = None;
                self.refused = None;
                // The next view needs a new frame.
                self.last = None;
                ctx.info(format!("camera {cam}: view {n} kept"));
            }
            (Some((c, Err(e))), _) if *c == cam => ctx.warn(format!("not kept: {e}")),
            _ => ctx.warn(format!(
                "no grid of camera {cam} to keep: v live or g grab, with the plate in view"
            )),
        }
    }

    fn solve(&mut self, cam: u32, ctx: &mut Ctx) {
        let Some(m) = ctx.cell.camera_model(cam) else {
            let why = ctx
                .cell
                .camera_problem(cam)
                .unwrap_or_else(|| "its camera description is not read yet".to_string());
            ctx.error(format!(
                "camera {cam}: no scale S to calibrate with — {why}; `vss calibrate --camera {cam} --scale SX,SY IMAGES…` makes the first one"
            ));
            return;
        };
        let (w, h) = self.size;
        let o = calib::Options {
            width: w,
            height: h,
            sx: m.sx,
            sy: m.sy,
            estimate_scale: self.estimate_scale,
            centre: self.centre_for(w, h),
            full_model: false,
        };
        match calib::calibrate(&self.views_of(cam), &o) {
            Ok(c) => {
                ctx.info(format!(
                    "camera {cam}: RMS {:.3} px over {} views",
                    c.rms,
                    c.views.len()
                ));
                for w in &c.warnings {
                    ctx.warn(w.clone());
                }
                self.refused = None;
                self.result = Some((cam, c));
            }
            Err(e) => {
                // The refusal names the command line's flags; here a key
                // does the same. The panel's line is the short why.
                let (why, short) = match e {
                    calib::CalibError::ScaleMismatch { .. } => (
                        format!("{e}; here `e` estimates sy"),
                        "views do not fit S (e)".to_string(),
                    ),
                    _ => (e.to_string(), e.to_string()),
                };
                ctx.error(why);
                self.refused = Some(short);
                self.result = None;
            }
        }
    }

    fn accept(&mut self, ctx: &mut Ctx) -> Vec<Cmd> {
        let Some((cam, _)) = &self.result else {
            ctx.warn("nothing to accept: Enter computes first");
            return Vec::new();
        };
        let Some(path) = ctx.cell.cdf_paths.get(*cam as usize - 1).cloned().flatten() else {
            ctx.error(format!("the profile names no .cdf for camera {cam}"));
            return Vec::new();
        };
        ctx.ask(
            format!(
                "write S, C, f, D of camera {cam} into {}? (its other entries are kept, an old file as .bak)",
                crate::text::path(&path)
            ),
            Pending::CalibWrite,
        );
        Vec::new()
    }

    /// The question was answered yes: the store writes the `.cdf`.
    pub fn confirmed(&mut self) -> Vec<Cmd> {
        match &self.result {
            Some((camera, c)) => vec![Cmd::Store(StoreCmd::WriteCdf {
                camera: *camera,
                calibration: Box::new(c.clone()),
            })],
            None => Vec::new(),
        }
    }
}

/// The last part of a path, for messages.
pub fn short_name(name: &str) -> String {
    Path::new(name)
        .file_name()
        .map_or(name.to_string(), |n| n.to_string_lossy().into_owned())
}

/// The photographs a typed text names: a folder's images (by name, numbers
/// in order), a file (its name may hold spaces), or files separated by
/// spaces.
fn photo_paths(text: &str) -> Result<Vec<PathBuf>, String> {
    if text.is_empty() {
        return Err("type a folder or files".into());
    }
    let p = Path::new(text);
    let paths: Vec<PathBuf> = if p.is_dir() {
        let rd = std::fs::read_dir(p).map_err(|e| format!("{text}: {e}"))?;
        let mut v: Vec<PathBuf> = rd
            .filter_map(Result::ok)
            .map(|e| e.path())
            // By name alone: one that is not a file (a FIFO, a link) is
            // said "not loaded" with why, not passed over without a word.
            .filter(|p| crate::formats::imageio::ImageKind::of(p).is_some())
            .collect();
        v.sort_by_key(|p| natural_key(&p.to_string_lossy()));
        if v.is_empty() {
            return Err(format!(
                "{text}: no images (.jpg .png .pgm .tif .bmp .img) in it"
            ));
        }
        v
    } else if p.is_file() {
        // One file, whose name may hold spaces ("plate 1.jpg").
        vec![p.to_path_buf()]
    } else {
        let v: Vec<PathBuf> = text.split_whitespace().map(PathBuf::from).collect();
        if let Some(missing) = v.iter().find(|p| !p.is_file()) {
            return Err(format!(
                "{}: no such file (a folder, or files separated by spaces)",
                crate::text::path(missing)
            ));
        }
        v
    };
    if paths.len() > MAX_PHOTOS {
        return Err(format!(
            "{} images; at most {MAX_PHOTOS} at once",
            paths.len()
        ));
    }
    Ok(paths)
}

/// A sort key that puts `name_2` before `name_10`.
fn natural_key(s: &str) -> Vec<(String, u64)> {
    let mut out = Vec::new();
    let mut text = String::new();
    let mut num: Option<u64> = None;
    for ch in s.chars() {
        if let Some(d) = ch.to_digit(10) {
            num = Some(
                num.unwrap_or(0)
                    .saturating_mul(10)
                    .saturating_add(u64::from(d)),
            );
        } else {
            if let Some(n) = num.take() {
                out.push((std::mem::take(&mut text), n));
            }
            text.push(ch);
        }
    }
    out.push((text, num.unwrap_or(0)));
    out
}
