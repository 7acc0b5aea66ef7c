//! Making text from files and devices safe to draw: control characters
//! (which could move the cursor or change the terminal's state) are removed.

/// Removes control characters (C0, DEL, C1) and escapes; tabs become spaces:
/// the crate's one sanitiser, [`crate::text::sanitize`].
pub fn clean(s: &str) -> String {
    crate::text::sanitize(s)
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
