//! The line extractor (llv.md §3): follows edge points from scan line to
//! scan line, predicting the next point from the least-squares line of the
//! points found so far, and keeps the segments that are long enough and not
//! too close to the scan direction.
//!
//! The extractor works in *scan coordinates* `(u, v)`: `u` runs along the
//! scan, `v` counts scan lines. For `EdgeH` that is `(x, y)`; for `EdgeV` it
//! is `(y, x)` — "swap x and y" of §3. A line is tracked towards increasing
//! `v` (down the image for `EdgeH`, to the right for `EdgeV`).
//!
//! Settled details:
//! - points are visited in lexical order of the scan frame (scan line by scan
//!   line, then along the scan); a visited start point is marked used;
//! - templates (§3.1) are correlated with all edge points, used or not; the
//!   first template with the largest score wins, in the order
//!   `-π/2, -π/4, -3π/4, 0`. The `0` template (a line along the scan) cannot
//!   be followed across scan lines: such a start is tracked as if
//!   perpendicular and the min-scan-angle test drops it if it really runs
//!   along the scan;
//! - the prediction's slope `du/dv` is clamped to ±8 (7° from the scan);
//! - the search window is `±search_width` around the prediction on each of
//!   the next `max_gap` scan lines (`for i in 1..=max_gap` of §3, so at most
//!   `max_gap - 1` empty scan lines are bridged), nearest unused point first (ties: smaller
//!   `u`);
//! - once a track has two points, the next point is predicted from its
//!   fitted line (not from the last point found), and only points of the
//!   start point's polarity (sign of the response) are taken: a straight
//!   edge keeps both, a track bending round a corner or a noise chain does
//!   not;
//! - once a track has 8 points, a next point more than 1.5 px from its
//!   fitted line ends it (shallow corners, branching shadow edges);
//! - a track whose mean |response| is below `min_response` is dropped as
//!   noise (a parameter the original did not have; see `LineParams`);
//! - the segment runs from the projection of its first point to that of its
//!   last; `response` is the mean signed response of its points, `residual`
//!   their RMS distance from the line.
//!
//! Speed: most edge points are noise (the adaptive threshold keeps at
//! least `M` a scan line), so the cost is in rejecting starts cheaply.
//! Input already in the scan frame's lexical order (EdgeH, row by row) is
//! filed in one pass; other input (EdgeV, which the edge stage emits row
//! by row, and points read from files in any order) by a counting sort.
//! Emitting EdgeV column by column instead cost the edge stage more than
//! it saved here. Each point's rounded `u` is kept, and a `Grid` of
//! bitmaps (every point; the unused ones by polarity; side by side per
//! word) answers "is there an unused point near here?" and the template
//! scores with a few word operations; points are found from a column by
//! the index of each word's first point instead of binary searches. The
//! successor test reads one 64-column window a scan line ahead, centred
//! on the start's column, against masks computed once a call (`Reach`:
//! the columns that can hold a candidate, and those within reach wherever
//! the start lies in its pixel), and compares floats only at the end
//! columns; the template scores are one table look-up a row. A track's
//! window is centred on the column nearest its prediction. The main loop
//! is generic over grid and walking, with the walking helpers out of line,
//! so that the grid loop keeps its values in registers (9.8 → 7.0 M
//! instructions for the H and V points of the 512² bench scene; a test
//! compares the result with that of the extractor before, kept in
//! `lines/reference.rs`, bit for bit). The bitmaps are exact only when
//! no two points of a scan line share a column (true of edge points, one
//! pixel thick), and are only built when they take at most 16 words a
//! point (so a stray point far outside the image does not size them);
//! otherwise — a hand-made file — the extractor walks the scan lines with
//! binary searches, with the same result (a test compares both).

use super::fit::LineFit;
use super::params::LineParams;
use super::{EdgePoint, EdgePoints, Point, ScanDir, Segment};

#[cfg(test)]
mod reference;

/// Largest `|du/dv|` used for the prediction.
const MAX_SLOPE: f64 = 8.0;

/// Points a track needs before the stray-point test applies, and the
/// distance (px) from its fitted line at which a next point ends it.
const STRAY_AFTER: usize = 8;
const STRAY_DISTANCE: f64 = 1.5;

/// Templates of §3.1, `[template][j + 2][i + 2]` (rows down, columns right),
/// in the order φ = 0, -π/4, -π/2, -3π/4.
const TEMPLATES: [[[u8; 5]; 5]; 4] = [
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 1, 1],
        [0, 0, 0, 2, 2],
        [0, 0, 0, 1, 1],
        [0, 0, 0, 0, 0],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 0, 1, 0, 0],
        [0, 0, 1, 2, 1],
        [0, 0, 0, 1, 2],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 1, 2, 1, 0],
        [0, 1, 2, 1, 0],
    ],
    [
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0],
        [1, 2, 1, 0, 0],
        [2, 1, 0, 0, 0],
    ],
];

/// Initial slope `du/dv` of each template.
const TEMPLATE_SLOPE: [f64; 4] = [0.0, 1.0, 0.0, -1.0];

/// Order in which tied templates are preferred.
const TEMPLATE_PREFERENCE: [usize; 4] = [2, 1, 3, 0];

/// Template scores of one row of the 5 × 5 neighbourhood, by the bits of
/// its columns (bit `i` for column `i - 2`): byte `t` is the score of
/// template `t` (at most 8, so the bytes of five rows never carry).
const ROW_SCORES: [[u32; 32]; 5] = row_scores();

const fn row_scores() -> [[u32; 32]; 5] {
    let mut table = [[0u32; 32]; 5];
    let mut j = 0;
    while j < 5 {
        let mut bits = 0;
        while bits < 32 {
            let mut t = 0;
            while t < 4 {
                let mut i = 0;
                while i < 5 {
                    if bits >> i & 1 != 0 {
                        table[j][bits] += (TEMPLATES[t][j][i] as u32) << (8 * t);
                    }
                    i += 1;
                }
                t += 1;
            }
            bits += 1;
        }
        j += 1;
    }
    table
}

/// One edge point in scan coordinates, with `u` rounded once for the
/// templates (`round(u) as i64`; the scan line, `round(v)`, is where the
/// point is filed).
#[derive(Clone, Copy, Debug, Default)]
struct ScanPoint {
    u: f32,
    v: f32,
    response: f32,
    iu: i64,
}

/// `x.round() as i64` for finite `x`, without the libm call `roundf` is on
/// baseline x86-64 (it was a fifth of the extractor's time): `|x| + 0.5` is
/// exact in `f64`, and truncating it rounds half away from zero.
#[inline]
fn round_i64(x: f32) -> i64 {
    let a = x.abs();
    if a >= 8_388_608.0 {
        // 2²³ and up: already whole (or saturating, like `as`).
        return x as i64;
    }
    let r = (a as f64 + 0.5) as i64;
    if x < 0.0 { -r } else { r }
}

/// [`round_i64`] of a finite `u`, shorter for the usual `u > -½`: there
/// `u + ½` is exact in `f64` and positive, and truncating it rounds.
#[inline]
fn round_u(u: f32) -> i64 {
    let t = u as f64 + 0.5;
    if t > 0.0 && t < 4e9 {
        // (`as u32`: the shorter saturating conversion on x86-64.)
        t as u32 as i64
    } else {
        round_i64(u)
    }
}

/// The whole number nearest `x` (ties to even), `|x| < 2⁵¹`: adding
/// 1.5 · 2⁵² leaves it in the low bits, without a saturating conversion.
#[inline]
fn round_f64(x: f64) -> i64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    (x + MAGIC).to_bits() as i64 - MAGIC.to_bits() as i64
}

/// The scan line of a point at scan coordinates `(u, v)`: `round(v)`, if
/// both are finite and it is in `0..10⁷`. As in [`round_u`], `v + ½` is
/// exact; it is in `(0, 10⁷)` exactly when `round(v)` is in range.
#[inline]
fn row_of(u: f32, v: f32) -> Option<usize> {
    let t = v as f64 + 0.5;
    (u.is_finite() && t > 0.0 && t < 1e7).then_some(t as u32 as usize)
}

/// What the successor test needs of scan line `row + i` ahead of a start
/// (`i = 1..=max_gap`), the same for every start: the reach `i + sw`, and
/// in the start's [`Grid::around`] window, the columns `iu ± (⌊reach⌋ + 2)`
/// that can hold a point within it and those of them that lie within it
/// wherever in its pixel the start is.
#[derive(Clone, Copy, Debug, Default)]
struct Reach {
    reach: f64,
    /// Columns `iu + d`, `|d| ≤ ⌊reach⌋ + 2`, as bits `32 + d`.
    near: u64,
    /// The columns of `near` with `|d| + 1 ≤ reach`: the pixel is within
    /// `u ± reach` for any `u` within ½ of `iu` (exactly, so by monotone
    /// rounding also in `f64`).
    inner: u64,
}

impl Reach {
    fn new(i: u32, sw: f64) -> Self {
        let reach = i as f64 + sw;
        let half = reach as i64 + 2;
        let (mut near, mut inner) = (0, 0);
        for d in -half..=half {
            near |= 1u64 << (32 + d);
            if (d.abs() + 1) as f64 <= reach {
                inner |= 1u64 << (32 + d);
            }
        }
        Reach { reach, near, inner }
    }
}

/// Reusable buffers of the extractor.
#[derive(Clone, Debug, Default)]
pub struct LineScratch {
    points: Vec<ScanPoint>,
    /// `row_start[r]..row_start[r + 1]` are the points of scan line `r`.
    row_start: Vec<u32>,
    used: Vec<bool>,
    /// Input not in scan order: each filed point in input order, with its
    /// scan line.
    staged: Vec<(ScanPoint, u32)>,
    reach: Vec<Reach>,
    grid: Grid,
    /// Tests: never use the [`Grid`] (to compare both ways).
    #[cfg(test)]
    walk_only: bool,
}

/// Segments of one edge-point set (llv.md §3).
pub fn extract(e: &EdgePoints, p: &LineParams) -> Vec<Segment> {
    let mut out = Vec::new();
    extract_into(e, p, &mut out, &mut LineScratch::default());
    out
}

/// The [`Grid`] bitmap of every point.
const OCCUPIED: usize = 0;

/// The [`Grid`] bitmap of the unused points with the polarity of `response`.
#[inline]
fn unused(response: f32) -> usize {
    1 + polarity(response)
}

/// The most words a [`Grid`] bitmap may take: 2²², 28 bytes each with the
/// three bitmaps and the index (117 MB). Edge points of the largest image
/// the stages take (8192², about 16 points a scan line) need a quarter of
/// it; beyond it the extractor walks.
const MAX_GRID_WORDS: usize = 1 << 22;

/// Bitmaps of the points by scan line and rounded `u` (one bit a pixel
/// column): every point, and the points not yet used. The template scores
/// and the successor test then read a few bits instead of walking the
/// scan lines. Only built when it is exact: every rounded `u` in
/// `0..2²⁰` and no two points of a scan line on one column (true of edge
/// points, which are one pixel thick; a file may say otherwise, and the
/// extractor then walks the scan lines).
#[derive(Clone, Debug, Default)]
struct Grid {
    /// Words a scan line: its columns (column `c` is bit `c + 64`) and an
    /// empty word on either side, so no window needs a special case at
    /// the image's sides.
    words: usize,
    /// Per word, three bitmaps: every point ([`OCCUPIED`]), and the unused
    /// points by polarity ([`unused`]; a track only takes points of its
    /// start's polarity, so only those can continue it). Side by side,
    /// so that filing a point or reading a window checks one index.
    cells: Vec<[u64; 3]>,
    /// Per word of the occupied bitmap that has a bit set: the index of its
    /// first point, so a column's point is found without a search (other
    /// words: anything).
    first: Vec<u32>,
    /// The columns a track searches for its next point, `±(⌊sw⌋ + 2)`
    /// around the one nearest the prediction, as [`Grid::around`] bits:
    /// every point within `sw` of the prediction is on one of them.
    search: u64,
}

impl Grid {
    /// Builds the bitmaps of `points`, filed by scan line and in order
    /// along each, whose rounded `u` are all in `0..=max_iu`, `max_iu <
    /// 2²⁰`; false (and no grid) when two points of a scan line share a
    /// column, or when the bitmaps would be large for their points (more
    /// than 2¹⁶ words each and 16 a point, or more than [`MAX_GRID_WORDS`]).
    #[inline(never)]
    fn build(
        &mut self,
        points: &[ScanPoint],
        row_start: &[u32],
        nrows: usize,
        max_iu: i64,
    ) -> bool {
        // The columns, and an empty word on either side.
        self.words = max_iu as usize / 64 + 3;
        let len = nrows.saturating_mul(self.words);
        if len > (16 * points.len()).clamp(1 << 16, MAX_GRID_WORDS) {
            // Far larger than its points (a sparse hand-made file, say a
            // stray point ten million scan lines down): walking is cheaper
            // than clearing the bitmaps, and they might not fit in memory.
            self.words = 0;
            return false;
        }
        self.cells.clear();
        self.cells.resize(len, [0; 3]);
        if self.first.len() < len {
            self.first.resize(len, 0);
        }
        for (r, ends) in row_start.windows(2).enumerate().take(nrows) {
            let base = r * self.words;
            for (k, q) in (ends[0]..ends[1]).zip(&points[ends[0] as usize..ends[1] as usize]) {
                let c = q.iu as usize + 64;
                let (w, bit) = (base + c / 64, 1u64 << (c % 64));
                let cell = &mut self.cells[w];
                let occupied = cell[OCCUPIED];
                if occupied & bit != 0 {
                    self.words = 0;
                    return false;
                }
                cell[OCCUPIED] = occupied | bit;
                cell[unused(q.response)] |= bit;
                if occupied == 0 {
                    self.first[w] = k;
                }
            }
        }
        true
    }

    /// The index of the point on scan line `r` at column `c` (a set bit).
    #[inline]
    fn point_at(&self, r: usize, c: i64) -> usize {
        let c = (c + 64) as usize;
        let k = r * self.words + c / 64;
        let below = self.cells[k][OCCUPIED] & ((1u64 << (c % 64)) - 1);
        self.first[k] as usize + below.count_ones() as usize
    }

    #[inline]
    fn mark_used(&mut self, r: usize, q: &ScanPoint) {
        let c = q.iu as usize + 64;
        self.cells[r * self.words + c / 64][unused(q.response)] &= !(1u64 << (c % 64));
    }

    /// The template of §3.1 for a point at column `iu` of scan line `row`:
    /// each row's five bits look up all four scores at once.
    fn template(&self, row: usize, iu: i64, nrows: usize) -> usize {
        let mut packed = 0;
        for (j, scores) in ROW_SCORES.iter().enumerate() {
            let r = (row + j).wrapping_sub(2);
            if r < nrows {
                packed += scores[(self.around(OCCUPIED, r, iu) >> 30 & 31) as usize];
            }
        }
        best_template(&packed.to_le_bytes().map(u32::from))
    }

    /// The 64 bits of scan line `r` around column `centre`: bit `k` for
    /// column `centre - 32 + k`. `centre` must be a point's column (or in
    /// `-32..=max_centre`).
    #[inline]
    fn around(&self, plane: usize, r: usize, centre: i64) -> u64 {
        let start = (centre + 32) as usize;
        let (w, b) = (r * self.words + start / 64, start % 64);
        let pair = &self.cells[w..w + 2];
        (pair[0][plane] >> b) | ((pair[1][plane] << 1) << (63 - b))
    }

    /// [`Grid::around`] any column: no bits far off the grid's columns.
    #[inline]
    fn around_any(&self, plane: usize, r: usize, centre: i64) -> u64 {
        let max_centre = (self.words as i64 - 1) * 64 - 33;
        if (-32..=max_centre).contains(&centre) {
            self.around(plane, r, centre)
        } else {
            0
        }
    }

    /// [`has_successor`] from the bitmaps, sharper: an unused point of the
    /// start's polarity (the only kind a track takes) with `u` in
    /// `[u − reach, u + reach]` on scan line `row + i`, `reach = i + sw`.
    /// A point's `u` is within ½ px of its column, so the columns
    /// `iu ± (⌊reach⌋ + 2)` hold every candidate: when their bits are clear
    /// (most start points on noise) the answer is no, in integer work alone.
    /// A column whose whole pixel lies inside the reach decides by its bit
    /// (the `inner` ones of [`Reach`], whatever the start's `u`); the ones
    /// at the ends by the point itself.
    fn has_successor(
        &self,
        points: &[ScanPoint],
        reach: &[Reach],
        sp: &ScanPoint,
        row: usize,
        nrows: usize,
    ) -> bool {
        let unused = unused(sp.response);
        let (mut near, mut inner) = (0, 0);
        for (r, rc) in (row + 1..nrows).zip(reach) {
            let bits = self.around(unused, r, sp.iu);
            near |= bits & rc.near;
            inner |= bits & rc.inner;
        }
        if near == 0 {
            return false;
        }
        if inner != 0 {
            return true;
        }
        for (r, rc) in (row + 1..nrows).zip(reach) {
            let mut bits = self.around(unused, r, sp.iu) & rc.near;
            let (a, b) = (sp.u as f64 - rc.reach, sp.u as f64 + rc.reach);
            while bits != 0 {
                let c = sp.iu - 32 + bits.trailing_zeros() as i64;
                bits &= bits - 1;
                let (left, right) = (c as f64 - 0.5, c as f64 + 0.5);
                if right < a || left > b {
                    continue;
                }
                if left >= a && right <= b {
                    return true;
                }
                // An end column: look at the point.
                let u = points[self.point_at(r, c)].u as f64;
                if u >= a && u <= b {
                    return true;
                }
            }
        }
        false
    }
}

/// Of the candidate points `near` (unused, in order along the scan line),
/// the one nearest the prediction `pred` within `±sw` that has the start's
/// polarity (ties: the first, the smaller `u`). A straight edge keeps its
/// polarity along its length; chains of noise points alternate.
fn nearest(
    points: &[ScanPoint],
    near: impl Iterator<Item = usize>,
    pred: f64,
    sw: f64,
    start_response: f32,
) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for idx in near {
        let q = &points[idx];
        let d = q.u as f64 - pred;
        if (q.u as f64) < pred - sw || d > sw {
            continue;
        }
        if polarity(q.response) != polarity(start_response) {
            continue;
        }
        if best.is_none_or(|(bd, _)| d.abs() < bd) {
            best = Some((d.abs(), idx));
        }
    }
    best.map(|(_, idx)| idx)
}

/// Which of a track's two polarities a point has: 1 for a positive
/// response (dark → light), 0 otherwise (as the extractor compares them).
#[inline]
fn polarity(response: f32) -> usize {
    usize::from(response > 0.0)
}

/// The template with the largest score, ties in [`TEMPLATE_PREFERENCE`].
fn best_template(score: &[u32; 4]) -> usize {
    let mut best = TEMPLATE_PREFERENCE[0];
    for &t in &TEMPLATE_PREFERENCE[1..] {
        if score[t] > score[best] {
            best = t;
        }
    }
    best
}

/// The points of scan line `r` from the first with `u ≥ t` to the line's
/// end (indices into `s.points`); empty outside `0..nrows`.
fn from_u(s: &LineScratch, r: i64, nrows: usize, t: f64) -> std::ops::Range<usize> {
    if r < 0 || r as usize >= nrows {
        return 0..0;
    }
    let (lo, hi) = (
        s.row_start[r as usize] as usize,
        s.row_start[r as usize + 1] as usize,
    );
    lo + s.points[lo..hi].partition_point(|q| (q.u as f64) < t)..hi
}

/// [`nearest`] unused point to `pred` on scan line `r`, by a binary search
/// (what the `Grid` answers when it is exact). Out of line: it keeps the
/// grid's loop small.
#[inline(never)]
fn walk_nearest(
    s: &LineScratch,
    r: usize,
    nrows: usize,
    pred: f64,
    sw: f64,
    start_response: f32,
) -> Option<usize> {
    let near = from_u(s, r as i64, nrows, pred - sw)
        .take_while(|&k| s.points[k].u as f64 - pred <= sw)
        .filter(|&k| !s.used[k]);
    nearest(&s.points, near, pred, sw, start_response)
}

/// Which template fits the neighbourhood of point `sp` on scan line `row`
/// best (§3.1), by walking the scan lines (what the `Grid` answers when
/// it is exact).
#[inline(never)]
fn template_of(s: &LineScratch, sp: &ScanPoint, row: usize, nrows: usize) -> usize {
    let iu = sp.iu;
    let mut score = [0u32; 4];
    for (j, r) in (row as i64 - 2..=row as i64 + 2).enumerate() {
        // Every point below `iu - 3` rounds below `iu - 2`; rounded `u` is
        // sorted along the scan line like `u` itself.
        for q in &s.points[from_u(s, r, nrows, iu.saturating_sub(3) as f64)] {
            let i = q.iu.saturating_sub(iu);
            if i < -2 {
                continue;
            }
            if i > 2 {
                break;
            }
            for (t, sc) in score.iter_mut().enumerate() {
                *sc += u32::from(TEMPLATES[t][j][(i + 2) as usize]);
            }
        }
    }
    best_template(&score)
}

/// Whether an unused point lies where any initial prediction (slope -1, 0
/// or 1) could find it on the next `max_gap` scan lines, by walking them.
#[inline(never)]
fn has_successor(
    s: &LineScratch,
    sp: &ScanPoint,
    row: usize,
    nrows: usize,
    p: &LineParams,
) -> bool {
    (1..=p.max_gap as usize).any(|i| {
        let reach = i as f64 + p.search_width;
        from_u(s, (row + i) as i64, nrows, sp.u as f64 - reach)
            .take_while(|&k| s.points[k].u as f64 <= sp.u as f64 + reach)
            .any(|k| !s.used[k])
    })
}

impl LineScratch {
    /// Files the points of `e` by scan line, in order along each (points
    /// that are not finite, or whose scan line is not in `0..10⁷`, are
    /// left out), and returns the number of scan lines. Input already in
    /// the scan frame's lexical order (EdgeH, or a file) is taken as it
    /// comes, in one pass; otherwise a counting sort by scan line keeps the
    /// order along the scan of the input (and sorts EdgeV column by
    /// column), and a scan line out of order along the scan is sorted.
    #[inline(never)]
    fn file(&mut self, e: &EdgePoints, vertical: bool) -> usize {
        let scan = |q: &EdgePoint| {
            let (u, v) = if vertical { (q.y, q.x) } else { (q.x, q.y) };
            let point = ScanPoint {
                u,
                v,
                response: q.response,
                iu: round_u(u),
            };
            (point, row_of(u, v))
        };
        // Local vectors: their lengths stay in registers.
        let mut points = std::mem::take(&mut self.points);
        let mut row_start = std::mem::take(&mut self.row_start);
        points.clear();
        row_start.clear();
        let (mut last_row, mut last_u) = (0, f32::NEG_INFINITY);
        let mut in_order = true;
        for q in &e.points {
            let (point, Some(r)) = scan(q) else {
                continue;
            };
            if r < last_row || (r == last_row && point.u < last_u) {
                in_order = false;
                break;
            }
            (last_row, last_u) = (r, point.u);
            if r >= row_start.len() {
                row_start.resize(r + 1, points.len() as u32);
            }
            points.push(point);
        }
        let nrows = if in_order {
            let nrows = row_start.len();
            row_start.push(points.len() as u32);
            nrows
        } else {
            let mut staged = std::mem::take(&mut self.staged);
            let nrows = counting_sort(e, &scan, &mut points, &mut row_start, &mut staged);
            self.staged = staged;
            nrows
        };
        self.points = points;
        self.row_start = row_start;
        nrows
    }
}

/// [`LineScratch::file`] of input out of scan order: a counting sort by
/// scan line (each point converted once, into `staged` with its scan
/// line; points without one are left out), then a sort of any scan line
/// out of order along the scan.
#[inline(never)]
fn counting_sort(
    e: &EdgePoints,
    scan: &impl Fn(&EdgePoint) -> (ScanPoint, Option<usize>),
    points: &mut Vec<ScanPoint>,
    row_start: &mut Vec<u32>,
    staged: &mut Vec<(ScanPoint, u32)>,
) -> usize {
    // `row_start[r + 2]` counts scan line `r` first.
    row_start.clear();
    staged.clear();
    for q in &e.points {
        if let (point, Some(r)) = scan(q) {
            if r + 2 >= row_start.len() {
                row_start.resize(r + 3, 0);
            }
            row_start[r + 2] += 1;
            staged.push((point, r as u32));
        }
    }
    let nrows = row_start.len().saturating_sub(2);
    row_start.resize(nrows + 2, 0);
    for r in 2..nrows + 2 {
        row_start[r] += row_start[r - 1];
    }
    points.clear();
    points.resize(staged.len(), ScanPoint::default());
    for &(point, r) in staged.iter() {
        let slot = &mut row_start[r as usize + 1];
        points[*slot as usize] = point;
        *slot += 1;
    }
    row_start.truncate(nrows + 1);
    // Within a scan line, order by u (the input may come from a file).
    for r in 0..nrows {
        let (lo, hi) = (row_start[r] as usize, row_start[r + 1] as usize);
        let row = &mut points[lo..hi];
        if !row.windows(2).all(|w| w[0].u <= w[1].u) {
            row.sort_unstable_by(|a, b| a.u.total_cmp(&b.u));
        }
    }
    nrows
}

/// Follows a line from start point `sp` on scan line `start_row` with the
/// initial slope of `template`, marking the points it takes used; returns
/// their fit, the sum of their responses and the last point.
#[allow(clippy::too_many_arguments)]
#[inline]
fn track<const GRID: bool>(
    s: &mut LineScratch,
    grid: &mut Grid,
    p: &LineParams,
    sp: &ScanPoint,
    start_row: usize,
    nrows: usize,
    template: usize,
) -> (LineFit, f64, ScanPoint) {
    let sw = p.search_width;
    let mut slope = TEMPLATE_SLOPE[template];
    let mut fit = LineFit::new();
    // (Every filed point is finite.)
    fit.add_finite(Point::new(sp.u as f64, sp.v as f64));
    // The mean, kept from one added point to the next (the prediction
    // and the stray test of every scan line tried use it).
    let mut mean = fit.mean();
    let mut resp_sum = sp.response as f64;
    let mut last = *sp;
    let mut row_e = start_row;
    let mut axis: Option<(f64, f64)> = None;
    loop {
        let mut found = None;
        // (Not `1..=max_gap`: an inclusive range costs more per step.)
        for i in 1..p.max_gap as usize + 1 {
            let r = row_e + i;
            if r >= nrows {
                break;
            }
            // Once two points are in, predict from the fitted line itself,
            // not from the last point: a track predicted from its last
            // point follows any chain that bends by less than the search
            // width per scan line, round a corner and along the next edge.
            let pred = match mean {
                Some(m) if fit.len() >= 2 => m.x + (r as f64 - m.y) * slope,
                _ => last.u as f64 + i as f64 * slope,
            };
            // No unused point near the prediction at all (how a noise
            // track usually ends): the bitmap says so without a search.
            // Every candidate's column is within sw + ½ of `pred`.
            // Otherwise the unused points near it are the window's bits,
            // in order along the scan line.
            let next = if GRID && pred.abs() < 1e9 {
                // The columns within ⌊sw⌋ + 2 of the one nearest `pred`.
                let centre = round_f64(pred);
                let mut bits = grid.around_any(unused(sp.response), r, centre) & grid.search;
                let near = std::iter::from_fn(|| {
                    (bits != 0).then(|| {
                        let c = centre - 32 + bits.trailing_zeros() as i64;
                        bits &= bits - 1;
                        grid.point_at(r, c)
                    })
                });
                nearest(&s.points, near, pred, sw, sp.response)
            } else {
                walk_nearest(s, r, nrows, pred, sw, sp.response)
            };
            if let Some(idx) = next {
                found = Some((idx, r));
                break;
            }
        }
        let Some((idx, r)) = found else { break };
        // A track that is well established stops where the next point
        // leaves its line: at a shallow corner (two edges at up to ~35°
        // meet within the search window) or where a shadow edge branches.
        // The distance from the line through the mean along the major
        // axis found after the last point (the fit has not changed
        // since): no trigonometry per point.
        if fit.len() >= STRAY_AFTER {
            if let (Some((du, dv)), Some(m)) = (axis, mean) {
                let q = s.points[idx];
                let cross = (q.u as f64 - m.x) * dv - (q.v as f64 - m.y) * du;
                if cross.abs() > STRAY_DISTANCE * (du * du + dv * dv).sqrt() {
                    break;
                }
            }
        }
        s.used[idx] = true;
        if GRID {
            grid.mark_used(r, &s.points[idx]);
        }
        let q = s.points[idx];
        fit.add_finite(Point::new(q.u as f64, q.v as f64));
        mean = fit.mean();
        resp_sum += q.response as f64;
        last = q;
        row_e = r;
        axis = fit.major_axis();
        if let Some((du, dv)) = axis {
            slope = if dv.abs() * MAX_SLOPE > du.abs() {
                du / dv
            } else {
                MAX_SLOPE * du.signum() * dv.signum()
            };
        }
    }
    (fit, resp_sum, last)
}

/// Follows the lines from every start point in turn (the main loop of
/// [`extract_into`]), with the [`Grid`] or by walking the scan lines: one
/// copy of the loop each, without the other's branches.
#[inline(never)]
fn follow<const GRID: bool>(
    s: &mut LineScratch,
    grid: &mut Grid,
    p: &LineParams,
    nrows: usize,
    vertical: bool,
    out: &mut Vec<Segment>,
) {
    let min_angle = p.min_scan_angle_deg.to_radians();
    for start_row in 0..nrows {
        for start in s.row_start[start_row] as usize..s.row_start[start_row + 1] as usize {
            if s.used[start] {
                continue;
            }
            s.used[start] = true;
            let sp = s.points[start];
            let template = if GRID {
                grid.mark_used(start_row, &sp);
                if !grid.has_successor(&s.points, &s.reach, &sp, start_row, nrows) {
                    continue;
                }
                grid.template(start_row, sp.iu, nrows)
            } else {
                if !has_successor(s, &sp, start_row, nrows, p) {
                    // No unused point within reach of any template's prediction:
                    // no line can start here (the same result, without the
                    // templates).
                    continue;
                }
                template_of(s, &sp, start_row, nrows)
            };
            let (fit, resp_sum, last) = track::<GRID>(s, grid, p, &sp, start_row, nrows, template);
            let response = resp_sum / fit.len() as f64;
            if response.abs() < p.min_response {
                continue;
            }
            // Projection onto a line never lengthens a segment: a track whose
            // ends are no further apart than `min_length` (less a hair for
            // rounding) is dropped before its line is computed.
            let (du, dv) = (last.u as f64 - sp.u as f64, last.v as f64 - sp.v as f64);
            if p.min_length > 0.0 && du * du + dv * dv < p.min_length * p.min_length * (1.0 - 1e-9)
            {
                continue;
            }
            let Some(line) = fit.line() else { continue };
            let a = line.project(Point::new(sp.u as f64, sp.v as f64));
            let b = line.project(Point::new(last.u as f64, last.v as f64));
            if a.dist(b) <= p.min_length {
                continue;
            }
            // Angle between the line and the scan direction (u axis).
            let scan_angle = line.a.abs().atan2(line.b.abs());
            if scan_angle <= min_angle {
                continue;
            }
            let swap = |q: Point| if vertical { Point::new(q.y, q.x) } else { q };
            out.push(Segment {
                a: swap(a),
                b: swap(b),
                response,
                residual: fit.rms_residual(),
                shadow: false,
            });
        }
    }
}

/// [`extract`] into reusable buffers; appends nothing else to `out` (it is
/// cleared first).
pub fn extract_into(e: &EdgePoints, p: &LineParams, out: &mut Vec<Segment>, s: &mut LineScratch) {
    out.clear();
    let vertical = e.dir == Some(ScanDir::Vertical);
    let nrows = s.file(e, vertical);
    let total = s.points.len();
    s.used.clear();
    s.used.resize(total, false);
    let mut grid = std::mem::take(&mut s.grid);
    let sw = p.search_width;
    let window_fits = sw.is_finite() && sw >= 0.0 && p.max_gap as f64 + sw <= 28.0;
    #[cfg(test)]
    let window_fits = window_fits && !s.walk_only;
    // Every rounded `u` in `0..2²⁰` (so in the grid's columns); the largest.
    let columns = s.points.iter().try_fold(0, |max, q| {
        (0..1 << 20).contains(&q.iu).then(|| max.max(q.iu))
    });
    // (No grid until one is built: a refused one leaves none.)
    grid.words = 0;
    let use_grid = window_fits
        && columns.is_some_and(|max_iu| grid.build(&s.points, &s.row_start, nrows, max_iu));
    s.reach.clear();
    if use_grid {
        s.reach.extend((1..=p.max_gap).map(|i| Reach::new(i, sw)));
        grid.search = Reach::new(0, sw).near;
        follow::<true>(s, &mut grid, p, nrows, vertical, out);
    } else {
        follow::<false>(s, &mut grid, p, nrows, vertical, out);
    }
    s.grid = grid;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::EdgePoint;

    fn points(dir: ScanDir, pts: &[(f32, f32)]) -> EdgePoints {
        let mut v: Vec<EdgePoint> = pts
            .iter()
            .map(|&(x, y)| EdgePoint {
                x,
                y,
                response: 10.0,
            })
            .collect();
        v.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
        EdgePoints {
            dir: Some(dir),
            width: 200,
            height: 200,
            points: v,
        }
    }

    #[test]
    fn templates_give_the_initial_direction_in_eight_directions() {
        // Lines through the start s = (50, 50) continue below it (scan frame),
        // so 8 image directions fold into the 4 templates per scan direction.
        let cases: [(f64, f64, usize); 4] =
            [(1.0, 0.0, 0), (1.0, 1.0, 1), (0.0, 1.0, 2), (-1.0, 1.0, 3)];
        for &(du, dv, want) in &cases {
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let mut pts = Vec::new();
                for k in 0..3 {
                    let (u, v) = (50.0 + k as f64 * du, 50.0 + k as f64 * dv);
                    let (x, y) = if dir == ScanDir::Vertical {
                        (v, u)
                    } else {
                        (u, v)
                    };
                    pts.push((x as f32, y as f32));
                }
                let e = points(dir, &pts);
                let mut s = LineScratch::default();
                extract_into(&e, &LineParams::default(), &mut Vec::new(), &mut s);
                let sp = *s
                    .points
                    .iter()
                    .find(|q| q.u == 50.0 && q.v == 50.0)
                    .unwrap();
                let nrows = s.row_start.len() - 1;
                assert_eq!(template_of(&s, &sp, 50, nrows), want, "{dir:?} ({du},{dv})");
                let mut grid = Grid::default();
                assert!(grid.build(&s.points, &s.row_start, nrows, 200));
                assert_eq!(grid.template(50, sp.iu, nrows), want, "grid {dir:?}");
            }
        }
    }

    #[test]
    fn a_drawn_line_is_extracted_in_every_steep_direction() {
        // Ideal points of lines at many angles, one per scan line.
        for deg in (-85..=85).step_by(5) {
            let ang = (deg as f64).to_radians();
            // Angle from the vertical for EdgeH: x = x0 + tan(ang) * y.
            if ang.abs() > 1.1 {
                continue;
            }
            let slope = ang.tan();
            let pts: Vec<(f32, f32)> = (20..120)
                .map(|y| ((100.0 + slope * (y as f64 - 20.0) + 0.3) as f32, y as f32))
                .collect();
            let e = points(ScanDir::Horizontal, &pts);
            let segs = extract(&e, &LineParams::default());
            assert_eq!(segs.len(), 1, "{deg}°: {segs:?}");
            let s = segs[0];
            assert!((s.a.y - 20.0).abs() < 1e-3 && (s.b.y - 119.0).abs() < 1e-3);
            assert!(s.residual < 1e-3);
            assert!((s.response - 10.0).abs() < 1e-9);
            // The same line scanned vertically, with x and y swapped.
            let pts: Vec<(f32, f32)> = pts.iter().map(|&(x, y)| (y, x)).collect();
            let e = points(ScanDir::Vertical, &pts);
            let segs = extract(&e, &LineParams::default());
            assert_eq!(segs.len(), 1, "V {deg}°");
            assert!((segs[0].a.x - 20.0).abs() < 1e-3);
        }
    }

    #[test]
    fn gaps_short_lines_and_scan_parallel_lines() {
        // max_gap = 3: the next point may be up to 3 rows below (2 empty
        // rows bridged), not 4.
        let mut pts: Vec<(f32, f32)> = (0..20).map(|y| (50.0, y as f32)).collect();
        pts.extend((22..40).map(|y| (50.0, y as f32)));
        pts.extend((43..60).map(|y| (50.0, y as f32)));
        let segs = extract(&points(ScanDir::Horizontal, &pts), &LineParams::default());
        assert_eq!(segs.len(), 2, "{segs:?}");
        // Too short: 8 px is not > min_length.
        let pts: Vec<(f32, f32)> = (0..9).map(|y| (50.0, y as f32)).collect();
        assert!(extract(&points(ScanDir::Horizontal, &pts), &LineParams::default()).is_empty());
        // 20° from the scan direction: one point every ~2.7 px along x.
        let pts: Vec<(f32, f32)> = (0..30).map(|y| (10.0 + y as f32 * 2.7, y as f32)).collect();
        let p = LineParams {
            search_width: 3.0,
            ..LineParams::default()
        };
        assert!(extract(&points(ScanDir::Horizontal, &pts), &p).is_empty());
        assert!(extract(&EdgePoints::default(), &p).is_empty());
    }

    /// A successor exactly at the edge of the reach of the first prediction
    /// (slope 2, search width 1: the next point is 2 px along, on the last
    /// column the test may look at) still starts the line.
    #[test]
    fn a_successor_at_the_edge_of_the_reach_starts_a_line() {
        let pts: Vec<(f32, f32)> = (0..30)
            .map(|y| (10.25 + 2.0 * y as f32, y as f32))
            .collect();
        let p = LineParams {
            search_width: 1.0,
            ..LineParams::default()
        };
        let e = points(ScanDir::Horizontal, &pts);
        let segs = extract(&e, &p);
        assert_eq!(segs.len(), 1, "{segs:?}");
        let mut s = LineScratch {
            walk_only: true,
            ..LineScratch::default()
        };
        let mut walk = Vec::new();
        extract_into(&e, &p, &mut walk, &mut s);
        assert_eq!(segs, walk);
    }

    /// A file may hold a stray point far from the others (here ten million
    /// scan lines down and a million columns along): the extractor walks
    /// the scan lines instead of clearing bitmaps for the whole span (which
    /// would not fit in memory), and finds the same line.
    #[test]
    fn a_stray_point_far_away_does_not_size_the_bitmaps() {
        let mut pts: Vec<(f32, f32)> = (0..30).map(|y| (40.0 + 0.5 * y as f32, y as f32)).collect();
        let near = extract(&points(ScanDir::Horizontal, &pts), &LineParams::default());
        assert_eq!(near.len(), 1);
        pts.push((1_000_000.0, 9_999_990.0));
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let pts: Vec<(f32, f32)> = if dir == ScanDir::Vertical {
                pts.iter().map(|&(x, y)| (y, x)).collect()
            } else {
                pts.clone()
            };
            let mut s = LineScratch::default();
            let mut segs = Vec::new();
            extract_into(
                &points(dir, &pts),
                &LineParams::default(),
                &mut segs,
                &mut s,
            );
            assert_eq!(s.grid.words, 0, "{dir:?}: no grid");
            assert!(
                s.grid.cells.len() < 1 << 20,
                "{dir:?}: {} cells",
                s.grid.cells.len()
            );
            assert_eq!(segs.len(), 1, "{dir:?}");
            let swap = |q: Point| {
                if dir == ScanDir::Vertical {
                    Point::new(q.y, q.x)
                } else {
                    q
                }
            };
            assert_eq!(
                (swap(segs[0].a), swap(segs[0].b)),
                (near[0].a, near[0].b),
                "{dir:?}"
            );
        }
    }

    /// The segments' bits, to compare NaN responses too.
    fn bits(segs: &[Segment]) -> Vec<[u64; 6]> {
        segs.iter()
            .map(|s| {
                assert!(!s.shadow);
                [s.a.x, s.a.y, s.b.x, s.b.y, s.response, s.residual].map(f64::to_bits)
            })
            .collect()
    }

    /// The extractor gives the segments of the one before the speed work
    /// (`reference.rs`), bit for bit and in the same order, on edge-point-like
    /// sets (noise and lines) and on what a file may hold: points sharing a
    /// column, negative or huge `u`, unsorted input, points and responses
    /// that are not finite, odd parameters.
    #[test]
    fn the_same_segments_as_the_reference_extractor_bit_for_bit() {
        let mut rng = crate::llv::synth::rng::SplitMix64::new(0x5eed_11e5);
        let mut s = LineScratch::default();
        let (mut out, mut segments, mut gridded) = (Vec::new(), 0, 0);
        for case in 0..400 {
            let (w, h) = (20 + rng.below(300), 20 + rng.below(200));
            let mut pts: Vec<EdgePoint> = Vec::new();
            let noise = 1 + rng.below(12);
            for y in 0..h {
                for _ in 0..rng.below(noise) {
                    pts.push(EdgePoint {
                        x: (rng.uniform() * w as f64) as f32,
                        y: y as f32,
                        response: rng.range(-20.0, 20.0) as f32,
                    });
                }
            }
            for _ in 0..rng.below(8) {
                let (x0, slope) = (rng.uniform() * w as f64, rng.range(-3.0, 3.0));
                let (y0, y1) = (rng.below(h), rng.below(h));
                let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                let jitter = [0.0, 0.3, 1.0][rng.below(3)];
                for y in y0.min(y1)..y0.max(y1) {
                    if rng.uniform() < 0.1 {
                        continue;
                    }
                    let x = x0 + slope * (y as f64 - y0 as f64) + rng.range(-jitter, jitter);
                    pts.push(EdgePoint {
                        x: x as f32,
                        y: y as f32,
                        response: (sign * rng.range(3.0, 50.0)) as f32,
                    });
                }
            }
            pts.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
            let kind = case % 8;
            if kind < 4 {
                // Edge points: one a pixel.
                pts.dedup_by_key(|q| (q.y, q.x.round()));
            }
            if kind == 1 && !pts.is_empty() {
                // Something odd in a file.
                for _ in 0..1 + rng.below(3) {
                    let k = rng.below(pts.len());
                    let odd = [
                        f32::NAN,
                        f32::INFINITY,
                        -f32::INFINITY,
                        -3.2,
                        -0.5,
                        -0.49,
                        0.5,
                        1.5e6,
                        3e9,
                        1e7,
                        9_999_999.5,
                        -2e9,
                    ][rng.below(12)];
                    match rng.below(3) {
                        0 => pts[k].x = odd,
                        1 => pts[k].y = odd,
                        _ => pts[k].response = odd,
                    }
                }
            }
            if kind == 2 {
                // Scan order of EdgeV (column by column).
                pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
            }
            if kind == 3 || kind == 5 {
                // Unsorted.
                for k in (1..pts.len()).rev() {
                    pts.swap(k, rng.below(k + 1));
                }
            }
            if kind == 6 {
                // Subpixel rows, some shared columns and equal `u`.
                for q in &mut pts {
                    q.y += rng.range(-0.6, 0.6) as f32;
                    if rng.uniform() < 0.05 {
                        q.x = q.x.round();
                    }
                }
            }
            let p = LineParams {
                max_gap: [3, 3, 3, 1, 2, 5, 0, 30][rng.below(8)],
                search_width: [2.0, 2.0, 1.0, 3.5, 0.0, 2.7, 26.0, f64::NAN][rng.below(8)],
                min_length: [8.0, 8.0, 0.0, 3.0][rng.below(4)],
                min_scan_angle_deg: [22.5, 22.5, 0.0, 60.0][rng.below(4)],
                min_response: [6.0, 0.0, 0.0, 15.0][rng.below(4)],
            };
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let e = EdgePoints {
                    dir: Some(dir),
                    width: w,
                    height: h,
                    points: pts.clone(),
                };
                let want = reference::extract(&e, &p);
                extract_into(&e, &p, &mut out, &mut s);
                assert_eq!(bits(&out), bits(&want), "case {case} {dir:?} {p:?}");
                segments += out.len();
                gridded += usize::from(s.grid.words > 0);
            }
        }
        // About a third of the cases have a grid: those with one point a
        // pixel, a window that fits and no point off the grid.
        assert!(
            segments > 2000 && gridded > 250,
            "{segments} segments, {gridded} gridded"
        );
    }

    /// The bitmaps are a shortcut, not a change: on noise with lines
    /// through it, edge-point-like (one per column) or not, the extractor
    /// gives the same segments, bit for bit, with and without them.
    #[test]
    fn the_grid_gives_the_same_segments_as_walking_the_scan_lines() {
        let mut rng = crate::llv::synth::rng::SplitMix64::new(0x1234_5678_9abc_def0);
        let mut unit = move || rng.uniform();
        let mut gridded = 0;
        for case in 0..40 {
            let (w, h) = (40 + case * 7, 30 + case * 5);
            let mut pts: Vec<EdgePoint> = Vec::new();
            // Noise: a few points a row on distinct columns.
            for y in 0..h {
                let mut cols: Vec<usize> = (0..6).map(|_| (unit() * w as f64) as usize).collect();
                cols.sort_unstable();
                cols.dedup();
                for c in cols {
                    let d = (unit() - 0.5) as f32;
                    let r = (unit() * 20.0 - 10.0) as f32;
                    pts.push(EdgePoint {
                        x: c as f32 + d,
                        y: y as f32,
                        response: r,
                    });
                }
            }
            // Lines at random angles, with gaps.
            for _ in 0..4 {
                let (x0, slope) = (unit() * w as f64, unit() * 2.4 - 1.2);
                let sign = if unit() < 0.5 { -1.0 } else { 1.0 };
                for y in 0..h {
                    if unit() < 0.1 {
                        continue;
                    }
                    let x = x0 + slope * y as f64 + (unit() - 0.5) * 0.6;
                    if x > 0.0 && x < w as f64 - 1.0 {
                        pts.push(EdgePoint {
                            x: x as f32,
                            y: y as f32,
                            response: (sign * (20.0 + unit() * 30.0)) as f32,
                        });
                    }
                }
            }
            pts.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
            // One point per pixel, as edge points are (else the grid is not
            // used at all).
            pts.dedup_by_key(|q| (q.y, q.x.round()));
            if case % 5 == 4 {
                // A point shifted left of the image: the grid is not used.
                pts[0].x = -3.2;
            }
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let e = EdgePoints {
                    dir: Some(dir),
                    width: w,
                    height: h,
                    points: pts.clone(),
                };
                for sw in [1.0, 2.0, 3.5] {
                    let p = LineParams {
                        search_width: sw,
                        min_response: 0.0,
                        ..LineParams::default()
                    };
                    let (mut fast, mut walk) = (Vec::new(), Vec::new());
                    let mut fs = LineScratch::default();
                    extract_into(&e, &p, &mut fast, &mut fs);
                    gridded += usize::from(fs.grid.words > 0);
                    if sw == 2.0 && fs.grid.words > 0 {
                        // The two ways of scoring the templates agree at
                        // every point.
                        let nrows = fs.row_start.len() - 1;
                        for r in 0..nrows {
                            for k in fs.row_start[r] as usize..fs.row_start[r + 1] as usize {
                                let q = fs.points[k];
                                assert_eq!(
                                    fs.grid.template(r, q.iu, nrows),
                                    template_of(&fs, &q, r, nrows),
                                    "case {case} {dir:?} row {r} point {k}"
                                );
                            }
                        }
                    }
                    let mut s = LineScratch {
                        walk_only: true,
                        ..LineScratch::default()
                    };
                    extract_into(&e, &p, &mut walk, &mut s);
                    assert_eq!(fast, walk, "case {case} {dir:?} sw {sw}");
                    if case == 0 && sw == 2.0 {
                        assert!(!fast.is_empty(), "the lines are found");
                    }
                }
            }
        }
        // 40 cases × 2 directions × 3 widths; the grid is refused only when
        // scanning along rows in the 8 cases with a point left of the image
        // (scanning along columns, that point is on no scan line).
        assert_eq!(gridded, 40 * 6 - 8 * 3, "cases that used the grid");
    }
}
