//! What the console answers to what the operator does, through messages
//! alone: a letter a session name cannot hold refused as it is typed; a
//! key that does nothing where it is pressed says so.

use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyEventState, KeyModifiers, ModifierKeyCode,
};
use vss::tui::app::{App, Modal, Overlay};
use vss::tui::event::Msg;
use vss::tui::keymap::SurveyAction;

use super::tui_harness::flat;
use super::tui_screens::{code, colour, draw, key, profile, survey};

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
