//! What the console answers to what the operator does, through messages
//! alone: a letter a session name cannot hold refused as it is typed.

use ratatui::crossterm::event::KeyCode;
use vss::tui::app::{App, Modal};
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
