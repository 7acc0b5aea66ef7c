//! A key held whose answer is always the same (F5, bound to nothing):
//! one entry with its count on the message line and in the log pane, and
//! in the log file its line once and how many times it was repeated.

use super::tui_harness::{Console, flat};

#[test]
fn a_key_held_is_one_entry_with_its_count_and_the_log_file_says_it() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_words("? help", 10);
    // The devices' note first: arriving between the presses (under load it
    // comes late) it would stand between F5's entry and F6's.
    c.wait_devices(20);
    c.send(&"\x1b[15~".repeat(500));
    let s = c.wait_words(
        "F5 does nothing here — ? lists this screen's keys (×500)",
        20,
    );
    assert!(!s.contains("(×501)"), "{s}");
    c.send("m");
    let s = c.wait_text("log:", 5);
    assert_eq!(
        flat(&s).matches("F5 does nothing here").count(),
        1,
        "one entry in the pane (the message line, while it is open):\n{s}"
    );
    c.send("\x1b[17~");
    c.wait_words("F6 does nothing here", 5);
    c.send("q");
    c.wait_exit(10);
    let file = c.dir.path().join("state/vss/console.log");
    let text = std::fs::read_to_string(&file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let f5: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].contains("F5 does nothing here"))
        .collect();
    assert_eq!(f5.len(), 1, "one line of F5:\n{text}");
    assert!(
        lines[f5[0] + 1].ends_with("info    last message repeated 499 times"),
        "then its count:\n{text}"
    );
    assert!(lines[f5[0] + 2].contains("F6 does nothing here"), "{text}");
    assert!(lines.last().unwrap().contains("console ended"), "{text}");
}
