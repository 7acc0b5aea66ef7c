//! One survey folder, several consoles: the session list a console shows
//! is read again every 2 s while it is on screen, so a session another
//! console (or a `vss grab`) opens, captures into or closes shows as it is
//! without a key pressed; the list is said to the screen only when it
//! changed, the highlight stays on its session, and nothing is written.

use std::path::Path;
use std::sync::mpsc::channel;
use std::time::{Duration, Instant, SystemTime};

use vss::profile::Profile;
use vss::session::Session;
use vss::session::lock::LockInfo;
use vss::tui::app::{App, RELIST};
use vss::tui::event::{Cmd, Msg, StoreCmd, StoreEvent};
use vss::tui::mode::Look;
use vss::tui::widgets::preview::PreviewMode;
use vss::tui::workers::store::Store;

use super::tui_harness::{Console, PROFILE, flat};

const DOWN: &str = "\x1b[B";

/// The left column of the screen, where the session list is.
fn panel(screen: &str) -> Vec<String> {
    screen
        .lines()
        .map(|l| l.chars().take(34).collect())
        .collect()
}

/// The row of session `name` in the list, and those its text wraps to.
fn row_of(screen: &str, name: &str) -> String {
    let lines = panel(screen);
    let Some(i) = lines.iter().position(|l| l.contains(&format!(" {name} "))) else {
        return String::new();
    };
    let more = lines[i + 1..].iter().take_while(|l| {
        l.chars().skip(1).take(3).all(|c| c == ' ') && !l.trim_matches(['│', ' ']).is_empty()
    });
    std::iter::once(&lines[i])
        .chain(more)
        .cloned()
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn the_list_shows_what_another_console_does_without_a_key() {
    // Two sessions, disc the newer: listed first, and highlighted.
    let mut a = Console::start(80, 24, &[]);
    a.create_session("cube");
    let mut a = a.restart(80, 24, &[]);
    a.create_session("disc");
    let mut a = a.restart(80, 24, &[]);
    a.wait_text("choose a session", 10);
    a.wait_text(" cube ", 10);
    // The operator highlights cube and leaves the keyboard.
    a.send(DOWN);
    let mut b = a.another(80, 24);
    b.wait_text(" cube ", 10);
    b.send(DOWN);
    b.send("\r");
    b.wait_text("session cube open", 10);
    // Within a few seconds, no key pressed: cube is in use.
    let s = a.wait("cube in use", 6, |s| {
        flat(&row_of(s, "cube")).contains("in use by")
    });
    assert!(!flat(&row_of(&s, "disc")).contains("in use by"), "{s}");
    // The other console captures and accepts image 1: the list says
    // cube's progress, and cube, now the newest, moves to the top.
    b.capture_current(1);
    b.press(
        super::tui_harness::SURVEY,
        vss::tui::keymap::Action::Survey(vss::tui::keymap::SurveyAction::Accept),
    );
    b.wait_text("image 1 accepted", 20);
    a.wait("cube 1 done", 6, |s| row_of(s, "cube").contains(" 1/"));
    // It quits: cube is free again.
    b.send("q");
    b.wait_exit(10);
    let s = a.wait("cube free", 6, |s| {
        let r = row_of(s, "cube");
        !r.is_empty() && !flat(&r).contains("in use by")
    });
    let rows = panel(&s);
    let at = |n: &str| rows.iter().position(|l| l.contains(&format!(" {n} ")));
    let (cube, disc) = (at("cube").unwrap(), at("disc").unwrap());
    assert!(cube < disc, "cube, the newest, first:\n{s}");
    // The highlight stayed on cube through the new order: Enter opens it.
    a.send("\r");
    a.wait_text("┌ session cube ─", 10);
    a.send("q");
    a.wait_exit(10);
}

/// The store of a console on a survey folder in `dir`, with sessions
/// `cube` and `disc`.
fn store_in(dir: &Path) -> (Store, std::sync::mpsc::Receiver<Msg>, Profile) {
    let text = PROFILE.replace(
        "dir = \"sessions\"",
        &format!("dir = {:?}", dir.join("sessions")),
    );
    std::fs::write(dir.join("cell.toml"), text).unwrap();
    let profile = Profile::load(dir.join("cell.toml").to_str().unwrap()).unwrap();
    for name in ["cube", "disc"] {
        drop(Session::create(&dir.join("sessions"), name, &profile).unwrap());
    }
    let (tx, rx) = channel();
    (Store::new(profile.clone(), tx), rx, profile)
}

/// Each file of the folder (recursively) with its length and time.
fn files(dir: &Path) -> Vec<(std::path::PathBuf, u64, SystemTime)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let m = e.metadata().unwrap();
        if m.is_dir() {
            out.extend(files(&e.path()));
        }
        out.push((e.path(), m.len(), m.modified().unwrap()));
    }
    out.sort();
    out
}

fn lists(rx: &std::sync::mpsc::Receiver<Msg>) -> Vec<Vec<String>> {
    rx.try_iter()
        .filter_map(|m| match m {
            Msg::Store(StoreEvent::Sessions(l)) => Some(
                l.into_iter()
                    .map(|e| format!("{} {}", e.name, e.summary))
                    .collect(),
            ),
            _ => None,
        })
        .collect()
}

#[test]
fn the_list_read_again_is_said_only_when_it_changed_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut store, rx, _) = store_in(tmp.path());
    let before = files(tmp.path());
    store.handle(StoreCmd::Relist);
    assert_eq!(lists(&rx).len(), 1, "the first is said");
    store.handle(StoreCmd::Relist);
    store.handle(StoreCmd::Relist);
    assert!(lists(&rx).is_empty(), "the same list again is not said");
    // Asked by the operator (o, a damaged session), it is said again.
    store.handle(StoreCmd::List);
    assert_eq!(lists(&rx).len(), 1);
    assert_eq!(files(tmp.path()), before, "reading the list wrote nothing");
    // Another holder takes cube's lock: said at the next reading.
    let info = LockInfo {
        user: "alice".into(),
        ..LockInfo::current()
    };
    let lock = tmp.path().join("sessions/cube/cube.lock");
    std::fs::write(&lock, toml::to_string(&info).unwrap()).unwrap();
    store.handle(StoreCmd::Relist);
    let said = lists(&rx);
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0]
            .iter()
            .any(|e| e.starts_with("cube ") && e.ends_with("(in use by alice)")),
        "{said:?}"
    );
    // Released: said again, free.
    std::fs::remove_file(&lock).unwrap();
    store.handle(StoreCmd::Relist);
    let said = lists(&rx);
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(said[0].iter().all(|e| !e.contains("in use")), "{said:?}");
}

#[test]
fn the_list_is_asked_for_every_two_seconds_while_shown() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut store, rx, profile) = store_in(tmp.path());
    let look = Look {
        mode: PreviewMode::Ascii,
        colour: false,
        c256: false,
    };
    let mut app = App::new(&profile, look);
    app.update(Msg::Resize(80, 24));
    let relist = |c: &[Cmd]| matches!(c, [Cmd::Store(StoreCmd::Relist)]);
    assert_eq!(app.start().len(), 1);
    let t0 = Instant::now();
    assert!(app.due(t0).is_empty(), "just listed");
    assert!(relist(&app.due(t0 + RELIST)), "shown: asked again");
    assert!(app.due(t0 + RELIST + Duration::from_millis(500)).is_empty());
    assert!(relist(&app.due(t0 + RELIST * 2)));
    // A session open (its checklist shown, not the list): not asked.
    store.handle(StoreCmd::Open(tmp.path().join("sessions/cube")));
    for m in rx.try_iter() {
        app.update(m);
    }
    assert!(app.session.view.is_some());
    assert!(app.due(t0 + RELIST * 10).is_empty());
}
