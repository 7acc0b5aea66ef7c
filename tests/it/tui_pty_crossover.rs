//! Two consoles that each hold a session and each take over the other's
//! at the same moment (a crossed take-over): console A holds `cube` and
//! says `y` to taking over `two`, which console B holds, while B says `y`
//! to taking over `cube`. Each asks the other through the session folder
//! and, while it waits for the lock it asked for, answers the request for
//! the session it holds, so both switches go through: A ends with `two`,
//! B with `cube`, nobody is signalled, nobody exits, every image saved
//! before is still in its session. Two real consoles on real ptys at
//! 80 × 24.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use vss::session::Session;
use vss::session::lock::{leave_path, read_holder};
use vss::tui::keymap::{Action, SurveyAction};

use super::tui_harness::{Console, SURVEY};

const UP: &str = "\x1b[A";
const DOWN: &str = "\x1b[B";

/// From the open session `from`, chooses `to` in the session list (one
/// row away, by `step`), says yes to leaving `from`, and waits for the
/// question about the console that holds `to`.
fn ask_for(c: &mut Console, from: &str, to: &str, step: &str) {
    c.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    c.wait_words("choose a session", 10);
    // Both rows read (a step before then moves nothing).
    c.wait(&format!("{to} listed"), 10, |s| {
        s.contains(&format!(" {to} ")) && s.contains(&format!(" {from} ")) && s.contains("/4 done")
    });
    c.send(step);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_words(&format!("Leave session {from} and open session {to}?"), 10);
    c.yes();
    c.wait_text("over anyway?", 10);
}

/// Waits for `c` to show session `name` open (its name in the title row
/// and on its checklist); fails at once, saying so, when the console has
/// ended instead (signalled).
fn wait_open(c: &mut Console, name: &str) {
    let panel = format!("┌ session {name} ");
    let end = Instant::now() + Duration::from_secs(20);
    loop {
        let s = c.screen();
        if s.lines().next().is_some_and(|l| l.contains(name)) && s.contains(&panel) {
            return;
        }
        if let Some(code) = c.exit_code() {
            panic!(
                "the console ended (exit code {code}) before it showed session {name}; screen:\n{s}"
            );
        }
        assert!(
            Instant::now() < end,
            "timed out waiting for session {name}; screen:\n{s}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Image 1 of the session at `dir` is recorded with its outputs.
fn image_1_kept(dir: &Path) {
    let s = Session::inspect(dir).unwrap();
    let r = s
        .manifest()
        .image(1)
        .unwrap_or_else(|| panic!("{}: image 1 recorded", dir.display()));
    assert!(
        r.outputs.is_some(),
        "{}: image 1 accepted: {r:?}",
        dir.display()
    );
}

/// Console A, which surveyed image 1 of `cube` and holds it, and console
/// B in the same folder, which sees it held; cube's folder.
fn cube_held() -> (Console, Console, PathBuf) {
    let mut a = Console::start(80, 24, &[]);
    a.survey(1);
    let cube = a.session();
    let b = a.another(80, 24);
    b.wait_text("in use by", 10);
    (a, b, cube)
}

/// Sends `sig` (`-STOP`, `-CONT`) to console `c`.
fn signal(c: &Console, sig: &str) {
    let pid = c.child.process_id().expect("its pid").to_string();
    let ok = std::process::Command::new("kill")
        .args([sig, &pid])
        .status();
    assert!(ok.is_ok_and(|st| st.success()), "kill {sig} {pid}");
}

#[test]
fn two_consoles_taking_over_each_others_session_at_once_both_get_it() {
    // A surveys image 1 of cube and holds it.
    let (mut a, mut b, cube) = cube_held();
    let two = a.sessions().join("two");
    // B, in the same folder, makes session two and accepts image 1 there.
    b.create_session("two");
    b.capture_current(1);
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    b.wait_text("image 1 accepted", 20);
    let a_pid = a.child.process_id().expect("A's pid");
    let b_pid = b.child.process_id().expect("B's pid");
    assert_eq!(
        read_holder(&cube.join("cube.lock")).map(|h| h.pid),
        Some(a_pid)
    );
    assert_eq!(
        read_holder(&two.join("two.lock")).map(|h| h.pid),
        Some(b_pid)
    );
    // The list has two (saved last) above cube: each chooses the other's.
    ask_for(&mut a, "cube", "two", UP);
    ask_for(&mut b, "two", "cube", DOWN);
    // Both say yes within the same second.
    let t0 = Instant::now();
    a.yes();
    b.yes();
    wait_open(&mut a, "two");
    wait_open(&mut b, "cube");
    // Past the wait after which an unanswered holder is signalled: both
    // still run, each on the other's session.
    while t0.elapsed() < Duration::from_secs(10) {
        assert_eq!(a.exit_code(), None, "A ended; screen:\n{}", a.screen());
        assert_eq!(b.exit_code(), None, "B ended; screen:\n{}", b.screen());
        std::thread::sleep(Duration::from_millis(100));
    }
    wait_open(&mut a, "two");
    wait_open(&mut b, "cube");
    // Each lock names its new holder; the requests are gone.
    assert_eq!(
        read_holder(&two.join("two.lock")).map(|h| h.pid),
        Some(a_pid)
    );
    assert_eq!(
        read_holder(&cube.join("cube.lock")).map(|h| h.pid),
        Some(b_pid)
    );
    assert!(!leave_path(&two.join("two.lock")).exists());
    assert!(!leave_path(&cube.join("cube.lock")).exists());
    // Nothing saved before is lost.
    image_1_kept(&cube);
    image_1_kept(&two);
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
}

/// While a take-over waits for a holder that does not answer (stopped
/// here; the taker's SIGTERM comes with a SIGCONT, so it ends), `a` on the
/// image under review is refused, saying why: the store does its commands
/// in order, and before, the accept was done after the switch, writing
/// this session's image 1 into the session taken over.
#[test]
fn writes_wait_while_another_session_is_being_opened() {
    let (mut a, mut b, cube) = cube_held();
    let ldr = cube.join("cube1.ldr");
    // Its bytes and time: B's image 1 may have the same lines (the same
    // camera sees the same scene), its writing would still show.
    let stamp = |p: &Path| {
        let m = std::fs::metadata(p).expect("cube's image 1 lines");
        (std::fs::read(p).unwrap(), m.modified().unwrap())
    };
    let before = stamp(&ldr);
    b.create_session("two");
    b.capture_current(1);
    signal(&a, "-STOP");
    ask_for(&mut b, "two", "cube", DOWN);
    b.yes();
    b.wait_words("asking process", 10);
    b.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = b.wait_words("accepting refused: session cube is being opened", 10);
    assert!(!s.contains("image 1 accepted"), "{s}");
    // Past the wait for an answer, A is signalled, and continued so that
    // it ends on the signal: B opens cube. (The message "asking it to end"
    // may be on screen only for a moment before the opening's own.)
    wait_open(&mut b, "cube");
    assert_eq!(
        a.wait_exit(15),
        143,
        "A ended on the signal (128 + SIGTERM)"
    );
    // Cube's image 1 is A's, untouched; two's image 1 was not accepted.
    std::thread::sleep(Duration::from_millis(500));
    assert!(stamp(&ldr) == before, "cube1.ldr untouched");
    let two = Session::inspect(&a.sessions().join("two")).unwrap();
    assert!(
        two.manifest().image(1).is_none_or(|r| r.outputs.is_none()),
        "two's image 1 not accepted"
    );
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
}

/// A console that quits while its take-over waits for a holder that does
/// not answer gives the take-over up: the request is withdrawn and the
/// holder is never signalled. Before, the quitting console went on
/// waiting (up to 10 s, nothing on screen) and signalled the holder after
/// 5 s: the operator had changed their mind, and the other console ended.
#[test]
fn a_console_that_quits_during_a_take_over_signals_nobody() {
    let (mut a, mut b, cube) = cube_held();
    let a_pid = a.child.process_id().expect("A's pid").to_string();
    // Its devices found first, so that what the take-over says is the
    // newest message (under load the devices' line came after it).
    b.wait_devices(20);
    signal(&a, "-STOP");
    b.wait_text(" cube ", 10);
    b.press(SURVEY, Action::Survey(SurveyAction::Enter));
    b.wait_text("over anyway?", 10);
    b.yes();
    b.wait_words("asking process", 10);
    b.send("q");
    b.wait_exit(15);
    // Past the wait after which the holder would have been signalled.
    std::thread::sleep(Duration::from_secs(6));
    signal(&a, "-CONT");
    std::thread::sleep(Duration::from_secs(2));
    assert_eq!(
        a.exit_code(),
        None,
        "A was signalled; screen:\n{}",
        a.screen()
    );
    assert_eq!(
        read_holder(&cube.join("cube.lock")).map(|h| h.pid.to_string()),
        Some(a_pid.clone())
    );
    assert!(
        !leave_path(&cube.join("cube.lock")).exists(),
        "request withdrawn"
    );
    a.send("q");
    assert_eq!(a.wait_exit(10), 0);
}
