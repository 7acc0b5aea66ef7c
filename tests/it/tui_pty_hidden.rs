//! Nothing the operator cannot see decides the result (issue 33), through
//! the real binary in a pty at 80 × 24: a value tuned on the Pipeline
//! panel is named in the next-step box before it goes into the next
//! capture, and `D` puts it back; an image captured again is run with the
//! values it was made with. Damage is counted where the survey ends and
//! in the report's message, listed first on the Session screen, and a
//! damaged `.ldr` is made again from the saved frames, offered first.

use vss::session::manifest::Manifest;
use vss::tui::keymap::{Action, FilesAction, GlobalAction, PipelineAction, Scope, SurveyAction};

use super::tui_harness::{Console, PIPELINE, SESSION, SURVEY};

/// The screen's words, box borders left out, so text wrapped inside a box
/// reads on.
fn flat(s: &str) -> String {
    s.replace(['│', '|'], " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

fn wait_words(c: &Console, text: &str, secs: u64) -> String {
    c.wait(text, secs, |s| flat(s).contains(text))
}

fn global(c: &mut Console, g: GlobalAction) {
    c.press(Scope::Global, Action::Global(g));
}

fn manifest(c: &Console) -> Manifest {
    let path = c.session().join("cube.toml");
    Manifest::parse(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
}

/// `lines.min_length` of image `k`'s recorded outputs.
fn min_length(c: &Console, k: u32) -> Option<f64> {
    manifest(c)
        .image(k)?
        .outputs
        .as_ref()?
        .params
        .get("lines.min_length")
}

#[test]
fn tuned_values_are_named_before_a_capture_and_reset_by_a_key() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(2);
    let profile = min_length(&c, 1).expect("image 1 recorded");
    // Tune on the Pipeline screen while image 3 waits for its capture.
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Pipeline),
    );
    c.wait_text("parameters", 10);
    c.choose_param("lines.min_length");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Type));
    c.wait_text("lines.min_length =", 5);
    c.send("\x15"); // Ctrl-U: the old text away
    c.send("40\r");
    wait_words(&c, "lines.min_length 40", 10);
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Survey),
    );
    wait_words(&c, "not the profile's: lines.min_length 40 · D", 10);
    // Captured again, image 1 runs with what it was made with, not 40.
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    c.wait_text("Capture image 1 again", 10);
    c.yes();
    c.wait("image 1's values, the profile's, on the panel", 10, |s| {
        !flat(s).contains("not the profile's")
    });
    global(&mut c, GlobalAction::ToggleLog);
    wait_words(
        &c,
        "the panel now shows the values image 1 was made with",
        10,
    );
    global(&mut c, GlobalAction::ToggleLog);
    global(&mut c, GlobalAction::ToggleLog);
    // Back to 40, then D: every value is the profile's again.
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Pipeline),
    );
    c.wait_text("parameters", 10);
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Type));
    c.wait_text("lines.min_length =", 5);
    c.send("\x1540\r");
    wait_words(&c, "lines.min_length 40", 10);
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Survey),
    );
    wait_words(&c, "not the profile's: lines.min_length 40", 10);
    c.press(SURVEY, Action::Survey(SurveyAction::ResetParams));
    wait_words(&c, "back to the profile's values: lines.min_length 40", 10);
    let s = c.screen();
    assert!(!flat(&s).contains("not the profile's"), "{s}");
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 1 is accepted. Replace", 10);
    c.yes();
    c.wait_text("image 1 accepted", 20);
    c.wait("image 1 recorded anew", 20, |_| {
        min_length(&c, 1) == Some(profile)
    });
    c.send("q");
    c.wait_exit(15);
}

#[test]
fn damage_is_counted_listed_first_and_a_damaged_ldr_made_again() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(3);
    c.wait_text("3 of 4 done", 20);
    c.capture_current(4);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Survey complete.", 20);
    let d = c.session();
    let mut c = c.restart_after(|dir| {
        let img = dir.join("sessions/cube/cube2b.img");
        let f = std::fs::OpenOptions::new().write(true).open(&img).unwrap();
        f.set_len(5000).unwrap();
        std::fs::write(dir.join("sessions/cube/cube4.ldr"), "not a line file\n").unwrap();
    });
    c.wait_text("4/4 done", 10);
    c.send("\r");
    let s = wait_words(&c, "survey complete, 2 problems: image 2", 15);
    assert!(
        s.contains("lighting b, image 4 lines") && !s.contains("Survey complete."),
        "{s}"
    );
    // The report's message counts them.
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Session),
    );
    let s = c.wait_text("problem(s), listed first", 10);
    let (bad, good) = (s.find("DAMAGED"), s.find(" ok "));
    assert!(
        bad.zip(good).is_some_and(|(b, g)| b < g),
        "the damaged files are listed before those that read:\n{s}"
    );
    c.press(SESSION, Action::Files(FilesAction::Export));
    let s = wait_words(&c, "2 problem(s) marked in it", 30);
    assert_eq!(
        flat(&s).matches("report written").count(),
        1,
        "one message for the report:\n{s}"
    );
    // R on image 4 offers the remake from its saved frames first.
    global(
        &mut c,
        GlobalAction::GoTo(vss::tui::keymap::ScreenId::Survey),
    );
    c.wait_text("session cube", 10);
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    let s = wait_words(&c, "y makes them again from its saved frames", 10);
    assert!(flat(&s).contains("outputs are damaged"), "{s}");
    c.yes();
    c.wait("the .ldr made again", 30, |_| {
        vss::formats::lines::read_lines(&d.join("cube4.ldr")).is_ok()
    });
    // The message says how, in the log: on a busy machine the status line
    // may show the next one ("saved outputs and lines loaded") before the
    // screen is read.
    global(&mut c, GlobalAction::ToggleLog);
    wait_words(&c, "from its saved frames with its recorded values", 10);
    c.send("q");
    c.wait_exit(15);
}

/// The session list puts the session worked on last first (alphabetical
/// put `alpha` over the `zulu` just worked on), marks the one open in
/// this console as such (not "in use by" its own user), the next-step box
/// beside the list says Enter opens a session (not that it captures), and
/// after a restart Enter opens the one just worked on.
#[test]
fn sessions_are_listed_most_recent_first_and_the_open_one_marked() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("alpha");
    c.press(SURVEY, Action::Survey(SurveyAction::NewSession));
    c.wait_text("new session name", 5);
    c.send("zulu\r");
    c.wait_text("session zulu", 10);
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 2: camera", 20);
    // Wait for the list the store made after the capture to be asked for.
    c.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    let s = c.wait_text("open another session", 10);
    let rows: Vec<&str> = s.lines().filter(|l| l.contains(" done")).collect();
    assert!(
        rows.first()
            .is_some_and(|r| r.contains("zulu") && r.contains("(open here)")),
        "{s}"
    );
    assert!(!s.contains("in use by"), "{s}");
    // The next-step box says what Enter does while the list is open: it
    // opens a session, it does not capture image 2.
    let w = s.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        w.contains("Session zulu stays open until another is."),
        "{s}"
    );
    assert!(
        w.contains("↑↓ Enter opens a session · Esc goes back"),
        "{s}"
    );
    assert!(!w.contains("Enter captures"), "{s}");
    // The key bar offers no key for the hidden image.
    let bar = s.lines().rev().take(2).collect::<Vec<_>>().join(" ");
    for hint in ["a accept", "R redo", "c camera", "p place"] {
        assert!(!bar.contains(hint), "{hint}: {s}");
    }
    // Its key does nothing to it, and says why.
    c.press(SURVEY, Action::Survey(SurveyAction::Camera));
    wait_words(
        &c,
        "the session list is open: Esc goes back to the checklist first",
        10,
    );
    c.send("\x1b");
    let s = c.wait_text("Enter captures", 10);
    assert!(!s.contains("stays open until"), "{s}");
    assert!(s.contains("Image 2: camera 2 (c)"), "{s}");
    let mut c = c.restart(80, 24, &[]);
    c.wait_text("zulu", 10);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("session zulu", 10);
    c.send("q");
    c.wait_exit(15);
}

/// At 60 × 20 during a capture the screen still says what is captured and
/// shows the question `q` asks, with its keys; when the capture ends the
/// question no longer applies and closes itself, and the enlarged window
/// shows no stale "Quit anyway?".
#[test]
fn too_small_keeps_the_capture_and_the_question_in_sight() {
    let profile = super::tui_harness::PROFILE
        .replace("settle_ms = 5", "settle_ms = 400")
        .replace("width = 128\nheight = 128", "width = 256\nheight = 256");
    let mut c = Console::start_with(&profile, 80, 24, &[], |_| {});
    c.create_session("cube");
    c.wait_text("Image 1: camera", 10);
    // Keys other than q and Esc wait for a larger window: the capture
    // starts before the window shrinks.
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("capturing", 10);
    c.resize(20, 60);
    c.wait_text("terminal too small", 10);
    c.wait_words("capturing image 1", 10);
    c.send("q");
    let s = wait_words(&c, "A capture is under way. Quit anyway?", 10);
    assert!(s.contains("y yes"), "{s}");
    let s = c.wait("the question closed after the capture", 60, |s| {
        !s.contains("capturing") && s.contains("q quits")
    });
    assert!(!flat(&s).contains("Quit anyway"), "{s}");
    c.resize(24, 80);
    let s = c.wait_text("before CONNECT", 30);
    assert!(!flat(&s).contains("Quit anyway"), "{s}");
    c.send("q");
    c.wait_exit(15);
}
