//! Lee's one-dimensional edge detector (llv.md §2): the kernel, the signed
//! convolution along one scan direction, peaks one pixel thick along the
//! scan, parabolic subpixel positions and the per-region adaptive threshold.
//!
//! Exactness: the kernel is applied with integer coefficients (`φ'(t)·A³`
//! is a whole number), so every sum of 8-bit pixels is exact in `f32` and the
//! response is rounded once, when it is scaled by `1/A³`.
//!
//! Layout: a [`Response`] is always stored in image order, `data[y·w + x]`,
//! for both scan directions. The vertical convolution and the vertical peak
//! test then run over whole rows (contiguous, vectorisable) instead of
//! striding down columns, so no transposed copy is needed.

use super::image::GreyImage;
use super::params::EdgeParams;
use super::{EdgePoint, EdgePoints, LlvError, ScanDir};

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
    /// Pixels as `f32`, converted once per call.
    pixels: Vec<f32>,
}

/// [`response`] into reusable buffers.
///
/// The antisymmetry of the kernel halves the work:
/// `E(x) = Σ_{s=1..A} c_s (Img(x+s) - Img(x-s))` with `c_s = 6 s (A-s)`
/// (then scaled by `1/A³`); all sums are of whole numbers, exact in `f32`.
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
    out.width = w;
    out.height = h;
    out.dir = dir;
    out.data.clear();
    out.data.resize(w * h, f32::NAN);
    let mut coef = [0f32; 7];
    for (s, v) in coef.iter_mut().enumerate().take(a) {
        *v = (6 * (s + 1) * (a - s - 1)) as f32;
    }
    let c = &coef[..a];
    let scale = 1.0 / (a * a * a) as f32;
    let px = &mut scratch.pixels;
    px.clear();
    px.extend(img.data().iter().map(|&v| v as f32));
    match dir {
        ScanDir::Horizontal => {
            if w > 2 * a {
                for (row, orow) in px.chunks_exact(w).zip(out.data.chunks_exact_mut(w)) {
                    let o = &mut orow[a..w - a];
                    o.fill(0.0);
                    let n = o.len();
                    for (k, &cs) in c.iter().enumerate() {
                        let s = k + 1;
                        // Output j is pixel x = j + A: x + s = j + A + s.
                        let right = &row[a + s..a + s + n];
                        let left = &row[a - s..a - s + n];
                        for ((o, &r), &l) in o.iter_mut().zip(right).zip(left) {
                            *o += cs * (r - l);
                        }
                    }
                    for v in o.iter_mut() {
                        *v *= scale;
                    }
                }
            }
        }
        ScanDir::Vertical => {
            if h > 2 * a {
                for y in a..h - a {
                    let orow = &mut out.data[y * w..(y + 1) * w];
                    orow.fill(0.0);
                    for (k, &cs) in c.iter().enumerate() {
                        let s = k + 1;
                        let below = &px[(y + s) * w..(y + s + 1) * w];
                        let above = &px[(y - s) * w..(y - s + 1) * w];
                        for ((o, &b), &t) in orow.iter_mut().zip(below).zip(above) {
                            *o += cs * (b - t);
                        }
                    }
                    for v in orow.iter_mut() {
                        *v *= scale;
                    }
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
            let add = |counts: &mut Vec<u32>, y: usize, sign: bool| {
                for (c, &m) in counts.iter_mut().zip(&mask[y * w..(y + 1) * w]) {
                    if !m {
                        if sign {
                            *c += 1;
                        } else {
                            *c -= 1;
                        }
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
                    if c != 0 {
                        *d = f32::NAN;
                    }
                }
            }
        }
    }
}

/// A peak before the adaptive threshold.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Candidate {
    x: u32,
    y: u32,
    e: f32,
    delta: f32,
    region: u32,
}

/// Reusable buffers of the peak finder.
#[derive(Clone, Debug, Default)]
pub struct PeakScratch {
    candidates: Vec<Candidate>,
    hist: Vec<u32>,
    thresholds: Vec<u32>,
    flags: Vec<u8>,
}

/// `flags[i] = 1` where `|mid[i]|` is a peak between `|lo[i]|` and `|hi[i]|`
/// (§2.3) above `t`. Branch-free so it vectorises; NaN compares false.
#[inline]
fn peak_flags(lo: &[f32], mid: &[f32], hi: &[f32], t: f32, flags: &mut [u8]) {
    for (((f, &m), &l), &h) in flags.iter_mut().zip(mid).zip(lo).zip(hi) {
        let e0 = m.abs();
        *f = u8::from((e0 > l.abs()) & (e0 >= h.abs()) & (e0 > t));
    }
}

/// Calls `f(i)` for every `i` with `flags[i] != 0`, in order, skipping
/// empty stretches eight bytes at a time.
#[inline]
fn for_each_flag(flags: &[u8], mut f: impl FnMut(usize)) {
    let mut chunks = flags.chunks_exact(8);
    let mut base = 0;
    for ch in &mut chunks {
        let mut word = u64::from_le_bytes([ch[0], ch[1], ch[2], ch[3], ch[4], ch[5], ch[6], ch[7]]);
        while word != 0 {
            let bit = word.trailing_zeros() as usize;
            f(base + bit / 8);
            word &= !(0xFFu64 << (bit / 8 * 8));
        }
        base += 8;
    }
    for (k, &v) in chunks.remainder().iter().enumerate() {
        if v != 0 {
            f(base + k);
        }
    }
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
pub fn peaks_into(resp: &Response, p: &EdgeParams, out: &mut EdgePoints, s: &mut PeakScratch) {
    let (w, h) = (resp.width, resp.height);
    out.dir = Some(resp.dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    if w < 3 || h < 3 || resp.data.len() != w * h {
        return;
    }
    let t = p.floor as f32;
    let r = p.region_lines.max(1) as usize;
    let cands = &mut s.candidates;
    cands.clear();
    s.flags.clear();
    s.flags.resize(w, 0);
    let flags = &mut s.flags;
    match resp.dir {
        ScanDir::Horizontal => {
            for (y, row) in resp.data.chunks_exact(w).enumerate() {
                peak_flags(
                    &row[..w - 2],
                    &row[1..w - 1],
                    &row[2..],
                    t,
                    &mut flags[1..w - 1],
                );
                let region = (y / r) as u32;
                for_each_flag(flags, |x| {
                    let (em, e0, ep) = (row[x - 1].abs(), row[x].abs(), row[x + 1].abs());
                    cands.push(Candidate {
                        x: x as u32,
                        y: y as u32,
                        e: row[x],
                        delta: subpixel(em, e0, ep),
                        region,
                    });
                });
            }
        }
        ScanDir::Vertical => {
            for y in 1..h - 1 {
                let up = &resp.data[(y - 1) * w..y * w];
                let row = &resp.data[y * w..(y + 1) * w];
                let dn = &resp.data[(y + 1) * w..(y + 2) * w];
                peak_flags(up, row, dn, t, flags);
                for_each_flag(flags, |x| {
                    let (em, e0, ep) = (up[x].abs(), row[x].abs(), dn[x].abs());
                    cands.push(Candidate {
                        x: x as u32,
                        y: y as u32,
                        e: row[x],
                        delta: subpixel(em, e0, ep),
                        region: (x / r) as u32,
                    });
                });
            }
        }
    }
    let nreg = match resp.dir {
        ScanDir::Horizontal => h.div_ceil(r),
        ScanDir::Vertical => w.div_ceil(r),
    };
    s.hist.clear();
    s.hist.resize(nreg * BINS, 0);
    for c in cands.iter() {
        let bin = (c.e.abs() as usize).min(BINS - 1);
        s.hist[c.region as usize * BINS + bin] += 1;
    }
    s.thresholds.clear();
    let m = p.per_region;
    for hist in s.hist.chunks_exact(BINS) {
        let mut th = hist.iter().rposition(|&n| n > 0).unwrap_or(0);
        let mut sum = 0u32;
        while sum < m && th > 1 {
            sum += hist[th];
            th -= 1;
        }
        s.thresholds.push(th as u32);
    }
    let vertical = resp.dir == ScanDir::Vertical;
    out.points.extend(
        cands
            .iter()
            .filter(|c| {
                let size = c.e.abs() as u32;
                size > s.thresholds[c.region as usize] && c.e.abs() > t
            })
            .map(|c| {
                let (x, y) = if vertical {
                    (c.x as f32, c.y as f32 + c.delta)
                } else {
                    (c.x as f32 + c.delta, c.y as f32)
                };
                EdgePoint {
                    x,
                    y,
                    response: c.e,
                }
            }),
    );
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

    fn img_from(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
        let mut d = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                d.push(f(x, y));
            }
        }
        GreyImage::new(w, h, d).unwrap()
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
