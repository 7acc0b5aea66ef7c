//! Calibration on real photographs (`../shared/data/calib-real/`: 17 phone
//! photographs of a 9 × 7-square checkerboard on paper, with text, clips and
//! a wall round it), beside OpenCV's result on the same views (its README):
//! RMS 0.345 px, fx 706.6, fy 706.3, cx 334.4, cy 303.9 px. A missing folder
//! fails these tests. And the bad inputs a real board gives, made from
//! these photographs: each refused with what was found.

use std::path::{Path, PathBuf};

use crate::support::vss;
use vss::calib::{self, CalibError, DetectError, Detector, Options, Plate, View};
use vss::formats::imageio;
use vss::llv::GreyImage;

/// OpenCV's figures on the 17 views (README of the folder), its default
/// model (k1 k2 p1 p2 k3).
const CV_RMS: f64 = 0.345;
const CV_FX: f64 = 706.6;
const CV_FY: f64 = 706.3;
const CV_C: [f64; 2] = [334.4, 303.9];
/// OpenCV's cross-validated (held-out) error with its default model
/// (`benches/opencv_calib.py`, docs/calibration.md).
const CV_HELD_OUT: f64 = 0.400;

pub fn data_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/calib-real");
    assert!(
        d.is_dir(),
        "{}: the real photographs are missing (see docs/calibration.md)",
        d.display()
    );
    d
}

/// The 17 photographs, in their number's order.
pub fn photo_paths() -> Vec<PathBuf> {
    let d = data_dir();
    let v: Vec<PathBuf> = (1..=17)
        .map(|k| d.join(format!("Whitchurch_{k}.jpg")))
        .collect();
    for p in &v {
        assert!(p.is_file(), "{} is missing", p.display());
    }
    v
}

fn photos() -> Vec<(String, GreyImage)> {
    photo_paths()
        .iter()
        .map(|p| {
            let f = imageio::read_any(p).unwrap_or_else(|e| panic!("{e}"));
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                f.image,
            )
        })
        .collect()
}

/// The board of the photographs: 9 × 7 squares (its size is not known;
/// intrinsics in pixels do not depend on it).
pub const BOARD: &str =
    "kind = \"checkerboard\"\ncolumns = 9\nrows = 7\nsquare = 25.0\norigin = \"top-left\"\n";

fn board(columns: u32, rows: u32) -> Plate {
    let t = BOARD
        .replace("columns = 9", &format!("columns = {columns}"))
        .replace("rows = 7", &format!("rows = {rows}"));
    Plate::from_toml(&t, Path::new("board.toml")).unwrap()
}

/// Options with S = 0.001 mm/px both ways, so that f / sx is in pixels.
fn options(w: usize, h: usize) -> Options {
    Options {
        width: w,
        height: h,
        sx: 0.001,
        sy: 0.001,
        estimate_scale: false,
        centre: None,
        full_model: false,
    }
}

#[test]
fn the_board_is_found_in_every_photograph_and_calibrates_as_opencv() {
    let imgs = photos();
    let plate = board(9, 7);
    let t0 = std::time::Instant::now();
    let found = calib::detect_all(&imgs, &plate);
    let ms = t0.elapsed().as_secs_f64() * 1e3 / imgs.len() as f64;
    assert!(
        found.refused.is_empty(),
        "refused: {:?}",
        found
            .refused
            .iter()
            .map(|(n, e)| format!("{n}: {e}"))
            .collect::<Vec<_>>()
    );
    assert_eq!(found.views.len(), 17);
    for (v, _) in &found.views {
        assert_eq!(v.corners.len(), 48, "{}", v.name);
    }
    let views: Vec<View> = found.views.iter().map(|(v, _)| v.clone()).collect();
    let (w, h) = imgs[0].1.size();
    let c = calib::calibrate(&views, &options(w, h)).unwrap_or_else(|e| panic!("{e}"));
    let fx = c.model.f / c.model.sx;
    let fy = c.model.f / c.model.sy;
    let x = calib::cross_validate(&views, &options(w, h)).expect("cross-validation");
    // The figures docs/calibration.md quotes (`-- --nocapture`).
    eprintln!(
        "calib-real: 17/17 found ({ms:.1} ms a view, debug build), RMS {:.4} px (OpenCV {CV_RMS}), fx {fx:.2} fy {fy:.2} (OpenCV {CV_FX} {CV_FY}), C {:.2} {:.2} (OpenCV {} {}), fixed {:?}, uncertainty {:?}, cross-validation held-out RMS {:.4} px, halves differ {:.3} px RMS {:.3} max",
        c.rms,
        c.model.cx,
        c.model.cy,
        CV_C[0],
        CV_C[1],
        c.fixed.iter().map(|p| p.name).collect::<Vec<_>>(),
        c.uncertainty,
        x.held_out_rms,
        x.difference_rms,
        x.difference_max
    );
    // Issue 32's goals: RMS within 0.02 px of OpenCV's, f within 0.5 %, C
    // within 2 px. Without k2 (`.cdf` `K`) the RMS was 0.027 px above
    // OpenCV's and C 2.02 px off.
    assert!((c.rms - CV_RMS).abs() <= 0.02, "RMS {} px", c.rms);
    assert!((fx - CV_FX).abs() / CV_FX <= 0.005, "fx {fx}");
    assert!((fy - CV_FY).abs() / CV_FY <= 0.005, "fy {fy}");
    let dc = (c.model.cx - CV_C[0]).hypot(c.model.cy - CV_C[1]);
    assert!(dc <= 2.0, "C {} {} is {dc} px off", c.model.cx, c.model.cy);
    assert!(c.model.radial[0] != 0.0, "k2 estimated: {:?}", c.params);
    // Cross-validated: no worse than OpenCV's.
    assert!(x.held_out_rms <= CV_HELD_OUT, "held out {}", x.held_out_rms);
    // The uncertainty is stated at the middle and the four corners, and
    // is larger at the corners, where fewer views reached.
    assert_eq!(c.uncertainty.len(), 5);
    assert!(c.uncertainty.iter().all(|u| u.1 > 0.0 && u.1 < 5.0));
    assert!(c.uncertainty[1..].iter().all(|u| u.1 > c.uncertainty[0].1));
}

/// A photograph as a new image of the same size: `f(x, y)` gives the
/// source point (or `None` for the wall's grey).
fn remap(img: &GreyImage, f: impl Fn(f64, f64) -> Option<(f64, f64)>) -> GreyImage {
    let (w, h) = img.size();
    let mut out = vec![128u8; w * h];
    for y in 0..h {
        for x in 0..w {
            if let Some((sx, sy)) = f(x as f64, y as f64)
                && sx >= 0.0
                && sy >= 0.0
                && sx < (w - 1) as f64
                && sy < (h - 1) as f64
            {
                out[y * w + x] = img.get(sx.round() as usize, sy.round() as usize).unwrap();
            }
        }
    }
    GreyImage::new(w, h, out).unwrap()
}

/// A box blur of radius `r`, three times (about a Gaussian of σ ≈ r).
fn blur(img: &GreyImage, r: usize) -> GreyImage {
    let (w, h) = img.size();
    let mut a: Vec<f64> = img.data().iter().map(|&v| f64::from(v)).collect();
    for _ in 0..3 {
        let mut b = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let (x0, x1) = (x.saturating_sub(r), (x + r).min(w - 1));
                b[y * w + x] = (x0..=x1).map(|k| a[y * w + k]).sum::<f64>() / (x1 - x0 + 1) as f64;
            }
        }
        for y in 0..h {
            for x in 0..w {
                let (y0, y1) = (y.saturating_sub(r), (y + r).min(h - 1));
                a[y * w + x] = (y0..=y1).map(|k| b[k * w + x]).sum::<f64>() / (y1 - y0 + 1) as f64;
            }
        }
    }
    GreyImage::new(w, h, a.iter().map(|v| v.round() as u8).collect()).unwrap()
}

fn detect(img: &GreyImage, plate: &Plate) -> Result<calib::Detection, DetectError> {
    Detector::new().detect(img, plate)
}

#[test]
fn a_wrong_board_size_says_what_grid_was_found() {
    let imgs = photos();
    let e = detect(&imgs[0].1, &board(10, 7)).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, DetectError::GridSize { .. }), "{m}");
    assert!(m.contains("a grid of 8 × 6 inner corners"), "{m}");
    assert!(m.contains("the plate file says 9 × 6"), "{m}");
    let e = detect(&imgs[0].1, &board(9, 6)).unwrap_err();
    assert!(e.to_string().contains("the plate file says 8 × 5"), "{e}");
}

#[test]
fn a_blurred_board_is_called_blurred_not_missing() {
    let imgs = photos();
    let img = blur(&imgs[0].1, 5);
    let e = detect(&img, &board(9, 7)).unwrap_err();
    assert!(matches!(e, DetectError::Blurred { .. }), "{e}");
    assert!(!e.to_string().contains("not in view"), "{e}");
    // A slight blur still gives the board.
    detect(&blur(&imgs[0].1, 1), &board(9, 7)).unwrap();
}

/// A horizontal motion blur: each pixel the mean of `n` pixels of its row
/// (the board moved `n` px while the shutter was open).
fn motion_blur(img: &GreyImage, n: usize) -> GreyImage {
    let (w, h) = img.size();
    let d = img.data();
    let out = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                let x0 = x as i64 - (n / 2) as i64;
                let sum: u32 = (0..n as i64)
                    .map(|k| u32::from(d[y * w + (x0 + k).clamp(0, w as i64 - 1) as usize]))
                    .sum();
                ((sum + n as u32 / 2) / n as u32) as u8
            })
        })
        .collect();
    GreyImage::new(w, h, out).unwrap()
}

#[test]
fn a_motion_blurred_board_is_called_blurred_not_the_wrong_size() {
    let imgs = photos();
    // Photograph 13 smeared 20 px sideways: a part of the board is found
    // (the lattice breaks across the motion); photograph 1 smeared 15 px:
    // the whole board is found, its corners 3 px off. Both were taken for
    // what they are not (a wrong plate file; a good view).
    for (k, n) in [(12, 20), (0, 15), (0, 12)] {
        let e = detect(&motion_blur(&imgs[k].1, n), &board(9, 7))
            .expect_err(&format!("{} smeared {n} px was used", imgs[k].0));
        let m = e.to_string();
        assert!(matches!(e, DetectError::Blurred { .. }), "{m}");
        let width: f64 = m
            .split("its edges are ")
            .nth(1)
            .and_then(|t| t.split(" px wide (at most 6 px").next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("{m}"));
        assert!(width > 6.0, "{m}");
        assert!(!m.contains("the plate file says"), "{m}");
    }
    // Through the command line: the smeared view is left out saying so,
    // the others calibrate.
    let tmp = tempfile::tempdir().unwrap();
    let plate = write_board(tmp.path());
    let smeared = tmp.path().join("smeared.png");
    let img = imageio::read_any(&photo_paths()[12]).unwrap();
    let image = motion_blur(&img.image, 20);
    imageio::write_any(&smeared, &vss::formats::img::ImgFile { image, ..img }).unwrap();
    let mut paths = photo_paths()[..6].to_vec();
    paths.push(smeared);
    let r = vss()
        .args(["calibrate", "--plate"])
        .arg(&plate)
        .args(["--scale", "0.001,0.001", "--out"])
        .arg(tmp.path().join("cam1.cdf"))
        .args(&paths)
        .output()
        .unwrap();
    let (so, se) = (
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr),
    );
    assert!(r.status.success(), "{so}\n{se}");
    let line = se
        .lines()
        .find(|l| l.contains("smeared.png"))
        .unwrap_or_else(|| panic!("{se}"));
    assert!(
        line.contains("left out") && line.contains("but blurred: its edges are"),
        "{line}"
    );
    assert!(!line.contains("plate file"), "{line}");
    assert!(so.contains("in 6 views"), "{so}");
}

#[test]
fn a_board_half_out_of_frame_is_called_so() {
    let imgs = photos();
    let (img, plate) = (&imgs[0].1, board(9, 7));
    let d = detect(img, &plate).unwrap();
    let xs: Vec<f64> = d.corners.iter().map(|c| c.px[0]).collect();
    let (lo, hi) = xs
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &x| (a.0.min(x), a.1.max(x)));
    // Shift the picture left so that the board's middle falls on the
    // image's left edge.
    let dx = (lo + hi) / 2.0;
    let shifted = remap(img, |x, y| Some((x + dx, y)));
    let e = detect(&shifted, &plate).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, DetectError::PartlyOut { .. }), "{m}");
    assert!(m.contains("partly out of the frame"), "{m}");
    assert!(!m.contains("not in view"), "{m}");
}

#[test]
fn two_boards_in_one_photograph_are_refused() {
    let imgs = photos();
    let img = &imgs[0].1;
    let (w, h) = img.size();
    // Two half-size copies side by side.
    let two = remap(img, |x, y| {
        let half = w as f64 / 2.0;
        let sx = if x < half { 2.0 * x } else { 2.0 * (x - half) };
        let sy = 2.0 * (y - h as f64 / 4.0);
        Some((sx, sy))
    });
    let e = detect(&two, &board(9, 7)).unwrap_err();
    assert!(matches!(e, DetectError::TwoBoards { .. }), "{e}");
    assert!(e.to_string().contains("two boards"), "{e}");
}

#[test]
fn too_few_or_alike_views_are_refused_with_what_to_do() {
    let imgs = photos();
    let plate = board(9, 7);
    let found = calib::detect_all(&imgs[..2], &plate);
    let views: Vec<View> = found.views.iter().map(|(v, _)| v.clone()).collect();
    let (w, h) = imgs[0].1.size();
    let e = calib::calibrate(&views, &options(w, h)).unwrap_err();
    assert!(matches!(e, CalibError::TooFewViews { usable: 2 }), "{e}");
    // One view three times: nothing to tell f from the distance.
    let same = vec![views[0].clone(), views[0].clone(), views[0].clone()];
    let e = calib::calibrate(&same, &options(w, h)).unwrap_err();
    assert!(
        matches!(
            e,
            CalibError::Degenerate { .. }
                | CalibError::AllParallel { .. }
                | CalibError::WeakParameter { .. }
        ),
        "{e}"
    );
}

fn write_board(dir: &Path) -> PathBuf {
    let p = dir.join("board.toml");
    std::fs::write(&p, BOARD).unwrap();
    p
}

#[test]
fn the_cli_calibrates_photographs_as_its_help_says() {
    let tmp = tempfile::tempdir().unwrap();
    let plate = write_board(tmp.path());
    let out = tmp.path().join("phone.cdf");
    let r = vss()
        .current_dir(tmp.path())
        .args(["calibrate", "--plate"])
        .arg(&plate)
        .args(["--scale", "0.001,0.001", "--centre", "-3.5,310", "--out"])
        .arg(&out)
        .args(photo_paths())
        .output()
        .unwrap();
    let so = String::from_utf8_lossy(&r.stdout);
    let se = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{so}\n{se}");
    let cdf = vss::formats::cdf::read_cdf(&out).unwrap();
    let m = cdf.camera_model().unwrap();
    assert_eq!((m.cx, m.cy), (-3.5, 310.0));
    // The higher radial term is solved for, printed and written as `K`
    // (which lens correction reads back).
    assert!(m.radial[0] != 0.0, "{:?}", m.radial);
    assert!(so.lines().any(|l| l.starts_with("k2 ")), "{so}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("\nK=A\n"), "{text}");
    assert!(so.contains("cross-validation"), "{so}");
    assert!(so.contains("projection uncertainty"), "{so}");
    // Two views: refused, nothing written.
    let out2 = tmp.path().join("two.cdf");
    let r = vss()
        .args(["calibrate", "--plate"])
        .arg(&plate)
        .args(["--scale", "0.001,0.001", "--out"])
        .arg(&out2)
        .args(&photo_paths()[..2])
        .output()
        .unwrap();
    let se = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        se.contains("at least 3") && se.contains("nothing written"),
        "{se}"
    );
    assert!(!out2.exists());
    // A photograph of another size: refused, nothing written.
    let img = imageio::read_any(&photo_paths()[0]).unwrap();
    let (w, h) = img.image.size();
    let small = GreyImage::new(
        w - 40,
        h,
        (0..h)
            .flat_map(|y| img.image.row(y)[..w - 40].to_vec())
            .collect(),
    )
    .unwrap();
    let odd = tmp.path().join("odd.png");
    imageio::write_any(
        &odd,
        &vss::formats::img::ImgFile {
            image: small,
            ..img.clone()
        },
    )
    .unwrap();
    let mut paths = photo_paths()[..5].to_vec();
    paths.push(odd);
    let r = vss()
        .args(["calibrate", "--plate"])
        .arg(&plate)
        .args(["--scale", "0.001,0.001", "--out"])
        .arg(&out2)
        .args(&paths)
        .output()
        .unwrap();
    let se = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        se.contains("600 × 640") && se.contains("nothing written"),
        "{se}"
    );
    assert!(!out2.exists());
}

#[test]
fn the_report_is_written_before_the_cdf_and_backups_are_never_overwritten() {
    let tmp = tempfile::tempdir().unwrap();
    let plate = write_board(tmp.path());
    let out = tmp.path().join("phone.cdf");
    let run = |extra: &[&str], report: Option<&Path>| {
        let mut c = vss();
        c.args(["calibrate", "--yes", "--plate"])
            .arg(&plate)
            .args(["--scale", "0.001,0.001", "--out"])
            .arg(&out)
            .args(extra);
        if let Some(r) = report {
            c.arg("--report").arg(r);
        }
        c.args(&photo_paths()[..8]).output().unwrap()
    };
    assert!(run(&[], None).status.success());
    let first = std::fs::read(&out).unwrap();
    // A report that cannot be written (its folder does not exist): the
    // .cdf is left as it was.
    let r = run(
        &["--centre", "image"],
        Some(&tmp.path().join("no/such/page.ps")),
    );
    assert!(!r.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), first, "the .cdf was replaced");
    assert!(!tmp.path().join("phone.cdf.bak").exists());
    // Two replacements: the first backup is kept, the second goes beside it.
    assert!(run(&["--centre", "image"], None).status.success());
    let second = std::fs::read(&out).unwrap();
    assert_eq!(
        std::fs::read(tmp.path().join("phone.cdf.bak")).unwrap(),
        first
    );
    assert!(run(&[], None).status.success());
    assert_eq!(
        std::fs::read(tmp.path().join("phone.cdf.bak")).unwrap(),
        first
    );
    assert_eq!(
        std::fs::read(tmp.path().join("phone.cdf.bak.1")).unwrap(),
        second
    );
}

#[test]
fn plate_files_are_read_bounded_and_never_found_by_accident() {
    let tmp = tempfile::tempdir().unwrap();
    // A plate planted in ./profiles/plates/ is not taken for the built-in one.
    std::fs::create_dir_all(tmp.path().join("profiles/plates")).unwrap();
    std::fs::write(
        tmp.path().join("profiles/plates/squares.toml"),
        "kind = \"squares\"\nrows = 2\ncolumns = 2\nsquare = 1.0\npitch = 2.0\norigin = \"top-left\"\n",
    )
    .unwrap();
    let r = vss()
        .current_dir(tmp.path())
        .args(["calibrate", "--check-plate", "--plate", "squares"])
        .output()
        .unwrap();
    let so = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(so.contains("8 columns × 6 rows"), "{so}");
    // Which plate file is in use is said (issue 34): the built-in one, or
    // the file named, by its absolute path.
    assert!(so.contains("plate file: squares (built in)"), "{so}");
    std::fs::write(
        tmp.path().join("mine.toml"),
        vss::calib::plate::BUILT_IN[0].1,
    )
    .unwrap();
    let r = vss()
        .current_dir(tmp.path())
        .args(["calibrate", "--check-plate", "--plate", "mine.toml"])
        .output()
        .unwrap();
    let so = String::from_utf8_lossy(&r.stdout);
    let mine = tmp.path().join("mine.toml");
    assert!(
        so.contains(&format!("plate file: {}", mine.display())),
        "{so}"
    );
    // A FIFO does not block the reader; /dev/zero behind a link is refused.
    let fifo = tmp.path().join("fifo.toml");
    crate::support::files::mkfifo(&fifo);
    let zero = tmp.path().join("zero.toml");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let big = tmp.path().join("big.toml");
    std::fs::write(&big, "#".repeat(1 << 20)).unwrap();
    for (p, want) in [
        (&fifo, "not a regular file"),
        (&zero, "symbolic link"),
        (&big, "more than"),
    ] {
        let mut child = vss()
            .args(["calibrate", "--check-plate", "--plate"])
            .arg(p)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let t0 = std::time::Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if t0.elapsed().as_secs() > 10 {
                child.kill().unwrap();
                panic!("{} blocked the reader", p.display());
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        let out = child.wait_with_output().unwrap();
        let se = String::from_utf8_lossy(&out.stderr);
        assert!(!status.success());
        assert!(se.contains(want), "{}: {se}", p.display());
    }
}

#[test]
fn a_damaged_or_linked_out_file_is_refused_before_the_work_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let plate = write_board(tmp.path());
    let run = |out: &Path, report: &Path| {
        vss()
            .args(["calibrate", "--yes", "--plate"])
            .arg(&plate)
            .args(["--scale", "0.001,0.001", "--out"])
            .arg(out)
            .arg("--report")
            .arg(report)
            .args(&photo_paths()[..8])
            .output()
            .unwrap()
    };
    // A hand-edited camera file: its f is not a number.
    let damaged = tmp.path().join("cam1.cdf");
    let text = "S=S\n0.001\n0.001\nC=A\n320\n320\nf=A\nNaN\nD=N\n0\n0\n0\n0\n0\n";
    std::fs::write(&damaged, text).unwrap();
    let report = tmp.path().join("cam1.ps");
    let r = run(&damaged, &report);
    let (so, se) = (
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr),
    );
    assert!(!r.status.success(), "{so}\n{se}");
    assert!(
        se.contains("cam1.cdf:8:") && se.contains("nothing written"),
        "{se}"
    );
    // Refused before the views were searched: no table, no page.
    assert!(!so.contains("overall:"), "{so}");
    assert!(!report.exists(), "a report of a calibration not written");
    assert_eq!(std::fs::read_to_string(&damaged).unwrap(), text);
    // A link to the camera's file: refused the same way, the file and the
    // link left as they were.
    let target = tmp.path().join("cam2-2026.cdf");
    std::fs::write(&target, text.replace("NaN", "8.5")).unwrap();
    let link = tmp.path().join("cam2.cdf");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let report = tmp.path().join("cam2.ps");
    let r = run(&link, &report);
    let (so, se) = (
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr),
    );
    assert!(!r.status.success(), "{so}\n{se}");
    assert!(
        se.contains("symbolic link") && se.contains("nothing written"),
        "{se}"
    );
    assert!(!so.contains("overall:"), "{so}");
    assert!(!report.exists());
    assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
    assert_eq!(
        std::fs::read_to_string(&target).unwrap(),
        text.replace("NaN", "8.5")
    );
}

/// Photographs of a camera with square pixels calibrated with another
/// camera's scale S (sy / sx = 0.696, the simulated cell's camera 1, as
/// the Calibrate screen does when camera 1 is chosen): refused as a scale
/// that does not fit, not as "a view whose grid was misread, or a plate
/// file that does not match the plate".
#[test]
fn views_that_fit_only_another_scale_are_refused_naming_the_scale() {
    let imgs = photos();
    let found = calib::detect_all(&imgs, &board(9, 7));
    let views: Vec<View> = found.views.iter().map(|(v, _)| v.clone()).collect();
    let (w, h) = imgs[0].1.size();
    let o = Options {
        sx: 0.0112,
        sy: 0.0078,
        ..options(w, h)
    };
    let e = calib::calibrate(&views, &o).unwrap_err();
    let CalibError::ScaleMismatch { stated, fits, rms } = e else {
        panic!("{e}");
    };
    assert!((stated - 0.0078 / 0.0112).abs() < 1e-12);
    assert!((fits - 1.0).abs() < 0.01, "square pixels: {fits}");
    assert!(rms < 0.4, "{rms}");
    let text = e.to_string();
    assert!(text.contains("estimate sy"), "{text}");
    // Twelve of them: the wrong scale converges (to C outside the image
    // and RMS 1.8 px), and is refused all the same.
    let e = calib::calibrate(&views[..12], &o).unwrap_err();
    let CalibError::ScaleMismatch { fits, rms, .. } = e else {
        panic!("{e}");
    };
    assert!((fits - 1.0).abs() < 0.01 && rms < 0.4, "{fits} {rms}");
}
