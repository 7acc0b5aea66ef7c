//! Running the LLV stages on a session's images and saving the results:
//! [`Session::save_outputs`] for a pipeline run the console made, and
//! [`Session::redo`] to re-run one image from a chosen stage with new
//! parameters (`vss session redo`).
//!
//! From `lens` or `edges` the whole pipeline runs on the saved grey images
//! (with the image's `.cdf` for lens correction). From `lines` the saved
//! edge files are the input, from `connect` the saved `.lex`: the earlier
//! stages' files and the parameters they were made with stay as they are.

use std::fmt;

use super::manifest::{Counts, TimingsRecord};
use super::{OutputSet, Session, SessionError};
use crate::formats;
use crate::llv::edit::EditOp;
use crate::llv::lens::LensMap;
use crate::llv::params::Stage;
use crate::llv::pipeline::{self, Input, StageOutputs, Timings};
use crate::llv::{GreyImage, Params, Segment};

/// What a redo did.
#[derive(Clone, Debug, PartialEq)]
pub struct RedoSummary {
    pub image: u32,
    pub from: Stage,
    pub counts: Counts,
    pub timings: TimingsRecord,
    pub lens_corrected: bool,
}

impl fmt::Display for RedoSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.counts;
        let t = &self.timings;
        write!(
            f,
            "image {} redone from {:?}{}: {} + {} edge points, {} lines extracted, {} lines \
             (lens {} µs, edges {} µs, lines {} µs, connect {} µs)",
            self.image,
            self.from,
            if self.lens_corrected {
                " with lens correction"
            } else {
                ""
            },
            c.edges_h,
            c.edges_v,
            c.lines_raw,
            c.lines,
            t.lens_us,
            t.edges_us,
            t.lines_us,
            t.connect_us
        )
    }
}

fn timings(t: &Timings) -> TimingsRecord {
    TimingsRecord {
        lens_us: t.lens_us,
        edges_us: t.edges_us,
        lines_us: t.lines_us,
        connect_us: t.connect_us,
    }
}

/// How an edit reads in the log: `connect 3 7`, `extend 1 2`, `delete 4 5`.
pub fn describe(op: &EditOp) -> String {
    match op {
        EditOp::Connect(a, b) => format!("connect {a} {b}"),
        EditOp::Extend(a, b) => format!("extend {a} {b}"),
        EditOp::Delete(v) => {
            let list: Vec<String> = v.iter().map(ToString::to_string).collect();
            format!("delete {}", list.join(" "))
        }
    }
}

impl Session {
    /// Saves a pipeline run of image `k`: `.imc` (when lens correction was
    /// applied), `.hpo`, `.vpo`, `.lex`, `.ldr`, then the manifest record.
    /// `out.corrected[i]` belongs to the i-th captured lighting in letter
    /// order, the order of [`Session::load_images`].
    pub fn save_outputs(
        &mut self,
        k: u32,
        out: &StageOutputs,
        params: &Params,
    ) -> Result<(), SessionError> {
        let set = OutputSet {
            corrected: &out.corrected,
            edges_h: Some(&out.edges_h),
            edges_v: Some(&out.edges_v),
            lines_raw: Some(&out.lines_raw),
            lines: Some(&out.lines),
            timings: timings(&out.timings),
        };
        self.save_output_set(k, &set, params)
    }

    /// Records a manual edit given as an [`EditOp`] (see [`Session::record_edit`]).
    pub fn record_edit_op(
        &mut self,
        k: u32,
        op: &EditOp,
        lines: &[Segment],
    ) -> Result<(), SessionError> {
        self.record_edit(k, &describe(op), lines)
    }

    /// The lens map of image `k` from its `.cdf`, if it has one with a
    /// camera model that changes anything.
    pub fn lens_map(
        &self,
        k: u32,
        width: usize,
        height: usize,
    ) -> Result<Option<LensMap>, SessionError> {
        let Some(cdf) = self.manifest.image(k).and_then(|r| r.cdf.as_ref()) else {
            return Ok(None);
        };
        let path = self.path(&cdf.file);
        let c = formats::cdf::read_cdf(&path)?;
        match c.camera_model().filter(|m| !m.is_identity()) {
            Some(m) => {
                formats::cdf::check_camera_area(&m, width, height, &path)?;
                Ok(Some(LensMap::new(&m, width, height)))
            }
            None => Ok(None),
        }
    }

    /// Re-runs image `k` from stage `from` with `params` and saves the
    /// result (replacing the `.ldr`, and with it the manual edits).
    pub fn redo(
        &mut self,
        k: u32,
        from: Stage,
        params: &Params,
    ) -> Result<RedoSummary, SessionError> {
        self.writable()?;
        super::check_image_number(k)?;
        let name = self.name.to_string();
        let missing = |what: String| SessionError::Missing {
            session: name.clone(),
            image: k,
            what,
        };
        let prev = self
            .manifest
            .image(k)
            .and_then(|r| r.outputs.as_ref())
            .map(|o| o.params.clone());
        let mut lens_corrected = false;
        match from {
            Stage::Lens | Stage::Edges => {
                let images: Vec<GreyImage> = self
                    .load_images(k)?
                    .into_iter()
                    .map(|(_, f)| f.image)
                    .collect();
                let Some(first) = images.first() else {
                    return Err(missing(
                        "no grey image captured yet: capture it first".into(),
                    ));
                };
                let (w, h) = first.size();
                let map = if params.lens.enabled {
                    self.lens_map(k, w, h)?
                } else {
                    None
                };
                let input = Input {
                    images: &images,
                    ambient: None,
                    lens: map.as_ref(),
                };
                let out = pipeline::run(&input, params)?;
                lens_corrected = !out.corrected.is_empty();
                self.save_outputs(k, &out, params)?;
            }
            Stage::Lines | Stage::Connect => {
                // Later stages only: the earlier ones keep their parameters.
                let Some(mut used) = prev else {
                    return Err(missing(format!(
                        "no saved outputs to start from {from:?}: redo from edges first"
                    )));
                };
                used.connect = params.connect.clone();
                let (raw, lines_us) = if from == Stage::Lines {
                    used.lines = params.lines.clone();
                    let t = std::time::Instant::now();
                    let mut raw = Vec::new();
                    for ext in ["hpo", "vpo"] {
                        let e = formats::edgefile::read_edges(
                            &self.path(&self.file_name(k, None, ext)),
                        )?;
                        raw.extend(crate::llv::lines::extract(&e, &used.lines));
                    }
                    (Some(raw), micros(t))
                } else {
                    (None, 0)
                };
                let lex = match &raw {
                    Some(r) => r.clone(),
                    None => {
                        let mut l = formats::lines::read_lines(
                            &self.path(&self.file_name(k, None, "lex")),
                        )?;
                        if let Some(a) = self
                            .manifest
                            .image(k)
                            .and_then(|r| r.outputs.as_ref())
                            .and_then(|o| o.lex_attributes.as_ref())
                        {
                            a.apply(&mut l);
                        }
                        l
                    }
                };
                let t = std::time::Instant::now();
                let mut lines = crate::llv::connect::connect(&lex, &used.connect);
                if used.connect.corner_radius > 0.0 {
                    crate::llv::corners::close_corners(&mut lines, used.connect.corner_radius);
                }
                let connect_us = micros(t);
                let set = OutputSet {
                    lines_raw: raw.as_deref(),
                    lines: Some(&lines),
                    timings: TimingsRecord {
                        lines_us,
                        connect_us,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                self.save_output_set(k, &set, &used)?;
            }
        }
        let o = self
            .manifest
            .image(k)
            .and_then(|r| r.outputs.as_ref())
            .ok_or_else(|| missing("outputs were not recorded".into()))?;
        Ok(RedoSummary {
            image: k,
            from,
            counts: o.counts,
            timings: o.timings,
            lens_corrected,
        })
    }
}

fn micros(t: std::time::Instant) -> u64 {
    u64::try_from(t.elapsed().as_micros()).unwrap_or(u64::MAX)
}
