//! Lee's one-dimensional edge detector (llv.md §2): the kernel, the signed
//! convolution along one scan direction, peaks one pixel thick along the
//! scan, parabolic subpixel positions and the per-region adaptive threshold.
//!
//! Exactness: the kernel is applied with integer coefficients (`φ'(t)·A³`
//! is a whole number), so every sum of 8-bit pixels is exact (in integer
//! lanes, `edges/row.rs`) and the response is rounded once, when it is scaled by
//! `1/A³`.
//!
//! Speed: the peak finder makes two passes instead of listing every
//! candidate (about one pixel in thirteen on a noisy image): the first
//! tests four pixels at a time and puts the compare's sign bits straight
//! into one bit mask per 64 pixels (through `wide`, `movmskps` on x86-64),
//! then histograms the candidates' sizes per region; the second keeps the
//! candidates at or above the region's limit, one bit at a time without a
//! branch on the answer, and emits the kept ones. The region's limit is
//! found walking up from size 2, where it usually is, not down from the
//! largest peak. Mispredicted branches, not arithmetic, bounded the older
//! code. The straightforward former implementation is kept in
//! `edges/reference.rs` (tests only); the tests compare both bit for bit.
//!
//! Layout: a [`Response`] is always stored in image order, `data[y·w + x]`,
//! for both scan directions. The vertical convolution and the vertical peak
//! test then run over whole rows (contiguous, vectorisable) instead of
//! striding down columns, so no transposed copy is needed.

use super::image::GreyImage;
use super::params::EdgeParams;
use super::{EdgePoint, EdgePoints, LlvError, ScanDir};
use wide::{CmpGe, CmpGt, f32x4};

#[cfg(test)]
mod reference;
pub(crate) mod row;

/// The largest bin of the peak-size histogram (responses are below 255).
const BINS: usize = 256;

/// The Lee kernel `φ'(t)` for `t = -A..=A` (index `t + A`), in `f32`.
/// It sums to zero and a unit step gives a peak of `1 - 1/A²`.
pub fn kernel(a: usize) -> Vec<f32> {
    let s = 1.0 / (a * a * a) as f64;
    integer_kernel(a)
        .into_iter()
        .map(|k| (k as f64 * s) as f32)
        .collect()
}

/// `φ'(t) · A³` for `t = -A..=A`: whole numbers.
fn integer_kernel(a: usize) -> Vec<i32> {
    let a = a as i32;
    (-a..=a)
        .map(|t| {
            if t <= 0 {
                -6 * t * (t + a)
            } else {
                6 * t * (t - a)
            }
        })
        .collect()
}

/// A signed edge response along one scan direction, in grey levels, stored
/// in image order (`data[y * width + x]`). NaN marks "no response": within
/// `A` pixels of the border along the scan or of an invalid pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    pub width: usize,
    pub height: usize,
    pub dir: ScanDir,
    pub data: Vec<f32>,
}

impl Default for Response {
    /// An empty horizontal response (a buffer to fill with [`response_into`]).
    fn default() -> Self {
        Response {
            width: 0,
            height: 0,
            dir: ScanDir::Horizontal,
            data: Vec::new(),
        }
    }
}

impl Response {
    /// Sets the size and direction for a fill that writes every value it
    /// needs; the buffer is only (re)allocated, as NaN, when the pixel count
    /// changes, so a warm buffer is reused as it is.
    pub(crate) fn reshape(&mut self, w: usize, h: usize, dir: ScanDir) {
        self.width = w;
        self.height = h;
        self.dir = dir;
        if self.data.len() != w * h {
            self.data.clear();
            self.data.resize(w * h, f32::NAN);
        }
    }

    /// The response at `(x, y)`; `None` outside the image or where NaN.
    pub fn get(&self, x: usize, y: usize) -> Option<f32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.data
            .get(y * self.width + x)
            .copied()
            .filter(|v| !v.is_nan())
    }
}

fn check_half_width(a: usize) -> Result<(), LlvError> {
    if !(3..=7).contains(&a) {
        return Err(LlvError::Param {
            name: "edges.half_width",
            value: a as f64,
            range: "3 to 7",
        });
    }
    Ok(())
}

/// The Lee response of `img` along `dir` with half-width `a` (3–7).
pub fn response(img: &GreyImage, dir: ScanDir, a: usize) -> Result<Response, LlvError> {
    let mut out = Response::default();
    response_into(img, dir, a, &mut out, &mut ResponseScratch::default())?;
    Ok(out)
}

/// Reusable buffers of [`response_into`].
#[derive(Clone, Debug, Default)]
pub struct ResponseScratch {
    /// Invalid-pixel counts (images with a validity mask).
    counts: Vec<u32>,
}

/// [`response`] into reusable buffers.
///
/// Each row goes through the shared row kernel (`row::lee_row`): the
/// antisymmetry of the kernel halves the work,
/// `E(x) = Σ_{s=1..A} c_s (Img(x+s) - Img(x-s))` with `c_s = 6 s (A-s)`
/// (then scaled by `1/A³`); the sums are of whole numbers, exact in
/// integer lanes. Every output is written exactly once (NaN outside the
/// valid band), with no fill pass before.
pub fn response_into(
    img: &GreyImage,
    dir: ScanDir,
    a: usize,
    out: &mut Response,
    scratch: &mut ResponseScratch,
) -> Result<(), LlvError> {
    check_half_width(a)?;
    img.check_stage_size()?;
    let (w, h) = img.size();
    let px = img.data();
    if px.len() != w * h {
        return Err(LlvError::BufferSize {
            width: w,
            height: h,
            expected: w * h,
            actual: px.len(),
        });
    }
    out.reshape(w, h, dir);
    match dir {
        ScanDir::Horizontal => {
            for (row, orow) in px.chunks_exact(w).zip(out.data.chunks_exact_mut(w)) {
                if w > 2 * a {
                    orow[..a].fill(f32::NAN);
                    orow[w - a..].fill(f32::NAN);
                    row::lee_row(&row::Taps::horizontal(row, a), a, &mut orow[a..w - a]);
                } else {
                    orow.fill(f32::NAN);
                }
            }
        }
        ScanDir::Vertical => {
            for (y, orow) in out.data.chunks_exact_mut(w).enumerate() {
                if y >= a && y + a < h {
                    row::lee_row(&row::Taps::vertical(px, w, y, a), a, orow);
                } else {
                    orow.fill(f32::NAN);
                }
            }
        }
    }
    if let Some(mask) = img.valid_mask() {
        mask_invalid(mask, w, h, dir, a, &mut out.data, &mut scratch.counts);
    }
    Ok(())
}

/// Sets NaN wherever the kernel window touches an invalid pixel.
fn mask_invalid(
    mask: &[bool],
    w: usize,
    h: usize,
    dir: ScanDir,
    a: usize,
    data: &mut [f32],
    counts: &mut Vec<u32>,
) {
    match dir {
        ScanDir::Horizontal => {
            counts.clear();
            counts.resize(w + 1, 0);
            for (mrow, drow) in mask.chunks_exact(w).zip(data.chunks_exact_mut(w)) {
                if mrow.iter().all(|&v| v) {
                    continue;
                }
                // Prefix counts of invalid pixels in the row.
                for x in 0..w {
                    counts[x + 1] = counts[x] + u32::from(!mrow[x]);
                }
                for (x, d) in drow.iter_mut().enumerate() {
                    let lo = x.saturating_sub(a);
                    let hi = (x + a + 1).min(w);
                    if counts[hi] != counts[lo] {
                        *d = f32::NAN;
                    }
                }
            }
        }
        ScanDir::Vertical => {
            // Per column, the number of invalid pixels in rows y-A..=y+A.
            counts.clear();
            counts.resize(w, 0);
            // Branch-free (selects), so every row's update vectorises.
            let add = |counts: &mut [u32], y: usize, sign: bool| {
                let mrow = &mask[y * w..(y + 1) * w];
                if sign {
                    for (c, &m) in counts.iter_mut().zip(mrow) {
                        *c += u32::from(!m);
                    }
                } else {
                    for (c, &m) in counts.iter_mut().zip(mrow) {
                        *c -= u32::from(!m);
                    }
                }
            };
            for y in 0..a.min(h) {
                add(counts, y, true);
            }
            for y in 0..h {
                if y + a < h {
                    add(counts, y + a, true);
                }
                if y > a {
                    add(counts, y - a - 1, false);
                }
                for (d, &c) in data[y * w..(y + 1) * w].iter_mut().zip(counts.iter()) {
                    *d = if c != 0 { f32::NAN } else { *d };
                }
            }
        }
    }
}

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
    bits_h: Vec<u64>,
    bits_v: Vec<u64>,
    /// Vertical scan: per column, the lower limit on `|E|` of a kept peak
    /// and the column's histogram offset.
    lim: Vec<f32>,
    offset: Vec<u32>,
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

/// The peak test (§2.3) on the 64 pixels of one word: bit `i` is set where
/// `|mid[i]|` is above `|lo[i]|`, at least `|hi[i]|` and above `t1` (see
/// [`first_pass_floor`]); NaN compares false. Four lanes at a time, and
/// the compare's sign bits go straight into the word (`movmskps` on
/// x86-64): no flag bytes to pack afterwards.
#[inline(always)]
fn candidate_word(lo: &[f32; WORD], mid: &[f32; WORD], hi: &[f32; WORD], t1: f32x4) -> u64 {
    let quad = |s: &[f32; WORD], i: usize| f32x4::from([s[i], s[i + 1], s[i + 2], s[i + 3]]);
    let test = |i: usize| {
        let e0 = quad(mid, i).abs();
        let c = e0.cmp_gt(quad(lo, i).abs()) & e0.cmp_ge(quad(hi, i).abs()) & e0.cmp_gt(t1);
        c.move_mask() as u32 & 0xF
    };
    // Eight pixels a step: half the loop's overhead, constant shifts
    // (sixteen a step measured no better).
    let mut bits = 0u64;
    for i in (0..WORD).step_by(8) {
        bits |= u64::from(test(i) | test(i + 4) << 4) << i;
    }
    bits
}

/// [`candidate_word`] over a whole scan line of `n = mid.len()` pixels
/// (`lo`, `hi` as long): bit `i % 64` of `words[i / 64]` for pixel `i`,
/// `n.div_ceil(64)` words. A last partial word is computed on the 64 pixels
/// that end the line and shifted into place; a line shorter than a word
/// goes through a copy padded with NaN.
#[inline(always)]
fn candidates(lo: &[f32], mid: &[f32], hi: &[f32], t1: f32, words: &mut [u64]) {
    let n = mid.len().min(lo.len()).min(hi.len());
    let t1 = f32x4::splat(t1);
    if n < WORD {
        let mut pad = [[f32::NAN; WORD]; 3];
        for (p, s) in pad.iter_mut().zip([lo, mid, hi]) {
            p[..n].copy_from_slice(&s[..n]);
        }
        if let Some(w) = words.first_mut() {
            *w = candidate_word(&pad[0], &pad[1], &pad[2], t1);
        }
        return;
    }
    let full = n / WORD;
    for (k, w) in words.iter_mut().enumerate().take(full) {
        let at = k * WORD;
        *w = candidate_word(block(lo, at), block(mid, at), block(hi, at), t1);
    }
    if n % WORD != 0 {
        let at = n - WORD;
        let bits = candidate_word(block(lo, at), block(mid, at), block(hi, at), t1);
        if let Some(w) = words.get_mut(full) {
            *w = bits >> (full * WORD - at);
        }
    }
}

/// The `WORD` values of `s` from `at` (the caller checked the length).
#[inline(always)]
fn block(s: &[f32], at: usize) -> &[f32; WORD] {
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

/// Calls `f(i)` for every set bit `i` of `words` (bit `i % 64` of word
/// `i / 64`), in order.
#[inline(always)]
fn for_each_bit(words: &[u64], mut f: impl FnMut(usize)) {
    for (k, &w) in words.iter().enumerate() {
        for b in set_bits(w) {
            f(k * WORD + b);
        }
    }
}

/// The second pass: keeps the candidate bits `i` with `keep(i)`, without a
/// branch on the answer (about half the candidates are kept, at random).
#[inline(always)]
fn retain_bits(words: &mut [u64], mut keep: impl FnMut(usize) -> bool) {
    for (k, w) in words.iter_mut().enumerate() {
        let mut kept = 0u64;
        for b in set_bits(*w) {
            kept |= u64::from(keep(k * WORD + b)) << b;
        }
        *w = kept;
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

/// Counts a candidate of size `bin` in a region's histogram.
#[inline(always)]
fn count(hist: &mut [u32], bin: usize) {
    hist[TOTAL] += 1;
    hist[bin] += 1;
}

/// A region's lower limit on `|E|` for a kept peak, from the histogram of
/// its candidate sizes (≥ 2, with their number in bin [`TOTAL`]), per
/// llv.md §2.5; clears the histogram.
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
    hist[TOTAL] = 0;
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

/// [`peaks`] into reusable buffers.
///
/// Two passes instead of a list of every candidate: the first marks the
/// candidates in bit masks and histograms their sizes per region (for a
/// horizontal scan, region by region while its rows are in the first-level
/// cache), the second keeps the marked candidates at or above the region's
/// limit and emits them, in lexical order.
pub fn peaks_into(resp: &Response, p: &EdgeParams, out: &mut EdgePoints, s: &mut PeakScratch) {
    let (w, h) = (resp.width, resp.height);
    out.dir = Some(resp.dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    if w < 3 || h < 3 || resp.data.len() != w.saturating_mul(h) {
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
    match resp.dir {
        ScanDir::Horizontal => peaks_h(resp, t1, r, m, out, s),
        ScanDir::Vertical => peaks_v(resp, t1, r, m, out, s),
    }
}

fn peaks_h(resp: &Response, t1: f32, r: usize, m: u32, out: &mut EdgePoints, s: &mut PeakScratch) {
    let w = resp.width;
    if s.hist.len() < BINS {
        s.hist.clear();
        s.hist.resize(BINS, 0);
    }
    let hist = &mut s.hist[..BINS];
    // Bit i of a row's words is the pixel x = i + 1 (the test needs both
    // neighbours).
    let nw = (w - 2).div_ceil(WORD);
    let rows = r.min(resp.height);
    if s.bits_h.len() != rows * nw {
        s.bits_h.clear();
        s.bits_h.resize(rows * nw, 0);
    }
    for (g, region) in resp.data.chunks(w * r).enumerate() {
        for (row, words) in region.chunks_exact(w).zip(s.bits_h.chunks_exact_mut(nw)) {
            let mid = &row[1..w - 1];
            candidates(&row[..w - 2], mid, &row[2..], t1, words);
            for_each_bit(words, |i| count(hist, bin(mid[i].abs())));
        }
        let lim = limit(hist, m);
        if lim == f32::INFINITY {
            continue;
        }
        for (k, (row, words)) in region
            .chunks_exact(w)
            .zip(s.bits_h.chunks_exact_mut(nw))
            .enumerate()
        {
            let y = (g * r + k) as f32;
            retain_bits(words, |i| row[i + 1].abs() >= lim);
            for_each_bit(words, |i| {
                let x = i + 1;
                let (em, e0, ep) = (row[x - 1].abs(), row[x].abs(), row[x + 1].abs());
                out.points.push(EdgePoint {
                    x: x as f32 + subpixel(em, e0, ep),
                    y,
                    response: row[x],
                });
            });
        }
    }
}

fn peaks_v(resp: &Response, t1: f32, r: usize, m: u32, out: &mut EdgePoints, s: &mut PeakScratch) {
    let (w, h) = (resp.width, resp.height);
    let nreg = w.div_ceil(r);
    if s.hist.len() != nreg * BINS {
        s.hist.clear();
        s.hist.resize(nreg * BINS, 0);
    }
    debug_assert!(s.hist.iter().all(|&n| n == 0), "histograms left dirty");
    let nw = w.div_ceil(WORD);
    s.offset.clear();
    s.offset.extend((0..w).map(|x| ((x / r) * BINS) as u32));
    // One row of words per response row (the first and last are unused);
    // the first pass writes every word it reads later.
    if s.bits_v.len() != nw * h {
        s.bits_v.clear();
        s.bits_v.resize(nw * h, 0);
    }
    let (hist, offset) = (&mut s.hist, &s.offset);
    let data = &resp.data;
    let mut word_rows = s.bits_v.chunks_exact_mut(nw);
    word_rows.next();
    for (y, words) in (1..h - 1).zip(&mut word_rows) {
        let up = &data[(y - 1) * w..y * w];
        let row = &data[y * w..(y + 1) * w];
        let dn = &data[(y + 1) * w..(y + 2) * w];
        candidates(up, row, dn, t1, words);
        for_each_bit(words, |x| {
            let o = offset[x] as usize;
            count(&mut hist[o..o + BINS], bin(row[x].abs()));
        });
    }
    s.lim.clear();
    for (g, hist) in hist.chunks_exact_mut(BINS).enumerate() {
        let l = limit(hist, m);
        s.lim.extend(std::iter::repeat_n(l, r.min(w - g * r)));
    }
    let lim = &s.lim;
    let mut word_rows = s.bits_v.chunks_exact_mut(nw);
    word_rows.next();
    for (y, words) in (1..h - 1).zip(&mut word_rows) {
        let up = &data[(y - 1) * w..y * w];
        let row = &data[y * w..(y + 1) * w];
        let dn = &data[(y + 1) * w..(y + 2) * w];
        retain_bits(words, |x| row[x].abs() >= lim[x]);
        let yf = y as f32;
        for_each_bit(words, |x| {
            let (em, e0, ep) = (up[x].abs(), row[x].abs(), dn[x].abs());
            out.points.push(EdgePoint {
                x: x as f32,
                y: yf + subpixel(em, e0, ep),
                response: row[x],
            });
        });
    }
}

/// Response and peaks of one image along `dir`.
pub fn detect(img: &GreyImage, dir: ScanDir, p: &EdgeParams) -> Result<EdgePoints, LlvError> {
    let a = p.half_width as usize;
    let r = response(img, dir, a)?;
    Ok(peaks(&r, p))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::synth::rng::SplitMix64;

    fn img_from(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
        let mut d = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                d.push(f(x, y));
            }
        }
        GreyImage::new(w, h, d).unwrap()
    }

    /// A random scene: a few steps of random height and direction, noise of
    /// random amplitude, optionally a validity mask with random invalid
    /// blobs and a few scattered invalid pixels.
    fn random_image(rng: &mut SplitMix64, w: usize, h: usize, masked: bool) -> GreyImage {
        let (x0, y0) = (
            (rng.next_u64() % w as u64) as i64,
            (rng.next_u64() % h as u64) as i64,
        );
        let (lv0, lv1, lv2) = (
            rng.next_u64() % 256,
            rng.next_u64() % 256,
            rng.next_u64() % 256,
        );
        let noise = 1 + rng.next_u64() % 40;
        let mut img = img_from(w, h, |x, y| {
            let (x, y) = (x as i64, y as i64);
            let base = if x + y / 3 < x0 {
                lv0
            } else if y - x / 2 < y0 {
                lv1
            } else {
                lv2
            };
            let n = rng_at(x as u64, y as u64, noise);
            (base as i64 + n).clamp(0, 255) as u8
        });
        if masked {
            let mut mask = vec![true; w * h];
            for _ in 0..3 {
                let (cx, cy) = (rng.next_u64() % w as u64, rng.next_u64() % h as u64);
                let rad = 1 + rng.next_u64() % 6;
                for y in 0..h as u64 {
                    for x in 0..w as u64 {
                        if x.abs_diff(cx).pow(2) + y.abs_diff(cy).pow(2) <= rad * rad {
                            mask[(y * w as u64 + x) as usize] = false;
                        }
                    }
                }
            }
            for _ in 0..4 {
                mask[(rng.next_u64() % (w * h) as u64) as usize] = false;
            }
            img.set_valid_mask(Some(mask)).unwrap();
        }
        img
    }

    /// Deterministic noise in `-amp..=amp` at a pixel.
    fn rng_at(x: u64, y: u64, amp: u64) -> i64 {
        let mut r = SplitMix64::new((x << 32 | y) ^ 0x9E37_79B9_7F4A_7C15);
        r.next_u64();
        (r.next_u64() % (2 * amp + 1)) as i64 - amp as i64
    }

    fn same_bits(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(u, v)| u.to_bits() == v.to_bits() || (u.is_nan() && v.is_nan()))
    }

    /// Same header and the same points, bit for bit, in the same order.
    fn same_points(a: &EdgePoints, b: &EdgePoints) -> bool {
        let bits = |p: &EdgePoint| (p.x.to_bits(), p.y.to_bits(), p.response.to_bits());
        (a.dir, a.width, a.height) == (b.dir, b.width, b.height)
            && a.points.iter().map(bits).eq(b.points.iter().map(bits))
    }

    #[test]
    fn fast_responses_equal_the_reference_bit_for_bit() {
        let mut rng = SplitMix64::new(0x1234_5678_9ABC_DEF1);
        let (mut fast, mut slow) = (Response::default(), Response::default());
        let (mut fs, mut ss) = (
            ResponseScratch::default(),
            reference::ResponseScratch::default(),
        );
        for (w, h) in [(16, 16), (37, 53), (130, 17), (17, 130), (64, 40)] {
            for masked in [false, true] {
                let img = random_image(&mut rng, w, h, masked);
                for a in 3..=7 {
                    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                        response_into(&img, dir, a, &mut fast, &mut fs).unwrap();
                        reference::response_into(&img, dir, a, &mut slow, &mut ss).unwrap();
                        assert_eq!((fast.width, fast.height, fast.dir), (w, h, dir));
                        assert!(
                            same_bits(&fast.data, &slow.data),
                            "{w}x{h} masked={masked} a={a} {dir:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn fast_peaks_equal_the_reference_point_for_point() {
        let mut rng = SplitMix64::new(0xDEAD_BEEF_0BAD_F00D);
        let mut resp = Response::default();
        let mut rs = ResponseScratch::default();
        let (mut fast, mut slow) = (EdgePoints::default(), EdgePoints::default());
        let (mut fs, mut ss) = (PeakScratch::default(), reference::PeakScratch::default());
        let mut kept = 0;
        // Scan lines shorter than a word, of whole words, and with a
        // partial last word, in both directions.
        for (w, h) in [
            (16, 16),
            (37, 53),
            (130, 17),
            (17, 130),
            (96, 80),
            (66, 70),
            (200, 23),
        ] {
            for masked in [false, true] {
                let img = random_image(&mut rng, w, h, masked);
                for a in 3..=7 {
                    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                        response_into(&img, dir, a, &mut resp, &mut rs).unwrap();
                        for (floor, m, r) in [
                            (2.0, 8, 1),
                            (0.0, 1, 1),
                            (0.0, 8, 3),
                            (5.5, 3, 2),
                            (1.0, 50, 7),
                            (2.0, 4096, 1),
                            (0.5, 2, 4096),
                            (2.0, 0, 1),
                        ] {
                            let p = EdgeParams {
                                half_width: a as u32,
                                floor,
                                per_region: m,
                                region_lines: r,
                                ..EdgeParams::default()
                            };
                            // The fast path's scratch is shared across sizes,
                            // directions and parameters, as in the pipeline.
                            peaks_into(&resp, &p, &mut fast, &mut fs);
                            reference::peaks_into(&resp, &p, &mut slow, &mut ss);
                            assert!(
                                same_points(&fast, &slow),
                                "{w}x{h} masked={masked} a={a} {dir:?} T={floor} M={m} r={r}"
                            );
                            kept += fast.points.len();
                        }
                    }
                }
            }
        }
        assert!(kept > 10_000, "the cases keep points: {kept}");
    }

    #[test]
    fn peaks_of_unusual_responses_equal_the_reference() {
        // Hand-made responses: sizes 0 and 1 only, huge values, infinities,
        // NaN holes, ties.
        let (w, h) = (23, 19);
        let mut rng = SplitMix64::new(42);
        let cases: [&dyn Fn(&mut SplitMix64) -> f32; 4] = [
            &|r| (r.next_u64() % 200) as f32 / 100.0,
            &|r| {
                [
                    1.5,
                    0.0,
                    f32::NAN,
                    300.0,
                    -1e9,
                    2.0,
                    2.0,
                    256.0,
                    -255.5,
                    256.0,
                ][(r.next_u64() % 10) as usize]
            },
            &|r| [f32::INFINITY, 5.0, -3.0, 4.99][(r.next_u64() % 4) as usize],
            &|r| (r.next_u64() % 7) as f32 - 3.0,
        ];
        for f in cases {
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let data = (0..w * h).map(|_| f(&mut rng)).collect();
                let resp = Response {
                    width: w,
                    height: h,
                    dir,
                    data,
                };
                for (floor, m, r) in [(0.0, 1, 1), (2.0, 3, 2), (0.0, 0, 1)] {
                    let p = EdgeParams {
                        floor,
                        per_region: m,
                        region_lines: r,
                        ..EdgeParams::default()
                    };
                    let fast = peaks(&resp, &p);
                    let slow = reference::peaks(&resp, &p);
                    assert!(same_points(&fast, &slow), "{dir:?} T={floor} M={m} r={r}");
                }
            }
        }
    }

    #[test]
    fn kernel_sums_to_zero_and_step_gives_one_minus_inverse_square() {
        for a in 3..=7 {
            let k = kernel(a);
            assert_eq!(k.len(), 2 * a + 1);
            let sum: f64 = k.iter().map(|&v| v as f64).sum();
            assert!(sum.abs() < 1e-6, "A={a}: sum {sum}");
            // A unit step 0 → 1 at x: response = Σ_{t<0} φ'(t).
            let step: f64 = k[..a].iter().map(|&v| v as f64).sum();
            let want = 1.0 - 1.0 / (a * a) as f64;
            assert!((step - want).abs() < 1e-6, "A={a}: {step} vs {want}");
            for t in 0..=a {
                assert_eq!(k[a + t], -k[a - t], "antisymmetric");
            }
        }
    }

    #[test]
    fn step_responses_have_the_right_sign_and_size() {
        let img = img_from(32, 20, |x, _| if x < 16 { 50 } else { 150 });
        let r = response(&img, ScanDir::Horizontal, 4).unwrap();
        let want = 100.0 * (1.0 - 1.0 / 16.0);
        assert!((r.get(15, 5).unwrap() - want).abs() < 1e-4);
        assert!((r.get(16, 5).unwrap() - want).abs() < 1e-4);
        assert!(r.get(3, 5).is_none() && r.get(28, 5).is_none());
        let rv = response(&img, ScanDir::Vertical, 4).unwrap();
        assert_eq!(rv.get(15, 10), Some(0.0));
        // Light → dark is negative, vertically too.
        let img = img_from(20, 32, |_, y| if y < 16 { 200 } else { 10 });
        let rv = response(&img, ScanDir::Vertical, 3).unwrap();
        assert!((rv.get(7, 15).unwrap() + 190.0 * (1.0 - 1.0 / 9.0)).abs() < 1e-4);
    }

    #[test]
    fn a_step_gives_one_point_per_row_at_the_step() {
        let img = img_from(40, 30, |x, _| if x < 20 { 30 } else { 200 });
        let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
        assert_eq!(e.points.len(), 30);
        for p in &e.points {
            assert!((p.x - 19.5).abs() < 1e-6, "{p:?}");
            assert!(p.response > 150.0);
        }
        // Lexical order.
        assert!(e.points.windows(2).all(|w| w[0].y < w[1].y));
        let ev = detect(&img, ScanDir::Vertical, &EdgeParams::default()).unwrap();
        assert!(ev.points.is_empty());
    }

    #[test]
    fn subpixel_follows_an_antialiased_edge() {
        // A step at x = 20.3 (pixel centres at integers): coverage-weighted.
        for &pos in &[20.0f64, 20.25, 20.5, 20.8] {
            let img = img_from(48, 20, |x, _| {
                let lo = x as f64 - 0.5;
                let cover = (x as f64 + 0.5 - pos.max(lo)).clamp(0.0, 1.0);
                (40.0 + 160.0 * cover).round() as u8
            });
            let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
            assert_eq!(e.points.len(), 20);
            let x = e.points[0].x as f64;
            assert!((x - pos).abs() < 0.12, "step at {pos}: found {x}");
        }
    }

    #[test]
    fn peaks_are_one_pixel_thick_on_a_ramp_and_thresholded_per_row() {
        // A ramp of 4 px: one peak per row, at the ramp's centre.
        let img = img_from(40, 20, |x, _| (x.clamp(13, 17) * 10) as u8);
        let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
        assert_eq!(e.points.len(), 20);
        assert!(e.points.iter().all(|p| (p.x - 15.0).abs() < 1e-5));
        // Noise-like alternating small peaks: M = 2 keeps the two strongest.
        let img = img_from(64, 16, |x, _| {
            if x % 8 < 4 {
                100
            } else {
                100 + (x / 8) as u8 * 3 + 6
            }
        });
        let p = EdgeParams {
            per_region: 2,
            ..EdgeParams::default()
        };
        let e = detect(&img, ScanDir::Horizontal, &p).unwrap();
        for y in 0..16 {
            let n = e.points.iter().filter(|q| q.y == y as f32).count();
            assert!((2..=3).contains(&n), "row {y}: {n} points");
        }
    }

    #[test]
    fn no_panic_on_small_flat_and_invalid_images() {
        let p = EdgeParams::default();
        let flat = GreyImage::filled(16, 16, 77).unwrap();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            for a in 3..=7 {
                let r = response(&flat, dir, a).unwrap();
                assert_eq!(peaks(&r, &p).points.len(), 0);
            }
        }
        let mut img = img_from(16, 16, |x, y| ((x * 37 + y * 11) % 256) as u8);
        img.set_valid_mask(Some(vec![false; 256])).unwrap();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let r = response(&img, dir, 7).unwrap();
            assert!(r.data.iter().all(|v| v.is_nan()));
            assert!(peaks(&r, &p).points.is_empty());
        }
        assert!(response(&GreyImage::filled(15, 40, 0).unwrap(), ScanDir::Vertical, 4).is_err());
        assert!(response(&flat, ScanDir::Vertical, 8).is_err());
    }

    #[test]
    fn invalid_pixels_suppress_responses_around_them() {
        let mut img = img_from(32, 32, |x, _| if x < 16 { 0 } else { 200 });
        let mut mask = vec![true; 32 * 32];
        mask[10 * 32 + 16] = false;
        img.set_valid_mask(Some(mask)).unwrap();
        let rh = response(&img, ScanDir::Horizontal, 4).unwrap();
        assert!(rh.get(15, 10).is_none() && rh.get(12, 10).is_none());
        assert!(rh.get(11, 10).is_some() && rh.get(15, 9).is_some());
        let rv = response(&img, ScanDir::Vertical, 4).unwrap();
        assert!(rv.get(16, 6).is_none() && rv.get(16, 14).is_none());
        assert!(rv.get(16, 5).is_some() && rv.get(16, 15).is_some());
        assert!(rv.get(17, 10).is_some());
    }
}
