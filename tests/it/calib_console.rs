//! The Calibrate screen in the real console (a pty): the simulated cell
//! shows the plate (`p`), each grab's grid is found and kept (`Space`), the
//! calibration computed (`Enter`) and accepted (`a`, asked first because
//! the camera's `.cdf` is there): the new file has the calibration, the old
//! one is kept beside it as `.bak`, and the open session's manifest records
//! it (camera, views, fit). And a camera calibrated from a folder of real
//! photographs (`../shared/data/calib-real`) at 80 × 24.

use vss::formats::cdf::{Status, read_cdf, write_cdf};
use vss::tui::keymap::{Action, CalibrateAction as CA, GlobalAction, Scope, ScreenId};

use super::tui_harness::Console;

const PROFILE: &str = r#"
name = "calibration test cell"

[relay]
settle_ms = 5

[[lights]]
name = "left"
relay = 0

[[lighting]]
letter = "a"
on = ["left"]

[survey]
dir = "sessions"
cameras = 2
cdf = ["cam1.cdf", "cam2.cdf"]

[sim]
width = 512
height = 512
seed = 1
noise = 2.0
"#;

#[test]
fn a_camera_calibrated_on_the_calibrate_screen() {
    let mut c = Console::start_with(PROFILE, 120, 40, &[], |dir| {
        for cam in 1..=2 {
            let cdf = vss::rig::sim::camera_cdf(cam, 512, 512).unwrap();
            write_cdf(&dir.join(format!("cam{cam}.cdf")), &cdf).unwrap();
        }
    });
    let dir = c.dir.path().to_path_buf();
    let before = std::fs::read(dir.join("cam1.cdf")).unwrap();
    let truth = read_cdf(&dir.join("cam1.cdf"))
        .unwrap()
        .camera_model()
        .unwrap();
    c.wait_text("Survey", 10);
    c.create_session("cube");
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Calibrate)),
    );
    c.wait_text("views kept: 0", 10);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.press(cb, Action::Calibrate(CA::Plate));
    c.wait_text("plate shown (p)", 10);
    for n in 1..=6 {
        c.press(cb, Action::Calibrate(CA::Grab));
        c.wait("a grid in the new frame", 30, |s| {
            s.contains("188 corners found")
        });
        c.press(cb, Action::Calibrate(CA::Keep));
        c.wait_text(&format!("views kept: {n}"), 10);
    }
    c.press(cb, Action::Calibrate(CA::Centre));
    c.wait_text("stated, image middle", 10);
    c.press(cb, Action::Calibrate(CA::Solve));
    let s = c.wait("the calibration", 30, |s| {
        s.contains("RMS 0.") && s.contains("worst views")
    });
    assert!(s.contains("mean residual ×"), "{s}");
    c.press(cb, Action::Calibrate(CA::Accept));
    c.wait_text("write S, C, f, D", 10);
    c.yes();
    c.wait("the file written", 10, |_| {
        std::fs::read(dir.join("cam1.cdf")).is_ok_and(|b| b != before)
    });
    assert_eq!(std::fs::read(dir.join("cam1.cdf.bak")).unwrap(), before);
    c.wait_text("recorded in session cube", 10);
    let manifest = dir.join("sessions/cube/cube.toml");
    let m = vss::session::manifest::Manifest::parse(
        &std::fs::read_to_string(&manifest).unwrap(),
        &manifest,
    )
    .unwrap();
    let [rec] = m.calibration.as_slice() else {
        panic!("one calibration recorded: {:?}", m.calibration);
    };
    assert_eq!((rec.camera, rec.views), (1, 6), "{rec:?}");
    assert!(
        rec.cdf.ends_with("cam1.cdf") && rec.centre_stated,
        "{rec:?}"
    );
    assert!(rec.rms_px > 0.0 && rec.rms_px < 0.5, "{rec:?}");
    let got = read_cdf(&dir.join("cam1.cdf")).unwrap();
    assert_eq!(got.get("D").unwrap().status, Status::Calibrated);
    assert_eq!(got.get("C").unwrap().status, Status::Stated);
    assert_eq!(got.get("T").unwrap().status, Status::Calibrated, "T kept");
    let m = got.camera_model().unwrap();
    assert!(
        (m.f - truth.f).abs() / truth.f < 0.005,
        "f {} against {}",
        m.f,
        truth.f
    );
    c.send("q");
    c.wait_exit(10);
}

/// At 80 × 24: a frame without the plate is not kept and says why, and
/// two views are refused with what to do, no `.cdf` touched; with eight
/// the whole solution fits the panel.
#[test]
fn too_few_views_and_no_plate_are_refused_at_80_by_24() {
    let mut c = Console::start_with(PROFILE, 80, 24, &[], |dir| {
        for cam in 1..=2 {
            let cdf = vss::rig::sim::camera_cdf(cam, 512, 512).unwrap();
            write_cdf(&dir.join(format!("cam{cam}.cdf")), &cdf).unwrap();
        }
    });
    let dir = c.dir.path().to_path_buf();
    let before = std::fs::read(dir.join("cam1.cdf")).unwrap();
    c.wait_text("Survey", 10);
    // The cell connected first: its message would hide the answer to a key
    // pressed before it (seen on a loaded machine).
    c.wait_text("grabber VSS-SIM", 30);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Calibrate)),
    );
    c.wait_text("views kept: 0", 10);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.press(cb, Action::Calibrate(CA::Keep));
    c.wait_words("no grid of camera 1 to keep", 10);
    // The bare cell: the grab has no plate in it.
    c.press(cb, Action::Calibrate(CA::Grab));
    c.wait_words("grid: the plate is not in view", 30);
    c.press(cb, Action::Calibrate(CA::Keep));
    c.wait_words("not kept: the plate is not in view", 10);
    c.press(cb, Action::Calibrate(CA::Plate));
    c.wait_text("plate shown (p)", 10);
    for n in 1..=2 {
        c.press(cb, Action::Calibrate(CA::Grab));
        c.wait("a grid in the new frame", 30, |s| s.contains("188 corners"));
        c.press(cb, Action::Calibrate(CA::Keep));
        c.wait_text(&format!("views kept: {n}"), 10);
    }
    c.press(cb, Action::Calibrate(CA::Solve));
    c.wait_words("2 usable view(s) of the plate; at least 3 are needed", 30);
    c.press(cb, Action::Calibrate(CA::Accept));
    c.wait_words("nothing to accept", 10);
    assert_eq!(std::fs::read(dir.join("cam1.cdf")).unwrap(), before);
    assert!(!dir.join("cam1.cdf.bak").exists());
    // Enough views: every parameter and the worst views fit in 80 × 24.
    for n in 3..=8 {
        c.press(cb, Action::Calibrate(CA::Grab));
        c.wait("a grid in the new frame", 30, |s| s.contains("188 corners"));
        c.press(cb, Action::Calibrate(CA::Keep));
        c.wait_text(&format!("views kept: {n}"), 10);
    }
    c.press(cb, Action::Calibrate(CA::Solve));
    // The panel's last rows: the frame is drawn top to bottom.
    let s = c.wait("the calibration", 30, |s| s.contains("worst views"));
    for want in ["RMS 0.", "Cx", "f ", "k1", "p2", " view "] {
        assert!(s.contains(want), "{want} on the screen:\n{s}");
    }
    c.send("q");
    c.wait_exit(10);
}

/// A camera calibrated from twelve real photographs in a folder, at
/// 80 × 24, in under a minute: `o` and the folder typed, each photograph
/// shown with its corners (`n`), one dropped and kept again, the plate
/// file chosen (`f`), the centre stated at coordinates (`S`), `Enter`, `a`.
/// The figures are readable: no `e0` exponents, the residual pane a few
/// arrows, not a blot.
#[test]
fn a_camera_calibrated_from_a_folder_of_photographs_at_80_by_24() {
    let mut c = phone_cell(true);
    let dir = c.dir.path().to_path_buf();
    let before = std::fs::read(dir.join("cam1.cdf")).unwrap();
    c.wait_text("Survey", 10);
    let t0 = std::time::Instant::now();
    load_photos(&mut c);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.wait_text("photo 1/12: 48 corners, kept", 10);
    // Step to the third, drop it, keep it again.
    c.press(cb, Action::Calibrate(CA::Next));
    c.press(cb, Action::Calibrate(CA::Next));
    c.wait_text("photo 3/12", 10);
    c.press(cb, Action::Calibrate(CA::Drop));
    c.wait_text("views kept: 11", 10);
    c.wait_text("photo 3/12: 48 corners, dropped", 10);
    c.press(cb, Action::Calibrate(CA::Keep));
    c.wait_text("views kept: 12", 10);
    c.press(cb, Action::Calibrate(CA::CentreAt));
    c.wait_text("centre C (px):", 10);
    c.send("334.5,-3e2\r");
    c.wait_text("stated 334.5,-300", 10);
    c.press(cb, Action::Calibrate(CA::Centre));
    c.wait_text("centre C: solved", 10);
    c.press(cb, Action::Calibrate(CA::Solve));
    let s = c.wait("the calibration", 60, |s| s.contains("worst views"));
    for want in ["RMS 0.3", "Cx", "k1", "p2", "mean residual"] {
        assert!(s.contains(want), "{want} on the screen:\n{s}");
    }
    // Annoyance 8: no standard error as `5.5e0`, and the residual pane is
    // a few arrows, not every corner's vector.
    assert!(!s.contains("e0 ") && !s.contains("e0\n"), "{s}");
    let braille = s
        .chars()
        .filter(|ch| ('\u{2801}'..='\u{28ff}').contains(ch))
        .count();
    assert!(braille < 200, "{braille} Braille cells:\n{s}");
    c.press(cb, Action::Calibrate(CA::Accept));
    c.wait_text("write S, C, f, D", 10);
    c.yes();
    c.wait("the file written", 10, |_| {
        std::fs::read(dir.join("cam1.cdf")).is_ok_and(|b| b != before)
    });
    let secs = t0.elapsed().as_secs_f64();
    eprintln!("calibrated from 12 photographs in {secs:.1} s at 80 x 24 (debug build)");
    assert!(secs < 60.0, "{secs} s");
    let got = read_cdf(&dir.join("cam1.cdf")).unwrap();
    assert_eq!(got.get("C").unwrap().status, Status::Calibrated);
    let m = got.camera_model().unwrap();
    // OpenCV on the same twelve views with one radial term (k2, k3 fixed):
    // fx 706.2, C 331.6 294.5 ± 2.0 2.3 px; vss's C is about ± 2.2 px
    // here, so within three standard errors.
    assert!((m.f / m.sx - 706.2).abs() / 706.2 < 0.005, "{m:?}");
    assert!((m.cx - 331.6).hypot(m.cy - 294.5) < 7.0, "{m:?}");
    c.send("q");
    c.wait_exit(10);
}

/// Photographs of a camera whose `sy / sx` the `.cdf` does not give (here
/// the simulated camera's `S`, 0.696, for the phone's square pixels): the
/// refusal names the key that estimates `sy`, `e` does, and the `.cdf`
/// written has `S` calibrated with the ratio the views fit, at 80 × 24.
#[test]
fn a_scale_the_views_do_not_fit_is_estimated_with_e() {
    let mut c = phone_cell(false);
    let dir = c.dir.path().to_path_buf();
    let stated = read_cdf(&dir.join("cam1.cdf"))
        .unwrap()
        .camera_model()
        .unwrap();
    assert!((stated.sy / stated.sx - 1.0).abs() > 0.2, "{stated:?}");
    c.wait_text("Survey", 10);
    load_photos(&mut c);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.wait_text("scale S: as the .cdf states (e)", 10);
    c.press(cb, Action::Calibrate(CA::Solve));
    c.wait_words(
        "the corners do not fit one camera with the stated scale S",
        60,
    );
    c.send("!");
    c.wait_words("here `e` estimates sy", 10);
    c.send("\x1b");
    c.wait("the message closed", 10, |s| !s.contains("last message"));
    c.wait_text("refused: views do not fit S (e)", 10);
    c.press(cb, Action::Calibrate(CA::Scale));
    c.wait_text("scale S: sy estimated (e)", 10);
    c.press(cb, Action::Calibrate(CA::Solve));
    let s = c.wait("the calibration", 60, |s| s.contains("worst views"));
    for want in ["RMS 0.3", "Cx", "sy ", "scale S: sy estimated"] {
        assert!(s.contains(want), "{want} on the screen:\n{s}");
    }
    c.press(cb, Action::Calibrate(CA::Accept));
    c.wait_text("write S, C, f, D", 10);
    c.yes();
    c.wait_words("camera 1: wrote", 10);
    let got = read_cdf(&dir.join("cam1.cdf")).unwrap();
    assert_eq!(got.get("S").unwrap().status, Status::Calibrated);
    let m = got.camera_model().unwrap();
    // sx as stated; sy from the views: the phone's pixels are square.
    assert_eq!(m.sx, stated.sx);
    assert!((m.sy / m.sx - 1.0).abs() < 0.01, "{m:?}");
    // OpenCV's fx on these twelve views (the test above).
    assert!((m.f / m.sx - 706.2).abs() / 706.2 < 0.005, "{m:?}");
    c.send("q");
    c.wait_exit(10);
}

/// The test cell with twelve of the real checkerboard photographs in
/// `photos/` and their board in `board.toml`; each camera's `.cdf` is the
/// simulated one's, with the phone's square 1 µm pixels as `S` when
/// `square_pixels`.
fn phone_cell(square_pixels: bool) -> Console {
    let photos = super::calib_real::photo_paths();
    Console::start_with(PROFILE, 80, 24, &[], |dir| {
        for cam in 1..=2 {
            let mut cdf = vss::rig::sim::camera_cdf(cam, 512, 512).unwrap();
            if square_pixels {
                cdf.set(vss::formats::cdf::CdfParam {
                    name: "S".into(),
                    status: Status::Stated,
                    rows: vec![vec![0.001], vec![0.001]],
                });
            }
            write_cdf(&dir.join(format!("cam{cam}.cdf")), &cdf).unwrap();
        }
        std::fs::create_dir(dir.join("photos")).unwrap();
        for p in &photos[..12] {
            std::fs::copy(p, dir.join("photos").join(p.file_name().unwrap())).unwrap();
        }
        std::fs::write(dir.join("board.toml"), super::calib_real::BOARD).unwrap();
    })
}

/// On the Calibrate screen: `f` chooses `board.toml`, `o` loads `photos`,
/// and the grid is kept in all twelve.
fn load_photos(c: &mut Console) {
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Calibrate)),
    );
    c.wait_text("views kept: 0", 10);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.press(cb, Action::Calibrate(CA::PlateFile));
    c.wait_text("plate:", 10);
    c.send("board.toml\r");
    c.wait_text("plate board.toml", 10);
    c.press(cb, Action::Calibrate(CA::Open));
    c.wait_text("photographs to load:", 10);
    c.send("photos\r");
    c.wait_text("views kept: 12", 60);
}
