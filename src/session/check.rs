//! `vss session check`: every file the manifest names exists and parses with
//! the format readers; files changed since they were recorded, stale
//! outputs, a `.ses` that disagrees, leftovers of interrupted saves and
//! VSS-named data files the manifest does not record (a second writer's, or
//! a save that failed before its record) are listed; so are the manifest's
//! records that contradict themselves or the frame they describe (a size
//! its header does not have, a lighting recorded twice for one image).
//! Problems (missing or unreadable files, contradictions) make the check fail;
//! the rest are warnings a person should read.

use std::collections::HashSet;
use std::path::Path;

use super::progress::{OutputState, output_state};
use super::{Session, stamp};
use crate::formats;

/// What `check` found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CheckReport {
    /// Files the manifest names that are missing or do not parse.
    pub problems: Vec<String>,
    /// Files changed since recorded, `.ses` disagreements, leftovers.
    pub warnings: Vec<String>,
    /// Images whose outputs are stale, with why.
    pub stale: Vec<(u32, String)>,
    /// The files (as the manifest names them) that read but changed since
    /// recorded; each also has its warning.
    pub changed: Vec<String>,
    /// Files read and parsed.
    pub checked: usize,
}

impl CheckReport {
    /// No problems (warnings and stale outputs allowed).
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }
}

pub fn check(s: &Session) -> CheckReport {
    let mut r = CheckReport::default();
    let m = s.manifest();
    let mut recorded: HashSet<String> = HashSet::new();
    for rec in &m.image {
        let mut expected: Vec<(String, &str)> = Vec::new();
        expected.extend(rec.cdf.iter().map(|f| (f.file.clone(), f.hash.as_str())));
        expected.extend(rec.grey.iter().map(|g| (g.file.clone(), g.hash.as_str())));
        if let Some(o) = &rec.outputs {
            for f in &o.files {
                // After manual edits the `.ldr` is the last edit's.
                let hash = match rec.edit.last() {
                    Some(e) if f.file.ends_with(".ldr") => e.hash.as_str(),
                    _ => f.hash.as_str(),
                };
                expected.push((f.file.clone(), hash));
            }
        } else if let Some(e) = rec.edit.last() {
            let ldr = s.file_name(rec.number, None, "ldr");
            expected.push((ldr, e.hash.as_str()));
        }
        // The pixel size of each grey image read whole, for `contradictions`.
        let mut sizes: Vec<(String, (usize, usize))> = Vec::new();
        for (file, hash) in expected {
            recorded.insert(file.clone());
            if let Some(size) = check_file(&s.path(&file), &file, hash, &mut r) {
                sizes.push((file, size));
            }
        }
        if let OutputState::Stale(why) = output_state(rec) {
            r.stale.push((rec.number, why));
        }
        contradictions(s, rec, &sizes, &mut r);
    }
    let ses_file = format!("{}.ses", s.name());
    match formats::ses::read_ses(&s.path(&ses_file)) {
        Err(e) => r.problems.push(e.to_string()),
        Ok(ses) => {
            r.checked += 1;
            let lightings = m.lighting.len() as u32;
            if ses.cameras != m.session.cameras || ses.lightings != lightings {
                r.warnings.push(format!(
                    "{ses_file} says {} cameras and {} lightings; the manifest {} and {lightings}",
                    ses.cameras, ses.lightings, m.session.cameras
                ));
            }
            let last = m.image.iter().map(|i| i.number).max().unwrap_or(0);
            if ses.images < last {
                r.warnings.push(format!(
                    "{ses_file} says {} images but the manifest records image {last}",
                    ses.images
                ));
            }
        }
    }
    for file in unrecorded(s, &recorded) {
        r.warnings.push(format!(
            "{}: a file of this session that the manifest does not record (another \
             writer's, or a save that failed): outputs and reports ignore it",
            crate::text::path(s.path(&file))
        ));
    }
    for p in s.leftovers() {
        r.warnings.push(format!(
            "{}: left over from an interrupted save; opening the session for writing removes it",
            crate::text::path(&p)
        ));
    }
    r
}

/// The extensions of the files a manifest records.
const DATA_EXTS: [&str; 7] = ["img", "imc", "hpo", "vpo", "lex", "ldr", "cdf"];

/// Data files in the session folder under this session's VSS names that
/// are not in `recorded`, sorted.
fn unrecorded(s: &Session, recorded: &HashSet<String>) -> Vec<String> {
    let Ok(rd) = std::fs::read_dir(s.dir()) else {
        return Vec::new();
    };
    let mut v: Vec<String> = rd
        .flatten()
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| !recorded.contains(n))
        .filter(|n| {
            formats::names::VssFile::parse_in(n, s.name())
                .is_ok_and(|f| &f.session == s.name() && DATA_EXTS.contains(&f.ext.as_str()))
        })
        .collect();
    v.sort();
    v
}

/// Reads and parses one recorded file, with its problems and warnings in
/// `r`; gives the pixel size of an image (`.img`, `.imc`) that parsed.
fn check_file(path: &Path, file: &str, hash: &str, r: &mut CheckReport) -> Option<(usize, usize)> {
    let ext = file.rsplit_once('.').map_or("", |(_, e)| e);
    // An image larger than the stages take (one of 40000² is 1.6 GB) is
    // refused from its header, not read whole to be hashed and parsed.
    if matches!(ext, "img" | "imc")
        && let Ok(h) = formats::img::read_header(path)
        && let Err(e @ crate::llv::LlvError::TooLarge { .. }) =
            crate::llv::image::check_stage_size(h.width.into(), h.height.into())
    {
        r.problems.push(format!(
            "{}: byte 4: {e}; not read",
            crate::text::path(path)
        ));
        return None;
    }
    let bytes = match crate::fsutil::read_input(path, formats::max_len(path)) {
        Ok(b) => b,
        Err(e) => {
            r.problems.push(format!("{}: {e}", crate::text::path(path)));
            return None;
        }
    };
    let parsed = match ext {
        "img" | "imc" => formats::img::parse_img(&bytes, path).map(|f| Some(f.image.size())),
        "hpo" | "vpo" => formats::edgefile::parse_edges(&bytes, path).map(|_| None),
        "lex" | "ldr" => match std::str::from_utf8(&bytes) {
            Ok(t) => formats::lines::parse_lines(t, path).map(|_| None),
            Err(e) => {
                r.problems
                    .push(format!("{}: not text: {e}", crate::text::path(path)));
                return None;
            }
        },
        "cdf" => match std::str::from_utf8(&bytes) {
            Ok(t) => formats::cdf::parse_cdf(t, path).map(|_| None),
            Err(e) => {
                r.problems
                    .push(format!("{}: not text: {e}", crate::text::path(path)));
                return None;
            }
        },
        _ => Ok(None),
    };
    match parsed {
        Err(e) => {
            r.problems.push(e.to_string());
            None
        }
        Ok(size) => {
            r.checked += 1;
            if stamp::hash(&bytes) != hash {
                r.changed.push(file.to_string());
                r.warnings.push(format!(
                    "{}: changed since the manifest recorded it (outputs made from it may be stale)",
                    crate::text::path(path)
                ));
            }
            size
        }
    }
}

/// The records of image `rec` that contradict the frames they describe or
/// each other, as problems naming the manifest, the file and the field: a
/// grey image's `width`/`height` that its `.img` header does not have (the
/// file may be the one recorded, hash and all, and the record edited), a
/// lighting recorded twice. `sizes` are the grey images' pixel sizes as
/// [`check_file`] read them (one that did not read is its own problem).
fn contradictions(
    s: &Session,
    rec: &super::manifest::ImageRecord,
    sizes: &[(String, (usize, usize))],
    r: &mut CheckReport,
) {
    let manifest = s.path(&format!("{}.toml", s.name()));
    let m = crate::text::path(&manifest);
    let k = rec.number;
    for (i, g) in rec.grey.iter().enumerate() {
        if let Some(first) = rec.grey[..i].iter().find(|o| o.letter == g.letter) {
            r.problems.push(format!(
                "{m}: image {k} records lighting {:?} twice ({} and {}): which frame is it?",
                g.letter, first.file, g.file
            ));
        }
        let Some(&(_, (w, h))) = sizes.iter().find(|(f, _)| *f == g.file) else {
            continue;
        };
        let (hw, hh) = (w as u32, h as u32);
        for (field, recorded, header) in [("width", g.width, hw), ("height", g.height, hh)] {
            if recorded != header {
                r.problems.push(format!(
                    "{m}: image {k}, {}: {field} = {recorded} recorded, but the file's header \
                     says {header} ({hw} x {hh})",
                    g.file
                ));
            }
        }
    }
}
