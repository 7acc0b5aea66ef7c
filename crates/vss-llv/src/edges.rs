//! Lee's one-dimensional edge detector (llv.md §2): the kernel, the signed
//! convolution along one scan direction, its noise scale per tile
//! (`edges/noise.rs`), and the edge points: peaks one pixel thick along the
//! scan with parabolic subpixel positions, kept where they stand out of the
//! noise and among the `M` strongest of their region (`edges/peaks.rs`,
//! which says where this leaves §2.5 and why).
//!
//! One form for every response: whole numbers. The kernel has integer
//! coefficients (`φ'(t)·A³` is a whole number), so a response of 8-bit
//! pixels is an exact integer sum, and [`Response`] keeps those sums as
//! `i16` with the grey levels of one unit (`scale`): `1/A³` for one image
//! with `A ≤ 5`, whose sums fit (`edges/row.rs`); a power of two more for
//! `A` = 6, 7 and for several lightings combined (`photometric.rs`), whose
//! sums are rounded once to fit. Everything after the kernel compares
//! magnitudes `|sum|` ([`key`]) and converts to grey levels only at the
//! points it keeps; nothing else is stored per pixel.
//!
//! Layout: a response is stored in image order, `[y·w + x]`, for both scan
//! directions. The vertical convolution and the vertical peak test then run
//! over whole rows (contiguous, vectorisable) instead of striding down
//! columns; a vertical track reads down a column, whose cache lines serve
//! the next 32 columns' scan lines.

use super::image::GreyImage;
use super::params::EdgeParams;
use super::{EdgePoints, LlvError, ScanDir};

pub(crate) mod band;
pub mod noise;
pub mod peaks;
#[cfg(test)]
mod reference;
pub(crate) mod row;

pub use noise::{NoiseMap, NoiseScratch};
pub use peaks::{PeakMap, PeakScratch, Starts, detect_into, detect_unmapped_into, peaks};

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

/// The sum that marks "no response": within `A` pixels of the border along
/// the scan, or of an invalid pixel. Its [`key`] is `i16::MAX`, above every
/// real magnitude (at most 32 000), so as a neighbour it stops a peak, and
/// the peak tests exclude it as a candidate.
pub const NONE: i16 = i16::MIN;

/// The largest magnitude a sum may have (real sums are clamped to it), so
/// that [`NONE`]'s key stays above every real one.
pub(crate) const SUM_MAX: i32 = 32_000;

/// The magnitude of a sum: `|s|`, and `i16::MAX` for [`NONE`] (saturating).
#[inline(always)]
pub fn key(s: i16) -> i16 {
    s.saturating_abs()
}

/// A signed edge response along one scan direction, stored in image order
/// (`[y * width + x]`) as whole numbers of `scale` grey levels, [`NONE`]
/// where there is no response (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    pub width: usize,
    pub height: usize,
    pub dir: ScanDir,
    scale: f32,
    sums: Vec<i16>,
}

impl Default for Response {
    /// An empty horizontal response (a buffer to fill).
    fn default() -> Self {
        Response {
            width: 0,
            height: 0,
            dir: ScanDir::Horizontal,
            scale: 0.0,
            sums: Vec::new(),
        }
    }
}

impl Response {
    /// Sets the size, direction and unit for a fill that writes every
    /// value; the buffer is only (re)allocated when the pixel count
    /// changes, so a warm buffer is reused as it is.
    pub(crate) fn reshape(&mut self, w: usize, h: usize, dir: ScanDir, scale: f32) {
        self.width = w;
        self.height = h;
        self.dir = dir;
        self.scale = scale;
        if self.sums.len() != w * h {
            self.sums.clear();
            self.sums.resize(w * h, NONE);
        }
    }

    /// Grey levels of one unit of [`Response::sums`].
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// Per pixel, in image order, the response in units of `scale`
    /// ([`NONE`]: no response).
    pub fn sums(&self) -> &[i16] {
        &self.sums
    }

    pub(crate) fn sums_mut(&mut self) -> &mut [i16] {
        &mut self.sums
    }

    /// Whether the response has a value (or "none") for every pixel of a
    /// `w × h` image.
    pub fn covers(&self, w: usize, h: usize) -> bool {
        (self.width, self.height) == (w, h) && self.sums.len() == w * h
    }

    /// The value at index `i = y · width + x` in grey levels, NaN for "no
    /// response" (and outside the image).
    pub fn value(&self, i: usize) -> f32 {
        match self.sums.get(i) {
            Some(&s) if s != NONE => f32::from(s) * self.scale,
            _ => f32::NAN,
        }
    }

    /// The response at `(x, y)`; `None` outside the image or where none.
    pub fn get(&self, x: usize, y: usize) -> Option<f32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        Some(self.value(y * self.width + x)).filter(|v| !v.is_nan())
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
    /// Images with a validity mask.
    mask: MaskBufs,
    /// One row of `i32` sums (`A` = 6, 7).
    wide: Vec<i32>,
}

/// [`response`] into reusable buffers.
///
/// Each row goes through the shared row kernel (`edges/row.rs`): the
/// antisymmetry of the kernel halves the work,
/// `E(x) = Σ_{s=1..A} c_s (Img(x+s) - Img(x-s))` with `c_s = 6 s (A-s)`,
/// the sums of whole numbers exact in integer lanes. For `A ≤ 5` they are
/// stored as they are (`scale = 1/A³`); for `A` = 6, 7 (up to 85 680) they
/// are halved or quartered, rounding half away from zero. Every output is
/// written exactly once ([`NONE`] outside the valid band).
pub fn response_into(
    img: &GreyImage,
    dir: ScanDir,
    a: usize,
    out: &mut Response,
    scratch: &mut ResponseScratch,
) -> Result<(), LlvError> {
    let (w, h, px) = checked_input(img, a)?;
    let shift = row::shift(a, 1);
    out.reshape(w, h, dir, row::scale(a) * (1u32 << shift) as f32);
    let sums = &mut out.sums;
    rows_into(px, w, h, dir, a, shift, 0, sums, &mut scratch.wide);
    if let Some(mask) = img.valid_mask() {
        mask_invalid(mask, w, h, dir, a, sums, &mut scratch.mask);
    }
    Ok(())
}

/// The sums of the image rows `y0..` that `out` holds (whole rows of `w`),
/// unmasked: what [`response_into`] writes there before the mask.
#[allow(clippy::too_many_arguments)]
fn rows_into(
    px: &[u8],
    w: usize,
    h: usize,
    dir: ScanDir,
    a: usize,
    shift: u32,
    y0: usize,
    out: &mut [i16],
    wide: &mut Vec<i32>,
) {
    match dir {
        ScanDir::Horizontal => {
            for (row, srow) in px[y0 * w..].chunks_exact(w).zip(out.chunks_exact_mut(w)) {
                if w <= 2 * a {
                    srow.fill(NONE);
                    continue;
                }
                srow[..a].fill(NONE);
                srow[w - a..].fill(NONE);
                let taps = row::Taps::horizontal(row, a);
                row_sums(&taps, a, shift, &mut srow[a..w - a], wide);
            }
        }
        ScanDir::Vertical => {
            for (k, srow) in out.chunks_exact_mut(w).enumerate() {
                let y = y0 + k;
                if y < a || y + a >= h {
                    srow.fill(NONE);
                    continue;
                }
                let taps = row::Taps::vertical(px, w, y, a);
                row_sums(&taps, a, shift, srow, wide);
            }
        }
    }
}

/// One row of sums, stored as `i16` (exactly for `A ≤ 5`, else shifted).
fn row_sums(taps: &row::Taps, a: usize, shift: u32, out: &mut [i16], wide: &mut Vec<i32>) {
    if row::sums_i16(taps, a, out) {
        return;
    }
    wide.clear();
    wide.resize(out.len(), 0);
    row::sums_i32(taps, a, wide);
    row::narrow(wide, shift, out);
}

/// The size and pixels of an image the kernel with half-width `a` can run
/// on (a valid half-width, a stage-sized image, a whole buffer).
pub(crate) fn checked_input(img: &GreyImage, a: usize) -> Result<(usize, usize, &[u8]), LlvError> {
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

/// Sets [`NONE`] wherever the kernel window touches an invalid pixel.
///
/// A lens-corrected image's valid pixels form one interval in every row
/// (the image of the source's rectangle), so the usual case is done with
/// fills: a horizontal response is none within `a` of each row's interval
/// ends, a vertical one outside the intersection of the intervals of the
/// `2a + 1` rows under its window. Rows with holes inside their interval
/// (a mask from elsewhere) go through [`mask_invalid_plain`].
pub(crate) fn mask_invalid(
    mask: &[bool],
    w: usize,
    h: usize,
    dir: ScanDir,
    a: usize,
    data: &mut [i16],
    bufs: &mut MaskBufs,
) {
    if mask.len() != w * h || data.len() != w * h {
        return;
    }
    // Per row: the first valid pixel, one past the last, and whether all
    // between are valid (`lo == hi`: none valid).
    let spans = &mut bufs.spans;
    spans.clear();
    for row in mask.chunks_exact(w) {
        let lo = row.iter().position(|&v| v).unwrap_or(w);
        let hi = row.iter().rposition(|&v| v).map_or(lo, |x| x + 1);
        let whole = row[lo..hi].iter().all(|&v| v);
        spans.push((lo, hi, whole));
    }
    if !spans.iter().all(|s| s.2) {
        mask_invalid_plain(mask, w, h, dir, a, data, &mut bufs.counts);
        return;
    }
    for (y, drow) in data.chunks_exact_mut(w).enumerate() {
        // The valid outputs of row y: `lo..hi`.
        let (lo, hi) = match dir {
            ScanDir::Horizontal => {
                let (l, r, _) = spans[y];
                (
                    if l == 0 { 0 } else { l + a },
                    if r == w { w } else { r.saturating_sub(a) },
                )
            }
            ScanDir::Vertical => {
                let window = &spans[y.saturating_sub(a)..(y + a + 1).min(h)];
                let l = window.iter().map(|s| s.0).max().unwrap_or(w);
                let r = window.iter().map(|s| s.1).min().unwrap_or(0);
                (l, r)
            }
        };
        if lo >= hi {
            drow.fill(NONE);
        } else {
            drow[..lo].fill(NONE);
            drow[hi..].fill(NONE);
        }
    }
}

/// Buffers of [`mask_invalid`].
#[derive(Clone, Debug, Default)]
pub(crate) struct MaskBufs {
    counts: Vec<u32>,
    spans: Vec<(usize, usize, bool)>,
}

/// [`mask_invalid`] for any mask: a count of the invalid pixels under every
/// window (the reference the interval case is tested against).
pub(crate) fn mask_invalid_plain(
    mask: &[bool],
    w: usize,
    h: usize,
    dir: ScanDir,
    a: usize,
    data: &mut [i16],
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
                        *d = NONE;
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
                    *d = if c != 0 { NONE } else { *d };
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
