//! Several images of one view under different lights, combined into one edge
//! response (llv.md §2.6, the VSS authors' "photometric stereo"): every edge
//! is taken from the images that show it, and noise, which does not
//! correlate between images, does not add up.
//!
//! Per image `i` the Lee response `r_i` is computed as for a single image
//! ([`edges::response`]). If an ambient-only image is given, its response is
//! subtracted first: the kernel is linear, so `r(Img_i − Amb) = r(Img_i) −
//! r(Amb)` exactly, with no clipping of the negative differences that an
//! 8-bit difference image would suffer. Each image's noise level is
//! `τ_i = noise_factor × median |r_i|` (edges are sparse, so the median
//! absolute response is a robust noise scale: for Gaussian noise of response
//! deviation σ it is 0.67 σ, and the default factor 3 puts `τ` at 2 σ).
//!
//! **Why `w_i = sign(r_i)` where `|r_i| ≥ τ_i`, else 0, is the best of the
//! `3ⁿ` weight choices.** The objective `Σ w_i r_i − Σ |w_i| τ_i` is a sum of
//! one term per image, each depending only on that image's `w_i`. So it is
//! maximised image by image: `w_i = 0` gives 0, `w_i = ±1` gives `±r_i − τ_i`;
//! the best is `max(0, |r_i| − τ_i)`, reached by the rule above. n
//! comparisons instead of `3ⁿ` trials.
//!
//! **The combined response is the optimum's value, `Σ max(0, |r_i| − τ_i)`,
//! i.e. `Σ |w_i| τ_i` is subtracted.** Without the subtraction a pixel whose
//! noise just crosses `τ` in each of four images would score about `4 τ`, far
//! above the floor `T`, and the response would jump at every threshold
//! crossing, creating false local maxima. With it the response is 0 where no
//! image shows more than its noise (so `T` reads as "grey levels above
//! noise"), it is continuous, and around a peak where all three samples are
//! above `τ` the subpixel parabola of §2.4 is unchanged (it is invariant to
//! a constant offset).
//!
//! **Sign.** `Σ w_i r_i` is never negative, but a line keeps its mean signed
//! response. The combined response takes the sign of the image with the
//! largest `|r_i|` — the image that shows the edge best, which is the same
//! image all along a straight edge between two faces.
//!
//! Peaks, subpixel positions and the adaptive threshold then run unchanged
//! through [`edges::peaks`]. A pixel with no response (NaN: near the border
//! or an invalid pixel) in any image has no combined response.

use super::edges::{self, Response, ResponseScratch, row};
use super::params::EdgeParams;
use super::{GreyImage, LlvError, ScanDir};

/// At most this many samples estimate an image's median |response|: the
/// standard error of the median of n samples is about 1.25 σ / √n, 2 % of
/// the noise level for 4 k samples — far below what moves a threshold — and
/// the selection costs microseconds instead of a pass over the image.
const MEDIAN_SAMPLES: usize = 1 << 12;

/// Reusable buffers of [`combined_response_into`]: after the first call
/// with a given image size, later calls allocate nothing.
#[derive(Clone, Debug, Default)]
pub struct PhotoScratch {
    response: ResponseScratch,
    r: Response,
    amb: Response,
    best: Vec<f32>,
    samples: Vec<f32>,
    taus: Vec<f32>,
    /// One row each: the ambient response, an image's response, the best
    /// signed response.
    amb_row: Vec<f32>,
    row: Vec<f32>,
    best_row: Vec<f32>,
}

/// The response of several lightings of one view, per §2.6 (module doc).
///
/// `images` are the lit images (at least one); `ambient`, if given, is the
/// ambient-only image of the same view, subtracted from each. All must share
/// one size ([`LlvError::SizeMismatch`] otherwise). The result goes through
/// [`edges::peaks`] like a single image's response.
pub fn combined_response(
    images: &[GreyImage],
    ambient: Option<&GreyImage>,
    dir: ScanDir,
    p: &EdgeParams,
) -> Result<Response, LlvError> {
    let mut out = Response::default();
    combined_response_into(
        images,
        ambient,
        dir,
        p,
        &mut out,
        &mut PhotoScratch::default(),
    )?;
    Ok(out)
}

/// [`combined_response`] into reusable buffers (the pipeline's workspace).
pub fn combined_response_into(
    images: &[GreyImage],
    ambient: Option<&GreyImage>,
    dir: ScanDir,
    p: &EdgeParams,
    out: &mut Response,
    s: &mut PhotoScratch,
) -> Result<(), LlvError> {
    let first = images.first().ok_or(LlvError::Param {
        name: "images",
        value: 0.0,
        range: "at least one lit image",
    })?;
    for img in images.iter().chain(ambient) {
        if img.size() != first.size() {
            return Err(LlvError::SizeMismatch {
                a: first.size(),
                b: img.size(),
            });
        }
    }
    if !(p.noise_factor.is_finite() && p.noise_factor >= 0.0) {
        return Err(LlvError::Param {
            name: "edges.noise_factor",
            value: p.noise_factor,
            range: "0.5 to 20",
        });
    }
    let a = p.half_width as usize;
    let masked = images
        .iter()
        .chain(ambient)
        .any(|m| m.valid_mask().is_some());
    if !masked && (3..=7).contains(&a) && first.check_stage_size().is_ok() {
        fused(images, ambient, dir, a, p.noise_factor, out, s);
        return Ok(());
    }
    // Images with invalid pixels (after lens correction), and the errors of
    // bad sizes and half-widths: whole responses per image, which
    // `edges::response_into` masks and checks.
    per_image(images, ambient, dir, p, out, s)
}

/// The combination from one whole response per image (module doc).
fn per_image(
    images: &[GreyImage],
    ambient: Option<&GreyImage>,
    dir: ScanDir,
    p: &EdgeParams,
    out: &mut Response,
    s: &mut PhotoScratch,
) -> Result<(), LlvError> {
    let a = p.half_width as usize;
    if let Some(m) = ambient {
        edges::response_into(m, dir, a, &mut s.amb, &mut s.response)?;
    }
    let amb = ambient.map(|_| s.amb.data.as_slice());
    // `out.data` holds the running sum; `best` the strongest signed response.
    for (k, img) in images.iter().enumerate() {
        let r = if k == 0 { &mut *out } else { &mut s.r };
        edges::response_into(img, dir, a, r, &mut s.response)?;
        let tau = noise_level_of(&r.data, amb, p.noise_factor, &mut s.samples);
        if k == 0 {
            s.best.clear();
            s.best.resize(r.data.len(), 0.0);
            start(&mut out.data, amb, tau, &mut s.best);
        } else {
            accumulate_diff(&s.r.data, amb, tau, &mut out.data, &mut s.best);
        }
    }
    sign(&mut out.data, &s.best);
    Ok(())
}

/// The Lee kernel as the row path applies it: half-width, the antisymmetric
/// coefficients `c_s = 6 s (A − s)` for s = 1..A and the scale `1/A³` — as
/// `edges::response_into` uses them, so both paths agree bit for bit.
#[derive(Clone, Copy)]
struct Kernel {
    a: usize,
    coef: [f32; 7],
    scale: f32,
}

impl Kernel {
    fn new(a: usize) -> Kernel {
        let mut coef = [0f32; 7];
        for (s, v) in coef.iter_mut().enumerate().take(a) {
            *v = (6 * (s + 1) * (a - s - 1)) as f32;
        }
        Kernel {
            a,
            coef,
            scale: 1.0 / (a * a * a) as f32,
        }
    }
    fn c(&self) -> &[f32] {
        &self.coef[..self.a]
    }
}

/// The response of one image at one pixel inside the valid band.
fn response_at(img: &[u8], w: usize, x: usize, y: usize, dir: ScanDir, k: &Kernel) -> f32 {
    let mut o = 0f32;
    for (i, &cs) in k.c().iter().enumerate() {
        let s = i + 1;
        let (hi, lo) = match dir {
            ScanDir::Horizontal => (img[y * w + x + s], img[y * w + x - s]),
            ScanDir::Vertical => (img[(y + s) * w + x], img[(y - s) * w + x]),
        };
        o += cs * (hi as f32 - lo as f32);
    }
    o * k.scale
}

/// One output row `y` of one image's response into `row` (length `w`; only
/// the valid band `a..w-a` is written for the horizontal scan), through the
/// row kernel `edges::response_into` uses, so both paths agree bit for bit.
fn response_row(img: &[u8], w: usize, y: usize, dir: ScanDir, a: usize, out: &mut [f32]) {
    match dir {
        ScanDir::Horizontal => {
            if let (Some(src), Some(o)) = (img.get(y * w..(y + 1) * w), out.get_mut(a..w - a)) {
                row::lee_row(&row::Taps::horizontal(src, a), a, o);
            }
        }
        ScanDir::Vertical => row::lee_row(&row::Taps::vertical(img, w, y, a), a, out),
    }
}

/// The whole combination row by row, for images without invalid pixels:
/// every row buffer stays in the first-level cache and the output is
/// written once, instead of one full response per image written and read
/// back. Same arithmetic, in the same order, as the per-image path.
fn fused(
    images: &[GreyImage],
    ambient: Option<&GreyImage>,
    dir: ScanDir,
    a: usize,
    factor: f64,
    out: &mut Response,
    s: &mut PhotoScratch,
) {
    let (w, h) = images[0].size();
    let kern = Kernel::new(a);
    out.reshape(w, h, dir);
    // No response outside the valid band; the band is written below.
    for (y, orow) in out.data.chunks_exact_mut(w).enumerate() {
        match dir {
            ScanDir::Horizontal => {
                orow[..a].fill(f32::NAN);
                orow[w - a..].fill(f32::NAN);
            }
            ScanDir::Vertical if y < a || y + a >= h => orow.fill(f32::NAN),
            ScanDir::Vertical => {}
        }
    }
    // The valid band: x in a..w-a (horizontal) or y in a..h-a (vertical).
    let inside = |x: usize, y: usize| match dir {
        ScanDir::Horizontal => x >= a && x + a < w,
        ScanDir::Vertical => y >= a && y + a < h,
    };
    // Noise levels from the same subsample the per-image path uses.
    let stride = (w * h).div_ceil(MEDIAN_SAMPLES).max(1);
    s.taus.clear();
    for img in images {
        s.samples.clear();
        for k in (0..w * h).step_by(stride) {
            let (x, y) = (k % w, k / w);
            if inside(x, y) {
                let mut v = response_at(img.data(), w, x, y, dir, &kern);
                if let Some(m) = ambient {
                    v -= response_at(m.data(), w, x, y, dir, &kern);
                }
                s.samples.push(v.abs());
            }
        }
        s.taus.push(median(&mut s.samples) * factor as f32);
    }
    for buf in [&mut s.amb_row, &mut s.row, &mut s.best_row] {
        buf.clear();
        buf.resize(w, 0.0);
    }
    let (rows, cols) = match dir {
        ScanDir::Horizontal => (0..h, a..w - a),
        ScanDir::Vertical => (a..h - a, 0..w),
    };
    for y in rows {
        if let Some(m) = ambient {
            response_row(m.data(), w, y, dir, a, &mut s.amb_row);
        }
        let sum = &mut out.data[y * w..(y + 1) * w];
        for (i, img) in images.iter().enumerate() {
            response_row(img.data(), w, y, dir, a, &mut s.row);
            let tau = s.taus[i];
            let cols = cols.clone();
            let (r, amb, sm, best) = (
                &s.row[cols.clone()],
                &s.amb_row[cols.clone()],
                &mut sum[cols.clone()],
                &mut s.best_row[cols],
            );
            match (i == 0, ambient.is_some()) {
                (true, true) => combine_row::<true, true>(r, amb, tau, sm, best),
                (true, false) => combine_row::<true, false>(r, amb, tau, sm, best),
                (false, true) => combine_row::<false, true>(r, amb, tau, sm, best),
                (false, false) => combine_row::<false, false>(r, amb, tau, sm, best),
            }
        }
        let cols = cols.clone();
        for (o, &b) in sum[cols.clone()].iter_mut().zip(&s.best_row[cols]) {
            *o = if b < 0.0 { -*o } else { *o };
        }
    }
}

/// One image's contribution to one row of the combination, as [`start`]
/// (`FIRST`) or [`accumulate_diff`] do it, with the ambient response
/// subtracted when `SUB`. The flags are constants, so the loop has only
/// selects and vectorises.
#[inline(always)]
fn combine_row<const FIRST: bool, const SUB: bool>(
    r: &[f32],
    amb: &[f32],
    tau: f32,
    sum: &mut [f32],
    best: &mut [f32],
) {
    for (((&v, &am), o), b) in r.iter().zip(amb).zip(sum.iter_mut()).zip(best.iter_mut()) {
        let v = if SUB { v - am } else { v };
        let m = v.abs();
        let cc = m - tau;
        let add = if cc > 0.0 || cc.is_nan() { cc } else { 0.0 };
        if FIRST {
            *o = add;
            *b = v;
        } else {
            *o += add;
            *b = if m > b.abs() { v } else { *b };
        }
    }
}

/// `τ = factor × median |r − amb|` over the finite values, on an even
/// subsample of at most [`MEDIAN_SAMPLES`] values (no pass over the image).
fn noise_level_of(r: &[f32], amb: Option<&[f32]>, factor: f64, buf: &mut Vec<f32>) -> f32 {
    let stride = r.len().div_ceil(MEDIAN_SAMPLES).max(1);
    buf.clear();
    match amb {
        Some(amb) => buf.extend(
            r.iter()
                .zip(amb)
                .step_by(stride)
                .map(|(v, a)| (v - a).abs())
                .filter(|v| v.is_finite()),
        ),
        None => buf.extend(
            r.iter()
                .step_by(stride)
                .map(|v| v.abs())
                .filter(|v| v.is_finite()),
        ),
    }
    median(buf) * factor as f32
}

fn median(buf: &mut [f32]) -> f32 {
    if buf.is_empty() {
        return 0.0;
    }
    let mid = buf.len() / 2;
    let (_, m, _) = buf.select_nth_unstable_by(mid, f32::total_cmp);
    *m
}

/// The first image: `sum = max(0, |r − amb| − τ)` in place, `best = r − amb`.
fn start(sum: &mut [f32], amb: Option<&[f32]>, tau: f32, best: &mut [f32]) {
    if let Some(amb) = amb {
        for (v, &a) in sum.iter_mut().zip(amb) {
            *v -= a;
        }
    }
    for (v, b) in sum.iter_mut().zip(best.iter_mut()) {
        *b = *v;
        let c = v.abs() - tau;
        *v = if c > 0.0 || c.is_nan() { c } else { 0.0 };
    }
}

/// A further image: [`accumulate`] of `r − amb`, in one pass.
fn accumulate_diff(r: &[f32], amb: Option<&[f32]>, tau: f32, sum: &mut [f32], best: &mut [f32]) {
    match amb {
        None => accumulate(r, tau, sum, best),
        Some(amb) => {
            for (((&v, &a), s), b) in r.iter().zip(amb).zip(sum.iter_mut()).zip(best.iter_mut()) {
                let v = v - a;
                let m = v.abs();
                let c = m - tau;
                *s += if c > 0.0 || c.is_nan() { c } else { 0.0 };
                *b = if m > b.abs() { v } else { *b };
            }
        }
    }
}

/// Gives each combined magnitude the sign of its strongest image.
fn sign(sum: &mut [f32], best: &[f32]) {
    for (o, &b) in sum.iter_mut().zip(best) {
        *o = if b < 0.0 { -*o } else { *o };
    }
}

/// `τ = factor × median |r|` over the finite responses, estimated on an even
/// subsample of at most `MEDIAN_SAMPLES` (4096) values. 0 for a response with no
/// finite value.
pub fn noise_level(r: &[f32], factor: f64) -> f32 {
    noise_level_of(r, None, factor, &mut Vec::new())
}

/// Adds one image's optimal-weight contribution `max(0, |r| − τ)` to `sum`
/// and keeps in `best` the signed response of largest magnitude so far.
/// NaN in `r` makes `sum` NaN (no response).
pub fn accumulate(r: &[f32], tau: f32, sum: &mut [f32], best: &mut [f32]) {
    for ((&v, s), b) in r.iter().zip(sum.iter_mut()).zip(best.iter_mut()) {
        let m = v.abs();
        let c = m - tau;
        // Written as selects (no early exit) so the loop vectorises.
        *s += if c > 0.0 || c.is_nan() { c } else { 0.0 };
        *b = if m > b.abs() { v } else { *b };
    }
}

/// The combined signed response: `sum` with the sign of `best`.
pub fn finish(sum: &[f32], best: &[f32], out: &mut [f32]) {
    for ((o, &s), &b) in out.iter_mut().zip(sum).zip(best) {
        *o = if b < 0.0 { -s } else { s };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_the_optimum_of_all_3_pow_n_choices() {
        // Brute force over every weight vector for random responses.
        let mut rng = crate::llv::synth::rng::SplitMix64::new(0x9E37_79B9_7F4A_7C15);
        let mut next = || (rng.next_u64() % 2001) as f32 / 10.0 - 100.0;
        for _ in 0..200 {
            let n = 4;
            let r: Vec<f32> = (0..n).map(|_| next()).collect();
            let tau: Vec<f32> = (0..n).map(|_| next().abs() / 2.0).collect();
            let mut brute = f32::MIN;
            for code in 0..3usize.pow(n as u32) {
                let mut c = code;
                let mut v = 0.0;
                for i in 0..n {
                    let w = (c % 3) as f32 - 1.0;
                    c /= 3;
                    v += w * r[i] - w.abs() * tau[i];
                }
                brute = brute.max(v);
            }
            let (mut sum, mut best) = (vec![0.0], vec![0.0]);
            for i in 0..n {
                accumulate(&r[i..=i], tau[i], &mut sum, &mut best);
            }
            assert!((sum[0] - brute).abs() < 1e-3, "{r:?} {tau:?}");
        }
    }

    #[test]
    fn sign_follows_the_strongest_image_and_nan_propagates() {
        let (mut sum, mut best) = (vec![0.0; 3], vec![0.0; 3]);
        accumulate(&[10.0, -3.0, 1.0], 2.0, &mut sum, &mut best);
        accumulate(&[-30.0, 1.0, f32::NAN], 2.0, &mut sum, &mut best);
        let mut out = vec![0.0; 3];
        finish(&sum, &best, &mut out);
        assert_eq!(out[0], -(8.0 + 28.0));
        assert_eq!(out[1], -1.0);
        assert!(out[2].is_nan());
    }

    #[test]
    fn noise_level_is_the_scaled_median() {
        let r: Vec<f32> = (0..1001)
            .map(|i| if i % 2 == 0 { i as f32 } else { -(i as f32) })
            .collect();
        assert_eq!(noise_level(&r, 3.0), 1500.0);
        assert_eq!(noise_level(&[f32::NAN; 4], 3.0), 0.0);
        // Subsampled on large inputs, still close.
        let mut x = 1u64;
        let big: Vec<f32> = (0..1_000_000)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 40) as f32 / (1u64 << 24) as f32 * 1000.0
            })
            .collect();
        let m = noise_level(&big, 1.0);
        assert!((m - 500.0).abs() < 25.0, "{m}");
    }

    const W: usize = 96;

    /// A 96 × 32 image with a vertical step from `lo` to `hi` at column `at`
    /// and a faint pseudo-random texture (0–3 grey levels) as noise.
    fn step(lo: u8, hi: u8, at: usize) -> GreyImage {
        let data = (0..W * 32)
            .map(|k| {
                let x = k % W;
                let h = (k as u64 ^ 0x5DEECE66D).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                (if x < at { lo } else { hi }) + (h >> 62) as u8
            })
            .collect();
        GreyImage::new(W, 32, data).unwrap()
    }

    fn at(r: &Response, x: usize, y: usize) -> f32 {
        r.data[y * r.width + x]
    }

    #[test]
    fn an_edge_seen_in_one_image_survives_with_its_sign() {
        let p = EdgeParams::default();
        let flat = step(100, 100, 16);
        let dark_to_light = step(50, 150, 16);
        let r = combined_response(
            &[flat.clone(), dark_to_light.clone()],
            None,
            ScanDir::Horizontal,
            &p,
        )
        .unwrap();
        let single = edges::response(&dark_to_light, ScanDir::Horizontal, 4).unwrap();
        let (c, s) = (
            at(&r, 16, 10).max(at(&r, 15, 10)),
            at(&single, 16, 10).max(at(&single, 15, 10)),
        );
        assert!(c > 0.8 * s && c <= s, "combined {c}, single {s}");
        // Light→dark gives a negative combined response.
        let r =
            combined_response(&[flat, step(150, 50, 16)], None, ScanDir::Horizontal, &p).unwrap();
        assert!(at(&r, 16, 10).min(at(&r, 15, 10)) < -0.8 * s);
        // Away from the edge, only noise: nothing above the floor.
        assert!(at(&r, 8, 10).abs() < p.floor as f32);
        // No response near the border.
        assert!(at(&r, 1, 10).is_nan());
    }

    #[test]
    fn the_ambient_image_is_subtracted() {
        let p = EdgeParams::default();
        // The ambient light alone shows a step at column 30; the lit image
        // adds a step at column 60 on top of it.
        let amb = step(40, 80, 30);
        let lit: Vec<u8> = amb
            .data()
            .iter()
            .enumerate()
            .map(|(k, &v)| v + if k % W >= 60 { 60 } else { 0 })
            .collect();
        let lit = GreyImage::new(W, 32, lit).unwrap();
        let with = combined_response(
            std::slice::from_ref(&lit),
            Some(&amb),
            ScanDir::Horizontal,
            &p,
        )
        .unwrap();
        let without = combined_response(&[lit], None, ScanDir::Horizontal, &p).unwrap();
        let peak = |r: &Response, x: usize| at(r, x, 10).abs().max(at(r, x - 1, 10).abs());
        assert!(peak(&without, 30) > 20.0);
        assert!(peak(&with, 30) < 1.0, "{}", peak(&with, 30));
        assert!(peak(&with, 60) > 40.0);
    }

    #[test]
    fn sizes_must_match_and_there_must_be_an_image() {
        let p = EdgeParams::default();
        let a = GreyImage::filled(32, 32, 9).unwrap();
        let b = GreyImage::filled(32, 33, 9).unwrap();
        assert!(matches!(
            combined_response(&[a.clone(), b.clone()], None, ScanDir::Vertical, &p),
            Err(LlvError::SizeMismatch { .. })
        ));
        assert!(matches!(
            combined_response(std::slice::from_ref(&a), Some(&b), ScanDir::Vertical, &p),
            Err(LlvError::SizeMismatch { .. })
        ));
        assert!(combined_response(&[], None, ScanDir::Vertical, &p).is_err());
    }

    #[test]
    fn reused_buffers_give_the_same_response() {
        let p = EdgeParams::default();
        let imgs = [step(50, 150, 16), step(120, 60, 40), step(90, 90, 8)];
        let amb = step(30, 60, 70);
        let mut s = PhotoScratch::default();
        let mut out = Response::default();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            for ambient in [Some(&amb), None] {
                for n in [3, 1, 2] {
                    let fresh = combined_response(&imgs[..n], ambient, dir, &p).unwrap();
                    combined_response_into(&imgs[..n], ambient, dir, &p, &mut out, &mut s).unwrap();
                    assert_eq!(out.data.len(), fresh.data.len());
                    for (x, y) in out.data.iter().zip(&fresh.data) {
                        assert!(x == y || (x.is_nan() && y.is_nan()));
                    }
                }
            }
        }
    }

    #[test]
    fn the_row_path_equals_the_per_image_path_bit_for_bit() {
        let mut x = 99u64;
        let mut noisy = |lo: u8, hi: u8, at: usize| {
            let data = (0..150 * 50)
                .map(|k| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let v = if k % 150 + k / 150 < at { lo } else { hi };
                    v.saturating_add((x >> 59) as u8)
                })
                .collect();
            GreyImage::new(150, 50, data).unwrap()
        };
        let imgs = [noisy(40, 200, 50), noisy(150, 90, 70), noisy(100, 100, 0)];
        let amb = noisy(20, 45, 60);
        for a in 3..=7 {
            let p = EdgeParams {
                half_width: a,
                ..EdgeParams::default()
            };
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                for ambient in [Some(&amb), None] {
                    let (mut f, mut r) = (Response::default(), Response::default());
                    let mut s = PhotoScratch::default();
                    fused(
                        &imgs,
                        ambient,
                        dir,
                        a as usize,
                        p.noise_factor,
                        &mut f,
                        &mut s,
                    );
                    per_image(&imgs, ambient, dir, &p, &mut r, &mut s).unwrap();
                    assert_eq!((f.width, f.height, f.dir), (r.width, r.height, r.dir));
                    for (k, (u, v)) in f.data.iter().zip(&r.data).enumerate() {
                        assert!(
                            u.to_bits() == v.to_bits() || (u.is_nan() && v.is_nan()),
                            "{k}: {u} {v}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn invalid_pixels_give_no_response_around_them() {
        let p = EdgeParams::default();
        let mut lit = step(50, 150, 40);
        let mut mask = vec![true; W * 32];
        mask[10 * W + 20] = false;
        lit.set_valid_mask(Some(mask)).unwrap();
        let r = combined_response(&[lit, step(60, 60, 0)], None, ScanDir::Horizontal, &p).unwrap();
        for x in 16..=24 {
            assert!(at(&r, x, 10).is_nan(), "x = {x}");
        }
        assert!(at(&r, 30, 10).is_finite() && at(&r, 20, 11).is_finite());
    }
}
