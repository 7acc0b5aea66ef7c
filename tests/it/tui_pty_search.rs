//! `/` searches what is in front (issue 33, annoyance 10), through the real
//! binary in a pty at 80 × 24: the help window, the message log and the
//! Session screen's file list. A text typed after `/` and Enter brings the
//! first match into view, `n` the next, `N` the previous, `Esc` ends the
//! search; a text that matches nothing says so and keeps the field open.

use vss::tui::keymap::{Action, GlobalAction, Scope, ScreenId, SearchAction};

use super::tui_harness::Console;

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

fn search(c: &mut Console, a: SearchAction) {
    c.press(Scope::Search, Action::Search(a));
}

/// `/`, then `text` and Enter.
fn find(c: &mut Console, text: &str) {
    c.send("/");
    c.wait_text("for:", 5);
    c.send(text);
    c.send("\r");
}

#[test]
fn slash_searches_the_help_the_log_and_the_file_list() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(3);
    // The help: the checklist's marks are pages down.
    c.press(Scope::Global, Action::Global(GlobalAction::Help));
    let s = c.wait_text("help: rows 1", 5);
    assert!(!s.contains("an output file does not read"), "{s}");
    find(&mut c, "OUTPUT FILE");
    let s = wait_words(&c, "match 1 of 1", 5);
    assert!(s.contains("an output file does not read"), "{s}");
    // A text in no row: said, the field kept to change it.
    search(&mut c, SearchAction::Clear);
    c.wait("the search ended", 5, |s| !s.contains("match 1 of"));
    assert!(
        c.screen().contains("help: rows"),
        "Esc ended the search, not the help"
    );
    find(&mut c, "zebra");
    wait_words(&c, "no match for \"zebra\" in the help", 5);
    c.send("\x1b");
    c.wait("the field closed", 5, |s| !s.contains("for:"));
    c.send("\x1b");
    c.wait("the help closed", 5, |s| !s.contains("help: rows"));
    // The log, newest match first: n goes back to older ones.
    find(&mut c, "image 1");
    let s = wait_words(&c, "match 1 of", 5);
    let count: usize = flat(&s)
        .split("match 1 of ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(count >= 2, "several messages name image 1:\n{s}");
    assert!(s.contains("log: "), "the log pane expanded:\n{s}");
    search(&mut c, SearchAction::Next);
    wait_words(&c, &format!("match 2 of {count}"), 5);
    search(&mut c, SearchAction::Prev);
    search(&mut c, SearchAction::Prev);
    wait_words(&c, &format!("match {count} of {count}"), 5);
    search(&mut c, SearchAction::Clear);
    let shown = format!(" of {count}");
    c.wait("the search ended", 5, |s| !s.contains(&shown));
    c.press(Scope::Global, Action::Global(GlobalAction::ToggleLog));
    // The file list: the session's log file is listed last, below the
    // rows that fit.
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Session)),
    );
    let s = c.wait_text("files (", 10);
    assert!(s.contains("more"), "more files than rows:\n{s}");
    assert!(!s.contains("cube.log"), "{s}");
    find(&mut c, "cube.log");
    let s = wait_words(&c, "match 1 of 1", 5);
    assert!(s.contains("cube.log"), "{s}");
    search(&mut c, SearchAction::Clear);
    c.wait("the search ended", 5, |s| !s.contains("match 1 of 1"));
    c.send("q");
    c.wait_exit(15);
}

/// A text is found in an entry's whole text, not row by row: the help's
/// last paragraph (pages below the window) wraps at 80 columns between
/// "row or a" and "line", and `/` finds "row or a line" and scrolls it
/// into view.
#[test]
fn slash_finds_a_text_wrapped_over_two_rows_below_the_window() {
    let mut c = Console::start(80, 24, &[]);
    c.press(Scope::Global, Action::Global(GlobalAction::Help));
    let s = c.wait_text("help: rows 1", 5);
    assert!(!s.contains("Shift+drag"), "the paragraph is below:\n{s}");
    find(&mut c, "row or a line");
    let s = wait_words(&c, "match 1 of 1", 5);
    assert!(s.contains("Shift+drag selects text"), "{s}");
    // The text found is split over two rows: no row of the window holds
    // it whole (the hint row below it says what is searched for).
    let window: Vec<&str> = s.lines().filter(|l| l.starts_with('│')).collect();
    assert!(
        window.iter().all(|l| !l.contains("row or a line")),
        "the text is on one row, the test tests nothing:\n{s}"
    );
    assert!(flat(&window.join("\n")).contains("row or a line"), "{s}");
    search(&mut c, SearchAction::Clear);
    c.wait("the search ended", 5, |s| !s.contains("match 1 of 1"));
    c.send("\x1b");
    c.wait("the help closed", 5, |s| !s.contains("help: rows"));
    c.send("q");
    c.wait_exit(15);
}
