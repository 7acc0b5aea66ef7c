//! The survey report of a session, whoever asks for it: `vss report` and
//! the console's export both call [`write()`], so they write the same pages.
//!
//! [`image_report`] gathers what the report shows about an image: its grey
//! images, edge files, raw and connected lines (with attributes), and from
//! the manifest the camera, parameters, counts, timings, whether the
//! outputs are stale, and the edit log. A file that is missing or
//! unreadable becomes a note on the page naming it, instead of failing the
//! whole report or being left out without a word; [`write()`] also returns
//! these notes as [`Written::problems`], so `vss report` exits non-zero and
//! the console says them, not only the page.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use super::ps::{self, PsWriter};
use super::{ImageReport, check_picture_size, svg};
use crate::formats;
use crate::fsutil::write_atomic_with;
use crate::session::progress::{OutputState, output_state};
use crate::session::{Session, SessionError};

/// What can stop a report being written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("cannot write {}: {source}", crate::text::path(path))]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Stopped after some files were written: they are the new report, and
    /// the message says so (else "cannot write all1.svg" reads as if
    /// nothing had changed, while all.ps was replaced).
    #[error(
        "{source}{}; written before it stopped (the NEW report): {}",
        source.on_disk().map_or(String::new(), |o| format!(" ({o})")),
        list(written)
    )]
    Partly {
        source: Box<ReportError>,
        written: Vec<PathBuf>,
    },
}

/// `a.ps, a1.svg`.
fn list(paths: &[PathBuf]) -> String {
    let names: Vec<String> = paths.iter().map(crate::text::path).collect();
    names.join(", ")
}

impl ReportError {
    /// What is on disk where the report could not be written (see
    /// [`on_disk`]), or `None` when nothing was being written.
    pub fn on_disk(&self) -> Option<String> {
        match self {
            ReportError::Write { path, .. } => Some(on_disk(path)),
            ReportError::Session(_) => None,
            // Said in its message, with what was written.
            ReportError::Partly { .. } => None,
        }
    }

    /// Whether some files of the report were written before it stopped
    /// (then [`ReportError::on_disk`] is `None`: its message says it all).
    pub fn wrote_some(&self) -> bool {
        matches!(self, ReportError::Partly { .. })
    }
}

/// What a failed write left at `path`: the file that was there before,
/// untouched (the writes are atomic), with the time it was written, or
/// nothing. For the message after "cannot write …", so the operator knows
/// the report on disk is not the new one. Something there that is not a
/// file (a folder, a link) is not called a report.
pub fn on_disk(path: &Path) -> String {
    let meta = std::fs::symlink_metadata(path);
    if meta.as_ref().is_ok_and(|m| !m.is_file()) {
        return format!("nothing was written at {}", crate::text::path(path));
    }
    match meta.and_then(|m| m.modified()) {
        Ok(t) => {
            let secs = t
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            format!(
                "{} on disk is the OLD report, untouched, written {}",
                crate::text::path(path),
                crate::clock::rfc3339(secs)
            )
        }
        Err(_) => format!("there is no {} yet", crate::text::path(path)),
    }
}

/// What [`write()`] wrote: the files, in order, and the problems marked in
/// them (a file the report could not show, named, with where it is
/// damaged), each once, as the page's note says it. The report is written
/// whole either way; a problem is what the caller must say, not hide.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Written {
    pub files: Vec<PathBuf>,
    pub problems: Vec<String>,
}

/// Where a survey report goes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Targets {
    /// The PostScript report of every image, in one file.
    pub ps: Option<PathBuf>,
    /// One SVG per image: this file for a single image, else this file with
    /// the image number before the extension (`out.svg` → `out3.svg`).
    pub svg: Option<PathBuf>,
}

impl Targets {
    /// What the console's export writes: `NAME.ps` in the session folder and
    /// `NAMEk.svg` beside it for each image.
    pub fn in_session(s: &Session) -> Targets {
        let name = s.name().as_str();
        Targets {
            ps: Some(s.path(&format!("{name}.ps"))),
            svg: Some(s.path(&format!("{name}.svg"))),
        }
    }
}

/// The heading of a survey report, of all images or of image `k`.
pub fn title(s: &Session, image: Option<u32>) -> String {
    match image {
        Some(k) => format!("survey {} image {k}", s.name()),
        None => format!("survey {}", s.name()),
    }
}

/// The image numbers a report of `image` (or of every image with anything
/// recorded) shows, in order. An image the manifest does not record is an
/// error naming it.
pub fn image_numbers(s: &Session, image: Option<u32>) -> Result<Vec<u32>, SessionError> {
    match image {
        Some(k) if s.manifest().image(k).is_some() => Ok(vec![k]),
        // The error `image_report` gives for it.
        Some(k) => image_report(s, k).map(|_| vec![k]),
        None => Ok(s.manifest().image.iter().map(|r| r.number).collect()),
    }
}

/// Writes the survey report of `image` (or of every image) to `targets`
/// and returns the files written, in order, with the problems marked in
/// them (see [`Written`]). A session without images gives a report without
/// pages.
///
/// One image's pictures are in memory at a time, and no file's text is
/// held whole: the PostScript is streamed page by page into the temporary
/// file of [`write_atomic_with`], each SVG likewise. The PostScript header
/// states the page count, so the images are read twice: once to count
/// their pages, once to write them (reading a survey's files costs far less
/// than holding all its pictures). A failure half-way (a full disk, a file
/// that changed so the pages no longer match the count) leaves the file
/// that was there untouched, and the error names it.
///
/// A failure after some files were written is [`ReportError::Partly`],
/// naming them.
pub fn write(s: &Session, image: Option<u32>, targets: &Targets) -> Result<Written, ReportError> {
    let mut written = Written::default();
    match write_into(s, image, targets, &mut written) {
        Ok(()) => Ok(written),
        Err(e) if written.files.is_empty() => Err(e),
        Err(e) => Err(ReportError::Partly {
            source: Box::new(e),
            written: written.files,
        }),
    }
}

/// [`write()`], adding to `written` as it goes.
fn write_into(
    s: &Session,
    image: Option<u32>,
    targets: &Targets,
    written: &mut Written,
) -> Result<(), ReportError> {
    let numbers = image_numbers(s, image)?;
    let mut found = |r: &ImageReport| {
        for p in &r.problems {
            if !written.problems.contains(p) {
                written.problems.push(p.clone());
            }
        }
    };
    if let Some(p) = &targets.ps {
        let mut pages = 0;
        for &k in &numbers {
            let r = image_report(s, k)?;
            found(&r);
            pages += ps::image_report_pages(&r);
        }
        let title = title(s, image);
        stream(p, |w, failed| {
            let mut doc = PsWriter::begin(w, &title, pages)?;
            for &k in &numbers {
                let r = image_report(s, k).map_err(|e| {
                    let err = std::io::Error::other(e.to_string());
                    *failed = Some(e);
                    err
                })?;
                doc.image_report(&r)?;
            }
            doc.finish().map(drop)
        })?;
        written.files.push(p.clone());
    }
    if let Some(p) = &targets.svg {
        for &k in &numbers {
            let path = if numbers.len() == 1 && image.is_some() {
                p.clone()
            } else {
                numbered(p, k)
            };
            let r = image_report(s, k)?;
            found(&r);
            stream(&path, |w, _| svg::write_image_svg(w, &r).map(drop))?;
            written.files.push(path);
        }
    }
    Ok(())
}

/// Writes `path` atomically with `fill`, which writes into the temporary
/// file and may set the session error that stopped it. Nothing at `path`
/// changes unless all of it was written.
fn stream(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<&mut File>, &mut Option<SessionError>) -> std::io::Result<()>,
) -> Result<(), ReportError> {
    let mut failed = None;
    let result = write_atomic_with(path, |w| fill(w, &mut failed));
    match (result, failed) {
        (Ok(()), _) => Ok(()),
        (Err(_), Some(e)) => Err(ReportError::Session(e)),
        (Err(source), None) => Err(ReportError::Write {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// `out.svg` → `out3.svg`.
pub fn numbered(p: &Path, k: u32) -> PathBuf {
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = p
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "svg".into());
    p.with_file_name(format!("{stem}{k}.{ext}"))
}

/// Everything the report shows of image `k`, read from the session's files.
pub fn image_report(s: &Session, k: u32) -> Result<ImageReport, SessionError> {
    let m = s.manifest();
    let rec = m.image(k).ok_or_else(|| SessionError::Missing {
        session: s.name().to_string(),
        image: k,
        what: "nothing recorded for this image".into(),
    })?;
    let mut r = ImageReport {
        title: format!("{}{k}", s.name()),
        ..Default::default()
    };
    // What the report cannot show, said on the page in the order found,
    // right after this first line, and returned (see [`Written`]).
    let mut problems = Vec::new();
    let mut notes = vec![format!(
        "image {k}: camera {}, location {}{}",
        rec.camera,
        rec.location,
        rec.cdf.as_ref().map_or(String::new(), |c| format!(
            ", camera description {}",
            c.file
        ))
    )];
    for g in &rec.grey {
        // The size from the header first: a picture the report cannot draw
        // is a note, before its pixels are read.
        match formats::img::read_img_sized(&s.path(&g.file), check_picture_size) {
            Ok(f) => {
                let light = m
                    .lighting
                    .iter()
                    .find(|l| l.letter == g.letter)
                    .map_or(String::new(), |l| format!(" (lights: {})", l.on.join(", ")));
                r.greys.push((format!("{}{light}", g.file), f.image));
            }
            Err(e) => problems.push(format!("cannot show {}: {e}", g.file)),
        }
    }
    // Sizes that come from the manifest or an edge header, not from pixels
    // read, are checked before the report draws with them.
    if let Some((_, img)) = r.greys.first() {
        (r.width, r.height) = img.size();
    } else if let Some(g) = rec.grey.first() {
        let (w, h) = (g.width as usize, g.height as usize);
        match check_picture_size(w, h) {
            Ok(()) => (r.width, r.height) = (w, h),
            Err(e) => problems.push(format!(
                "cannot use the size of {} recorded in the manifest: {e}",
                g.file
            )),
        }
    }
    // A stage output is shown when it is there; one the manifest records
    // that is gone is a note, as an unreadable one is.
    let recorded = |file: &str| {
        rec.outputs
            .as_ref()
            .is_some_and(|o| o.files.iter().any(|f| f.file == file))
    };
    let present = |file: &str, problems: &mut Vec<String>| {
        let there = s.path(file).exists();
        if !there && recorded(file) {
            problems.push(format!(
                "cannot show {file}: the manifest records it, but it is missing"
            ));
        }
        there
    };
    for (ext, slot) in [("hpo", &mut r.edges_h), ("vpo", &mut r.edges_v)] {
        let file = s.file_name(k, None, ext);
        if !present(&file, &mut problems) {
            continue;
        }
        match formats::edgefile::read_edges(&s.path(&file)) {
            Ok(e) if e.width > 0 && e.height > 0 => match check_picture_size(e.width, e.height) {
                Ok(()) => *slot = Some(e),
                Err(err) => problems.push(format!("cannot show {file}: {err}")),
            },
            Ok(e) => *slot = Some(e),
            Err(e) => problems.push(format!("cannot show {file}: {e}")),
        }
    }
    if r.width == 0
        && let Some(e) = r.edges_h.as_ref().or(r.edges_v.as_ref())
    {
        (r.width, r.height) = (e.width, e.height);
    }
    let lex = s.file_name(k, None, "lex");
    if present(&lex, &mut problems) {
        match formats::lines::read_lines(&s.path(&lex)) {
            Ok(mut l) => {
                if let Some(a) = rec.outputs.as_ref().and_then(|o| o.lex_attributes.as_ref()) {
                    a.apply(&mut l);
                }
                r.lines_raw = Some(l);
            }
            Err(e) => problems.push(format!("cannot show {lex}: {e}")),
        }
    }
    let ldr = s.file_name(k, None, "ldr");
    if present(&ldr, &mut problems) {
        match s.load_lines(k) {
            Ok(l) => r.lines = Some(l),
            Err(e) => problems.push(format!("cannot show {ldr}: {e}")),
        }
    }
    notes.extend(problems.iter().cloned());
    if let Some(o) = &rec.outputs {
        notes.push(format!(
            "outputs made {} by vss {}{}",
            o.made,
            o.version,
            match output_state(rec) {
                OutputState::Stale(why) => format!(" -- STALE: {why}"),
                _ => String::new(),
            }
        ));
        let c = &o.counts;
        notes.push(format!(
            "counts: {} edge points horizontal, {} vertical; {} lines extracted, {} after post-processing",
            c.edges_h, c.edges_v, c.lines_raw, c.lines
        ));
        let t = &o.timings;
        notes.push(format!(
            "timings: lens {:.1} ms, edges {:.1} ms, lines {:.1} ms, connect {:.1} ms",
            t.lens_us as f64 / 1e3,
            t.edges_us as f64 / 1e3,
            t.lines_us as f64 / 1e3,
            t.connect_us as f64 / 1e3
        ));
        notes.push("parameters:".into());
        notes.extend(params_lines(&o.params));
    } else {
        notes.push("no stage outputs yet".into());
    }
    if !rec.edit.is_empty() {
        notes.push(format!("manual edits ({}):", rec.edit.len()));
        notes.extend(
            rec.edit
                .iter()
                .map(|e| format!("  {} {} -> {} lines", e.at, e.op, e.lines)),
        );
    }
    r.notes = notes;
    r.problems = problems;
    Ok(r)
}

/// The parameters as `  edges.floor = 2` lines.
pub fn params_lines(p: &crate::llv::Params) -> Vec<String> {
    let Ok(text) = toml::to_string(p) else {
        return vec!["  (parameters cannot be shown)".into()];
    };
    let mut section = String::new();
    let mut out = Vec::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if let Some(s) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = format!("{s}.");
        } else {
            out.push(format!("  {section}{line}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_are_listed_by_dotted_key() {
        let lines = params_lines(&crate::llv::Params::default());
        assert!(
            lines.iter().any(|l| l == "  edges.half_width = 3"),
            "{lines:?}"
        );
        assert!(lines.iter().any(|l| l.starts_with("  connect.wl = ")));
    }

    #[test]
    fn numbered_inserts_the_image_number() {
        assert_eq!(
            numbered(Path::new("/t/out.svg"), 3),
            Path::new("/t/out3.svg")
        );
    }
}
