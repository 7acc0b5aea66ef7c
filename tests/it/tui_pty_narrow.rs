//! Every text at 80 columns wraps, scrolls or is shortened so that nothing
//! is cut (issue 33, annoyance 7), through the real binary in a pty at
//! 80 × 24: the session list's "(in use by …)", the DEVICE LOST banner on
//! the hint rows, the Pipeline screen's zoom readout.

use vss::tui::keymap::{Action, NavAction, SurveyAction};

use super::tui_harness::{Console, PIPELINE, PROFILE, SURVEY};

/// The screen's words, box borders left out, so text wrapped inside a box
/// reads on.
fn flat(s: &str) -> String {
    s.replace(['│', '|'], " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn the_session_list_says_whole_who_holds_a_session() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    // A second console in the same folder lists cube as held by the first.
    let mut other = c.another(80, 24);
    let s = other.wait("cube listed as in use", 10, |s| {
        flat(s).contains("(in use by")
    });
    let words = flat(&s);
    let at = words
        .find("(in use by ")
        .unwrap_or_else(|| panic!("cube held by the first console:\n{s}"));
    let rest = &words[at + "(in use by ".len()..];
    let user = rest.split(')').next().unwrap_or("");
    assert!(
        rest.contains(')') && !user.trim().is_empty() && !user.contains('…'),
        "the holder's name whole, then the bracket closed:\n{s}"
    );
    other.send("q");
    other.wait_exit(15);
    // The first console lists its own session as open here.
    c.press(SURVEY, Action::Survey(SurveyAction::OpenPicker));
    let s = c.wait_text("open another session", 10);
    assert!(flat(&s).contains("cube 0/4 done (open here)"), "{s}");
    c.send("\x1b");
    c.send("q");
    c.wait_exit(15);
}

#[test]
fn the_device_lost_banner_is_whole_on_the_hint_rows() {
    let profile =
        format!("{PROFILE}\n[grabber]\nkind = \"vsg\"\nport = \"/dev/vss-no-such-grabber-here\"\n");
    let mut c = Console::start_with(&profile, 80, 24, &[], |_| {});
    c.wait_text("DEVICE LOST", 20);
    // What the log says was lost, whole, on the hint rows too.
    let file = c.dir.path().join("state/vss/console.log");
    c.wait("the loss in the log file", 10, |_| {
        std::fs::read_to_string(&file).is_ok_and(|l| l.contains("device lost: "))
    });
    let log = std::fs::read_to_string(&file).unwrap();
    let why = log
        .split("device lost: ")
        .nth(1)
        .and_then(|r| r.split(" — retrying").next())
        .unwrap()
        .to_string();
    let s = c.screen();
    let banner = &s[s.find("DEVICE LOST").unwrap()..];
    assert!(
        flat(banner).starts_with(&format!("DEVICE LOST: {why}")),
        "the banner says it whole ({why}):\n{s}"
    );
    c.send("q");
    c.wait_exit(15);
}

#[test]
fn the_zoom_readout_fits_at_80_columns() {
    // 512 × 512, as the cell's cameras: three-digit places.
    let profile = PROFILE.replace("width = 128\nheight = 128", "width = 512\nheight = 512");
    let mut c = Console::start_with(&profile, 80, 24, &[], |_| {});
    c.create_session("cube");
    c.capture_current(1);
    c.open_pipeline();
    for _ in 0..3 {
        c.press(PIPELINE, Action::Nav(NavAction::ZoomIn));
    }
    let s = c.wait_text("×8", 10);
    let row = s
        .lines()
        .find(|l| l.contains("×8"))
        .unwrap()
        .trim_end()
        .to_string();
    // The place shown ends the row: `y` then its range, whole.
    let tail = row.rsplit('y').next().unwrap_or("").trim();
    let range: Vec<&str> = tail.split('–').collect();
    assert!(
        range.len() == 2 && range.iter().all(|n| n.parse::<u32>().is_ok()),
        "the y range of the view whole at the row's end: {row:?}\n{s}"
    );
    c.send("q");
    c.wait_exit(15);
}
