//! Parameter files `.par` (formats.md §3), the exchange format with the
//! cell's other programs: `n "set name"`, then `n` lines `index value`, then
//! `n` lines `index "name" type` (type `i` int, `b` bool 0/1, `f` float, `F`
//! file name, `s` string).
//!
//! The LLV parameters map to parameter files one set per stage: the set is
//! named `vss lens`, `vss edges`, `vss lines`, `vss connect` (or `vss all`),
//! each entry is named with the parameter's profile key (`edges.per_region`),
//! typed `i`, `b` or `f` after the parameter's kind, and holds its value
//! (integers in decimal, booleans 0/1, floats with the shortest digits that
//! read back the same number). Import applies every entry whose name is a
//! parameter key, with the range check of [`crate::llv::params`], and notes
//! the others.

use std::path::Path;

use super::{
    FormatError, FormatErrorKind as K, Location, numbered_lines, read_text, shorten, write_bytes,
};
use crate::llv::Params;
use crate::llv::params::{Kind, PARAMS, Stage};

/// The type letter of an entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ParType {
    /// `i`
    Int,
    /// `b` (0 or 1)
    Bool,
    /// `f`
    Float,
    /// `F` (a file name)
    File,
    /// `s`
    Str,
}

impl ParType {
    pub fn letter(self) -> char {
        match self {
            ParType::Int => 'i',
            ParType::Bool => 'b',
            ParType::Float => 'f',
            ParType::File => 'F',
            ParType::Str => 's',
        }
    }
    pub fn from_letter(s: &str) -> Option<ParType> {
        Some(match s {
            "i" => ParType::Int,
            "b" => ParType::Bool,
            "f" => ParType::Float,
            "F" => ParType::File,
            "s" => ParType::Str,
            _ => return None,
        })
    }
    /// Why `value` is not a valid value of this type, if it is not.
    pub fn check(self, value: &str) -> Option<String> {
        match self {
            ParType::Int => value.parse::<i64>().is_err().then(|| {
                format!(
                    "expected a whole number (type i), found \"{}\"",
                    shorten(value)
                )
            }),
            ParType::Bool => (value != "0" && value != "1")
                .then(|| format!("expected 0 or 1 (type b), found \"{}\"", shorten(value))),
            ParType::Float => match value.parse::<f64>() {
                Ok(v) if v.is_finite() => None,
                _ => Some(format!(
                    "expected a finite number (type f), found \"{}\"",
                    shorten(value)
                )),
            },
            ParType::File | ParType::Str => None,
        }
    }
}

/// One entry: its description, type and value (as written; see
/// [`ParType::check`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParEntry {
    pub name: String,
    pub kind: ParType,
    pub value: String,
}

/// A parameter set.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ParFile {
    pub name: String,
    pub entries: Vec<ParEntry>,
}

/// Parses `.par` text; `path` names the file in errors.
pub fn parse_par(text: &str, path: &Path) -> Result<ParFile, FormatError> {
    parse_par_spanned(text, path).map(|(f, _)| f)
}

/// Splits `"name" rest` into the quoted text and the rest.
fn quoted(s: &str) -> Option<(&str, &str)> {
    let s = s.strip_prefix('"')?;
    let end = s.rfind('"')?;
    Some((s.get(..end)?, s.get(end + 1..)?))
}

/// Why `name` cannot stand in a `.par` file, if so: a `"` (the format has
/// no escape) or a control character. The reader and the writer both ask,
/// so what reads back is what was written.
fn name_problem(name: &str, what: &str) -> Option<String> {
    if let Some(at) = name.chars().position(|c| c == '"') {
        return Some(format!(
            "{what} holds a '\"' at character {}: names may not hold quotes",
            at + 1
        ));
    }
    control_problem(name, what)
}

/// Why `text` (a name or a value) cannot stand in a `.par` file, if so: a
/// control character, which would end its line or reach a terminal.
fn control_problem(text: &str, what: &str) -> Option<String> {
    let (at, c) = text.chars().enumerate().find(|(_, c)| c.is_control())?;
    Some(format!(
        "{what} holds the control character U+{:04X} at character {}: \
         .par files hold printable text",
        u32::from(c),
        at + 1
    ))
}

/// Like [`parse_par`], also returning the line of each entry's value.
pub fn parse_par_spanned(text: &str, path: &Path) -> Result<(ParFile, Vec<usize>), FormatError> {
    let all: Vec<(usize, &str)> = numbered_lines(text)
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    let mut lines = all.iter().copied();
    let err = |n: usize, kind: K, m: String| FormatError::at_line(path, n, kind, m);
    let Some((n1, first)) = lines.next() else {
        return Err(err(
            1,
            K::Missing,
            "empty parameter file: expected `n \"set name\"` on the first line".into(),
        ));
    };
    let first = first.trim();
    let (count, rest) = first.split_once(char::is_whitespace).unwrap_or((first, ""));
    let count: usize = count.parse().map_err(|_| {
        err(
            n1,
            K::Syntax,
            format!(
                "expected the entry count and the set's name in quotes, found \"{}\"",
                shorten(first)
            ),
        )
    })?;
    let Some((name, tail)) = quoted(rest.trim()) else {
        return Err(err(
            n1,
            K::Syntax,
            format!(
                "expected the set's name in double quotes after the count, found \"{}\"",
                shorten(rest)
            ),
        ));
    };
    if let Some(m) = name_problem(name, "the set's name") {
        return Err(err(n1, K::Syntax, m));
    }
    if !tail.trim().is_empty() {
        return Err(err(
            n1,
            K::Syntax,
            format!("unexpected \"{}\" after the set's name", shorten(tail)),
        ));
    }
    // The count is bounded by the file's real lines before anything is
    // allocated for it.
    let have = all.len().saturating_sub(1);
    if have < count.saturating_mul(2) {
        let last = all.last().map_or(n1, |(n, _)| *n);
        return Err(err(
            last,
            K::Missing,
            format!(
                "the set has {count} entries, which needs {} value and description lines; the file has {have}",
                count.saturating_mul(2)
            ),
        ));
    }
    // Values first (index → value, line), then descriptions.
    let mut values: Vec<Option<(String, usize)>> = vec![None; count];
    let mut descs: Vec<Option<(String, ParType)>> = vec![None; count];
    let mut last = n1;
    for _ in 0..count {
        let Some((n, l)) = lines.next() else {
            return Err(err(
                last,
                K::Missing,
                format!(
                    "file ends after {} of {count} value lines; expected \"index value\"",
                    values.iter().flatten().count()
                ),
            ));
        };
        last = n;
        let t = l.trim();
        let (i, v) = t.split_once(char::is_whitespace).unwrap_or((t, ""));
        let i = index(i, count, n, path)?;
        let slot = slot(&mut values, i, n, path)?;
        if slot.is_some() {
            return Err(err(n, K::Syntax, format!("value of entry {i} given twice")));
        }
        if let Some(m) = control_problem(v.trim(), &format!("the value of entry {i}")) {
            return Err(err(n, K::Syntax, m));
        }
        *slot = Some((v.trim().to_string(), n));
    }
    for _ in 0..count {
        let Some((n, l)) = lines.next() else {
            return Err(err(
                last,
                K::Missing,
                format!(
                    "file ends after {} of {count} description lines; expected `index \"name\" type`",
                    descs.iter().flatten().count()
                ),
            ));
        };
        last = n;
        let t = l.trim();
        let (i, rest) = t.split_once(char::is_whitespace).unwrap_or((t, ""));
        let i = index(i, count, n, path)?;
        let Some((dname, ty)) = quoted(rest.trim()) else {
            return Err(err(
                n,
                K::Syntax,
                format!("expected `index \"name\" type`, found \"{}\"", shorten(t)),
            ));
        };
        if let Some(m) = name_problem(dname, "the name") {
            return Err(err(n, K::Syntax, m));
        }
        let Some(ty) = ParType::from_letter(ty.trim()) else {
            return Err(err(
                n,
                K::Syntax,
                format!(
                    "expected type i, b, f, F or s, found \"{}\"",
                    shorten(ty.trim())
                ),
            ));
        };
        let slot = slot(&mut descs, i, n, path)?;
        if slot.is_some() {
            return Err(err(
                n,
                K::Syntax,
                format!("description of entry {i} given twice"),
            ));
        }
        *slot = Some((dname.to_string(), ty));
    }
    if let Some((n, l)) = lines.next() {
        return Err(err(
            n,
            K::Syntax,
            format!(
                "expected the end of the file after {count} entries, found \"{}\"",
                shorten(l.trim())
            ),
        ));
    }
    let mut f = ParFile {
        name: name.to_string(),
        entries: Vec::with_capacity(count),
    };
    let mut spans = Vec::with_capacity(count);
    for (v, d) in values.into_iter().zip(descs) {
        // Every index 0..count was seen exactly once (count lines, no repeats).
        let (Some((value, line)), Some((name, kind))) = (v, d) else {
            return Err(err(
                last,
                K::Missing,
                "an entry lacks its value or description".into(),
            ));
        };
        if let Some(m) = kind.check(&value) {
            return Err(err(
                line,
                K::Syntax,
                format!("entry {} \"{}\": {m}", f.entries.len(), shorten(&name)),
            ));
        }
        f.entries.push(ParEntry { name, kind, value });
        spans.push(line);
    }
    Ok((f, spans))
}

fn index(tok: &str, count: usize, n: usize, path: &Path) -> Result<usize, FormatError> {
    match tok.parse::<usize>() {
        Ok(i) if i < count => Ok(i),
        Ok(i) => Err(FormatError::at_line(
            path,
            n,
            K::Range,
            format!(
                "index {i} out of range: expected 0 to {}",
                count.saturating_sub(1)
            ),
        )),
        Err(_) => Err(FormatError::at_line(
            path,
            n,
            K::Syntax,
            format!("expected an entry index, found \"{}\"", shorten(tok)),
        )),
    }
}

fn slot<'a, T>(
    v: &'a mut [Option<T>],
    i: usize,
    n: usize,
    path: &Path,
) -> Result<&'a mut Option<T>, FormatError> {
    v.get_mut(i)
        .ok_or_else(|| FormatError::at_line(path, n, K::Range, format!("index {i} out of range")))
}

/// The `.par` text of a set, exactly as formats.md §3 lays it out.
pub fn format_par(f: &ParFile) -> String {
    let mut s = format!("{} \"{}\"\n", f.entries.len(), f.name);
    for (i, e) in f.entries.iter().enumerate() {
        s.push_str(&format!("{i} {}\n", e.value));
    }
    for (i, e) in f.entries.iter().enumerate() {
        s.push_str(&format!("{i} \"{}\" {}\n", e.name, e.kind.letter()));
    }
    s
}

/// Why a set cannot be written so that it reads back the same, if so.
pub fn check_writable(f: &ParFile) -> Option<String> {
    if let Some(m) = name_problem(&f.name, "the set's name") {
        return Some(m);
    }
    for (i, e) in f.entries.iter().enumerate() {
        if let Some(m) = name_problem(&e.name, "the name") {
            return Some(format!("entry {i}: {m}"));
        }
        if let Some(m) = control_problem(&e.value, "the value") {
            return Some(format!("entry {i}: {m}"));
        }
        if e.value.trim() != e.value {
            return Some(format!("entry {i}: the value may not have outer spaces"));
        }
        if let Some(m) = e.kind.check(&e.value) {
            return Some(format!("entry {i} \"{}\": {m}", e.name));
        }
    }
    None
}

/// Reads a `.par` file.
pub fn read_par(path: &Path) -> Result<ParFile, FormatError> {
    parse_par(&read_text(path)?, path)
}

/// Writes a `.par` file atomically; see [`check_writable`].
pub fn write_par(path: &Path, f: &ParFile) -> Result<(), FormatError> {
    if let Some(m) = check_writable(f) {
        return Err(FormatError::new(path, Location::None, K::Range, m));
    }
    write_bytes(path, format_par(f).as_bytes())
}

/// Which LLV parameters a parameter file carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamSet {
    Lens,
    Edges,
    Lines,
    Connect,
    All,
}

impl ParamSet {
    pub const ALL: [ParamSet; 5] = [
        ParamSet::Lens,
        ParamSet::Edges,
        ParamSet::Lines,
        ParamSet::Connect,
        ParamSet::All,
    ];

    /// `edges`, `lines`, …
    pub fn key(self) -> &'static str {
        match self {
            ParamSet::Lens => "lens",
            ParamSet::Edges => "edges",
            ParamSet::Lines => "lines",
            ParamSet::Connect => "connect",
            ParamSet::All => "all",
        }
    }
    pub fn parse(s: &str) -> Option<ParamSet> {
        ParamSet::ALL.into_iter().find(|p| p.key() == s)
    }
    /// The set's name in a parameter file: `vss edges`.
    pub fn file_name(self) -> String {
        format!("vss {}", self.key())
    }
    fn includes(self, st: Stage) -> bool {
        match self {
            ParamSet::Lens => st == Stage::Lens,
            ParamSet::Edges => st == Stage::Edges,
            ParamSet::Lines => st == Stage::Lines,
            ParamSet::Connect => st == Stage::Connect,
            ParamSet::All => true,
        }
    }
}

/// A parameter set of the LLV parameters (see the module doc for the mapping).
pub fn from_params(p: &Params, set: ParamSet) -> ParFile {
    let entries = PARAMS
        .iter()
        .filter(|sp| set.includes(sp.stage))
        .map(|sp| {
            let v = p.get(sp.key).unwrap_or(0.0);
            let (kind, value) = match sp.kind {
                Kind::Bool => (ParType::Bool, if v != 0.0 { "1" } else { "0" }.to_string()),
                Kind::Int => (ParType::Int, format!("{}", v as i64)),
                Kind::Float => (ParType::Float, format!("{v}")),
            };
            ParEntry {
                name: sp.key.to_string(),
                kind,
                value,
            }
        })
        .collect();
    ParFile {
        name: set.file_name(),
        entries,
    }
}

/// Parses `.par` text and applies it to `base` (errors name the value line).
pub fn import_params(
    text: &str,
    path: &Path,
    base: &Params,
) -> Result<(Params, Vec<String>), FormatError> {
    let (f, spans) = parse_par_spanned(text, path)?;
    let mut p = base.clone();
    let notes = apply(&f, Some(&spans), &mut p, path)?;
    Ok((p, notes))
}

fn apply(
    f: &ParFile,
    spans: Option<&[usize]>,
    p: &mut Params,
    path: &Path,
) -> Result<Vec<String>, FormatError> {
    let mut notes = Vec::new();
    for (i, e) in f.entries.iter().enumerate() {
        let loc = spans
            .and_then(|s| s.get(i))
            .map_or(Location::None, |&l| Location::Line(l));
        let Some(sp) = crate::llv::params::spec(&e.name) else {
            notes.push(format!(
                "entry {i} \"{}\" is not an LLV parameter: ignored",
                shorten(&e.name)
            ));
            continue;
        };
        let v: f64 = match e.value.parse() {
            Ok(v) => v,
            Err(_) => {
                return Err(FormatError::new(
                    path,
                    loc,
                    K::Syntax,
                    format!(
                        "{}: expected a number, found \"{}\"",
                        sp.key,
                        shorten(&e.value)
                    ),
                ));
            }
        };
        p.set(sp.key, v)
            .map_err(|er| FormatError::new(path, loc, K::Range, er.to_string()))?;
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "4 \"Demo parameter set\"\n0 2\n1 1\n2 test.img\n3 .54321875\n\
0 \"Number of cameras\" i\n1 \"Apply Lens correction\" b\n2 \"Output file name\" F\n3 \"Arbitrary threshold\" f\n";

    #[test]
    fn spec_example_reads_and_writes_back() {
        let f = parse_par(SPEC, Path::new("demo.par")).unwrap();
        assert_eq!(f.name, "Demo parameter set");
        assert_eq!(f.entries[3].value, ".54321875");
        assert_eq!(f.entries[2].kind, ParType::File);
        assert_eq!(format_par(&f), SPEC);
    }

    #[test]
    fn params_round_trip_through_par() {
        let mut p = Params::default();
        p.set("edges.floor", 3.75).unwrap();
        p.set("connect.enabled", 0.0).unwrap();
        let f = from_params(&p, ParamSet::All);
        assert_eq!(f.entries.len(), PARAMS.len());
        let (q, notes) =
            import_params(&format_par(&f), Path::new("a.par"), &Params::default()).unwrap();
        assert_eq!(q, p);
        assert!(notes.is_empty());
    }

    #[test]
    fn out_of_range_names_the_line() {
        let t = "1 \"vss edges\"\n0 99\n0 \"edges.half_width\" i\n";
        let e = import_params(t, Path::new("e.par"), &Params::default()).unwrap_err();
        assert_eq!(e.location, Location::Line(2));
        assert!(e.message.contains("3 to 7"), "{e}");
    }
}
