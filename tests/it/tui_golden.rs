//! Whole-screen snapshots of the console at 80 × 24: every screen of
//! [`ScreenId::ALL`], the session picker before a session is open, a
//! question and the help overlay, each drawn through ratatui's
//! `TestBackend` from messages alone (`tui_screens`'s helpers) and written
//! as text — each row's symbols, 80 columns, a newline after each row — to
//! `tests/golden/screens/NAME.txt`. The test compares byte for byte, so a
//! moved border or a shortened label fails where "contains text" would
//! not; an intended change shows up as a diff of those files in review.
//! Regenerate deliberately with
//! `VSS_REGEN=1 cargo test --test it tui_golden::` and read the diff.
//!
//! Nothing volatile reaches a snapshot: the profile and the session folder
//! are fixed absolute names that are never created, and the pipeline's
//! stage times are pinned by `tui_screens::run`. One thing is masked after
//! drawing, because no message can set it: the message log stamps each
//! entry with the wall clock (`HH:MM:SS`, `src/tui/app/log.rs`), so a row
//! that begins with one of the log's own stamps has it replaced by
//! `hh:mm:ss` ([`snapshot`]). Nothing else is touched.

use std::path::PathBuf;

use vss::tui::app::App;
use vss::tui::event::{FileState, ImageState, Msg, SessionEntry, SessionView, StoreEvent};
use vss::tui::keymap::{Action, GlobalAction, Scope, ScreenId, SurveyAction};

use super::tui_screens::{colour, draw, go, press, profile, reviewed, survey, view};
use crate::support::golden;

const W: u16 = 80;
const H: u16 = 24;

/// The app drawn at 80 × 24, as text, with the log's clock masked (see
/// the module doc).
fn snapshot(app: &App) -> String {
    let (text, _) = draw(app, W, H);
    let stamps: Vec<&str> = app.chrome.log.entries().map(|e| e.time.as_str()).collect();
    let mut out = String::new();
    for row in text.lines() {
        match stamps.iter().find(|t| row.starts_with(**t)) {
            Some(t) => {
                out.push_str("hh:mm:ss");
                out.push_str(&row[t.len()..]);
            }
            None => out.push_str(row),
        }
        out.push('\n');
    }
    out
}

/// The snapshot's file name for a screen.
fn name(s: ScreenId) -> &'static str {
    match s {
        ScreenId::Survey => "survey_review",
        ScreenId::Capture => "capture",
        ScreenId::Pipeline => "pipeline",
        ScreenId::Edit => "edit",
        ScreenId::Session => "session",
        ScreenId::Calibrate => "calibrate",
    }
}

fn entry(name: &str, summary: &str, damaged: Option<&str>) -> SessionEntry {
    SessionEntry {
        name: name.into(),
        dir: PathBuf::from(format!("/srv/vss/sessions/{name}")),
        summary: summary.into(),
        damaged: damaged.map(str::to_string),
    }
}

/// The session with image 1 captured, run and edited and image 2 half
/// captured with a damaged file: what the Session screen lists.
fn session_view() -> SessionView {
    let mut v = view();
    v.images = vec![
        ImageState {
            k: 1,
            camera: 1,
            location: 1,
            captured: vec!['a', 'b', 'c'],
            outputs: true,
            edits: 1,
            ..Default::default()
        },
        ImageState {
            k: 2,
            camera: 2,
            location: 1,
            captured: vec!['a'],
            damaged: vec![('b', "cube2b.img: truncated at byte 4096".into())],
            ..Default::default()
        },
    ];
    v.next = Some((2, Some('b')));
    let file = |name: &str, state: &str, ok: bool| FileState {
        name: name.into(),
        state: state.into(),
        ok,
        changed: false,
    };
    v.files = vec![
        file("cube.toml", "manifest", true),
        file("cube.ses", "3 numbers", true),
        file("cube1a.img", "96 × 96", true),
        file("cube1b.img", "96 × 96", true),
        file("cube1c.img", "96 × 96", true),
        file("cube1.lex", "12 lines", true),
        file("cube2a.img", "96 × 96", true),
        file("cube2b.img", "truncated at byte 4096", false),
    ];
    v
}

/// Every snapshot: its name and the app drawn for it.
fn scenes() -> Vec<(&'static str, App)> {
    let mut out = Vec::new();

    // At launch: the profile is read, the survey folder listed.
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Sessions(vec![
        entry("bad", "", Some("bad.toml:11: planned_images: invalid type")),
        entry("cube", "1/4 done", None),
        entry("yard", "4/4 done", None),
    ])));
    out.push(("start", app));

    // Each screen after image 1 was captured under its three lightings and
    // run through the pipeline (Survey is in review).
    for s in ScreenId::ALL {
        let mut app = reviewed();
        if s == ScreenId::Session {
            // As the store worker reports the folder after a save.
            app.update(Msg::Store(StoreEvent::Updated(session_view())));
        }
        go(&mut app, s);
        out.push((name(s), app));
    }

    // A question: Enter in review asks before accepting.
    let mut app = reviewed();
    survey(&mut app, SurveyAction::Enter);
    out.push(("question_accept", app));

    // The help overlay's first page, over the Pipeline screen.
    let mut app = reviewed();
    go(&mut app, ScreenId::Pipeline);
    press(&mut app, Scope::Global, Action::Global(GlobalAction::Help));
    out.push(("help", app));

    out
}

#[test]
fn every_screen_matches_its_snapshot_at_80x24() {
    let dir = golden::dir("screens");
    let mut failed = Vec::new();
    let mut names = Vec::new();
    for (name, app) in scenes() {
        let text = snapshot(&app);
        assert_eq!(text.lines().count(), usize::from(H), "{name}");
        assert!(
            text.lines().all(|r| r.chars().count() == usize::from(W)),
            "{name}: every row is 80 columns"
        );
        let path = dir.join(format!("{name}.txt"));
        if let Err(e) = golden::compare_text(&path, &text, "cargo test --test it tui_golden::") {
            failed.push(format!("{name}: {e}"));
        }
        names.push(format!("{name}.txt"));
    }
    assert!(failed.is_empty(), "{}", failed.join("\n\n"));
    // No snapshot is left behind by a scene that was renamed or removed.
    let mut kept: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    kept.sort();
    names.sort();
    assert_eq!(
        kept, names,
        "tests/golden/screens/ holds exactly the scenes"
    );
}

/// The snapshots are of the app, not of the moment: drawing the same
/// scenes twice gives the same bytes.
#[test]
fn the_scenes_draw_the_same_twice() {
    for ((name, a), (_, b)) in scenes().into_iter().zip(scenes()) {
        assert_eq!(snapshot(&a), snapshot(&b), "{name}");
    }
}

/// A difference is reported row by row, expected above what was drawn.
#[test]
fn a_changed_row_is_shown_in_the_failure() {
    let e = golden::row_diff("one\ntwo\nthree\n", "one\nTWO\nthree\n");
    assert!(
        e.contains("1 row(s)")
            && e.contains("row  2 expected |two|")
            && e.contains("got      |TWO|"),
        "{e}"
    );
}
