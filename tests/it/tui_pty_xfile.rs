//! The console against a shop floor's files and folders: a session folder
//! moved away while it is open, a manifest that is not a file.

use vss::tui::keymap::{Action, SurveyAction};

use super::tui_harness::{Console, SURVEY, flat};

/// A session folder renamed while the console has it open (someone tidies
/// the survey folder): the next save is refused and said as what happened
/// — the folder is gone — not as a take-over by "nobody"; nothing is
/// written (no folder is made again at the old path); and once the folder
/// is put back, `a` saves.
#[test]
fn a_session_folder_moved_away_while_open_is_said_and_nothing_is_written() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let d = c.session();
    c.capture_current(1);
    let moved = c.sessions().join("cube-moved");
    std::fs::rename(&d, &moved).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = c.wait_text("outputs of image 1 NOT saved", 10);
    let s = flat(&s);
    assert!(s.contains("is gone (moved"), "what happened:\n{s}");
    assert!(!s.contains("taken over"), "not a take-over:\n{s}");
    assert!(!d.exists(), "nothing made at the old path");
    assert!(
        !moved.join("cube1.ldr").exists(),
        "nothing written where it went"
    );
    std::fs::rename(&moved, &d).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("image 1 accepted", 20);
    assert!(d.join("cube1.ldr").is_file());
    c.send("q");
    c.wait_exit(10);
}

/// A session whose manifest was replaced by a folder is listed DAMAGED
/// with why, not left out of the list as if there were no session.
#[test]
fn a_session_whose_manifest_is_a_folder_is_listed_damaged() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let m = c.session().join("cube.toml");
    let mut c = c.restart_after(|_| {
        std::fs::remove_file(&m).unwrap();
        std::fs::create_dir(&m).unwrap();
    });
    c.wait_text("choose a session", 10);
    c.wait("cube listed DAMAGED", 10, |s| {
        s.lines()
            .any(|r| r.contains("cube") && r.contains("DAMAGED"))
    });
    c.send("q");
    c.wait_exit(10);
}
