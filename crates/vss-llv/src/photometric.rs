//! Several images of one view under different lights, combined into one edge
//! response (llv.md §2.6, the VSS authors' "photometric stereo"): every edge
//! is taken from the images that show it, and noise, which does not
//! correlate between images, does not add up the way edges do.
//!
//! Per image `i` the Lee response `r_i` is computed as for a single image
//! ([`edges::response`]), as the kernel's exact integer sums. If an
//! ambient-only image is given, its response is subtracted first: the
//! kernel is linear, so `r(Img_i − Amb) = r(Img_i) − r(Amb)` exactly, with
//! no clipping of the negative differences that an 8-bit difference image
//! would suffer.
//!
//! **The combination is `Σ g_i |r_i|` over the terms of the strongest
//! term's sign**, with that sign: the strongest term `g_i |r_i|` is the
//! image that shows the edge best, which is the same image all along a
//! straight edge between two faces, and an image where the response has
//! the other sign shows another edge there, or noise, which would only
//! raise the floor. `g_i` brings every
//! image to the noise units of the least noisy one: `g_i = m_min / m_i`, `m_i`
//! the image's noise level as a median |response| (with
//! `edges.noise_percentile`, the percentile of strips' medians, as one
//! image's threshold reads its sensor noise: `noise_median`). Without it a
//! dim image would count less than a bright one for the same evidence, and
//! a noisy one more.
//!
//! The combined response is then treated exactly as one image's:
//! [`edges::peaks()`] measures its noise per tile, bounds it by the least
//! textured tiles, and thresholds it, so `edges.noise_sigmas`,
//! `lines.track_sigmas` and the a-contrario test mean what they mean with
//! one image. The combination is never negative before its sign is given,
//! so on pure noise its median — and the noise the tiles read — is high
//! compared with the spread of its values: on noise it is stricter than
//! one image (the `calibration` test below), while an edge seen in several
//! images adds up linearly.
//!
//! **Why only one sign.** Summing every term's magnitude (the rule before)
//! adds each image's noise whatever its sign, so with exposures of their
//! own the floor rose with every term as fast as the edge: on photographs
//! lit three ways, each with its own noise, it lost to the best single
//! image; a signed sum `Σ g_i r_i`, where noise of opposite signs cancels,
//! beat it there but cancelled the edges whose polarity the lights flip
//! (lights on opposite sides of a workpiece). Summing the terms of one sign
//! keeps what each did well (docs/accuracy.md, "Several lightings").
//!
//! **Why not the thesis's τ.** The earlier rule took a noise level
//! `τ_i = edges.noise_factor × m_i` off each term (`Σ max(0, |r_i| − τ_i)`,
//! the optimum of the weights `w_i ∈ {−1, 0, 1}`) and modelled the combined
//! response's noise from the τ's. On real photographs the τ, read from
//! textured images, took faint edges away on real photographs lit several
//! ways, and on the synthetic lightings it let more noise through than this
//! rule (docs/llv.md, "Measurements behind the design"). `edges.noise_factor`
//! is kept so that older profiles and sessions read; it has no effect.
//!
//! Peaks, subpixel positions and the adaptive threshold then run unchanged
//! through [`edges::peaks()`]. A pixel with no response (near the border or
//! an invalid pixel) in any image has no combined response.
//!
//! **Whole numbers throughout.** Every image's sums, the gains (fixed point,
//! at most 1) and the combination are computed in `i32`, row by row (the
//! rows stay in the first-level cache and the output is written once),
//! and the combined sum is stored as the single image's is, halved as many
//! times as the number of terms needs to fit (`edges/row.rs`: a quarter for
//! four lightings, an eighth with an ambient image: 1/8 of a grey level at
//! `A` = 4, far below any noise). No `f32` response is made, so several
//! lightings cost the kernels and a few integer operations a pixel each.

use super::edges::{self, NONE, Response, row};
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
    samples: Vec<i32>,
    /// Each image's noise level (median |sum|) and its gain
    /// (`GAIN_ONE` = 1).
    medians: Vec<i32>,
    gains: Vec<i32>,
    /// Strip medians of [`noise_median`].
    strips: Vec<i32>,
    /// One row each: the ambient sums, an image's sums, the combined sum,
    /// the strongest signed term.
    amb_row: Vec<i32>,
    row: Vec<i32>,
    sum_row: Vec<i32>,
    neg_row: Vec<i32>,
    best_row: Vec<i32>,
    mask: edges::MaskBufs,
}

/// The response of several lightings of one view, per §2.6 (module doc).
///
/// `images` are the lit images (at least one); `ambient`, if given, is the
/// ambient-only image of the same view, subtracted from each. All must share
/// one size ([`LlvError::SizeMismatch`] otherwise). The result goes through
/// [`edges::peaks()`] like a single image's response.
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
    let a = p.half_width as usize;
    for img in images.iter().chain(ambient) {
        if img.size() != first.size() {
            return Err(LlvError::SizeMismatch {
                a: first.size(),
                b: img.size(),
            });
        }
        edges::checked_input(img, a)?;
    }
    let (w, h) = first.size();
    // Each term is at most twice an image's largest sum with an ambient
    // image subtracted.
    let terms = images.len() as u32 * if ambient.is_some() { 2 } else { 1 };
    let shift = row::shift(a, terms);
    out.reshape(w, h, dir, row::scale(a) * (1u32 << shift) as f32);
    for buf in [
        &mut s.amb_row,
        &mut s.row,
        &mut s.sum_row,
        &mut s.neg_row,
        &mut s.best_row,
    ] {
        buf.clear();
        buf.resize(w, 0);
    }
    let (rows, cols) = match dir {
        ScanDir::Horizontal => (0..h, a..w - a),
        ScanDir::Vertical => (a..h - a, 0..w),
    };
    // Noise levels from about MEDIAN_SAMPLES samples: every second pixel
    // of rows spread evenly over the valid band (whole rows through the
    // row kernel; every second, as neighbours along a horizontal scan are
    // correlated).
    let per_row = cols.len().div_ceil(2).max(1);
    let nrows = MEDIAN_SAMPLES.div_ceil(per_row).clamp(1, rows.len().max(1));
    s.medians.clear();
    for img in images {
        s.samples.clear();
        for k in 0..nrows {
            let y = rows.start + (2 * k + 1) * rows.len() / (2 * nrows);
            if !rows.contains(&y) {
                continue;
            }
            if let Some(m) = ambient {
                response_row(m.data(), w, y, dir, a, &mut s.amb_row);
            }
            response_row(img.data(), w, y, dir, a, &mut s.row);
            for x in cols.clone().step_by(2) {
                let amb = if ambient.is_some() { s.amb_row[x] } else { 0 };
                s.samples.push((s.row[x] - amb).abs());
            }
        }
        s.medians.push(noise_median(
            &mut s.samples,
            &mut s.strips,
            p.noise_percentile,
        ));
    }
    gains(&s.medians, &mut s.gains);
    let sums = out.sums_mut();
    sums.fill(NONE);
    for y in rows {
        if let Some(m) = ambient {
            response_row(m.data(), w, y, dir, a, &mut s.amb_row);
        }
        for (i, img) in images.iter().enumerate() {
            response_row(img.data(), w, y, dir, a, &mut s.row);
            let c = cols.clone();
            combine(
                (i == 0, ambient.is_some()),
                i,
                &s.row[c.clone()],
                &s.amb_row[c.clone()],
                s.gains[i],
                (&mut s.sum_row[c.clone()], &mut s.neg_row[c.clone()]),
                &mut s.best_row[c],
            );
        }
        let c = cols.clone();
        let orow = &mut sums[y * w..(y + 1) * w][c.clone()];
        finish_row(
            orow,
            &s.sum_row[c.clone()],
            &s.neg_row[c.clone()],
            &s.best_row[c],
            shift,
        );
    }
    // No combined response where any image's kernel touches an invalid
    // pixel.
    for img in images.iter().chain(ambient) {
        if let Some(mask) = img.valid_mask() {
            edges::mask_invalid(mask, w, h, dir, a, sums, &mut s.mask);
        }
    }
    Ok(())
}

/// One output row `y` of one image's sums into `out` (length `w`; only
/// the valid band `a..w-a` is written for the horizontal scan), through the
/// row kernel of `edges/row.rs`.
fn response_row(img: &[u8], w: usize, y: usize, dir: ScanDir, a: usize, out: &mut [i32]) {
    match dir {
        ScanDir::Horizontal => {
            if let (Some(src), Some(o)) = (img.get(y * w..(y + 1) * w), out.get_mut(a..w - a)) {
                row::sums_i32(&row::Taps::horizontal(src, a), a, o);
            }
        }
        ScanDir::Vertical => row::sums_i32(&row::Taps::vertical(img, w, y, a), a, out),
    }
}

/// [`combine_row`] with the flags chosen at run time, compiled for AVX2 too
/// (eight `i32` lanes) and picked at run time. `image` is the image's
/// place in the combination (the first of two equally strong terms gives
/// the sign).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
fn combine(
    (first, sub): (bool, bool),
    image: usize,
    r: &[i32],
    amb: &[i32],
    gain: i32,
    (sum, neg): (&mut [i32], &mut [i32]),
    best: &mut [i32],
) {
    let rank = (MAX_RANK - image.min(MAX_RANK as usize) as i32) << 1;
    match (first, sub) {
        (true, true) => combine_row::<true, true>(r, amb, gain, rank, sum, neg, best),
        (true, false) => combine_row::<true, false>(r, amb, gain, rank, sum, neg, best),
        (false, true) => combine_row::<false, true>(r, amb, gain, rank, sum, neg, best),
        (false, false) => combine_row::<false, false>(r, amb, gain, rank, sum, neg, best),
    }
}

/// The strongest term's key is `g |v| << 6 | rank << 1 | sign`, rank `31 −`
/// the image's place: the largest key is the largest gained term, of the
/// first image among equals, and its last bit is the sign. (`|v|` is at
/// most twice an image's largest sum, 171 360 at `A` = 7, so the key and
/// `|v| × GAIN_ONE` fit an `i32`.)
const MAX_RANK: i32 = 31;

/// The combined row: the sum of the terms of the strongest term's sign
/// (`sum` the positive terms', `neg` the negative terms'), narrowed to the
/// stored unit, with that sign.
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
fn finish_row(out: &mut [i16], sum: &[i32], neg: &[i32], best: &[i32], shift: u32) {
    for (((o, &m), &n), &b) in out.iter_mut().zip(sum).zip(neg).zip(best) {
        *o = if b & 1 != 0 {
            -row::narrow_one(n, shift)
        } else {
            row::narrow_one(m, shift)
        };
    }
}

/// One image's contribution to one row of the combination: `sum +=
/// gain × |v|` where `v > 0`, `neg +=` it where `v < 0`, with `v = r −
/// amb` (`SUB`) or `r`, and `best` the key
/// ([`MAX_RANK`]) of the `v` of largest magnitude so far (`FIRST` starts
/// both). The flags are constants, so the loop vectorises. The strongest
/// term is a maximum of keys, not a select of values: a select that keeps
/// the old value becomes a masked store (`vpmaskmovd`), which costs AMD's
/// cores tens of cycles a row (a quarter of five lightings' time on an
/// EPYC).
#[inline(always)]
fn combine_row<const FIRST: bool, const SUB: bool>(
    r: &[i32],
    amb: &[i32],
    gain: i32,
    rank: i32,
    sum: &mut [i32],
    neg: &mut [i32],
    best: &mut [i32],
) {
    for ((((&v, &am), o), n), b) in r
        .iter()
        .zip(amb)
        .zip(sum.iter_mut())
        .zip(neg.iter_mut())
        .zip(best.iter_mut())
    {
        let v = if SUB { v - am } else { v };
        let m = v.abs();
        let add = (m * gain) >> GAIN_BITS;
        let key = (add << 6) | rank | i32::from(v < 0);
        let down = if v < 0 { add } else { 0 };
        if FIRST {
            *o = add - down;
            *n = down;
            *b = key;
        } else {
            *o += add - down;
            *n += down;
            *b = (*b).max(key);
        }
    }
}

/// Fixed-point bits of a gain: `GAIN_ONE` is 1.
const GAIN_BITS: u32 = 10;
const GAIN_ONE: i32 = 1 << GAIN_BITS;

/// Each image's gain from its noise level (median |sum|): the least noisy
/// image's level over its own, at most 1, so every term is in the least
/// noisy image's noise units and no sum grows (a term is at most its
/// `|v|`, and `|v| × GAIN_ONE` fits an `i32`: see [`MAX_RANK`]). A level of
/// 0 (an image without noise) counts as 1.
fn gains(medians: &[i32], out: &mut Vec<i32>) {
    let least = medians.iter().copied().min().unwrap_or(0).max(1);
    out.clear();
    out.extend(
        medians
            .iter()
            .map(|&m| ((least << GAIN_BITS) / m.max(1)).min(GAIN_ONE)),
    );
}

/// Samples in one strip of [`noise_median`]: 512, every second pixel of
/// about a row of a 1024-px image (its median within about 6 % on noise,
/// so that the lower percentiles of pure noise are not biased much low).
const STRIP: usize = 512;

/// An image's noise level as a median |response|. With `percentile` 0, the
/// median of all samples. Otherwise, as for one image's threshold
/// (`edges.noise_percentile`, `edges/noise.rs`): the samples are cut into
/// strips of [`STRIP`], and the level is that percentile of the strips'
/// medians — the sensor's noise, read where the image is least textured,
/// not raised by texture that covers most of a photograph. On noise alone
/// every strip measures the same and the two agree.
fn noise_median(samples: &mut [i32], strips: &mut Vec<i32>, percentile: f64) -> i32 {
    if percentile <= 0.0 || samples.len() < 2 * STRIP {
        return median(samples);
    }
    strips.clear();
    strips.extend(
        samples
            .chunks_mut(STRIP)
            .filter(|c| c.len() * 2 >= STRIP)
            .map(median),
    );
    let last = strips.len() - 1;
    let k = ((percentile.min(100.0) / 100.0) * last as f64).round() as usize;
    let (_, m, _) = strips.select_nth_unstable(k.min(last));
    *m
}

fn median(buf: &mut [i32]) -> i32 {
    if buf.is_empty() {
        return 0;
    }
    let mid = buf.len() / 2;
    let (_, m, _) = buf.select_nth_unstable(mid);
    *m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sum_is_of_the_strongest_terms_sign_times_the_gains() {
        let mut rng = crate::rng::SplitMix64::new(0x9E37_79B9_7F4A_7C15);
        let mut next = || (rng.next_u64() % 200_001) as i32 - 100_000;
        for _ in 0..200 {
            let r: Vec<i32> = (0..4).map(|_| next()).collect();
            let g: Vec<i32> = (0..4).map(|_| next().rem_euclid(GAIN_ONE + 1)).collect();
            let (mut sum, mut neg, mut best) = (vec![0], vec![0], vec![0]);
            for i in 0..4 {
                let sums = (&mut sum[..], &mut neg[..]);
                combine((i == 0, false), i, &r[i..=i], &[0], g[i], sums, &mut best);
            }
            let term = |i: usize| (i64::from(r[i].abs()) * i64::from(g[i])) >> GAIN_BITS;
            let of_sign = |down: bool| {
                (0..4)
                    .filter(|&i| (r[i] < 0) == down)
                    .map(term)
                    .sum::<i64>()
            };
            assert_eq!(i64::from(sum[0]), of_sign(false), "{r:?} {g:?}");
            assert_eq!(i64::from(neg[0]), of_sign(true), "{r:?} {g:?}");
            // The strongest term (the first of equals) gives the sign.
            let strongest = (0..4).rev().max_by_key(|&i| term(i)).unwrap();
            assert_eq!(best[0] & 1 != 0, r[strongest] < 0, "{r:?} {g:?}");
        }
    }

    #[test]
    fn gains_bring_each_image_to_the_least_noisy_ones_units() {
        let mut g = Vec::new();
        gains(&[40, 10, 20, 0], &mut g);
        // The least noisy level is 0, counted as 1.
        assert_eq!(g, [GAIN_ONE / 40, GAIN_ONE / 10, GAIN_ONE / 20, GAIN_ONE]);
        gains(&[40, 10, 20], &mut g);
        assert_eq!(g, [GAIN_ONE / 4, GAIN_ONE, GAIN_ONE / 2]);
        gains(&[], &mut g);
        assert!(g.is_empty());
    }

    #[test]
    fn sign_follows_the_strongest_image() {
        let (mut sum, mut neg, mut best) = (vec![0; 3], vec![0; 3], vec![0; 3]);
        for (i, r) in [[10, -3, 7], [-30, 1, -7]].iter().enumerate() {
            let sums = (&mut sum[..], &mut neg[..]);
            combine((i == 0, false), i, r, &[0; 3], GAIN_ONE, sums, &mut best);
        }
        assert_eq!((&sum[..], &neg[..]), (&[10, 1, 7][..], &[30, 3, 7][..]));
        // The sign of the strongest term; of the first of two as strong.
        let signs: Vec<bool> = best.iter().map(|b| b & 1 != 0).collect();
        assert_eq!(signs, [true, true, false]);
        // Only the terms of the strongest's sign are summed: the others
        // are another edge, or noise.
        let mut out = [0i16; 3];
        finish_row(&mut out, &sum, &neg, &best, 0);
        assert_eq!(out, [-30, -3, 7]);
    }

    #[test]
    fn noise_levels_of_noise_free_images_are_zero_and_gains_one() {
        // A flat image with one bright column: the median |sum| is 0.
        let img = GreyImage::new(
            64,
            64,
            (0..64 * 64)
                .map(|k| if k % 64 == 30 { 200 } else { 50 })
                .collect(),
        )
        .unwrap();
        let mut s = PhotoScratch::default();
        let mut out = Response::default();
        // A = 4, whose kernel's sum over a one-pixel line is 18 / 64.
        let p = EdgeParams {
            half_width: 4,
            ..EdgeParams::default()
        };
        combined_response_into(
            &[img.clone(), img],
            None,
            ScanDir::Horizontal,
            &p,
            &mut out,
            &mut s,
        )
        .unwrap();
        assert_eq!(s.medians, [0, 0]);
        assert_eq!(s.gains, [GAIN_ONE, GAIN_ONE]);
        // A one-pixel bright line: rising at 29, falling at 31, each
        // 150 · 18 / 64 grey levels in each image, summed.
        let one = 150.0 * 18.0 / 64.0;
        assert!((out.get(29, 10).unwrap() - 2.0 * one).abs() < 0.1);
        assert!((out.get(31, 10).unwrap() + 2.0 * one).abs() < 0.1);
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
        r.value(y * r.width + x)
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
                    assert_eq!(out, fresh);
                }
            }
        }
    }

    /// The combination equals the rule applied to each image's own
    /// response, pixel by pixel, for every half-width, both directions,
    /// with and without an ambient image, within the rounding of the
    /// stored unit.
    #[test]
    fn the_combination_equals_the_rule_on_each_images_response() {
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
        for a in 3..=7u32 {
            let p = EdgeParams {
                half_width: a,
                ..EdgeParams::default()
            };
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                for ambient in [Some(&amb), None] {
                    let c = combined_response(&imgs, ambient, dir, &p).unwrap();
                    let mut s = PhotoScratch::default();
                    let mut again = Response::default();
                    combined_response_into(&imgs, ambient, dir, &p, &mut again, &mut s).unwrap();
                    let singles: Vec<Response> = imgs
                        .iter()
                        .map(|m| edges::response(m, dir, a as usize).unwrap())
                        .collect();
                    let amb_r = ambient.map(|m| edges::response(m, dir, a as usize).unwrap());
                    for i in 0..150 * 50 {
                        // The sum of each sign, and the strongest gained
                        // term of each sign.
                        let (mut up, mut down, mut pos, mut neg) = (0f32, 0f32, 0f32, 0f32);
                        let mut none = false;
                        for (k, r) in singles.iter().enumerate() {
                            let mut v = r.value(i);
                            if let Some(ar) = &amb_r {
                                v -= ar.value(i);
                            }
                            none |= v.is_nan();
                            let t = v.abs() * s.gains[k] as f32 / GAIN_ONE as f32;
                            if v < 0.0 {
                                down += t;
                                neg = neg.max(t);
                            } else {
                                up += t;
                                pos = pos.max(t);
                            }
                        }
                        let got = c.value(i);
                        if none {
                            assert!(got.is_nan(), "A {a} {dir:?} {i}");
                        } else {
                            // Each image's sum at A = 6, 7 was rounded to its
                            // stored unit; the combination is rounded once.
                            let tol = c.scale() * 0.5 + 3.0 * singles[0].scale();
                            // The sign of the strongest term, and the sum of
                            // the terms of that sign, where the two signs'
                            // strongest terms are told apart.
                            if (pos - neg).abs() > tol {
                                assert_eq!(got < 0.0, neg > pos, "A {a} {dir:?} {i}");
                                let sum = if neg > pos { down } else { up };
                                assert!(
                                    (got.abs() - sum).abs() <= tol,
                                    "A {a} {dir:?} {i}: {got} vs {sum}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn invalid_pixels_give_no_response_around_them() {
        // A = 4: the kernel's reach is 4 px either side of the invalid pixel.
        let p = EdgeParams {
            half_width: 4,
            ..EdgeParams::default()
        };
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

#[cfg(test)]
mod calibration {
    //! The combination against noise itself: edge points at `z` sigmas on
    //! several images of pure noise must be no more common than the
    //! a-contrario table says they are on one image (module doc: a sum of
    //! magnitudes is stricter on noise than one image).
    use super::*;
    use crate::lines::nfa;
    use crate::rng::SplitMix64;

    fn noise_image(w: usize, h: usize, sigma: f64, seed: u64) -> GreyImage {
        let mut rng = SplitMix64::new(seed);
        let data = (0..w * h)
            .map(|_| (128.0 + sigma * rng.gauss()).round().clamp(0.0, 255.0) as u8)
            .collect();
        GreyImage::new(w, h, data).unwrap()
    }

    /// Edge points per pixel at `edges.noise_sigmas = z` (no floor, no
    /// `M` limit) in both scan directions, over what the table gives one
    /// image: `2 q_A(z)` (both polarities).
    fn ratio(images: &[GreyImage], ambient: Option<&GreyImage>, z: f64) -> f64 {
        let p = EdgeParams {
            noise_sigmas: z,
            floor: 0.0,
            per_region: 4096,
            ..EdgeParams::default()
        };
        let (w, h) = images[0].size();
        let mut points = 0;
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let r = combined_response(images, ambient, dir, &p).unwrap();
            points += edges::peaks(&r, &p).points.len();
        }
        let a = p.half_width as usize;
        let pixels = 2 * w * (h - 2 * a);
        points as f64 / pixels as f64 / (2.0 * nfa::q(a, z))
    }

    #[test]
    fn noise_passes_the_sigmas_no_more_often_than_from_one_image() {
        let (w, h) = (512, 512);
        let lit: Vec<GreyImage> = (0..4).map(|i| noise_image(w, h, 6.0, 7 + i)).collect();
        let amb = noise_image(w, h, 6.0, 99);
        // One image against the table: the yardstick (within the counts'
        // spread of 10–20 % and the table's own approximation).
        for z in [2.5, 3.0, 3.5] {
            let k = ratio(&lit[..1], None, z);
            assert!((0.3..=2.5).contains(&k), "one image, z {z}: {k:.2}");
        }
        for ambient in [None, Some(&amb)] {
            for z in [2.5, 3.0, 3.5] {
                let k = ratio(&lit, ambient, z);
                eprintln!(
                    "ambient {}, z {z}: {k:.3} × one image's rate",
                    ambient.is_some()
                );
                assert!(
                    k <= 1.0,
                    "ambient {}, z {z}: {k:.2} × one image's rate",
                    ambient.is_some()
                );
            }
        }
    }
}
