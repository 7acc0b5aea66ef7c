//! The Edit screen's actions: selecting lines by keyboard (next/previous,
//! nearest to the cursor, the two lines of a corner) and the manual
//! operations on them, each recorded in the session's edit log.

use super::{App, Level};
use crate::llv::edit::EditOp;
use crate::llv::{Point, Segment};
use crate::tui::event::{Cmd, StoreCmd};
use crate::tui::keymap::Action;
use crate::tui::widgets::preview::point_segment_distance;

impl App {
    pub(super) fn edit_action(&mut self, a: Action) -> Vec<Cmd> {
        let cursor = self.edit.cursor_point(self.preview_size());
        let Some(cur) = self.current.as_mut() else {
            self.log.push(
                Level::Warn,
                "no lines to edit: capture and run an image first",
            );
            return Vec::new();
        };
        let k = cur.k;
        let Some(ed) = cur.editor.as_mut() else {
            self.log.push(
                Level::Warn,
                "no lines to edit yet: the pipeline is still running",
            );
            return Vec::new();
        };
        let lines = ed.lines();
        let n = lines.len();
        let sel = &mut self.edit.selected;
        let op = match a {
            Action::LineNext | Action::LinePrev => {
                if n > 0 {
                    let last = sel.last().copied();
                    let i = match (a, last) {
                        (Action::LineNext, Some(i)) => (i + 1) % n,
                        (Action::LinePrev, Some(i)) => (i + n - 1) % n,
                        (Action::LineNext, None) => 0,
                        _ => n - 1,
                    };
                    *sel = vec![i];
                }
                return Vec::new();
            }
            Action::LineNearest => {
                *sel = nearest_line(lines, cursor).into_iter().collect();
                return Vec::new();
            }
            Action::Mark => {
                if let Some(i) = nearest_line(lines, cursor) {
                    if let Some(pos) = sel.iter().position(|&s| s == i) {
                        sel.remove(pos);
                    } else {
                        sel.push(i);
                    }
                }
                return Vec::new();
            }
            Action::Corner => {
                *sel = corner_lines(lines, cursor);
                if sel.len() < 2 {
                    self.log
                        .push(Level::Warn, "no corner of two lines near the cursor");
                }
                return Vec::new();
            }
            Action::Connect | Action::Extend => {
                let [i, j] = sel[..] else {
                    self.log.push(
                        Level::Warn,
                        "select exactly two lines first (k at a corner, or Space on each)",
                    );
                    return Vec::new();
                };
                if a == Action::Connect {
                    EditOp::Connect(i, j)
                } else {
                    EditOp::Extend(i, j)
                }
            }
            Action::Delete => {
                if sel.is_empty() {
                    self.log
                        .push(Level::Warn, "select lines first (n, . or Space)");
                    return Vec::new();
                }
                EditOp::Delete(sel.clone())
            }
            Action::Undo | Action::RedoEdit => {
                let done = if a == Action::Undo {
                    ed.undo()
                } else {
                    ed.redo()
                };
                sel.clear();
                if !done {
                    self.log.push(Level::Info, "nothing to undo/redo");
                    return Vec::new();
                }
                cur.edits += 1;
                let what = if a == Action::Undo { "undo" } else { "redo" };
                return vec![Cmd::Store(StoreCmd::RecordEdit {
                    k,
                    what: what.into(),
                    lines: ed.lines().to_vec(),
                })];
            }
            _ => return Vec::new(),
        };
        let what = format!("{op:?}");
        match ed.apply(op) {
            Ok(()) => {
                sel.clear();
                cur.edits += 1;
                self.log.push(Level::Info, format!("edit: {what}"));
                vec![Cmd::Store(StoreCmd::RecordEdit {
                    k,
                    what,
                    lines: ed.lines().to_vec(),
                })]
            }
            Err(e) => {
                self.log.push(Level::Error, format!("edit refused: {e}"));
                Vec::new()
            }
        }
    }
}

/// The index of the line nearest to `p`.
pub fn nearest_line(lines: &[Segment], p: Point) -> Option<usize> {
    lines
        .iter()
        .enumerate()
        .map(|(i, s)| (i, point_segment_distance(p, s)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// The two different lines whose endpoints are nearest to `p`: the two ends
/// of the corner the operator points at.
pub fn corner_lines(lines: &[Segment], p: Point) -> Vec<usize> {
    let mut ends: Vec<(usize, f64)> = lines
        .iter()
        .enumerate()
        .map(|(i, s)| (i, s.a.dist(p).min(s.b.dist(p))))
        .collect();
    ends.sort_by(|a, b| a.1.total_cmp(&b.1));
    ends.into_iter().take(2).map(|e| e.0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_and_corner() {
        let ls = [
            Segment::new(Point::new(0.0, 0.0), Point::new(10.0, 0.0)),
            Segment::new(Point::new(11.0, 1.0), Point::new(11.0, 20.0)),
            Segment::new(Point::new(0.0, 30.0), Point::new(20.0, 30.0)),
        ];
        assert_eq!(nearest_line(&ls, Point::new(5.0, 28.0)), Some(2));
        let mut c = corner_lines(&ls, Point::new(10.5, 0.5));
        c.sort();
        assert_eq!(c, vec![0, 1]);
        assert_eq!(nearest_line(&[], Point::new(0.0, 0.0)), None);
    }
}
