//! Text shown to a person — on the terminal, in the console, in a report —
//! made safe to show. Names, notes, comments and error messages come from
//! files and devices that anyone may have written: a control character in
//! them (ESC, CSI, BEL, a carriage return) could clear the operator's
//! screen, move the cursor, set the window title or hide what follows, and
//! a bidirectional override could reorder what the operator reads. Every
//! path that shows such text goes through [`sanitize`] (one line) or
//! [`sanitize_lines`] (several), so none of them can forget a case.

/// What is shown for one character: control characters (C0, DEL, C1) and
/// bidirectional overrides are dropped, a tab becomes a space.
fn shown(c: char) -> Option<char> {
    match c {
        '\t' => Some(' '),
        c if c.is_control() => None,
        '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' => None,
        c => Some(c),
    }
}

/// One line of text made safe to show: control characters (line breaks
/// included) and bidirectional overrides removed, tabs turned into spaces.
pub fn sanitize(s: &str) -> String {
    s.chars().filter_map(shown).collect()
}

/// Text of several lines made safe to show: each line as [`sanitize`]
/// makes it, the line breaks (`\n`) kept.
pub fn sanitize_lines(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for (i, line) in s.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        out.extend(line.chars().filter_map(shown));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_controls_and_overrides_are_removed() {
        assert_eq!(sanitize("cube\x1b[2J1a\r\n\x07"), "cube[2J1a");
        assert_eq!(sanitize("a\tb\u{9b}c\u{202e}d"), "a bcd");
        assert_eq!(sanitize("Grün 25°"), "Grün 25°");
    }

    #[test]
    fn lines_keep_their_breaks_and_lose_the_rest() {
        assert_eq!(
            sanitize_lines("one\x1b]0;title\x07\ntwo\r\n\u{9b}2Jthree"),
            "one]0;title\ntwo\n2Jthree"
        );
    }
}
