//! Help, hints and feedback through the real binary in a pty at 80 × 24:
//! on every screen the help window fits, scrolls to its end and lists each
//! key the screen answers to with what it does, and the checklist's marks;
//! every hint of the screen's keys is on its status rows; the top bar names
//! the profile; a typed value that is refused stays to be corrected, one
//! that is taken is confirmed and clears the error; each parameter change
//! is logged and marked; a grab is logged; the log pane keeps the whole run
//! and scrolls to its first message and back.

use vss::tui::keymap::{self, Action, GlobalAction, PipelineAction, Scope, ScreenId};

use super::tui_harness::{Console, PIPELINE, flat, panel_value};

/// The first words of a key's description, as its help row starts.
fn opening(desc: &str) -> String {
    let mut out = String::new();
    for w in desc.split_whitespace() {
        if out.len() + w.len() > 30 {
            break;
        }
        if !out.is_empty() {
            out.push(' ');
        }
        out.push_str(w);
    }
    out
}

fn global(c: &mut Console, g: GlobalAction) {
    c.press(Scope::Global, Action::Global(g));
}

/// The help window's text from its first row to its last, page by page.
fn whole_help(c: &mut Console) -> String {
    global(c, GlobalAction::Help);
    let mut s = c.wait_text("┌ help", 5);
    let mut text = String::new();
    for _ in 0..40 {
        let rows: Vec<&str> = s.lines().collect();
        assert!(
            rows.iter().any(|r| r.contains("┌ help")) && rows.iter().any(|r| r.contains('└')),
            "the window fits, both borders on screen:\n{s}"
        );
        text.push_str(&s);
        text.push('\n');
        if s.contains("Shift+drag selects text") {
            c.send("\x1b");
            c.wait("help closed", 5, |s| !s.contains("┌ help"));
            return text;
        }
        c.press(
            Scope::Viewer,
            Action::Viewer(keymap::ViewerAction::PageDown),
        );
        let before = s.clone();
        s = c.wait("the next page", 5, |s| *s != before);
    }
    panic!("the help never reached its end:\n{s}");
}

#[test]
fn help_lists_every_key_of_every_screen_and_hints_fit() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    let top = c.screen();
    let first = top.lines().next().unwrap_or_default();
    assert!(
        first.contains("pty test cell"),
        "the top bar names the profile: {first}"
    );
    for (i, screen) in ScreenId::ALL.iter().enumerate() {
        c.send(&(i + 1).to_string());
        let hints = keymap::hints(Scope::Screen(*screen));
        let (k0, h0) = &hints[0];
        let s = c.wait(&format!("{} screen", screen.title()), 10, |s| {
            s.contains(&format!("{k0} {h0}"))
        });
        // Every hint of this screen's own keys is on the status rows.
        let status: String = s.lines().rev().take(3).collect::<Vec<_>>().join(" ");
        for (k, h) in &hints {
            assert!(
                status.contains(&format!("{k} {h}")),
                "{} screen: hint `{k} {h}` on the status rows:\n{s}",
                screen.title()
            );
        }
        let help = flat(&whole_help(&mut c));
        let mut scopes = vec![
            Scope::Screen(*screen),
            Scope::Global,
            Scope::Confirm,
            Scope::Prompt,
            Scope::Viewer,
        ];
        if keymap::has_picture(*screen) {
            scopes.push(Scope::Picture);
        }
        for scope in scopes {
            for (k, d) in keymap::describe(scope) {
                let row = format!("{k} {}", opening(d));
                assert!(
                    help.contains(&row),
                    "{} screen's help lists `{row}`:\n{help}",
                    screen.title()
                );
            }
        }
        assert!(help.contains("The checklist's marks"), "{help}");
        for (m, d) in vss::tui::screens::chrome::LEGEND {
            assert!(help.contains(&format!("{m} {d}")), "mark {m}: {help}");
        }
    }
    c.send("q");
    c.wait_exit(10);
}

#[test]
fn values_changes_and_grabs_are_confirmed_and_the_log_keeps_the_run() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    c.send("3");
    let s = c.wait_text("parameters", 10);
    assert!(s.contains("more"), "a longer list says so:\n{s}");
    c.choose_param("edges.half_width");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Type));
    c.wait_text("edges.half_width = 3", 5);
    // The field holds the value now: clear it, type a bad one.
    c.send("\x15wide\r");
    let s = c.wait_text("is not a number", 5);
    assert!(
        s.contains("edges.half_width = wide"),
        "the typed text stays to be corrected:\n{s}"
    );
    c.send("\x15");
    c.send("6\r");
    let s = c.wait("the value taken", 10, |s| {
        panel_value(s, "edges.half_width").as_deref() == Some("6") && !s.contains("running")
    });
    assert!(
        flat(&s).contains("edges.half_width = 6"),
        "confirmed on the message row:\n{s}"
    );
    assert!(
        !s.contains("is not a number"),
        "the old error is gone:\n{s}"
    );
    assert!(s.contains("6*"), "a value off the profile is marked:\n{s}");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Inc));
    c.wait_text("edges.half_width 6 → 7", 10);
    c.send("2");
    c.wait_text("grab", 10);
    c.press(
        Scope::Screen(ScreenId::Capture),
        Action::Capture(keymap::CaptureAction::Grab),
    );
    c.wait_text("grabbed a frame of camera", 20);
    // The log pane: the newest at the bottom, the run's first message at
    // the top, and back.
    global(&mut c, GlobalAction::ToggleLog);
    let s = c.wait_text("┌ log:", 5);
    assert!(s.contains("grabbed a frame"), "{s}");
    assert!(
        !s.contains("profile pty test cell"),
        "more than a pane:\n{s}"
    );
    global(&mut c, GlobalAction::LogTop);
    let s = c.wait_text("profile pty test cell", 5);
    assert!(s.contains("more rows (End: newest)"), "{s}");
    global(&mut c, GlobalAction::LogEnd);
    let s = c.wait("the newest again", 5, |s| {
        s.contains("grabbed a frame") && !s.contains("more rows")
    });
    assert!(s.contains("edges.half_width 6 → 7"), "{s}");
    c.send("q");
    c.wait_exit(10);
}
