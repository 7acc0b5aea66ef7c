//! The camera description an image records (`NAMEk.cdf`) as the console
//! and `vss session redo` both meet it, in the real console at 80 × 24: a
//! damaged record is refused by both in the same words, and a capture
//! without a description leaves no stale record.

use std::path::Path;

use vss::tui::keymap::{Action, PipelineAction, SurveyAction};

use super::tui_harness::{Console, PIPELINE, SURVEY, five_lightings, write_cdfs};

/// `vss session redo --from lens` of image 1, with the console's profile.
fn redo(c: &Console) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
        .current_dir(c.dir.path())
        .env("HOME", c.dir.path())
        .args(["session", "redo", "--profile", "cell.toml", "--image", "1"])
        .args(["--from", "lens"])
        .arg(c.session())
        .output()
        .unwrap()
}

/// Image 1's output files and the manifest, as bytes.
fn outputs(session: &Path) -> Vec<Vec<u8>> {
    [
        "cube1.hpo",
        "cube1.vpo",
        "cube1.lex",
        "cube1.ldr",
        "cube.toml",
    ]
    .iter()
    .map(|f| std::fs::read(session.join(f)).unwrap())
    .collect()
}

/// On the session list: opens `cube` and shows image 1 (the session
/// resumes at image 2).
fn show_image_1(c: &mut Console) {
    c.open_cube();
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait("image 1 shown with its saved outputs", 20, |s| {
        s.contains("Image 1: ") && s.contains("saved")
    });
}

/// The session's log, `cube.log`.
fn log(c: &Console) -> String {
    std::fs::read_to_string(c.session().join("cube.log")).unwrap_or_default()
}

/// Image 1 surveyed, then its recorded `cube1.cdf` cut short inside `D`'s
/// values (a full disk, a copy interrupted): the console shows the image
/// and its saved outputs but runs nothing and saves nothing, saying the
/// record is damaged, where, and what to do, in the words `vss session
/// redo` refuses the image with. Before, the console ran the image with
/// lens correction off (and could save those outputs) while redo refused.
#[test]
fn a_damaged_recorded_camera_description_is_refused_alike_by_the_console_and_redo() {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |d| {
        write_cdfs(d, 2);
    });
    c.survey(1);
    let session = c.session();
    let before = outputs(&session);
    let cdf = session.join("cube1.cdf");
    let mut c = c.restart_after(|_| {
        let text = std::fs::read_to_string(&cdf).unwrap();
        let d = text.find("D=").unwrap();
        let cut = d + text[d..].find('\n').unwrap() + 1;
        let cut = cut + text[cut..].find('\n').unwrap() + 1;
        std::fs::write(&cdf, &text[..cut]).unwrap();
    });
    // What the parser says of the cut file, with its line.
    let e = vss::formats::cdf::read_cdf(&cdf).unwrap_err();
    let vss::formats::Location::Line(n) = e.location else {
        panic!("a line: {e}");
    };
    let words = format!(
        "cube1.cdf is damaged (line {n}: {}); the image is not run without the lens \
         correction it was surveyed with",
        e.message
    );
    show_image_1(&mut c);
    c.wait("the load says why", 20, |_| log(&c).contains(&words));
    // A tuned value asks for a run: refused, and nothing to save.
    c.open_pipeline();
    c.choose_param("lens.enabled");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Dec));
    c.wait("the run refused", 20, |_| {
        log(&c).contains("not run: image 1: its recorded camera description")
    });
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Save));
    c.wait("the save refused", 20, |_| {
        log(&c).contains("not saved: image 1: its recorded camera description")
    });
    c.send("q");
    c.wait_exit(15);
    let log = log(&c);
    assert!(!log.contains("lens correction is off"), "{log}");
    assert!(outputs(&session) == before, "nothing saved: {log}");
    let out = redo(&c);
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{said}");
    assert!(said.contains(&words), "redo says the same: {said}");
    assert!(outputs(&session) == before, "redo saved nothing");
}

/// Image 1 surveyed with camera 1's `.cdf`, then the profile names none
/// for it, and image 1 captured again: the session no longer records the
/// old description with it (nor keeps its `cube1.cdf`), so `vss session
/// redo` runs it as the console did, without lens correction, and makes
/// what the console saved. Before, the old record stayed: redo corrected
/// the new frames with the old description.
#[test]
fn a_capture_without_a_camera_description_leaves_no_stale_record() {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |d| {
        write_cdfs(d, 2);
    });
    c.survey(1);
    let session = c.session();
    assert!(session.join("cube1.cdf").is_file());
    let mut c = c.restart_after(|d| {
        let profile = five_lightings(true).replace("cdf = [\"cam1.cdf\", \"cam2.cdf\"]\n", "");
        assert!(!profile.contains("cdf ="));
        std::fs::write(d.join("cell.toml"), profile).unwrap();
    });
    show_image_1(&mut c);
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    c.wait_text("Capture image 1 again", 10);
    c.yes();
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Replace its saved outputs", 10);
    c.yes();
    c.wait("image 1's outputs saved again", 30, |_| {
        log(&c).matches("image 1 accepted: outputs saved").count() == 2
    });
    c.send("q");
    c.wait_exit(15);
    let s = vss::session::Session::inspect(&session).unwrap();
    assert_eq!(s.manifest().image(1).unwrap().cdf, None, "no stale record");
    assert!(!session.join("cube1.cdf").exists(), "nor its file");
    let check = crate::support::run::output_in(
        c.dir.path(),
        &["session", "check", &session.to_string_lossy()],
    );
    let said = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success() && !said.contains("cube1.cdf"),
        "{said}"
    );
    let saved = std::fs::read(session.join("cube1.lex")).unwrap();
    let out = redo(&c);
    assert!(out.status.success(), "{out:?}");
    assert!(
        std::fs::read(session.join("cube1.lex")).unwrap() == saved,
        "vss session redo makes what the console saved"
    );
}
