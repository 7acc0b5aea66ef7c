//! The Calibrate screen: the plate's grid drawn over the live view or a
//! grab, the views kept with a map of where the plate's corners have been
//! seen, and after `Enter` the parameters with their standard errors, the
//! worst views and the residuals magnified in Braille. The state and keys
//! are in `app/calibrate.rs`.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, split_panel};
use crate::calib::{self, COVERAGE, Calibration, Detection};
use crate::llv::{Point, Segment};
use crate::tui::app::{App, PLATE};
use crate::tui::widgets::preview::{Layer, Preview, PreviewMode};

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
    let s = &app.screens.calibrate;
    let cam = s.camera;
    let (panel, right) = split_panel(
        area,
        super::panel_width(crate::tui::keymap::ScreenId::Calibrate),
    );
    let mut lines = vec![
        Line::styled(format!("camera {cam} (c)  plate {PLATE}"), t.title()),
        Line::raw(format!(
            "live {} (v)  grab g  plate p{}",
            if app.cell.device.live { "ON" } else { "off" },
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
    let ramp: &[char] = if app.chrome.look.mode != PreviewMode::Ascii {
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
        let mut p = Preview::new(
            Layer::Lines(&segs),
            app.chrome.look.mode,
            app.chrome.look.colour,
        );
        p.frame = Some((c.width, c.height));
        p.render(inner, buf);
        return;
    }
    let title = match &app.cell.live {
        Some((c, img)) => format!("camera {c} {}×{}", img.width(), img.height()),
        None => "no picture: v live, g grab".into(),
    };
    let b = block(app, &title);
    let inner = b.inner(right);
    b.render(right, buf);
    if let Some((_, img)) = &app.cell.live {
        let grid = match &s.last {
            Some((c, Ok(d))) if *c == cam => outlines(d),
            _ => Vec::new(),
        };
        Preview::new(
            Layer::LinesOver(img, &grid),
            app.chrome.look.mode,
            app.chrome.look.colour,
        )
        .render(inner, buf);
    }
}
