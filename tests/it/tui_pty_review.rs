//! Going back, safe keys and honest previews, through the real binary in a
//! pty at 80 × 24: after a restart the last worked image is on the
//! Pipeline screen and any image of the checklist can be gone back to and
//! edited (asked first, logged in words, undo taken back); keys that save
//! never sit on a moving key's letter, Enter in review and q during a
//! capture ask, the end of the survey is announced; pictures say their
//! stretch and where the view is, draw lines as coloured Braille on grey,
//! and follow the cursor; a click chooses a checklist row.

use vss::session::Session;
use vss::tui::keymap::{
    Action, EditAction, ModalAction, NavAction, PipelineAction, Scope, SurveyAction,
};

use super::tui_harness::{Console, EDIT, PIPELINE, PROFILE, SURVEY, flat};

fn edits(c: &Console, k: u32) -> Vec<String> {
    Session::inspect(&c.session())
        .ok()
        .and_then(|s| {
            s.manifest()
                .image(k)
                .map(|r| r.edit.iter().map(|e| e.op.clone()).collect())
        })
        .unwrap_or_default()
}

fn wait_edits(c: &Console, k: u32, n: usize) -> Vec<String> {
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    loop {
        let e = edits(c, k);
        if e.len() == n {
            return e;
        }
        assert!(
            std::time::Instant::now() < end,
            "{n} edits never recorded: {e:?}"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

#[test]
fn any_image_can_be_gone_back_to_and_edited() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(2);
    let mut c = c.restart_after(|_| {});
    c.open_cube();
    // The last worked image is on the Pipeline screen at once.
    c.send("3");
    c.wait_text("image 2a · lines over grey", 10);
    // Back to image 1 through the checklist.
    c.send("1");
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.wait_text("Image 1 chosen", 5);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("Image 1: ", 10);
    c.send("4");
    c.wait_text("image 1a · lines over grey", 10);
    c.press(EDIT, Action::Edit(EditAction::LineNext));
    c.press(EDIT, Action::Edit(EditAction::Delete));
    c.wait_words("Image 1 is accepted. Change its lines?", 10);
    c.yes();
    let e = wait_edits(&c, 1, 1);
    assert!(
        e[0].starts_with("deleted line 0 ("),
        "the edit's detail in words: {e:?}"
    );
    c.wait_text("last edits", 5);
    c.press(EDIT, Action::Edit(EditAction::Undo));
    wait_edits(&c, 1, 0);
    c.press(EDIT, Action::Edit(EditAction::Redo));
    wait_edits(&c, 1, 1);
    c.send("q");
    c.wait_exit(10);
}

/// A cell with one camera (a plan of one image) and a slow settle, so a
/// capture lasts long enough to press keys during it.
fn slow_cell() -> String {
    PROFILE
        .replace("settle_ms = 5", "settle_ms = 600")
        .replace("cameras = 4", "cameras = 1")
}

#[test]
fn keys_that_write_ask_or_stay_apart_from_moving_keys() {
    let mut c = Console::start_with(&slow_cell(), 80, 24, &[], |_| {});
    c.create_session("cube");
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("capturing", 10);
    c.send("q");
    c.wait_words("A capture is under way. Quit anyway?", 5);
    c.press(Scope::Confirm, Action::Modal(ModalAction::No));
    c.wait("image 1 reviewed", 30, |s| s.contains("before CONNECT"));
    // Enter in review asks; no does nothing.
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("Accept image 1 and go on", 5);
    c.press(Scope::Confirm, Action::Modal(ModalAction::No));
    // On the Pipeline screen, s and S (Caps Lock) move nothing into the
    // session.
    c.send("3");
    c.wait_text("parameters", 10);
    c.send("sS");
    c.press(PIPELINE, Action::Nav(NavAction::CursorDown));
    c.wait("the keys taken", 5, |s| s.contains("x64 y66"));
    assert!(
        !c.session().join("cube1.ldr").exists(),
        "nothing saved by s or S"
    );
    // The save key does.
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Save));
    c.wait_text("image 1 accepted: outputs saved", 10);
    // The plan of one image done: the end is announced.
    c.send("1");
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = c.wait_text("survey complete", 10);
    assert!(flat(&s).contains("5 writes the report"), "{s}");
    // The whole of the next step fits its box at 80 × 24, down to its end.
    assert!(flat(&s).contains("Enter one more (2)"), "{s}");
    // `o` with a session open shows the picker, Esc goes back.
    c.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    c.wait_text("open another session", 5);
    c.send("\x1b");
    c.wait_text("session cube", 5);
    c.send("q");
    c.wait_exit(10);
}

#[test]
fn pictures_say_what_they_show_and_follow_the_cursor() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    c.send("3");
    let s = c.wait("the Pipeline screen", 10, |s| {
        s.contains("parameters") && s.contains("stretched")
    });
    assert!(s.contains("whole image"), "{s}");
    assert!(!s.contains("-0.0"), "{s}");
    // Lines over grey: Braille in the line colour on a grey cell.
    let coloured_braille = c.with_screen(|sc| {
        let (rows, cols) = sc.size();
        (0..rows).any(|r| {
            (0..cols).any(|col| {
                sc.cell(r, col).is_some_and(|cell| {
                    let braille = cell
                        .contents()
                        .chars()
                        .next()
                        .is_some_and(|ch| ('\u{2801}'..='\u{28ff}').contains(&ch));
                    braille
                        && cell.fgcolor() == vt100::Color::Idx(196)
                        && matches!(cell.bgcolor(), vt100::Color::Idx(16 | 231 | 232..=255))
                })
            })
        })
    });
    assert!(
        coloured_braille,
        "red Braille on a grey cell:\n{}",
        c.screen()
    );
    for _ in 0..2 {
        c.press(PIPELINE, Action::Nav(NavAction::ZoomIn));
    }
    let before = c.wait_text("×4 x", 5);
    let view = |s: &str| {
        s.lines()
            .find_map(|l| l.find("×4 x").map(|i| l[i..].to_string()))
            .unwrap_or_default()
    };
    let v0 = view(&before);
    for _ in 0..40 {
        c.press(PIPELINE, Action::Nav(NavAction::CursorRight));
    }
    let s = c.wait("the view moved after the cursor", 5, |s| {
        view(s) != v0 && s.contains("x104 ")
    });
    assert!(!s.contains("-0.0"), "{s}");
    c.send("q");
    c.wait_exit(10);
}

/// A click on a checklist row chooses that image (SGR mouse reports).
#[test]
fn a_click_chooses_a_checklist_row() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    // The checklist's rows start on screen row 6 (1-based): top bar,
    // border, three heading rows; image 1 is the first.
    c.send("\x1b[<0;6;6M\x1b[<0;6;6m");
    c.wait_text("Image 1 chosen", 5);
    // The wheel over the list moves the choice down (past image 2, the
    // one under work).
    c.send("\x1b[<65;6;8M\x1b[<65;6;8M");
    c.wait_text("Image 3 chosen", 5);
    c.send("q");
    c.wait_exit(10);
}

/// After Ctrl-S on the Pipeline screen the image is saved (accepted): the
/// next-step box says so and that a goes on, not "a accepts"; a then goes
/// on without saving again.
#[test]
fn the_next_step_after_ctrl_s_says_the_image_is_saved() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    c.capture_current(1);
    let s = c.wait_text("a accepts", 10);
    assert!(!flat(&s).contains("saved a goes on"), "{s}");
    c.press(
        Scope::Global,
        Action::Global(vss::tui::keymap::GlobalAction::GoTo(
            vss::tui::keymap::ScreenId::Pipeline,
        )),
    );
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Save));
    c.wait_text("image 1 accepted: outputs saved", 20);
    c.press(
        Scope::Global,
        Action::Global(vss::tui::keymap::GlobalAction::GoTo(
            vss::tui::keymap::ScreenId::Survey,
        )),
    );
    let s = c.wait_words("a goes on: it is accepted", 10);
    assert!(!flat(&s).contains("a accepts"), "{s}");
    assert!(flat(&s).contains("before CONNECT), saved"), "{s}");
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 2: camera", 10);
    c.send("q");
    c.wait_exit(15);
}
