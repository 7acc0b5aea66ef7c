//! Changing a profile's LLV parameters in its own text, so the comments and
//! layout a person wrote survive `vss params import … --out`: each changed
//! value is replaced where it stands, with the comment beside it; a key the
//! file lacks is added to its `[llv.<group>]` table (or to a new such table
//! at the end). `toml_edit` keeps everything it does not touch as it was.
//! The result is parsed back and must load with exactly the asked
//! parameters.

use std::path::Path;

use toml_edit::{DocumentMut, Item, Table, Value};

use super::{Profile, ProfileError};
use crate::llv::Params;
use crate::llv::params::{Kind, PARAMS};

/// The TOML text of a parameter value.
pub fn toml_value(kind: Kind, v: f64) -> String {
    value_of(kind, v).to_string().trim().to_string()
}

/// A parameter value as a TOML value of its kind.
fn value_of(kind: Kind, v: f64) -> Value {
    match kind {
        Kind::Bool => Value::from(v != 0.0),
        Kind::Int => Value::from(v as i64),
        Kind::Float => Value::from(v),
    }
}

/// `text` (a profile) with its `[llv.*]` values replaced by `params`.
pub fn set_llv(text: &str, path: &Path, params: &Params) -> Result<String, ProfileError> {
    let invalid = |message: String| ProfileError::Invalid {
        path: path.to_path_buf(),
        line: 1,
        message,
    };
    let current = Profile::from_toml(text, path)?;
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| {
        invalid(format!("not valid TOML: {}", e.message().trim()))
    })?;
    let cannot = || {
        invalid(
            "cannot place the new [llv] values in this file's layout; write the parameters to a new profile instead"
                .into(),
        )
    };
    for sp in PARAMS {
        let (Some(old), Some(new)) = (current.llv.get(sp.key), params.get(sp.key)) else {
            continue;
        };
        if old == new {
            continue;
        }
        let (group, name) = sp.key.split_once('.').unwrap_or(("", sp.key));
        let llv = table_in(doc.as_table_mut(), "llv").ok_or_else(cannot)?;
        let g = table_in(llv, group).ok_or_else(cannot)?;
        let mut v = value_of(sp.kind, new);
        match g.get_mut(name).and_then(Item::as_value_mut) {
            Some(old) => {
                // The new value takes the old one's spacing and comment.
                *v.decor_mut() = old.decor().clone();
                *old = v;
            }
            None => {
                g.insert(name, Item::Value(v));
            }
        }
    }
    let out = doc.to_string();
    let check = Profile::from_toml(&out, path)?;
    if check.llv != *params {
        return Err(cannot());
    }
    Ok(out)
}

/// The table `key` of `parent`, made (as a `[header]` table, implicit when
/// it only holds tables) when the file lacks it; `None` when `key` holds
/// something else.
fn table_in<'a>(parent: &'a mut Table, key: &str) -> Option<&'a mut Table> {
    let implicit = key == "llv";
    let item = parent.entry(key).or_insert_with(|| {
        let mut t = Table::new();
        t.set_implicit(implicit);
        Item::Table(t)
    });
    item.as_table_mut()
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
        assert!(out.contains("[llv.connect]\nwl = 7.25"), "{out}");
        assert!(!out.contains("[llv]\n"), "no empty [llv] header: {out}");
        assert_eq!(
            Profile::from_toml(&out, Path::new("t.toml")).unwrap().llv,
            p
        );
    }
}
