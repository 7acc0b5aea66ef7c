//! Making text from files and devices safe to draw: control characters
//! (which could move the cursor or change the terminal's state) are removed.

/// Removes control characters (C0, DEL, C1) and escapes; tabs become spaces:
/// the crate's one sanitiser, [`crate::text::sanitize`].
pub fn clean(s: &str) -> String {
    crate::text::sanitize(s)
}
