//! Reading one image of a session back for the console: each lighting's
//! grey image on its own (a damaged one is reported, the others still
//! load), and the saved outputs and lines when they are current and read.

use crate::formats;
use crate::llv::pipeline::StageOutputs;
use crate::session::{OutputState, Session};
use crate::tui::event::{LoadedImage, SavedOutputs};

pub fn image(s: &Session, k: u32) -> LoadedImage {
    let mut out = LoadedImage {
        k,
        ..LoadedImage::default()
    };
    let Some(rec) = s.manifest().image(k) else {
        return out;
    };
    for g in &rec.grey {
        match crate::session::input::read_frame(&s.path(&g.file), g) {
            Ok(f) => out.images.push((g.letter, f.image)),
            Err(e) => out.damaged.push((g.letter, e.to_string())),
        }
    }
    let state = crate::session::progress::output_state(rec);
    out.accepted = state == OutputState::Done && out.damaged.is_empty();
    out.lines = s.load_lines(k).ok();
    out.camera = Some(s.image_camera(k).map_err(|e| e.to_string()));
    let read = rec.outputs.as_ref().map(|o| (o, saved(s, k, o)));
    if let Some((_, Err(why))) = &read {
        out.outputs_damaged = Some(why.clone());
    }
    if state == OutputState::Done
        && out.damaged.is_empty()
        && let Some((o, Ok(outputs))) = read
    {
        out.saved = Some(SavedOutputs {
            outputs,
            params: o.params.clone(),
        });
    } else {
        out.accepted = false;
    }
    out
}

/// The outputs of image `k` from its files, or why one does not read.
fn saved(
    s: &Session,
    k: u32,
    o: &crate::session::manifest::OutputRecord,
) -> Result<StageOutputs, String> {
    let path = |ext: &str| s.path(&s.file_name(k, None, ext));
    let text = |e: &dyn std::fmt::Display| e.to_string();
    let edges_h = formats::edgefile::read_edges(&path("hpo")).map_err(|e| text(&e))?;
    let edges_v = formats::edgefile::read_edges(&path("vpo")).map_err(|e| text(&e))?;
    let mut lines_raw = formats::lines::read_lines(&path("lex")).map_err(|e| text(&e))?;
    if let Some(a) = &o.lex_attributes {
        a.apply(&mut lines_raw);
    }
    let lines = s.load_lines(k).map_err(|e| text(&e))?;
    let mut corrected = Vec::new();
    let mut imc: Vec<&str> = o
        .files
        .iter()
        .map(|f| f.file.as_str())
        .filter(|f| f.ends_with(".imc"))
        .collect();
    imc.sort_unstable();
    let grey = s.manifest().image(k).map_or(&[][..], |r| r.grey.as_slice());
    for f in imc {
        // The size of its grey image (cube1a.imc of cube1a.img).
        let of = grey
            .iter()
            .find(|g| g.file.strip_suffix(".img") == f.strip_suffix(".imc"))
            .or(grey.first())
            .ok_or_else(|| format!("{f}: no grey image of image {k} is recorded"))?;
        corrected.push(
            crate::session::input::read_frame(&s.path(f), of)
                .map_err(|e| text(&e))?
                .image,
        );
    }
    Ok(StageOutputs {
        corrected,
        edges_h,
        edges_v,
        lines_raw,
        lines,
        params: o.params.clone(),
        ..StageOutputs::default()
    })
}
