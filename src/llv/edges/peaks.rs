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
//! the lanes with. The candidates above 3.5 σ are rare, so what follows is
//! plain code.
//!
//! Why one pass and bit masks: a call per peak to fill a map (about ten
//! thousand a direction), a second pass for the edge points, or a test of
//! pixel after pixel where a track looks each cost more than this pass
//! does in all; `docs/performance.md` has the measurements.

use super::{NoiseMap, Response, key};
use crate::llv::params::EdgeParams;
use crate::llv::{EdgePoint, EdgePoints, ScanDir};

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
    /// Candidates' keys grouped by region (regions with more than `M`).
    start: Vec<u32>,
    grouped: Vec<i16>,
    noise: super::NoiseScratch,
}

/// The pixel `[x, y]` of every edge point of a [`detect_into`] call, in
/// the points' order: where the line extractor starts its tracks.
pub type Starts = Vec<[u16; 2]>;

/// A peak found by the pass: its pixel and key (images are at most 8192
/// pixels a side, `image::MAX_PIXELS`, so coordinates fit `u16`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Peak {
    pub x: u16,
    pub y: u16,
    pub key: i16,
}

/// The peaks a line extractor may follow: one bit per pixel and polarity
/// for every peak along the scan above the tracking threshold (the floor
/// and a number of noise sigmas of its tile), in image order, each row
/// starting on a word. A track reads the peaks of its search window on the
/// next scan line from it ([`PeakMap::window`]): one word for a horizontal
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
        self.width = r.width;
        self.height = r.height;
        self.dir = Some(r.dir);
        self.floor = floor;
        self.sigmas = sigmas;
        self.wpr = r.width.div_ceil(64);
        for bits in [&mut self.pos, &mut self.neg] {
            bits.clear();
            bits.resize(self.wpr * r.height, 0);
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
        tile_floors(r, noise, floor, sigmas, &mut s.track_thr);
        let mut cand = std::mem::take(&mut s.cand);
        cand.clear();
        let track = std::mem::take(&mut s.track_thr);
        scan(r, noise, None, &track, s, &mut cand, self);
        s.track_thr = track;
        s.cand = cand;
    }

    /// Whether the map holds a response's rows (it was reset for one).
    fn holds(&self, r: &Response) -> bool {
        self.dir == Some(r.dir) && self.wpr > 0 && self.pos.len() == self.wpr * r.height
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
fn tile_floors(r: &Response, noise: &NoiseMap, floor: f64, sigmas: f64, out: &mut Vec<i32>) {
    let (nx, ny) = noise.tiles();
    out.clear();
    for t in 0..nx * ny {
        let limit = (floor as f32).max(sigmas as f32 * noise.sigma(t));
        out.push(key_floor(limit, r.scale()));
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
    let mut ns = std::mem::take(&mut s.noise);
    noise.estimate_into(resp, &mut ns);
    s.noise = ns;
    map.reset(resp, p.floor, track_sigmas);
    points_into(resp, noise, p, Some(map), out, starts, s);
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
    tile_floors(resp, noise, p.floor, p.noise_sigmas, &mut s.thr);
    let mut cand = std::mem::take(&mut s.cand);
    match map {
        Some(m) => {
            let (f, t) = (m.floor, m.sigmas);
            tile_floors(resp, noise, f, t, &mut s.track_thr);
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
    let rl = p.region_lines.max(1) as usize;
    let m = p.per_region.max(1) as usize;
    let region = |c: &Peak| -> usize {
        match resp.dir {
            ScanDir::Horizontal => usize::from(c.y) / rl,
            ScanDir::Vertical => usize::from(c.x) / rl,
        }
    };
    let nreg = match resp.dir {
        ScanDir::Horizontal => h.div_ceil(rl),
        ScanDir::Vertical => w.div_ceil(rl),
    };
    region_limits(&cand, nreg, m, region, s);
    let step = match resp.dir {
        ScanDir::Horizontal => 1,
        ScanDir::Vertical => w,
    };
    let sums = resp.sums();
    for c in &cand {
        if c.key < s.lim[region(c)] {
            continue;
        }
        let i = usize::from(c.y) * w + usize::from(c.x);
        let mag = |j: usize| f32::from(key(sums[j]));
        let d = subpixel(mag(i - step), mag(i), mag(i + step));
        let (x, y) = (f32::from(c.x), f32::from(c.y));
        let (x, y) = match resp.dir {
            ScanDir::Horizontal => (x + d, y),
            ScanDir::Vertical => (x, y + d),
        };
        out.points.push(EdgePoint {
            x,
            y,
            response: f32::from(sums[i]) * resp.scale(),
        });
        starts.push([c.x, c.y]);
    }
    s.cand = cand;
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
    let mapped = map.holds(resp);
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
    let vertical = resp.dir == ScanDir::Vertical;
    let rows = if vertical { 1..h - 1 } else { 0..h };
    if vertical {
        // The rows above and at the first: keys[0], keys[1].
        key_row(&sums[..w], &mut rb.keys[0][1..=w]);
        key_row(&sums[w..2 * w], &mut rb.keys[1][1..=w]);
    }
    for y in rows {
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
        let at = y * w;
        let row = &sums[at..at + w];
        // The signs: the row itself where the padded length stays inside
        // the response (what follows the row is never a peak: thresholds
        // are `i16::MAX` there), else a padded copy.
        let sign: &[i16] = match sums.get(at..at + wp) {
            Some(s) => s,
            None => {
                rb.sign[..w].copy_from_slice(row);
                &rb.sign
            }
        };
        let [k0, k1, k2] = &mut rb.keys;
        let keys: [&[i16]; 3] = if vertical {
            // keys[2] takes the row below; then the three turn.
            key_row(&sums[at + w..at + 2 * w], &mut k2[1..=w]);
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
        for (k, &word) in st.iter().enumerate() {
            let mut m = word;
            while m != 0 {
                let x = k * 64 + m.trailing_zeros() as usize;
                m &= m - 1;
                cand.push(Peak {
                    x: x as u16,
                    y: y as u16,
                    key: key(sums[at + x]),
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

/// `|s|` of every sum of `row` into `out` (as long), saturating: [`NONE`](super::NONE)
/// gives `i16::MAX`. Plain code the compiler vectorises (AVX2 at run time).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
fn key_row(row: &[i16], out: &mut [i16]) {
    for (k, &s) in out.iter_mut().zip(row) {
        *k = s.max(0i16.saturating_sub(s));
    }
}

/// The largest key a real sum has ([`SUM_MAX`]); `i16::MAX` is [`NONE`](super::NONE)'s.
const REAL: i16 = super::SUM_MAX as i16;

/// The peak test of one padded row, for positions `x` in `0..sign.len()`
/// (a multiple of 64): with `k = mid[x]`, position `x` is a peak along the
/// scan when `k > lo[x]`, `k ≥ hi[x]` and `k` is a real magnitude (not
/// [`NONE`](super::NONE)'s); an edge point's candidate when also `k > thr[x]`, a peak a
/// track may take when `k > trk[x]`, positive or negative by `sign[x]`.
/// `bits` gets the three masks, each `sign.len() / 64` words. Thirty-two
/// positions an iteration with AVX2 where the processor has it (`pulp`,
/// chosen at run time), else [`row_masks_plain`], the reference the tests
/// compare with.
fn row_masks(
    simd: Simd,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    bits: &mut [u64],
) {
    let n = sign.len();
    let words = n / 64;
    let ok = n % 64 == 0
        && [lo.len(), mid.len(), hi.len(), thr.len(), trk.len()]
            .iter()
            .all(|&l| l >= n)
        && bits.len() >= 3 * words;
    if !ok {
        debug_assert!(false, "row buffers not padded");
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = simd {
        simd.vectorize(
            #[inline(always)]
            || avx2_masks(simd, [lo, mid, hi], sign, thr, trk, bits),
        );
        return;
    }
    let _ = simd;
    for b in 0..n / 32 {
        let r = b * 32..b * 32 + 32;
        let m = row_masks_plain(
            [&lo[r.clone()], &mid[r.clone()], &hi[r.clone()]],
            &sign[r.clone()],
            &thr[r.clone()],
            &trk[r],
        );
        put32(bits, words, b, m);
    }
}

/// Stores the three 32-bit masks of block `b` (positions `32 b ..`) into
/// `bits` (three runs of `words` words).
#[inline(always)]
fn put32(bits: &mut [u64], words: usize, b: usize, m: [u32; 3]) {
    let (word, shift) = (b / 2, 32 * (b % 2));
    for (k, m) in m.into_iter().enumerate() {
        bits[k * words + word] |= u64::from(m) << shift;
    }
}

/// The vector unit [`row_masks`] uses: AVX2 where the processor has it
/// (asked once a pass), else none (plain code).
#[cfg(target_arch = "x86_64")]
type Simd = Option<pulp::x86::V3>;
#[cfg(not(target_arch = "x86_64"))]
type Simd = Option<()>;

/// Set to run the peak test in plain code even where AVX2 is there: for
/// measuring what the lanes save (`PLAIN=1 TIME=1 llv_count peaks`).
static PLAIN_ONLY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Runs the peak test in plain code from now on (`true`), or with AVX2
/// where the processor has it (`false`, the default): a switch for
/// benchmarks, which give the same results either way.
#[doc(hidden)]
pub fn plain_only(on: bool) {
    PLAIN_ONLY.store(on, std::sync::atomic::Ordering::Relaxed);
}

fn simd() -> Simd {
    if PLAIN_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    {
        pulp::x86::V3::try_new()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// [`row_masks`] with AVX2. (Helpers are `inline(always)` functions, not
/// closures, so that they compile inside the AVX2 context.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_masks(
    simd: pulp::x86::V3,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    bits: &mut [u64],
) {
    let a = simd.avx2;
    let n = sign.len() / 64 * 64;
    let words = n / 64;
    let (lo, mid, hi, thr, trk) = (&lo[..n], &mid[..n], &hi[..n], &thr[..n], &trk[..n]);
    let (st_bits, rest) = bits.split_at_mut(words);
    let (pos_bits, neg_bits) = rest.split_at_mut(words);
    // Two blocks of 32 a word: each word of each mask is stored once.
    let it = lo
        .chunks_exact(64)
        .zip(mid.chunks_exact(64))
        .zip(hi.chunks_exact(64))
        .zip(sign[..n].chunks_exact(64))
        .zip(thr.chunks_exact(64).zip(trk.chunks_exact(64)))
        .zip(
            st_bits
                .iter_mut()
                .zip(pos_bits.iter_mut().zip(neg_bits.iter_mut())),
        );
    for (((((l, m), h), sg), (t, tk)), (sb, (pb, nb))) in it {
        let half = |o: usize| avx2_half(a, [l, m, h], sg, t, tk, o);
        let [s0, p0, n0] = half(0);
        let [s1, p1, n1] = half(16);
        let [s2, p2, n2] = half(32);
        let [s3, p3, n3] = half(48);
        let word = |x0, x1, y0, y1| {
            u64::from(avx2_bits(a, x0, x1)) | u64::from(avx2_bits(a, y0, y1)) << 32
        };
        *sb = word(s0, s1, s2, s3);
        *pb = word(p0, p1, p2, p3);
        *nb = word(n0, n1, n2, n3);
    }
}

#[cfg(target_arch = "x86_64")]
type Avx2 = pulp::core_arch::x86::Avx2;
#[cfg(target_arch = "x86_64")]
type V = core::arch::x86_64::__m256i;

/// Sixteen `i16` from `s[o..]`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_load(s: &[i16], o: usize) -> V {
    pulp::cast(*s[o..].first_chunk::<16>().expect("16 lanes"))
}

/// The candidate, positive-track and negative-track lanes of the sixteen
/// positions from `o` of a block.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_half(
    a: Avx2,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    o: usize,
) -> [V; 3] {
    let zero: V = pulp::cast([0i16; 16]);
    let real: V = pulp::cast([REAL + 1; 16]);
    let k = avx2_load(mid, o);
    let up = a._mm256_cmpgt_epi16(k, avx2_load(lo, o));
    let down = a._mm256_cmpgt_epi16(avx2_load(hi, o), k);
    let peak = a._mm256_and_si256(
        a._mm256_andnot_si256(down, up),
        a._mm256_cmpgt_epi16(real, k),
    );
    let st = a._mm256_and_si256(peak, a._mm256_cmpgt_epi16(k, avx2_load(thr, o)));
    let tr = a._mm256_and_si256(peak, a._mm256_cmpgt_epi16(k, avx2_load(trk, o)));
    let ng = a._mm256_and_si256(tr, a._mm256_cmpgt_epi16(zero, avx2_load(sign, o)));
    [st, a._mm256_andnot_si256(ng, tr), ng]
}

/// Two halves' lanes as 32 bits in order (the pack interleaves the 128-bit
/// lanes; the permute puts them back).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_bits(a: Avx2, x: V, y: V) -> u32 {
    let p = a._mm256_permute4x64_epi64::<0b11_01_10_00>(a._mm256_packs_epi16(x, y));
    a._mm256_movemask_epi8(p) as u32
}

/// The masks of [`row_masks`] for one block of 32 positions, in plain
/// code (branch-free: no compare's outcome is guessed).
fn row_masks_plain([lo, mid, hi]: [&[i16]; 3], sign: &[i16], thr: &[i16], trk: &[i16]) -> [u32; 3] {
    let (mut st, mut pos, mut neg) = (0u32, 0u32, 0u32);
    let n = mid.len().min(32);
    let (lo, hi, sign, thr, trk) = (&lo[..n], &hi[..n], &sign[..n], &thr[..n], &trk[..n]);
    for j in 0..n {
        let k = mid[j];
        let peak = (k > lo[j]) & (k >= hi[j]) & (k <= REAL);
        let tr = peak & (k > trk[j]);
        let ng = tr & (sign[j] < 0);
        st |= u32::from(peak & (k > thr[j])) << j;
        pos |= u32::from(tr & !ng) << j;
        neg |= u32::from(ng) << j;
    }
    [st, pos, neg]
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
                });
            }
        }
    }
}

/// Per region, the smallest key kept: 0 where it has at most `m`
/// candidates, else its `m`-th largest key.
fn region_limits(
    cand: &[Peak],
    nreg: usize,
    m: usize,
    region: impl Fn(&Peak) -> usize,
    s: &mut PeakScratch,
) {
    s.count.clear();
    s.count.resize(nreg, 0);
    s.lim.clear();
    s.lim.resize(nreg, 0);
    for c in cand {
        s.count[region(c)] += 1;
    }
    if s.count.iter().all(|&c| c as usize <= m) {
        return;
    }
    // Group the keys of the crowded regions, then select in each.
    s.start.clear();
    let mut at = 0u32;
    for &c in &s.count {
        s.start.push(at);
        if c as usize > m {
            at += c;
        }
    }
    s.grouped.clear();
    s.grouped.resize(at as usize, 0);
    let mut fill = s.start.clone();
    for c in cand {
        let r = region(c);
        if s.count[r] as usize > m {
            s.grouped[fill[r] as usize] = c.key;
            fill[r] += 1;
        }
    }
    for r in 0..nreg {
        let c = s.count[r] as usize;
        if c > m {
            let g = &mut s.grouped[s.start[r] as usize..s.start[r] as usize + c];
            let (_, kth, _) = g.select_nth_unstable_by(m - 1, |a, b| b.cmp(a));
            s.lim[r] = *kth;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::GreyImage;
    use crate::llv::edges::response;

    fn params() -> EdgeParams {
        EdgeParams::default()
    }

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
        let d = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y));
        GreyImage::new(w, h, d.collect()).unwrap()
    }

    #[test]
    fn a_step_gives_one_point_a_row_and_a_flat_image_none() {
        let img = image(40, 30, |x, _| if x < 20 { 50 } else { 150 });
        let e = peaks(&response(&img, ScanDir::Horizontal, 4).unwrap(), &params());
        assert_eq!(e.points.len(), 30);
        for p in &e.points {
            assert!((p.x - 19.5).abs() < 1e-3 && p.response > 90.0, "{p:?}");
        }
        assert!(
            peaks(&response(&img, ScanDir::Vertical, 4).unwrap(), &params())
                .points
                .is_empty()
        );
        let flat = image(16, 16, |_, _| 7);
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            assert!(
                peaks(&response(&flat, dir, 4).unwrap(), &params())
                    .points
                    .is_empty()
            );
        }
    }

    #[test]
    fn m_keeps_the_strongest_of_a_region() {
        // Five steps of rising contrast along each row.
        let img = image(120, 20, |x, _| {
            let steps = [10u8, 30, 60, 100, 150, 210];
            steps[(x / 20).min(5)]
        });
        let r = response(&img, ScanDir::Horizontal, 4).unwrap();
        let mut p = params();
        p.per_region = 2;
        let e = peaks(&r, &p);
        assert_eq!(e.points.len(), 2 * 20);
        assert!(
            e.points.iter().all(|q| q.response > 45.0),
            "{:?}",
            e.points[0]
        );
        p.per_region = 8;
        assert_eq!(peaks(&r, &p).points.len(), 5 * 20);
        // Regions of ten rows: the two strongest of 50 candidates are a tie
        // of ten each.
        p.per_region = 2;
        p.region_lines = 10;
        assert_eq!(peaks(&r, &p).points.len(), 20);
    }

    #[test]
    fn vertical_points_are_in_image_order_with_subpixel_y() {
        let img = image(30, 40, |_, y| if 2 * y < 41 { 40 } else { 200 });
        let e = peaks(&response(&img, ScanDir::Vertical, 4).unwrap(), &params());
        assert_eq!(e.points.len(), 30);
        assert!(e.points.windows(2).all(|w| w[0].x < w[1].x));
        assert!(e.points.iter().all(|p| (p.y - 20.0).abs() <= 0.5));
    }

    /// The starts are the pixels of the points.
    #[test]
    fn starts_are_the_points_pixels() {
        let img = image(40, 30, |x, y| if x + y / 3 < 20 { 50 } else { 150 });
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let r = response(&img, dir, 4).unwrap();
            let (mut noise, mut out, mut starts) =
                (NoiseMap::default(), EdgePoints::default(), Starts::new());
            detect_into(
                &r,
                &params(),
                2.0,
                &mut noise,
                &mut PeakMap::default(),
                &mut out,
                &mut starts,
                &mut PeakScratch::default(),
            );
            assert_eq!(out.points.len(), starts.len());
            for (p, &[x, y]) in out.points.iter().zip(&starts) {
                assert!((p.x - f32::from(x)).abs() <= 0.5 && (p.y - f32::from(y)).abs() <= 0.5);
            }
        }
    }

    /// The lane-wise candidate test finds what the plain one does, on
    /// noise with edges, a validity mask, thresholds per tile and widths
    /// that are no multiple of sixteen.
    #[test]
    fn wide_candidates_equal_the_plain_ones() {
        use crate::llv::synth::rng::SplitMix64;
        let mut rng = SplitMix64::new(3);
        for (w, h) in [(16, 16), (37, 53), (130, 70), (200, 131)] {
            let mut img = image(w, h, |x, y| {
                let base = if x * 3 + y > w { 160.0 } else { 60.0 };
                (base + 4.0 * ((x * 7 + y * 13) % 11) as f64) as u8
            });
            let noisy: Vec<u8> = img
                .data()
                .iter()
                .map(|&v| (f64::from(v) + 6.0 * rng.gauss()).clamp(0.0, 255.0) as u8)
                .collect();
            img = GreyImage::new(w, h, noisy).unwrap();
            let mask: Vec<bool> = (0..w * h).map(|i| i % 97 != 5).collect();
            img.set_valid_mask(Some(mask)).unwrap();
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                for (a, plain) in [(4, false), (7, false), (4, true)] {
                    // (`plain`: the fallback for processors without AVX2,
                    // which other tests may meet meanwhile: the results
                    // are the same either way.)
                    plain_only(plain);
                    let r = response(&img, dir, a).unwrap();
                    let noise = NoiseMap::estimate(&r);
                    let (nx, ny) = noise.tiles();
                    let top = r
                        .sums()
                        .iter()
                        .map(|&v| i32::from(key(v)))
                        .filter(|&k| k < 32_000)
                        .max()
                        .unwrap_or(0);
                    let thr: Vec<i32> = (0..nx * ny).map(|t| top / 20 + 7 * t as i32).collect();
                    let (mut fast, mut reference) = (Vec::new(), Vec::new());
                    candidates(&r, &noise, &thr, &mut fast);
                    plain_only(false);
                    candidates_plain(&r, &noise, &thr, &mut reference);
                    // (A = 7 leaves a 16-pixel image almost no response.)
                    assert!(!reference.is_empty() || (a == 7 && w.min(h) < 20));
                    assert_eq!(fast, reference, "{w}x{h} {dir:?} A {a} plain {plain}");
                }
            }
        }
    }

    /// The peak map (made by the lane-wise pass where the machine has
    /// AVX2) holds exactly the plain test's peaks above the tracking
    /// threshold, by polarity, and its windows read them in scan order
    /// for both directions.
    #[test]
    fn the_peak_map_holds_the_plain_peaks() {
        use crate::llv::synth::rng::SplitMix64;
        let mut rng = SplitMix64::new(5);
        for (w, h) in [(16, 16), (37, 53), (130, 70), (200, 131)] {
            let mut img = image(w, h, |x, y| if x * 2 + y > w { 150 } else { 70 });
            let noisy: Vec<u8> = img
                .data()
                .iter()
                .map(|&v| (f64::from(v) + 5.0 * rng.gauss()).clamp(0.0, 255.0) as u8)
                .collect();
            img = GreyImage::new(w, h, noisy).unwrap();
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let r = response(&img, dir, 4).unwrap();
                let noise = NoiseMap::estimate(&r);
                let mut map = PeakMap::default();
                map.build_into(&r, &noise, 2.0, 1.5, &mut PeakScratch::default());
                let mut thr = Vec::new();
                tile_floors(&r, &noise, 2.0, 1.5, &mut thr);
                let mut plain = Vec::new();
                candidates_plain(&r, &noise, &thr, &mut plain);
                assert!(plain.len() > 20 || w < 20, "{w}x{h} {dir:?}");
                let (len_u, lines) = match dir {
                    ScanDir::Horizontal => (w, h),
                    ScanDir::Vertical => (h, w),
                };
                let mut found = Vec::new();
                for v in 0..lines {
                    for positive in [true, false] {
                        let mut lo = 0;
                        while lo < len_u {
                            let hi = (lo + 23).min(len_u);
                            let mut bits = map.window(positive, v, lo, hi);
                            while bits != 0 {
                                let u = lo + bits.trailing_zeros() as usize;
                                bits &= bits - 1;
                                let (x, y) = if dir == ScanDir::Vertical {
                                    (v, u)
                                } else {
                                    (u, v)
                                };
                                let i = y * w + x;
                                assert_eq!(r.sums()[i] > 0, positive);
                                found.push(i as u32);
                            }
                            lo = hi;
                        }
                    }
                }
                found.sort_unstable();
                let want: Vec<u32> = plain
                    .iter()
                    .map(|c| u32::from(c.y) * w as u32 + u32::from(c.x))
                    .collect();
                assert_eq!(found, want, "{w}x{h} {dir:?}");
            }
        }
    }

    #[test]
    fn key_floors() {
        assert_eq!(key_floor(2.0, 0.5), 4);
        assert_eq!(key_floor(0.0, 0.5), -1);
        assert_eq!(key_floor(f32::NAN, 0.5), i32::from(i16::MAX));
        assert_eq!(key_floor(2.0, 0.0), i32::from(i16::MAX));
        assert_eq!(key_floor(1e9, 0.5), i32::from(i16::MAX));
    }
}
