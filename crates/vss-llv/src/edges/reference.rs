//! The straightforward Lee response, kept as the reference the row kernel
//! of `edges.rs` is tested against bit for bit: one pass per tap over `f32`
//! pixels. Test-only.

use super::super::image::GreyImage;
use super::super::{LlvError, ScanDir};
use super::check_half_width;

/// Buffers of the reference response.
#[derive(Default)]
pub struct ResponseScratch {
    counts: Vec<u32>,
    pixels: Vec<f32>,
}

/// The Lee response of `img` along `dir` in grey levels, NaN where there
/// is none, in image order, into `out`.
///
/// The antisymmetry of the kernel halves the work:
/// `E(x) = Σ_{s=1..A} c_s (Img(x+s) - Img(x-s))` with `c_s = 6 s (A-s)`
/// (then scaled by `1/A³`); all sums are of whole numbers, exact in `f32`.
pub fn response_into(
    img: &GreyImage,
    dir: ScanDir,
    a: usize,
    out: &mut Vec<f32>,
    scratch: &mut ResponseScratch,
) -> Result<(), LlvError> {
    check_half_width(a)?;
    img.check_stage_size()?;
    let (w, h) = img.size();
    out.clear();
    out.resize(w * h, f32::NAN);
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
                for (row, orow) in px.chunks_exact(w).zip(out.chunks_exact_mut(w)) {
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
                    let orow = &mut out[y * w..(y + 1) * w];
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
        mask_invalid(mask, w, h, dir, a, out, &mut scratch.counts);
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
