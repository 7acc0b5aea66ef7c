//! What the console answers to what the operator does, through messages
//! alone: a letter a session name cannot hold refused as it is typed; a
//! key that does nothing where it is pressed says so; a warning at
//! start-up stays on the message line; the same message again and again
//! is one entry with its count; a hidden log still shows answers and failures.

use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyEventState, KeyModifiers, ModifierKeyCode,
};
use vss::tui::app::{App, Modal, Overlay};
use vss::tui::event::{Msg, StoreEvent};
use vss::tui::keymap::SurveyAction;

use super::tui_harness::flat;
use super::tui_screens::{code, colour, draw, grabber_connected, key, profile, survey};

fn field_text(app: &App) -> (String, Option<String>) {
    match &app.chrome.modal {
        Some(Modal::Prompt(p)) => (p.text.clone(), p.error.clone()),
        other => panic!("the field is open: {other:?}"),
    }
}

/// `é` typed into the new session's name is refused at once, with the
/// words Enter says, and the field keeps what it had; so are `/` and `.`;
/// the allowed letters go on being typed.
#[test]
fn a_letter_a_session_name_cannot_hold_is_refused_as_it_is_typed() {
    let mut app = App::new(&profile(), colour());
    survey(&mut app, SurveyAction::NewSession);
    for c in "cub".chars() {
        key(&mut app, c);
    }
    key(&mut app, 'é');
    let (text, error) = field_text(&app);
    assert_eq!(text, "cub", "é is not typed");
    let error = error.expect("the field says why");
    assert!(
        error.contains("'é'") && error.contains("use only the letters a-z and A-Z"),
        "{error}"
    );
    let (s, _) = draw(&app, 80, 24);
    assert!(
        flat(&s).contains("contains 'é'"),
        "the field shows it:\n{s}"
    );
    // A pasted text comes as its characters: each bad one is left out.
    for c in "e/2.x".chars() {
        key(&mut app, c);
    }
    assert_eq!(field_text(&app).0, "cube2x");
    let line = message_line(&app);
    assert!(
        line.contains("contains '.' at position 6"),
        "still said: {line}"
    );
    code(&mut app, KeyCode::Home);
    key(&mut app, ' ');
    assert_eq!(field_text(&app).0, "cube2x", "a space at the start too");
    assert!(field_text(&app).1.is_some_and(|e| e.contains("' '")));
}

/// The message line's text (its rows, joined).
fn message_line(app: &App) -> String {
    let (s, _) = draw(app, 80, 24);
    let rows: Vec<&str> = s.lines().collect();
    flat(&rows[rows.len() - 5..].join(" "))
}

fn with(code: KeyCode, modifiers: KeyModifiers, kind: KeyEventKind) -> Msg {
    Msg::Key(KeyEvent {
        code,
        modifiers,
        kind,
        state: KeyEventState::NONE,
    })
}

/// F5 on a screen where it is bound to nothing says so by its name, and
/// where the keys are; in a question, the question's keys. F1 opens the
/// help as `?` does. What is no key press of its own — a release, a
/// modifier alone, a resize — says nothing, and in a text field a key
/// types or does nothing, silently.
#[test]
fn a_key_bound_to_nothing_says_so() {
    let mut app = App::new(&profile(), colour());
    app.start();
    code(&mut app, KeyCode::F(5));
    let line = message_line(&app);
    assert!(
        line.contains("F5 does nothing here — ? lists this screen's keys"),
        "{line}"
    );
    app.update(with(
        KeyCode::Delete,
        KeyModifiers::SHIFT,
        KeyEventKind::Press,
    ));
    assert!(message_line(&app).contains("S-Del does nothing here"));
    let n = app.chrome.log.len();
    app.update(with(
        KeyCode::F(6),
        KeyModifiers::NONE,
        KeyEventKind::Release,
    ));
    app.update(with(
        KeyCode::Modifier(ModifierKeyCode::LeftShift),
        KeyModifiers::SHIFT,
        KeyEventKind::Press,
    ));
    app.update(with(
        KeyCode::CapsLock,
        KeyModifiers::NONE,
        KeyEventKind::Press,
    ));
    app.update(Msg::Resize(100, 30));
    app.update(Msg::Resize(80, 24));
    assert_eq!(app.chrome.log.len(), n, "nothing said for these");
    code(&mut app, KeyCode::F(1));
    assert_eq!(app.chrome.overlay, Some(Overlay::Help { scroll: 0 }));
    code(&mut app, KeyCode::Esc);
    // A question: its own keys are offered.
    survey(&mut app, SurveyAction::NewSession);
    code(&mut app, KeyCode::F(5));
    assert_eq!(app.chrome.log.len(), n, "a text field says nothing");
    for c in "q1".chars() {
        key(&mut app, c);
    }
    code(&mut app, KeyCode::Enter);
    code(&mut app, KeyCode::F(5));
    let line = message_line(&app);
    assert!(
        line.contains("F5 does nothing here — y yes, n no"),
        "{line}"
    );
}

/// A camera description the profile names that cannot be used is
/// warned of at start-up; the grabber's "connected" note that comes just
/// after goes to the log and does not push the warning off the line
/// (before, the line said "grabber … connected" at once).
#[test]
fn a_start_up_warning_is_not_pushed_off_the_line_by_the_grabber_s_note() {
    let mut app = App::new(&profile(), colour());
    app.tracker.params.lens.enabled = true;
    app.start();
    app.update(Msg::Store(StoreEvent::Cameras(vec![Err(
        "/srv/vss/cam1.cdf: line 3: k1 is not a number".into(),
    )])));
    app.update(Msg::Store(StoreEvent::Sessions(Vec::new())));
    grabber_connected(&mut app);
    let line = message_line(&app);
    assert!(
        line.contains("lens correction OFF for camera 1") && line.contains("k1 is not a number"),
        "{line}"
    );
    assert!(line.contains("(+1 newer in the log)"), "{line}");
    // A key's answer takes the line as always.
    code(&mut app, KeyCode::F(5));
    assert!(message_line(&app).contains("F5 does nothing here"));
}

/// The console started, the store having answered with no cameras'
/// problems and no sessions: nothing to warn of.
fn started_quietly() -> App {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Cameras(Vec::new())));
    app.update(Msg::Store(StoreEvent::Sessions(Vec::new())));
    app
}

/// A start-up with nothing to warn of holds nothing: the grabber's note
/// shows at once.
#[test]
fn a_quiet_start_up_lets_the_grabber_s_note_show() {
    let mut app = started_quietly();
    grabber_connected(&mut app);
    let line = message_line(&app);
    assert!(line.contains("VSS-SIM"), "{line}");
    assert!(!line.contains("newer in the log"), "{line}");
}

/// F5 pressed again and again says its answer once, with a count, on
/// the message line and in the log; each press is still the answer to
/// its key, held against a background note; the log file gets the line
/// once, and the count once another message ends the run.
#[test]
fn the_same_answer_again_is_one_entry_with_its_count() {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.take_log_lines();
    let n = app.chrome.log.len();
    for _ in 0..500 {
        code(&mut app, KeyCode::F(5));
    }
    assert_eq!(app.chrome.log.len(), n + 1, "one entry");
    let line = message_line(&app);
    assert!(line.contains("? lists this screen's keys (×500)"), "{line}");
    grabber_connected(&mut app);
    code(&mut app, KeyCode::F(5));
    grabber_connected(&mut app);
    let line = message_line(&app);
    assert!(
        line.contains("F5 does nothing here") && line.contains("(+1 newer in the log)"),
        "the answer held, not the note: {line}"
    );
    let file = |app: &mut App| match app.take_log_lines() {
        Some(vss::tui::event::Cmd::Store(vss::tui::event::StoreCmd::Log(l))) => l,
        other => panic!("{other:?}"),
    };
    let lines = file(&mut app);
    let f5 = lines
        .iter()
        .filter(|l| l.contains("F5 does nothing"))
        .count();
    assert_eq!(f5, 2, "{lines:#?}");
    assert!(
        lines
            .iter()
            .any(|l| l.ends_with("last message repeated 499 times")),
        "{lines:#?}"
    );
}

/// The log hidden (`m` twice: one line, expanded, hidden) hides notes,
/// not what the operator must see: the answer to a key is shown while it
/// is held, and a warning or an error that comes since (a device lost, a
/// save that failed) takes the line. Before, the hidden log drew no
/// message row at all: F5 seemed to do nothing and a failure went unseen.
#[test]
fn a_hidden_log_still_shows_answers_and_failures_but_not_notes() {
    let mut app = started_quietly();
    key(&mut app, 'm');
    key(&mut app, 'm');
    assert!(!message_line(&app).contains("does nothing"));
    code(&mut app, KeyCode::F(5));
    let line = message_line(&app);
    assert!(line.contains("F5 does nothing here"), "{line}");
    // Once the answer is no longer held its row goes (a frame is drawn),
    // and a note does not bring it back.
    let later = std::time::Instant::now() + std::time::Duration::from_secs(60);
    assert!(app.release_held(later), "the row goes: the screen changes");
    assert!(!message_line(&app).contains("F5"));
    grabber_connected(&mut app);
    let line = message_line(&app);
    assert!(!line.contains("VSS-SIM") && !line.contains("F5"), "{line}");
    app.update(Msg::Device(vss::tui::event::DeviceEvent::Lost {
        error: "/dev/ttyUSB0: the device vanished".into(),
        busy: false,
    }));
    let line = message_line(&app);
    assert!(line.contains("the device vanished"), "{line}");
}
