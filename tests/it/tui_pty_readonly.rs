//! A session whose folder cannot be written (here a read-only bind mount
//! of it, which holds for root too) is opened only to look, after the
//! operator says yes: the top bar says "read-only: nothing will be saved",
//! the images and lines show, every action that would write is refused
//! with what was refused, `q` quits at once, and no file of the folder
//! changes. Root bind-mounts the folder read-only; anyone else takes the
//! folder's write permission away (which root would not notice).

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use vss::tui::keymap::{Action, FilesAction, ModalAction, Scope, ScreenId, SurveyAction};

use super::tui_harness::{Console, SURVEY, flat};
use crate::support::files::ReadOnly;

/// Every file of `dir` with its length and modification time.
pub fn files(dir: &Path) -> Vec<(PathBuf, u64, SystemTime)> {
    let mut out: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| {
            let m = e.metadata().unwrap();
            (e.path(), m.len(), m.modified().unwrap())
        })
        .collect();
    out.sort();
    out
}

#[test]
fn a_session_that_cannot_be_written_opens_only_to_look() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    let dir = c.session();
    let mut mounted = None;
    let mut c = c.restart_after(|_| mounted = ReadOnly::make(&dir));
    let Some(_ro) = mounted else {
        eprintln!("SKIPPED: root here cannot mount, and writes through permissions");
        c.send("q");
        c.wait_exit(10);
        return;
    };
    assert!(
        std::fs::write(dir.join("probe"), "x").is_err(),
        "the folder is read-only"
    );
    let before = files(&dir);
    // The list read (its row says how far the survey is), then Enter.
    c.wait("the session listed", 10, |s| {
        s.contains("choose a session") && s.contains("done")
    });
    // Asked, not downgraded silently: no keeps the list.
    c.send("\r");
    c.wait_words("Open it read-only", 10);
    c.press(Scope::Confirm, Action::Modal(ModalAction::No));
    c.wait("the question closed", 5, |s| {
        !s.contains("Open it read-only")
    });
    assert!(c.screen().contains("choose a session"));
    // Yes: open to look, said on the top bar.
    c.send("\r");
    c.wait_words("Open it read-only", 10);
    c.yes();
    let s = c.wait_text("read-only: nothing will be saved", 10);
    assert!(s.lines().next().unwrap().contains("read-only"), "{s}");
    assert!(s.contains("done"), "image 1 is listed done:\n{s}");
    // The next step offers nothing that would write.
    let s = c.wait_words("Open only to look", 10);
    assert!(!flat(&s).contains("captures lightings"), "{s}");
    // It opens on its newest done image, with its lines, without a key;
    // Enter there would accept it: refused.
    c.wait_text("image 1a + lines", 20);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_words("accepting refused", 10);
    // Enter on the next image would capture: refused.
    c.press(SURVEY, Action::Survey(SurveyAction::Down));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait("image 2 under work", 10, |s| s.contains(">  2 "));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_words("capturing refused", 10);
    // Image 1 can be gone back to and seen with its lines ...
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("image 1a + lines", 20);
    // ... but not accepted, taken again, or reported.
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_words("accepting refused", 10);
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    c.wait_words("taking an image again refused", 10);
    c.press(
        Scope::Global,
        Action::Global(vss::tui::keymap::GlobalAction::GoTo(ScreenId::Session)),
    );
    c.wait_text("files (", 10);
    c.press(
        Scope::Screen(ScreenId::Session),
        Action::Files(FilesAction::Export),
    );
    c.wait_words("writing the reports refused", 10);
    // Nothing to lose: q quits at once.
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
    assert_eq!(files(&dir), before, "no file of the folder changed");
    assert!(
        !c.screen().contains("NOT saved"),
        "no write was tried:\n{}",
        c.screen()
    );
}
