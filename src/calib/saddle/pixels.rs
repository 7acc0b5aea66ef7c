//! The pixel-level parts of the checkerboard detector: the smoothed image,
//! the saddle response and its candidates, bilinear samples, the X test of
//! a corner's four sectors, the `cornerSubPix`-like refinement and the edge
//! width used to tell a blurred board.

use super::*;

/// The image as `f32`, smoothed by `[1 4 6 4 1] / 16` both ways.
pub(super) fn smooth(img: &GreyImage) -> Vec<f32> {
    let (w, h) = img.size();
    let d = img.data();
    let k = [1.0f32, 4.0, 6.0, 4.0, 1.0];
    let mut tmp = vec![0f32; w * h];
    for y in 0..h {
        let row = &d[y * w..(y + 1) * w];
        for x in 0..w {
            let mut s = 0.0;
            for (t, kk) in k.iter().enumerate() {
                let xx = (x + t).saturating_sub(2).min(w - 1);
                s += kk * f32::from(row[xx]);
            }
            tmp[y * w + x] = s / 16.0;
        }
    }
    let mut out = vec![0f32; w * h];
    for y in 0..h {
        for (t, kk) in k.iter().enumerate() {
            let yy = (y + t).saturating_sub(2).min(h - 1);
            let src = &tmp[yy * w..(yy + 1) * w];
            let dst = &mut out[y * w..(y + 1) * w];
            for (o, s) in dst.iter_mut().zip(src) {
                *o += kk * s;
            }
        }
        for o in &mut out[y * w..(y + 1) * w] {
            *o /= 16.0;
        }
    }
    out
}

/// `−det H` at step `d` (px) on the smoothed image; 0 near the border.
pub(super) fn saddle_response(s: &[f32], w: usize, h: usize, d: usize) -> Vec<f32> {
    let mut r = vec![0f32; w * h];
    if w <= 2 * d + 2 || h <= 2 * d + 2 {
        return r;
    }
    for y in d..h - d {
        for x in d..w - d {
            let i = y * w + x;
            let c = s[i];
            let ixx = s[i + d] + s[i - d] - 2.0 * c;
            let iyy = s[i + d * w] + s[i - d * w] - 2.0 * c;
            let ixy =
                (s[i + d * w + d] + s[i - d * w - d] - s[i + d * w - d] - s[i - d * w + d]) / 4.0;
            r[i] = ixy * ixy - ixx * iyy;
        }
    }
    r
}

/// Local maxima of `r` (radius 3) above a fraction of the strongest, with
/// their position refined by a parabola through the neighbours.
pub(super) fn candidates(r: &[f32], w: usize, h: usize) -> Vec<Cand> {
    let most = r.iter().copied().fold(0f32, f32::max);
    if most <= 0.0 {
        return Vec::new();
    }
    let thr = most * MIN_RESPONSE;
    let rad = 3usize;
    let mut out = Vec::new();
    for y in rad..h.saturating_sub(rad) {
        for x in rad..w.saturating_sub(rad) {
            let v = r[y * w + x];
            if v < thr {
                continue;
            }
            let mut is_max = true;
            'n: for yy in y - rad..=y + rad {
                for xx in x - rad..=x + rad {
                    let u = r[yy * w + xx];
                    if u > v || (u == v && (yy, xx) < (y, x)) {
                        is_max = false;
                        break 'n;
                    }
                }
            }
            if !is_max {
                continue;
            }
            let fit = |a: f32, b: f32, c: f32| {
                let den = a - 2.0 * b + c;
                if den.abs() < 1e-12 {
                    0.0
                } else {
                    f64::from(0.5 * (a - c) / den).clamp(-0.5, 0.5)
                }
            };
            let i = y * w + x;
            let dx = fit(r[i - 1], v, r[i + 1]);
            let dy = fit(r[i - w], v, r[i + w]);
            out.push(Cand {
                p: [x as f64 + dx, y as f64 + dy],
                r: v,
            });
        }
    }
    out.sort_by(|a, b| b.r.total_cmp(&a.r));
    out.truncate(MAX_CANDIDATES);
    out
}

/// Bilinear sample of the image (clamped to it).
pub(super) fn sample(img: &GreyImage, x: f64, y: f64) -> f64 {
    let (w, h) = img.size();
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let d = img.data();
    let g = |xx: usize, yy: usize| f64::from(d[yy * w + xx]);
    (g(x0, y0) * (1.0 - fx) + g(x1, y0) * fx) * (1.0 - fy)
        + (g(x0, y1) * (1.0 - fx) + g(x1, y1) * fx) * fy
}

/// The mean of a small cross of samples round `(x, y)`.
pub(super) fn patch(img: &GreyImage, x: f64, y: f64, r: f64) -> f64 {
    let mut s = 0.0;
    for (dx, dy) in [(0.0, 0.0), (r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)] {
        s += sample(img, x + dx, y + dy);
    }
    s / 5.0
}

/// The four squares round corner `p` with lattice steps `u`, `v`: the
/// grey of the square towards `+u+v` less that towards `+u−v` (its sign
/// tells the colours), or `None` unless they alternate dark, light, dark,
/// light with enough contrast.
pub(super) fn x_test(img: &GreyImage, p: [f64; 2], u: [f64; 2], v: [f64; 2]) -> Option<f64> {
    let (w, h) = img.size();
    let at = |a: f64, b: f64| {
        let x = p[0] + 0.5 * (a * u[0] + b * v[0]);
        let y = p[1] + 0.5 * (a * u[1] + b * v[1]);
        (x >= 0.0 && y >= 0.0 && x <= (w - 1) as f64 && y <= (h - 1) as f64).then_some((x, y))
    };
    let side = (u[0].hypot(u[1])).min(v[0].hypot(v[1]));
    let r = (0.12 * side).clamp(0.5, 3.0);
    let mut g = [0.0; 4];
    for (k, (a, b)) in [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        let (x, y) = at(a, b)?;
        g[k] = patch(img, x, y, r);
    }
    let contrast = ((g[0] + g[2]) - (g[1] + g[3])) / 2.0;
    let c = contrast.abs();
    if c < MIN_CONTRAST || (g[0] - g[2]).abs() > 0.6 * c || (g[1] - g[3]).abs() > 0.6 * c {
        return None;
    }
    Some(contrast)
}

/// Refines a corner as `cornerSubPix`: window half-size `win`, gradients of
/// the image by central differences, bilinearly sampled round the point.
pub(super) fn subpixel(img: &GreyImage, p: [f64; 2], win: i32) -> Option<[f64; 2]> {
    let (w, h) = img.size();
    let mut q = p;
    let wf = f64::from(win);
    for _ in 0..40 {
        let (mut a, mut b, mut cc, mut bx, mut by) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for j in -win..=win {
            for i in -win..=win {
                let (x, y) = (q[0] + f64::from(i), q[1] + f64::from(j));
                if x < 1.0 || y < 1.0 || x > (w - 2) as f64 || y > (h - 2) as f64 {
                    return None;
                }
                let gx = (sample(img, x + 1.0, y) - sample(img, x - 1.0, y)) / 2.0;
                let gy = (sample(img, x, y + 1.0) - sample(img, x, y - 1.0)) / 2.0;
                let m = (-(f64::from(i) / wf).powi(2) - (f64::from(j) / wf).powi(2)).exp();
                let (gxx, gxy, gyy) = (gx * gx * m, gx * gy * m, gy * gy * m);
                a += gxx;
                b += gxy;
                cc += gyy;
                bx += gxx * f64::from(i) + gxy * f64::from(j);
                by += gxy * f64::from(i) + gyy * f64::from(j);
            }
        }
        let det = a * cc - b * b;
        if det.abs() < 1e-9 {
            return None;
        }
        let dx = (cc * bx - b * by) / det;
        let dy = (a * by - b * bx) / det;
        q = [q[0] + dx, q[1] + dy];
        if norm(sub(q, p)) > wf {
            return None;
        }
        if dx * dx + dy * dy < 1e-6 {
            break;
        }
    }
    Some(q)
}

/// How wide the board's edges are (px, 10–90 % of the step between a dark
/// and a light square), the median over the corners: the contrast across a
/// side over the steepest gradient along it times 0.8 (a Gaussian-blurred
/// step rises 10–90 % over 0.8 of contrast / slope, 2.56 σ).
pub(super) fn edge_width(img: &GreyImage, pts: &[([f64; 2], [f64; 2], f64)]) -> f64 {
    let mut widths = Vec::new();
    for &(p, u, contrast) in pts {
        // Across the side from p along u, halfway: the side runs along v,
        // so sample along a line perpendicular to u's neighbour side.
        let mid = [p[0] + 0.5 * u[0], p[1] + 0.5 * u[1]];
        let len = norm(u);
        if len < 4.0 {
            continue;
        }
        // The side between the two squares at `mid` runs along u; across
        // it is the perpendicular.
        let n = [-u[1] / len, u[0] / len];
        let reach = 0.4 * len;
        let steps = (2.0 * reach).ceil() as i32 * 2;
        let mut slope: f64 = 0.0;
        for t in -steps..steps {
            let s0 = f64::from(t) * 0.25;
            let a = sample(img, mid[0] + n[0] * s0, mid[1] + n[1] * s0);
            let b = sample(img, mid[0] + n[0] * (s0 + 0.5), mid[1] + n[1] * (s0 + 0.5));
            slope = slope.max((b - a).abs() / 0.5);
        }
        if slope > 0.0 {
            widths.push(0.8 * contrast.abs() / slope);
        }
    }
    if widths.is_empty() {
        return 0.0;
    }
    widths.sort_by(f64::total_cmp);
    widths[widths.len() / 2]
}

/// How wide the edges of grid `g` are (px, as [`edge_width`] measures
/// them): the wider of the medians along the grid's two directions. A
/// motion blur widens only the edges that cross the motion, so the sides
/// of one direction alone can read sharp on a smeared board. `up` maps the
/// grid's points into `img` (a grid found at half size is doubled).
pub(super) fn grid_edge_width(img: &GreyImage, g: &Grid, up: impl Fn([f64; 2]) -> [f64; 2]) -> f64 {
    let contrast = {
        let mut v = g.contrast.clone();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let at = |i: usize, j: usize| g.pts.get(j * g.ni + i).copied().flatten().map(&up);
    let (mut along_i, mut along_j) = (Vec::new(), Vec::new());
    for j in 0..g.nj {
        for i in 0..g.ni {
            let Some(p) = at(i, j) else { continue };
            if let Some(q) = at(i + 1, j).filter(|_| i + 1 < g.ni) {
                along_i.push((p, sub(q, p), contrast));
            }
            if let Some(q) = at(i, j + 1) {
                along_j.push((p, sub(q, p), contrast));
            }
        }
    }
    edge_width(img, &along_i).max(edge_width(img, &along_j))
}
