//! Switching sessions keeps the open one until the other is open: a
//! console that holds session `cube` and asks for a session another
//! console still runs on, then answers `n` to the held-session question,
//! still holds `cube` — its lock names it, a third party finds it held,
//! and it saves the next image there. Once the other console has quit,
//! the switch goes through, and only then is `cube` released. Two real
//! consoles on real ptys at 80 × 24.

use vss::session::lock::read_holder;
use vss::session::{Session, SessionError};
use vss::tui::keymap::{Action, ModalAction, Scope, SurveyAction};

use super::tui_harness::{Console, SURVEY, flat};

const DOWN: &str = "\x1b[B";

/// From the session list, open `two` (listed below `cube`, the open one)
/// and say yes to leaving `cube` for it.
fn switch_to_two(b: &mut Console) {
    b.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    b.wait_words("choose a session", 10);
    b.send(DOWN);
    b.press(SURVEY, Action::Survey(SurveyAction::Enter));
    b.wait_words("Leave session cube and open session two?", 10);
    b.yes();
}

#[test]
fn declining_a_held_session_keeps_the_open_one_held_and_saving() {
    // The first console holds session two and runs on.
    let mut a = Console::start(80, 24, &[]);
    a.create_session("two");
    let two_lock = a.sessions().join("two/two.lock");
    let two_held = std::fs::read(&two_lock).expect("the first console holds two");
    // The second makes its own session cube and accepts image 1 there.
    let mut b = a.another(80, 24);
    b.wait_text("in use by", 10);
    b.create_session("cube");
    let b_pid = b.child.process_id().expect("the second console's pid");
    // In the first console's folder: the second's own is empty.
    let cube = a.session();
    let lock = cube.join("cube.lock");
    b.capture_current(1);
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    b.wait_text("image 1 accepted", 20);
    // It switches to two (the list: cube, the newer, first and chosen)
    // and declines the question about the console that holds it.
    switch_to_two(&mut b);
    b.wait_text("over anyway?", 10);
    b.press(Scope::Confirm, Action::Modal(ModalAction::No));
    let s = b.wait("the question closed", 10, |s| !s.contains("over anyway?"));
    assert!(s.lines().next().unwrap().contains("cube"), "{s}");
    // cube's lock still names the second console ...
    let holder = read_holder(&lock).map(|h| h.pid);
    assert_eq!(holder, Some(b_pid), "cube's lock after declining two");
    // ... so a third party finds it held ...
    match Session::open(&cube) {
        Err(SessionError::Locked { stale: false, .. }) => {}
        Err(e) => panic!("cube: {e}"),
        Ok(_) => panic!("a third party could take cube, which the console shows open"),
    }
    // ... and the console saves image 2 into it.
    b.capture_current(2);
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = b.wait_text("image 2 accepted", 20);
    assert!(!s.contains("NOT saved"), "{s}");
    let m = Session::inspect(&cube).unwrap();
    let r = m.manifest().image(2).expect("image 2 recorded in cube");
    assert!(r.outputs.is_some(), "image 2 accepted: {r:?}");
    // The first console was left alone: two's lock is the same bytes.
    assert_eq!(std::fs::read(&two_lock).unwrap(), two_held);
    assert_eq!(a.exit_code(), None, "the first console runs on");
    // Once it has quit, the switch goes through: two is the second's,
    // and only then is cube released.
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
    switch_to_two(&mut b);
    b.wait_text("session two open", 10);
    assert_eq!(read_holder(&two_lock).map(|h| h.pid), Some(b_pid));
    assert!(!lock.exists(), "cube's lock released once two is open");
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
    // The store said, when two was held, that cube stayed open here.
    let log = std::fs::read_to_string(cube.join("cube.log")).unwrap();
    assert!(
        flat(&log).contains("session cube is still open here, its lock kept"),
        "{log}"
    );
}
