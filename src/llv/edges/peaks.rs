//! The peak finder (llv.md §2.3–2.5): peaks one pixel thick along the scan,
//! parabolic subpixel positions and the per-region adaptive threshold, on
//! a [`Response`] in either of its forms (`f32` values, or the kernel's
//! exact sums), with the same points bit for bit.
//!
//! Two passes instead of a list of every candidate (about one pixel in
//! thirteen on a noisy image): the first tests a word of 64 pixels at a
//! time and puts the compare's sign bits straight into one bit mask per
//! word (and a second mask of the candidates of size 3 and up, [`BIG`]),
//! then histograms those big candidates' sizes per region, counting the
//! rest in bulk; the second keeps the candidates at or above the region's
//! limit — all of them, or all big ones, or the big ones that pass a test
//! one bit at a time without a branch on the answer — and emits them. The region's
//! limit is found walking up from size 2, where it usually is, not down
//! from the largest peak. Mispredicted branches, not arithmetic, bounded
//! the older code. The straightforward former implementation is kept in
//! `reference.rs` (tests only); the tests compare both bit for bit.
//!
//! The exact form is the faster one: the test compares `i16` magnitudes
//! `|S|` sixteen at a time (`pcmpgtw`, `packsswb`, `pmovmskb` on x86-64)
//! where the `f32` form compares four, and nothing converts to `f32` but
//! the candidates. `|E| = |S| · (1/A³)` rounds monotonically and never
//! maps two sums to one value (they differ by `1/A³`, far above an `f32`
//! step at these sizes), so comparing `|S|` is comparing `|E|`; limits on
//! `|E|` (the floor, a region's limit) become the smallest `|S|` that
//! reaches them, found once a call or region.

use super::{BINS, Exact, NONE, Response};
use crate::llv::params::EdgeParams;
use crate::llv::{EdgePoint, EdgePoints, ScanDir};
use wide::{CmpEq, CmpGe, CmpGt, f32x4, i16x16};

/// Reusable buffers of the peak finder.
///
/// `hist` holds one 256-bin histogram of peak sizes per region of the
/// vertical scan (one per row region of the horizontal scan is enough); it
/// is all zeros between calls: each use clears the bins it filled.
#[derive(Clone, Debug, Default)]
pub struct PeakScratch {
    hist: Vec<u32>,
    /// Candidate bits (then kept bits) of the rows of one region
    /// (horizontal scan) or of the whole response (vertical scan), 64
    /// pixels per word, see [`candidates`].
    bits_h: Vec<Bits>,
    bits_v: Vec<Bits>,
    /// Vertical scan: per column, the lower limit of a kept peak (on `|E|`,
    /// or on `|S|` in the exact form) and the column's histogram offset.
    lim: Vec<f32>,
    lim_keys: Vec<i32>,
    offset: Vec<u32>,
    /// Vertical scan: per word of columns, those of each [`Keep`] rule.
    rules: Vec<[u64; 3]>,
}

/// The first pass's test folds "above the floor `T`" and "size ≥ 2"
/// (smaller sizes never count for the threshold, see [`limit`]) into one
/// comparison `|E| > t1`: `t1 = T` if `T ≥ 2`, else the largest `f32`
/// below 2 (so `|E| > t1 ⇔ |E| ≥ 2`). `T` is not NaN here.
fn first_pass_floor(t: f32) -> f32 {
    let below_two = f32::from_bits(2f32.to_bits() - 1);
    if t >= 2.0 { t } else { below_two }
}

/// Pixels per candidate word.
const WORD: usize = 64;

/// The candidate bits of one word: `[CAND]` every candidate, `[BIG_CAND]`
/// those of size [`BIG`] and up.
type Bits = [u64; 2];
const CAND: usize = 0;
const BIG_CAND: usize = 1;

/// Candidates of size 2, the smallest (most of them, on noise: about 60 %
/// on the bench scene), are counted in a region's total only, by popcount
/// where the region is whole words; only those of this size and up go
/// into the histogram one by one. The keep pass then needs no test at all
/// where the limit is 2 or 3 (all candidates, or all big ones: 97 % of
/// the bench scene's regions), and tests big candidates only above.
const BIG: f32 = 3.0;

/// What the peak finder reads of a response, in one of its forms: per
/// pixel a value whose magnitude orders as `|E|`.
trait Source {
    /// A pixel's value: the signed `f32` response, or the exact `|S|`.
    type T: Copy;
    /// The first pass's floor and the size [`BIG`], prepared once a call.
    type Floor: Copy;
    /// A region's limit, prepared once a region.
    type Lim: Copy;
    /// Fills a scan line shorter than a word: never a peak, and it stops
    /// its neighbours from being one.
    const PAD: Self::T;
    fn values(&self) -> &[Self::T];
    fn floor(&self, t1: f32) -> Self::Floor;
    /// The peak test (§2.3) on the 64 pixels of one word: bit `i` of
    /// `[CAND]` is set where the magnitude of `mid[i]` is above that of
    /// `lo[i]`, at least that of `hi[i]` and above the floor (see
    /// [`first_pass_floor`]), and bit `i` of `[BIG_CAND]` where, besides,
    /// `|E| ≥ BIG`; a pixel without a response (or a neighbour without
    /// one) is never a candidate.
    fn word(
        lo: &[Self::T; WORD],
        mid: &[Self::T; WORD],
        hi: &[Self::T; WORD],
        t1: Self::Floor,
    ) -> Bits;
    /// `|E|` of a value.
    fn mag(&self, v: Self::T) -> f32;
    /// The signed response `E` at index `i`.
    fn signed(&self, i: usize) -> f32;
    fn lim(&self, lim: f32) -> Self::Lim;
    /// `|E| ≥ lim` (for a value with a response).
    fn at_least(v: Self::T, lim: Self::Lim) -> bool;
    fn lims(s: &mut PeakScratch) -> &mut Vec<Self::Lim>;
}

/// The `f32` form: NaN is "no response", and compares false.
struct Float<'a>(&'a [f32]);

impl Source for Float<'_> {
    type T = f32;
    type Floor = (f32x4, f32x4);
    type Lim = f32;
    const PAD: f32 = f32::NAN;

    fn values(&self) -> &[f32] {
        self.0
    }

    fn floor(&self, t1: f32) -> (f32x4, f32x4) {
        (f32x4::splat(t1), f32x4::splat(BIG))
    }

    /// Four lanes at a time, and the compare's sign bits go straight into
    /// the word (`movmskps` on x86-64): no flag bytes to pack afterwards.
    #[inline(always)]
    fn word(lo: &[f32; WORD], mid: &[f32; WORD], hi: &[f32; WORD], t: (f32x4, f32x4)) -> Bits {
        let quad = |s: &[f32; WORD], i: usize| f32x4::from([s[i], s[i + 1], s[i + 2], s[i + 3]]);
        let test = |i: usize| {
            let e0 = quad(mid, i).abs();
            let c = e0.cmp_gt(quad(lo, i).abs()) & e0.cmp_ge(quad(hi, i).abs()) & e0.cmp_gt(t.0);
            let big = c & e0.cmp_ge(t.1);
            [c.move_mask() as u32 & 0xF, big.move_mask() as u32 & 0xF]
        };
        // Eight pixels a step: half the loop's overhead, constant shifts
        // (sixteen a step measured no better).
        let mut bits = [0u64; 2];
        for i in (0..WORD).step_by(8) {
            let (a, b) = (test(i), test(i + 4));
            for (w, (a, b)) in bits.iter_mut().zip(a.into_iter().zip(b)) {
                *w |= u64::from(a | b << 4) << i;
            }
        }
        bits
    }

    #[inline(always)]
    fn mag(&self, v: f32) -> f32 {
        v.abs()
    }

    #[inline(always)]
    fn signed(&self, i: usize) -> f32 {
        self.0[i]
    }

    fn lim(&self, lim: f32) -> f32 {
        lim
    }

    #[inline(always)]
    fn at_least(v: f32, lim: f32) -> bool {
        v.abs() >= lim
    }

    fn lims(s: &mut PeakScratch) -> &mut Vec<f32> {
        &mut s.lim
    }
}

impl Source for &Exact {
    type T = i16;
    /// The largest `|S|` at or below the floor, and below [`BIG`].
    type Floor = (i16x16, i16x16);
    /// The smallest `|S|` that reaches the limit (32 768: none does).
    type Lim = i32;
    const PAD: i16 = NONE;

    fn values(&self) -> &[i16] {
        &self.keys
    }

    fn floor(&self, t1: f32) -> (i16x16, i16x16) {
        let below = |first: i32| i16x16::splat((first - 1).min(i32::from(i16::MAX)) as i16);
        (
            below(self.first_key(t1, |e| e > t1)),
            below(self.first_key(BIG, |e| e >= BIG)),
        )
    }

    /// Sixteen lanes at a time: the compares' masks packed to bytes and
    /// their sign bits taken at once (`packsswb`, `pmovmskb` on x86-64).
    #[inline(always)]
    fn word(lo: &[i16; WORD], mid: &[i16; WORD], hi: &[i16; WORD], t: (i16x16, i16x16)) -> Bits {
        let load = |s: &[i16; WORD], i: usize| {
            i16x16::new(*s[i..].first_chunk::<16>().expect("within the word"))
        };
        let none = i16x16::splat(NONE);
        let test = |i: usize| {
            let k0 = load(mid, i);
            // `k0 ≥ hi` as "not hi > k0"; `NONE` neighbours are above any
            // `k0` but `NONE` itself, which is left out.
            let c = k0.cmp_gt(load(lo, i)) & k0.cmp_gt(t.0);
            let c = c & !(load(hi, i).cmp_gt(k0) | k0.cmp_eq(none));
            [c, c & k0.cmp_gt(t.1)]
        };
        let mut bits = [0u64; 2];
        for i in (0..WORD).step_by(16) {
            for (w, c) in bits.iter_mut().zip(test(i)) {
                *w |= u64::from(c.move_mask() as u32 & 0xFFFF) << i;
            }
        }
        bits
    }

    #[inline(always)]
    fn mag(&self, k: i16) -> f32 {
        f32::from(k) * self.scale
    }

    #[inline(always)]
    fn signed(&self, i: usize) -> f32 {
        f32::from(self.sums[i]) * self.scale
    }

    fn lim(&self, lim: f32) -> i32 {
        self.first_key(lim, |e| e >= lim)
    }

    #[inline(always)]
    fn at_least(k: i16, lim: i32) -> bool {
        i32::from(k) >= lim
    }

    fn lims(s: &mut PeakScratch) -> &mut Vec<i32> {
        &mut s.lim_keys
    }
}

impl Exact {
    /// The smallest `|S|` in `0..=32 767` whose `|E|` satisfies `reaches`
    /// (monotone in `|E|`: false, then true), or 32 768 if none does:
    /// from the guess `e / scale` for the threshold `e`, a step or two
    /// either way at most.
    fn first_key(&self, e: f32, reaches: impl Fn(f32) -> bool) -> i32 {
        let mag = |k: i32| k as f32 * self.scale;
        let top = i32::from(i16::MAX);
        // (A saturating conversion: +∞ gives `i32::MAX`.)
        let mut k = ((e / self.scale) as i32).clamp(0, top + 1);
        while k > 0 && reaches(mag(k - 1)) {
            k -= 1;
        }
        while k <= top && !reaches(mag(k)) {
            k += 1;
        }
        k
    }
}

/// The peak test over a whole scan line of `n = mid.len()` pixels (`lo`,
/// `hi` as long): bit `i % 64` of `words[i / 64]` for pixel `i`,
/// `n.div_ceil(64)` words. A last partial word is computed on the 64
/// pixels that end the line and shifted into place; a line shorter than a
/// word goes through a padded copy.
#[inline(always)]
fn candidates<S: Source>(lo: &[S::T], mid: &[S::T], hi: &[S::T], t1: S::Floor, words: &mut [Bits]) {
    let n = mid.len().min(lo.len()).min(hi.len());
    if n < WORD {
        let mut pad = [[S::PAD; WORD]; 3];
        for (p, s) in pad.iter_mut().zip([lo, mid, hi]) {
            p[..n].copy_from_slice(&s[..n]);
        }
        if let Some(w) = words.first_mut() {
            *w = S::word(&pad[0], &pad[1], &pad[2], t1);
        }
        return;
    }
    let full = n / WORD;
    for (k, w) in words.iter_mut().enumerate().take(full) {
        let at = k * WORD;
        *w = S::word(block(lo, at), block(mid, at), block(hi, at), t1);
    }
    if n % WORD != 0 {
        let at = n - WORD;
        let bits = S::word(block(lo, at), block(mid, at), block(hi, at), t1);
        if let Some(w) = words.get_mut(full) {
            *w = bits.map(|b| b >> (full * WORD - at));
        }
    }
}

/// The `WORD` values of `s` from `at` (the caller checked the length).
#[inline(always)]
fn block<T>(s: &[T], at: usize) -> &[T; WORD] {
    s[at..at + WORD].try_into().expect("a whole word")
}

/// The positions of the set bits of one word, lowest first.
#[inline(always)]
fn set_bits(mut bits: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let b = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            b
        })
    })
}

/// Calls `f(i)` for every set bit `i` of plane `plane` of `words` (bit
/// `i % 64` of word `i / 64`), in order.
#[inline(always)]
fn for_each_bit(words: &[Bits], plane: usize, mut f: impl FnMut(usize)) {
    for (k, w) in words.iter().enumerate() {
        for b in set_bits(w[plane]) {
            f(k * WORD + b);
        }
    }
}

/// The bits `i` of `bits` (word `k`) with `keep(i)`, without a branch on
/// the answer (about half the candidates tested are kept, at random).
#[inline(always)]
fn retain(bits: u64, k: usize, mut keep: impl FnMut(usize) -> bool) -> u64 {
    let mut kept = 0u64;
    for b in set_bits(bits) {
        kept |= u64::from(keep(k * WORD + b)) << b;
    }
    kept
}

/// How the keep pass treats a region with limit `lim`: keep every
/// candidate (`lim ≤ 2`: every candidate's `|E|` is at least 2, see
/// [`first_pass_floor`]), every big one (`lim` = 3 = [`BIG`]; limits are
/// whole numbers or +∞), or test the big ones.
#[derive(Clone, Copy)]
enum Keep {
    All,
    Big,
    Test,
}

/// The keep pass on one word `k` of candidate bits: the candidates of
/// the columns of rule [`Keep::All`] in `rules`, the big ones of those of
/// [`Keep::Big`], and the big ones of those of [`Keep::Test`] that pass
/// `test` (a horizontal region has one rule for every column).
#[inline(always)]
fn kept(wd: Bits, rules: &[u64; 3], k: usize, test: impl FnMut(usize) -> bool) -> u64 {
    (wd[CAND] & rules[Keep::All as usize])
        | (wd[BIG_CAND] & rules[Keep::Big as usize])
        | retain(wd[BIG_CAND] & rules[Keep::Test as usize], k, test)
}

fn keep_rule(lim: f32) -> Keep {
    if lim <= 2.0 {
        Keep::All
    } else if lim <= BIG {
        Keep::Big
    } else {
        Keep::Test
    }
}

/// The histogram bin of a peak: its size, `|E|` rounded down, at most 255.
#[inline]
fn bin(e0: f32) -> usize {
    // (A conversion to `u8` saturates itself, more cheaply than one to a
    // wider type; `min` also takes NaN to 255.)
    e0.min((BINS - 1) as f32) as u8 as usize
}

/// The bin of a region's histogram that counts its candidates: sizes 0
/// and 1 are never candidates (the first pass's test excludes them), so
/// bin 0 is free.
const TOTAL: usize = 0;

/// Counts a big candidate of size `bin` in a region's histogram (see
/// [`limit`]).
#[inline(always)]
fn count_big(hist: &mut [u32], bin: usize) {
    hist[1] += 1;
    hist[bin] += 1;
}

/// A region's lower limit on `|E|` for a kept peak, per llv.md §2.5, from
/// its histogram: the number of candidates in bin [`TOTAL`], the number
/// of big ones in bin 1 (free, like bin 0) and the count of each big size
/// in its bin (size 2 gets the rest); clears the histogram.
///
/// The rule walks a threshold `th` down from the largest size `tmax`,
/// adding each bin's count, until `M` candidates are above it or it reaches
/// 1; a peak is kept when its size `⌊|E|⌋ > th`, i.e. `|E| ≥ th + 1` (`th`
/// is a whole number), which is what the second pass compares, without
/// rounding. So the limit is the largest size `v` (2 to `tmax`) with at
/// least `M` candidates of size `≥ v`, or 2 if there is none. That is
/// found here walking up from 2, subtracting the bins below `v` from the
/// total: the limit is near the noise level, far below `tmax`, so this is
/// the short way. With `M = 0` the rule keeps nothing below `tmax + 1`
/// (sizes are clamped at 255, so a huge `|E|` may still pass); with no
/// candidate the limit is +∞.
fn limit(hist: &mut [u32], m: u32) -> f32 {
    let Some(hist) = hist.first_chunk_mut::<BINS>() else {
        return f32::INFINITY;
    };
    let n = hist[TOTAL];
    if n == 0 {
        return f32::INFINITY;
    }
    hist[2] += n - hist[1];
    hist[TOTAL] = 0;
    hist[1] = 0;
    let lim = if m == 0 {
        hist.iter()
            .rposition(|&c| c != 0)
            .map_or(2, |tmax| tmax + 1)
    } else if n < m {
        2
    } else {
        let mut v = 2;
        let mut below = 0;
        while v < BINS - 1 && n - (below + hist[v]) >= m {
            below += hist[v];
            v += 1;
        }
        v
    };
    *hist = [0; BINS];
    lim as f32
}

/// Parabolic subpixel offset through `|E|` at a peak and its two neighbours,
/// clamped to ±0.5 (llv.md §2.4).
#[inline]
fn subpixel(em: f32, e0: f32, ep: f32) -> f32 {
    let den = 2.0 * (em - 2.0 * e0 + ep);
    if den < 0.0 {
        ((em - ep) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Peaks of a response with subpixel positions and the per-region adaptive
/// threshold (llv.md §2.3–2.5), in lexical order.
///
/// Settled details:
/// - a peak needs both neighbours along the scan to have a response, so no
///   edge is reported at the border of the valid area;
/// - a region is `region_lines` consecutive scan lines (rows for
///   `Horizontal`, columns for `Vertical`);
/// - "size" is `|E|` rounded down to whole grey levels; a candidate is kept
///   when its size is above the region's threshold and `|E| > T`.
pub fn peaks(resp: &Response, p: &EdgeParams) -> EdgePoints {
    let mut out = EdgePoints::default();
    peaks_into(resp, p, &mut out, &mut PeakScratch::default());
    out
}

/// [`peaks`] into reusable buffers (see the module doc for how).
pub fn peaks_into(resp: &Response, p: &EdgeParams, out: &mut EdgePoints, s: &mut PeakScratch) {
    let (w, h) = (resp.width, resp.height);
    out.dir = Some(resp.dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    if w < 3 || h < 3 || !resp.covers(w, h) {
        return;
    }
    let t = p.floor as f32;
    if t.is_nan() {
        // No `|E| > T` holds: no peak at all.
        return;
    }
    let t1 = first_pass_floor(t);
    let r = p.region_lines.max(1) as usize;
    let m = p.per_region;
    let params = Region { w, h, r, m };
    match (resp.dir, resp.is_exact()) {
        (ScanDir::Horizontal, false) => peaks_h(&Float(&resp.data), t1, params, out, s),
        (ScanDir::Vertical, false) => peaks_v(&Float(&resp.data), t1, params, out, s),
        (ScanDir::Horizontal, true) => peaks_h(&&resp.exact, t1, params, out, s),
        (ScanDir::Vertical, true) => peaks_v(&&resp.exact, t1, params, out, s),
    }
}

/// The size of the response and the adaptive threshold's parameters.
#[derive(Clone, Copy)]
struct Region {
    w: usize,
    h: usize,
    /// Scan lines per region.
    r: usize,
    /// `M`.
    m: u32,
}

fn peaks_h<S: Source>(src: &S, t1: f32, p: Region, out: &mut EdgePoints, s: &mut PeakScratch) {
    let Region { w, h, r, m } = p;
    if s.hist.len() < BINS {
        s.hist.clear();
        s.hist.resize(BINS, 0);
    }
    let hist = &mut s.hist[..BINS];
    let t1 = src.floor(t1);
    // Bit i of a row's words is the pixel x = i + 1 (the test needs both
    // neighbours).
    let nw = (w - 2).div_ceil(WORD);
    let rows = r.min(h);
    if s.bits_h.len() != rows * nw {
        s.bits_h.clear();
        s.bits_h.resize(rows * nw, [0; 2]);
    }
    for (g, region) in src.values().chunks(w * r).enumerate() {
        for (row, words) in region.chunks_exact(w).zip(s.bits_h.chunks_exact_mut(nw)) {
            let mid = &row[1..w - 1];
            candidates::<S>(&row[..w - 2], mid, &row[2..], t1, words);
            for wd in words.iter() {
                hist[TOTAL] += wd[CAND].count_ones();
                hist[1] += wd[BIG_CAND].count_ones();
            }
            for_each_bit(words, BIG_CAND, |i| hist[bin(src.mag(mid[i]))] += 1);
        }
        let lim = limit(hist, m);
        if lim == f32::INFINITY {
            continue;
        }
        let mut rules = [0; 3];
        rules[keep_rule(lim) as usize] = !0;
        let lim = src.lim(lim);
        for (k, (row, words)) in region
            .chunks_exact(w)
            .zip(s.bits_h.chunks_exact_mut(nw))
            .enumerate()
        {
            let y = g * r + k;
            for (j, wd) in words.iter_mut().enumerate() {
                wd[CAND] = kept(*wd, &rules, j, |i| S::at_least(row[i + 1], lim));
            }
            for_each_bit(words, CAND, |i| {
                let x = i + 1;
                let (em, e0, ep) = (src.mag(row[x - 1]), src.mag(row[x]), src.mag(row[x + 1]));
                out.points.push(EdgePoint {
                    x: x as f32 + subpixel(em, e0, ep),
                    y: y as f32,
                    response: src.signed(y * w + x),
                });
            });
        }
    }
}

/// Rows `y - 1`, `y`, `y + 1` of a `w`-wide image (`1 ≤ y`, `y + 1` a row).
#[inline(always)]
fn around<T>(data: &[T], w: usize, y: usize) -> [&[T]; 3] {
    [y - 1, y, y + 1].map(|r| &data[r * w..(r + 1) * w])
}

fn peaks_v<S: Source>(src: &S, t1: f32, p: Region, out: &mut EdgePoints, s: &mut PeakScratch) {
    let Region { w, h, r, m } = p;
    let nreg = w.div_ceil(r);
    if s.hist.len() != nreg * BINS {
        s.hist.clear();
        s.hist.resize(nreg * BINS, 0);
    }
    debug_assert!(s.hist.iter().all(|&n| n == 0), "histograms left dirty");
    let t1 = src.floor(t1);
    let nw = w.div_ceil(WORD);
    s.offset.clear();
    s.offset.extend((0..w).map(|x| ((x / r) * BINS) as u32));
    // One row of words per response row (the first and last are unused);
    // the first pass writes every word it reads later.
    if s.bits_v.len() != nw * h {
        s.bits_v.clear();
        s.bits_v.resize(nw * h, [0; 2]);
    }
    let data = src.values();
    let mut word_rows = s.bits_v.chunks_exact_mut(nw);
    word_rows.next();
    for (y, words) in (1..h - 1).zip(&mut word_rows) {
        let [up, row, dn] = around(data, w, y);
        candidates::<S>(up, row, dn, t1, words);
        let (hist, offset) = (&mut s.hist, &s.offset);
        for_each_bit(words, CAND, |x| hist[offset[x] as usize + TOTAL] += 1);
        for_each_bit(words, BIG_CAND, |x| {
            let o = offset[x] as usize;
            count_big(&mut hist[o..o + BINS], bin(src.mag(row[x])));
        });
    }
    // Per column, its region's limit (as `S` compares it) and, per word,
    // the columns of each keep rule.
    let mut lims = std::mem::take(S::lims(s));
    lims.clear();
    s.rules.clear();
    s.rules.resize(nw, [0; 3]);
    for (g, hist) in s.hist.chunks_exact_mut(BINS).enumerate() {
        let l = limit(hist, m);
        let rule = keep_rule(l) as usize;
        let l = src.lim(l);
        for x in g * r..(g * r + r).min(w) {
            lims.push(l);
            s.rules[x / WORD][rule] |= 1 << (x % WORD);
        }
    }
    let mut word_rows = s.bits_v.chunks_exact_mut(nw);
    word_rows.next();
    for (y, words) in (1..h - 1).zip(&mut word_rows) {
        let [up, row, dn] = around(data, w, y);
        for (k, (wd, rules)) in words.iter_mut().zip(&s.rules).enumerate() {
            wd[CAND] = kept(*wd, rules, k, |x| S::at_least(row[x], lims[x]));
        }
        let yf = y as f32;
        for_each_bit(words, CAND, |x| {
            let (em, e0, ep) = (src.mag(up[x]), src.mag(row[x]), src.mag(dn[x]));
            out.points.push(EdgePoint {
                x: x as f32,
                y: yf + subpixel(em, e0, ep),
                response: src.signed(y * w + x),
            });
        });
    }
    *S::lims(s) = lims;
}
