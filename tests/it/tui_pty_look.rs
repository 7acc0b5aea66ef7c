//! Looking at a session another console holds and still runs (the 3 a.m.
//! case: a colleague's console is running the survey): the second console
//! is offered take over / read-only / neither; read-only opens it by the
//! same path as an unwritable folder — no lock written, no take-over
//! request, nothing saved — and the first console goes on saving. The
//! read-only view's hint rows offer only the keys that work there. Two
//! real consoles on real ptys at 80 × 24.

use std::path::PathBuf;
use std::time::SystemTime;

use vss::session::Session;
use vss::session::lock::leave_path;
use vss::tui::keymap::{Action, GlobalAction, ModalAction, Scope, ScreenId, SurveyAction};

use super::tui_harness::{Console, SURVEY, flat, line_count};
use super::tui_pty_readonly::files;

/// The bottom rows of the screen, where the hints are (at most three).
fn hint_rows(s: &str) -> String {
    let rows: Vec<&str> = s.lines().collect();
    flat(&rows[rows.len().saturating_sub(3)..].join("\n"))
}

/// The lock file's bytes and the folder's files with their lengths and
/// times, as the first console left them.
type Before = (Vec<u8>, Vec<(PathBuf, u64, SystemTime)>);

/// A first console that surveyed images 1 to `n` of `cube` and holds it,
/// and a second one in the same folder that chose to look at it
/// read-only; the folder as it was before the second started.
fn looking(n: u32) -> (Console, Console, Before) {
    let mut a = Console::start(80, 24, &[]);
    a.survey(n);
    let (b, before) = look_at(&a);
    (a, b, before)
}

/// A second console in `a`'s folder that chose to look at the session `a`
/// holds read-only; the folder as it was before it started.
fn look_at(a: &Console) -> (Console, Before) {
    let dir = a.session();
    let held = std::fs::read(dir.join("cube.lock")).expect("the first console holds the lock");
    let before = files(&dir);
    let mut b = a.another(80, 24);
    b.wait_text("in use by", 10);
    // Its devices found first, so that what opening says is the newest.
    b.wait_devices(10);
    // Esc leaves the question and the session alone.
    b.send("\r");
    b.wait_text("over anyway?", 10);
    b.send("\x1b");
    b.wait("the question closed", 10, |s| {
        !s.contains("over anyway?") && s.contains("choose a session")
    });
    b.send("\r");
    // Three choices, all in sight at 80 × 24, in the question's box and
    // on the hint row.
    let s = b.wait_text("over anyway?", 10);
    assert!(s.contains("y yes   n no   r read-only"), "{s}");
    assert!(hint_rows(&s).contains("y yes n no r read-only"), "{s}");
    b.press(Scope::Confirm, Action::Modal(ModalAction::Look));
    let s = b.wait_text("read-only: nothing will be saved", 10);
    assert!(s.lines().next().unwrap().contains("read-only"), "{s}");
    (b, (held, before))
}

#[test]
fn a_second_console_looks_at_a_held_session_without_disturbing_it() {
    let (mut a, mut b, (held, before)) = looking(1);
    let dir = a.session();
    let lock = dir.join("cube.lock");
    let s = b.screen();
    assert!(s.contains("1 of 4 done"), "image 1 is listed done:\n{s}");
    // Said whose it stays, and that what it saves will show (in the log:
    // the image's loading is said after it).
    b.press(Scope::Global, Action::Global(GlobalAction::ToggleLog));
    b.wait("the log says whose it stays", 10, |s| {
        flat(&s.replace('│', " ")).contains("stays with process")
    });
    b.press(Scope::Global, Action::Global(GlobalAction::ToggleLog));
    b.press(Scope::Global, Action::Global(GlobalAction::ToggleLog));
    // Its image with its lines shows (the newest done image, opened on).
    b.wait_text("image 1a + lines", 20);
    // The first console was not disturbed: its lock is the same bytes, no
    // request to leave was made, no file of the folder changed.
    assert_eq!(std::fs::read(&lock).unwrap(), held, "the lock is untouched");
    assert!(!leave_path(&lock).exists(), "no take-over request");
    assert_eq!(files(&dir), before, "nothing written into the folder");
    assert!(
        !a.screen().contains("taken over"),
        "the first console keeps the session:\n{}",
        a.screen()
    );
    // It still saves: image 2 captured and accepted.
    a.capture_current(2);
    a.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = a.wait_text("image 2 accepted", 20);
    assert!(!s.contains("NOT saved"), "{s}");
    // What it saved shows in the second console without a key: the view
    // is read again when the folder changes.
    b.wait("image 2 shows done in the second console", 10, |s| {
        s.contains("2 of 4 done")
    });
    // The second console leaves at once, the lock still the first's.
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
    assert_eq!(std::fs::read(&lock).unwrap(), held, "the lock is untouched");
    assert_eq!(a.exit_code(), None, "the first console runs on");
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
}

/// The console holding the session is gone (its SSH connection dropped):
/// the one looking chooses the session again in the list (`o`, Enter) and
/// has it to write, without a restart. While the holder still ran, the same
/// choice asked the usual question and left both as they were. Before, it
/// only closed the list: the session stayed read-only until a restart.
#[test]
fn choosing_the_session_looked_at_again_asks_for_it_to_write() {
    let (mut a, mut b, (held, _)) = looking(1);
    let lock = a.session().join("cube.lock");
    b.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    // The next-step box beside the list says what choosing it does (it
    // said "a accepts", as if the session could be written).
    let s = b.wait_text("this one, to write", 10);
    assert!(s.contains("open another session"), "{s}");
    assert!(!s.contains("a accepts"), "{s}");
    b.send("\r");
    b.wait_text("over anyway?", 10);
    b.send("n");
    let s = b.wait("the question closed", 10, |s| !s.contains("over anyway?"));
    assert!(s.lines().next().unwrap().contains("read-only"), "{s}");
    assert_eq!(std::fs::read(&lock).unwrap(), held, "the lock is untouched");
    assert_eq!(a.exit_code(), None, "the first console runs on");
    a.end_by(rustix::process::Signal::HUP);
    b.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    b.wait_text("open another session", 10);
    b.send("\r");
    let s = b.wait("the session open to write", 10, |s| {
        let title = s.lines().next().unwrap_or("");
        title.contains("cube") && !title.contains("read-only") && s.contains("1 of 4 done")
    });
    assert!(!s.contains("over anyway?"), "{s}");
    assert_ne!(
        std::fs::read(&lock).unwrap(),
        held,
        "the lock is this console's"
    );
    // It writes: image 2 captured and accepted.
    b.capture_current(2);
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = b.wait_text("image 2 accepted", 20);
    assert!(!s.contains("NOT saved"), "{s}");
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
}

#[test]
fn the_read_only_view_offers_only_the_keys_that_work_there() {
    let (mut a, mut b, _) = looking(1);
    // The writing console offers accept and redo on its hint rows ...
    let s = a.screen();
    assert!(hint_rows(&s).contains("a accept"), "{s}");
    // ... the one only looking does not, on the image shown (image 1, done,
    // opened on) or the next.
    b.wait_text("image 1a + lines", 20);
    for next in [false, true] {
        if next {
            b.press(SURVEY, Action::Survey(SurveyAction::Down));
            b.press(SURVEY, Action::Survey(SurveyAction::Enter));
            b.wait("image 2 under work", 10, |s| s.contains(">  2 "));
        }
        let s = b.wait("the hints drawn", 10, |s| hint_rows(s).contains("o open"));
        let h = hint_rows(&s);
        for refused in ["a accept", "R redo", "c camera", "p place"] {
            assert!(!h.contains(refused), "{refused:?} offered:\n{s}");
        }
    }
    // The key still refuses, with what it was.
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    b.wait_words("accepting refused", 10);
    // The other screens offer looking, not changing: the lines (Edit),
    // the outputs (Pipeline), the reports (Session).
    let screens: [(ScreenId, &str, &[&str]); 3] = [
        (
            ScreenId::Edit,
            "nearest",
            &["connect", "extend", "delete", "undo", "redo"],
        ),
        (ScreenId::Pipeline, "view", &["save"]),
        (ScreenId::Session, "check", &["export"]),
    ];
    for (screen, offered, refused) in screens {
        // The writing console offers them there ...
        a.press(Scope::Global, Action::Global(GlobalAction::GoTo(screen)));
        let s = a.wait(&format!("the {screen:?} hints"), 10, |s| {
            hint_rows(s).contains(offered)
        });
        for r in refused {
            assert!(hint_rows(&s).contains(r), "{screen:?}: {r:?} offered:\n{s}");
        }
        // ... the one only looking does not.
        b.press(Scope::Global, Action::Global(GlobalAction::GoTo(screen)));
        let s = b.wait(&format!("the {screen:?} hints"), 10, |s| {
            hint_rows(s).contains(offered)
        });
        for r in refused {
            assert!(
                !hint_rows(&s).contains(r),
                "{screen:?}: {r:?} offered:\n{s}"
            );
        }
    }
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
}

/// Nothing can be captured in a read-only view: it opens on the newest
/// done image, its row chosen, its frame with its lines shown and its line
/// count on the Pipeline screen, without a key. It opened on the next image
/// to capture (3), beside image 2's frame without its lines.
#[test]
fn opens_on_the_newest_done_image() {
    let (mut a, mut b, _) = looking(2);
    let s = b.wait_text("image 2a + lines", 20);
    assert!(s.contains("2 of 4 done"), "{s}");
    // Image 2's checklist row is the one under work, not image 3's.
    assert!(s.contains(">  2 ") && !s.contains(">  3 "), "{s}");
    let recorded = Session::inspect(&a.session())
        .expect("the session reads")
        .manifest()
        .image(2)
        .and_then(|r| r.outputs.as_ref())
        .map(|o| o.counts.lines as usize)
        .expect("image 2's outputs are recorded");
    b.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
    );
    b.wait(&format!("image 2's {recorded} lines"), 10, |s| {
        s.contains("image 2") && line_count(s) == Some(recorded)
    });
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
}

/// With no image done, the read-only view opens on the newest image with
/// frames, its row chosen and its frame shown. It opened on the survey's
/// next image (1, whose outputs are missing) instead of on image 2, the one
/// captured last.
#[test]
fn with_no_image_done_opens_on_the_newest_captured_image() {
    let mut a = Console::start(80, 24, &[]);
    a.create_session("cube");
    a.capture_current(1);
    // On to image 2 without accepting image 1, and image 2 captured.
    a.press(SURVEY, Action::Survey(SurveyAction::Down));
    a.press(SURVEY, Action::Survey(SurveyAction::Enter));
    a.capture_current(2);
    let (mut b, _) = look_at(&a);
    let s = b.wait_text("image 2a", 20);
    assert!(s.contains("0 of 4 done"), "{s}");
    assert!(s.contains(">  2 ") && !s.contains(">  1 "), "{s}");
    // Its stages run here, and what they found is said without the keys
    // that only work to write (it said "a accepts, R captures again").
    b.wait_text("image 2a + lines", 20);
    b.press(Scope::Global, Action::Global(GlobalAction::ToggleLog));
    let s = b.wait("the log says image 2's lines", 10, |s| {
        let log = flat(&s.replace('│', " "));
        let counted = log
            .split("image 2: ")
            .skip(1)
            .any(|m| m.starts_with(|c: char| c.is_ascii_digit()));
        counted || log.contains("a accepts")
    });
    assert!(!flat(&s.replace('│', " ")).contains("a accepts"), "{s}");
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
}
