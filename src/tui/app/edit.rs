//! The Edit screen's state and keys: a highlighted line (next, previous,
//! nearest the cursor), a selection (`Space` toggles the highlighted line,
//! the corner key takes the two lines of a corner), and the operations on
//! it — connect, extend, delete, undo, redo — each written to the session
//! at once. Editing an accepted image asks first; the lines an edit made
//! are highlighted after it; the log says in words what was done.

use super::{Ctx, Pending, PreviewNav};
use crate::llv::Point;
use crate::llv::edit::{EditOp, corner_lines, describe, nearest_line, result_lines};
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
    /// The edit waiting for the answer to "edit an accepted image?".
    pub waiting: Option<EditAction>,
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
        self.apply(op, a, ctx)
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
                None => (
                    StoreCmd::UndoEdit { k, lines },
                    "undone: the last edit".into(),
                ),
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
