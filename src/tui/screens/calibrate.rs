//! The Calibrate screen: a camera's intrinsic calibration on the cell. The
//! live view (or single grabs) shows the plate's grid where it is found;
//! `Space` keeps the view, with a counter and a map of where the plate's
//! corners have been seen; `Enter` solves (`crate::calib`, the same
//! functions as `vss calibrate`) and shows the residuals magnified in
//! Braille with the worst views named; `a` writes `camN.cdf` at the
//! profile's path for that camera, asking first when one is there and
//! keeping the old file as `camN.cdf.bak`. On the simulated cell `p` puts
//! the plate in view, at a new pose each freeze.
//!
//! Finding the grid takes a few tens of milliseconds a frame and solving a
//! dozen views a tenth of a second; both run on the UI thread, between
//! frames that come at most twice a second.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, split_panel};
use crate::calib::{self, COVERAGE, Calibration, Detection, Detector, Plate, View};
use crate::llv::{Point, Segment};
use crate::rig::sim::plate::{Mode, PlateTarget};
use crate::tui::app::{App, Level, Modal, Pending};
use crate::tui::event::{Cmd, DeviceCmd};
use crate::tui::keymap::{self, Action, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview};

/// The plate the console calibrates with (`profiles/plates/`).
pub const PLATE: &str = "squares";

/// The Calibrate screen's state.
#[derive(Debug, Default)]
pub struct CalibrateScreen {
    plate: Option<Result<Plate, String>>,
    detector: Detector,
    /// The grid in the latest frame: its camera and what was found.
    pub last: Option<(u32, Result<Detection, String>)>,
    /// Views kept: camera, view.
    pub kept: Vec<(u32, View)>,
    /// Image size of the views kept.
    size: (usize, usize),
    pub result: Option<(u32, Calibration)>,
    /// The last refusal of a solution.
    pub refused: Option<String>,
    pub centre_stated: bool,
    pub plate_shown: bool,
}

impl CalibrateScreen {
    pub fn handle_key(&mut self, key: KeyEvent) -> Option<Action> {
        keymap::lookup(Scope::Screen(ScreenId::Calibrate), &key)
    }

    fn plate(&mut self) -> Result<&Plate, String> {
        let p = self
            .plate
            .get_or_insert_with(|| Plate::load(PLATE).map_err(|e| e.to_string()));
        p.as_ref().map_err(Clone::clone)
    }

    /// Views kept of camera `cam`.
    pub fn views_of(&self, cam: u32) -> Vec<View> {
        self.kept
            .iter()
            .filter(|(c, _)| *c == cam)
            .map(|(_, v)| v.clone())
            .collect()
    }
}

impl App {
    /// A new live frame or grab: find the grid in it.
    pub fn calib_frame(&mut self) {
        let Some((cam, img)) = &self.live else { return };
        let cam = *cam;
        let found = match self.calib.plate() {
            Ok(p) => {
                let p = p.clone();
                self.calib
                    .detector
                    .detect(img, &p)
                    .map_err(|e| e.to_string())
            }
            Err(e) => Err(e),
        };
        self.calib.last = Some((cam, found));
    }

    pub fn calib_action(&mut self, a: Action) -> Vec<Cmd> {
        let cam = self.capture.camera;
        match a {
            Action::CalibPlate => {
                let plate = match self.calib.plate() {
                    Ok(p) => p.clone(),
                    Err(e) => {
                        self.log.push(Level::Error, e);
                        return Vec::new();
                    }
                };
                self.calib.plate_shown = !self.calib.plate_shown;
                let target = self.calib.plate_shown.then_some(PlateTarget {
                    plate,
                    mode: Mode::Held,
                });
                vec![Cmd::Device(DeviceCmd::SimTarget(target))]
            }
            Action::CalibKeep => {
                match (&self.calib.last, &self.live) {
                    (Some((c, Ok(d))), Some((_, img))) if *c == cam => {
                        if self.calib.kept.iter().any(|(k, _)| *k == cam)
                            && self.calib.size != img.size()
                        {
                            self.log
                                .push(Level::Warn, "this frame's size differs from the views kept");
                            return Vec::new();
                        }
                        self.calib.size = img.size();
                        let n = self.calib.views_of(cam).len() + 1;
                        let view = View {
                            name: format!("view {n}"),
                            corners: d.corners.clone(),
                        };
                        self.calib.kept.push((cam, view));
                        self.calib.result = None;
                        // The next view needs a new frame.
                        self.calib.last = None;
                        self.log
                            .push(Level::Info, format!("camera {cam}: view {n} kept"));
                    }
                    (Some((_, Err(e))), _) => self.log.push(Level::Warn, format!("not kept: {e}")),
                    _ => self.log.push(
                        Level::Warn,
                        "no grid to keep: v live or g grab, with the plate in view",
                    ),
                }
                Vec::new()
            }
            Action::CalibDrop => {
                if let Some(i) = self.calib.kept.iter().rposition(|(c, _)| *c == cam) {
                    self.calib.kept.remove(i);
                    self.calib.result = None;
                }
                Vec::new()
            }
            Action::CalibCentre => {
                self.calib.centre_stated = !self.calib.centre_stated;
                Vec::new()
            }
            Action::CalibSolve => {
                self.calib_solve(cam);
                Vec::new()
            }
            Action::CalibAccept => self.calib_accept(),
            _ => Vec::new(),
        }
    }

    fn calib_solve(&mut self, cam: u32) {
        let path = self.cdf_paths.get(cam as usize - 1).cloned().flatten();
        let scale = path
            .as_deref()
            .and_then(|p| crate::formats::cdf::read_cdf(p).ok())
            .and_then(|c| calib::scale_of(&c));
        let Some((sx, sy)) = scale else {
            self.log.push(
                Level::Error,
                format!("camera {cam}: the profile's .cdf gives no scale S (vss calibrate --scale SX,SY can)"),
            );
            return;
        };
        let (w, h) = self.calib.size;
        let o = calib::Options {
            width: w,
            height: h,
            sx,
            sy,
            estimate_scale: false,
            centre: self
                .calib
                .centre_stated
                .then_some([w as f64 / 2.0, h as f64 / 2.0]),
        };
        match calib::calibrate(&self.calib.views_of(cam), &o) {
            Ok(c) => {
                self.log.push(
                    Level::Info,
                    format!(
                        "camera {cam}: RMS {:.3} px over {} views",
                        c.rms,
                        c.views.len()
                    ),
                );
                for w in &c.warnings {
                    self.log.push(Level::Warn, w.clone());
                }
                self.calib.refused = None;
                self.calib.result = Some((cam, c));
            }
            Err(e) => {
                self.log.push(Level::Error, e.to_string());
                self.calib.refused = Some(e.to_string());
                self.calib.result = None;
            }
        }
    }

    fn calib_accept(&mut self) -> Vec<Cmd> {
        let Some((cam, _)) = &self.calib.result else {
            self.log
                .push(Level::Warn, "nothing to accept: Enter computes first");
            return Vec::new();
        };
        let Some(path) = self.cdf_paths.get(*cam as usize - 1).cloned().flatten() else {
            self.log.push(
                Level::Error,
                format!("the profile names no .cdf for camera {cam}"),
            );
            return Vec::new();
        };
        if path.exists() {
            self.modal = Some(Modal::Confirm {
                question: format!(
                    "replace S, C, f, D of {}? (its other entries are kept, the old file as .bak)",
                    path.display()
                ),
                on_yes: Pending::CalibWrite,
            });
            return Vec::new();
        }
        self.calib_write()
    }

    /// Writes the calibration shown into its camera's `.cdf`.
    pub fn calib_write(&mut self) -> Vec<Cmd> {
        let Some((cam, c)) = &self.calib.result else {
            return Vec::new();
        };
        let Some(path) = self.cdf_paths.get(*cam as usize - 1).cloned().flatten() else {
            return Vec::new();
        };
        match calib::write_intrinsics(&path, c) {
            Ok(_) => self
                .log
                .push(Level::Info, format!("wrote {}", path.display())),
            Err(e) => self.log.push(Level::Error, e.to_string()),
        }
        Vec::new()
    }
}

/// The cells found, as outlines to draw over the picture.
fn outlines(d: &Detection) -> Vec<Segment> {
    d.cells
        .iter()
        .flat_map(|c| {
            (0..4).map(move |k| {
                let (a, b) = (c[k], c[(k + 1) % 4]);
                Segment::new(Point::new(a[0], a[1]), Point::new(b[0], b[1]))
            })
        })
        .collect()
}

/// The residual vectors, magnified, as segments from each corner.
fn residuals(c: &Calibration) -> Vec<Segment> {
    let k = crate::report::calibration::magnification(c);
    c.views
        .iter()
        .flat_map(|v| v.residuals.iter())
        .map(|(p, r)| {
            Segment::new(
                Point::new(p[0], p[1]),
                Point::new(p[0] + k * r[0] + 0.5, p[1] + k * r[1] + 0.5),
            )
        })
        .collect()
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let s = &app.calib;
    let cam = app.capture.camera;
    let (panel, right) = split_panel(area, 34);
    let mut lines = vec![
        Line::styled(format!("camera {cam} (c)  plate {PLATE}"), t.title()),
        Line::raw(format!(
            "live {} (v)  grab g  plate p{}",
            if app.device.live { "ON" } else { "off" },
            if s.plate_shown { " (in view)" } else { "" }
        )),
    ];
    match &s.last {
        Some((c, Ok(d))) if *c == cam => lines.push(Line::styled(
            format!("grid: {} corners found", d.corners.len()),
            t.ok(),
        )),
        Some((c, Err(e))) if *c == cam => lines.push(Line::styled(format!("grid: {e}"), t.warn())),
        _ => lines.push(Line::raw("grid: no frame yet")),
    }
    let views = s.views_of(cam);
    lines.push(Line::raw(format!(
        "views kept: {} (Space keep, Bksp drop)",
        views.len()
    )));
    // Coverage: where the corners of the kept views fell.
    let (w, h) = s.size;
    let hits = calib::coverage(
        views.iter().flat_map(|v| v.corners.iter().map(|c| c.px)),
        w.max(1),
        h.max(1),
    );
    let most = hits.iter().copied().max().unwrap_or(0).max(1);
    let ramp: &[char] = if app.look.mode != crate::tui::widgets::preview::PreviewMode::Ascii {
        &[' ', '░', '▒', '▓', '█']
    } else {
        &[' ', '.', ':', '*', '#']
    };
    lines.push(Line::styled("coverage", t.title()));
    for row in 0..COVERAGE {
        let cells: String = (0..COVERAGE)
            .map(|col| {
                let v = hits[row * COVERAGE + col];
                let i = if v == 0 {
                    0
                } else {
                    1 + (v * 3).div_ceil(most).min(3)
                };
                let c = ramp[i.min(ramp.len() - 1)];
                format!("{c}{c}")
            })
            .collect();
        lines.push(Line::raw(format!(" |{cells}|")));
    }
    lines.push(Line::raw(format!(
        "centre C: {} (s)",
        if s.centre_stated {
            "stated, image middle"
        } else {
            "solved"
        }
    )));
    match &s.result {
        Some((c_cam, c)) if *c_cam == cam => {
            lines.push(Line::styled(
                format!("RMS {:.3} px  p95 {:.3} px", c.rms, c.p95),
                t.ok(),
            ));
            for p in &c.params {
                lines.push(Line::raw(format!(
                    "{:<3}{:>13.6} ±{:.1e}",
                    p.name, p.value, p.se
                )));
            }
            let mut worst: Vec<_> = c.views.iter().collect();
            worst.sort_by(|a, b| b.rms.total_cmp(&a.rms));
            let names: Vec<String> = worst
                .iter()
                .take(3)
                .map(|v| format!("{} {:.3}", v.name, v.rms))
                .collect();
            lines.push(Line::raw(format!("worst: {}", names.join(", "))));
            lines.push(Line::raw("a accept: write the camera's .cdf"));
        }
        _ => {
            if let Some(e) = &s.refused {
                lines.push(Line::styled(e.clone(), t.error()));
            }
            lines.push(Line::raw("Enter: compute"));
        }
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block(app, "calibration"))
        .render(panel, buf);
    if let Some((c_cam, c)) = &s.result
        && *c_cam == cam
    {
        let segs = residuals(c);
        let b = block(
            app,
            &format!(
                "residuals ×{} over {} corners",
                crate::report::calibration::magnification(c),
                segs.len()
            ),
        );
        let inner = b.inner(right);
        b.render(right, buf);
        let mut p = Preview::new(Layer::Lines(&segs), app.look.mode, app.look.colour);
        p.frame = Some((c.width, c.height));
        p.render(inner, buf);
        return;
    }
    let title = match &app.live {
        Some((c, img)) => format!("camera {c} {}×{}", img.width(), img.height()),
        None => "no picture: v live, g grab".into(),
    };
    let b = block(app, &title);
    let inner = b.inner(right);
    b.render(right, buf);
    if let Some((_, img)) = &app.live {
        let grid = match &s.last {
            Some((c, Ok(d))) if *c == cam => outlines(d),
            _ => Vec::new(),
        };
        Preview::new(Layer::LinesOver(img, &grid), app.look.mode, app.look.colour)
            .render(inner, buf);
    }
}
