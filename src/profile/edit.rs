//! Changing a profile's LLV parameters in its own text, so the comments and
//! layout a person wrote survive `vss params import … --out`: each changed
//! value is replaced where it stands; a key the file lacks is added under its
//! `[llv.<group>]` header (or in a new such table at the end). The result is
//! parsed back and must load with exactly the asked parameters.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};

use super::{Profile, ProfileError};
use crate::llv::Params;
use crate::llv::params::{Kind, PARAMS};

/// The TOML text of a parameter value.
pub fn toml_value(kind: Kind, v: f64) -> String {
    match kind {
        Kind::Bool => (v != 0.0).to_string(),
        Kind::Int => format!("{}", v as i64),
        // Debug keeps a `.0` or an exponent, so TOML reads a float.
        Kind::Float => format!("{v:?}"),
    }
}

fn value_span(doc: &DeTable<'_>, group: &str, name: &str) -> Option<Range<usize>> {
    let llv = doc.iter().find(|(k, _)| k.get_ref().as_ref() == "llv")?.1;
    let DeValue::Table(llv) = llv.get_ref() else {
        return None;
    };
    let g = llv.iter().find(|(k, _)| k.get_ref().as_ref() == group)?.1;
    let DeValue::Table(g) = g.get_ref() else {
        return None;
    };
    g.iter()
        .find(|(k, _)| k.get_ref().as_ref() == name)
        .map(|(_, v)| v.span())
}

/// `text` (a profile) with its `[llv.*]` values replaced by `params`.
pub fn set_llv(text: &str, path: &Path, params: &Params) -> Result<String, ProfileError> {
    let invalid = |line: usize, message: String| ProfileError::Invalid {
        path: path.to_path_buf(),
        line,
        message,
    };
    let current = Profile::from_toml(text, path)?;
    let doc = DeTable::parse(text)
        .map_err(|e| invalid(1, format!("not valid TOML: {}", e.message().trim())))?;
    let mut replace: Vec<(Range<usize>, String)> = Vec::new();
    let mut missing: Vec<(&str, &str, String)> = Vec::new();
    for sp in PARAMS {
        let (Some(old), Some(new)) = (current.llv.get(sp.key), params.get(sp.key)) else {
            continue;
        };
        let (group, name) = sp.key.split_once('.').unwrap_or(("", sp.key));
        match value_span(doc.get_ref(), group, name) {
            Some(r) if old != new => replace.push((r, toml_value(sp.kind, new))),
            Some(_) => {}
            None if old != new => missing.push((group, name, toml_value(sp.kind, new))),
            None => {}
        }
    }
    let mut out = text.to_string();
    replace.sort_by_key(|(r, _)| std::cmp::Reverse(r.start));
    for (r, v) in replace {
        if out.get(r.clone()).is_some() {
            out.replace_range(r, &v);
        }
    }
    for (group, name, v) in missing {
        let header = format!("[llv.{group}]");
        let at = find_header_end(&out, &header);
        match at {
            Some(i) => out.insert_str(i, &format!("{name} = {v}\n")),
            None => {
                if !out.ends_with('\n') && !out.is_empty() {
                    out.push('\n');
                }
                out.push_str(&format!("\n{header}\n{name} = {v}\n"));
            }
        }
    }
    let check = Profile::from_toml(&out, path)?;
    if check.llv != *params {
        return Err(invalid(
            1,
            "cannot place the new [llv] values in this file's layout; write the parameters to a new profile instead".into(),
        ));
    }
    Ok(out)
}

/// Byte offset just after the line `header` (its trimmed text), if present.
fn find_header_end(text: &str, header: &str) -> Option<usize> {
    let mut off = 0;
    for line in text.split_inclusive('\n') {
        off += line.len();
        if line.trim() == header {
            if !line.ends_with('\n') {
                return None;
            }
            return Some(off);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "name = \"t\"\n[[lights]]\nname = \"l\"\nrelay = 0\n[[lighting]]\nletter = \"a\"\non = [\"l\"]\n\
# edges, tuned by hand\n[llv.edges]\nhalf_width = 4 # A\nfloor = 2.0\n";

    #[test]
    fn values_replaced_in_place_and_keys_added() {
        let mut p = Params::default();
        p.edges.half_width = 5;
        p.edges.floor = 3.5;
        p.edges.per_region = 12;
        p.connect.wl = 7.25;
        let out = set_llv(BASE, Path::new("t.toml"), &p).unwrap();
        assert!(out.contains("half_width = 5 # A\n"), "{out}");
        assert!(out.contains("# edges, tuned by hand"));
        assert!(out.contains("per_region = 12"));
        assert!(out.contains("[llv.connect]\nwl = 7.25"));
        assert_eq!(
            Profile::from_toml(&out, Path::new("t.toml")).unwrap().llv,
            p
        );
    }
}
