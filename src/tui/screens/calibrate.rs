//! The Calibrate screen: the plate's grid drawn over the live view, a grab
//! or a photograph loaded from a file, the views kept with a map of where
//! the plate's corners have been seen, and after `Enter` the parameters with
//! their standard errors, the worst views and the residuals magnified: the
//! mean residual of the corners in each cell of a grid sized to the pane, so
//! that even at 80 × 24 the picture shows where the fit is off, not a blot
//! of every corner's vector. The state and keys are in `app/calibrate.rs`.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{Theme, block, split_panel};
use crate::calib::{self, COVERAGE, Calibration, Detection, View};
use crate::llv::{Point, Segment};
use crate::tui::app::{App, CalibrateScreen};
use crate::tui::app::{Centre, short_name};
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

/// The residuals, magnified: the mean residual of the corners in each cell
/// of a `cols × rows` grid over the image, a segment from the cell's mean
/// corner position.
fn residuals(c: &Calibration, cols: usize, rows: usize) -> Vec<Segment> {
    let k = crate::report::calibration::magnification(c);
    let (cols, rows) = (cols.max(1), rows.max(1));
    let mut sums = vec![([0.0f64; 4], 0usize); cols * rows];
    for (p, r) in c.views.iter().flat_map(|v| v.residuals.iter()) {
        let i = ((p[0] / c.width.max(1) as f64 * cols as f64).floor() as isize)
            .clamp(0, cols as isize - 1) as usize;
        let j = ((p[1] / c.height.max(1) as f64 * rows as f64).floor() as isize)
            .clamp(0, rows as isize - 1) as usize;
        let e = &mut sums[j * cols + i];
        e.0[0] += p[0];
        e.0[1] += p[1];
        e.0[2] += r[0];
        e.0[3] += r[1];
        e.1 += 1;
    }
    sums.iter()
        .filter(|(_, n)| *n > 0)
        .map(|(s, n)| {
            let n = *n as f64;
            let (x, y) = (s[0] / n, s[1] / n);
            Segment::new(
                Point::new(x, y),
                Point::new(x + k * s[2] / n + 0.5, y + k * s[3] / n + 0.5),
            )
        })
        .collect()
}

/// The panel's line on the grid in the latest frame.
fn grid_line(s: &CalibrateScreen, cam: u32, t: Theme) -> Line<'static> {
    if let Some(p) = s.shown_photo(cam) {
        let i = s.shown.unwrap_or(0) + 1;
        let n = s.photos.len();
        return match &p.found {
            Ok(d) => Line::styled(
                format!(
                    "photo {i}/{n}: {} corners, {} (n)",
                    d.corners.len(),
                    if s.is_kept(cam, &p.name) {
                        "kept"
                    } else {
                        "dropped"
                    }
                ),
                t.ok(),
            ),
            Err(e) => Line::styled(
                format!("photo {i}/{n}: {}", e.split(": ").next().unwrap_or(e)),
                t.warn(),
            ),
        };
    }
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
    let mut lines = vec![Line::styled(
        format!("camera {cam} (c) plate {} (f)", short_name(&s.plate_name)),
        t.title(),
    )];
    // With a solution shown, its figures take the room of the live view's
    // line, the grid line and the coverage map (80 × 24 has sixteen rows
    // here; the residuals replace the picture, and the key bar keeps v, p).
    let solved = s.result.as_ref().filter(|(c, _)| *c == cam).map(|(_, c)| c);
    if solved.is_none() {
        lines.push(Line::raw(format!(
            "live {} (v)  plate {} (p)",
            if app.cell.device.live { "ON" } else { "off" },
            if s.plate_shown { "shown" } else { "away" }
        )));
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
    lines.push(Line::raw(match s.centre {
        Centre::Solved => "centre C: solved (s, S)".to_string(),
        Centre::Middle => "centre C: stated, image middle (s)".to_string(),
        Centre::At([x, y]) => format!("centre C: stated {x},{y} (S)"),
    }));
    lines.push(Line::raw(if s.estimate_scale {
        "scale S: sy estimated (e)"
    } else {
        "scale S: as the .cdf states (e)"
    }));
    match solved {
        Some(c) => {
            lines.push(Line::styled(
                format!("RMS {:.3} px  p95 {:.3} px", c.rms, c.p95),
                t.ok(),
            ));
            for p in &c.params {
                lines.push(Line::raw(format!(
                    "{:<3}{:>13.6} ±{}",
                    p.name,
                    p.value,
                    calib::sig3(p.se)
                )));
            }
            let mut worst: Vec<_> = c.views.iter().collect();
            worst.sort_by(|a, b| b.rms.total_cmp(&a.rms));
            let names: Vec<String> = worst
                .iter()
                .take(2)
                .map(|v| format!("{} {:.3}", short_name(&v.name), v.rms))
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
        let probe = block(app, "residuals");
        let room = probe.inner(right);
        // A cell of the grid for every four columns and two rows.
        let (cols, rows) = (
            (usize::from(room.width) / 4).clamp(2, 24),
            (usize::from(room.height) / 2).clamp(2, 16),
        );
        let segs = residuals(c, cols, rows);
        let b = block(
            app,
            &format!(
                "mean residual ×{} in {} cells",
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
    if let Some(photo) = s.shown_photo(cam) {
        let title = format!(
            "{} {}/{}",
            short_name(&photo.name),
            s.shown.unwrap_or(0) + 1,
            s.photos.len()
        );
        let b = block(app, &title);
        let inner = b.inner(right);
        b.render(right, buf);
        let grid = match &photo.found {
            Ok(d) => outlines(d),
            Err(_) => Vec::new(),
        };
        Preview::new(
            Layer::LinesOver(&photo.image, &grid),
            app.chrome.look.mode,
            app.chrome.look.colour,
        )
        .render(inner, buf);
        return;
    }
    let title = match &app.cell.live {
        Some((c, img)) => format!("camera {c} {}×{}", img.width(), img.height()),
        None => "no picture: v live, g grab, o files".into(),
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
