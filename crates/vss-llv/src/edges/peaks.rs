//! Edge points: peaks of the response one pixel thick along the scan
//! (llv.md §2.3), with parabolic subpixel positions (§2.4), kept where they
//! stand out of the noise.
//!
//! The threshold (replacing §2.5's "at least `M` a region"): a peak is an
//! edge point when its magnitude `|E|`
//! - exceeds the floor `T` (grey levels), and
//! - exceeds `noise_sigmas` times the noise scale `σ_r` of its tile
//!   ([`NoiseMap`]: the robust scale of the response itself), and
//! - is among the `M` strongest of its region (ties kept).
//!
//! §2.5 kept *at least* `M` peaks a scan line: on a line that crosses no
//! edge that promotes the `M` largest noise peaks, and on the bench scene
//! 13 k of its 16 k points were noise, which the line extractor then paid
//! to follow and which became tilted, bent lines. Measured against the
//! noise, `M` only limits clutter (texture, a pattern) and noise is never
//! promoted; with the default 3.5 σ_r a tile of pure noise keeps about 4
//! points in 10 000 pixels. Edge points are where lines *start*: the line
//! extractor follows them through weaker peaks, so the threshold here can
//! be high.
//!
//! One pass finds both: the edge points' candidates and the peak map the
//! line extractor follows ([`PeakMap`]: every peak above its lower
//! threshold, a bit per pixel and polarity). Per row, the magnitudes are
//! computed once into a row padded to whole words; the test runs 32 pixels
//! at a time with AVX2 where the processor has it (`pulp`, chosen at run
//! time, safe intrinsics), and the compares' sign bits (movemask) are the
//! map's words and the candidates' bits as they are; elsewhere the same
//! test runs in plain code, which is also the reference the tests compare
//! the lanes with. Each candidate takes along its sum and its neighbours'
//! keys, so that its edge point is made without reading the response
//! again (`peaks/points.rs`).
//!
//! Why one pass and bit masks: a call per peak to fill a map (about ten
//! thousand a direction), a second pass for the edge points, or a test of
//! pixel after pixel where a track looks each cost more than this pass
//! does in all; `docs/performance.md` has the measurements.

mod lanes;
mod points;
mod scan_layout;
pub(crate) mod strips;

use super::band::{Rows, Whole};
#[cfg(test)]
use super::key;
use super::{NoiseMap, Response};
use crate::params::EdgeParams;
use crate::{EdgePoint, EdgePoints, ScanDir};
#[doc(hidden)]
pub use lanes::plain_only;
use lanes::{key_row, row_masks, simd};

/// Reusable buffers of the edge-point selection.
#[derive(Clone, Debug, Default)]
pub struct PeakScratch {
    /// Candidates: pixel index and key, in image order.
    cand: Vec<Peak>,
    /// Per tile, the largest key that does not pass: for an edge point,
    /// for a peak a track may take.
    thr: Vec<i32>,
    track_thr: Vec<i32>,
    /// Per column of a row of tiles, the same two.
    cols: Vec<i16>,
    /// Per column, its tile; the rows of the pass.
    tiles: Vec<u32>,
    rows: ScanRows,
    /// Per region: candidate count, then the smallest key kept.
    count: Vec<u32>,
    lim: Vec<i16>,
    /// Candidates' keys grouped by region (regions with more than `M`):
    /// where each region's start, and where its next key goes.
    start: Vec<u32>,
    fill: Vec<u32>,
    grouped: Vec<i16>,
    /// The kept candidates, where a region has more than `M`.
    kept: Vec<Peak>,
    noise: super::NoiseScratch,
}

/// The pixel `[x, y]` of every edge point of a [`detect_into`] call, in
/// the points' order: where the line extractor starts its tracks.
pub type Starts = Vec<[u16; 2]>;

/// A peak found by the pass: its pixel and key (images are at most 8192
/// pixels a side, `image::MAX_PIXELS`, so coordinates fit `u16`), its sum,
/// and the keys before and after it along the scan: all its edge point
/// needs, taken while its rows are at hand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Peak {
    pub x: u16,
    pub y: u16,
    pub key: i16,
    pub sum: i16,
    pub lo: i16,
    pub hi: i16,
}

/// The peaks a line extractor may follow: one bit per pixel and polarity
/// for every peak along the scan above the tracking threshold (the floor
/// and a number of noise sigmas of its tile), in image order, each row
/// starting on a word. A track reads the peaks of its search window on the
/// next scan line from it (`PeakMap::window`): one word for a horizontal
/// scan, a bit a row for a vertical one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PeakMap {
    width: usize,
    height: usize,
    dir: Option<ScanDir>,
    floor: f64,
    sigmas: f64,
    /// Words per image row.
    wpr: usize,
    pos: Vec<u64>,
    neg: Vec<u64>,
}

impl PeakMap {
    /// Whether the map is that of a response of this size and direction
    /// at this threshold.
    pub fn fits(&self, r: &Response, floor: f64, sigmas: f64) -> bool {
        (self.width, self.height, self.dir) == (r.width, r.height, Some(r.dir))
            && self.floor.to_bits() == floor.to_bits()
            && self.sigmas.to_bits() == sigmas.to_bits()
            && self.wpr > 0
    }

    /// Sizes and clears the map for `r` at a threshold.
    fn reset(&mut self, r: &Response, floor: f64, sigmas: f64) {
        let shape = Shape {
            w: r.width,
            h: r.height,
            dir: r.dir,
        };
        self.reset_for(shape, floor, sigmas);
    }

    /// [`PeakMap::reset`] for a response of this shape.
    fn reset_for(&mut self, shape: Shape, floor: f64, sigmas: f64) {
        self.width = shape.w;
        self.height = shape.h;
        self.dir = Some(shape.dir);
        self.floor = floor;
        self.sigmas = sigmas;
        self.wpr = shape.w.div_ceil(64);
        for bits in [&mut self.pos, &mut self.neg] {
            bits.clear();
            bits.resize(self.wpr * shape.h, 0);
        }
    }

    /// The map of `r`'s peaks above `floor` grey levels and `sigmas` noise
    /// sigmas (what [`detect_into`] makes along with the edge points).
    pub fn build_into(
        &mut self,
        r: &Response,
        noise: &NoiseMap,
        floor: f64,
        sigmas: f64,
        s: &mut PeakScratch,
    ) {
        self.reset(r, floor, sigmas);
        if !r.covers(r.width, r.height) || floor.is_nan() {
            return;
        }
        tile_floors(r.scale(), noise, floor, sigmas, &mut s.track_thr);
        let mut cand = std::mem::take(&mut s.cand);
        cand.clear();
        let track = std::mem::take(&mut s.track_thr);
        scan(r, noise, None, &track, s, &mut cand, self);
        s.track_thr = track;
        s.cand = cand;
    }

    /// Whether the map holds the rows of a response of `h` rows along
    /// `dir` (it was reset for one).
    fn holds(&self, dir: ScanDir, h: usize) -> bool {
        self.dir == Some(dir) && self.wpr > 0 && self.pos.len() == self.wpr * h
    }

    /// The image coordinates of scan position `(u, v)`.
    #[inline(always)]
    fn xy(&self, u: usize, v: usize) -> (usize, usize) {
        if self.dir == Some(ScanDir::Vertical) {
            (v, u)
        } else {
            (u, v)
        }
    }

    /// The peaks of one polarity on scan line `v` at positions `lo..hi`
    /// (`hi − lo ≤ 64`), as bits from `lo`.
    #[inline]
    pub(crate) fn window(&self, positive: bool, v: usize, lo: usize, hi: usize) -> u64 {
        let bits = if positive { &self.pos } else { &self.neg };
        let n = hi.saturating_sub(lo).min(64);
        if n == 0 {
            return 0;
        }
        if self.dir == Some(ScanDir::Vertical) {
            // Column v, rows lo..lo + n: a bit a row.
            let (word, shift) = (v / 64, v % 64);
            let mut b = 0u64;
            for k in 0..n {
                let w = bits.get((lo + k) * self.wpr + word).copied().unwrap_or(0);
                b |= (w >> shift & 1) << k;
            }
            return b;
        }
        let at = v * self.wpr + lo / 64;
        let off = lo % 64;
        let Some(&w0) = bits.get(at) else { return 0 };
        let mut b = w0 >> off;
        if off > 0 && off + n > 64 {
            b |= bits.get(at + 1).map_or(0, |w| w << (64 - off));
        }
        if n < 64 { b & ((1u64 << n) - 1) } else { b }
    }

    /// Clears scan position `(u, v)` in both polarities (a track took it).
    #[inline]
    pub(crate) fn clear(&mut self, u: usize, v: usize) {
        let (x, y) = self.xy(u, v);
        let at = y * self.wpr + x / 64;
        let m = !(1u64 << (x % 64));
        for bits in [&mut self.pos, &mut self.neg] {
            if let Some(w) = bits.get_mut(at) {
                *w &= m;
            }
        }
    }

    /// Whether scan position `(u, v)` is in the map (either polarity).
    #[inline]
    pub(crate) fn is_set(&self, u: usize, v: usize) -> bool {
        let (x, y) = self.xy(u, v);
        let at = y * self.wpr + x / 64;
        let bit = |b: &[u64]| b.get(at).is_some_and(|w| w >> (x % 64) & 1 != 0);
        bit(&self.pos) || bit(&self.neg)
    }

    /// Copies `o` into `self`, reusing the buffers.
    pub(crate) fn copy_from(&mut self, o: &PeakMap) {
        self.width = o.width;
        self.height = o.height;
        self.dir = o.dir;
        self.floor = o.floor;
        self.sigmas = o.sigmas;
        self.wpr = o.wpr;
        self.pos.clone_from(&o.pos);
        self.neg.clone_from(&o.neg);
    }
}

/// Per tile of `noise`, the largest key at or below `floor` grey levels and
/// `sigmas` noise sigmas (a key passes when it is above this).
fn tile_floors(scale: f32, noise: &NoiseMap, floor: f64, sigmas: f64, out: &mut Vec<i32>) {
    let (nx, ny) = noise.tiles();
    let rest = sigmas as f32;
    out.clear();
    for t in 0..nx * ny {
        let limit = (floor as f32).max(rest * noise.sigma(t));
        out.push(key_floor(limit, scale));
    }
}

/// The largest key at or below `limit` grey levels with `scale` grey levels
/// a key: a key passes when it is above this.
pub(crate) fn key_floor(limit: f32, scale: f32) -> i32 {
    if limit.is_nan() || scale.is_nan() || scale <= 0.0 {
        // (NaN: the caller refused it; no scale: an empty response.)
        return i32::from(i16::MAX);
    }
    if limit <= 0.0 {
        return -1;
    }
    let k = (limit / scale).floor();
    if k >= f32::from(i16::MAX) {
        i32::from(i16::MAX)
    } else {
        k as i32
    }
}

/// Parabolic subpixel offset through `|E|` at a peak and its two neighbours,
/// clamped to ±0.5 (llv.md §2.4).
#[inline]
pub(crate) fn subpixel(em: f32, e0: f32, ep: f32) -> f32 {
    let den = 2.0 * (em - 2.0 * e0 + ep);
    if den < 0.0 {
        ((em - ep) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Edge points of a response (see the module doc), estimating its noise
/// map first.
pub fn peaks(resp: &Response, p: &EdgeParams) -> EdgePoints {
    let mut s = PeakScratch::default();
    let (mut noise, mut map) = (NoiseMap::default(), PeakMap::default());
    let (mut out, mut starts) = (EdgePoints::default(), Starts::new());
    detect_into(
        resp,
        p,
        p.noise_sigmas,
        &mut noise,
        &mut map,
        &mut out,
        &mut starts,
        &mut s,
    );
    out
}

/// The noise map, the peak map and the edge points of a response, into
/// reusable buffers: what the pipeline does per scan direction, in one
/// pass over the response. The peak map holds the peaks above
/// `track_sigmas` noise sigmas (the line extractor's threshold); `starts`
/// gets each edge point's pixel index, where the line extractor starts.
#[allow(clippy::too_many_arguments)]
pub fn detect_into(
    resp: &Response,
    p: &EdgeParams,
    track_sigmas: f64,
    noise: &mut NoiseMap,
    map: &mut PeakMap,
    out: &mut EdgePoints,
    starts: &mut Starts,
    s: &mut PeakScratch,
) {
    bounded_noise(resp, p, noise, s);
    map.reset(resp, p.floor, track_sigmas);
    points_into(resp, noise, p, Some(map), out, starts, s);
}

/// The response's noise map, bounded as `p` says (both detections').
fn bounded_noise(resp: &Response, p: &EdgeParams, noise: &mut NoiseMap, s: &mut PeakScratch) {
    let mut ns = std::mem::take(&mut s.noise);
    noise.estimate_into(resp, &mut ns);
    noise.bound(p.noise_percentile, p.noise_cap, &mut ns);
    s.noise = ns;
}

/// [`detect_into`] without the peak map, for the drawing front end
/// (`lines.draw`), which does not read it: `map` is marked as holding no
/// response, so that a tracker given it later makes its own.
pub fn detect_unmapped_into(
    resp: &Response,
    p: &EdgeParams,
    noise: &mut NoiseMap,
    map: &mut PeakMap,
    out: &mut EdgePoints,
    starts: &mut Starts,
    s: &mut PeakScratch,
) {
    bounded_noise(resp, p, noise, s);
    (map.wpr, map.dir) = (0, None);
    points_into(resp, noise, p, None, out, starts, s);
}

/// Edge points of a response given its noise map, in image order (row by
/// row, left to right, for either direction).
///
/// Settled details: a peak needs both neighbours along the scan to have a
/// response (no edge at the border of the valid area); a region is
/// `region_lines` consecutive scan lines (rows for `Horizontal`, columns
/// for `Vertical`); where a region has more than `M` candidates, those at
/// least as strong as its `M`-th strongest are kept.
pub fn points_into(
    resp: &Response,
    noise: &NoiseMap,
    p: &EdgeParams,
    map: Option<&mut PeakMap>,
    out: &mut EdgePoints,
    starts: &mut Starts,
    s: &mut PeakScratch,
) {
    let (w, h) = (resp.width, resp.height);
    out.dir = Some(resp.dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    starts.clear();
    s.cand.clear();
    if w < 3 || h < 3 || !resp.covers(w, h) || p.floor.is_nan() {
        return;
    }
    tile_floors(resp.scale(), noise, p.floor, p.noise_sigmas, &mut s.thr);
    let mut cand = std::mem::take(&mut s.cand);
    match map {
        Some(m) => {
            let (f, t) = (m.floor, m.sigmas);
            tile_floors(resp.scale(), noise, f, t, &mut s.track_thr);
            let (thr, track) = (std::mem::take(&mut s.thr), std::mem::take(&mut s.track_thr));
            scan(resp, noise, Some(&thr), &track, s, &mut cand, m);
            (s.thr, s.track_thr) = (thr, track);
        }
        None => {
            let thr = std::mem::take(&mut s.thr);
            scan(
                resp,
                noise,
                Some(&thr),
                &[],
                s,
                &mut cand,
                &mut PeakMap::default(),
            );
            s.thr = thr;
        }
    }
    let shape = Shape {
        w,
        h,
        dir: resp.dir,
    };
    select(shape, resp.scale(), p, &cand, out, starts, s);
    s.cand = cand;
}

/// The edge points among the candidates `cand` of a response: those
/// among the `M` strongest of their region, with their subpixel positions,
/// into `out` and `starts`.
fn select(
    shape: Shape,
    scale: f32,
    p: &EdgeParams,
    cand: &[Peak],
    out: &mut EdgePoints,
    starts: &mut Starts,
    s: &mut PeakScratch,
) {
    if !points::crowdable(shape, p) {
        points::emit(shape, scale, cand, out, starts);
        return;
    }
    let (region, nreg, m) = regions(shape, p);
    points::region_limits(cand, nreg, m, region, s);
    let mut kept = std::mem::take(&mut s.kept);
    kept.clear();
    kept.extend(cand.iter().filter(|c| c.key >= s.lim[region(c)]));
    points::emit(shape, scale, &kept, out, starts);
    s.kept = kept;
}

/// The region of a candidate, the number of regions, and `M`: a region
/// is `region_lines` scan lines.
fn regions(shape: Shape, p: &EdgeParams) -> (impl Fn(&Peak) -> usize + Copy, usize, usize) {
    let Shape { w, h, dir } = shape;
    let rl = p.region_lines.max(1) as usize;
    let m = p.per_region.max(1) as usize;
    let region = move |c: &Peak| -> usize {
        let at = match dir {
            ScanDir::Horizontal => usize::from(c.y),
            ScanDir::Vertical => usize::from(c.x),
        };
        // (No division for the default region of one scan line.)
        if rl == 1 { at } else { at / rl }
    };
    let nreg = match dir {
        ScanDir::Horizontal => h.div_ceil(rl),
        ScanDir::Vertical => w.div_ceil(rl),
    };
    (region, nreg, m)
}

/// The edge point of candidate `c`: its subpixel position along the scan
/// and its response.
#[inline]
fn point_of(c: &Peak, shape: Shape, scale: f32) -> EdgePoint {
    let mag = f32::from;
    let d = subpixel(mag(c.lo), mag(c.key), mag(c.hi));
    placed(c, d, response_of(c, scale), shape)
}

/// The response (grey levels) of candidate `c`, `scale` grey levels a sum.
#[inline(always)]
fn response_of(c: &Peak, scale: f32) -> f32 {
    f32::from(c.sum) * scale
}

/// The edge point of candidate `c` at subpixel offset `d` along the scan,
/// with its response `r`: the one place a candidate becomes a point
/// ([`point_of`], and `points::emit` for a batch).
#[inline(always)]
fn placed(c: &Peak, d: f32, r: f32, shape: Shape) -> EdgePoint {
    let (x, y) = (f32::from(c.x), f32::from(c.y));
    let (x, y) = match shape.dir {
        ScanDir::Horizontal => (x + d, y),
        ScanDir::Vertical => (x, y + d),
    };
    EdgePoint { x, y, response: r }
}

/// Every pixel that is a peak along the scan (`|E|` above the left/upper
/// neighbour's, at least the right/lower one's) and above its tile's
/// threshold `thr` (per tile of `noise`, as keys), in image order, with its
/// key.
#[cfg(test)]
fn candidates(resp: &Response, noise: &NoiseMap, thr: &[i32], cand: &mut Vec<Peak>) {
    let mut s = PeakScratch::default();
    scan(
        resp,
        noise,
        Some(thr),
        &[],
        &mut s,
        cand,
        &mut PeakMap::default(),
    );
}

/// One pass over a response: the edge points' candidates (peaks above
/// `start`, per tile, when given) into `cand`, and every peak above
/// `track` into `map` when it was reset for `resp` (else it is left
/// alone). `s` gives the row buffers.
///
/// Each row's magnitudes are computed once, into a row padded to whole
/// blocks of 32 positions with a sentinel (`i16::MAX`, which stops a peak
/// like [`NONE`](super::NONE)) at each end, so that the test runs on aligned blocks with
/// no edge cases: position `x` reads `keys[x]`, `keys[x + 1]`,
/// `keys[x + 2]` of the row (horizontal scan) or of the rows above, at and
/// below (vertical scan, three rows kept in turn).
fn scan(
    resp: &Response,
    noise: &NoiseMap,
    start: Option<&[i32]>,
    track: &[i32],
    s: &mut PeakScratch,
    cand: &mut Vec<Peak>,
    map: &mut PeakMap,
) {
    let (w, h) = (resp.width, resp.height);
    let sums = resp.sums();
    if w < 3 || h < 3 || sums.len() != w * h {
        return;
    }
    let shape = Shape {
        w,
        h,
        dir: resp.dir,
    };
    let ys = if resp.dir == ScanDir::Vertical {
        1..h - 1
    } else {
        0..h
    };
    let th = Thresholds { start, track };
    let mut push = |c: Peak| cand.push(c);
    scan_rows(&mut Whole(sums, w), shape, ys, noise, th, s, &mut push, map);
}

/// A response's size and scan direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shape {
    pub w: usize,
    pub h: usize,
    pub dir: ScanDir,
}

/// The keys a peak must pass, per tile: an edge point's (none: no
/// candidates), a tracked peak's.
#[derive(Clone, Copy)]
pub(crate) struct Thresholds<'a> {
    pub start: Option<&'a [i32]>,
    pub track: &'a [i32],
}

/// [`scan`] of the rows `ys` of a `w × h` response (`w`, `h` ≥ 3) that
/// `rows` gives (it loads them and, along a vertical scan, the rows
/// above and below); each candidate goes to `sink`, in image order.
#[allow(clippy::too_many_arguments)]
pub(crate) fn scan_rows<R: Rows>(
    rows_of: &mut R,
    shape: Shape,
    ys: std::ops::Range<usize>,
    noise: &NoiseMap,
    th: Thresholds,
    s: &mut PeakScratch,
    sink: &mut impl FnMut(Peak),
    map: &mut PeakMap,
) {
    let Shape { w, h, dir } = shape;
    let (start, track) = (th.start, th.track);
    if ys.is_empty() {
        return;
    }
    let vertical = dir == ScanDir::Vertical;
    if vertical {
        rows_of.load(ys.start - 1, (ys.end + 1).min(h));
    } else {
        rows_of.load(ys.start, ys.end);
    }
    let mapped = map.holds(dir, h);
    let wpr = w.div_ceil(64);
    // Positions padded to whole blocks (and words: two blocks a word).
    let wp = wpr * 64;
    let simd = simd();
    let as_key = |t: Option<&i32>| {
        t.copied()
            .unwrap_or(i32::MAX)
            .clamp(-1, i32::from(i16::MAX)) as i16
    };
    noise.columns_into(w, &mut s.tiles);
    let rb = &mut s.rows;
    for k in &mut rb.keys {
        k.clear();
        k.resize(wp + 2, i16::MAX);
    }
    rb.sign.clear();
    rb.sign.resize(wp, 0);
    rb.bits.clear();
    rb.bits.resize(3 * wpr, 0);
    let mut tile_row = usize::MAX;
    let y_first = ys.start;
    if vertical {
        // The rows above and at the first: keys[0], keys[1].
        key_row(&rows_of.row(y_first - 1)[..w], &mut rb.keys[0][1..=w]);
        key_row(&rows_of.row(y_first)[..w], &mut rb.keys[1][1..=w]);
    }
    for y in ys {
        // The thresholds of every column of this row's tiles: `cols[..wp]`
        // the edge points', `cols[wp..]` the tracks' (never passed beyond
        // the row).
        let t0 = noise.row_of(y);
        if t0 != tile_row {
            tile_row = t0;
            s.cols.clear();
            s.cols.resize(2 * wp, i16::MAX);
            for (x, &tx) in s.tiles.iter().enumerate() {
                let t = t0 + tx as usize;
                if let Some(st) = start {
                    s.cols[x] = as_key(st.get(t));
                }
                if mapped {
                    s.cols[wp + x] = as_key(track.get(t));
                }
            }
        }
        let from = rows_of.row(y);
        let row = &from[..w];
        // The signs: the row itself where the padded length stays inside
        // the response (what follows the row is never a peak: thresholds
        // are `i16::MAX` there), else a padded copy.
        let sign: &[i16] = match from.get(..wp) {
            Some(s) => s,
            None => {
                rb.sign[..w].copy_from_slice(row);
                &rb.sign
            }
        };
        let [k0, k1, k2] = &mut rb.keys;
        let keys: [&[i16]; 3] = if vertical {
            // keys[2] takes the row below; then the three turn.
            key_row(&rows_of.row(y + 1)[..w], &mut k2[1..=w]);
            [&k0[1..], &k1[1..], &k2[1..]]
        } else {
            key_row(row, &mut k0[1..=w]);
            [&k0[..], &k0[1..], &k0[2..]]
        };
        rb.bits.fill(0);
        let (cs, ct) = s.cols.split_at(wp);
        row_masks(simd, keys, sign, cs, ct, &mut rb.bits);
        let (st, rest) = rb.bits.split_at(wpr);
        let (pos, neg) = rest.split_at(wpr);
        if mapped {
            map.pos[y * wpr..(y + 1) * wpr].copy_from_slice(pos);
            map.neg[y * wpr..(y + 1) * wpr].copy_from_slice(neg);
        }
        // (The key from the key row: `key(row[x])` is a branch on the
        // sign, which a photograph's edges make unpredictable.)
        let [lo, mid, hi] = keys;
        for (k, &word) in st.iter().enumerate() {
            let mut m = word;
            while m != 0 {
                let x = k * 64 + m.trailing_zeros() as usize;
                m &= m - 1;
                sink(Peak {
                    x: x as u16,
                    y: y as u16,
                    key: mid[x],
                    sum: row[x],
                    lo: lo[x],
                    hi: hi[x],
                });
            }
        }
        if vertical {
            rb.keys.rotate_left(1);
        }
    }
}

/// The scan's row buffers (see [`scan`]).
#[derive(Clone, Debug, Default)]
struct ScanRows {
    /// Padded key rows: position `x` at index `x + 1`.
    keys: [Vec<i16>; 3],
    /// The row's sums, padded with zeros.
    sign: Vec<i16>,
    /// The row's candidate, positive and negative bits, a word per 64
    /// positions each.
    bits: Vec<u64>,
}

/// [`candidates`] in plain code, one pixel and tile at a time: the
/// reference the lane-wise test is compared with.
#[cfg(test)]
fn candidates_plain(resp: &Response, noise: &NoiseMap, thr: &[i32], cand: &mut Vec<Peak>) {
    let (w, h) = (resp.width, resp.height);
    let sums = resp.sums();
    let step = match resp.dir {
        ScanDir::Horizontal => 1,
        ScanDir::Vertical => w,
    };
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let inside = match resp.dir {
                ScanDir::Horizontal => x >= 1 && x + 1 < w,
                ScanDir::Vertical => y >= 1 && y + 1 < h,
            };
            if !inside {
                continue;
            }
            let k0 = key(sums[i]);
            let th = thr[noise.tile_of(x, y)];
            if i32::from(k0) > th
                && k0 > key(sums[i - step])
                && k0 >= key(sums[i + step])
                && sums[i] != super::NONE
            {
                cand.push(Peak {
                    x: x as u16,
                    y: y as u16,
                    key: k0,
                    sum: sums[i],
                    lo: key(sums[i - step]),
                    hi: key(sums[i + step]),
                });
            }
        }
    }
}

#[cfg(test)]
mod tests;
