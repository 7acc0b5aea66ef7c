//! The console's picture of a session, made from its manifest and the last
//! check of its files: the checklist (damaged lightings and outputs marked)
//! and every file with its state.

use crate::session::{CheckReport, OutputState, Session, Step};
use crate::tui::event::{FileState, ImageState, SessionView};
use crate::tui::text::clean;

/// Whether a problem of a check is about file `file` (problems start with
/// the file's path).
pub fn names_file(problem: &str, file: &str) -> bool {
    problem.starts_with(&format!("{file}:")) || problem.contains(&format!("/{file}:"))
}

/// The console's picture of `s`. `check` is the last full check of its
/// files (`checked` says whether it was made just now); `read_only`: it is
/// open only to look.
pub fn view(
    s: &Session,
    check: Option<&CheckReport>,
    checked: bool,
    read_only: bool,
) -> SessionView {
    let p = s.progress();
    let m = s.manifest();
    let problem = |file: &str| -> Option<String> {
        check?
            .problems
            .iter()
            .find(|p| names_file(p, file))
            .map(|p| clean(p))
    };
    let changed = |file: &str| check.is_some_and(|c| c.changed.iter().any(|f| f == file));
    let images = p
        .images
        .iter()
        .map(|i| {
            let rec = m.image(i.number);
            let damaged = rec
                .map(|r| {
                    r.grey
                        .iter()
                        .filter_map(|g| problem(&g.file).map(|why| (g.letter, why)))
                        .collect()
                })
                .unwrap_or_default();
            let outputs_damaged = rec
                .and_then(|r| r.outputs.as_ref())
                .and_then(|o| o.files.iter().find_map(|f| problem(&f.file)));
            ImageState {
                k: i.number,
                camera: i.camera,
                location: i.location,
                captured: i.captured.clone(),
                outputs: i.outputs != OutputState::Missing,
                stale: matches!(i.outputs, OutputState::Stale(_)),
                edits: i.edits,
                damaged,
                outputs_damaged,
                params: rec
                    .and_then(|r| r.outputs.as_ref())
                    .map(|o| o.params.clone()),
            }
        })
        .collect();
    let next = p.next_step().map(|st| match st {
        Step::Capture { image, letter } => (image, Some(letter)),
        Step::Process { image } => (image, None),
    });
    let name = s.name().as_str().to_string();
    let mut names: Vec<String> = vec![format!("{name}.ses"), format!("{name}.toml")];
    names.extend(m.files().into_iter().map(|(_, f, _)| f.to_string()));
    if let Ok(rd) = std::fs::read_dir(s.dir()) {
        let mut extra: Vec<String> = rd
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".ps") || n.ends_with(".svg") || n.ends_with(".log"))
            .collect();
        extra.sort();
        names.extend(extra);
    }
    names.dedup();
    let files = names
        .into_iter()
        .map(|n| {
            let path = s.path(&n);
            let changed = changed(&n);
            let (state, ok) = match (std::fs::metadata(&path), problem(&n)) {
                (Err(_), _) => ("MISSING".to_string(), false),
                (Ok(_), Some(p)) => (format!("DAMAGED: {p}"), false),
                (Ok(m), None) if changed => (
                    format!(
                        "CHANGED since the manifest recorded it (outputs made from it may be \
                         stale) {:.1} KiB",
                        m.len() as f64 / 1024.0
                    ),
                    true,
                ),
                (Ok(m), None) => (format!("ok {:.1} KiB", m.len() as f64 / 1024.0), true),
            };
            FileState {
                name: clean(&n),
                state: clean(&state),
                ok,
                changed: changed && ok,
            }
        })
        .collect();
    SessionView {
        name,
        dir: s.dir().to_path_buf(),
        letters: s.letters(),
        images,
        next,
        files,
        checked,
        read_only,
    }
}
