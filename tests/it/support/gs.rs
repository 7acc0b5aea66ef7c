//! Helpers shared by the report tests (included with `#[path]`): run
//! Ghostscript on a PostScript file and read the rendered page back.

#![allow(dead_code)]

use std::path::Path;
use std::process::Command;

/// Fails the test unless Ghostscript (`gs`) is installed: the reports are
/// checked by rendering them, and a check that skips itself where `gs` is
/// missing passes without checking anything. `bash .ci/run` installs it.
pub fn require_gs() {
    let ok = Command::new("gs")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        ok,
        "Ghostscript (gs) is needed to check the PostScript reports: apt-get install -y ghostscript (bash .ci/run does)"
    );
}

/// Renders every page of `ps` at `dpi` on `paper` (a4, letter, …) and
/// returns the pages as RGB images. Panics with gs's output if it reports
/// any error.
pub fn render(ps: &Path, paper: &str, dpi: u32) -> Vec<image::RgbImage> {
    let dir = ps.parent().unwrap();
    let stem = ps.file_stem().unwrap().to_string_lossy().to_string();
    let pattern = dir.join(format!("{stem}-{paper}-%03d.png"));
    let out = Command::new("gs")
        .args(["-q", "-dSAFER", "-dBATCH", "-dNOPAUSE", "-sDEVICE=png16m"])
        .arg(format!("-r{dpi}"))
        .arg(format!("-sPAPERSIZE={paper}"))
        .arg("-dFIXEDMEDIA")
        .arg(format!("-sOutputFile={}", pattern.display()))
        .arg(ps)
        .output()
        .expect("run gs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "gs failed on {}:\n{text}",
        ps.display()
    );
    assert!(
        !text.contains("Error"),
        "gs reported an error on {}:\n{text}",
        ps.display()
    );
    let mut pages = Vec::new();
    for i in 1.. {
        let p = dir.join(format!("{stem}-{paper}-{i:03}.png"));
        if !p.exists() {
            break;
        }
        pages.push(image::open(&p).expect("read gs png").to_rgb8());
    }
    pages
}

pub fn dark(img: &image::RgbImage, x: u32, y: u32) -> bool {
    img.get_pixel_checked(x, y)
        .is_some_and(|p| p.0.iter().map(|&c| u32::from(c)).sum::<u32>() < 3 * 100)
}

/// Whether any pixel within `r` of `(x, y)` is dark.
pub fn dark_near(img: &image::RgbImage, x: f64, y: f64, r: i64) -> bool {
    let (cx, cy) = (x.round() as i64, y.round() as i64);
    (-r..=r).any(|dy| {
        (-r..=r).any(|dx| {
            let (px, py) = (cx + dx, cy + dy);
            px >= 0 && py >= 0 && dark(img, px as u32, py as u32)
        })
    })
}

/// The bounding box `(x0, y0, x1, y1)` of the rows and columns that hold a
/// dark run at least `min_run` pixels long: finds a frame or a dark picture
/// while ignoring caption text.
pub fn long_run_box(img: &image::RgbImage, min_run: u32) -> Option<(u32, u32, u32, u32)> {
    let (w, h) = img.dimensions();
    let mut bx: Option<(u32, u32, u32, u32)> = None;
    let mut grow = |x0: u32, y0: u32, x1: u32, y1: u32| {
        bx = Some(match bx {
            None => (x0, y0, x1, y1),
            Some((a, b, c, d)) => (a.min(x0), b.min(y0), c.max(x1), d.max(y1)),
        });
    };
    for y in 0..h {
        let mut run = 0;
        for x in 0..w {
            if dark(img, x, y) {
                run += 1;
                if run >= min_run {
                    grow(x + 1 - run, y, x, y);
                }
            } else {
                run = 0;
            }
        }
    }
    for x in 0..w {
        let mut run = 0;
        for y in 0..h {
            if dark(img, x, y) {
                run += 1;
                if run >= min_run {
                    grow(x, y + 1 - run, x, y);
                }
            } else {
                run = 0;
            }
        }
    }
    bx
}
