//! Camera calibration files as a cell meets them, in the real console at
//! 80 × 24: a camera whose `.cdf` distortion folds the image (a digit of
//! `D` lost by hand) is refused by the Pipeline with where it folds, and
//! the frames captured are kept.

use vss::formats::cdf::{read_cdf, write_cdf};
use vss::tui::keymap::{Action, GlobalAction, ScreenId, SurveyAction};

use super::tui_harness::{
    Console, PIPELINE, SURVEY, five_lightings, flat, panel_value, write_cdfs,
};

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

/// Image 1 surveyed, then camera 1 recalibrated (its `.cdf` replaced,
/// another `k1` and centre, while no console runs), the console started
/// again and image 1 shown: the console, image 1's recorded `.cdf` and
/// `.lex` as surveyed.
fn surveyed_then_recalibrated() -> (Console, Vec<u8>, Vec<u8>) {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |d| {
        write_cdfs(d, 2);
    });
    c.survey(1);
    let session = c.session();
    let recorded = std::fs::read(session.join("cube1.cdf")).unwrap();
    let first = std::fs::read(session.join("cube1.lex")).unwrap();
    let mut c = c.restart_after(|d| {
        let path = d.join("cam1.cdf");
        let cdf = read_cdf(&path).unwrap();
        let mut m = cdf.camera_model().unwrap();
        let mut k = m.distortion.unwrap();
        k[0] *= 2.0;
        m.distortion = Some(k);
        m.cx += 6.0;
        assert!(m.fold_in(128, 128).is_none(), "a lens that does not fold");
        let mut out = vss::formats::cdf::Cdf::from_camera(&m, cdf.extrinsic());
        out.set(cdf.get("S").unwrap().clone());
        write_cdf(&path, &out).unwrap();
    });
    c.open_cube();
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait("image 1 shown with its saved outputs", 20, |s| {
        s.contains("Image 1: ") && s.contains("saved")
    });
    (c, recorded, first)
}

/// Waits until the log has said `n` times that image 1's outputs were saved.
fn wait_saved(c: &Console, n: usize) {
    let log = c.session().join("cube.log");
    c.wait("image 1's outputs saved", 30, |_| {
        std::fs::read_to_string(&log)
            .is_ok_and(|t| t.matches("image 1 accepted: outputs saved").count() == n)
    });
}

/// Says yes to replacing image 1's saved outputs, waits until they are
/// saved, and quits.
fn replace_and_quit(c: &mut Console) {
    c.wait_text("Replace its saved outputs", 10);
    c.yes();
    wait_saved(c, 2);
    c.send("q");
    c.wait_exit(15);
}

/// Image 1's `.lex` after `vss session redo --from lens`, with the
/// console's profile.
fn redone(c: &Console) -> Vec<u8> {
    let session = c.session();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
        .current_dir(c.dir.path())
        .env("HOME", c.dir.path())
        .args(["session", "redo", "--profile", "cell.toml", "--image", "1"])
        .args(["--from", "lens"])
        .arg(&session)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    std::fs::read(session.join("cube1.lex")).unwrap()
}

/// After a recalibration, an image surveyed before it and run again in
/// the console (here lens correction off and on) is corrected with the
/// description recorded with it, as `vss session redo` does, so the
/// outputs the console saves are those redo makes. Before, the console
/// used the new file while the session still recorded the old one.
#[test]
fn an_image_surveyed_before_a_recalibration_runs_with_its_recorded_camera() {
    use vss::tui::keymap::PipelineAction;
    let (mut c, recorded, first) = surveyed_then_recalibrated();
    c.open_pipeline();
    c.choose_param("lens.enabled");
    for action in [PipelineAction::Dec, PipelineAction::Inc] {
        c.press(PIPELINE, Action::Pipeline(action));
        let want = if action == PipelineAction::Dec {
            "0"
        } else {
            "1"
        };
        c.wait(&format!("lens.enabled = {want} run"), 20, |s| {
            panel_value(s, "lens.enabled").as_deref() == Some(want)
                && !s.contains("running")
                && !s.contains("stale")
        });
    }
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Save));
    replace_and_quit(&mut c);
    let session = c.session();
    assert!(
        std::fs::read(session.join("cube1.cdf")).unwrap() == recorded,
        "still recorded with the description it was captured with"
    );
    let saved = std::fs::read(session.join("cube1.lex")).unwrap();
    assert!(
        saved == first,
        "run again with its recorded camera, the same lines as when surveyed"
    );
    assert!(
        redone(&c) == saved,
        "vss session redo makes what the console saved"
    );
}

/// After a recalibration, an image surveyed before it and captured again
/// (R) is recorded with the new description, which the console corrected
/// its new frames with: `vss session redo` makes what the console saved.
/// Before, the image kept the old description on record while the console
/// used the new one.
#[test]
fn an_image_captured_again_after_a_recalibration_is_recorded_with_the_new_camera() {
    let (mut c, recorded, _) = surveyed_then_recalibrated();
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    c.wait_text("Capture image 1 again", 10);
    c.yes();
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    replace_and_quit(&mut c);
    let session = c.session();
    let now = vss::formats::cdf::format_cdf(&read_cdf(&c.dir.path().join("cam1.cdf")).unwrap());
    let on_record = std::fs::read(session.join("cube1.cdf")).unwrap();
    assert!(
        on_record != recorded,
        "the old description is no longer on record"
    );
    assert_eq!(String::from_utf8_lossy(&on_record), now, "the new one is");
    let saved = std::fs::read(session.join("cube1.lex")).unwrap();
    assert!(
        redone(&c) == saved,
        "vss session redo makes what the console saved"
    );
}
