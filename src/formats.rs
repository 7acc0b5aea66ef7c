//! The cell's file formats (spec/formats.md): grey images (`.img`/`.imc` and
//! the common image formats), camera descriptions (`.cdf`), line files
//! (`.lex`/`.ldr`), edge-point files (`.hpo`/`.vpo`), parameter files (`.par`),
//! session files (`.ses`) and the VSS file-name scheme.
//!
//! Writers produce exactly the layouts of the spec and go through
//! [`crate::fsutil::write_atomic`]; readers accept what the spec allows and
//! refuse the rest with a [`FormatError`] that names the file, the line or
//! byte offset, and what was expected. No reader panics, and none allocates
//! more than the file's real size justifies.

use std::fmt;
use std::path::{Path, PathBuf};

pub mod cdf;
pub mod edgefile;
pub mod imageio;
pub mod img;
pub mod lines;
pub mod names;
pub mod par;
pub mod pixels;
pub mod ses;

/// Where in a file an error was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// The file as a whole (cannot be opened, empty, …).
    None,
    /// A 1-based line number of a text file.
    Line(usize),
    /// A 0-based byte offset of a binary file.
    Byte(u64),
}

/// What went wrong, for code that reacts to it (tests, the console).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatErrorKind {
    /// The file cannot be read or written.
    Io,
    /// The file ends before what its header or layout promises.
    Truncated,
    /// The file's size does not match its header.
    SizeMismatch,
    /// A valid but unsupported variant (compressed `.img`, unknown extension).
    Unsupported,
    /// Text where a number belongs, a malformed line, a wrong magic.
    Syntax,
    /// A number outside what the format or the cell allows (NaN, too large).
    Range,
    /// Not UTF-8 (text formats) or a character the format cannot hold.
    Encoding,
    /// Something required is absent (`Faces:`, a parameter, a value line).
    Missing,
}

/// A file that could not be read or written. Displays as
/// `cube1.ldr:14: expected "start end", found "3 x"` or
/// `cube1a.img: byte 12: …`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormatError {
    pub path: PathBuf,
    pub location: Location,
    pub kind: FormatErrorKind,
    pub message: String,
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = crate::text::path(&self.path);
        match self.location {
            Location::None => write!(f, "{p}: {}", self.message),
            Location::Line(n) => write!(f, "{p}:{n}: {}", self.message),
            Location::Byte(b) => write!(f, "{p}: byte {b}: {}", self.message),
        }
    }
}

impl std::error::Error for FormatError {}

impl FormatError {
    /// Where and what, without the file's name (which the caller's message
    /// names already): `line 9: D needs 5 value line(s), found 1`.
    pub fn located(&self) -> String {
        match self.location {
            Location::None => self.message.clone(),
            Location::Line(n) => format!("line {n}: {}", self.message),
            Location::Byte(b) => format!("byte {b}: {}", self.message),
        }
    }

    pub fn new(
        path: &Path,
        location: Location,
        kind: FormatErrorKind,
        message: impl Into<String>,
    ) -> Self {
        FormatError {
            path: path.to_path_buf(),
            location,
            kind,
            message: message.into(),
        }
    }

    /// An error at a 1-based line of a text file.
    pub fn at_line(
        path: &Path,
        line: usize,
        kind: FormatErrorKind,
        message: impl Into<String>,
    ) -> Self {
        Self::new(path, Location::Line(line), kind, message)
    }

    /// An error at a byte offset of a binary file.
    pub fn at_byte(
        path: &Path,
        byte: u64,
        kind: FormatErrorKind,
        message: impl Into<String>,
    ) -> Self {
        Self::new(path, Location::Byte(byte), kind, message)
    }

    /// An I/O error on the file as a whole.
    pub fn io(path: &Path, what: &str, e: &std::io::Error) -> Self {
        Self::new(
            path,
            Location::None,
            FormatErrorKind::Io,
            format!("cannot {what}: {e}"),
        )
    }
}

/// The largest file of each kind a reader takes, from what its format
/// allows (the cell's files are far smaller; these only stop a hostile or
/// broken file from costing gigabytes):
/// - `.img`/`.imc`: the 64-byte header, a 200-byte comment and 65535 × 65535
///   pixels, the most its 16-bit size fields can describe;
/// - `.hpo`/`.vpo`: a header line and 12 bytes for each of up to
///   [`edgefile::MAX_POINTS`] points, 48 MiB;
/// - PNG, PGM, TIFF, BMP: 512 MiB (the decoded image may have at most
///   256 MiB, and none of these is larger than what it decodes to by much);
/// - `.lex`/`.ldr`: 256 MiB of text (about 4 M segments);
/// - `.cdf`, `.par`: 1 MiB of text; `.ses`: three numbers, 4 KiB;
/// - anything else: 16 MiB.
pub fn max_len(path: &Path) -> u64 {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "img" | "imc" => img::max_file_len(),
        "hpo" | "vpo" => edgefile::max_file_len(),
        "png" | "pgm" | "pnm" | "tif" | "tiff" | "bmp" => 512 << 20,
        "lex" | "ldr" => 256 << 20,
        "cdf" | "par" => 1 << 20,
        "ses" => 4 << 10,
        _ => 16 << 20,
    }
}

/// Reads a whole file through [`crate::fsutil::read_input`]: a regular file,
/// not through a link, at most [`max_len`] bytes.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, FormatError> {
    read_bytes_within(path, max_len(path))
}

/// [`read_bytes`] with an explicit bound.
pub(crate) fn read_bytes_within(path: &Path, limit: u64) -> Result<Vec<u8>, FormatError> {
    crate::fsutil::read_input(path, limit).map_err(|e| input_err(path, &e))
}

/// An error opening or reading an input file: a file over its bound is a
/// `Range` error, anything else `Io`.
pub(crate) fn input_err(path: &Path, e: &std::io::Error) -> FormatError {
    let kind = if e.kind() == std::io::ErrorKind::FileTooLarge {
        FormatErrorKind::Range
    } else {
        FormatErrorKind::Io
    };
    FormatError::new(path, Location::None, kind, format!("cannot read: {e}"))
}

/// Stages a file of a set written as one ([`crate::fsutil::StagedWrites`]),
/// mapping the error.
pub fn stage(
    set: &mut crate::fsutil::StagedWrites,
    path: &Path,
    bytes: &[u8],
) -> Result<(), FormatError> {
    set.stage(path, bytes)
        .map_err(|e| FormatError::io(path, "write", &e))
}

/// Writes a file atomically, mapping the error.
pub(crate) fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    crate::fsutil::write_atomic(path, bytes).map_err(|e| FormatError::io(path, "write", &e))
}

/// Decodes a text file's bytes as UTF-8; the error names the line and byte
/// of the first bad sequence.
pub(crate) fn decode_text<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str, FormatError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes
            .get(..at)
            .map_or(1, |b| b.iter().filter(|&&c| c == b'\n').count() + 1);
        FormatError::at_line(
            path,
            line,
            FormatErrorKind::Encoding,
            format!("not UTF-8 text (bad byte at offset {at}); expected a text file"),
        )
    })
}

/// Reads a text file as UTF-8, without a leading byte-order mark (which
/// some Windows editors add).
pub(crate) fn read_text(path: &Path) -> Result<String, FormatError> {
    Ok(text_of(&read_bytes(path)?, path)?.to_string())
}

/// A text file's bytes as [`read_text`] reads them: UTF-8, without a
/// leading byte-order mark.
pub(crate) fn text_of<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str, FormatError> {
    let text = decode_text(bytes, path)?;
    Ok(text.strip_prefix('\u{feff}').unwrap_or(text))
}

/// The lines of a text with their 1-based numbers, without `\r\n`/`\n`.
pub(crate) fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
}

/// Parses a finite float; NaN and infinities are refused (`Range`), text is
/// `Syntax`.
pub(crate) fn parse_f64(
    tok: &str,
    path: &Path,
    line: usize,
    what: &str,
) -> Result<f64, FormatError> {
    let v: f64 = tok.parse().map_err(|_| {
        FormatError::at_line(
            path,
            line,
            FormatErrorKind::Syntax,
            format!("expected {what} (a number), found \"{}\"", shorten(tok)),
        )
    })?;
    if !v.is_finite() {
        return Err(FormatError::at_line(
            path,
            line,
            FormatErrorKind::Range,
            format!("{what} must be a finite number, found \"{}\"", shorten(tok)),
        ));
    }
    Ok(v)
}

/// A number written with six decimals (`0.011250`, as the cell's other
/// programs write it) when that is exact, else with as many digits as it
/// takes to read back the same `f64`.
pub(crate) fn fmt_exact(v: f64) -> String {
    let six = format!("{v:.6}");
    if six.parse::<f64>().ok() == Some(v) {
        six
    } else {
        format!("{v}")
    }
}

/// At most 40 characters of a token, for error messages, control characters
/// shown as `?`.
pub(crate) fn shorten(s: &str) -> String {
    let mut out: String = s
        .chars()
        .take(40)
        .map(|c| if c.is_control() { '?' } else { c })
        .collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// A comment or name made safe to show to the operator (formats.md §2):
/// the crate's one sanitiser.
pub use crate::text::sanitize;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_and_place() {
        let e = FormatError::at_line(
            Path::new("cube1.ldr"),
            14,
            FormatErrorKind::Syntax,
            "expected \"start end\", found \"3 x\"",
        );
        assert_eq!(
            e.to_string(),
            "cube1.ldr:14: expected \"start end\", found \"3 x\""
        );
        let e = FormatError::at_byte(Path::new("a.img"), 12, FormatErrorKind::Unsupported, "x");
        assert_eq!(e.to_string(), "a.img: byte 12: x");
    }

    #[test]
    fn exact_numbers_keep_six_decimals() {
        assert_eq!(fmt_exact(0.01125), "0.011250");
        assert_eq!(fmt_exact(-88.393677), "-88.393677");
        let v = 0.000_527_123_456_7;
        assert_eq!(fmt_exact(v).parse::<f64>().unwrap(), v);
    }

    #[test]
    fn bad_utf8_names_line() {
        let e = decode_text(b"ok\nbad \xff", Path::new("x.cdf")).unwrap_err();
        assert_eq!(e.kind, FormatErrorKind::Encoding);
        assert_eq!(e.location, Location::Line(2));
    }
}
