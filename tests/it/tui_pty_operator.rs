//! Found by using the console as an operator does, through the real
//! binary in a pty at 80 × 24: a session mended while the console runs
//! opens without a restart; keys typed while the terminal is too small
//! do nothing unseen, and Esc there says to enlarge it; a frame changed
//! since recorded is said on the Session screen; going to an image with
//! nothing captured says what Enter does; every lighting of a profile
//! with more of them than Shift keys is set from the Capture screen; a
//! camera description that is not there is named once, with its camera.

use super::tui_harness::{Console, five_lightings, flat};
use crate::support::fixtures;
use vss::tui::keymap::{Action, CaptureAction, Scope, ScreenId};

/// A session whose manifest does not read is listed as damaged; the
/// error says to mend it "then open it again", and once mended (while
/// the console runs) Enter opens it: the list is read again, not the
/// one from the console's start.
#[test]
fn a_session_mended_while_the_console_runs_opens() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let m = c.session().join("cube.toml");
    let good = std::fs::read_to_string(&m).unwrap();
    let mut c = c.restart_after(|dir| {
        let m = dir.join("sessions/cube/cube.toml");
        let half = &good[..good.len() / 2];
        std::fs::write(m, format!("{half}\n[[[")).unwrap();
    });
    c.wait_text("DAMAGED", 10);
    c.send("\r");
    let s = c.wait_text("last message", 5);
    assert!(s.contains("cannot be opened"), "{s}");
    c.send("\x1b");
    c.wait("the window closed", 5, |s| !s.contains("last message"));
    std::fs::write(&m, &good).unwrap();
    c.send("\r");
    let s = c.wait("the mended session open", 10, |s| {
        s.contains("lightings abc") || s.contains("last message")
    });
    assert!(
        s.contains("┌ session cube") && !s.contains("last message"),
        "the mended session opens:\n{s}"
    );
    c.send("q");
    c.wait_exit(10);
}

/// A manifest naming a camera its session does not have (camera 9) is
/// listed as damaged and, asked for, said with its record and camera,
/// the file left as it is; it opened, and the image's camera went to the
/// next capture.
#[test]
fn a_session_naming_a_camera_it_lacks_is_said_damaged() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let m = c.session().join("cube.toml");
    let good = std::fs::read_to_string(&m).unwrap();
    let bad = format!("{good}\n[[image]]\nnumber = 99\ncamera = 9\nlocation = 1\n");
    let mut c = c.restart_after(|dir| {
        std::fs::write(dir.join("sessions/cube/cube.toml"), &bad).unwrap();
    });
    c.wait_text("DAMAGED", 10);
    c.send("\r");
    let s = c.wait_text("last message", 5);
    let said = flat(&s.replace('│', " "));
    assert!(
        said.contains("cannot be opened")
            && said.contains("[[image]] number 99: camera 9 is not one of the session's cameras"),
        "{s}"
    );
    assert_eq!(
        std::fs::read_to_string(&m).unwrap(),
        bad,
        "the manifest is kept"
    );
    c.send("\x1b");
    c.wait("the window closed", 5, |s| !s.contains("last message"));
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}

/// While the terminal is too small the screen says only that, q quits
/// and Esc stops: Enter on the session list (unseen) opened the session,
/// and any other key acted on a screen the operator could not see.
#[test]
fn keys_typed_in_too_small_a_terminal_act_on_nothing_unseen() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let mut c = c.restart(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.resize(20, 60);
    let s = c.wait_text("terminal too small", 10);
    assert!(s.contains("other keys wait"), "{s}");
    c.send("\r");
    c.send("n");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let s = c.screen();
    assert!(!s.contains("new session name"), "{s}");
    c.resize(24, 80);
    let s = c.wait_text("choose a session", 10);
    assert!(
        !s.contains("lightings abc"),
        "no session opened unseen:\n{s}"
    );
    c.send("q");
    c.wait_exit(10);
}

/// Esc where it does nothing, in too small a terminal, says there what
/// helps: a window at least the size vss needs, and q to quit. It said
/// "? lists this screen's keys", and ? lists nothing while no screen is
/// drawn; and it was seen only once the window was larger again.
#[test]
fn esc_in_too_small_a_terminal_says_to_enlarge_it() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_text("choose a session", 10);
    c.open_pipeline();
    c.resize(12, 50);
    c.wait_text("terminal too small", 10);
    c.send("\x1b");
    let s = c.wait_words("Esc does nothing here", 10);
    let f = flat(&s);
    assert!(
        f.contains("the terminal is too small: enlarge it to at least 64 × 18; q quits"),
        "{s}"
    );
    assert!(!f.contains("? lists"), "{s}");
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}

/// A frame whose pixels changed since the manifest recorded it (the
/// header intact, so it still reads) is listed on the Session screen as
/// changed, before the files that are as recorded, as `vss session check`
/// warns; the screen said "ok".
#[test]
fn a_frame_changed_since_recorded_is_said_on_the_session_screen() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    let mut c = c.restart_after(|dir| {
        let img = dir.join("sessions/cube/cube1b.img");
        let mut bytes = std::fs::read(&img).unwrap();
        let n = bytes.len();
        for b in &mut bytes[n - 500..] {
            *b ^= 0x55;
        }
        std::fs::write(&img, bytes).unwrap();
    });
    c.wait_text("choose a session", 10);
    // The list read (Enter on it before then opens nothing).
    c.wait_text(" cube ", 10);
    c.send("\r");
    c.wait_text("lightings abc", 10);
    c.send("5");
    let s = c.wait_text("files (", 10);
    let flat = super::tui_harness::flat(&s.replace('│', " "));
    assert!(
        flat.contains("cube1b.img CHANGED since the manifest"),
        "the changed frame is said:\n{s}"
    );
    c.send("q");
    c.wait_exit(10);
}

/// `Enter` on a checklist row whose image has nothing captured says so
/// and what `Enter` does next; it once said only "image 2".
#[test]
fn going_to_an_image_with_nothing_captured_says_what_enter_does() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    c.send("\x1b[B");
    c.send("\r");
    c.wait_words("image 2: nothing captured yet — Enter captures it", 10);
    c.send("q");
    c.wait_exit(10);
}

/// A cell with more lighting configurations than the key table has Shift
/// keys (eight; Shift+A to F): at 80 × 24 the Capture screen's panel lists
/// what fits around the chosen row, and ↑↓ Space set any lighting, here h
/// (relays 0 and 3 through the simulated board). Before, g and h had no
/// key and their rows ran off the panel.
#[test]
fn every_lighting_of_a_profile_is_set_from_the_capture_screen() {
    let profile = format!(
        "name = \"eight lightings\"\n{}{}",
        fixtures::five_lightings!(),
        r#"
[[lighting]]
letter = "f"
on = ["lf", "rf"]
[[lighting]]
letter = "g"
on = ["lb", "rb"]
[[lighting]]
letter = "h"
on = ["lf", "rb"]

[relay]
settle_ms = 5

[survey]
dir = "sessions"
cameras = 2

[sim]
width = 128
height = 128

[llv.lens]
enabled = false
"#
    );
    let mut c = Console::start_with(&profile, 80, 24, &[], |_| {});
    c.wait_text("n new", 20);
    c.send("2");
    let s = c.wait_text("lightings (Space", 5);
    assert!(s.contains("↓ 2 more"), "the rows that do not fit:\n{s}");
    let capture = Scope::Screen(ScreenId::Capture);
    // Four lights, then the eighth lighting.
    for _ in 0..11 {
        c.press(capture, Action::Capture(CaptureAction::LightNext));
    }
    c.wait_text("↑ 2 more", 5);
    c.press(capture, Action::Capture(CaptureAction::LightToggle));
    c.wait_text("lighting h", 10);
    let s = c.wait("the board's relays 0 and 3", 10, |s| {
        s.contains("mask 0x0009")
    });
    assert!(
        s.contains(" h lf+rb  <") && s.contains(" g lb+rb") && s.contains("[x] rb"),
        "lighting h set and marked:\n{s}"
    );
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}

/// A camera description the profile names but that is not there: the
/// start-up warning names the camera once and the file's trouble (it said
/// "camera 1: camera 1: …").
#[test]
fn a_missing_camera_description_is_said_once_per_camera() {
    let mut c = Console::start_with(&five_lightings(true), 80, 24, &[], |_| {});
    let s = c.wait_text("lens correction OFF for camera", 20);
    let said = flat(&s);
    // The newest of the two cameras' warnings holds the line.
    let k = if said.contains("for camera 1:") { 1 } else { 2 };
    assert!(
        said.contains(&format!("lens correction OFF for camera {k}: "))
            && said.contains(&format!("cam{k}.cdf: cannot read")),
        "{s}"
    );
    assert!(!said.contains(&format!("camera {k}: camera {k}")), "{s}");
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}
