//! The Calibrate screen: the plate's grid drawn over the live view or a
//! grab, the views kept with a map of where the plate's corners have been
//! seen, and after `Enter` the parameters with their standard errors, the
//! worst views and the residuals magnified in Braille. The state and keys
//! are in `app/calibrate.rs`.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{Theme, block, split_panel};
use crate::calib::{self, COVERAGE, Calibration, Detection, View};
use crate::llv::{Point, Segment};
use crate::tui::app::{App, CalibrateScreen, PLATE};
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

/// The panel's line on the grid in the latest frame.
fn grid_line(s: &CalibrateScreen, cam: u32, t: Theme) -> Line<'static> {
    match &s.last {
        Some((c, Ok(d))) if *c == cam => {
            Line::styled(format!("grid: {} corners found", d.corners.len()), t.ok())
        }
        Some((c, Err(e))) if *c == cam => {
            // What went wrong; what to do is in the message `Space` gives.
            let e = e.to_string();
            let what = e.split(": ").next().unwrap_or(&e);
            Line::styled(format!("grid: {what}"), t.warn())
        }
        _ => Line::raw("grid: no frame yet"),
    }
}

/// The coverage map: where the corners of the views kept fell.
fn coverage_lines(
    views: &[View],
    (w, h): (usize, usize),
    ascii: bool,
    t: Theme,
) -> Vec<Line<'static>> {
    let hits = calib::coverage(
        views.iter().flat_map(|v| v.corners.iter().map(|c| c.px)),
        w.max(1),
        h.max(1),
    );
    let most = hits.iter().copied().max().unwrap_or(0).max(1);
    let ramp: &[char] = if ascii {
        &[' ', '.', ':', '*', '#']
    } else {
        &[' ', '░', '▒', '▓', '█']
    };
    let mut lines = vec![Line::styled("coverage", t.title())];
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
    lines
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
            "live {} (v)  plate {} (p)",
            if app.cell.device.live { "ON" } else { "off" },
            if s.plate_shown { "shown" } else { "away" }
        )),
    ];
    // With a solution shown, its figures take the room of the grid line
    // and the coverage map (80 × 24 has sixteen rows here).
    let solved = s.result.as_ref().filter(|(c, _)| *c == cam).map(|(_, c)| c);
    if solved.is_none() {
        lines.push(grid_line(s, cam, t));
    }
    let views = s.views_of(cam);
    lines.push(Line::raw(format!(
        "views kept: {} (Space/Bksp)",
        views.len()
    )));
    if solved.is_none() {
        let ascii = app.chrome.look.mode == PreviewMode::Ascii;
        lines.extend(coverage_lines(&views, s.size, ascii, t));
    }
    lines.push(Line::raw(format!(
        "centre C: {} (s)",
        if s.centre_stated {
            "stated, image middle"
        } else {
            "solved"
        }
    )));
    match solved {
        Some(c) => {
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
                .take(2)
                .map(|v| format!("{} {:.3}", v.name, v.rms))
                .collect();
            lines.push(Line::styled("worst views (RMS px):", t.title()));
            lines.push(Line::raw(format!(" {}", names.join("  "))));
        }
        None => match &s.refused {
            // Why; what to do is in the message line (`!` shows it all).
            Some(e) => lines.push(Line::styled(
                format!("refused: {}", e.split(": ").next().unwrap_or(e)),
                t.error(),
            )),
            None => lines.push(Line::raw("Enter: compute")),
        },
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
