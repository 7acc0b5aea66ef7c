//! The Edit screen's state and keys: a highlighted line (next, previous,
//! nearest the cursor), a selection (`Space` toggles the highlighted line,
//! the corner key takes the two lines of a corner), and the operations on
//! it — connect, extend, delete, undo, redo — each written to the session
//! at once. Editing an accepted image asks first, and so does an edit
//! whose result looks like nonsense ([`doubtful`]: a corner far outside the
//! image or far from both lines, a joining line across half the image); the
//! lines an edit made are highlighted after it; the log says in words what
//! was done.

use super::{Ctx, Pending, PreviewNav};
use crate::llv::edit::{
    EditOp, corner_lines, describe, nearest_line, point_segment_distance, point_words, result_lines,
};
use crate::llv::{Point, Segment};
use crate::tui::event::{Cmd, StoreCmd};
use crate::tui::keymap::EditAction;

pub use crate::llv::edit::describe as describe_op;

/// The Edit screen's own state.
#[derive(Clone, Debug, Default)]
pub struct EditScreen {
    /// The line the keys point at.
    pub highlighted: Option<usize>,
    /// The lines an operation takes.
    pub selected: Vec<usize>,
    /// The lines the last edit made or moved.
    pub result: Vec<usize>,
    pub nav: PreviewNav,
    /// The edit waiting for the answer to "edit an accepted image?" or
    /// "... anyway?".
    pub waiting: Option<EditAction>,
    /// The operator said yes to the doubtful edit about to be applied.
    doubt_confirmed: bool,
}

impl EditScreen {
    /// Forgets the highlight and selection (the lines changed under them).
    pub fn clear(&mut self) {
        self.highlighted = None;
        self.selected.clear();
        self.result.clear();
    }

    /// The cursor as an image point (image centre before it moves).
    pub fn cursor_point(&self, size: Option<(usize, usize)>) -> Point {
        let (x, y) = self.nav.cursor_or_centre(size.unwrap_or((1, 1)));
        Point::new(x as f64, y as f64)
    }

    pub fn update(&mut self, a: EditAction, ctx: &mut Ctx) -> Vec<Cmd> {
        let cursor = self.cursor_point(ctx.tracker.preview_size());
        let Some(cur) = ctx.tracker.current.as_ref() else {
            ctx.warn("no lines to edit: capture and run an image, or go to one (Survey, 1)");
            return Vec::new();
        };
        let Some(lines) = cur.lines() else {
            ctx.warn("no lines to edit yet: the pipeline is still running");
            return Vec::new();
        };
        let n = lines.len();
        let (k, accepted, confirmed) = (cur.k, cur.accepted, cur.edit_confirmed);
        let op = match a {
            EditAction::LineNext | EditAction::LinePrev => {
                if n > 0 {
                    self.highlighted = Some(match (a, self.highlighted) {
                        (EditAction::LineNext, Some(i)) => (i + 1) % n,
                        (EditAction::LinePrev, Some(i)) => (i + n - 1) % n,
                        (EditAction::LineNext, None) => 0,
                        _ => n - 1,
                    });
                }
                return Vec::new();
            }
            EditAction::LineNearest => {
                self.highlighted = nearest_line(lines, cursor);
                return Vec::new();
            }
            EditAction::Toggle => {
                let Some(i) = self.highlighted.filter(|&i| i < n) else {
                    ctx.warn("highlight a line first: n, p or . (nearest the cursor)");
                    return Vec::new();
                };
                if let Some(pos) = self.selected.iter().position(|&s| s == i) {
                    self.selected.remove(pos);
                } else {
                    self.selected.push(i);
                }
                return Vec::new();
            }
            EditAction::Corner => {
                self.selected = corner_lines(lines, cursor);
                self.highlighted = self.selected.first().copied();
                if self.selected.len() < 2 {
                    ctx.warn("no corner of two lines near the cursor");
                }
                return Vec::new();
            }
            EditAction::ClearSelection => {
                self.clear();
                return Vec::new();
            }
            EditAction::Connect | EditAction::Extend => {
                let [i, j] = self.selected[..] else {
                    ctx.warn("select exactly two lines first (v at a corner, or Space on each)");
                    return Vec::new();
                };
                if a == EditAction::Connect {
                    Some(EditOp::Connect(i, j))
                } else {
                    Some(EditOp::Extend(i, j))
                }
            }
            EditAction::Delete => {
                let sel = if self.selected.is_empty() {
                    self.highlighted.into_iter().collect()
                } else {
                    self.selected.clone()
                };
                if sel.is_empty() {
                    ctx.warn("select lines first (n, . or Space)");
                    return Vec::new();
                }
                Some(EditOp::Delete(sel))
            }
            EditAction::Undo | EditAction::Redo => None,
        };
        if accepted && !confirmed {
            self.waiting = Some(a);
            ctx.ask(
                format!(
                    "Image {k} is accepted. Change its lines? Each edit rewrites its .ldr \
                     (undo takes it back)."
                ),
                Pending::Edit,
            );
            return Vec::new();
        }
        if let Some(op) = &op
            && !std::mem::take(&mut self.doubt_confirmed)
            && let Some(size) = ctx.tracker.preview_size()
            && let Some(why) = doubtful(op, lines, size)
        {
            self.waiting = Some(a);
            ctx.warn(format!("image {k}: {why}"));
            ctx.ask(
                format!("{why}. {} anyway?", verb(op)),
                Pending::EditDoubtful,
            );
            return Vec::new();
        }
        self.apply(op, a, ctx)
    }

    /// Carries out the doubtful edit the operator confirmed.
    pub fn doubt_confirmed(&mut self, ctx: &mut Ctx) -> Vec<Cmd> {
        match self.waiting.take() {
            Some(a) => {
                self.doubt_confirmed = true;
                let cmds = self.update(a, ctx);
                self.doubt_confirmed = false;
                cmds
            }
            None => Vec::new(),
        }
    }

    /// Carries out the edit the operator confirmed.
    pub fn confirmed(&mut self, ctx: &mut Ctx) -> Vec<Cmd> {
        if let Some(c) = ctx.tracker.current.as_mut() {
            c.edit_confirmed = true;
        }
        match self.waiting.take() {
            Some(a) => self.update(a, ctx),
            None => Vec::new(),
        }
    }

    fn apply(&mut self, op: Option<EditOp>, a: EditAction, ctx: &mut Ctx) -> Vec<Cmd> {
        let Some(cur) = ctx.tracker.current.as_mut() else {
            return Vec::new();
        };
        let k = cur.k;
        if cur.editor.is_none() {
            let lines = cur.lines().map(<[_]>::to_vec).unwrap_or_default();
            cur.editor = Some(crate::llv::edit::LineEditor::new(lines));
        }
        let Some(ed) = cur.editor.as_mut() else {
            return Vec::new();
        };
        let Some(op) = op else {
            // Undo and redo move in the editor's history; the session's
            // log keeps the edits in effect, so neither counts as an edit.
            let before = ed.lines().to_vec();
            let undo = a == EditAction::Undo;
            let redone = if undo { None } else { ed.next_redo().cloned() };
            let done = if undo { ed.undo() } else { ed.redo() };
            self.clear();
            if !done {
                ctx.info(if undo {
                    "nothing to undo"
                } else {
                    "nothing to redo"
                });
                return Vec::new();
            }
            let lines = ed.lines().to_vec();
            let (cmd, what) = match redone {
                Some(op) => {
                    let what = describe(&op, &before);
                    self.result = result_lines(&op, &lines);
                    (
                        StoreCmd::RecordEdit {
                            k,
                            what: what.clone(),
                            lines,
                        },
                        format!("redone: {what}"),
                    )
                }
                // Undone, the lines are those the edit was made on, so it
                // is described as it was when made.
                None => {
                    let what = ed
                        .next_redo()
                        .map_or_else(|| "the last edit".into(), |op| describe(op, &lines));
                    (StoreCmd::UndoEdit { k, lines }, format!("undone: {what}"))
                }
            };
            ctx.info(format!("image {k}: {what}"));
            return vec![Cmd::Store(cmd)];
        };
        let what = describe(&op, ed.lines());
        match ed.apply(op.clone()) {
            Ok(()) => {
                self.clear();
                let lines = ed.lines().to_vec();
                self.result = result_lines(&op, &lines);
                self.highlighted = self.result.first().copied();
                cur.edits += 1;
                ctx.info(format!("image {k}: {what}"));
                vec![Cmd::Store(StoreCmd::RecordEdit { k, what, lines })]
            }
            Err(e) => {
                ctx.error(format!("edit refused: {e}"));
                Vec::new()
            }
        }
    }
}

fn verb(op: &EditOp) -> &'static str {
    match op {
        EditOp::Connect(..) => "Connect",
        EditOp::Extend(..) => "Extend",
        EditOp::Delete(_) => "Delete",
    }
}

/// Why `op` on `lines` of a `size` (width, height) image looks like
/// nonsense, or `None`: an extension whose corner lies more than an eighth
/// of the image's larger side outside it, or more than a quarter of that
/// side from both lines (two nearly parallel lines meet far away); a
/// connection whose new line spans more than half of that side. The
/// operator may still have meant it, so the console asks rather than
/// refuses.
pub fn doubtful(op: &EditOp, lines: &[Segment], size: (usize, usize)) -> Option<String> {
    let (w, h) = (size.0 as f64, size.1 as f64);
    let side = w.max(h);
    match op {
        EditOp::Extend(i, j) => {
            let after = crate::llv::edit::apply(lines, op).ok()?;
            let (l1, l2) = (lines.get(*i)?, lines.get(*j)?);
            // Both lines end at the corner now: the end that moved.
            let n1 = after.get(*i)?;
            let x = if n1.a != l1.a { n1.a } else { n1.b };
            let outside = (-x.x).max(x.x - w).max(-x.y).max(x.y - h).max(0.0);
            let far = point_segment_distance(x, l1).min(point_segment_distance(x, l2));
            let corner = format!("lines {i} and {j} meet at {}", point_words(x));
            if outside > side / 8.0 {
                Some(format!(
                    "{corner}, {outside:.0} px outside the {}×{} image ({:.0} px from the \
                     nearer line)",
                    size.0, size.1, far
                ))
            } else if far > side / 4.0 {
                Some(format!(
                    "{corner}, {far:.0} px from the nearer of the two: nearly parallel lines"
                ))
            } else {
                None
            }
        }
        EditOp::Connect(i, j) => {
            let after = crate::llv::edit::apply(lines, op).ok()?;
            let new = after.last()?;
            let len = new.length();
            (len > side / 2.0).then(|| {
                format!(
                    "connecting lines {i} and {j} draws a line {len:.0} px long, across more \
                     than half the image"
                )
            })
        }
        EditOp::Delete(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    #[test]
    fn nearly_parallel_lines_extended_far_outside_are_doubtful() {
        // Two lines 1° apart on a 512² image meet far outside it.
        let lines = [
            seg(100.0, 100.0, 300.0, 100.0),
            seg(100.0, 120.0, 300.0, 123.5),
        ];
        let why = doubtful(&EditOp::Extend(0, 1), &lines, (512, 512)).expect("doubtful");
        assert!(why.contains("outside the 512×512 image"), "{why}");
        // A corner of two square lines just beside them is not.
        let corner = [
            seg(100.0, 100.0, 300.0, 100.0),
            seg(310.0, 110.0, 310.0, 300.0),
        ];
        assert_eq!(doubtful(&EditOp::Extend(0, 1), &corner, (512, 512)), None);
    }

    #[test]
    fn a_corner_inside_the_image_but_far_from_both_lines_is_doubtful() {
        let lines = [seg(10.0, 10.0, 60.0, 10.0), seg(400.0, 300.0, 400.0, 400.0)];
        let why = doubtful(&EditOp::Extend(0, 1), &lines, (512, 512)).expect("doubtful");
        assert!(why.contains("from the nearer of the two"), "{why}");
    }

    #[test]
    fn a_connection_across_the_image_is_doubtful_a_short_one_not() {
        let lines = [seg(10.0, 10.0, 50.0, 10.0), seg(480.0, 480.0, 500.0, 500.0)];
        assert!(doubtful(&EditOp::Connect(0, 1), &lines, (512, 512)).is_some());
        let near = [seg(10.0, 10.0, 50.0, 10.0), seg(60.0, 12.0, 100.0, 12.0)];
        assert_eq!(doubtful(&EditOp::Connect(0, 1), &near, (512, 512)), None);
    }
}
