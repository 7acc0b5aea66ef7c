//! The VSS file-name scheme (formats.md §1): `session + image [+ lighting]
//! + "." + extension`, e.g. `cube7b.img` is grey image 7 of session `cube`
//! under lighting `b`.
//!
//! Session names are 1–32 characters of `A–Z a–z 0–9 _ -`, not starting
//! with a digit or `-`, because the name becomes a file name. The old DOS
//! limit (name + image number ≤ 8 characters) is only a warning.
//! A session name that ends in a digit makes names ambiguous (`cube71.img`:
//! `cube` 71 or `cube7` 1?); [`VssFile::parse`] reads the digits as the image
//! number, [`VssFile::parse_in`] resolves it with the known session.

use std::fmt;

/// Longest session name.
pub const MAX_SESSION_LEN: usize = 32;

/// A name that cannot be a session or VSS file name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    #[error("session name is empty; use 1 to {MAX_SESSION_LEN} letters, digits, _ or -")]
    Empty,
    #[error("session name is {len} characters long; at most {MAX_SESSION_LEN}")]
    TooLong { len: usize },
    #[error(
        "session name {name:?} contains a path separator; a session name becomes a file name, use letters, digits, _ or -"
    )]
    PathSeparator { name: String },
    #[error("session name {name:?} contains \"..\"; use letters, digits, _ or -")]
    DotDot { name: String },
    #[error(
        "session name contains a control character at position {pos}; use letters, digits, _ or -"
    )]
    Control { pos: usize },
    #[error("session name {name:?} starts with {c:?}; it must start with a letter or _")]
    BadStart { name: String, c: char },
    #[error(
        "session name {name:?} contains {c:?} at position {pos}; use only the letters a-z and A-Z, digits, _ or -"
    )]
    BadChar { name: String, c: char, pos: usize },
    #[error(
        "{name:?} is not a VSS file name: {why} (expected session + image number [+ lighting letter] + \".\" + extension, e.g. cube7b.img)"
    )]
    File { name: String, why: String },
}

/// A checked session name.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SessionName(String);

impl SessionName {
    pub fn new(s: &str) -> Result<Self, NameError> {
        let shown = || {
            s.chars()
                .filter(|c| !c.is_control())
                .take(40)
                .collect::<String>()
        };
        if s.is_empty() {
            return Err(NameError::Empty);
        }
        if let Some(pos) = s.chars().position(char::is_control) {
            return Err(NameError::Control { pos: pos + 1 });
        }
        if s.contains('/') || s.contains('\\') {
            return Err(NameError::PathSeparator { name: shown() });
        }
        if s.contains("..") {
            return Err(NameError::DotDot { name: shown() });
        }
        let len = s.chars().count();
        if len > MAX_SESSION_LEN {
            return Err(NameError::TooLong { len });
        }
        let ok = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
        if let Some((pos, c)) = s.chars().enumerate().find(|&(_, c)| !ok(c)) {
            return Err(NameError::BadChar {
                name: shown(),
                c,
                pos: pos + 1,
            });
        }
        if let Some(c) = s.chars().next().filter(|c| c.is_ascii_digit() || *c == '-') {
            return Err(NameError::BadStart { name: shown(), c });
        }
        Ok(SessionName(s.to_string()))
    }
    pub fn as_str(&self) -> &str {
        &self.0
    }
    /// The DOS-rule warning for image `image` (name + number > 8
    /// characters), if it applies.
    pub fn dos_warning(&self, image: u32) -> Option<String> {
        let n = self.0.len() + image.to_string().len();
        (n > 8).then(|| {
            format!(
                "\"{}{image}\" is {n} characters: older DOS tools of the cell expect session name + image number to be at most 8",
                self.0
            )
        })
    }
}

impl fmt::Display for SessionName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// One file of a session: `cube7b.img`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VssFile {
    pub session: SessionName,
    /// 1-based image number.
    pub image: u32,
    /// The lighting letter `a`–`z` (grey images only).
    pub lighting: Option<char>,
    /// The extension without the dot: `img`, `hpo`, …
    pub ext: String,
}

impl VssFile {
    /// The file name: `cube7b.img`.
    pub fn file_name(&self) -> String {
        let mut s = format!("{}{}", self.session, self.image);
        if let Some(l) = self.lighting {
            s.push(l);
        }
        s.push('.');
        s.push_str(&self.ext);
        s
    }

    /// Parses a file name, reading all trailing digits of the stem as the
    /// image number.
    pub fn parse(name: &str) -> Result<Self, NameError> {
        Self::parse_with(name, None)
    }

    /// Parses a file name of a known session (resolves names whose session
    /// ends in a digit).
    pub fn parse_in(name: &str, session: &SessionName) -> Result<Self, NameError> {
        Self::parse_with(name, Some(session))
    }

    fn parse_with(name: &str, session: Option<&SessionName>) -> Result<Self, NameError> {
        let bad = |why: &str| NameError::File {
            name: name.chars().filter(|c| !c.is_control()).take(60).collect(),
            why: why.to_string(),
        };
        let (stem, ext) = name.rsplit_once('.').ok_or_else(|| bad("no extension"))?;
        if ext.is_empty() || !ext.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(bad("the extension must be letters or digits"));
        }
        let (stem, lighting) = match stem.chars().last() {
            Some(c)
                if c.is_ascii_lowercase()
                    && stem[..stem.len() - 1].ends_with(|d: char| d.is_ascii_digit()) =>
            {
                (&stem[..stem.len() - 1], Some(c))
            }
            _ => (stem, None),
        };
        let (sess, digits) = match session {
            Some(s) => {
                let d = stem
                    .strip_prefix(s.as_str())
                    .ok_or_else(|| bad("it does not start with the session name"))?;
                (s.as_str(), d)
            }
            None => {
                let cut = stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
                (&stem[..cut], &stem[cut..])
            }
        };
        if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
            return Err(bad("no image number after the session name"));
        }
        let image: u32 = digits
            .parse()
            .map_err(|_| bad("the image number is too large"))?;
        if image == 0 {
            return Err(bad("image numbers start at 1"));
        }
        let session = SessionName::new(sess).map_err(|e| bad(&e.to_string()))?;
        Ok(VssFile {
            session,
            image,
            lighting,
            ext: ext.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_and_parse() {
        let f = VssFile::parse("cube7b.img").unwrap();
        assert_eq!(f.session.as_str(), "cube");
        assert_eq!((f.image, f.lighting, f.ext.as_str()), (7, Some('b'), "img"));
        assert_eq!(f.file_name(), "cube7b.img");
        let f = VssFile::parse("test1.ldr").unwrap();
        assert_eq!((f.image, f.lighting), (1, None));
        let s = SessionName::new("cube7").unwrap();
        let f = VssFile::parse_in("cube71a.img", &s).unwrap();
        assert_eq!((f.session.as_str(), f.image), ("cube7", 1));
        assert!(VssFile::parse("cube.img").is_err());
        assert!(VssFile::parse("cube0.img").is_err());
    }

    #[test]
    fn bad_session_names() {
        assert!(matches!(SessionName::new(""), Err(NameError::Empty)));
        assert!(matches!(
            SessionName::new("a/b"),
            Err(NameError::PathSeparator { .. })
        ));
        assert!(matches!(
            SessionName::new("a..b"),
            Err(NameError::DotDot { .. })
        ));
        assert!(matches!(
            SessionName::new("a\nb"),
            Err(NameError::Control { .. })
        ));
        assert!(matches!(
            SessionName::new("7up"),
            Err(NameError::BadStart { .. })
        ));
        assert!(matches!(
            SessionName::new("-x"),
            Err(NameError::BadStart { .. })
        ));
        assert!(matches!(
            SessionName::new("a b"),
            Err(NameError::BadChar { .. })
        ));
        assert!(matches!(
            SessionName::new(&"a".repeat(33)),
            Err(NameError::TooLong { .. })
        ));
        assert!(SessionName::new(&"a".repeat(32)).is_ok());
        let s = SessionName::new("cube").unwrap();
        assert!(s.dos_warning(7).is_none());
        assert!(
            SessionName::new("longname")
                .unwrap()
                .dos_warning(7)
                .is_some()
        );
    }
}
