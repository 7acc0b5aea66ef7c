//! The line extractor as it was before the speed work of `lines.rs`
//! (bucketing by counting sort, `Grid` of bitmaps with per-word counts,
//! a successor test with float arithmetic per scan line), kept as the
//! reference the fast extractor is tested against bit for bit. Test-only.

use super::super::fit::LineFit;
use super::super::params::LineParams;
use super::super::{EdgePoints, Point, ScanDir, Segment};

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

/// Reusable buffers of the extractor.
#[derive(Clone, Debug, Default)]
pub struct LineScratch {
    points: Vec<ScanPoint>,
    /// `row_start[r]..row_start[r + 1]` are the points of scan line `r`.
    row_start: Vec<u32>,
    used: Vec<bool>,
    /// The scan line of each input point (`u32::MAX`: not finite).
    rows: Vec<u32>,
    grid: Grid,
}

/// Segments of one edge-point set (llv.md §3).
#[allow(dead_code)]
pub fn extract(e: &EdgePoints, p: &LineParams) -> Vec<Segment> {
    let mut out = Vec::new();
    extract_into(e, p, &mut out, &mut LineScratch::default());
    out
}

/// Bitmaps of the points by scan line and rounded `u` (one bit a pixel
/// column): every point, and the points not yet used. The template scores
/// and the successor test then read a few bits instead of walking the
/// scan lines. Only built when it is exact: every rounded `u` in
/// `0..2²⁰` and no two points of a scan line on one column (true of edge
/// points, which are one pixel thick; a file may say otherwise, and the
/// extractor then walks the scan lines).
#[derive(Clone, Debug, Default)]
struct Grid {
    words: usize,
    occupied: Vec<u64>,
    /// The unused points, by polarity ([`polarity`]): a track only takes
    /// points of its start's polarity, so only those can continue it.
    unused: [Vec<u64>; 2],
    /// Per word of `occupied`: the index of the first point at or after
    /// its first column (points before it on the scan line, plus the scan
    /// line's start), so a column's point is found without a search.
    before: Vec<u32>,
}

impl Grid {
    fn build(&mut self, points: &[ScanPoint], row_start: &[u32], nrows: usize) -> bool {
        self.occupied.clear();
        self.unused[0].clear();
        self.unused[1].clear();
        self.before.clear();
        self.words = 0;
        let mut max = 0i64;
        for q in points {
            if !(0..1 << 20).contains(&q.iu) {
                return false;
            }
            max = max.max(q.iu);
        }
        // The columns, and an empty word on either side.
        self.words = max as usize / 64 + 3;
        self.occupied.resize(nrows * self.words, 0);
        for r in 0..nrows {
            let base = r * self.words;
            for q in &points[row_start[r] as usize..row_start[r + 1] as usize] {
                let c = q.iu as usize + 64;
                let (w, bit) = (base + c / 64, 1u64 << (c % 64));
                if self.occupied[w] & bit != 0 {
                    self.occupied.clear();
                    self.words = 0;
                    return false;
                }
                self.occupied[w] |= bit;
            }
        }
        for u in &mut self.unused {
            u.resize(self.occupied.len(), 0);
        }
        for r in 0..nrows {
            for q in &points[row_start[r] as usize..row_start[r + 1] as usize] {
                let c = q.iu as usize + 64;
                self.unused[polarity(q.response)][r * self.words + c / 64] |= 1u64 << (c % 64);
            }
        }
        self.before.reserve(self.occupied.len());
        for (&first, row) in row_start.iter().zip(self.occupied.chunks_exact(self.words)) {
            let mut n = first;
            for &w in row {
                self.before.push(n);
                n += w.count_ones();
            }
        }
        true
    }

    /// Bits `k = 0..n` (`n < 64`) of scan line `r` for columns `lo + k`.
    /// Each scan line has an empty word before and after its columns
    /// (column `c` is bit `c + 64`), so no window needs a special case at
    /// the image's sides.
    #[inline]
    fn window(&self, bits: &[u64], r: usize, lo: i64, n: u32) -> u64 {
        let start = lo + 64;
        if start < 0 {
            return 0;
        }
        let (w, b) = ((start >> 6) as usize, (start & 63) as u32);
        if w + 1 >= self.words {
            return 0;
        }
        let base = r * self.words + w;
        let (first, second) = (bits[base], bits[base + 1]);
        let v = (first >> b) | ((second << 1) << (63 - b));
        v & ((1u64 << n) - 1)
    }

    /// The index of the point on scan line `r` at column `c` (a set bit).
    #[inline]
    fn point_at(&self, r: usize, c: i64) -> usize {
        let c = (c + 64) as usize;
        let k = r * self.words + c / 64;
        let below = self.occupied[k] & ((1u64 << (c % 64)) - 1);
        self.before[k] as usize + below.count_ones() as usize
    }

    #[inline]
    fn mark_used(&mut self, r: usize, q: &ScanPoint) {
        let c = q.iu as usize + 64;
        self.unused[polarity(q.response)][r * self.words + c / 64] &= !(1u64 << (c % 64));
    }

    /// The template of §3.1 for a point at column `iu` of scan line `row`.
    fn template(&self, row: usize, iu: i64, nrows: usize) -> usize {
        let mut score = [0u32; 4];
        for (j, r) in (row as i64 - 2..=row as i64 + 2).enumerate() {
            if r < 0 || r as usize >= nrows {
                continue;
            }
            let mut bits = self.window(&self.occupied, r as usize, iu - 2, 5);
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                for (t, sc) in score.iter_mut().enumerate() {
                    *sc += u32::from(TEMPLATES[t][j][i]);
                }
                bits &= bits - 1;
            }
        }
        best_template(&score)
    }

    /// [`has_successor`] from the bitmaps, sharper: an unused point of the
    /// start's polarity (the only kind a track takes) with `u` in
    /// `[u − reach, u + reach]` on scan line `row + i`, `reach = i + sw`.
    /// A point's `u` is within ½ px of its column, so the columns
    /// `iu ± (⌊reach⌋ + 2)` hold every candidate: when their bits are clear
    /// (most start points on noise) the answer is no, in integer work alone.
    /// A column whose whole pixel lies inside the reach decides by its bit;
    /// the ones at the ends by the point itself.
    fn has_successor(
        &self,
        s: &LineScratch,
        sp: &ScanPoint,
        row: usize,
        max_gap: usize,
        sw: f64,
    ) -> bool {
        let nrows = s.row_start.len() - 1;
        for i in 1..=max_gap {
            let r = row + i;
            if r >= nrows {
                return false;
            }
            let reach = i as f64 + sw;
            let half = reach as i64 + 2;
            let lo = sp.iu - half;
            let unused = &self.unused[polarity(sp.response)];
            let mut bits = self.window(unused, r, lo, (2 * half + 1) as u32);
            if bits == 0 {
                continue;
            }
            let (a, b) = (sp.u as f64 - reach, sp.u as f64 + reach);
            while bits != 0 {
                let c = lo + bits.trailing_zeros() as i64;
                bits &= bits - 1;
                let (left, right) = (c as f64 - 0.5, c as f64 + 0.5);
                if right < a || left > b {
                    continue;
                }
                if left >= a && right <= b {
                    return true;
                }
                // An end column: look at the point.
                let u = s.points[self.point_at(r, c)].u as f64;
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

/// Which template fits the neighbourhood of point `sp` on scan line `row`
/// best (§3.1), by walking the scan lines (what the `Grid` answers when
/// it is exact).
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

/// [`extract`] into reusable buffers; appends nothing else to `out` (it is
/// cleared first).
pub fn extract_into(e: &EdgePoints, p: &LineParams, out: &mut Vec<Segment>, s: &mut LineScratch) {
    out.clear();
    let vertical = e.dir == Some(ScanDir::Vertical);
    // Scan lines: counting sort by scan line keeps the order along the scan
    // of the lexically ordered input (and sorts EdgeV column by column).
    let row_of = |u: f32, v: f32| -> Option<usize> {
        if !(u.is_finite() && v.is_finite()) {
            return None;
        }
        let r = round_i64(v);
        (0..10_000_000).contains(&r).then_some(r as usize)
    };
    let to_scan = |x: f32, y: f32| if vertical { (y, x) } else { (x, y) };
    s.rows.clear();
    s.rows.extend(e.points.iter().map(|q| {
        let (u, v) = to_scan(q.x, q.y);
        row_of(u, v).map_or(u32::MAX, |r| r as u32)
    }));
    let nrows = s
        .rows
        .iter()
        .filter(|&&r| r != u32::MAX)
        .max()
        .map_or(0, |&r| r as usize + 1);
    s.row_start.clear();
    s.row_start.resize(nrows + 2, 0);
    for &r in &s.rows {
        if r != u32::MAX {
            s.row_start[r as usize + 2] += 1;
        }
    }
    for r in 2..nrows + 2 {
        s.row_start[r] += s.row_start[r - 1];
    }
    let total = s.row_start[nrows + 1] as usize;
    s.points.clear();
    s.points.resize(total, ScanPoint::default());
    for (q, &r) in e.points.iter().zip(&s.rows) {
        if r != u32::MAX {
            let (u, v) = to_scan(q.x, q.y);
            let slot = &mut s.row_start[r as usize + 1];
            s.points[*slot as usize] = ScanPoint {
                u,
                v,
                response: q.response,
                iu: round_i64(u),
            };
            *slot += 1;
        }
    }
    s.row_start.truncate(nrows + 1);
    // Within a scan line, order by u (the input may come from a file).
    for r in 0..nrows {
        let (lo, hi) = (s.row_start[r] as usize, s.row_start[r + 1] as usize);
        let row = &mut s.points[lo..hi];
        if !row.windows(2).all(|w| w[0].u <= w[1].u) {
            row.sort_unstable_by(|a, b| a.u.total_cmp(&b.u));
        }
    }
    s.used.clear();
    s.used.resize(total, false);
    let mut grid = std::mem::take(&mut s.grid);
    let sw = p.search_width;
    let window_fits = sw.is_finite() && sw >= 0.0 && p.max_gap as f64 + sw <= 28.0;
    let use_grid = window_fits && grid.build(&s.points, &s.row_start, nrows);

    let min_angle = p.min_scan_angle_deg.to_radians();
    let mut start_row = 0;
    for start in 0..total {
        while s.row_start[start_row + 1] as usize <= start {
            start_row += 1;
        }
        if s.used[start] {
            continue;
        }
        s.used[start] = true;
        let sp = s.points[start];
        let template = if use_grid {
            grid.mark_used(start_row, &sp);
            if !grid.has_successor(s, &sp, start_row, p.max_gap as usize, sw) {
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
        let mut slope = TEMPLATE_SLOPE[template];
        let mut fit = LineFit::new();
        fit.add(Point::new(sp.u as f64, sp.v as f64));
        // The mean, kept from one added point to the next (the prediction
        // and the stray test of every scan line tried use it).
        let mut mean = fit.mean();
        let mut resp_sum = sp.response as f64;
        let mut last = sp;
        let mut row_e = start_row;
        let mut axis: Option<(f64, f64)> = None;
        loop {
            let mut found = None;
            for i in 1..=p.max_gap as usize {
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
                if use_grid && pred.abs() < 1e9 {
                    let half = sw as i64 + 2;
                    let lo = pred as i64 - half;
                    let unused = &grid.unused[polarity(sp.response)];
                    let mut bits = grid.window(unused, r, lo, (2 * half + 1) as u32);
                    let near = std::iter::from_fn(|| {
                        (bits != 0).then(|| {
                            let c = lo + bits.trailing_zeros() as i64;
                            bits &= bits - 1;
                            grid.point_at(r, c)
                        })
                    });
                    if let Some(idx) = nearest(&s.points, near, pred, sw, sp.response) {
                        found = Some((idx, r));
                        break;
                    }
                    continue;
                }
                let near = from_u(s, r as i64, nrows, pred - sw)
                    .take_while(|&k| s.points[k].u as f64 - pred <= sw)
                    .filter(|&k| !s.used[k]);
                if let Some(idx) = nearest(&s.points, near, pred, sw, sp.response) {
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
            if use_grid {
                grid.mark_used(r, &s.points[idx]);
            }
            let q = s.points[idx];
            fit.add(Point::new(q.u as f64, q.v as f64));
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
        let response = resp_sum / fit.len() as f64;
        if response.abs() < p.min_response {
            continue;
        }
        // Projection onto a line never lengthens a segment: a track whose
        // ends are no further apart than `min_length` (less a hair for
        // rounding) is dropped before its line is computed.
        let (du, dv) = (last.u as f64 - sp.u as f64, last.v as f64 - sp.v as f64);
        if p.min_length > 0.0 && du * du + dv * dv < p.min_length * p.min_length * (1.0 - 1e-9) {
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
    s.grid = grid;
}
