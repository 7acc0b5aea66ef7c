//! Reading a manifest record by record. Parsing a whole TOML file into one
//! document tree costs 21 to 76 times its text in memory (issue 34, N5: a
//! 16 MiB manifest took 1.27 GB), and the console's session list reads
//! every manifest of the survey folder. So the text is first cut, with
//! `toml_parser`'s lexer (the one under `toml`, run as an iterator: no token
//! list is kept), into the `[[image]]` records and the rest (the root keys,
//! `[session]`, `[[lighting]]`, `[[calibration]]`); each image record is
//! then deserialized on its own and dropped before the next, so the peak is
//! the text, the [`Manifest`] built from it and one record's tree.
//!
//! The cut follows TOML's own rule: a table header is a `[` that begins a
//! line outside any value, and `[image.…]` headers belong to the last
//! `[[image]]` before them. Every byte of the text goes to exactly one
//! piece and every piece is parsed, so a syntax error anywhere is found;
//! an error's line is that of the whole file. A file the cut cannot follow
//! (a damaged one) ends up in the rest, which is parsed whole as before.

use std::ops::Range;
use std::path::Path;

use serde::Deserialize;
use toml_parser::Source;
use toml_parser::lexer::TokenKind;

use super::{ImageRecord, Manifest};
use crate::session::SessionError;

/// The most bytes one `[[image]]` record may take, and the part outside
/// the records (root keys, `[session]`, `[[lighting]]`,
/// `[[calibration]]`) together. A record's tree costs up to 77 times its
/// text (a 4 MiB manifest of one record took 325 MB), so the cap bounds a
/// read at the text plus about 20 MB. The largest record vss writes for a
/// real image — 26 lightings, every parameter changed, 100 lines'
/// attributes, 10 hand edits — takes 12 822 bytes (`session_big`), so the
/// cap is a margin of 20 times over it: room for some 5 000 lines'
/// attributes or 1 900 edits.
pub const MAX_RECORD_LEN: usize = 256 << 10;

/// One `[[image]]` record's text on its own: a document with one image.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OneImage {
    image: Vec<ImageRecord>,
}

/// The manifest text cut into pieces (byte ranges of the text).
#[derive(Debug, Default, PartialEq)]
struct Cut {
    /// Everything outside the `[[image]]` records, in file order.
    rest: Vec<Range<usize>>,
    /// Each `[[image]]` record, from its header to the next header that is
    /// not one of its sub-tables.
    images: Vec<Range<usize>>,
}

/// What a table header names: whether it is `[[…]]` and its first key.
struct Header {
    array: bool,
    /// The first key, decoded (`"image"` and `image` are the same key).
    first: String,
    /// More keys follow (`[image.grey]`).
    dotted: bool,
}

/// Cuts `text` at its table headers (see the module doc).
fn cut(text: &str) -> Cut {
    let source = Source::new(text);
    let mut tokens = source.lex().peekable();
    let mut out = Cut::default();
    // Where the current piece began, and whether it is an image record.
    let (mut start, mut in_image) = (0usize, false);
    // Nesting of `[` and `{` inside a value; a header opens only at 0.
    let mut depth = 0usize;
    // Only whitespace since the last line break.
    let mut line_start = true;
    let mut line_pos = 0usize;
    while let Some(t) = tokens.next() {
        let kind = t.kind();
        match kind {
            TokenKind::Newline => {
                line_start = true;
                line_pos = t.span().end();
                continue;
            }
            TokenKind::Whitespace => continue,
            TokenKind::Eof => break,
            _ => {}
        }
        let first_on_line = std::mem::replace(&mut line_start, false);
        if depth == 0 && first_on_line && kind == TokenKind::LeftSquareBracket {
            let h = header(&source, &mut tokens);
            let is_image = h.first == "image";
            let new_record = is_image && h.array && !h.dotted;
            // `[image.…]` stays with its record; anything else ends it.
            if new_record || (in_image && !is_image) {
                close(&mut out, start..line_pos, in_image);
                start = line_pos;
                in_image = new_record;
            }
            continue;
        }
        match kind {
            TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => depth += 1,
            TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => {
                depth = depth.saturating_sub(1);
            }
            _ => {}
        }
    }
    close(&mut out, start..text.len(), in_image);
    out
}

/// Ends a piece (empty ones are dropped).
fn close(out: &mut Cut, r: Range<usize>, image: bool) {
    if r.is_empty() {
        return;
    }
    if image {
        out.images.push(r);
    } else {
        out.rest.push(r);
    }
}

/// Reads a table header after its opening `[`, up to its last `]` or the
/// end of the line (a damaged header: the parse of its piece says what).
fn header<I: Iterator<Item = toml_parser::lexer::Token>>(
    source: &Source<'_>,
    tokens: &mut std::iter::Peekable<I>,
) -> Header {
    let mut h = Header {
        array: false,
        first: String::new(),
        dotted: false,
    };
    if tokens
        .peek()
        .is_some_and(|t| t.kind() == TokenKind::LeftSquareBracket)
    {
        h.array = true;
        tokens.next();
    }
    let mut keys = 0usize;
    while let Some(t) = tokens.peek() {
        match t.kind() {
            TokenKind::Newline | TokenKind::Eof => break,
            TokenKind::Whitespace | TokenKind::Comment => {}
            TokenKind::RightSquareBracket | TokenKind::Dot => {}
            _ => {
                if keys == 0
                    && let Some(raw) = source.get(*t)
                {
                    let mut key = String::new();
                    let mut errors: Option<toml_parser::ParseError> = None;
                    raw.decode_key(&mut key, &mut errors);
                    h.first = key;
                }
                keys += 1;
            }
        }
        tokens.next();
    }
    h.dotted = keys > 1;
    h
}

/// Whether every record of manifest text is within [`MAX_RECORD_LEN`]: what
/// the reader refuses, and the writer checks before it writes (so a session
/// never saves what it could not read back).
pub(crate) fn check_record_sizes(text: &str, path: &Path) -> Result<(), SessionError> {
    check_sizes(text, &cut(text), path, "nothing was written")
}

fn check_sizes(text: &str, pieces: &Cut, path: &Path, outcome: &str) -> Result<(), SessionError> {
    let too_big = |r: &Range<usize>, what: &str, len: usize| SessionError::Manifest {
        path: path.to_path_buf(),
        line: line_of(text, r.start),
        message: format!(
            "{what} takes {len} bytes, more than the {MAX_RECORD_LEN} one may take \
             (a real one takes about 13 KiB); {outcome}"
        ),
    };
    if let Some(r) = pieces.images.iter().find(|r| r.len() > MAX_RECORD_LEN) {
        return Err(too_big(r, "this [[image]] record", r.len()));
    }
    let rest_len: usize = pieces.rest.iter().map(|r| r.len()).sum();
    if rest_len > MAX_RECORD_LEN
        && let Some(first) = pieces.rest.first()
    {
        return Err(too_big(
            first,
            "the part outside the [[image]] records (session, lightings, calibrations)",
            rest_len,
        ));
    }
    Ok(())
}

/// Parses manifest text record by record into a [`Manifest`] (not yet
/// checked for sense); errors name `path` and the line in the whole file.
pub(super) fn parse(text: &str, path: &Path) -> Result<Manifest, SessionError> {
    let pieces = cut(text);
    check_sizes(text, &pieces, path, "nothing of the manifest was read")?;
    // The rest, made one text; `map` gives each of its pieces' offsets.
    let mut rest = String::with_capacity(pieces.rest.iter().map(|r| r.len()).sum());
    let mut map = Vec::with_capacity(pieces.rest.len());
    for r in &pieces.rest {
        map.push((rest.len(), r.start));
        rest.push_str(text.get(r.clone()).unwrap_or_default());
    }
    let at = |offset: usize| {
        let i = map.partition_point(|&(s, _)| s <= offset).saturating_sub(1);
        map.get(i).map_or(offset, |&(s, f)| f + (offset - s))
    };
    let mut m: Manifest = toml::from_str(&rest).map_err(|e| error(text, path, &e, at))?;
    if !m.image.is_empty()
        && let Some(first) = pieces.images.first()
    {
        return Err(SessionError::Manifest {
            path: path.to_path_buf(),
            line: line_of(text, first.start),
            message: "duplicate key `image`: the images are given both as a value and as \
                      [[image]] tables"
                .into(),
        });
    }
    m.image.reserve_exact(pieces.images.len());
    for r in &pieces.images {
        let one: OneImage = toml::from_str(text.get(r.clone()).unwrap_or_default())
            .map_err(|e| error(text, path, &e, |o| r.start + o))?;
        m.image.extend(one.image);
    }
    Ok(m)
}

/// A TOML error as the manifest's error: its message, and the line in the
/// whole file of where it points (`at` maps a piece's offset to the file's).
fn error(
    text: &str,
    path: &Path,
    e: &toml::de::Error,
    at: impl Fn(usize) -> usize,
) -> SessionError {
    SessionError::Manifest {
        path: path.to_path_buf(),
        line: e.span().map_or(0, |s| line_of(text, at(s.start))),
        message: e.message().trim().to_string(),
    }
}

/// The 1-based line of byte `offset` of `text`.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pieces(text: &str) -> (Vec<&str>, Vec<&str>) {
        let c = cut(text);
        let get = |v: &[Range<usize>]| v.iter().map(|r| &text[r.clone()]).collect::<Vec<_>>();
        (get(&c.rest), get(&c.images))
    }

    #[test]
    fn image_records_are_cut_with_their_sub_tables() {
        let text = "format = 1\n[session]\nname = \"s\"\n[[lighting]]\nletter = \"a\"\n\
                    [[image]]\nnumber = 1\n[[image.grey]]\nfile = \"x\"\n  [ \"image\" . outputs ]\n\
                    made = \"m\"\n[[ image ]] # two\nnumber = 2\n[[calibration]]\ncamera = 1\n";
        let (rest, images) = pieces(text);
        assert_eq!(
            rest,
            [
                "format = 1\n[session]\nname = \"s\"\n[[lighting]]\nletter = \"a\"\n",
                "[[calibration]]\ncamera = 1\n"
            ]
        );
        assert_eq!(
            images,
            [
                "[[image]]\nnumber = 1\n[[image.grey]]\nfile = \"x\"\n  [ \"image\" . outputs ]\nmade = \"m\"\n",
                "[[ image ]] # two\nnumber = 2\n"
            ]
        );
    }

    #[test]
    fn brackets_inside_values_and_strings_are_not_headers() {
        let text = "[[lighting]]\non = [\n[\"a\"],\n]\nnote = \"\"\"\n[[image]]\n\"\"\"\n\
                    t = {\nx = [1],\n}\n[[image]]\nnumber = 1\n";
        let (rest, images) = pieces(text);
        assert_eq!(rest.len(), 1, "{rest:?}");
        assert!(rest[0].ends_with("}\n"), "{rest:?}");
        assert_eq!(images, ["[[image]]\nnumber = 1\n"]);
    }

    #[test]
    fn an_image_table_before_any_record_stays_in_the_rest() {
        // Not a record: the rest's parse says what is wrong with it.
        let (rest, images) = pieces("[image.grey]\nx = 1\n[[image]]\nnumber = 1\n");
        assert_eq!(rest, ["[image.grey]\nx = 1\n"]);
        assert_eq!(images, ["[[image]]\nnumber = 1\n"]);
    }
}
