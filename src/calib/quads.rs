//! The plate's squares as quadrilaterals whose sides are fitted to the
//! LLV engine's edge points.
//!
//! Which edges belong to which square is found from the grey image: the
//! image is split at Otsu's threshold and each dark (on a checkerboard also
//! each light) connected region that is a filled convex quadrilateral gives
//! a square's rough outline. That outline only picks what belongs to a side:
//! the pipeline's segments that run along it (direction within 8°, both ends
//! within 3 px, overlapping it) give its line to within a pixel, and the
//! side's line is then the total-least-squares fit of the engine's subpixel
//! edge points along it (from the scan direction across it, of one
//! polarity, within a pixel of the segments' line), leaving out the few
//! pixels next to each corner, where Lee's kernel sees both sides and the
//! points bend (a segment that ran into a corner carries that bend; its
//! points without the ends do not). The corners are where consecutive
//! sides' lines cross: each rests on the edge points of two whole sides.
//! Without a segment along a side, the outline's side stands in for the
//! segments' line; the points still decide.

use crate::llv::{EdgePoints, GreyImage, Segment};

/// Regions smaller than this are not squares (px).
const MIN_AREA: usize = 40;
/// A side's segments run within this of its rough line (px) …
const NEAR: f64 = 3.0;
/// … and within this angle of it (degrees) …
const MAX_ANGLE_DEG: f64 = 8.0;
/// Edge points nearer a corner than this (along the side, px; a quarter of
/// a shorter side) are left out: Lee's kernel (half-width 4) sees both
/// sides there.
const TRIM: f64 = 5.0;
/// A side needs this many edge points.
const MIN_POINTS: usize = 5;
/// Edge points in buckets of this size (px), for the sides' look-ups.
const BUCKET: f64 = 8.0;
/// Erosions of a checkerboard's regions, so that squares touching at a
/// corner come apart.
const ERODE: usize = 2;
/// Sides shorter than this are not trusted (px).
pub const MIN_SIDE: f64 = 6.0;

/// One square as found.
#[derive(Clone, Debug)]
pub struct Quad {
    /// Corners in image order with the plate's handedness.
    pub corners: [[f64; 2]; 4],
    pub centre: [f64; 2],
    pub dark: bool,
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

/// Otsu's threshold of the image's histogram.
fn otsu(img: &GreyImage) -> u8 {
    let mut hist = [0u64; 256];
    for &v in img.data() {
        hist[usize::from(v)] += 1;
    }
    let total: u64 = hist.iter().sum();
    let sum_all: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    let (mut w0, mut sum0, mut best, mut best_t) = (0u64, 0.0, -1.0, 128u8);
    for (t, &c) in hist.iter().enumerate() {
        w0 += c;
        sum0 += t as f64 * c as f64;
        let w1 = total - w0;
        if w0 == 0 || w1 == 0 {
            continue;
        }
        let (m0, m1) = (sum0 / w0 as f64, (sum_all - sum0) / w1 as f64);
        let between = w0 as f64 * w1 as f64 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            best_t = t as u8;
        }
    }
    best_t
}

/// 4-connected regions of `mask` not touching the image's border, as pixel
/// lists.
fn regions(mask: &[bool], w: usize, h: usize) -> Vec<Vec<(usize, usize)>> {
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !mask[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let mut pix = Vec::new();
        let mut border = false;
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            pix.push((x, y));
            border |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
            let mut push = |j: usize| {
                if mask[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                push(i - 1);
            }
            if x + 1 < w {
                push(i + 1);
            }
            if y > 0 {
                push(i - w);
            }
            if y + 1 < h {
                push(i + w);
            }
        }
        if !border && pix.len() >= MIN_AREA {
            out.push(pix);
        }
    }
    out
}

/// The rough outline of a region: its farthest pixels, if it is a filled
/// convex quadrilateral.
fn outline(pix: &[(usize, usize)]) -> Option<[[f64; 2]; 4]> {
    let n = pix.len() as f64;
    let p = |q: &(usize, usize)| [q.0 as f64, q.1 as f64];
    let c = pix.iter().fold([0.0, 0.0], |a, q| {
        [a[0] + q.0 as f64 / n, a[1] + q.1 as f64 / n]
    });
    let far = |from: [f64; 2]| {
        pix.iter()
            .map(p)
            .max_by(|a, b| norm(sub(*a, from)).total_cmp(&norm(sub(*b, from))))
    };
    let a = far(c)?;
    let b = far(a)?;
    let side = |sign: f64| {
        pix.iter().map(p).max_by(|u, v| {
            (sign * cross(sub(b, a), sub(*u, a))).total_cmp(&(sign * cross(sub(b, a), sub(*v, a))))
        })
    };
    let (s1, s2) = (side(1.0)?, side(-1.0)?);
    let q = [a, s1, b, s2];
    // Filled: the pixels cover the outline's area (grown by half a pixel).
    let area: f64 = (0..4)
        .map(|k| cross(q[k], q[(k + 1) % 4]))
        .sum::<f64>()
        .abs()
        / 2.0;
    let perimeter: f64 = (0..4).map(|k| norm(sub(q[(k + 1) % 4], q[k]))).sum();
    let fill = n / (area + perimeter / 2.0 + 1.0);
    if !(0.8..=1.2).contains(&fill) || (0..4).any(|k| norm(sub(q[(k + 1) % 4], q[k])) < MIN_SIDE) {
        return None;
    }
    Some(q)
}

/// A line `(point on it, unit direction)`.
type Line = ([f64; 2], [f64; 2]);

/// The engine's edge points of both scan directions, bucketed by place.
pub struct EdgeIndex {
    w: usize,
    h: usize,
    /// Per scan direction (horizontal, vertical): bucket → points
    /// `(x, y, response)`.
    buckets: [Vec<Vec<[f64; 3]>>; 2],
}

impl EdgeIndex {
    pub fn new(h_pts: &EdgePoints, v_pts: &EdgePoints, w: usize, h: usize) -> EdgeIndex {
        let (bw, bh) = (
            w.div_ceil(BUCKET as usize).max(1),
            h.div_ceil(BUCKET as usize).max(1),
        );
        let mut buckets = [vec![Vec::new(); bw * bh], vec![Vec::new(); bw * bh]];
        for (k, pts) in [h_pts, v_pts].into_iter().enumerate() {
            for p in &pts.points {
                let (bx, by) = (
                    (p.x as f64 / BUCKET) as usize,
                    (p.y as f64 / BUCKET) as usize,
                );
                if p.x >= 0.0 && p.y >= 0.0 && bx < bw && by < bh {
                    buckets[k][by * bw + bx].push([
                        f64::from(p.x),
                        f64::from(p.y),
                        f64::from(p.response),
                    ]);
                }
            }
        }
        EdgeIndex {
            w: bw,
            h: bh,
            buckets,
        }
    }

    /// Points of scan direction `k` within `r` of the box round `p`–`q`.
    fn near(&self, k: usize, p: [f64; 2], q: [f64; 2], r: f64) -> impl Iterator<Item = &[f64; 3]> {
        let b =
            |v: f64, n: usize| ((v / BUCKET).floor().max(0.0) as usize).min(n.saturating_sub(1));
        let (x0, x1) = (b(p[0].min(q[0]) - r, self.w), b(p[0].max(q[0]) + r, self.w));
        let (y0, y1) = (b(p[1].min(q[1]) - r, self.h), b(p[1].max(q[1]) + r, self.h));
        let w = self.w;
        (y0..=y1)
            .flat_map(move |y| (x0..=x1).map(move |x| y * w + x))
            .flat_map(move |i| self.buckets[k][i].iter())
    }
}

/// The line of the segments along side `p`–`q`, if any run along it.
fn segments_line(p: [f64; 2], q: [f64; 2], segs: &[Segment]) -> Option<Line> {
    let len = norm(sub(q, p));
    let d = [(q[0] - p[0]) / len, (q[1] - p[1]) / len];
    let nrm = [-d[1], d[0]];
    let cos_max = MAX_ANGLE_DEG.to_radians().cos();
    let mut pts: Vec<([f64; 2], f64)> = Vec::new();
    for s in segs {
        let (a, b) = ([s.a.x, s.a.y], [s.b.x, s.b.y]);
        let sl = s.length();
        if sl < MIN_SIDE {
            continue;
        }
        if dot(sub(b, a), d).abs() / sl < cos_max {
            continue;
        }
        if dot(sub(a, p), nrm).abs() > NEAR || dot(sub(b, p), nrm).abs() > NEAR {
            continue;
        }
        let (ta, tb) = (dot(sub(a, p), d), dot(sub(b, p), d));
        let overlap = ta.max(tb).min(len) - ta.min(tb).max(0.0);
        if overlap < 0.3 * len {
            continue;
        }
        pts.push((a, sl / 2.0));
        pts.push((b, sl / 2.0));
    }
    fit(&pts)
}

/// Weighted total-least-squares line through points.
fn fit(pts: &[([f64; 2], f64)]) -> Option<Line> {
    let wsum: f64 = pts.iter().map(|x| x.1).sum();
    if pts.len() < 2 || wsum.is_nan() || wsum <= 0.0 {
        return None;
    }
    let m = pts.iter().fold([0.0, 0.0], |acc, (x, w)| {
        [acc[0] + x[0] * w / wsum, acc[1] + x[1] * w / wsum]
    });
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (x, w) in pts {
        let (dx, dy) = (x[0] - m[0], x[1] - m[1]);
        sxx += w * dx * dx;
        sxy += w * dx * dy;
        syy += w * dy * dy;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    Some((m, [theta.cos(), theta.sin()]))
}

/// The line of side `p`–`q` (rough corners): the edge points along the
/// segments' line (or the rough side), corners trimmed, fitted twice with a
/// tighter band the second time.
fn side_line(p: [f64; 2], q: [f64; 2], segs: &[Segment], edges: &EdgeIndex) -> Option<Line> {
    let len = norm(sub(q, p));
    let d = [(q[0] - p[0]) / len, (q[1] - p[1]) / len];
    let mut line = segments_line(p, q, segs).unwrap_or((p, d));
    // The scan across the side: horizontal scans find steep sides.
    let k = if d[1].abs() > d[0].abs() { 0 } else { 1 };
    // Short sides (a small or far plate) keep their middle half.
    let trim = TRIM.min(0.25 * len);
    let mut sign = 0.0;
    for band in [1.5, 0.75] {
        let nrm = [-line.1[1], line.1[0]];
        let mut pts = Vec::new();
        let mut resp = 0.0;
        for e in edges.near(k, p, q, 2.0) {
            let x = [e[0], e[1]];
            let t = dot(sub(x, p), d);
            if t < trim || t > len - trim || dot(sub(x, line.0), nrm).abs() > band {
                continue;
            }
            if sign != 0.0 && e[2] * sign < 0.0 {
                continue;
            }
            resp += e[2];
            pts.push((x, 1.0));
        }
        if pts.len() < MIN_POINTS {
            return None;
        }
        sign = resp.signum();
        line = fit(&pts)?;
    }
    Some(line)
}

fn intersect(l1: ([f64; 2], [f64; 2]), l2: ([f64; 2], [f64; 2])) -> Option<[f64; 2]> {
    let den = cross(l1.1, l2.1);
    if den.abs() < 0.2 {
        return None;
    }
    let t = cross(sub(l2.0, l1.0), l2.1) / den;
    Some([l1.0[0] + t * l1.1[0], l1.0[1] + t * l1.1[1]])
}

/// 3 × 3 erosion, so that squares touching at a corner come apart.
fn erode(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut out = vec![false; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w - 1 {
            out[y * w + x] = (0..3).all(|dy| (0..3).all(|dx| mask[(y + dy - 1) * w + x + dx - 1]));
        }
    }
    out
}

/// Every square of the plate found in `img`: its outline from the regions,
/// its sides from `segs`. `both` takes light regions too (checkerboards);
/// `hand` is the plate's handedness (corner order in the image).
pub fn quads(
    img: &GreyImage,
    segs: &[Segment],
    edges: &EdgeIndex,
    both: bool,
    hand: f64,
) -> Vec<Quad> {
    let (w, h) = img.size();
    let t = otsu(img);
    let mut out = Vec::new();
    let polarities: &[bool] = if both { &[true, false] } else { &[true] };
    for &dark in polarities {
        let mut mask: Vec<bool> = img.data().iter().map(|&v| (v <= t) == dark).collect();
        if both {
            for _ in 0..ERODE {
                mask = erode(&mask, w, h);
            }
        }
        for pix in regions(&mask, w, h) {
            let Some(mut rough) = outline(&pix) else {
                continue;
            };
            if both {
                // Back out to where the region was before the erosion.
                let c = [
                    rough.iter().map(|p| p[0]).sum::<f64>() / 4.0,
                    rough.iter().map(|p| p[1]).sum::<f64>() / 4.0,
                ];
                for p in &mut rough {
                    let d = sub(*p, c);
                    let n = norm(d).max(1e-9);
                    let grow = ERODE as f64 * std::f64::consts::SQRT_2;
                    *p = [p[0] + d[0] / n * grow, p[1] + d[1] / n * grow];
                }
            }
            let lines: Option<Vec<_>> = (0..4)
                .map(|k| side_line(rough[k], rough[(k + 1) % 4], segs, edges))
                .collect();
            let Some(lines) = lines else { continue };
            let corners: Option<Vec<[f64; 2]>> = (0..4)
                .map(|k| intersect(lines[(k + 3) % 4], lines[k]))
                .collect();
            let Some(c) = corners else { continue };
            let mut c: [[f64; 2]; 4] = [c[0], c[1], c[2], c[3]];
            // The corners must stay near the rough outline's.
            if (0..4).any(|k| norm(sub(c[k], rough[k])) > 2.0 * NEAR + 2.0) {
                continue;
            }
            let area: f64 = (0..4).map(|k| cross(c[k], c[(k + 1) % 4])).sum::<f64>() / 2.0;
            if area * hand < 0.0 {
                c.reverse();
            }
            let centre = [
                c.iter().map(|p| p[0]).sum::<f64>() / 4.0,
                c.iter().map(|p| p[1]).sum::<f64>() / 4.0,
            ];
            out.push(Quad {
                corners: c,
                centre,
                dark,
            });
        }
    }
    out
}
