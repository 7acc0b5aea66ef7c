//! Today's straightforward edge detector, kept as the reference the fast
//! paths of `edges.rs` are tested against bit for bit: one pass per tap over
//! `f32` pixels, every candidate peak collected, histogrammed and filtered.
//! Test-only.

use super::super::image::GreyImage;
use super::super::params::EdgeParams;
use super::super::{EdgePoint, EdgePoints, LlvError, ScanDir};
use super::{BINS, Response, check_half_width};

/// Buffers of the reference response.
#[derive(Default)]
pub struct ResponseScratch {
    counts: Vec<u32>,
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
struct Candidate {
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
