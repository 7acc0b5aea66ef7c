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

/// A file's or folder's path as a message shows it: unambiguous, and on
/// one line. What [`sanitize`] would drop is escaped instead, so that two
/// names never read alike and a name never breaks the message: a line
/// break as `\n` (also `\r`, `\t`), other control characters and bytes
/// that are not UTF-8 as `\xHH`, C1 controls and bidirectional overrides
/// as `\u{HHHH}`, and a backslash as `\\`. Every message that names a
/// file (the command line's and the console's) shows it through this.
pub fn path(p: impl AsRef<std::path::Path>) -> String {
    use std::fmt::Write as _;
    use std::os::unix::ffi::OsStrExt as _;
    let mut out = String::new();
    for chunk in p.as_ref().as_os_str().as_bytes().utf8_chunks() {
        for c in chunk.valid().chars() {
            match c {
                '\\' => out.push_str("\\\\"),
                '\n' => out.push_str("\\n"),
                '\r' => out.push_str("\\r"),
                '\t' => out.push_str("\\t"),
                c if c.is_ascii_control() => {
                    let _ = write!(out, "\\x{:02x}", u32::from(c));
                }
                c if shown(c) != Some(c) => {
                    let _ = write!(out, "\\u{{{:04x}}}", u32::from(c));
                }
                c => out.push(c),
            }
        }
        for b in chunk.invalid() {
            let _ = write!(out, "\\x{b:02x}");
        }
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

    #[test]
    fn paths_are_shown_escaped_on_one_line() {
        use std::os::unix::ffi::OsStrExt as _;
        assert_eq!(path("sessions/cube/cube1a.img"), "sessions/cube/cube1a.img");
        assert_eq!(path("a\nb.img"), "a\\nb.img");
        assert_eq!(path("a\\nb.img"), "a\\\\nb.img");
        assert_eq!(path("x\x1b[2J\ty\r"), "x\\x1b[2J\\ty\\r");
        assert_eq!(path("p\u{9b}q\u{202e}r Grün"), "p\\u{009b}q\\u{202e}r Grün");
        let bytes = std::ffi::OsStr::from_bytes(b"f\xffg");
        assert_eq!(path(std::path::Path::new(bytes)), "f\\xffg");
    }
}
