//! Gathering what the report shows about an image of a session: its grey
//! images, edge files, raw and connected lines (with attributes), and the
//! parameters, counts, timings and edit log from the manifest. Files that
//! are missing or unreadable become a note on the page instead of failing
//! the whole report.

use super::progress::{OutputState, output_state};
use super::{Session, SessionError};
use crate::formats;
use crate::report::{ImageReport, check_picture_size};

impl Session {
    /// The report of image `k`.
    pub fn image_report(&self, k: u32) -> Result<ImageReport, SessionError> {
        let rec = self
            .manifest
            .image(k)
            .ok_or_else(|| SessionError::Missing {
                session: self.name.to_string(),
                image: k,
                what: "nothing recorded for this image".into(),
            })?;
        let mut r = ImageReport {
            title: format!("{}{k}", self.name),
            ..Default::default()
        };
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
            match formats::img::read_img(&self.path(&g.file)) {
                Ok(f) => {
                    let light = self
                        .manifest
                        .lighting
                        .iter()
                        .find(|l| l.letter == g.letter)
                        .map_or(String::new(), |l| format!(" (lights: {})", l.on.join(", ")));
                    r.greys.push((format!("{}{light}", g.file), f.image));
                }
                Err(e) => notes.push(format!("cannot show {}: {e}", g.file)),
            }
        }
        // Sizes that come from the manifest or an edge header, not from
        // pixels read, are checked before the report draws with them.
        if let Some((_, img)) = r.greys.first() {
            (r.width, r.height) = img.size();
        } else if let Some(g) = rec.grey.first() {
            let (w, h) = (g.width as usize, g.height as usize);
            match check_picture_size(w, h) {
                Ok(()) => (r.width, r.height) = (w, h),
                Err(e) => notes.push(format!(
                    "cannot use the size of {} recorded in the manifest: {e}",
                    g.file
                )),
            }
        }
        let mut read_edges = |ext: &str| {
            let file = self.file_name(k, None, ext);
            let p = self.path(&file);
            if !p.exists() {
                return None;
            }
            let e = formats::edgefile::read_edges(&p)
                .map_err(|e| notes.push(format!("cannot show {file}: {e}")))
                .ok()?;
            if e.width > 0
                && e.height > 0
                && let Err(err) = check_picture_size(e.width, e.height)
            {
                notes.push(format!("cannot show {file}: {err}"));
                return None;
            }
            Some(e)
        };
        r.edges_h = read_edges("hpo");
        r.edges_v = read_edges("vpo");
        if r.width == 0
            && let Some(e) = r.edges_h.as_ref().or(r.edges_v.as_ref())
        {
            (r.width, r.height) = (e.width, e.height);
        }
        let lex = self.file_name(k, None, "lex");
        if self.path(&lex).exists() {
            match formats::lines::read_lines(&self.path(&lex)) {
                Ok(mut l) => {
                    if let Some(a) = rec.outputs.as_ref().and_then(|o| o.lex_attributes.as_ref()) {
                        a.apply(&mut l);
                    }
                    r.lines_raw = Some(l);
                }
                Err(e) => notes.push(format!("cannot show {lex}: {e}")),
            }
        }
        let ldr = self.file_name(k, None, "ldr");
        if self.path(&ldr).exists() {
            match self.load_lines(k) {
                Ok(l) => r.lines = Some(l),
                Err(e) => notes.push(format!("cannot show {ldr}: {e}")),
            }
        }
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
        Ok(r)
    }

    /// Reports of every image with anything recorded, in order.
    pub fn reports(&self) -> Result<Vec<ImageReport>, SessionError> {
        self.manifest
            .image
            .iter()
            .map(|r| self.image_report(r.number))
            .collect()
    }
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
            lines.iter().any(|l| l == "  edges.half_width = 4"),
            "{lines:?}"
        );
        assert!(lines.iter().any(|l| l.starts_with("  connect.wl = ")));
    }
}
