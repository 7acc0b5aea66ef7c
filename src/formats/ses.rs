//! Session files `.ses` (formats.md §1): exactly three numbers, one per
//! line — number of images, of cameras, of lighting configurations — so
//! older tools keep reading them. Everything richer lives in the session's
//! manifest, which the console owns.

use std::path::Path;

use super::{FormatError, FormatErrorKind as K, numbered_lines, read_text, shorten};

/// Most lighting configurations: they are lettered `a`–`z`.
pub const MAX_LIGHTINGS: u32 = 26;

/// The three numbers of a `.ses` file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ses {
    pub images: u32,
    pub cameras: u32,
    pub lightings: u32,
}

impl Ses {
    /// Why these numbers cannot describe a session, if they cannot: every
    /// count is at least 1, lightings at most 26 (letters a–z).
    pub fn check(&self) -> Option<String> {
        if self.images == 0 || self.cameras == 0 || self.lightings == 0 {
            return Some(
                "images, cameras and lighting configurations must each be at least 1".into(),
            );
        }
        if self.lightings > MAX_LIGHTINGS {
            return Some(format!(
                "{} lighting configurations: at most {MAX_LIGHTINGS} (letters a to z)",
                self.lightings
            ));
        }
        None
    }
}

const WHAT: [&str; 3] = [
    "the number of images",
    "the number of cameras",
    "the number of lighting configurations",
];

/// Parses `.ses` text; `path` names the file in errors.
pub fn parse_ses(text: &str, path: &Path) -> Result<Ses, FormatError> {
    let mut nums = [0u32; 3];
    let mut seen = 0;
    let mut last = 1;
    for (n, line) in numbered_lines(text) {
        last = n;
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let Some(what) = WHAT.get(seen) else {
            return Err(FormatError::at_line(
                path,
                n,
                K::Syntax,
                format!(
                    "a .ses file holds exactly three numbers; found more: \"{}\"",
                    shorten(t)
                ),
            ));
        };
        let v: u32 = t.parse().map_err(|_| {
            FormatError::at_line(
                path,
                n,
                K::Syntax,
                format!("expected {what} (a whole number), found \"{}\"", shorten(t)),
            )
        })?;
        let max = if seen == 2 { MAX_LIGHTINGS } else { u32::MAX };
        if v == 0 || v > max {
            return Err(FormatError::at_line(
                path,
                n,
                K::Range,
                format!("{what} is {v}; allowed 1 to {max}"),
            ));
        }
        if let Some(slot) = nums.get_mut(seen) {
            *slot = v;
        }
        seen += 1;
    }
    if let Some(what) = WHAT.get(seen) {
        return Err(FormatError::at_line(
            path,
            last,
            K::Missing,
            format!("file ends before {what}; a .ses file holds three numbers, one per line"),
        ));
    }
    Ok(Ses {
        images: nums[0],
        cameras: nums[1],
        lightings: nums[2],
    })
}

/// The `.ses` text: three numbers, one per line.
pub fn format_ses(s: &Ses) -> String {
    format!("{}\n{}\n{}\n", s.images, s.cameras, s.lightings)
}

/// Reads a `.ses` file.
pub fn read_ses(path: &Path) -> Result<Ses, FormatError> {
    parse_ses(&read_text(path)?, path)
}

#[cfg(test)]
mod tests {
    use super::super::Location;
    use super::*;

    #[test]
    fn three_numbers() {
        let s = parse_ses("8\r\n4\r\n5\r\n\r\n", Path::new("cube.ses")).unwrap();
        assert_eq!(
            s,
            Ses {
                images: 8,
                cameras: 4,
                lightings: 5
            }
        );
        assert_eq!(format_ses(&s), "8\n4\n5\n");
        let e = parse_ses("8\n4\n", Path::new("cube.ses")).unwrap_err();
        assert_eq!((e.kind, e.location), (K::Missing, Location::Line(2)));
        let e = parse_ses("8\n4\n5\n6\n", Path::new("cube.ses")).unwrap_err();
        assert_eq!((e.kind, e.location), (K::Syntax, Location::Line(4)));
        let e = parse_ses("8\n4\n27\n", Path::new("cube.ses")).unwrap_err();
        assert_eq!((e.kind, e.location), (K::Range, Location::Line(3)));
    }
}
