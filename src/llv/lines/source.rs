//! Where the tracker finds its next point: the peaks of a response, read
//! where it looks ([`ResponsePeaks`], the pipeline), or a set of edge
//! points alone ([`PointPeaks`], edge files and hand-made point sets).
//!
//! Both work in scan coordinates `(u, v)`: `u` along the scan, `v` the scan
//! line (for `EdgeH` that is `(x, y)`; for `EdgeV`, `(y, x)`).

use crate::llv::edges::peaks::subpixel;
use crate::llv::edges::{Keys, NoiseMap, PeakMap};
use crate::llv::{EdgePoints, ScanDir};

/// A point the tracker may take: its position, signed response (grey
/// levels), noise sigmas (NaN where the noise is unknown) and identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cand {
    pub u: f64,
    pub v: usize,
    pub response: f32,
    pub z: f32,
    pub id: usize,
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
    fn is_taken(&self, c: &Cand) -> bool;
}

/// Peaks read from a response: local maxima of `|E|` along the scan above
/// `track_sigmas` noise sigmas of their tile (and the floor), as the edge
/// points are, only with a lower threshold. Nothing is listed in advance:
/// a scan line is read only where a track looks.
pub struct ResponsePeaks<'a> {
    k: Keys<'a>,
    /// Index steps along the scan and from one scan line to the next.
    step_u: usize,
    step_v: usize,
    len_u: usize,
    nlines: usize,
    /// Per tile, `scale / σ`.
    inv_sigma: Vec<f32>,
    /// Tile of each column and of each row (image frame).
    tile_x: Vec<u16>,
    tile_y: Vec<u32>,
    /// The unused peaks above the threshold, by polarity: bit `i` for
    /// image index `i` (found once a call, sixteen pixels at a time; a
    /// track then reads a bit where it looks, and clears it).
    pos: Vec<u64>,
    neg: Vec<u64>,
}

/// Reusable buffers of [`ResponsePeaks`].
#[derive(Clone, Debug, Default)]
pub struct ResponseBufs {
    inv_sigma: Vec<f32>,
    tile_x: Vec<u16>,
    tile_y: Vec<u32>,
    pos: Vec<u64>,
    neg: Vec<u64>,
}

impl<'a> ResponsePeaks<'a> {
    /// Reads the peaks of `k` from `map` (its peaks above the tracking
    /// threshold, which the caller checked).
    pub fn new(k: Keys<'a>, noise: &NoiseMap, map: &PeakMap, b: &mut ResponseBufs) -> Self {
        let (w, h) = (k.width, k.height);
        let (nx, ny) = noise.tiles();
        b.inv_sigma.clear();
        for t in 0..nx * ny {
            let s = noise.sigma(t);
            b.inv_sigma
                .push(if s > 0.0 { k.scale / s } else { f32::INFINITY });
        }
        b.tile_x.clear();
        b.tile_x.extend((0..w).map(|x| noise.tile_of(x, 0) as u16));
        b.tile_y.clear();
        b.tile_y.extend((0..h).map(|y| noise.tile_of(0, y) as u32));
        // Taken points are cleared from these copies.
        b.pos.clone_from(&map.pos);
        b.neg.clone_from(&map.neg);
        let (step_u, step_v, len_u, nlines) = match k.dir {
            ScanDir::Horizontal => (1, w, w, h),
            ScanDir::Vertical => (w, 1, h, w),
        };
        ResponsePeaks {
            k,
            step_u,
            step_v,
            len_u,
            nlines,
            inv_sigma: std::mem::take(&mut b.inv_sigma),
            tile_x: std::mem::take(&mut b.tile_x),
            tile_y: std::mem::take(&mut b.tile_y),
            pos: std::mem::take(&mut b.pos),
            neg: std::mem::take(&mut b.neg),
        }
    }

    /// Gives the buffers back.
    pub fn finish(self, b: &mut ResponseBufs) {
        b.inv_sigma = self.inv_sigma;
        b.tile_x = self.tile_x;
        b.tile_y = self.tile_y;
        b.pos = self.pos;
        b.neg = self.neg;
    }

    /// The image index of scan position `(u, v)`.
    #[inline]
    fn index(&self, u: usize, v: usize) -> usize {
        u * self.step_u + v * self.step_v
    }

    /// Whether image index `i` is an unused peak of the polarity above its
    /// tile's threshold: one bit.
    #[inline(always)]
    fn is_peak(&self, i: usize, positive: bool) -> bool {
        let bits = if positive { &self.pos } else { &self.neg };
        bits.get(i / 64).is_some_and(|b| b >> (i % 64) & 1 != 0)
    }

    /// The candidate of the peak at `(u, v)`, image index `i`.
    #[inline]
    fn cand(&self, u: usize, v: usize, i: usize) -> Cand {
        let keys = self.k.keys;
        let (lo, k0, hi) = (keys[i - self.step_u], keys[i], keys[i + self.step_u]);
        let (x, y) = if self.step_u == 1 { (u, v) } else { (v, u) };
        let t = self.tile_y[y] as usize + self.tile_x[x] as usize;
        let d = subpixel(f32::from(lo), f32::from(k0), f32::from(hi));
        Cand {
            // (In `f32`, as edge points are: a track on the points alone
            // then sees the same positions.)
            u: f64::from(u as f32 + d),
            v,
            response: f32::from(self.k.sums[i]) * self.k.scale,
            z: f32::from(k0) * self.inv_sigma[t],
            id: i,
        }
    }

    /// The whole positions `u` whose peak may lie within `r` of `c`
    /// (peaks are not at a scan line's ends).
    #[inline]
    fn span(&self, c: f64, r: f64) -> std::ops::RangeInclusive<usize> {
        // `⌈c − r − ½⌉ ..= ⌊c + r + ½⌋` by truncation of positive values
        // (a libm call each on baseline x86-64 otherwise).
        let (lo, hi) = (c - r - 0.5, c + r + 0.5);
        let top = self.len_u as f64 - 2.0;
        if !(hi >= 1.0 && lo <= top) {
            #[allow(clippy::reversed_empty_ranges)]
            return 1..=0;
        }
        let lo = if lo <= 1.0 {
            1
        } else {
            let t = lo as usize;
            t + usize::from((t as f64) < lo)
        };
        let hi = if hi >= top { top as usize } else { hi as usize };
        lo..=hi
    }
}

impl Peaks for ResponsePeaks<'_> {
    fn lines(&self) -> usize {
        self.nlines
    }

    fn nearest(&self, v: usize, pred: f64, sw: f64, positive: bool) -> Option<Cand> {
        if v >= self.nlines {
            return None;
        }
        let mut best: Option<(f64, Cand)> = None;
        for u in self.span(pred, sw) {
            let i = self.index(u, v);
            if self.is_peak(i, positive) {
                let c = self.cand(u, v, i);
                let d = (c.u - pred).abs();
                if d <= sw && best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, c));
                }
            }
        }
        best.map(|(_, c)| c)
    }

    fn strongest(&self, v: usize, u: f64, reach: f64, positive: bool) -> Option<Cand> {
        if v >= self.nlines {
            return None;
        }
        let mut best: Option<(f32, f64, Cand)> = None;
        for x in self.span(u, reach) {
            let i = self.index(x, v);
            if self.is_peak(i, positive) {
                let c = self.cand(x, v, i);
                let d = (c.u - u).abs();
                let m = c.response.abs();
                if d <= reach && best.is_none_or(|(bm, bd, _)| m > bm || (m == bm && d < bd)) {
                    best = Some((m, d, c));
                }
            }
        }
        best.map(|(_, _, c)| c)
    }

    fn take(&mut self, c: &Cand) {
        let i = c.id;
        for bits in [&mut self.pos, &mut self.neg] {
            if let Some(b) = bits.get_mut(i / 64) {
                *b &= !(1 << (i % 64));
            }
        }
    }

    fn is_taken(&self, c: &Cand) -> bool {
        let i = c.id;
        let set = |bits: &[u64]| bits.get(i / 64).is_some_and(|b| b >> (i % 64) & 1 != 0);
        !(set(&self.pos) || set(&self.neg))
    }
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

    fn is_taken(&self, c: &Cand) -> bool {
        self.used[c.id]
    }
}
