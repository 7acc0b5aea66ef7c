//! The console when things go wrong, through the real binary in a pty at
//! 80 × 24: a long error wraps and opens in full and lands in the log
//! file; a damaged session is listed with why, a truncated image and a
//! garbled line file are marked and only the image's damaged lighting
//! retaken; a lighting the session cannot save (a link planted where its
//! file goes) is marked, keeps the image from being accepted and is
//! retaken alone; outputs that cannot be written keep the image under
//! review; a report that cannot be written says so;
//! a session held by a console that still runs is offered to take over;
//! a terminal too small, a dumb terminal and the Linux console.

use std::time::Duration;

use vss::tui::keymap::{Action, GlobalAction, Scope, SurveyAction};

use super::tui_harness::{Console, SESSION, SURVEY, flat};

/// The screen's words, box borders left out.
fn words(s: &str) -> String {
    s.replace(['│', '|'], " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

fn global(c: &mut Console, g: GlobalAction) {
    c.press(Scope::Global, Action::Global(g));
}

/// A refused session name is longer than a row: it wraps over the
/// message rows, `!` shows it whole, the log pane keeps it, and the log
/// file holds it.
#[test]
fn a_long_message_is_readable_and_kept() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_devices(10);
    c.press(SURVEY, Action::Survey(SurveyAction::NewSession));
    c.wait_text("new session name", 5);
    c.send("-bad-name-starting-with-a-dash\r");
    let s = c.wait_words("starts with '-'; it must start with a letter or _", 10);
    assert!(
        s.contains("-bad-name-starting-with-a-dash"),
        "the typed text is kept:\n{s}"
    );
    c.send("\x1b");
    c.wait("the field closed", 5, |s| !s.contains("new session name"));
    global(&mut c, GlobalAction::LastMessage);
    let s = c.wait_text("last message", 5);
    assert!(flat(&s).contains("it must start with a letter or _"), "{s}");
    c.send("\x1b");
    c.wait("the window closed", 5, |s| !s.contains("last message"));
    global(&mut c, GlobalAction::ToggleLog);
    let s = c.wait_text("log:", 5);
    assert!(
        s.contains("profile pty test cell") && s.contains("refused"),
        "{s}"
    );
    let file = c.dir.path().join("state/vss/console.log");
    let text = std::fs::read_to_string(&file).unwrap_or_default();
    assert!(
        text.contains("refused"),
        "the log file {}: {text}",
        file.display()
    );
    c.send("q");
    c.wait_exit(10);
}

#[test]
fn damaged_sessions_and_files_are_shown_and_only_the_damage_retaken() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    let d = c.session();
    // Damage: a truncated image of lighting b, a session whose manifest
    // does not read, a report that cannot be written over a folder.
    let mut c = c.restart_after(|dir| {
        let img = dir.join("sessions/cube/cube1b.img");
        let f = std::fs::OpenOptions::new().write(true).open(&img).unwrap();
        f.set_len(5000).unwrap();
        std::fs::write(dir.join("sessions/cube/cube1.ldr"), "not a line file\n").unwrap();
        let bad = dir.join("sessions/bad");
        std::fs::create_dir_all(&bad).unwrap();
        let m = std::fs::read_to_string(dir.join("sessions/cube/cube.toml")).unwrap();
        let m: String = m
            .lines()
            .map(|l| {
                if l.starts_with("planned_images") {
                    "planned_images = \"five\"".to_string()
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(bad.join("bad.toml"), m).unwrap();
        std::fs::create_dir(dir.join("sessions/cube/cube.ps")).unwrap();
    });
    let s = c.wait_text("DAMAGED", 10);
    assert!(
        s.contains("bad  DAMAGED: bad.toml:11"),
        "listed with the file and line, not hidden:\n{s}"
    );
    // The damaged one is first: Enter shows the full error and the command.
    c.send("\r");
    let s = c.wait_text("last message", 5);
    assert!(s.contains("vss session check"), "{s}");
    assert!(s.contains("bad.toml:11: invalid type"), "{s}");
    c.send("\x1b");
    c.wait("the window closed", 5, |s| !s.contains("last message"));
    c.press(SURVEY, Action::Survey(SurveyAction::Down));
    c.send("\r");
    let s = c.wait_text("session cube", 10);
    assert!(s.contains("a!c"), "the truncated lighting is marked:\n{s}");
    assert!(
        s.lines()
            .any(|r| r.contains("a!c") && r.contains("DAMAGED")),
        "so is the garbled .ldr, on image 1's row:\n{s}"
    );
    assert!(s.contains("damaged or missing"), "{s}");
    c.send("5");
    let s = c.wait_text("problem(s)", 10);
    assert!(s.contains("cube1b.img"), "{s}");
    c.press(
        SESSION,
        Action::Files(vss::tui::keymap::FilesAction::Export),
    );
    let s = c.wait_text("report NOT written", 10);
    assert!(s.contains("cube.ps"), "which file:\n{s}");
    c.send("1");
    c.wait_text("session cube", 5);
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    c.wait("the retake question", 10, |s| {
        words(s).contains("y sets up the retake of only b")
    });
    c.yes();
    let s = c.wait_text("captures lighting b again", 10);
    assert!(s.contains("Image 1"), "{s}");
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait("image 1 reviewed again", 30, |s| {
        s.contains("before CONNECT") && s.contains("abc") && !s.contains("a!c")
    });
    // The frame is saved by the store worker, which may finish after the
    // review is on screen: wait for the file itself.
    let end = std::time::Instant::now() + Duration::from_secs(20);
    let img = loop {
        match vss::formats::img::read_img(&d.join("cube1b.img")) {
            Ok(img) => break img,
            Err(e) => assert!(
                std::time::Instant::now() < end,
                "lighting b never retaken: {e}"
            ),
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(img.image.size(), (128, 128));
    c.send("q");
    c.wait_exit(10);
}

/// What the file a planted link points to holds.
const OUTSIDE: &str = "a file outside the session\n";

/// A console with session `cube` open and a link planted as the session's
/// file `name`, pointing outside the session; and the file it points to.
fn console_with_a_link(name: &str) -> (Console, std::path::PathBuf) {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let outside = c.dir.path().join("outside.txt");
    std::fs::write(&outside, OUTSIDE).unwrap();
    std::os::unix::fs::symlink(&outside, c.session().join(name)).unwrap();
    (c, outside)
}

/// Waits for `saved` to hold: the store worker writes files after the
/// screen that announces them.
fn saved_within_20_s(what: &str, saved: impl Fn() -> bool) {
    let end = std::time::Instant::now() + Duration::from_secs(20);
    while !saved() {
        assert!(std::time::Instant::now() < end, "{what} never saved");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A lighting whose file cannot be written (a link planted where it goes)
/// is marked `!` on the checklist, the image is not accepted while it is
/// not on disk, quitting asks first, nothing is written through the link,
/// and retaking that lighting alone once the link is gone puts it right.
#[test]
fn a_lighting_the_session_cannot_save_is_marked_and_keeps_the_image_from_acceptance() {
    let (mut c, outside) = console_with_a_link("cube1a.img");
    let d = c.session();
    c.capture_current(1);
    let s = c.wait("lighting a marked", 20, |s| {
        s.contains("!bc") && s.contains("lighting a NOT saved")
    });
    assert!(s.contains("R captures again"), "what to do:\n{s}");
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = c.wait_text("NOT accepted", 10);
    assert!(flat(&s).contains("symbolic link"), "why:\n{s}");
    assert!(s.contains("Image 1: "), "still on image 1:\n{s}");
    assert!(!d.join("cube1.ldr").exists(), "no outputs of image 1");
    assert_eq!(
        std::fs::read_to_string(&outside).unwrap(),
        OUTSIDE,
        "nothing written through the link"
    );
    // Quitting would lose the frame: it asks.
    c.send("q");
    let s = c.wait_text("Quit anyway?", 10);
    assert!(s.contains("Lighting a of image 1 is not saved"), "{s}");
    c.send("n");
    c.wait("the question closed", 5, |s| !s.contains("Quit anyway?"));
    std::fs::remove_file(d.join("cube1a.img")).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Redo));
    let s = c.wait("the retake question", 10, |s| {
        words(s).contains("retake of only a")
    });
    assert!(s.contains("lighting a not saved"), "{s}");
    c.yes();
    c.wait_text("captures lighting a again", 10);
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait("image 1 reviewed again", 30, |s| {
        s.contains("before CONNECT") && s.contains("abc") && !s.contains("NOT saved")
    });
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 2: camera", 20);
    saved_within_20_s("image 1's lighting a and outputs", || {
        d.join("cube1.ldr").exists() && vss::formats::img::read_img(&d.join("cube1a.img")).is_ok()
    });
    c.send("q");
    c.wait_exit(10);
}

/// Outputs that cannot be written at `a` (a link planted at the `.ldr`)
/// leave the image under review and not done, nothing is written through
/// the link, and `a` once the link is gone accepts it.
#[test]
fn outputs_that_cannot_be_saved_keep_the_image_under_review() {
    let (mut c, outside) = console_with_a_link("cube1.ldr");
    let d = c.session();
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = c.wait_text("outputs of image 1 NOT saved", 10);
    assert!(flat(&s).contains("symbolic link"), "why:\n{s}");
    let s = c.wait("image 1 under review again", 10, |s| {
        s.contains("Image 1: ") && s.contains("before CONNECT")
    });
    assert!(
        s.lines().any(|r| r.contains(">  1") && r.contains(" -")),
        "image 1 is the current row, not done:\n{s}"
    );
    assert_eq!(
        std::fs::read_to_string(&outside).unwrap(),
        OUTSIDE,
        "nothing written through the link"
    );
    accepted_once_the_link_is_gone(c, &d);
}

/// Outputs that could not be saved make `q` ask first, as the README
/// says ("a lighting or an output cannot be saved … `q` asks first"): no
/// quitting that silently drops them; once saved, `q` quits at once.
#[test]
fn q_asks_first_while_outputs_are_not_saved() {
    let (mut c, _outside) = console_with_a_link("cube1.ldr");
    let d = c.session();
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("outputs of image 1 NOT saved", 10);
    c.send("q");
    let s = c.wait("the question", 10, |s| {
        s.contains("Quit anyway") || c_exited(s)
    });
    assert!(
        words(&s).contains("The outputs of image 1 are not saved"),
        "q asks first:\n{s}"
    );
    c.send("n");
    c.wait("the question closed", 5, |s| !s.contains("Quit anyway"));
    assert_eq!(c.exit_code(), None, "still running");
    accepted_once_the_link_is_gone(c, &d);
}

/// With the link planted at `cube1.ldr` removed, `a` accepts image 1: its
/// outputs are written and said saved, and then `q` quits at once.
fn accepted_once_the_link_is_gone(mut c: Console, d: &std::path::Path) {
    std::fs::remove_file(d.join("cube1.ldr")).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 2: camera", 20);
    saved_within_20_s("image 1's outputs", || {
        vss::formats::lines::read_lines(&d.join("cube1.ldr")).is_ok()
    });
    // Until the save is said done, q rightly asks (the outputs are not
    // saved yet): the .ldr is on disk before the manifest records it.
    c.wait_text("image 1 accepted", 20);
    c.send("q");
    c.wait_exit(10);
}

/// The screen of a console that has ended (no question can show).
fn c_exited(s: &str) -> bool {
    s.trim().is_empty()
}

#[test]
fn too_small_a_terminal_says_so_and_recovers() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.resize(12, 50);
    let s = c.wait_text("terminal too small", 10);
    assert!(s.contains("50 × 12"), "{s}");
    c.resize(24, 80);
    c.wait_text("choose a session", 10);
    c.send("q");
    c.wait_exit(10);
}

#[test]
fn a_dumb_terminal_gets_words_not_escapes() {
    let mut c = Console::start(80, 24, &[("TERM", "dumb")]);
    c.wait_exit(10);
    assert_eq!(c.exit_code(), Some(2));
    let raw = String::from_utf8_lossy(&c.raw.lock().unwrap()).into_owned();
    assert!(raw.contains("cursor addressing"), "{raw:?}");
    assert!(!raw.contains('\x1b'), "no escape sequence: {raw:?}");
}

/// Every SGR colour parameter in `bytes`.
fn colours(bytes: &[u8]) -> Vec<String> {
    let s = String::from_utf8_lossy(bytes);
    s.split("\x1b[")
        .skip(1)
        .filter_map(|part| {
            let end = part.find(|c: char| !(c.is_ascii_digit() || c == ';'))?;
            part[end..]
                .starts_with('m')
                .then(|| part[..end].to_string())
        })
        .collect()
}

#[test]
fn the_linux_console_gets_sixteen_colours() {
    let mut c = Console::start(80, 24, &[("TERM", "linux")]);
    c.survey(1);
    c.send("3");
    let s = c.wait_text("parameters", 10);
    assert!(s.is_ascii(), "{s}");
    c.send("q");
    c.wait_exit(10);
    std::thread::sleep(Duration::from_millis(50));
    let sgr = colours(&c.raw.lock().unwrap());
    // crossterm writes even the sixteen named colours as `38;5;N`, which the
    // Linux console takes for N below 16: only those may appear.
    let mut indices = Vec::new();
    for p in &sgr {
        let n: Vec<&str> = p.split(';').collect();
        for w in n.windows(3) {
            if matches!(w[0], "38" | "48") && w[1] == "5" {
                indices.push(w[2].parse::<u32>().unwrap_or(999));
            }
        }
        assert!(
            !p.contains("38;2") && !p.contains("48;2"),
            "no true colour: {p}"
        );
    }
    assert!(!indices.is_empty(), "some colour is used");
    assert!(
        indices.iter().all(|&i| i < 16),
        "only the sixteen colours: {:?}",
        indices
            .iter()
            .filter(|&&i| i >= 16)
            .take(5)
            .collect::<Vec<_>>()
    );
}
