//! The Calibrate screen's state and keys: a camera's intrinsic calibration
//! on the cell. Each live frame or grab is searched for the plate's grid;
//! `Space` keeps the view; `Enter` solves with the same functions as `vss
//! calibrate` (`crate::calib`); `a` asks, then has the store worker write
//! the camera's `.cdf` at the profile's path (the old file kept as
//! `.bak`). On the simulated cell `p` puts the plate in view, at a new pose
//! each freeze.
//!
//! Finding the grid takes about 10 ms of CPU a frame at 512² and solving a
//! dozen views about 35 ms (docs/calibration.md); both run on the UI
//! thread, between frames that come at most twice a second.

use super::{Ctx, Pending};
use crate::calib::{self, Calibration, DetectError, Detection, Detector, Plate, PlateError, View};
use crate::llv::GreyImage;
use crate::rig::sim::plate::{Mode, PlateTarget};
use crate::tui::event::{Cmd, DeviceCmd, StoreCmd};
use crate::tui::keymap::CalibrateAction;

/// The plate the console calibrates with (`profiles/plates/`).
pub const PLATE: &str = "squares";

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
    pub centre_stated: bool,
    pub plate_shown: bool,
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
            centre_stated: false,
            plate_shown: false,
        }
    }
}

impl CalibrateScreen {
    /// The plate, read on first use.
    fn plate(&mut self) -> Result<Plate, PlateError> {
        if let Some(p) = &self.plate {
            return Ok(p.clone());
        }
        let p = Plate::load(PLATE)?;
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

    /// A new live frame or grab: finds the grid in it.
    pub fn frame(&mut self, camera: u32, img: &GreyImage) {
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
            CalibrateAction::Keep => {
                self.keep(cam, ctx);
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
                self.centre_stated = !self.centre_stated;
                self.result = None;
                self.refused = None;
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
                .unwrap_or("its camera description is not read yet")
                .to_string();
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
            estimate_scale: false,
            centre: self
                .centre_stated
                .then_some([w as f64 / 2.0, h as f64 / 2.0]),
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
                ctx.error(e.to_string());
                self.refused = Some(e.to_string());
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
                path.display()
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
