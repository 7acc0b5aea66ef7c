//! The renderer: area-sampled grey images of a scene through a camera, with
//! optional lens distortion, Gaussian blur and Gaussian sensor noise.
//!
//! A pixel that no projected face edge comes near sees one face only; its
//! value is that face's shading at the pixel centre (exact to second order:
//! shading varies slowly across a face). Every other pixel is area-sampled on
//! a 16 × 16 grid with a depth test per sample; the grid is sheared so that
//! all 256 samples have distinct `x` and distinct `y` offsets, which makes
//! the coverage of an axis-parallel edge exact to 1/256 of a pixel instead of
//! 1/16. Each face's share is shaded at the centroid of its samples.
//!
//! With `distort`, the image is the observed one: pixel `(xd, yd)` and each of
//! its samples look at the ideal scene at `CameraModel::observed_to_ideal`,
//! the exact inverse of what lens correction computes.

use super::raster::Prepared;
use super::{Camera, PointLight, RenderOptions, Scene};
use crate::llv::GreyImage;
use crate::llv::rng::SplitMix64;

/// Samples per side in an edge pixel.
const SS: usize = 16;

/// The noise-free, unblurred, unclamped render (grey levels, row-major), for
/// callers that add their own noise per frame (the simulated grabber).
pub fn render_exact(
    scene: &Scene,
    cam: &Camera,
    lights: &[PointLight],
    o: &RenderOptions,
) -> Vec<f64> {
    let (w, h) = (cam.width, cam.height);
    let distort = o.distort && !cam.model.is_identity();
    let to_ideal = |x: f64, y: f64| -> (f64, f64) {
        if distort {
            cam.model.observed_to_ideal(x, y)
        } else {
            (x, y)
        }
    };
    let to_observed = |x: f64, y: f64| -> (f64, f64) {
        if distort {
            cam.model.ideal_to_observed(x, y)
        } else {
            (x, y)
        }
    };
    let bounds = ideal_bounds(w, h, &to_ideal);
    let prep = Prepared::new(scene, cam, lights, o.ambient, bounds);

    // Pixels a projected face edge crosses: points every 1/20 px along each
    // edge mark the pixel they fall in. A pixel the edge only clips by less
    // than that step loses at most 1/800 of its area to the wrong face.
    let mut marked = vec![false; w * h];
    for f in &prep.faces {
        for (i, &(ax, ay)) in f.poly.iter().enumerate() {
            let (bx, by) = f.poly[(i + 1) % f.poly.len()];
            let len = (bx - ax).hypot(by - ay);
            if !len.is_finite() {
                continue;
            }
            let steps = ((len * 20.0).ceil() as usize).clamp(1, 20_000_000);
            for s in 0..=steps {
                let t = s as f64 / steps as f64;
                let (x, y) = to_observed(ax + (bx - ax) * t, ay + (by - ay) * t);
                let (px, py) = (x.round(), y.round());
                if px >= 0.0 && py >= 0.0 && px < w as f64 && py < h as f64 {
                    marked[py as usize * w + px as usize] = true;
                }
            }
        }
    }

    let offsets: Vec<(f64, f64)> = (0..SS * SS)
        .map(|k| {
            let (i, j) = ((k % SS) as f64, (k / SS) as f64);
            let n = SS as f64;
            ((i + (j + 0.5) / n) / n - 0.5, (j + (i + 0.5) / n) / n - 0.5)
        })
        .collect();
    let mut out = vec![0.0; w * h];
    // (face, count, Σx, Σy) of one edge pixel; faces are few per pixel.
    let mut acc: Vec<(usize, usize, f64, f64)> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f64, y as f64);
            let v = if marked[y * w + x] {
                acc.clear();
                let mut miss = 0usize;
                for &(ox, oy) in &offsets {
                    let (ix, iy) = to_ideal(xf + ox, yf + oy);
                    match prep.hit(ix, iy) {
                        Some(hit) => match acc.iter_mut().find(|a| a.0 == hit.face) {
                            Some(a) => {
                                a.1 += 1;
                                a.2 += ix;
                                a.3 += iy;
                            }
                            None => acc.push((hit.face, 1, ix, iy)),
                        },
                        None => miss += 1,
                    }
                }
                let n = offsets.len() as f64;
                let mut v = prep.background() * miss as f64 / n;
                for &(face, count, sx, sy) in &acc {
                    let c = count as f64;
                    v += prep.shade(face, sx / c, sy / c) * c / n;
                }
                v
            } else {
                let (ix, iy) = to_ideal(xf, yf);
                prep.value(ix, iy)
            };
            out[y * w + x] = v;
        }
    }
    out
}

/// The region of ideal pixels the observed image covers, padded.
fn ideal_bounds(w: usize, h: usize, to_ideal: &dyn Fn(f64, f64) -> (f64, f64)) -> [f64; 4] {
    let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    let (wf, hf) = (w as f64, h as f64);
    let n = 64;
    for k in 0..=n {
        let t = k as f64 / n as f64;
        for (x, y) in [
            (-0.5 + t * wf, -0.5),
            (-0.5 + t * wf, hf - 0.5),
            (-0.5, -0.5 + t * hf),
            (wf - 0.5, -0.5 + t * hf),
        ] {
            let (ix, iy) = to_ideal(x, y);
            b = [b[0].min(ix), b[1].min(iy), b[2].max(ix), b[3].max(iy)];
        }
    }
    [b[0] - 4.0, b[1] - 4.0, b[2] + 4.0, b[3] + 4.0]
}

/// Separable Gaussian blur with standard deviation `sigma` pixels; the border
/// repeats the outermost pixel.
pub fn blur(img: &mut [f64], w: usize, h: usize, sigma: f64) {
    if sigma <= 0.0 || !sigma.is_finite() || w == 0 || h == 0 {
        return;
    }
    let r = (3.0 * sigma).ceil() as usize;
    let mut k: Vec<f64> = (0..=2 * r)
        .map(|i| {
            let t = i as f64 - r as f64;
            (-t * t / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let s: f64 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= s);
    let mut tmp = vec![0.0; w * h];
    let clampi = |i: i64, n: usize| i.clamp(0, n as i64 - 1) as usize;
    for y in 0..h {
        let row = &img[y * w..(y + 1) * w];
        for x in 0..w {
            let mut a = 0.0;
            for (i, &kv) in k.iter().enumerate() {
                a += kv * row[clampi(x as i64 + i as i64 - r as i64, w)];
            }
            tmp[y * w + x] = a;
        }
    }
    for y in 0..h {
        for x in 0..w {
            let mut a = 0.0;
            for (i, &kv) in k.iter().enumerate() {
                a += kv * tmp[clampi(y as i64 + i as i64 - r as i64, h) * w + x];
            }
            img[y * w + x] = a;
        }
    }
}

/// Blur, noise (`o.seed`) and 8-bit quantisation of a [`render_exact`] result.
pub fn finish(mut img: Vec<f64>, w: usize, h: usize, o: &RenderOptions) -> GreyImage {
    blur(&mut img, w, h, o.blur_sigma);
    let mut rng = SplitMix64::new(o.seed);
    let noise = if o.noise_sigma.is_finite() && o.noise_sigma > 0.0 {
        o.noise_sigma
    } else {
        0.0
    };
    let data: Vec<u8> = img
        .iter()
        .map(|&v| {
            let n = if noise > 0.0 {
                noise * rng.gauss()
            } else {
                0.0
            };
            (v + n).round().clamp(0.0, 255.0) as u8
        })
        .collect();
    // Width and height come from a Camera the caller built; a zero size gives
    // an empty 1 × 1 image rather than a panic.
    GreyImage::new(w, h, data).unwrap_or_else(|_| GreyImage::filled(1, 1, 0).unwrap_or_default())
}
