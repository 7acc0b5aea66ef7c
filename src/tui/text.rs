//! Making text from files and devices safe to draw: control characters
//! (which could move the cursor or change the terminal's state) are removed.

/// Removes control characters (C0, DEL, C1) and escapes; tabs become spaces.
pub fn clean(s: &str) -> String {
    s.chars()
        .filter_map(|c| match c {
            '\t' => Some(' '),
            c if c.is_control() => None,
            // Bidi overrides can reorder what the operator reads.
            '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' => None,
            c => Some(c),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::clean;

    #[test]
    fn strips_escapes_and_controls() {
        assert_eq!(clean("cube\x1b[2J1a\r\n\x07"), "cube[2J1a");
        assert_eq!(clean("a\tb\u{9b}c\u{202e}d"), "a bcd");
        assert_eq!(clean("Grün 25°"), "Grün 25°");
    }
}
