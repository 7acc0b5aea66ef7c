//! Refitting each line on the image across it (the thesis's §7.1):
//! the step after CONNECT that places a line where the image says its edge
//! is, rather than where the scan-direction points put it.
//!
//! Why: the tracker's points are peaks of a kernel along the scan. For a
//! line 22.5–45° from its scan the edge's profile along the scan is
//! stretched by up to 2.6 times, and CONNECT then averages that version
//! with the other scan's (length-weighted). A kernel across the line sees
//! the edge's true profile, whatever its direction.
//!
//! The method, for a segment:
//! - It is read on the scan lines of the image axis nearer its normal
//!   (rows for a line nearer the vertical, columns otherwise), from
//!   `TRIM` px of line after its start to `TRIM` px before its end. On
//!   each, the image is sampled at `2R + 1` points one pixel apart across
//!   the line (`√(1 + slope²)` apart along the scan line, interpolated
//!   linearly along it), centred on the line. The scan lines are split
//!   into blocks of about `BLOCK` px of line whose profiles are summed
//!   (the edge averaged along its length, as the tracker's fit averages
//!   its points). A block with a sample outside the image, or next to an
//!   invalid pixel of a lens-corrected one, is left out.
//! - The profiles are differentiated across the line with Lee's kernel of
//!   half-width `KERNEL_A` (narrower than the edge stage's default 4, so
//!   that a second edge 4–8 px away pulls less). The polarity is that of
//!   the whole segment's summed profile at the line.
//! - In each block the peak of that polarity nearest the line, within
//!   `REACH` px, gives a point (parabolic subpixel position); the line
//!   is fitted to the points and the segment's ends are projected onto it.
//!   Each point weighs the square of its peak's derivative: under noise of
//!   one level a point's position varies as (noise / edge slope)², so a
//!   block where the edge fades (vignetting, a spot light's falloff, a
//!   face lit at a grazing angle) counts for what it is worth.
//! - A segment with fewer than `MIN_BLOCKS` blocks (under about 52 px),
//!   or whose blocks found a peak in fewer than half, keeps its line: a fit
//!   to a few block points has a worse direction than the tracker's fit to
//!   one point per scan line.
//! - With several lightings the image is, per segment, the one with the
//!   strongest edge at the line (the derivative of profiles summed on
//!   eight scan lines).
//!
//! How it was chosen: on the cube family, then checked on the yard family
//! (docs/llv.md, "Measurements behind the design"): only segments of
//! `MIN_BLOCKS` blocks and more are refitted (the direction of short ones
//! got worse), samples on scan lines interpolated along them only keep most
//! of the gain at a third of the cost of bilinear ones, and the squared
//! derivative as weight helps where edges fade along their length (the
//! yard's), not where they do not (the cubes').
//!
//! - **Ghosts.** A line the refit cannot place because fewer than half its
//!   blocks have an edge of either polarity within `REACH` is not on an
//!   edge along most of its length. Where it also runs beside a longer line
//!   at under [`GHOST_DEG`], touching it at one end and leaving it by a few
//!   pixels at the other, it is a second track of that line's edge that
//!   drifted off it (a line 22–30° from a scan direction is found in both
//!   scans, and the one along its stretched profile wanders), which CONNECT
//!   does not merge because it is not on the same line: [`drop_ghosts`]
//!   removes it. Either polarity counts, so that an edge whose contrast
//!   changes sign along it (a beam across a plate) is not a ghost; a line
//!   with no longer line beside it is never one, so that a faint edge the
//!   blocks miss is kept.
//!
//! The refit needs the image: lines made from edge files alone (`vss llv
//! --from-edges`, and a session image without frames) are not refitted;
//! it is `connect.refine` in a profile. `residual` stays the tracker's.

use super::fit::LineFit;
use super::image::GreyImage;
use super::{Point, Segment};

/// Pixels left out at each end of a segment (where a meeting edge bends
/// the profile): the kernel half-width of the edge stage's default.
const TRIM: f64 = 4.0;
/// Pixels of line summed into one block.
const BLOCK: usize = 8;
/// Least number of blocks for a segment to be refitted.
const MIN_BLOCKS: usize = 6;
/// Half-width of the derivative kernel across the line.
const KERNEL_A: usize = 3;
/// Farthest a block's peak may lie from the line (px).
const REACH: f64 = 1.0;
/// Samples to each side of the line: the peak test at `|k - R| ≤ 2` (a
/// peak within `REACH` and its two neighbours) with the kernel's
/// `KERNEL_A` on each side.
const R: usize = 2 + KERNEL_A;
const SAMPLES: usize = 2 * R + 1;
/// Pixels of a scan line a profile reads, at most (`|slope| ≤ 1`).
const SPAN: usize = 2 * R * 3 / 2 + 3;

type Profile = [f64; SAMPLES];
/// The derivatives of a profile at samples `R − 2 ..= R + 2`: all that
/// the peak test ([`peak_near_line`]) reads, for either polarity.
type Near = [f64; 5];

/// Reusable buffers of [`refine_into`].
#[derive(Clone, Debug, Default)]
pub struct RefineScratch {
    /// Per block: the derivatives near the line ([`Near`]).
    blocks: Vec<Near>,
    centres: Vec<f64>,
    /// The lines of the last [`refine_into`] that no edge confirms (module
    /// doc, "Ghosts"), by index, ascending.
    unconfirmed: Vec<usize>,
}

/// Largest angle (degrees) between a ghost and the line it runs beside.
pub const GHOST_DEG: f64 = 5.0;
/// A ghost touches that line within this distance (px) at one end…
const GHOST_NEAR: f64 = 1.5;
/// …and is at most this far from it at the other.
const GHOST_FAR: f64 = 6.0;

/// Lee's kernel of half-width `KERNEL_A`, negated so that a dark-to-bright
/// step along the normal gives a positive peak.
fn kernel() -> [f64; 2 * KERNEL_A + 1] {
    let a = KERNEL_A as i64;
    let mut k = [0.0; 2 * KERNEL_A + 1];
    for (i, t) in (-a..=a).enumerate() {
        let v = if t <= 0 {
            6 * t * (t + a)
        } else {
            -6 * t * (t - a)
        };
        k[i] = v as f64;
    }
    k
}

/// The derivative across the line at sample `k` (`KERNEL_A ≤ k < SAMPLES -
/// KERNEL_A`).
fn derivative(p: &Profile, kern: &[f64; 2 * KERNEL_A + 1], k: usize) -> f64 {
    kern.iter()
        .zip(&p[k - KERNEL_A..=k + KERNEL_A])
        .map(|(c, v)| c * v)
        .sum()
}

/// A segment in the frame of the image axis nearer its normal: `u` across
/// the line along that axis (`x` for a line nearer the vertical, `y`
/// otherwise), `v` the other axis (the scan line, row or column). The line
/// is `u = u0 + slope · (v − v0)`, `|slope| ≤ 1`.
struct Frame {
    steep: bool,
    u0: f64,
    v0: f64,
    slope: f64,
    /// `√(1 + slope²)`: the step along the axis that is one pixel across
    /// the line.
    sec: f64,
    /// The scan lines the blocks cover: `first..first + count`.
    first: usize,
    count: usize,
}

impl Frame {
    /// The frame of `s`, its scan lines less `TRIM` px of line at each
    /// end; `None` for a segment that is not finite or has no such lines.
    fn of(s: &Segment) -> Option<Frame> {
        let (dx, dy) = (s.b.x - s.a.x, s.b.y - s.a.y);
        let steep = dy.abs() >= dx.abs();
        let (ua, va, ub, vb) = if steep {
            (s.a.x, s.a.y, s.b.x, s.b.y)
        } else {
            (s.a.y, s.a.x, s.b.y, s.b.x)
        };
        let len = dx.hypot(dy);
        if !(len.is_finite() && len > 0.0 && ua.is_finite() && ub.is_finite()) {
            return None;
        }
        let slope = (ub - ua) / (vb - va);
        // `TRIM` px of line is `TRIM · |dv| / len` scan lines.
        let trim = TRIM * (vb - va).abs() / len;
        let (lo, hi) = (va.min(vb) + trim, va.max(vb) - trim);
        if !(lo.is_finite() && hi.is_finite() && lo <= hi && lo > -1.0) {
            return None;
        }
        let first = lo.max(0.0).ceil();
        let last = hi.floor();
        if last < first || last > (u32::MAX as f64) {
            return None;
        }
        Some(Frame {
            steep,
            u0: ua,
            v0: va,
            slope,
            sec: slope.hypot(1.0),
            first: first as usize,
            count: (last - first) as usize + 1,
        })
    }

    /// The line's `u` on scan line `v`.
    fn u_at(&self, v: f64) -> f64 {
        self.u0 + self.slope * (v - self.v0)
    }

    /// The image point at `u` across, scan line `v`.
    fn point(&self, u: f64, v: f64) -> Point {
        if self.steep {
            Point::new(u, v)
        } else {
            Point::new(v, u)
        }
    }

    /// Adds to `p` the profile across the line on scan line `v`: the image
    /// at `u_at(v) + (k − R) · sec` for each sample `k`, interpolated along
    /// the axis, where `sec = √(1 + slope²)` makes the samples one pixel
    /// apart across the line (they also move `(k − R) · slope / sec` along
    /// it, which a straight edge does not see). False (with `p` unchanged)
    /// where a sample is outside the image or next to an invalid pixel.
    ///
    /// `p` is in units of 2⁻¹⁶ grey levels ([`Sums`]): with the positions
    /// in 2⁻¹⁶ px, an interpolated value is a whole number of such units,
    /// and so are sums of profiles, exact in an `i64` (interpolating and
    /// summing in `f64` gives the same numbers: below 2⁵³ units nothing
    /// rounds), without a conversion a sample.
    fn add_profile(&self, img: &GreyImage, v: usize, p: &mut Sums) -> bool {
        let (w, h) = img.size();
        let (len_u, len_v) = if self.steep { (w, h) } else { (h, w) };
        let u = self.u_at(v as f64);
        let reach = R as f64 * self.sec;
        if v >= len_v || !(u - reach >= 0.0 && u + reach + 1.0 < len_u as f64) {
            return false;
        }
        // (Both positive: truncated to an `i64`, one instruction.)
        let lo = (u - reach) as i64 as usize;
        let n = (u + reach) as i64 as usize + 2 - lo;
        // The pixels `lo..lo + n` of the scan line, in a buffer on the
        // stack (`n ≤ 2 R √2 + 2`).
        let mut buf = [0i64; SPAN];
        let Some(buf) = buf.get_mut(..n) else {
            return false;
        };
        let d = img.data();
        let mask = img.valid_mask();
        if self.steep {
            let at = v * w + lo;
            if mask.is_some_and(|m| m[at..at + n].contains(&false)) {
                return false;
            }
            for (b, &g) in buf.iter_mut().zip(&d[at..at + n]) {
                *b = i64::from(g);
            }
        } else {
            let at = lo * w + v;
            if mask.is_some_and(|m| (0..n).any(|j| !m[at + j * w])) {
                return false;
            }
            for (j, b) in buf.iter_mut().enumerate() {
                *b = i64::from(d[at + j * w]);
            }
        }
        // The sample positions in the buffer in 1/2¹⁶ px (their rounding,
        // under 2⁻¹⁶ px a step, is far below what the fit resolves).
        const ONE: f64 = 65536.0;
        let mut x = ((u - reach - lo as f64) * ONE) as u32;
        let step = (self.sec * ONE) as u32;
        for out in p.iter_mut() {
            let i = ((x >> 16) as usize).min(n - 2);
            let f = i64::from(x & 0xFFFF);
            *out += (buf[i] << 16) + f * (buf[i + 1] - buf[i]);
            x += step;
        }
        true
    }
}

/// Profiles summed in units of 2⁻¹⁶ grey levels ([`Frame::add_profile`]).
type Sums = [i64; SAMPLES];

/// `p` in grey levels (exact: `|p|` is far below 2⁵³).
fn profile(p: &Sums) -> Profile {
    p.map(|v| v as f64 * (1.0 / 65536.0))
}

/// Refits each segment of `segs` on `images` (one image, or the lightings
/// of a view) as the module doc says; segments it cannot refit are left
/// as they are.
pub fn refine_into(images: &[GreyImage], segs: &mut [Segment], s: &mut RefineScratch) {
    if images.is_empty() {
        return;
    }
    let kern = kernel();
    s.unconfirmed.clear();
    for (i, seg) in segs.iter_mut().enumerate() {
        let Some(f) = Frame::of(seg) else {
            continue;
        };
        // Blocks of about `BLOCK` px of line.
        let len = seg.length();
        let steps = (len - 2.0 * TRIM).floor();
        if steps.is_nan() || steps < (MIN_BLOCKS * BLOCK - BLOCK / 2) as f64 {
            continue;
        }
        let blocks = ((steps as usize + BLOCK / 2) / BLOCK).min(f.count);
        if blocks < MIN_BLOCKS {
            continue;
        }
        let img = if images.len() == 1 {
            &images[0]
        } else {
            strongest(images, &f, &kern)
        };
        s.blocks.clear();
        s.centres.clear();
        let mut total: Sums = [0; SAMPLES];
        for b in 0..blocks {
            let (lo, hi) = (b * f.count / blocks, (b + 1) * f.count / blocks);
            let mut sums = [0; SAMPLES];
            if !(lo..hi).all(|i| f.add_profile(img, f.first + i, &mut sums)) {
                continue;
            }
            for (t, v) in total.iter_mut().zip(&sums) {
                *t += v;
            }
            s.blocks.push(near_derivatives(&profile(&sums), &kern));
            s.centres.push(f.first as f64 + 0.5 * (lo + hi - 1) as f64);
        }
        if s.blocks.len() < MIN_BLOCKS {
            continue;
        }
        let at_line = derivative(&profile(&total), &kern, R);
        if at_line == 0.0 || !at_line.is_finite() {
            continue;
        }
        let pol = at_line.signum();
        let mut fit = LineFit::new();
        for (p, &v) in s.blocks.iter().zip(&s.centres) {
            if let Some((o, d0)) = peak_near_line(p, pol) {
                fit.add_weighted(f.point(f.u_at(v) + o * f.sec, v), d0 * d0);
            }
        }
        if fit.len() < 2 || 2 * fit.len() < s.blocks.len() {
            let edge =
                |p: &Near| peak_near_line(p, pol).is_some() || peak_near_line(p, -pol).is_some();
            if 2 * s.blocks.iter().filter(|p| edge(p)).count() < s.blocks.len() {
                s.unconfirmed.push(i);
            }
            continue;
        }
        if let Some(line) = fit.line() {
            seg.a = line.project(seg.a);
            seg.b = line.project(seg.b);
        }
    }
}

/// Removes the ghosts among the lines [`refine_into`] left unconfirmed
/// (module doc): `segs` must be the lines it was given, unchanged since.
pub fn drop_ghosts(segs: &mut Vec<Segment>, s: &RefineScratch) {
    if s.unconfirmed.is_empty() {
        return;
    }
    let ghost = |i: usize| {
        let (u, ul) = (&segs[i], segs[i].length());
        segs.iter()
            .enumerate()
            .any(|(j, l)| j != i && l.length() >= ul && beside(u, l))
    };
    let gone: Vec<usize> = s
        .unconfirmed
        .iter()
        .copied()
        .filter(|&i| ghost(i))
        .collect();
    let mut k = 0;
    segs.retain(|_| {
        k += 1;
        gone.binary_search(&(k - 1)).is_err()
    });
}

/// Whether `u` runs beside `l` as a ghost does: within [`GHOST_DEG`] of its
/// direction, one end within [`GHOST_NEAR`] px of its line and the other
/// within [`GHOST_FAR`], over at least half of `u`'s length.
fn beside(u: &Segment, l: &Segment) -> bool {
    let (dx, dy) = (l.b.x - l.a.x, l.b.y - l.a.y);
    let (ux, uy) = (u.b.x - u.a.x, u.b.y - u.a.y);
    let (len, ulen) = (dx.hypot(dy), ux.hypot(uy));
    if !(len > 0.0 && ulen > 0.0) {
        return false;
    }
    let cos = (ux * dx + uy * dy).abs() / (len * ulen);
    let off = |p: &Point| ((p.x - l.a.x) * dy - (p.y - l.a.y) * dx).abs() / len;
    let along = |p: &Point| ((p.x - l.a.x) * dx + (p.y - l.a.y) * dy) / len;
    let (da, db) = (off(&u.a), off(&u.b));
    let (ta, tb) = (along(&u.a), along(&u.b));
    let overlap = ta.max(tb).min(len) - ta.min(tb).max(0.0);
    cos >= GHOST_DEG.to_radians().cos()
        && da.min(db) <= GHOST_NEAR
        && da.max(db) <= GHOST_FAR
        && overlap >= 0.5 * ulen
}

/// The derivatives of `p` that [`peak_near_line`] reads, each computed
/// once (the peak test reads the middle three two or three times each, and a
/// line the refit cannot place is tested for both polarities).
fn near_derivatives(p: &Profile, kern: &[f64; 2 * KERNEL_A + 1]) -> Near {
    std::array::from_fn(|j| derivative(p, kern, R - 2 + j))
}

/// The offset (px along the normal) of the peak of polarity `pol` nearest
/// the line within `REACH`, and the derivative there (times `pol`), if
/// there is such a peak; `near` are the profile's [`near_derivatives`].
fn peak_near_line(near: &Near, pol: f64) -> Option<(f64, f64)> {
    let d = |k: usize| pol * near[k + 2 - R];
    let mut best: Option<(f64, f64)> = None;
    for k in R - 1..=R + 1 {
        let (dm, d0, dp) = (d(k - 1), d(k), d(k + 1));
        if d0 <= 0.0 || d0 < dm || d0 < dp {
            continue;
        }
        let den = dm - 2.0 * d0 + dp;
        let off = if den < 0.0 {
            0.5 * (dm - dp) / den
        } else {
            0.0
        };
        let o = k as f64 - R as f64 + off.clamp(-0.5, 0.5);
        if o.abs() <= REACH && best.is_none_or(|b| o.abs() < b.0.abs()) {
            best = Some((o, d0));
        }
    }
    best
}

/// Of several images, the one whose edge at the line is strongest: the
/// derivative at the line of profiles summed on eight scan lines.
fn strongest<'a>(
    images: &'a [GreyImage],
    f: &Frame,
    kern: &[f64; 2 * KERNEL_A + 1],
) -> &'a GreyImage {
    let mut best = (0.0, &images[0]);
    for img in images {
        let mut sums = [0; SAMPLES];
        let whole = (0..8).all(|i| f.add_profile(img, f.first + i * f.count / 8, &mut sums));
        let m = if whole {
            derivative(&profile(&sums), kern, R).abs()
        } else {
            0.0
        };
        if m > best.0 {
            best = (m, img);
        }
    }
    best.1
}

#[cfg(test)]
mod tests;
