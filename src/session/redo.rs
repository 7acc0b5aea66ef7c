//! Running the LLV stages on a session's images and saving the results:
//! [`Session::save_outputs`] for a pipeline run the console made, and
//! [`Session::redo`] to re-run one image from a chosen stage with new
//! parameters (`vss session redo`).
//!
//! What runs, on which input, is [`super::input`]'s: from `lens` or `edges`
//! the whole pipeline on the image's lit frames less its ambient frame (with
//! the image's `.cdf` for lens correction); from `lines` with the earlier
//! stages' parameters, on the frames as the console does (on the saved edge
//! files when there are no frames); from `connect` on the saved `.lex`. The
//! earlier stages' files and the parameters they were made with stay as
//! they are.

use std::fmt;

use super::input::Runner;
use super::manifest::{Counts, TimingsRecord};
use super::{OutputSet, Session, SessionError};
use crate::llv::edit::EditOp;
use crate::llv::params::Stage;
use crate::llv::pipeline::StageOutputs;
use crate::llv::{Params, Segment};

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
    /// `out.corrected[i]` belongs to the i-th lit frame, the order of
    /// [`super::PipelineInput::images`].
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
            timings: TimingsRecord::from(&out.timings),
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

    /// Re-runs image `k` from stage `from` with `params` and saves the
    /// result (replacing the `.ldr`, and with it the manual edits): the
    /// stages of [`Session::run_stages`], saved by [`Session::save_stages`].
    pub fn redo(
        &mut self,
        k: u32,
        from: Stage,
        params: &Params,
    ) -> Result<RedoSummary, SessionError> {
        self.writable()?;
        let mut runner = Runner::new();
        let (out, used) = self.run_stages(k, from, params, &mut runner)?;
        let lens_corrected = !out.corrected.is_empty();
        self.save_stages(k, from, out, &used)?;
        let o = self
            .manifest
            .image(k)
            .and_then(|r| r.outputs.as_ref())
            .ok_or_else(|| SessionError::Missing {
                session: self.name.to_string(),
                image: k,
                what: "outputs were not recorded".into(),
            })?;
        Ok(RedoSummary {
            image: k,
            from,
            counts: o.counts,
            timings: o.timings,
            lens_corrected,
        })
    }
}
