//! Saving the stage outputs of one image: the lens-corrected images
//! (`.imc`), the edge points (`.hpo`, `.vpo`), the extracted lines (`.lex`)
//! and the post-processed lines (`.ldr`), then their record in the manifest:
//! parameters, counts, timings, inputs with their hashes, line attributes.
//!
//! A partial set (a redo from the line stage keeps the edge files) keeps the
//! previous record's files, counts and inputs for what it does not replace.

use super::manifest::{FileRecord, LineAttributes, OutputRecord, TimingsRecord};
use super::{Session, SessionError, stamp};
use crate::formats;
use crate::formats::img::ImgFile;
use crate::llv::{EdgePoints, GreyImage, Params, Segment};

/// The outputs to save. `corrected[i]` belongs to the i-th lit frame of
/// the image, in the order of [`super::FrameRule::lit_letters`] (that of
/// [`super::PipelineInput::images`]): the ambient frame has no `.imc`.
#[derive(Clone, Copy, Debug, Default)]
pub struct OutputSet<'a> {
    pub corrected: &'a [GreyImage],
    pub edges_h: Option<&'a EdgePoints>,
    pub edges_v: Option<&'a EdgePoints>,
    pub lines_raw: Option<&'a [Segment]>,
    pub lines: Option<&'a [Segment]>,
    pub timings: TimingsRecord,
}

impl Session {
    /// Writes the files of `set`, then records them. Manual edits of the
    /// previous `.ldr` no longer apply once a new `.ldr` is written: the edit
    /// log is cleared with it.
    pub fn save_output_set(
        &mut self,
        k: u32,
        set: &OutputSet<'_>,
        params: &Params,
    ) -> Result<(), SessionError> {
        self.writable()?;
        super::check_image_number(k)?;
        let captured: Vec<char> = self
            .manifest
            .image(k)
            .map(|r| r.grey.iter().map(|g| g.letter).collect())
            .unwrap_or_default();
        let letters = self.frame_rule().lit_letters(captured);
        let mut written: Vec<FileRecord> = Vec::new();
        for (i, img) in set.corrected.iter().enumerate() {
            let letter = letters.get(i).copied();
            let file = self.file_name(k, letter, "imc");
            let bytes = formats::img::encode_img(&ImgFile::new(img.clone()).with_comment(&file))?;
            written.push(self.put(file, &bytes)?);
        }
        if let Some(e) = set.edges_h {
            let file = self.file_name(k, None, "hpo");
            let bytes = formats::edgefile::encode_checked(&self.path(&file), e)?;
            written.push(self.put(file, &bytes)?);
        }
        if let Some(e) = set.edges_v {
            let file = self.file_name(k, None, "vpo");
            let bytes = formats::edgefile::encode_checked(&self.path(&file), e)?;
            written.push(self.put(file, &bytes)?);
        }
        if let Some(l) = set.lines_raw {
            let file = self.file_name(k, None, "lex");
            written.push(self.put(file, formats::lines::format_lines(l).as_bytes())?);
        }
        if let Some(l) = set.lines {
            let file = self.file_name(k, None, "ldr");
            written.push(self.put(file, formats::lines::format_lines(l).as_bytes())?);
        }

        let full = set.edges_h.is_some() && set.edges_v.is_some();
        let rec = self.record_mut(k)?;
        let mut inputs: Vec<FileRecord> = rec
            .grey
            .iter()
            .map(|g| FileRecord {
                file: g.file.clone(),
                hash: g.hash.clone(),
            })
            .chain(rec.cdf.clone())
            .collect();
        let prev = rec.outputs.take();
        let mut counts = prev.as_ref().map(|p| p.counts).unwrap_or_default();
        let mut timings = prev.as_ref().map(|p| p.timings).unwrap_or_default();
        let mut files = written.clone();
        let (mut lex_attr, mut ldr_attr) = (None, None);
        if let Some(p) = &prev {
            // A partial redo builds on the earlier stages' files: keep them,
            // and the inputs they were made from.
            if !full {
                inputs = p.inputs.clone();
            }
            for f in &p.files {
                if !files.iter().any(|w| w.file == f.file) {
                    files.push(f.clone());
                }
            }
            lex_attr = p.lex_attributes.clone();
            ldr_attr = p.ldr_attributes.clone();
        }
        files.sort_by(|a, b| a.file.cmp(&b.file));
        if let Some(e) = set.edges_h {
            counts.edges_h = e.points.len() as u64;
            timings.lens_us = set.timings.lens_us;
            timings.edges_us = set.timings.edges_us;
        }
        if let Some(e) = set.edges_v {
            counts.edges_v = e.points.len() as u64;
        }
        if let Some(l) = set.lines_raw {
            counts.lines_raw = l.len() as u64;
            timings.lines_us = set.timings.lines_us;
            lex_attr = LineAttributes::of(l);
        }
        if let Some(l) = set.lines {
            counts.lines = l.len() as u64;
            timings.connect_us = set.timings.connect_us;
            ldr_attr = LineAttributes::of(l);
            rec.edit.clear();
        }
        rec.outputs = Some(OutputRecord {
            made: stamp::now_rfc3339(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            inputs,
            files,
            counts,
            timings,
            lex_attributes: lex_attr,
            ldr_attributes: ldr_attr,
            params: params.clone(),
        });
        self.commit()
    }

    fn put(&self, file: String, bytes: &[u8]) -> Result<FileRecord, SessionError> {
        self.write_file(&file, bytes)?;
        Ok(FileRecord {
            hash: stamp::hash(bytes),
            file,
        })
    }
}
