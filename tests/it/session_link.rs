//! A session folder that is a symbolic link (`sessions/cube ->
//! elsewhere/cube`) is refused for writing, by the command line and by the
//! console alike, with a message naming the link and where it leads;
//! nothing is written through the link (not even the lock); looking at
//! the session through it still works.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::SystemTime;

use vss::tui::keymap::{Action, ModalAction, Scope};

use super::tui_harness::{Console, flat};
use super::tui_pty_readonly::files;

fn vss(args: &[&str], cwd: &Path) -> Output {
    crate::support::run::output_in(cwd, args)
}

/// The folder's entries (length, modification time) and its own
/// modification time, which any file made and removed in it moves.
fn state(dir: &Path) -> (Vec<(PathBuf, u64, SystemTime)>, SystemTime) {
    let m = std::fs::symlink_metadata(dir).unwrap().modified().unwrap();
    (files(dir), m)
}

/// `sessions/cube`, a link to the session `elsewhere/cube` made in `d`;
/// the real folder.
fn linked_session(d: &Path) -> PathBuf {
    let o = vss(&["session", "new", "cube", "--dir", "elsewhere"], d);
    assert!(o.status.success(), "{o:?}");
    let real = d.join("elsewhere/cube").canonicalize().unwrap();
    std::fs::create_dir_all(d.join("sessions")).unwrap();
    std::os::unix::fs::symlink(&real, d.join("sessions/cube")).unwrap();
    real
}

#[test]
fn the_command_line_writes_no_session_through_a_link() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let real = linked_session(d);
    let before = state(&real);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let want = format!(
        "sessions/cube is a symbolic link (to {0}): vss writes no session through a link — \
         open {0} itself",
        real.display()
    );
    for args in [
        &["session", "redo", "sessions/cube", "--image", "1"][..],
        &[
            "session",
            "redo",
            "sessions/cube/",
            "--image",
            "1",
            "--take-over",
        ][..],
    ] {
        let o = vss(args, d);
        let se = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {se}");
        assert!(se.contains(&want), "{args:?}: {se}");
        assert_eq!(state(&real), before, "{args:?} wrote through the link");
    }
    // A new session where a link stands: refused, the folder it leads to
    // left as it was.
    std::fs::create_dir_all(d.join("empty")).unwrap();
    std::os::unix::fs::symlink(d.join("empty"), d.join("sessions/disc")).unwrap();
    let o = vss(&["session", "new", "disc", "--dir", "sessions"], d);
    let se = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{se}");
    assert!(se.contains("sessions/disc is a symbolic link"), "{se}");
    assert_eq!(std::fs::read_dir(d.join("empty")).unwrap().count(), 0);
    // Looking reads through it.
    let o = vss(&["session", "show", "sessions/cube"], d);
    assert!(o.status.success(), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("session cube"));
    let o = vss(&["session", "check", "sessions/cube"], d);
    assert!(o.status.success(), "{o:?}");
    assert_eq!(state(&real), before);
    // The folder itself opens for writing (the refusal is the link's).
    let o = vss(
        &["session", "redo", real.to_str().unwrap(), "--image", "1"],
        d,
    );
    let se = String::from_utf8_lossy(&o.stderr);
    assert!(se.contains("no grey image captured yet"), "{se}");
}

#[test]
fn the_console_lists_a_linked_session_and_opens_it_only_to_look() {
    let mut real = PathBuf::new();
    let mut c = Console::start_with(super::tui_harness::PROFILE, 140, 30, &[], |d| {
        real = linked_session(d);
    });
    let before = state(&real);
    let s = c.wait("the session listed", 15, |s| {
        s.contains("choose a session") && s.contains(" cube ")
    });
    assert!(s.contains(" cube       0/4 done (a link)"), "{s}");
    c.send("\r");
    let s = c.wait_words("Open it read-only", 10);
    let f = flat(&s);
    assert!(f.contains("symbolic link"), "{s}");
    c.press(Scope::Confirm, Action::Modal(ModalAction::No));
    c.wait("the question closed", 5, |s| {
        !s.contains("Open it read-only")
    });
    assert_eq!(state(&real), before, "the console wrote through the link");
    c.send("q");
    c.wait_exit(10);
    assert_eq!(state(&real), before);
}
