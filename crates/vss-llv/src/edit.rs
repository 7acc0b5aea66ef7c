//! The operator's manual edits of a line set (llv.md §5): connect, extend and
//! delete, each undoable and redoable. [`LineEditor`] keeps the applied
//! operations as a log (what the session records) and a snapshot per step
//! (line sets are a few hundred segments, so snapshots are cheap and make
//! undo exact).

use serde::{Deserialize, Serialize};

use super::{Point, Segment};
use crate::fit::Line;

/// One manual operation; indices refer to the line set it is applied to.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum EditOp {
    /// Add a segment between the nearest endpoints of two lines.
    Connect(usize, usize),
    /// Extend two lines until their endpoints meet at their intersection.
    Extend(usize, usize),
    /// Remove lines.
    Delete(Vec<usize>),
}

/// Why an edit cannot be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EditError {
    #[error("there is no line {index}: the set has {len} lines (numbered from 0)")]
    NoSuchLine { index: usize, len: usize },
    #[error("line {0} cannot be joined to itself: pick two different lines")]
    SameLine(usize),
    #[error("lines {0} and {1} are parallel: they have no intersection to extend to")]
    Parallel(usize, usize),
    #[error("nothing to delete: select at least one line")]
    NothingSelected,
}

/// Applies `op` to `lines`, returning the new set (the input is untouched).
pub fn apply(lines: &[Segment], op: &EditOp) -> Result<Vec<Segment>, EditError> {
    let check = |i: usize| {
        if i < lines.len() {
            Ok(())
        } else {
            Err(EditError::NoSuchLine {
                index: i,
                len: lines.len(),
            })
        }
    };
    match op {
        EditOp::Connect(i, j) => {
            check(*i)?;
            check(*j)?;
            if i == j {
                return Err(EditError::SameLine(*i));
            }
            let (l1, l2) = (lines[*i], lines[*j]);
            let mut best = (f64::INFINITY, l1.a, l2.a);
            for p in [l1.a, l1.b] {
                for q in [l2.a, l2.b] {
                    if p.dist(q) < best.0 {
                        best = (p.dist(q), p, q);
                    }
                }
            }
            let mut out = lines.to_vec();
            out.push(Segment::new(best.1, best.2));
            Ok(out)
        }
        EditOp::Extend(i, j) => {
            check(*i)?;
            check(*j)?;
            if i == j {
                return Err(EditError::SameLine(*i));
            }
            let (l1, l2) = (lines[*i], lines[*j]);
            let (Some(g1), Some(g2)) = (line_of(&l1), line_of(&l2)) else {
                return Err(EditError::Parallel(*i, *j));
            };
            let x = g1.intersect(&g2).ok_or(EditError::Parallel(*i, *j))?;
            let mut out = lines.to_vec();
            out[*i] = move_nearer_end(l1, x);
            out[*j] = move_nearer_end(l2, x);
            Ok(out)
        }
        EditOp::Delete(idx) => {
            if idx.is_empty() {
                return Err(EditError::NothingSelected);
            }
            for &i in idx {
                check(i)?;
            }
            Ok(lines
                .iter()
                .enumerate()
                .filter(|(k, _)| !idx.contains(k))
                .map(|(_, l)| *l)
                .collect())
        }
    }
}

/// The infinite line through a segment (`None` if it has no length).
fn line_of(s: &Segment) -> Option<Line> {
    let len = s.length();
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let (a, b) = (-(s.b.y - s.a.y) / len, (s.b.x - s.a.x) / len);
    Some(Line {
        a,
        b,
        c: -(a * s.a.x + b * s.a.y),
    })
}

/// The segment with its endpoint nearer to `x` moved to `x`.
fn move_nearer_end(s: Segment, x: Point) -> Segment {
    if s.a.dist(x) <= s.b.dist(x) {
        Segment { a: x, ..s }
    } else {
        Segment { b: x, ..s }
    }
}

/// A line set under manual editing, with undo and redo.
#[derive(Clone, Debug, Default)]
pub struct LineEditor {
    /// `states[0]` is the original set; `states[k]` follows `log[k-1]`.
    states: Vec<Vec<Segment>>,
    log: Vec<EditOp>,
    /// Number of operations currently applied.
    pos: usize,
}

impl LineEditor {
    pub fn new(lines: Vec<Segment>) -> Self {
        LineEditor {
            states: vec![lines],
            log: Vec::new(),
            pos: 0,
        }
    }

    /// Applies an operation; any undone operations are forgotten.
    pub fn apply(&mut self, op: EditOp) -> Result<(), EditError> {
        let next = apply(self.lines(), &op)?;
        self.states.truncate(self.pos + 1);
        self.log.truncate(self.pos);
        self.states.push(next);
        self.log.push(op);
        self.pos += 1;
        Ok(())
    }

    /// Undoes the last applied operation; false when there is none.
    pub fn undo(&mut self) -> bool {
        if self.pos == 0 {
            return false;
        }
        self.pos -= 1;
        true
    }

    /// Re-applies the last undone operation; false when there is none.
    pub fn redo(&mut self) -> bool {
        if self.pos + 1 >= self.states.len() {
            return false;
        }
        self.pos += 1;
        true
    }

    /// The current line set.
    pub fn lines(&self) -> &[Segment] {
        self.states.get(self.pos).map_or(&[], |v| v.as_slice())
    }

    /// The operations applied to reach the current set, in order.
    pub fn log(&self) -> &[EditOp] {
        &self.log[..self.pos.min(self.log.len())]
    }

    /// The operation a redo would re-apply.
    pub fn next_redo(&self) -> Option<&EditOp> {
        self.log.get(self.pos)
    }

    /// The original line set.
    pub fn original(&self) -> &[Segment] {
        self.states.first().map_or(&[], |v| v.as_slice())
    }
}

/// Distance from a point to a segment (pixels).
pub fn point_segment_distance(p: Point, s: &Segment) -> f64 {
    let (vx, vy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let len2 = vx * vx + vy * vy;
    let t = if len2 > 0.0 {
        (((p.x - s.a.x) * vx + (p.y - s.a.y) * vy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.dist(Point::new(s.a.x + t * vx, s.a.y + t * vy))
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

/// A point in whole pixels for the operator, `(12,-3)`: a coordinate that
/// rounds to zero reads `0`, never `-0` (an endpoint a hair outside the
/// image's edge).
pub fn point_words(p: Point) -> String {
    let whole = |v: f64| {
        let r = v.round();
        if r == 0.0 { 0.0 } else { r }
    };
    format!("({:.0},{:.0})", whole(p.x), whole(p.y))
}

/// An edit in words, with the lines it touched as they were before it:
/// `connected lines 5 (10,20)-(90,20) and 4 (92,21)-(160,21)`.
pub fn describe(op: &EditOp, before: &[Segment]) -> String {
    let line = |i: usize| match before.get(i) {
        Some(s) => format!("{i} {}-{}", point_words(s.a), point_words(s.b)),
        None => i.to_string(),
    };
    match op {
        EditOp::Connect(i, j) => format!("connected lines {} and {}", line(*i), line(*j)),
        EditOp::Extend(i, j) => format!(
            "extended lines {} and {} to their intersection",
            line(*i),
            line(*j)
        ),
        EditOp::Delete(v) => {
            let list: Vec<String> = v.iter().map(|i| line(*i)).collect();
            let s = if v.len() == 1 { "" } else { "s" };
            format!("deleted line{s} {}", list.join(", "))
        }
    }
}

/// The lines an edit made or moved, as indices of the set after it.
pub fn result_lines(op: &EditOp, after: &[Segment]) -> Vec<usize> {
    match op {
        EditOp::Connect(..) => after.len().checked_sub(1).into_iter().collect(),
        EditOp::Extend(i, j) => vec![*i, *j],
        EditOp::Delete(_) => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    #[test]
    fn nearest_corner_and_words() {
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
        assert_eq!(
            describe(&EditOp::Connect(1, 0), &ls),
            "connected lines 1 (11,1)-(11,20) and 0 (0,0)-(10,0)"
        );
        assert_eq!(
            describe(&EditOp::Delete(vec![2]), &ls),
            "deleted line 2 (0,30)-(20,30)"
        );
        // An endpoint a hair left of the image reads 0, not -0.
        let edge = [seg(-0.3, 262.0, 273.4, -0.49)];
        assert_eq!(
            describe(&EditOp::Delete(vec![0]), &edge),
            "deleted line 0 (0,262)-(273,0)"
        );
        let after = apply(&ls, &EditOp::Connect(0, 1)).unwrap();
        assert_eq!(result_lines(&EditOp::Connect(0, 1), &after), vec![3]);
        assert!((point_segment_distance(Point::new(5.0, 3.0), &ls[0]) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn connect_extend_delete_with_undo_redo() {
        let start = vec![seg(0.0, 0.0, 10.0, 0.0), seg(15.0, 3.0, 15.0, 20.0)];
        let mut ed = LineEditor::new(start.clone());
        ed.apply(EditOp::Connect(0, 1)).unwrap();
        assert_eq!(ed.lines().len(), 3);
        assert_eq!(ed.lines()[2], seg(10.0, 0.0, 15.0, 3.0));
        assert!(ed.undo());
        assert_eq!(ed.lines(), &start[..]);
        ed.apply(EditOp::Extend(0, 1)).unwrap();
        assert_eq!(ed.lines()[0].b, Point::new(15.0, 0.0));
        assert_eq!(ed.lines()[1].a, Point::new(15.0, 0.0));
        assert!(!ed.redo(), "applying after undo drops the redo branch");
        assert_eq!(ed.log(), &[EditOp::Extend(0, 1)]);
        ed.apply(EditOp::Delete(vec![0])).unwrap();
        assert_eq!(ed.lines().len(), 1);
        assert!(ed.undo() && ed.undo() && !ed.undo());
        assert_eq!(ed.lines(), &start[..]);
        assert!(ed.redo());
        assert_eq!(ed.log().len(), 1);
        assert!(ed.redo() && !ed.redo());
        assert_eq!(ed.lines().len(), 1);
    }

    #[test]
    fn bad_edits_are_errors_and_change_nothing() {
        let mut ed = LineEditor::new(vec![seg(0.0, 0.0, 10.0, 0.0), seg(0.0, 5.0, 10.0, 5.0)]);
        assert_eq!(
            ed.apply(EditOp::Extend(0, 1)),
            Err(EditError::Parallel(0, 1))
        );
        assert!(matches!(
            ed.apply(EditOp::Connect(0, 7)),
            Err(EditError::NoSuchLine { index: 7, len: 2 })
        ));
        assert_eq!(ed.apply(EditOp::Connect(1, 1)), Err(EditError::SameLine(1)));
        assert_eq!(
            ed.apply(EditOp::Delete(vec![])),
            Err(EditError::NothingSelected)
        );
        assert!(ed.log().is_empty() && ed.lines().len() == 2);
    }
}
