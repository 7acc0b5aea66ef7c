//! The calibration page of a camera: where the corners were seen and how
//! far the solution leaves each (residual vectors, magnified), the coverage
//! of the image by the plate, and the parameters with their standard errors,
//! the reprojection error per view and the warnings — what the operator
//! checks before trusting a `.cdf`.

use std::fmt::Write as _;
use std::io;

use super::ps::{PsWriter, in_memory, page_heading, ps_string, text_cell};
use crate::calib::{COVERAGE, Calibration, coverage};

/// The page's text: parameters, views, warnings.
pub fn summary_lines(c: &Calibration) -> Vec<String> {
    let mut t = Vec::new();
    let n: usize = c.views.iter().map(|v| v.residuals.len()).sum();
    t.push(format!(
        "{n} corners in {} views: RMS {:.3} px, p95 {:.3} px",
        c.views.len(),
        c.rms,
        c.p95
    ));
    t.push(String::new());
    t.extend(crate::calib::parameter_lines(c, "+-"));
    t.push(String::new());
    t.push("view                     RMS px  p95 px  tilt".into());
    for v in &c.views {
        let name: String = v
            .name
            .chars()
            .rev()
            .take(24)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        t.push(format!(
            "{name:<24} {:>6.3} {:>7.3} {:>4.0} deg",
            v.rms, v.p95, v.tilt_deg
        ));
    }
    for w in &c.warnings {
        t.push(String::new());
        // Long warnings wrapped for the page's width.
        let mut line = String::from("warning:");
        for word in w.split_whitespace() {
            if line.len() + word.len() + 1 > 90 {
                t.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        t.push(line);
    }
    t
}

/// The magnification of the residual vectors: the largest is drawn a
/// twentieth of the image's width long.
pub fn magnification(c: &Calibration) -> f64 {
    let worst = c
        .views
        .iter()
        .flat_map(|v| v.residuals.iter().map(|r| r.1[0].hypot(r.1[1])))
        .fold(0.0, f64::max);
    if worst > 0.0 {
        (c.width.max(1) as f64 / 20.0 / worst).max(1.0).round()
    } else {
        1.0
    }
}

/// Writes the calibration page of camera `camera` into `doc`.
pub fn page<W: io::Write>(doc: &mut PsWriter<W>, camera: u32, c: &Calibration) -> io::Result<()> {
    page_named(doc, &format!("camera {camera}"), c)
}

/// Writes the calibration page of the camera called `name` into `doc`.
pub fn page_named<W: io::Write>(
    doc: &mut PsWriter<W>,
    name: &str,
    c: &Calibration,
) -> io::Result<()> {
    doc.raw_page(&page_body(name, c))
}

/// The body of the calibration page of the camera called `name` (a few
/// thousand lines of vectors at most: no pictures).
fn page_body(name: &str, c: &Calibration) -> Vec<u8> {
    let (w, h) = (c.width.max(1) as f64, c.height.max(1) as f64);
    let mut body = page_heading(&format!("{name}: calibration"), 0, 1);
    let k = magnification(c);
    // Residuals: each corner a dot, its residual a line from it.
    let _ = writeln!(body, "gsave\n{w} {h} 0 0 2 2 place");
    body.push_str("0 setlinewidth\nframe stroke\nframe clip newpath\n");
    for v in &c.views {
        for (p, r) in &v.residuals {
            let (x, y) = (p[0] / w, 1.0 - p[1] / h);
            let (x2, y2) = ((p[0] + k * r[0]) / w, 1.0 - (p[1] + k * r[1]) / h);
            let _ = writeln!(
                body,
                "{:.5} {:.5} {:.5} {:.5} l {:.5} {:.5} 0.003 0 360 arc fill",
                x.clamp(-1.0, 2.0),
                y.clamp(-1.0, 2.0),
                x2.clamp(-1.0, 2.0),
                y2.clamp(-1.0, 2.0),
                x.clamp(-1.0, 2.0),
                y.clamp(-1.0, 2.0)
            );
        }
    }
    let _ = writeln!(
        body,
        "grestore\n{} caption",
        ps_string(&format!(
            "residuals x{k}: the corners and where the solution puts them"
        ))
    );
    // Coverage: cells grey by how many corners fell in them.
    let hits = coverage(
        c.views.iter().flat_map(|v| v.residuals.iter().map(|r| r.0)),
        c.width,
        c.height,
    );
    let most = hits.iter().copied().max().unwrap_or(0).max(1) as f64;
    let _ = writeln!(body, "gsave\n{w} {h} 1 0 2 2 place");
    let n = COVERAGE as f64;
    for (i, &count) in hits.iter().enumerate() {
        let (cx, cy) = ((i % COVERAGE) as f64 / n, (i / COVERAGE) as f64 / n);
        let grey = 1.0 - 0.8 * count as f64 / most;
        let _ = writeln!(
            body,
            "{grey:.3} setgray {cx:.4} {:.4} {:.4} {:.4} rectfill",
            1.0 - cy - 1.0 / n,
            1.0 / n,
            1.0 / n
        );
    }
    body.push_str("0 setgray 0 setlinewidth frame stroke\n");
    let empty = hits.iter().filter(|&&h| h == 0).count();
    let _ = writeln!(
        body,
        "grestore\n{} caption",
        ps_string(&format!(
            "coverage: corners per {COVERAGE} x {COVERAGE} cell (darker: more); {empty} cells empty"
        ))
    );
    let mut body = body.into_bytes();
    // Writing into a `Vec` cannot fail.
    let _ = text_cell(&mut body, &summary_lines(c), (0, 1), (1, 2));
    body
}

/// A document of one calibration page.
pub fn document(camera: u32, c: &Calibration) -> String {
    document_named(&format!("camera {camera}"), c)
}

/// The calibration page of the camera called `name` as a PostScript file.
pub fn document_named(name: &str, c: &Calibration) -> String {
    in_memory(|v| {
        let mut doc = PsWriter::begin(v, &format!("{name} calibration"), 1)?;
        page_named(&mut doc, name, c)?;
        doc.finish()
    })
}
