//! The shading under a line: a line is kept only where its gradient
//! exceeds the slope of the image beside it by at least LSD's ρ
//! ([`super::align::min_slope`]).
//!
//! Why: ρ on the gradient along a line ([`super::align::keep_aligned`])
//! drops lines on flat grey, but not lines on shading: a soft shadow, a
//! wall lit from one side or the fall-off of a lamp has a gradient above ρ,
//! steady in direction, for tens of pixels across, and a track finds a
//! straight path anywhere on it. What makes an edge an edge is that its
//! gradient is a ridge across the line, not a plateau: the grey level
//! changes at the line more than on either side of it. The quantisation
//! argument behind ρ then applies to what the line adds to the shading.
//!
//! The gradient is the line's mean Sobel gradient across it (as for ρ); the shading
//! is read from the image's profile across the line: grey levels at
//! whole-pixel offsets `-REACH..=REACH` along the normal (bilinear), one
//! profile a pixel along the line up to [`PROFILES`] spread evenly over it,
//! averaged (noise and texture that the
//! line does not follow cancel); the mean slope from [`CORE`] to [`REACH`]
//! px out, in the direction of the profile's steepest step within [`CORE`]
//! px of the line, on each side; the lesser side counts (a neighbouring
//! edge, a window frame's other side, raises one side only; shading raises
//! both). The step itself is not compared with ρ: averaged along a long
//! line that is not exactly parallel to its edge, or on a slightly curved
//! edge, the profile's step is smeared (the synthetic yard lost faint true
//! edges so), while the Sobel gradient is read pixel by pixel. A line
//! without one whole profile inside the image is no evidence either way.
//!
//! The same profiles say two more things about a faint line
//! ([`super::align::keep_aligned`] decides with them):
//! - [`step_share`]: how much of the profile's change near the line is one
//!   step. A faint edge is a step; a door's panel line or a tile seam is a
//!   thin ridge or valley, two opposite steps whose gradient is as strong
//!   as a faint edge's, with no net step across.
//! - [`Across::steady`]: whether the step at the line keeps its sign from
//!   profile to profile. Along an edge it does; a line that follows texture
//!   (streaks on concrete, a shadow through foliage) has a strong gradient
//!   at every pixel, but its sides change along it, and the steps cancel.
//!   Read on single profiles at the line (±1 px), not on the mean profile's
//!   steepest step, so that a thin line, whose steepest step may fall on
//!   either flank, is not taken for texture.

use crate::{GreyImage, Segment};

/// Profile half-width (px): beyond a blurred edge's reach (σ ≤ 1.5 px),
/// within a soft shadow's.
pub const REACH: usize = 6;
/// At most this many profiles are averaged along a line: enough to
/// average out noise and texture the line does not follow (the slope
/// beside it is a difference of means over 4 px), and the cost stays that
/// of a short line whatever the length.
pub const PROFILES: usize = 16;
/// The step is looked for within this many px of the line (the line's
/// position error after the refit is under one pixel).
pub const CORE: usize = 2;
/// [`step_share`] reads this many px to either side: past a blurred
/// edge's ramp, and past both flanks of a thin ridge.
pub const SHARE_REACH: usize = 3;

/// The profiles across a line on one image (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// The mean profile: `2 REACH + 1` grey levels from the side of
    /// `-normal` to `+normal`.
    pub mean: [f64; 2 * REACH + 1],
    /// `|Σ d| / Σ |d|` over the profiles of their step across the line,
    /// `d = p[REACH + 1] - p[REACH - 1]`: 1 when every step has one sign,
    /// near 0 when they cancel; 1 when there is no step at all.
    pub steady: f64,
}

/// The profiles across `s` on `img` (module doc); `None` when no profile
/// lies wholly inside (and on valid pixels).
pub fn profile(img: &GreyImage, s: &Segment) -> Option<Profile> {
    let len = s.length();
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    let (w, h) = img.size();
    let d = img.data();
    let (dx, dy) = ((s.b.x - s.a.x) / len, (s.b.y - s.a.y) / len);
    let (nx, ny) = (-dy, dx);
    let at = |x: f64, y: f64| -> Option<f64> {
        if !(x >= 0.0 && y >= 0.0 && x < w as f64 - 1.0 && y < h as f64 - 1.0) {
            return None;
        }
        // (Truncation is the floor here, without a library call.)
        let (x0, y0) = (x as usize, y as usize);
        if img.valid_mask().is_some()
            && !(img.is_valid(x0, y0)
                && img.is_valid(x0 + 1, y0)
                && img.is_valid(x0, y0 + 1)
                && img.is_valid(x0 + 1, y0 + 1))
        {
            return None;
        }
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let i = y0 * w + x0;
        let (Some(&[p00, p10]), Some(&[p01, p11])) = (d.get(i..i + 2), d.get(i + w..i + w + 2))
        else {
            return None;
        };
        let p = f64::from;
        Some(
            (p(p00) * (1.0 - fx) + p(p10) * fx) * (1.0 - fy)
                + (p(p01) * (1.0 - fx) + p(p11) * fx) * fy,
        )
    };
    let mut sum = [0.0; 2 * REACH + 1];
    let mut p = [0.0; 2 * REACH + 1];
    let mut count = 0usize;
    let (mut signed, mut size) = (0.0, 0.0);
    // Profiles spread evenly along the line, at most PROFILES of them.
    let n = len.ceil().clamp(1.0, PROFILES as f64);
    'sample: for k in 0..n as usize {
        let t = (k as f64 + 0.5) / n * len;
        let (x, y) = (s.a.x + dx * t, s.a.y + dy * t);
        for (j, v) in p.iter_mut().enumerate() {
            let o = j as f64 - REACH as f64;
            match at(x + o * nx, y + o * ny) {
                Some(g) => *v = g,
                None => continue 'sample,
            }
        }
        for (a, v) in sum.iter_mut().zip(&p) {
            *a += v;
        }
        let d = p[REACH + 1] - p[REACH - 1];
        signed += d;
        size += d.abs();
        count += 1;
    }
    (count > 0).then(|| Profile {
        mean: sum.map(|v| v / count as f64),
        steady: if size > 0.0 {
            f64::abs(signed) / size
        } else {
            1.0
        },
    })
}

/// The mean profile across `s` on `img` ([`profile`]).
pub fn mean_profile(img: &GreyImage, s: &Segment) -> Option<[f64; 2 * REACH + 1]> {
    profile(img, s).map(|p| p.mean)
}

/// The shading under a line, from its mean profile (module doc): the mean
/// slope beside the line in the direction of its steepest step, on the
/// lesser side, at least 0 (grey levels a pixel).
pub fn shading(m: &[f64; 2 * REACH + 1]) -> f64 {
    let r = REACH;
    let diff = |j: usize| m[j + 1] - m[j];
    let (mut step, mut sign) = (0.0, 1.0);
    for j in r - CORE..r + CORE {
        if diff(j).abs() > step {
            step = diff(j).abs();
            sign = diff(j).signum();
        }
    }
    let beside = |js: std::ops::Range<usize>| {
        let n = js.len() as f64;
        js.map(|j| sign * diff(j)).sum::<f64>() / n
    };
    beside(0..r - CORE).min(beside(r + CORE..2 * r)).max(0.0)
}

/// How much of a mean profile's change within [`SHARE_REACH`] px of the
/// line is one step (module doc): `|m[+k] - m[-k]|` over the sum of the
/// 1-px changes between; 1 for a monotone step, near 0 for a thin ridge or
/// valley; 1 on flat grey (no evidence).
pub fn step_share(m: &[f64; 2 * REACH + 1]) -> f64 {
    let (r, k) = (REACH, SHARE_REACH);
    let total: f64 = (r - k..r + k).map(|j| (m[j + 1] - m[j]).abs()).sum();
    if total > 0.0 {
        (m[r + k] - m[r - k]).abs() / total
    } else {
        1.0
    }
}

/// What the profiles across a line say, over several lightings (the one
/// it is an edge in counts): the least [`shading`], the greatest
/// [`step_share`] and the greatest [`Profile::steady`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Across {
    pub shading: f64,
    pub step_share: f64,
    pub steady: f64,
}

/// [`Across`] for `s` over `images`; `None` when no image holds a whole
/// profile of it.
pub fn across(images: &[GreyImage], s: &Segment) -> Option<Across> {
    images
        .iter()
        .filter_map(|img| profile(img, s))
        .map(|p| Across {
            shading: shading(&p.mean),
            step_share: step_share(&p.mean),
            steady: p.steady,
        })
        .reduce(|a, b| Across {
            shading: a.shading.min(b.shading),
            step_share: a.step_share.max(b.step_share),
            steady: a.steady.max(b.steady),
        })
}

/// The least [`shading`] under `s` over `images` ([`across`]).
pub fn least_shading(images: &[GreyImage], s: &Segment) -> Option<f64> {
    across(images, s).map(|a| a.shading)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point;

    fn img(f: &dyn Fn(f64) -> f64) -> GreyImage {
        let (w, h) = (64, 64);
        GreyImage::new(
            w,
            h,
            (0..w * h)
                .map(|i| f((i % w) as f64).round().clamp(0.0, 255.0) as u8)
                .collect(),
        )
        .unwrap()
    }

    fn vertical() -> Segment {
        Segment::new(Point::new(31.5, 5.0), Point::new(31.5, 58.0))
    }

    /// A step of `c` grey levels at x = 31.5 blurred over `sigma` px
    /// (logistic, close to a Gaussian blur), on a ramp of `slope`.
    fn edge(c: f64, sigma: f64, slope: f64) -> GreyImage {
        img(&|x| 100.0 + slope * x + c / (1.0 + (-(x - 31.5) / (0.6 * sigma)).exp()))
    }

    #[test]
    fn a_soft_shadow_is_shading_and_a_sharp_edge_is_not() {
        let s = vertical();
        let sh = |img: &GreyImage| least_shading(std::slice::from_ref(img), &s).unwrap();
        // 12 grey levels, σ 1.5 px: a faint edge in a photograph.
        assert!(sh(&edge(12.0, 1.5, 0.0)) < 0.5);
        // The same on shading of 1.5 grey levels a pixel: that shading.
        let v = sh(&edge(12.0, 1.5, 1.5));
        assert!((v - 1.5).abs() < 0.6, "{v}");
        // A shadow's penumbra: 60 grey levels over σ 8 px. Its gradient at
        // the line is 3 grey levels a pixel, and above 2 beside it.
        let soft = edge(60.0, 8.0, 0.0);
        let m = mean_profile(&soft, &s).unwrap();
        assert!((m[REACH + 1] - m[REACH - 1]).abs() / 2.0 > 2.6, "{m:?}");
        assert!(sh(&soft) > 2.0, "{}", sh(&soft));
        // A steady ramp of 3 grey levels a pixel.
        assert!((sh(&img(&|x| 50.0 + 3.0 * x)) - 3.0).abs() < 0.1);
    }

    #[test]
    fn a_neighbouring_edge_on_one_side_does_not_count_as_shading() {
        // A bar 4 px wide: steps at 31.5 and 35.5.
        let bar = img(&|x| {
            if (32.0..36.0).contains(&x) {
                140.0
            } else {
                100.0
            }
        });
        assert_eq!(least_shading(&[bar], &vertical()), Some(0.0));
    }

    #[test]
    fn a_line_along_the_border_is_no_evidence() {
        let s = Segment::new(Point::new(2.0, 5.0), Point::new(2.0, 58.0));
        assert!(mean_profile(&edge(60.0, 8.0, 0.0), &s).is_none());
        assert_eq!(least_shading(&[edge(60.0, 8.0, 0.0)], &s), None);
    }
}
