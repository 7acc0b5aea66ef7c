//! CONNECT's index of the segments that may merge with one: a uniform grid
//! over the environments' bounds, each cell listing the segments whose
//! environments (as they are, or were before they grew) overlap it, each
//! with the bin of its direction. Two environments that meet share a cell
//! and, their directions differing by at most the largest merge angle, lie
//! in the same or neighbouring bins (a bin is wider than that angle): a
//! segment's possible partners are those listed in its own cells in its
//! own or a neighbouring bin.

use super::Geo;

/// A uniform grid of cells, each a list of `(segment, direction bin)`.
#[derive(Clone, Debug, Default)]
pub(super) struct Grid {
    x0: f64,
    y0: f64,
    /// 1 / cell size.
    inv: f64,
    nx: usize,
    ny: usize,
    /// Direction bins over the half turn (1: directions not binned).
    bins: usize,
    /// The [`Geo::turn`] at which each bin after the first starts.
    starts: Vec<f64>,
    cells: Vec<Vec<(u32, u8)>>,
    /// Per cell: how many of its first entries are in ascending order
    /// (those listed before [`Grid::seal`]).
    sealed: Vec<u32>,
    /// Per cell: the first of those after the segment of the first pass
    /// that gathered last ([`Grid::after_in_order`]).
    cursor: Vec<u32>,
}

/// Cell size (px): about an environment's length beyond an end (`wl`)
/// plus a short line.
const CELL: f64 = 32.0;
/// Up to this many segments (a synthetic scene's few tens) the grid is one
/// cell: placing them costs more than testing every pair.
const FEW: usize = 64;
/// The most cells along an axis (coordinates far off the image, from a
/// damaged line file, widen the cells instead).
const MAX_CELLS: usize = 256;
/// The most direction bins (a bin is a bit of a `u64` mask).
const MAX_BINS: usize = 64;
/// How much wider (degrees) a direction bin is than the largest merge
/// angle: far beyond the rounding of the angle test.
const BIN_MARGIN_DEG: f64 = 0.5;

/// Marks of the segments already seen in one gathering, renewed by a new
/// epoch rather than cleared.
#[derive(Clone, Debug, Default)]
pub(super) struct Seen {
    mark: Vec<u32>,
    epoch: u32,
}

impl Seen {
    pub(super) fn reset(&mut self, n: usize) {
        self.mark.clear();
        self.mark.resize(n, 0);
        self.epoch = 0;
    }

    fn next(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.mark.fill(0);
            self.epoch = 1;
        }
    }

    /// Whether `k` is seen for the first time in this gathering.
    fn first(&mut self, k: usize) -> bool {
        let new = self.mark[k] != self.epoch;
        self.mark[k] = self.epoch;
        new
    }
}

impl Grid {
    /// An empty grid over the bounds of `geo`, with direction bins for
    /// merges up to `max_angle` (radians).
    pub(super) fn reset(&mut self, geo: &[Geo], max_angle: f64) {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for g in geo {
            b[0] = b[0].min(g.bounds[0]);
            b[1] = b[1].min(g.bounds[1]);
            b[2] = b[2].max(g.bounds[2]);
            b[3] = b[3].max(g.bounds[3]);
        }
        let (w, h) = (b[2] - b[0], b[3] - b[1]);
        if geo.len() <= FEW || !(w.is_finite() && h.is_finite()) {
            // Few segments (or bounds that overflow): one cell holds them all.
            (self.x0, self.y0, self.inv, self.nx, self.ny) = (0.0, 0.0, 0.0, 1, 1);
        } else {
            let cell = CELL.max(w.max(h) / MAX_CELLS as f64);
            self.x0 = b[0];
            self.y0 = b[1];
            self.inv = 1.0 / cell;
            self.nx = ((w * self.inv) as usize + 1).min(MAX_CELLS);
            self.ny = ((h * self.inv) as usize + 1).min(MAX_CELLS);
        }
        // Bins of at least the merge angle and the margin; fewer than three
        // would all neighbour each other: one.
        let bins = (180.0 / (max_angle.to_degrees() + BIN_MARGIN_DEG)).floor();
        self.bins = if bins >= 3.0 {
            (bins as usize).min(MAX_BINS)
        } else {
            1
        };
        let step = std::f64::consts::PI / self.bins as f64;
        self.starts.clear();
        self.starts
            .extend((1..self.bins).map(|b| 1.0 - (b as f64 * step).cos()));
        self.clear();
    }

    /// Empties the cells, keeping the layout.
    pub(super) fn clear(&mut self) {
        let n = self.nx * self.ny;
        if self.cells.len() < n {
            self.cells.resize_with(n, Vec::new);
        }
        for c in &mut self.cells[..n] {
            c.clear();
        }
    }

    /// An empty grid of `other`'s layout.
    pub(super) fn reset_like(&mut self, other: &Grid) {
        (self.x0, self.y0, self.inv, self.nx, self.ny, self.bins) = (
            other.x0, other.y0, other.inv, other.nx, other.ny, other.bins,
        );
        self.starts.clone_from(&other.starts);
        self.clear();
    }

    /// The direction bin of `g`: its angle in `[0, π]` over the bins
    /// (by its [`Geo::turn`]; rounding at a bin's edge moves a direction by
    /// far less than the bins' margin over the merge angle).
    fn bin(&self, g: &Geo) -> u8 {
        self.starts.partition_point(|&s| s <= g.turn) as u8
    }

    /// The bins next to `g`'s (its own included), as a mask.
    fn near(&self, g: &Geo) -> u64 {
        if self.bins == 1 {
            return 1;
        }
        let (b, n) = (self.bin(g) as usize, self.bins);
        let next = if b + 1 == n { 0 } else { b + 1 };
        let prev = if b == 0 { n - 1 } else { b - 1 };
        (1 << b) | (1 << next) | (1 << prev)
    }

    /// Calls `f` with each cell the environment `g` overlaps: for each row
    /// of cells under its bounds, the columns of the rectangle's part in
    /// that row's band (clipped exactly: a long oblique line covers a few
    /// cells a row, not its whole bounding box), widened by `SLACK`.
    fn each_cell(&self, g: &Geo, mut f: impl FnMut(usize)) {
        const SLACK: f64 = 1e-6;
        if self.nx * self.ny == 1 {
            f(0);
            return;
        }
        // (Not negative, NaN made 0: truncated to an `i64`, one
        // instruction, rather than a `usize`.)
        let col = |x: f64| (((x - self.x0) * self.inv).max(0.0) as i64 as usize).min(self.nx - 1);
        let row = |y: f64| (((y - self.y0) * self.inv).max(0.0) as i64 as usize).min(self.ny - 1);
        let (r0, r1) = (row(g.bounds[1] - SLACK), row(g.bounds[3] + SLACK));
        let (c0, c1) = (col(g.bounds[0] - SLACK), col(g.bounds[2] + SLACK));
        if r0 == r1 || c0 == c1 || (r1 - r0 == 1 && c1 - c0 == 1) {
            // Bounds of one row or one column of cells (most environments):
            // the clipping below would keep them all; of 2 × 2 it would
            // drop one at most, not worth its cost.
            for cy in r0..=r1 {
                for cx in c0..=c1 {
                    f(cy * self.nx + cx);
                }
            }
            return;
        }
        let r = &g.env;
        let (lx, ly) = (r.d.0 * r.hl, r.d.1 * r.hl);
        let (wx, wy) = (-r.d.1 * r.hw, r.d.0 * r.hw);
        let corners = [
            (r.c.x + lx + wx, r.c.y + ly + wy),
            (r.c.x + lx - wx, r.c.y + ly - wy),
            (r.c.x - lx - wx, r.c.y - ly - wy),
            (r.c.x - lx + wx, r.c.y - ly + wy),
        ];
        for cy in r0..=r1 {
            // The band of this row (the outer rows reach to the bounds).
            let lo = if cy == r0 {
                f64::NEG_INFINITY
            } else {
                self.y0 + cy as f64 / self.inv - SLACK
            };
            let hi = if cy == r1 {
                f64::INFINITY
            } else {
                self.y0 + (cy + 1) as f64 / self.inv + SLACK
            };
            let (mut xmin, mut xmax) = (f64::INFINITY, f64::NEG_INFINITY);
            for (k, &(x, y)) in corners.iter().enumerate() {
                if (lo..=hi).contains(&y) {
                    xmin = xmin.min(x);
                    xmax = xmax.max(x);
                }
                let (x2, y2) = corners[(k + 1) % 4];
                for yb in [lo, hi] {
                    if (y - yb) * (y2 - yb) < 0.0 {
                        let xb = x + (x2 - x) * (yb - y) / (y2 - y);
                        xmin = xmin.min(xb);
                        xmax = xmax.max(xb);
                    }
                }
            }
            if xmin.partial_cmp(&xmax).is_none_or(|o| o.is_gt()) {
                // A band the rectangle only touches (or coordinates too large
                // to clip): its whole row under the bounds.
                (xmin, xmax) = (g.bounds[0], g.bounds[2]);
            }
            for cx in col(xmin - SLACK)..=col(xmax + SLACK) {
                f(cy * self.nx + cx);
            }
        }
    }

    /// Marks each cell's entries so far as its ascending prefix (the
    /// segments were inserted in order), for [`Grid::after_in_order`].
    pub(super) fn seal(&mut self) {
        let n = self.nx * self.ny;
        self.sealed.clear();
        self.sealed
            .extend(self.cells[..n].iter().map(|c| c.len() as u32));
        self.cursor.clear();
        self.cursor.resize(n, 0);
    }

    /// [`Grid::after`] for the first pass over a sealed grid, `i` never
    /// less than at the last call: the segments after `i` are unchanged, so
    /// their entries of the sealed prefixes are all there is to read, and
    /// in each cell those of the segments up to `i` are skipped for good
    /// (the entries added since are of segments up to `i`).
    pub(super) fn after_in_order(
        &mut self,
        i: u32,
        g: &Geo,
        seen: &mut Seen,
        out: &mut Vec<u32>,
        mut keep: impl FnMut(usize) -> bool,
    ) {
        out.clear();
        seen.next();
        let near = self.near(g);
        let mut cursor = std::mem::take(&mut self.cursor);
        self.each_cell(g, |c| {
            let (cell, end) = (&self.cells[c], self.sealed[c] as usize);
            let mut at = cursor[c] as usize;
            while at < end && cell[at].0 <= i {
                at += 1;
            }
            cursor[c] = at as u32;
            for &(k, b) in &cell[at..end] {
                if near >> b & 1 != 0 && seen.first(k as usize) && keep(k as usize) {
                    out.push(k);
                }
            }
        });
        self.cursor = cursor;
        out.sort_unstable();
    }

    /// Lists segment `k` with environment `g` in its cells. A segment
    /// listed again after it grew gets its new direction's bin: where its
    /// entry is a cell's last, that entry's bin is overwritten (an old bin
    /// would hide the grown segment from partners of its new direction).
    pub(super) fn insert(&mut self, k: u32, g: &Geo) {
        let b = self.bin(g);
        let mut cells = std::mem::take(&mut self.cells);
        self.each_cell(g, |c| {
            let c = &mut cells[c];
            match c.last_mut() {
                Some(e) if e.0 == k => e.1 = b,
                _ => c.push((k, b)),
            }
        });
        self.cells = cells;
    }

    /// Into `out`, ascending and without repeats: the segments `k` after
    /// `i` listed in the cells `g` overlaps in a bin next to `g`'s, for
    /// which `keep(k)` holds (called once for each).
    pub(super) fn after(
        &self,
        i: u32,
        g: &Geo,
        seen: &mut Seen,
        out: &mut Vec<u32>,
        mut keep: impl FnMut(usize) -> bool,
    ) {
        out.clear();
        seen.next();
        let near = self.near(g);
        self.each_cell(g, |c| {
            for &(k, b) in &self.cells[c] {
                if k > i && near >> b & 1 != 0 && seen.first(k as usize) && keep(k as usize) {
                    out.push(k);
                }
            }
        });
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ConnectParams;
    use crate::{Point, Segment};

    fn geo(ax: f64, ay: f64, bx: f64, by: f64) -> Geo {
        Geo::of(
            &Segment::new(Point::new(ax, ay), Point::new(bx, by)),
            &ConnectParams::default(),
        )
    }

    #[test]
    fn a_segment_listed_again_after_it_grew_is_found_by_its_new_direction() {
        // Segment 1 first points 30° off segment 0, then (merged with a
        // third, say) lies along it: a partner search from 0 must find it.
        let g0 = geo(0.0, 0.0, 40.0, 0.0);
        let before = geo(45.0, 0.0, 80.0, 20.2);
        let after = geo(45.0, 0.2, 90.0, 0.5);
        let mut grid = Grid::default();
        grid.reset(&[g0, before], 5f64.to_radians());
        assert!(grid.bins > 3 && grid.bin(&before) != grid.bin(&after));
        grid.insert(0, &g0);
        grid.insert(1, &before);
        grid.seal();
        let (mut seen, mut out) = (Seen::default(), Vec::new());
        seen.reset(2);
        grid.after(0, &g0, &mut seen, &mut out, |_| true);
        assert!(out.is_empty(), "30° apart: not a candidate, {out:?}");
        grid.insert(1, &after);
        grid.after(0, &g0, &mut seen, &mut out, |_| true);
        assert_eq!(out, [1]);
    }
}
