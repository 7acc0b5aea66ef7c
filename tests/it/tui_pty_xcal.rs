//! Camera calibration files as a cell meets them, in the real console at
//! 80 × 24: a camera whose `.cdf` distortion folds the image (a digit of
//! `D` lost by hand) is refused by the Pipeline with where it folds, and
//! the frames captured are kept.

use vss::formats::cdf::{read_cdf, write_cdf};
use vss::tui::keymap::{Action, GlobalAction, ScreenId, SurveyAction};

use super::tui_harness::{Console, SURVEY, five_lightings, flat, write_cdfs};

/// Camera 1's `.cdf` in `dir` with `k1` set to `k1`, the rest kept.
fn set_k1(dir: &std::path::Path, k1: f64) {
    let path = dir.join("cam1.cdf");
    let cdf = read_cdf(&path).unwrap();
    let mut m = cdf.camera_model().unwrap();
    let mut d = m.distortion.unwrap();
    d[0] = k1;
    m.distortion = Some(d);
    assert!(
        m.fold_in(128, 128).is_some(),
        "k1 {k1} should fold the image"
    );
    let mut out = vss::formats::cdf::Cdf::from_camera(&m, cdf.extrinsic());
    out.set(cdf.get("S").unwrap().clone());
    write_cdf(&path, &out).unwrap();
}

#[test]
fn a_camera_whose_distortion_folds_the_image_is_refused_on_the_pipeline() {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |d| {
        write_cdfs(d, 2);
        set_k1(d, 0.5);
    });
    c.create_session("cube");
    c.wait_text("Image 1: camera", 20);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    // Every lighting is captured and saved all the same; the stages are
    // refused, saying where the image folds.
    let session = c.session();
    c.wait("the five frames on disk and the stages refused", 60, |_| {
        ('a'..='e').all(|l| session.join(format!("cube1{l}.img")).is_file())
            && std::fs::read_to_string(session.join("cube.log"))
                .is_ok_and(|t| t.contains("distortion folds the image near pixel"))
    });
    let log = std::fs::read_to_string(session.join("cube.log")).unwrap();
    assert!(log.contains("check D and K"), "{log}");
    c.press(
        vss::tui::keymap::Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
    );
    let s = c.wait_words("folds the image", 20);
    assert!(!flat(&s).contains("before CONNECT"), "no lines: {s}");
    c.send("q");
    c.wait_exit(15);
}

/// Camera 1's `.cdf` edited on disk while the console runs (a hand edit,
/// or `vss calibrate --yes` in another terminal): the console goes on
/// correcting with the description it read, so the image is recorded with
/// that one too (what `vss session redo` re-runs it with), and a warning
/// says the file changed. Before, the session recorded the edited file
/// while the lines came from the old one.
#[test]
fn a_camera_file_edited_while_the_console_runs_is_not_recorded_unsaid() {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |d| {
        write_cdfs(d, 2);
    });
    let read = std::fs::read_to_string(c.dir.path().join("cam1.cdf")).unwrap();
    c.create_session("cube");
    // Another k1: a valid file, a different lens.
    let path = c.dir.path().join("cam1.cdf");
    let cdf = read_cdf(&path).unwrap();
    let mut m = cdf.camera_model().unwrap();
    let mut d = m.distortion.unwrap();
    d[0] *= 0.5;
    m.distortion = Some(d);
    let mut edited = vss::formats::cdf::Cdf::from_camera(&m, cdf.extrinsic());
    edited.set(cdf.get("S").unwrap().clone());
    write_cdf(&path, &edited).unwrap();
    c.capture_current(1);
    let recorded = std::fs::read_to_string(c.session().join("cube1.cdf")).unwrap();
    assert_eq!(
        recorded, read,
        "the image is recorded with the file read at start"
    );
    let log = std::fs::read_to_string(c.session().join("cube.log")).unwrap();
    assert!(
        log.contains("cam1.cdf changed since the console read it"),
        "{log}"
    );
    c.send("q");
    c.wait_exit(15);
}
