//! Where the tracker finds its next point: the peaks of a response, from the
//! edge pass's peak map ([`ResponsePeaks`], the pipeline), or a set of edge
//! points alone ([`PointPeaks`], edge files and hand-made point sets).
//!
//! Both work in scan coordinates `(u, v)`: `u` along the scan, `v` the scan
//! line (for `EdgeH` that is `(x, y)`; for `EdgeV`, `(y, x)`).

use crate::edges::band::PixelSums;
use crate::edges::peaks::subpixel;
use crate::edges::{NONE, NoiseMap, PeakMap, Response, key};
use crate::{EdgePoints, ScanDir};

/// A point the tracker may take: its position, signed response (grey
/// levels), noise sigmas (NaN where the noise is unknown) and identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cand {
    pub u: f64,
    pub v: usize,
    pub response: f32,
    pub z: f32,
    pub id: usize,
    /// The whole position along the scan (a response's pixel).
    pub pix: u32,
}

/// What the tracker asks of its points.
pub trait Peaks {
    /// Scan lines: `v` in `0..lines()`.
    fn lines(&self) -> usize;
    /// The unused peak of the given polarity on scan line `v` whose
    /// position is within `sw` of `pred`, nearest first (ties: smaller `u`).
    fn nearest(&self, v: usize, pred: f64, sw: f64, positive: bool) -> Option<Cand>;
    /// The strongest such peak within `reach` of `u` (ties: nearer `u`,
    /// then smaller).
    fn strongest(&self, v: usize, u: f64, reach: f64, positive: bool) -> Option<Cand>;
    fn take(&mut self, c: &Cand);
    /// Whether the seed `id` is taken: a point's index, or a scan
    /// position packed `v << 32 | u` (a response's).
    fn is_taken(&self, id: u64) -> bool;
    /// The point of seed `id`, to start a track from.
    fn seed(&self, id: u64) -> Option<Cand>;
}

/// Peaks read from a response: local maxima of `|E|` along the scan above
/// `track_sigmas` noise sigmas of their tile (and the floor), as the edge
/// points are, only with a lower threshold: the [`PeakMap`] the edge stage
/// made in its pass. A search window is one word of it; a point's
/// position, response and noise sigmas are read from the response only
/// for the peaks in the window.
pub struct ResponsePeaks<'a, S: SumAt = &'a [i16]> {
    sums: S,
    scale: f32,
    /// Index steps along the scan and from one scan line to the next.
    step_u: usize,
    step_v: usize,
    len_u: usize,
    nlines: usize,
    /// Per tile, `scale / σ`.
    inv_sigma: Vec<f32>,
    /// The tile of scan position `(u, v)` is `tile_u[u] + tile_v[v]`.
    tile_u: Vec<u32>,
    tile_v: Vec<u32>,
    /// The peaks not yet taken (a copy of the map's, in scan layout for a
    /// given map: [`PeakMap::scan_copy_from`]; cleared as tracks
    /// take them), and the map itself; without it (a map given to be
    /// used up), a seed's bit 63 says whether it was in the map.
    map: PeakMap,
    orig: Option<&'a PeakMap>,
}

/// Reusable buffers of [`ResponsePeaks`].
#[derive(Clone, Debug, Default)]
pub struct ResponseBufs {
    inv_sigma: Vec<f32>,
    tile_u: Vec<u32>,
    tile_v: Vec<u32>,
    map: PeakMap,
}

/// A response's sum at an image index.
pub trait SumAt {
    fn sum_at(&self, i: usize) -> i16;
}

impl SumAt for &[i16] {
    #[inline(always)]
    fn sum_at(&self, i: usize) -> i16 {
        self[i]
    }
}

impl SumAt for PixelSums<'_> {
    #[inline]
    fn sum_at(&self, i: usize) -> i16 {
        self.at(i)
    }
}

impl<'a> ResponsePeaks<'a> {
    /// The peaks of `r` in `map` (made for it: [`PeakMap::fits`]), with the
    /// noise sigmas of their tile of `noise`.
    pub fn new(r: &'a Response, noise: &NoiseMap, map: &'a PeakMap, b: &mut ResponseBufs) -> Self {
        let (w, h) = (r.width, r.height);
        let sums = if r.covers(w, h) { r.sums() } else { &[] };
        let shape = (w, h, r.dir, r.scale());
        b.map.scan_copy_from(map);
        let work = std::mem::take(&mut b.map);
        ResponsePeaks::with_sums(shape, sums, !sums.is_empty(), noise, work, Some(map), b)
    }
}

impl<'a> ResponsePeaks<'a, PixelSums<'a>> {
    /// The peaks in `map` (made for it) of a response read at pixels; the
    /// map is used up (tracks clear what they take), so a seed carries in
    /// bit 63 whether it was in the map.
    pub(crate) fn of_pixels(
        src: PixelSums<'a>,
        noise: &NoiseMap,
        map: PeakMap,
        b: &mut ResponseBufs,
    ) -> Self {
        let shape = (src.w, src.h, src.dir, src.scale());
        ResponsePeaks::with_sums(shape, src, true, noise, map, None, b)
    }

    /// Whether scan position `(u, v)` is (still) in the map.
    pub(crate) fn in_map(&self, u: usize, v: usize) -> bool {
        self.map.is_set(u, v)
    }
}

impl<'a, S: SumAt> ResponsePeaks<'a, S> {
    /// The peaks of a response of size, direction and unit `shape`
    /// (`sums`: none unless `valid`) in `map`, a copy of `orig` if given.
    fn with_sums(
        shape: (usize, usize, ScanDir, f32),
        sums: S,
        valid: bool,
        noise: &NoiseMap,
        map: PeakMap,
        orig: Option<&'a PeakMap>,
        b: &mut ResponseBufs,
    ) -> Self {
        let (w, h, dir, scale) = shape;
        let (nx, ny) = noise.tiles();
        b.inv_sigma.clear();
        for t in 0..nx * ny {
            let s = noise.sigma(t);
            b.inv_sigma
                .push(if s > 0.0 { scale / s } else { f32::INFINITY });
        }
        let (cols, rows) = (&mut b.tile_u, &mut b.tile_v);
        let (cols, rows) = if dir == ScanDir::Horizontal {
            (cols, rows)
        } else {
            (rows, cols)
        };
        noise.columns_into(w, cols);
        rows.clear();
        rows.extend((0..h).map(|y| noise.row_of(y) as u32));
        let (step_u, step_v, len_u, nlines) = match dir {
            ScanDir::Horizontal => (1, w, w, h),
            ScanDir::Vertical => (w, 1, h, w),
        };
        ResponsePeaks {
            sums,
            scale,
            step_u,
            step_v,
            len_u,
            nlines: if valid { nlines } else { 0 },
            inv_sigma: std::mem::take(&mut b.inv_sigma),
            tile_u: std::mem::take(&mut b.tile_u),
            tile_v: std::mem::take(&mut b.tile_v),
            map,
            orig,
        }
    }

    /// Gives the buffers back.
    pub fn finish(self, b: &mut ResponseBufs) {
        b.inv_sigma = self.inv_sigma;
        b.tile_u = self.tile_u;
        b.tile_v = self.tile_v;
        b.map = self.map;
    }

    /// The image index of scan position `(u, v)`.
    #[inline]
    fn index(&self, u: usize, v: usize) -> usize {
        u * self.step_u + v * self.step_v
    }

    /// The magnitude (key) of the sum at image index `j`.
    #[inline(always)]
    fn mag(&self, j: usize) -> f32 {
        f32::from(key(self.sums.sum_at(j)))
    }

    /// The signed response (grey levels) at image index `i`.
    #[inline(always)]
    fn response(&self, i: usize) -> f32 {
        f32::from(self.sums.sum_at(i)) * self.scale
    }

    /// The subpixel position of the peak at whole position `u`, image
    /// index `i`, and its magnitude.
    #[inline(always)]
    fn position(&self, u: usize, i: usize) -> (f64, f32) {
        let k0 = self.mag(i);
        let d = subpixel(self.mag(i - self.step_u), k0, self.mag(i + self.step_u));
        // (In `f32`, as edge points are: a track on the points alone then
        // sees the same positions.)
        (f64::from(u as f32 + d), k0)
    }

    /// The candidate of the peak at `(u, v)`, image index `i`, at
    /// position `pos` with magnitude `k0` ([`ResponsePeaks::position`]).
    #[inline(always)]
    fn cand_at(&self, u: usize, v: usize, i: usize, pos: f64, k0: f32) -> Cand {
        Cand {
            u: pos,
            v,
            response: self.response(i),
            z: k0 * self.inv_sigma[(self.tile_u[u] + self.tile_v[v]) as usize],
            id: i,
            pix: u as u32,
        }
    }

    /// The candidate of the peak at `(u, v)`, image index `i`.
    #[inline]
    fn cand(&self, u: usize, v: usize, i: usize) -> Cand {
        let (pos, k0) = self.position(u, i);
        self.cand_at(u, v, i, pos, k0)
    }

    /// The candidate at scan position `(u, v)` (an edge point's pixel).
    pub fn start(&self, u: usize, v: usize) -> Option<Cand> {
        if !(u >= 1 && u + 1 < self.len_u && v < self.nlines) {
            return None;
        }
        let i = self.index(u, v);
        (self.sums.sum_at(i) != NONE).then(|| self.cand(u, v, i))
    }

    /// The whole positions `u` whose peak may lie within `r` of `c`
    /// (peaks are not at a scan line's ends), as `lo..hi`, at most 64.
    #[inline]
    fn span(&self, c: f64, r: f64) -> (usize, usize) {
        // `⌈c − r − ½⌉ ..= ⌊c + r + ½⌋`, clamped to `1..len_u − 1`; in
        // `i64` (saturating casts of values far inside its range).
        let top = self.len_u as i64 - 1;
        let (lo, hi) = (c - r - 0.5, c + r + 0.5);
        if !(hi >= 1.0 && lo < top as f64) {
            return (1, 1);
        }
        let l = lo as i64;
        let l = (l + i64::from((l as f64) < lo)).max(1);
        let h = (hi as i64 + 1).min(top).min(l + 64);
        (l as usize, h.max(l) as usize)
    }
}

impl<S: SumAt> Peaks for ResponsePeaks<'_, S> {
    fn lines(&self) -> usize {
        self.nlines
    }

    #[inline(always)]
    fn nearest(&self, v: usize, pred: f64, sw: f64, positive: bool) -> Option<Cand> {
        if v >= self.nlines {
            return None;
        }
        let (lo, hi) = self.span(pred, sw);
        let mut bits = self.map.window(positive, v, lo, hi);
        // Only the position chooses: the candidate is made of the chosen
        // peak alone.
        let mut best: Option<(f64, usize, f64, f32)> = None;
        while bits != 0 {
            let u = lo + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let (pos, k0) = self.position(u, self.index(u, v));
            let d = (pos - pred).abs();
            if d <= sw && best.is_none_or(|(bd, ..)| d < bd) {
                best = Some((d, u, pos, k0));
            }
        }
        best.map(|(_, u, pos, k0)| self.cand_at(u, v, self.index(u, v), pos, k0))
    }

    fn strongest(&self, v: usize, u: f64, reach: f64, positive: bool) -> Option<Cand> {
        if v >= self.nlines {
            return None;
        }
        let (lo, hi) = self.span(u, reach);
        let mut bits = self.map.window(positive, v, lo, hi);
        // Only the magnitude and position choose (the candidate's
        // `response.abs()`).
        let mut best: Option<(f32, f64, usize, f64, f32)> = None;
        while bits != 0 {
            let x = lo + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let i = self.index(x, v);
            let (pos, k0) = self.position(x, i);
            let d = (pos - u).abs();
            let m = self.response(i).abs();
            if d <= reach && best.is_none_or(|(bm, bd, ..)| m > bm || (m == bm && d < bd)) {
                best = Some((m, d, x, pos, k0));
            }
        }
        best.map(|(_, _, x, pos, k0)| self.cand_at(x, v, self.index(x, v), pos, k0))
    }

    fn take(&mut self, c: &Cand) {
        self.map.clear(c.pix as usize, c.v);
    }

    fn is_taken(&self, id: u64) -> bool {
        // Taken: a peak of the map that a track cleared (a start below
        // the map's threshold is never taken by a track).
        let (u, v) = unpack(id);
        let was = match self.orig {
            Some(m) => m.is_set(u, v),
            None => id >> 63 != 0,
        };
        was && !self.map.is_set(u, v)
    }

    fn seed(&self, id: u64) -> Option<Cand> {
        let (u, v) = unpack(id);
        self.start(u, v)
    }
}

/// The scan position `(u, v)` of a response's seed `v << 32 | u` (bit 63
/// aside: [`ResponsePeaks::of_pixels`]).
#[inline]
fn unpack(id: u64) -> (usize, usize) {
    (
        (id & 0xFFFF_FFFF) as usize,
        (id >> 32 & 0x7FFF_FFFF) as usize,
    )
}

/// A point filed in scan coordinates.
#[derive(Clone, Copy, Debug, Default)]
pub struct Filed {
    pub u: f32,
    pub response: f32,
    /// Noise sigmas (NaN: unknown, as from an edge file).
    pub z: f32,
}

/// Edge points alone (no response, no noise scale): every point is a
/// candidate.
pub struct PointPeaks<'a> {
    /// Points by scan line, sorted by `u`: line `v` is
    /// `pts[start[v]..start[v + 1]]`.
    pts: &'a [Filed],
    start: &'a [u32],
    used: &'a mut Vec<bool>,
}

/// Reusable buffers of [`PointPeaks`].
#[derive(Clone, Debug, Default)]
pub struct PointBufs {
    pub pts: Vec<Filed>,
    pub start: Vec<u32>,
    pub used: Vec<bool>,
    staged: Vec<(u32, Filed)>,
}

/// The number of scan lines of a point set: its header's size across the
/// scan, or (a header of size 0) what its points need, at most 2¹⁶.
fn scan_lines(e: &EdgePoints, vertical: bool) -> usize {
    let header = if vertical { e.width } else { e.height };
    if header > 0 {
        return header;
    }
    let top = e
        .points
        .iter()
        .map(|p| if vertical { p.x } else { p.y })
        .filter(|v| v.is_finite() && *v >= -0.5)
        .fold(-1f32, f32::max);
    ((top + 0.5).floor() as i64 + 1).clamp(0, 1 << 16) as usize
}

impl PointBufs {
    /// Files `e`'s points by scan line (points with non-finite coordinates,
    /// or on no scan line of the image, are left out); the seeds are then
    /// the filed points in order.
    pub fn file(&mut self, e: &EdgePoints) {
        let vertical = e.dir == Some(ScanDir::Vertical);
        let nlines = scan_lines(e, vertical);
        self.staged.clear();
        for p in &e.points {
            let (u, v) = if vertical { (p.y, p.x) } else { (p.x, p.y) };
            let r = (v + 0.5).floor();
            if u.is_finite() && r >= 0.0 && (r as usize) < nlines && p.response.is_finite() {
                self.staged.push((
                    r as u32,
                    Filed {
                        u,
                        response: p.response,
                        z: f32::NAN,
                    },
                ));
            }
        }
        self.staged
            .sort_by(|a, b| a.0.cmp(&b.0).then(a.1.u.total_cmp(&b.1.u)));
        self.start.clear();
        self.start.resize(nlines + 1, 0);
        for &(r, _) in &self.staged {
            self.start[r as usize + 1] += 1;
        }
        for i in 0..nlines {
            self.start[i + 1] += self.start[i];
        }
        self.pts.clear();
        self.pts.extend(self.staged.iter().map(|s| s.1));
        self.used.clear();
        self.used.resize(self.pts.len(), false);
    }

    pub fn peaks(&mut self) -> PointPeaks<'_> {
        PointPeaks {
            pts: &self.pts,
            start: &self.start,
            used: &mut self.used,
        }
    }
}

impl PointPeaks<'_> {
    /// The scan line of filed point `i`.
    pub fn line_of(&self, i: usize) -> usize {
        self.start.partition_point(|&s| s as usize <= i) - 1
    }

    pub fn point(&self, i: usize) -> Cand {
        let p = self.pts[i];
        Cand {
            u: f64::from(p.u),
            v: self.line_of(i),
            response: p.response,
            z: p.z,
            id: i,
            pix: 0,
        }
    }

    pub fn len(&self) -> usize {
        self.pts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pts.is_empty()
    }

    /// The unused points of the polarity on line `v` within `r` of `c`.
    fn within(&self, v: usize, c: f64, r: f64, positive: bool) -> impl Iterator<Item = Cand> + '_ {
        let (a, b) = match (self.start.get(v), self.start.get(v + 1)) {
            (Some(&a), Some(&b)) => (a as usize, b as usize),
            _ => (0, 0),
        };
        let line = &self.pts[a..b];
        let from = line.partition_point(|p| f64::from(p.u) < c - r);
        line[from..]
            .iter()
            .enumerate()
            .take_while(move |(_, p)| f64::from(p.u) <= c + r)
            .filter(move |&(j, p)| (p.response > 0.0) == positive && !self.used[a + from + j])
            .map(move |(j, p)| Cand {
                u: f64::from(p.u),
                v,
                response: p.response,
                z: p.z,
                id: a + from + j,
                pix: 0,
            })
    }
}

impl Peaks for PointPeaks<'_> {
    fn lines(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    fn nearest(&self, v: usize, pred: f64, sw: f64, positive: bool) -> Option<Cand> {
        let mut best: Option<(f64, Cand)> = None;
        for c in self.within(v, pred, sw, positive) {
            let d = (c.u - pred).abs();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, c));
            }
        }
        best.map(|(_, c)| c)
    }

    fn strongest(&self, v: usize, u: f64, reach: f64, positive: bool) -> Option<Cand> {
        let mut best: Option<(f32, f64, Cand)> = None;
        for c in self.within(v, u, reach, positive) {
            let (m, d) = (c.response.abs(), (c.u - u).abs());
            if best.is_none_or(|(bm, bd, _)| m > bm || (m == bm && d < bd)) {
                best = Some((m, d, c));
            }
        }
        best.map(|(_, _, c)| c)
    }

    fn take(&mut self, c: &Cand) {
        self.used[c.id] = true;
    }

    fn is_taken(&self, id: u64) -> bool {
        self.used.get(id as usize).copied().unwrap_or(true)
    }

    fn seed(&self, id: u64) -> Option<Cand> {
        (id < self.pts.len() as u64).then(|| self.point(id as usize))
    }
}
