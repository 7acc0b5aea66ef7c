//! The console's life in a terminal, as an operator over SSH lives it:
//! started from a shell, suspended with Ctrl-Z and brought back with `fg`,
//! stopped by signals, on terminals too small to draw it.

use std::time::Duration;

use super::tui_harness::{Console, SURVEY, flat};

/// The pid of the process whose parent is `parent` (the console a shell
/// runs), from `/proc`.
fn child_of(parent: u32) -> Option<i32> {
    std::fs::read_dir("/proc").ok()?.flatten().find_map(|e| {
        let pid: i32 = e.file_name().to_str()?.parse().ok()?;
        let stat = std::fs::read_to_string(e.path().join("stat")).ok()?;
        let rest = &stat[stat.rfind(')')? + 1..];
        let ppid: u32 = rest.split_whitespace().nth(1)?.parse().ok()?;
        (ppid == parent).then_some(pid)
    })
}

/// Whether the terminal is as a shell wants it: main screen, cursor
/// shown, no mouse reports.
fn shell_terminal(c: &Console) -> bool {
    c.with_screen(|s| {
        !s.alternate_screen()
            && !s.hide_cursor()
            && s.mouse_protocol_mode() == vt100::MouseProtocolMode::None
    })
}

/// Ctrl-Z (and SIGTSTP sent from elsewhere) gives the terminal back to
/// the shell, as it had it, and `fg` brings the console back whole and
/// taking keys one by one. Before, in raw mode Ctrl-Z was a key bound to
/// nothing; SIGTSTP stopped the console with the terminal in the
/// alternate screen, cursor hidden, mouse reports on; after `fg` the
/// screen was not redrawn and keys came only line by line, echoed.
#[test]
fn ctrl_z_gives_the_shell_back_and_fg_brings_the_console_back() {
    let mut c = Console::start_under_shell(80, 24);
    c.create_session("cube");
    let shell = c.child.process_id().expect("the shell's pid");
    let vss = child_of(shell).expect("the console runs under the shell");
    for how in ["Ctrl-Z", "SIGTSTP"] {
        if how == "Ctrl-Z" {
            c.send("\x1a");
        } else {
            assert_eq!(
                rustix::process::kill_process(
                    rustix::process::Pid::from_raw(vss).unwrap(),
                    rustix::process::Signal::TSTP
                ),
                Ok(())
            );
        }
        let s = c.wait(&format!("the shell's job stopped after {how}"), 10, |s| {
            s.contains("Stopped") && shell_terminal(&c)
        });
        assert!(
            flat(&s).contains("session cube stays open here; fg brings the console back"),
            "what the console says as it stops ({how}):\n{s}"
        );
        c.send("fg\r");
        c.wait(&format!("the console drawn again after {how}"), 10, |s| {
            s.contains("session cube")
                && s.lines().last().is_some_and(|l| l.contains("quit"))
                && !s.contains("Stopped")
        });
        assert!(c.with_screen(|s| s.alternate_screen() && s.hide_cursor()));
        // Raw mode again: one key acts at once, without Enter and unechoed.
        c.send("2");
        c.wait_text("lights", 10);
        c.send("1");
        c.wait_text("lightings", 10);
    }
    c.send("q");
    let end = std::time::Instant::now() + Duration::from_secs(15);
    while !ended(vss) {
        assert!(std::time::Instant::now() < end, "q did not end the console");
        std::thread::sleep(Duration::from_millis(50));
    }
    // `fg`'s status is the console's.
    c.send("echo fg said $?\r");
    let s = c.wait_text("fg said 0", 10);
    assert!(shell_terminal(&c), "after q:\n{s}");
    let log = std::fs::read_to_string(c.session().join("cube.log")).unwrap();
    for said in [
        "suspended (Ctrl-Z)",
        "suspended (SIGTSTP)",
        "back from suspension",
    ] {
        assert!(log.contains(said), "{said:?} in the log:\n{log}");
    }
}

/// A console no shell could continue (here, like `ssh host vss`, it leads
/// its own session) is not stopped by Ctrl-Z, which would leave it stopped
/// for good holding its session: it says why and goes on.
#[test]
fn ctrl_z_without_a_shell_says_why_and_goes_on() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.send("\x1a");
    c.wait_words("Ctrl-Z: not suspended", 10);
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(c.exit_code(), None, "the console still runs");
    c.send("2");
    c.wait_text("lights", 10);
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}

/// A console killed outright (SIGKILL, a power cut of the SSH server's
/// side) leaves its lock: the next console's session list does not say
/// the session is "in use" by someone, and it opens without a question.
/// Before, the list said "(in use by root)" of a lock nobody held.
#[test]
fn a_session_left_by_a_killed_console_is_not_said_in_use() {
    let mut a = Console::start(80, 24, &[]);
    a.create_session("cube");
    a.end_by(rustix::process::Signal::KILL);
    assert!(a.session().join("cube.lock").is_file(), "the lock stays");
    let mut b = a.another(80, 24);
    // The list's rows wrap in its own column: the words are read there.
    let s = b.wait("the lock said stale", 10, |s| {
        let list: String = s
            .lines()
            .map(|l| l.split("││").next().unwrap_or("").replace('│', " "))
            .collect::<Vec<_>>()
            .join(" ");
        flat(&list).contains("(stale lock: its console ended)")
    });
    assert!(!s.contains("in use by"), "{s}");
    b.send("\r");
    let s = b.wait_text("lightings", 10);
    assert!(!s.contains("Take it over"), "{s}");
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
}

/// A window a few rows high still says the keys of what is asked on its
/// bottom rows, as the hint row does; why nothing else shows comes after,
/// in the room left. Before, at 20 × 5 the explanation took four rows and
/// the keys of an open field ("Enter accept  Esc cancel") were cut.
#[test]
fn a_tiny_terminal_still_says_the_keys_of_what_is_asked() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.press(
        SURVEY,
        vss::tui::keymap::Action::Survey(vss::tui::keymap::SurveyAction::NewSession),
    );
    c.wait_text("new session name", 5);
    c.resize(5, 20);
    let s = c.wait("the field's keys at 20 x 5", 10, |s| {
        s.contains("terminal too small") && flat(s).contains("Esc cancel")
    });
    assert!(s.contains("new session name"), "{s}");
    c.send("\x1b");
    let s = c.wait("the key that quits at 20 x 5", 10, |s| {
        s.lines().rev().map(str::trim).find(|l| !l.is_empty()) == Some("q quits")
    });
    assert!(s.contains("terminal too small"), "{s}");
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}

/// Whether process `pid` has ended (gone, or a zombie not yet reaped).
fn ended(pid: i32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Err(_) => true,
        Ok(stat) => stat
            .rfind(')')
            .and_then(|i| stat[i + 1..].split_whitespace().next())
            .is_some_and(|st| matches!(st, "Z" | "X")),
    }
}

/// The SSH connection drops while the console is suspended: the shell
/// sends its stopped job SIGHUP and SIGCONT. The console ends as on any
/// hang-up (the log says so, the lock is released) without taking the
/// terminal again.
#[test]
fn a_suspended_console_whose_shell_hangs_up_ends_cleanly() {
    let mut c = Console::start_under_shell(80, 24);
    c.create_session("cube");
    let shell = c.child.process_id().expect("the shell's pid");
    let vss = child_of(shell).expect("the console runs under the shell");
    c.send("\x1a");
    c.wait("the shell's job stopped", 10, |s| {
        s.contains("Stopped") && shell_terminal(&c)
    });
    let rc = rustix::process::kill_process(
        rustix::process::Pid::from_raw(shell as i32).unwrap(),
        rustix::process::Signal::HUP,
    );
    assert_eq!(rc, Ok(()));
    let end = std::time::Instant::now() + Duration::from_secs(15);
    while !ended(vss) {
        assert!(std::time::Instant::now() < end, "the console did not end");
        std::thread::sleep(Duration::from_millis(50));
    }
    let log = std::fs::read_to_string(c.session().join("cube.log")).unwrap();
    // The shell's SIGHUP and the terminal's hang-up (its input ends) come
    // together; the log names whichever the console saw first.
    let ended = log
        .lines()
        .find(|l| l.contains("console ended:"))
        .unwrap_or_default();
    assert!(
        ended.contains("SIGHUP: the terminal hung up")
            || ended.contains("the terminal's input ended (hang-up)"),
        "{log}"
    );
    assert!(!log.contains("back from suspension"), "{log}");
    assert!(
        !c.session().join("cube.lock").exists(),
        "the lock is released"
    );
    assert!(shell_terminal(&c), "not taken again:\n{}", c.screen());
}

/// Ctrl-C gets out of what is open, as an operator's hands expect: of a
/// field as Esc does (the console stays), and a second Ctrl-C at "Quit
/// anyway?" (asked by the first, during a capture) quits. Before, Ctrl-C
/// in a field or a question did nothing at all.
#[test]
fn ctrl_c_leaves_a_field_and_a_second_one_quits_during_a_capture() {
    // A capture long enough to be under way when the keys come.
    let profile = super::tui_harness::PROFILE
        .replace("settle_ms = 5", "settle_ms = 400")
        .replace("width = 128\nheight = 128", "width = 256\nheight = 256");
    let mut c = Console::start_with(&profile, 80, 24, &[], |_| {});
    c.wait_text("choose a session", 10);
    c.press(
        SURVEY,
        vss::tui::keymap::Action::Survey(vss::tui::keymap::SurveyAction::NewSession),
    );
    c.wait_text("new session name", 5);
    c.send("cu\x03");
    c.wait("the field closed", 10, |s| {
        !s.contains("new session name") && s.contains("choose a session")
    });
    assert_eq!(c.exit_code(), None, "the console still runs");
    c.create_session("cube");
    c.wait_text("Image 1: camera", 10);
    c.press(
        SURVEY,
        vss::tui::keymap::Action::Survey(vss::tui::keymap::SurveyAction::Enter),
    );
    c.wait_text("capturing", 10);
    c.send("\x03");
    c.wait_words("Quit anyway?", 10);
    c.send("\x03");
    assert_eq!(c.wait_exit(15), 0, "the second Ctrl-C quits");
}

/// The terminal the console draws on stops taking output (its window is
/// gone) while the console still runs: it ends as on a hang-up, its
/// saves finished and its lock released, the log saying why. Here its
/// screen is a second terminal, closed under it, so no SIGHUP comes.
/// Before, the failed draw returned at once: the store was never told to
/// finish, the lock stayed and the log had no last line.
#[test]
fn a_terminal_that_cannot_be_written_ends_the_console_cleanly() {
    use portable_pty::{PtySize, native_pty_system};
    let size = PtySize {
        rows: 24,
        cols: 80,
        pixel_width: 0,
        pixel_height: 0,
    };
    let screen = native_pty_system().openpty(size).unwrap();
    let tty = screen.master.tty_name().expect("the screen's tty");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cell.toml"), super::tui_harness::PROFILE).unwrap();
    let cwd = dir.path().to_path_buf();
    let vss = env!("CARGO_BIN_EXE_vss");
    let made = std::process::Command::new(vss)
        .args(["--profile", "cell.toml", "session", "new", "cube"])
        .current_dir(&cwd)
        .env("XDG_STATE_HOME", cwd.join("state"))
        .output()
        .unwrap();
    assert!(made.status.success(), "{made:?}");
    let cmd = format!("exec {vss} --profile cell.toml > {}", tty.display());
    let mut c = Console::spawn_program("sh", &cwd, dir, 80, 24, &[], &["-c", &cmd]);
    // Keys go to the console's own terminal; it opens the one session.
    let lock = c.session().join("cube.lock");
    let end = std::time::Instant::now() + Duration::from_secs(20);
    while !lock.exists() {
        assert!(
            std::time::Instant::now() < end,
            "the session was not opened"
        );
        std::thread::sleep(Duration::from_millis(1500));
        if !lock.exists() {
            c.send("\r");
        }
        std::thread::sleep(Duration::from_millis(500));
    }
    drop(screen);
    // A key makes the console draw, on a terminal that is gone.
    c.send("2");
    assert_ne!(c.wait_exit(15), 0, "ended by the terminal's failure");
    let log = std::fs::read_to_string(c.session().join("cube.log")).unwrap();
    assert!(
        log.contains("console ended: the terminal cannot be written"),
        "{log}"
    );
    assert!(!lock.exists(), "the lock is released");
}

/// Ctrl-Z on a console started through a parent in its own process group
/// (`cargo run`, a wrapper script, `sh -c`) stops the whole job, as the
/// terminal's Ctrl-Z does, so the shell gets the terminal back; `fg`
/// continues both. Stopping the console alone left the shell waiting on
/// the parent, with nobody reading the terminal.
#[test]
fn ctrl_z_stops_the_whole_job_when_the_console_runs_under_a_wrapper() {
    let mut c = Console::start_under_shell_as(80, 24, |vss| {
        format!("sh -c '{vss} --profile cell.toml; echo wrapper ended'")
    });
    c.wait_text("choose a session", 10);
    c.send("\x1a");
    c.wait("the shell's job stopped", 10, |s| {
        s.contains("Stopped") && shell_terminal(&c)
    });
    c.send("fg\r");
    c.wait("the console drawn again", 10, |s| {
        s.contains("choose a session") && !s.contains("Stopped")
    });
    c.send("2");
    c.wait_text("lights", 10);
    c.send("q");
    c.wait_text("wrapper ended", 10);
}

/// A console left suspended (Ctrl-Z) in a shell that still runs — a
/// detached tmux — holds its session; another console's take-over (`y`)
/// gets it: the holder, asked and then signalled, is continued so that it
/// can end (saves finished, lock released) without drawing. Before, the
/// signal waited while the holder was stopped: the take-over failed
/// "still held … after asking it to end", and the suspended console ended
/// the moment its operator brought it back with `fg`.
#[test]
fn a_suspended_console_s_session_can_be_taken_over() {
    let mut a = Console::start_under_shell(80, 24);
    a.create_session("cube");
    let shell = a.child.process_id().expect("the shell's pid");
    let vss = child_of(shell).expect("the console runs under the shell");
    a.send("\x1a");
    a.wait("the shell's job stopped", 10, |s| {
        s.contains("Stopped") && shell_terminal(&a)
    });
    let mut b = a.another(80, 24);
    b.wait_text("choose a session", 10);
    // The list's row first: an Enter before the folder is read asks nothing.
    b.wait_text(" cube ", 10);
    b.send("\r");
    b.wait("the question to take it over", 10, |s| {
        flat(&s.replace('│', " ")).contains("Take it over anyway?")
    });
    b.yes();
    b.wait_text("lightings", 30);
    let end = std::time::Instant::now() + Duration::from_secs(10);
    while !ended(vss) {
        assert!(
            std::time::Instant::now() < end,
            "the suspended console did not end"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let log = std::fs::read_to_string(a.session().join("cube.log")).unwrap();
    assert!(log.contains("console ended: SIGTERM"), "{log}");
    assert!(shell_terminal(&a), "not drawn again:\n{}", a.screen());
    b.send("q");
    assert_eq!(b.wait_exit(10), 0);
}

/// A name pasted with a letter outside a-z (an é, from a keyboard or a
/// paste) is refused in words that do not call it a non-letter: the rule
/// shown before typing and the refusal both say which letters. Before,
/// both said "letters", and the refusal of 'é' read "use only letters".
/// The é is refused as it is typed, the field keeping "cub".
#[test]
fn a_session_name_with_an_accent_is_refused_in_words_that_say_which_letters() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.press(
        SURVEY,
        vss::tui::keymap::Action::Survey(vss::tui::keymap::SurveyAction::NewSession),
    );
    let s = c.wait_text("new session name", 5);
    assert!(
        flat(&s.replace('│', " ")).contains("letters a-z A-Z, digits"),
        "{s}"
    );
    c.send("cubé");
    let s = c.wait("the refusal", 10, |s| s.contains("refused"));
    let said = flat(&s.replace('│', " "));
    assert!(
        said.contains("contains 'é' at position 4; use only the letters a-z and A-Z"),
        "{s}"
    );
    c.send("\x1b");
    c.wait("the field closed", 5, |s| !s.contains("new session name"));
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}
