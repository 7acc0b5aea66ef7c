//! Gradient-orientation agreement along a line (the level-line alignment
//! of LSD and ELSED, contrast-invariant): a line keeps the parts of it
//! where, at most pixels, the image's gradient points across it.
//!
//! Why: the extractor's significance test counts response peaks measured
//! against the noise, which assumes noise between edges. Texture (gravel,
//! foliage, a carpet) is not noise: it is full of strong peaks of both
//! polarities, through which a track finds a straight enough path, and a
//! track that leaves its edge goes on through it. Along a true edge the
//! gradient is perpendicular to the line at nearly every pixel, whatever the
//! contrast; along a path through texture its direction is random, within
//! `±ALIGN_DEG` of the normal (either sign) at a quarter of the pixels.
//!
//! Samples: one a pixel along the line (the midpoints of `⌈length⌉` equal
//! steps), the Sobel gradient at the nearest pixel (it averages three pixels
//! along a near-axis edge, so faint edges in JPEG noise keep their
//! direction), on the image where it is largest when several lightings are
//! combined (an edge may be bright-on-dark under one light and dark-on-bright
//! under another, so either sign counts). Samples near the border or on an
//! invalid pixel (lens correction) are no evidence either way.
//!
//! A line whose aligned samples are as many as random directions would give
//! with a probability below `10^LOG10_SIGNIFICANT` (binomial tail, a quarter
//! a sample: the a-contrario test on orientation) is kept whole: a long
//! faint edge in strong noise, whose Sobel direction is off at many pixels,
//! is still far more aligned than chance. Any other line is cut where more
//! than [`GAP`] samples in a row are not aligned;
//! each part is kept when at least `min` of its samples are aligned and it
//! is at least `min_length` long. A part that reaches within [`GAP`]
//! samples of an end of the line keeps that endpoint (a corner, where the
//! gradient turns, does not shorten its edges).
//!
//! A direction is only as good as the gradient it comes from: where the
//! gradient is below `q / sin ALIGN_DEG`, a quantisation error of `q` grey
//! levels can turn it beyond the tolerance (LSD's argument for its
//! threshold ρ). A line whose mean gradient across it is below that,
//! with `q` one grey level (2.6 grey levels a pixel), lies on shading, a
//! faint cloud or faint print, and is dropped whatever its alignment. The
//! mean is taken along the whole line, not per sample: a faint edge in
//! noise (10 grey levels at a blur of σ 1.5 px has a slope of 2.7) dips
//! below it at single pixels but not on average. It is the gradient's
//! component across the line, not its magnitude: where a line crosses a
//! strong edge (a post in front of a faint shading boundary, a joint
//! between two faint pieces that CONNECT bridged), that edge's gradient
//! runs along the line and is no evidence for it. A gradient
//! above ρ may still be shading's, not the line's: what counts is the
//! gradient along the line less the shading beside it
//! ([`super::step`]).
//!
//! Under twice ρ a line needs more than that, because a faint straight
//! edge that nobody would draw (a door's panel line, wood grain, a tile
//! seam, texture a track ran along) has the same gradient as a faint edge
//! that matters:
//! - The shorter the line, the more gradient: its mean over `L` samples is
//!   as much evidence as `√L` samples' worth, so below [`SHORT`] px the bound
//!   is `ρ √(SHORT / L)` (at most twice ρ). Long faint edges keep ρ.
//! - Just above ρ ([`MARGINAL`]), the profile across it must be one step
//!   ([`super::step::step_share`] at least [`MIN_STEP_SHARE`]), not a thin
//!   ridge or valley.
//! - A line shorter than [`SHORT`] px whose step across it changes sign
//!   along it ([`super::step::Across::steady`] under [`MIN_STEADY`]) follows
//!   texture, not an edge.

use crate::{GreyImage, Point, Segment};

/// Largest angle (degrees) between the gradient and the line's normal at an
/// aligned pixel.
pub const ALIGN_DEG: f64 = 22.5;

/// A line this unlikely under random directions is kept whole (log10).
pub const LOG10_SIGNIFICANT: f64 = -5.0;

/// Least mean gradient across a line (grey levels a pixel),
/// [`min_slope`]: one grey level of quantisation over `sin ALIGN_DEG`.
pub fn min_slope() -> f64 {
    1.0 / ALIGN_DEG.to_radians().sin()
}

/// Below this length (px) a faint line needs a gradient above ρ
/// (module doc).
pub const SHORT: f64 = 100.0;
/// Under this many ρ a line's profile must be one step (module doc).
pub const MARGINAL: f64 = 1.15;
/// Least [`super::step::step_share`] of a line under [`MARGINAL`] ρ.
pub const MIN_STEP_SHARE: f64 = 0.3;
/// Least [`super::step::Across::steady`] of a faint line shorter than
/// [`SHORT`].
pub const MIN_STEADY: f64 = 0.3;

/// The least mean gradient of a line `len` px long under twice ρ
/// (module doc): `ρ √(SHORT / len)`, between ρ and 2 ρ.
pub fn min_slope_of_length(len: f64) -> f64 {
    let q = if len > 0.0 {
        (SHORT / len).sqrt().clamp(1.0, 2.0)
    } else {
        2.0
    };
    q * min_slope()
}

/// Whether a line of mean gradient `g` (ρ ≤ `g` < 2 ρ) and length `len`,
/// with `across` it ([`super::step::across`]; `None`: no evidence), is
/// kept (module doc); the profiles are read only if the length leaves it
/// open.
pub fn faint_line_kept(
    g: f64,
    len: f64,
    across: impl FnOnce() -> Option<super::step::Across>,
) -> bool {
    let rho = min_slope();
    if g < min_slope_of_length(len) {
        return false;
    }
    let Some(a) = across() else {
        return true;
    };
    g - a.shading >= rho
        && (g >= MARGINAL * rho || a.step_share >= MIN_STEP_SHARE)
        && (len >= SHORT || a.steady >= MIN_STEADY)
}

/// Non-aligned samples in a row that a part may hold.
pub const GAP: usize = 3;

/// Per sample of a line: aligned, not aligned, or no evidence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sample {
    Aligned,
    Across,
    Unknown,
}

/// The samples of a line (module doc), one a pixel; returns the mean
/// gradient across it (grey levels a pixel) of the samples with evidence.
pub fn samples(images: &[GreyImage], s: &Segment, out: &mut Vec<Sample>) -> f64 {
    out.clear();
    let len = s.length();
    let Some(first) = images.first() else {
        return 0.0;
    };
    let (w, h) = first.size();
    if !(len.is_finite() && len > 0.0) {
        return 0.0;
    }
    if images.len() == 1 && first.valid_mask().is_none() {
        return samples_of_one(first, s, len, out);
    }
    let (mut mag, mut counted) = (0.0, 0usize);
    let (dx, dy) = ((s.b.x - s.a.x) / len, (s.b.y - s.a.y) / len);
    let c2 = ALIGN_DEG.to_radians().cos().powi(2);
    let n = len.ceil().max(1.0);
    for k in 0..n as usize {
        let t = (k as f64 + 0.5) / n * len;
        let (x, y) = ((s.a.x + dx * t).round(), (s.a.y + dy * t).round());
        if !(x >= 1.0 && y >= 1.0 && x < w as f64 - 1.0 && y < h as f64 - 1.0) {
            out.push(Sample::Unknown);
            continue;
        }
        let (x, y) = (x as usize, y as usize);
        let mut best: Option<(f64, f64)> = None;
        let mut valid = true;
        for img in images {
            if img.size() != (w, h) {
                continue;
            }
            if img.valid_mask().is_some()
                && !(y - 1..=y + 1).all(|v| (x - 1..=x + 1).all(|u| img.is_valid(u, v)))
            {
                valid = false;
                break;
            }
            // (Inside: `1 ≤ x < w − 1`, `1 ≤ y < h − 1`.)
            let Some((gx, gy)) = sobel(img.data(), w, y * w + x) else {
                continue;
            };
            if best.is_none_or(|(bx, by)| gx * gx + gy * gy > bx * bx + by * by) {
                best = Some((gx, gy));
            }
        }
        let (Some(g), true) = (best, valid) else {
            out.push(Sample::Unknown);
            continue;
        };
        let (sample, m) = classify(g, (dx, dy), c2);
        mag += m;
        counted += 1;
        out.push(sample);
    }
    mean_slope(mag, counted)
}

/// The Sobel gradient `(gx, gy)` at index `at` of an image `d`, `w` px a
/// row, whose 3 × 3 window the caller knows to be inside it (`None` only
/// should it not be).
#[inline(always)]
fn sobel(d: &[u8], w: usize, at: usize) -> Option<(f64, f64)> {
    let (r0, r1, r2) = (
        d.get(at - w - 1..at - w + 2)?,
        d.get(at - 1..at + 2)?,
        d.get(at + w - 1..at + w + 2)?,
    );
    let p = |r: &[u8], i: usize| i32::from(r[i]);
    let gx = p(r0, 2) + 2 * p(r1, 2) + p(r2, 2) - p(r0, 0) - 2 * p(r1, 0) - p(r2, 0);
    let gy = p(r2, 0) + 2 * p(r2, 1) + p(r2, 2) - p(r0, 0) - 2 * p(r0, 1) - p(r0, 2);
    Some((f64::from(gx), f64::from(gy)))
}

/// A sample of gradient `g` on a line of unit direction `d` (module doc):
/// aligned when the gradient is within [`ALIGN_DEG`] of across the line
/// (`c2` its cosine squared), and the gradient's component across it.
#[inline(always)]
fn classify((gx, gy): (f64, f64), (dx, dy): (f64, f64), c2: f64) -> (Sample, f64) {
    let g2 = gx * gx + gy * gy;
    let across = -gx * dy + gy * dx;
    // (`&`, not `&&`: no branch on a sample that texture makes random.)
    let sample = if (g2 > 0.0) & (across * across >= c2 * g2) {
        Sample::Aligned
    } else {
        Sample::Across
    };
    (sample, across.abs())
}

/// The mean slope (grey levels a pixel) of `counted` samples whose Sobel
/// gradients across the line sum to `mag` (Sobel's sum is 8 times the
/// slope); 0 for none.
fn mean_slope(mag: f64, counted: usize) -> f64 {
    if counted > 0 {
        mag / (8.0 * counted as f64)
    } else {
        0.0
    }
}

/// [`samples`] on one image without invalid pixels, `len` the length of
/// `s` (finite, positive): the same samples, read with one bounds test a
/// sample.
fn samples_of_one(img: &GreyImage, s: &Segment, len: f64, out: &mut Vec<Sample>) -> f64 {
    let (w, h) = img.size();
    let d = img.data();
    let (mut mag, mut counted) = (0.0, 0usize);
    let (dx, dy) = ((s.b.x - s.a.x) / len, (s.b.y - s.a.y) / len);
    let c2 = ALIGN_DEG.to_radians().cos().powi(2);
    let n = len.ceil().max(1.0);
    let (wf, hf) = (w as f64, h as f64);
    // Each sample is written in place (no call in the loop keeps the sums
    // in registers); `Unknown` stays where there is no evidence.
    out.resize(n as usize, Sample::Unknown);
    for (k, o) in out.iter_mut().enumerate() {
        let t = (k as f64 + 0.5) / n * len;
        let (x, y) = (s.a.x + dx * t, s.a.y + dy * t);
        // `x.round()` (halves away from 0) is in `1..w - 1` exactly when
        // `0.5 ≤ x < w − 1.5`, and there it is `x + 0.5` truncated (the sum
        // is exact below 2⁵¹, or rounds to the same whole number): the
        // library's `round` is a call without SSE 4.1. (Truncated to an
        // `i64`, one instruction, rather than a `usize`.)
        if !(x >= 0.5 && y >= 0.5 && x < wf - 1.5 && y < hf - 1.5) {
            continue;
        }
        let (x, y) = ((x + 0.5) as i64 as usize, (y + 0.5) as i64 as usize);
        let Some(g) = sobel(d, w, y * w + x) else {
            continue;
        };
        let (sample, m) = classify(g, (dx, dy), c2);
        mag += m;
        counted += 1;
        *o = sample;
    }
    mean_slope(mag, counted)
}

/// The fraction of a line's samples with evidence that are aligned; `None`
/// when none has evidence.
pub fn aligned_fraction(images: &[GreyImage], s: &Segment) -> Option<f64> {
    let mut v = Vec::new();
    samples(images, s, &mut v);
    let counted = v.iter().filter(|x| **x != Sample::Unknown).count();
    let aligned = v.iter().filter(|x| **x == Sample::Aligned).count();
    (counted > 0).then(|| aligned as f64 / counted as f64)
}

/// The parts of `s` to keep, by the samples (module doc): `(t0, t1)` as
/// fractions of its length.
fn parts(v: &[Sample], min: f64, out: &mut Vec<(f64, f64)>) {
    out.clear();
    let n = v.len();
    let mut k = 0;
    while k < n {
        // Skip a run of misaligned samples; a part starts at evidence for it.
        if v[k] == Sample::Across {
            k += 1;
            continue;
        }
        let start = k;
        let (mut last, mut run) = (k, 0usize);
        let (mut aligned, mut counted) = (0usize, 0usize);
        while k < n {
            match v[k] {
                Sample::Across => {
                    run += 1;
                    if run > GAP {
                        break;
                    }
                    counted += 1;
                }
                s => {
                    run = 0;
                    last = k;
                    if s == Sample::Aligned {
                        aligned += 1;
                        counted += 1;
                    }
                }
            }
            k += 1;
        }
        // The samples past `last` are misaligned: not part of this one.
        counted -= run.min(counted);
        if counted == 0 || aligned as f64 >= min * counted as f64 {
            let t0 = if start <= GAP {
                0.0
            } else {
                start as f64 / n as f64
            };
            let t1 = if last + 1 + GAP >= n {
                1.0
            } else {
                (last + 1) as f64 / n as f64
            };
            out.push((t0, t1));
        }
    }
}

/// The samples with evidence and the aligned ones, in one pass.
fn counts(v: &[Sample]) -> (usize, usize) {
    v.iter().fold((0, 0), |(c, a), x| {
        (
            c + usize::from(*x != Sample::Unknown),
            a + usize::from(*x == Sample::Aligned),
        )
    })
}

/// Reusable buffers of [`keep_aligned`] (a warm workspace allocates
/// nothing).
#[derive(Clone, Debug, Default)]
pub struct AlignScratch {
    v: Vec<Sample>,
    ps: Vec<(f64, f64)>,
    out: Vec<Segment>,
}

/// Keeps the aligned parts of the lines at least `min_length` long
/// (module doc). `min` ≤ 0 keeps every line as it is.
pub fn keep_aligned(
    images: &[GreyImage],
    lines: &mut Vec<Segment>,
    min: f64,
    min_length: f64,
    scratch: &mut AlignScratch,
) {
    if min.is_nan() || min <= 0.0 || images.is_empty() {
        return;
    }
    let AlignScratch { v, ps, out } = scratch;
    out.clear();
    for s in lines.iter() {
        // The profiles across a line are read only where they can decide:
        // at twice ρ, the image beside the line would have to slope at half
        // the line's own gradient on both sides, a blurred edge's shape
        // rather than shading's.
        let g = samples(images, s, v);
        if g < min_slope()
            || (g < 2.0 * min_slope()
                && !faint_line_kept(g, s.length(), || super::step::across(images, s)))
        {
            continue;
        }
        let (counted, aligned) = counts(v);
        if counted == 0 {
            out.push(*s);
            continue;
        }
        parts(v, min, ps);
        // A line that is one part from end to end is kept whole either way:
        // the test against chance (a logarithm a term) is left unread.
        if ps.as_slice() == [(0.0, 1.0)]
            || super::nfa::log10_binomial_tail(counted, aligned, 0.25) <= LOG10_SIGNIFICANT
        {
            out.push(*s);
            continue;
        }
        for &(t0, t1) in ps.iter() {
            if t0 == 0.0 && t1 == 1.0 {
                out.push(*s);
                continue;
            }
            let at = |t: f64| Point::new(s.a.x + (s.b.x - s.a.x) * t, s.a.y + (s.b.y - s.a.y) * t);
            let mut part = *s;
            part.a = at(t0);
            part.b = at(t1);
            if part.length() >= min_length {
                out.push(part);
            }
        }
    }
    std::mem::swap(lines, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> Segment {
        Segment::new(Point::new(x0, y0), Point::new(x1, y1))
    }

    #[test]
    fn an_edge_is_aligned_and_texture_is_not() {
        let (w, h) = (64, 64);
        let step = GreyImage::new(
            w,
            h,
            (0..w * h)
                .map(|i| if i % w < 32 { 50 } else { 150 })
                .collect(),
        )
        .unwrap();
        let s = line(31.5, 5.0, 31.5, 58.0);
        assert_eq!(aligned_fraction(std::slice::from_ref(&step), &s), Some(1.0));
        let mut r = crate::rng::SplitMix64::new(3);
        let tex = GreyImage::new(
            w,
            h,
            (0..w * h).map(|_| (r.uniform() * 255.0) as u8).collect(),
        )
        .unwrap();
        let f = aligned_fraction(std::slice::from_ref(&tex), &s).unwrap();
        assert!(f < 0.5, "{f}");
        let mut lines = vec![s];
        keep_aligned(&[tex], &mut lines, 0.6, 8.0, &mut AlignScratch::default());
        assert!(lines.is_empty(), "{lines:?}");
        let mut lines = vec![s];
        keep_aligned(&[step], &mut lines, 0.6, 8.0, &mut AlignScratch::default());
        assert_eq!(lines, vec![s]);
    }

    #[test]
    fn a_line_on_shading_is_dropped_and_a_faint_step_is_kept() {
        // Shading of one grey level a pixel: the gradient is across the
        // line everywhere, but too weak for its direction to mean anything.
        let (w, h) = (64, 64);
        let img = |f: &dyn Fn(usize) -> u8| {
            GreyImage::new(w, h, (0..w * h).map(|i| f(i % w)).collect()).unwrap()
        };
        let ramp = img(&|x| 100 + x as u8);
        let s = line(31.5, 5.0, 31.5, 58.0);
        assert_eq!(aligned_fraction(std::slice::from_ref(&ramp), &s), Some(1.0));
        let mut lines = vec![s];
        keep_aligned(&[ramp], &mut lines, 0.9, 8.0, &mut AlignScratch::default());
        assert!(lines.is_empty(), "{lines:?}");
        // A step of 10 grey levels is a line.
        let step = img(&|x| if x < 32 { 100 } else { 110 });
        let mut lines = vec![s];
        keep_aligned(&[step], &mut lines, 0.9, 8.0, &mut AlignScratch::default());
        assert_eq!(lines, vec![s]);
    }

    #[test]
    fn a_line_on_a_soft_shadow_is_dropped() {
        // A penumbra of 60 grey levels over σ 8 px: its gradient along the
        // line is above ρ and across it everywhere, but nearly as steep
        // 2-6 px beside it: no step of its own.
        let (w, h) = (64, 64);
        let px = (0..w * h)
            .map(|i| {
                let x = (i % w) as f64;
                (100.0 + 60.0 / (1.0 + (-(x - 31.5) / 4.8).exp())).round() as u8
            })
            .collect();
        let img = GreyImage::new(w, h, px).unwrap();
        let s = line(31.5, 5.0, 31.5, 58.0);
        let mut v = Vec::new();
        assert!(samples(std::slice::from_ref(&img), &s, &mut v) > min_slope());
        assert_eq!(aligned_fraction(std::slice::from_ref(&img), &s), Some(1.0));
        let mut lines = vec![s];
        keep_aligned(&[img], &mut lines, 0.9, 8.0, &mut AlignScratch::default());
        assert!(lines.is_empty(), "{lines:?}");
    }

    /// A 64 × 160 image whose grey level at `(x, y)` is `f(x, y)`.
    fn tall(f: &dyn Fn(usize, usize) -> u8) -> GreyImage {
        let (w, h) = (64, 160);
        GreyImage::new(w, h, (0..w * h).map(|i| f(i % w, i / w)).collect()).unwrap()
    }

    fn kept(img: &GreyImage, s: Segment) -> bool {
        let mut lines = vec![s];
        keep_aligned(
            std::slice::from_ref(img),
            &mut lines,
            0.9,
            8.0,
            &mut AlignScratch::default(),
        );
        lines == vec![s]
    }

    /// 6 grey levels on even rows, 5 on odd ones: a Sobel gradient of 2.75
    /// grey levels a pixel at every row, just above ρ.
    fn faint(y: usize) -> u8 {
        100 - 6 + (y % 2) as u8
    }

    #[test]
    fn a_short_faint_line_needs_more_gradient_than_a_long_one() {
        let step = tall(&|x, y| if x < 32 { 100 } else { faint(y) });
        let mut v = Vec::new();
        let long = line(32.0, 5.0, 32.0, 150.0);
        let g = samples(std::slice::from_ref(&step), &long, &mut v);
        assert!((g - 2.75).abs() < 1e-9 && g < MARGINAL * min_slope(), "{g}");
        assert!(kept(&step, long));
        // A piece of it 40 px long: as steep, and as clean a step.
        assert!(!kept(&step, line(32.0, 5.0, 32.0, 45.0)));
        assert!(min_slope_of_length(40.0) > g);
        assert_eq!(min_slope_of_length(SHORT), min_slope());
        assert_eq!(min_slope_of_length(1.0), 2.0 * min_slope());
    }

    #[test]
    fn strong_edges_crossing_a_faint_line_are_no_evidence_for_it() {
        // A vertical step of 4 grey levels (a slope of 2, under ρ), crossed
        // every 20 rows by a dark bar 4 rows tall across the whole image
        // (posts in front of a faint shading boundary): the bars' gradient
        // runs along the line, and only its component across counts.
        let s = line(32.0, 5.0, 32.0, 150.0);
        let plain = tall(&|x, _| if x < 32 { 100 } else { 104 });
        let barred = tall(&|x, y| {
            let dark = if y % 20 < 4 { 60 } else { 0 };
            (if x < 32 { 100 } else { 104 }) - dark
        });
        let mut v = Vec::new();
        let g = samples(std::slice::from_ref(&barred), &s, &mut v);
        assert!((g - 2.0).abs() < 1e-9, "{g}");
        assert_eq!(g, samples(std::slice::from_ref(&plain), &s, &mut v));
        // Most samples are aligned: the line is not cut at the bars.
        assert!(aligned_fraction(std::slice::from_ref(&barred), &s).unwrap() > 0.7);
        assert!(!kept(&plain, s));
        assert!(!kept(&barred, s));
        // A step of 8 (a slope of 4) is a line, bars or not.
        let strong = tall(&|x, y| {
            let dark = if y % 20 < 4 { 60 } else { 0 };
            (if x < 32 { 100 } else { 108 }) - dark
        });
        assert!(kept(&strong, s));
    }

    #[test]
    fn a_thin_valley_as_faint_as_an_edge_is_dropped() {
        // Two columns darker: the same Sobel gradient at the line as the
        // faint step above, but no step across it.
        let valley = tall(&|x, y| if (32..34).contains(&x) { faint(y) } else { 100 });
        let s = line(32.0, 5.0, 32.0, 150.0);
        let mut v = Vec::new();
        let g = samples(std::slice::from_ref(&valley), &s, &mut v);
        assert!((g - 2.75).abs() < 1e-9, "{g}");
        assert!(!kept(&valley, s));
        // The same valley twice as deep is strong enough to be a line (a
        // wire, a grout line).
        let deep = tall(&|x, y| {
            if (32..34).contains(&x) {
                2 * faint(y) - 100
            } else {
                100
            }
        });
        assert!(kept(&deep, s));
    }

    #[test]
    fn a_short_line_whose_step_changes_sign_along_it_is_dropped() {
        // A vertical boundary that is brighter on the right for 6 rows,
        // darker for the next 6: texture's, not an edge's.
        let zigzag = tall(&|x, y| match (x < 32, (y / 6) % 2) {
            (true, _) => 100,
            (false, 0) => 108,
            (false, _) => 92,
        });
        let s = line(32.0, 5.0, 32.0, 95.0);
        let a = super::super::step::across(std::slice::from_ref(&zigzag), &s).unwrap();
        assert!(a.steady < MIN_STEADY, "{a:?}");
        let mut v = Vec::new();
        let g = samples(std::slice::from_ref(&zigzag), &s, &mut v);
        assert!(
            g >= min_slope_of_length(s.length()) && g < 2.0 * min_slope(),
            "{g}"
        );
        assert!(!kept(&zigzag, s));
        // The same boundary with one sign is an edge.
        let edge = tall(&|x, _| if x < 32 { 100 } else { 108 });
        assert!(kept(&edge, s));
    }

    #[test]
    fn a_line_running_on_past_its_edge_is_cut_there() {
        // A vertical step on rows 0..16 only; below it, texture: the line
        // as a whole is not beyond chance, and its edge part is kept.
        let (w, h) = (64, 64);
        let mut r = crate::rng::SplitMix64::new(5);
        let px: Vec<u8> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if y < 16 {
                    if x < 32 { 50 } else { 150 }
                } else {
                    (r.uniform() * 255.0) as u8
                }
            })
            .collect();
        let img = GreyImage::new(w, h, px).unwrap();
        // (0.9: the default; at 0.6 a stretch of this
        // texture, 11 of 17 aligned, would pass too.)
        let mut lines = vec![line(31.5, 2.0, 31.5, 60.0)];
        keep_aligned(&[img], &mut lines, 0.9, 8.0, &mut AlignScratch::default());
        assert_eq!(lines.len(), 1, "{lines:?}");
        let l = lines[0];
        assert_eq!(l.a, Point::new(31.5, 2.0));
        assert!((l.b.y - 16.0).abs() < 3.0, "{l:?}");
    }
}
