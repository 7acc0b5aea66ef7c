//! Lee's one-dimensional edge detector (llv.md §2): the kernel, the signed
//! convolution along one scan direction, its noise scale per tile
//! (`edges/noise.rs`), and the edge points: peaks one pixel thick along the
//! scan with parabolic subpixel positions, kept where they stand out of the
//! noise and among the `M` strongest of their region (`edges/peaks.rs`,
//! which says where this leaves §2.5 and why).
//!
//! Exactness: the kernel is applied with integer coefficients (`φ'(t)·A³`
//! is a whole number), so every sum of 8-bit pixels is exact (in integer
//! lanes, `edges/row.rs`) and the response is rounded once, when it is scaled by
//! `1/A³`.
//!
//! Exact form: a single image's response with `A ≤ 5` keeps those sums
//! (`i16`, with their magnitudes) instead of `f32` values. Everything after
//! the kernel reads a response as such integer magnitudes ([`Keys`]); an
//! `f32` response (several lightings, `A` = 6, 7) is quantised to them
//! once, finer than any noise.
//!
//! Layout: a [`Response`] is always stored in image order, `[y·w + x]`,
//! for both scan directions. The vertical convolution and the vertical peak
//! test then run over whole rows (contiguous, vectorisable) instead of
//! striding down columns, so no transposed copy is needed.

use super::image::GreyImage;
use super::params::EdgeParams;
use super::{EdgePoints, LlvError, ScanDir};

pub mod noise;
pub(crate) mod peaks;
#[cfg(test)]
mod reference;
pub(crate) mod row;

pub use noise::{NoiseMap, NoiseScratch};
pub use peaks::{PeakMap, PeakScratch, detect_into, detect_keys_into, peaks, peaks_into};

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
///
/// A response of one image with `A ≤ 5` ([`exact_response_into`], what the
/// pipeline uses) is held as the kernel's exact integer sums instead, and
/// `data` is then empty: read values with [`Response::get`] or
/// [`Response::value`], which give the same `f32` either way. (Two
/// responses of equal values in different forms compare unequal.)
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    pub width: usize,
    pub height: usize,
    pub dir: ScanDir,
    pub data: Vec<f32>,
    exact: Exact,
}

/// The exact form of a [`Response`]: per pixel the kernel's sum `S`
/// (`E = S · scale`, `scale = 1/A³`) and its magnitude `|S|`, or
/// [`NONE`] there for "no response". In use when `scale > 0`.
#[derive(Clone, Debug, Default, PartialEq)]
struct Exact {
    scale: f32,
    sums: Vec<i16>,
    keys: Vec<i16>,
}

/// The magnitude that marks "no response" in [`Exact::keys`]: above every
/// sum's (at most 30 600), so that as a neighbour it stops a peak, and
/// never a candidate itself (the peak test excludes it).
pub(crate) const NONE: i16 = i16::MAX;

impl Default for Response {
    /// An empty horizontal response (a buffer to fill with [`response_into`]).
    fn default() -> Self {
        Response {
            width: 0,
            height: 0,
            dir: ScanDir::Horizontal,
            data: Vec::new(),
            exact: Exact::default(),
        }
    }
}

/// `x.round().clamp(±FLOAT_KEY_MAX) as i16` for a finite `x`, without the
/// libm call `round` is on baseline x86-64 (it was a fifth of a
/// several-lightings run): truncate, then step away from zero where the
/// fraction is a half or more. Exact: below 2²³ the fraction `x − trunc x`
/// is computed without rounding.
#[inline]
fn round_key(x: f32) -> i16 {
    let x = x.clamp(-FLOAT_KEY_MAX, FLOAT_KEY_MAX);
    let t = x as i32;
    let f = x - t as f32;
    (t + i32::from(f >= 0.5) - i32::from(f <= -0.5)) as i16
}

impl Response {
    /// Sets the size and direction for a fill that writes every value it
    /// needs; the buffer is only (re)allocated, as NaN, when the pixel count
    /// changes, so a warm buffer is reused as it is.
    pub(crate) fn reshape(&mut self, w: usize, h: usize, dir: ScanDir) {
        self.width = w;
        self.height = h;
        self.dir = dir;
        self.exact.scale = 0.0;
        if self.data.len() != w * h {
            self.data.clear();
            self.data.resize(w * h, f32::NAN);
        }
    }

    /// [`Response::reshape`] for the exact form with half-width `a`; the
    /// `f32` values are emptied (their buffer is kept for reuse).
    fn reshape_exact(&mut self, w: usize, h: usize, dir: ScanDir, a: usize) {
        self.width = w;
        self.height = h;
        self.dir = dir;
        self.data.clear();
        let e = &mut self.exact;
        e.scale = row::scale(a);
        if e.sums.len() != w * h {
            e.sums.clear();
            e.sums.resize(w * h, 0);
            e.keys.clear();
            e.keys.resize(w * h, NONE);
        }
    }

    /// Whether the response is held as exact sums (`data` is then empty).
    pub fn is_exact(&self) -> bool {
        self.exact.scale > 0.0
    }

    /// Whether the response has a value (or "none") for every pixel of a
    /// `w × h` image.
    pub fn covers(&self, w: usize, h: usize) -> bool {
        let n = if self.is_exact() {
            self.exact.keys.len()
        } else {
            self.data.len()
        };
        (self.width, self.height) == (w, h) && n == w * h
    }

    /// The value at index `i = y · width + x`, NaN for "no response" (and
    /// outside the image).
    pub fn value(&self, i: usize) -> f32 {
        if self.is_exact() {
            match self.exact.keys.get(i) {
                Some(&k) if k != NONE => f32::from(self.exact.sums[i]) * self.exact.scale,
                _ => f32::NAN,
            }
        } else {
            self.data.get(i).copied().unwrap_or(f32::NAN)
        }
    }

    /// The response at `(x, y)`; `None` outside the image or where NaN.
    pub fn get(&self, x: usize, y: usize) -> Option<f32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        Some(self.value(y * self.width + x)).filter(|v| !v.is_nan())
    }
}

/// A response read as integer magnitudes: what the edge-point selection,
/// the noise estimate and the line extractor work on, whichever form the
/// response is held in. `E = sums[i] · scale`; `keys[i] = |sums[i]|`, or
/// [`NONE`] where there is no response (as a neighbour it stops a peak).
#[derive(Clone, Copy, Debug)]
pub struct Keys<'a> {
    pub width: usize,
    pub height: usize,
    pub dir: ScanDir,
    /// Grey levels per unit of a key.
    pub scale: f32,
    pub sums: &'a [i16],
    pub keys: &'a [i16],
}

impl Keys<'_> {
    /// The signed response at index `i` (NaN where there is none).
    #[inline]
    pub fn value(&self, i: usize) -> f32 {
        match self.keys.get(i) {
            Some(&k) if k != NONE => f32::from(self.sums[i]) * self.scale,
            _ => f32::NAN,
        }
    }
}

/// The buffer behind a [`Keys`] view of an `f32` response.
#[derive(Clone, Debug, Default)]
pub struct KeyBuf {
    exact: Exact,
}

/// Keys of an `f32` response are in units of at least 1/128 grey level
/// (finer than any noise an 8-bit image has), coarser only where the
/// response exceeds 250 grey levels (several lightings summed).
const FLOAT_KEY_UNIT: f32 = 1.0 / 128.0;

/// The largest key an `f32` response is quantised to (below [`NONE`]).
const FLOAT_KEY_MAX: f32 = 32_000.0;

impl Response {
    /// The response as integer magnitudes: a view of the exact sums, or of
    /// `buf` holding the `f32` values quantised (see [`FLOAT_KEY_UNIT`]).
    pub fn keys<'a>(&'a self, buf: &'a mut KeyBuf) -> Keys<'a> {
        let e = if self.is_exact() {
            &self.exact
        } else {
            // Branch-free passes over slices (a push and a branch a pixel
            // cost sixty instructions): a NaN is skipped by `max`, and `±∞`
            // is no response.
            let top = self.data.iter().fold(0f32, |m, v| {
                let a = v.abs();
                if a < f32::INFINITY { m.max(a) } else { m }
            });
            let scale = (top / FLOAT_KEY_MAX).max(FLOAT_KEY_UNIT);
            let inv = 1.0 / scale;
            let b = &mut buf.exact;
            b.scale = scale;
            let n = self.data.len();
            b.sums.resize(n, 0);
            b.keys.resize(n, 0);
            for ((&v, s), k) in self.data.iter().zip(&mut b.sums).zip(&mut b.keys) {
                let finite = v.is_finite();
                let q = round_key(if finite { v * inv } else { 0.0 });
                *s = q;
                *k = if finite { q.saturating_abs() } else { NONE };
            }
            &buf.exact
        };
        Keys {
            width: self.width,
            height: self.height,
            dir: self.dir,
            scale: e.scale,
            sums: &e.sums,
            keys: &e.keys,
        }
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
    let (w, h, px) = checked_input(img, a)?;
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
        mask_invalid(
            mask,
            w,
            h,
            dir,
            a,
            &mut out.data,
            f32::NAN,
            &mut scratch.counts,
        );
    }
    Ok(())
}

/// [`response_into`] in the exact form (see [`Response`]) for `a ≤ 5`,
/// where the kernel's sums fit `i16`; the `f32` form for `a` = 6, 7. The
/// peaks found in either form are the same, bit for bit: the peak finder
/// compares magnitudes `|S|` (ordered as `|E|`) and converts to `f32`,
/// exactly as [`response_into`] does, only at candidates.
pub fn exact_response_into(
    img: &GreyImage,
    dir: ScanDir,
    a: usize,
    out: &mut Response,
    scratch: &mut ResponseScratch,
) -> Result<(), LlvError> {
    if a > 5 {
        return response_into(img, dir, a, out, scratch);
    }
    let (w, h, px) = checked_input(img, a)?;
    out.reshape_exact(w, h, dir, a);
    let Exact { sums, keys, .. } = &mut out.exact;
    let rows = sums.chunks_exact_mut(w).zip(keys.chunks_exact_mut(w));
    match dir {
        ScanDir::Horizontal => {
            for ((srow, krow), row) in rows.zip(px.chunks_exact(w)) {
                let taps = row::Taps::horizontal(row, a);
                if !(w > 2 * a
                    && row::lee_row_exact(&taps, a, &mut srow[a..w - a], &mut krow[a..w - a]))
                {
                    krow.fill(NONE);
                    continue;
                }
                krow[..a].fill(NONE);
                krow[w - a..].fill(NONE);
            }
        }
        ScanDir::Vertical => {
            for (y, (srow, krow)) in rows.enumerate() {
                if !(y >= a
                    && y + a < h
                    && row::lee_row_exact(&row::Taps::vertical(px, w, y, a), a, srow, krow))
                {
                    krow.fill(NONE);
                }
            }
        }
    }
    if let Some(mask) = img.valid_mask() {
        mask_invalid(mask, w, h, dir, a, keys, NONE, &mut scratch.counts);
    }
    Ok(())
}

/// The size and pixels of an image the kernel with half-width `a` can run
/// on (a valid half-width, a stage-sized image, a whole buffer).
fn checked_input(img: &GreyImage, a: usize) -> Result<(usize, usize, &[u8]), LlvError> {
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
    Ok((w, h, px))
}

/// Sets `none` wherever the kernel window touches an invalid pixel.
#[allow(clippy::too_many_arguments)]
fn mask_invalid<T: Copy>(
    mask: &[bool],
    w: usize,
    h: usize,
    dir: ScanDir,
    a: usize,
    data: &mut [T],
    none: T,
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
                        *d = none;
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
                    *d = if c != 0 { none } else { *d };
                }
            }
        }
    }
}

/// Response and peaks of one image along `dir`.
pub fn detect(img: &GreyImage, dir: ScanDir, p: &EdgeParams) -> Result<EdgePoints, LlvError> {
    let a = p.half_width as usize;
    let r = response(img, dir, a)?;
    Ok(peaks(&r, p))
}

#[cfg(test)]
mod tests;
