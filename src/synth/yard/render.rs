//! The yard renderer: exact area coverage of each pixel's footprint by the
//! layered facets, a pillbox defocus, and sensor noise.
//!
//! A pixel's footprint is its unit square, or through the lens the
//! quadrilateral of its four corners mapped to ideal coordinates (exact to
//! second order in the pixel size). Facets are taken front to back: each
//! takes `footprint ∩ facet` out of what is still uncovered (convex pieces,
//! `poly::split`), shaded at that part's centroid, so occlusion and
//! anti-aliasing are exact areas rather than samples. A tile index lists the
//! facets that can touch each 16-px tile, front first, cut after the first
//! facet that covers the whole tile.
//!
//! Defocus is a uniform disk (a pillbox, what an out-of-focus lens gives)
//! of radius 2σ, so that its standard deviation per axis is σ; each tap is
//! the disk's area in that pixel. Noise is Gaussian with a fixed σ, or
//! signal-dependent: variance `gain · I + read²` (shot noise in its normal
//! approximation, plus read noise), then rounding to 0–255.

use super::poly::{self, P2, Relation};
use super::shade::Pcg32;
use super::{Facet, YardNoise, YardScene};
use crate::llv::GreyImage;

const TILE: f64 = 16.0;
/// Facets' boxes are grown by this when filed in tiles, so a footprint or a
/// query point a little outside its tile still finds every facet.
const PAD: f64 = 2.5;

/// Facets by tile, front first.
pub struct Index {
    x0: f64,
    y0: f64,
    nx: usize,
    ny: usize,
    tiles: Vec<Vec<u32>>,
}

impl Index {
    /// Files the facets over the ideal region `[x0, x1] × [y0, y1]`.
    pub fn new(facets: &[Facet], bounds: [f64; 4]) -> Index {
        let (x0, y0) = (bounds[0] - TILE, bounds[1] - TILE);
        let nx = (((bounds[2] + TILE - x0) / TILE).ceil() as usize).max(1);
        let ny = (((bounds[3] + TILE - y0) / TILE).ceil() as usize).max(1);
        let mut tiles: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
        let mut full = vec![false; nx * ny];
        for (fi, f) in facets.iter().enumerate().rev() {
            let b = f.poly.bbox;
            let cell = |v: f64, o: f64, n: usize| {
                ((v - o) / TILE).floor().clamp(0.0, n as f64 - 1.0) as usize
            };
            let (i0, i1) = (cell(b[0] - PAD, x0, nx), cell(b[2] + PAD, x0, nx));
            let (j0, j1) = (cell(b[1] - PAD, y0, ny), cell(b[3] + PAD, y0, ny));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let t = j * nx + i;
                    if full[t] {
                        continue;
                    }
                    tiles[t].push(fi as u32);
                    let (tx, ty) = (x0 + i as f64 * TILE - PAD, y0 + j as f64 * TILE - PAD);
                    let e = TILE + 2.0 * PAD;
                    let corners = [(tx, ty), (tx + e, ty), (tx + e, ty + e), (tx, ty + e)];
                    if f.poly.relation(&corners) == Relation::Inside {
                        full[t] = true;
                    }
                }
            }
        }
        Index {
            x0,
            y0,
            nx,
            ny,
            tiles,
        }
    }

    /// The facets that may contain points near `p`, front first.
    pub fn at(&self, p: P2) -> &[u32] {
        let i = ((p.0 - self.x0) / TILE).floor();
        let j = ((p.1 - self.y0) / TILE).floor();
        if !(i >= 0.0 && j >= 0.0 && (i as usize) < self.nx && (j as usize) < self.ny) {
            return &[];
        }
        &self.tiles[j as usize * self.nx + i as usize]
    }

    /// The front-most facet containing `p`.
    pub fn top(&self, facets: &[Facet], p: P2) -> Option<usize> {
        self.at(p)
            .iter()
            .map(|&f| f as usize)
            .find(|&f| facets[f].poly.contains(p, 0.0))
    }
}

/// The ideal position of observed point `(x, y)`.
pub fn to_ideal(scene: &YardScene, distort: bool, x: f64, y: f64) -> P2 {
    if distort {
        scene.lens.observed_to_ideal(x, y)
    } else {
        (x, y)
    }
}

/// The region of ideal coordinates the observed image covers.
pub fn ideal_bounds(scene: &YardScene, distort: bool) -> [f64; 4] {
    let (w, h) = (scene.width as f64, scene.height as f64);
    let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    for k in 0..=64 {
        let t = k as f64 / 64.0;
        for (x, y) in [
            (-0.5 + t * w, -0.5),
            (-0.5 + t * w, h - 0.5),
            (-0.5, -0.5 + t * h),
            (w - 0.5, -0.5 + t * h),
        ] {
            let (ix, iy) = to_ideal(scene, distort, x, y);
            b = [b[0].min(ix), b[1].min(iy), b[2].max(ix), b[3].max(iy)];
        }
    }
    b
}

/// The noise-free, unblurred image (grey levels, row-major, unclamped).
pub fn render_exact(scene: &YardScene, distort: bool) -> Vec<f64> {
    let (w, h) = (scene.width, scene.height);
    let distort = distort && !scene.lens.is_identity();
    let index = Index::new(&scene.facets, ideal_bounds(scene, distort));
    // Footprint corners, shared by neighbouring pixels.
    let mut corners = Vec::with_capacity((w + 1) * (h + 1));
    for y in 0..=h {
        for x in 0..=w {
            corners.push(to_ideal(scene, distort, x as f64 - 0.5, y as f64 - 0.5));
        }
    }
    let mut out = vec![0.0; w * h];
    let mut r = Renderer::default();
    for y in 0..h {
        for x in 0..w {
            let c = |i: usize, j: usize| corners[(y + j) * (w + 1) + x + i];
            let quad = [c(0, 0), c(1, 0), c(1, 1), c(0, 1)];
            out[y * w + x] = r.pixel(scene, &index, &quad);
        }
    }
    out
}

#[derive(Default)]
struct Renderer {
    pieces: Vec<Vec<P2>>,
    next: Vec<Vec<P2>>,
    inside: Vec<P2>,
    tmp: Vec<P2>,
}

impl Renderer {
    fn pixel(&mut self, scene: &YardScene, index: &Index, quad: &[P2; 4]) -> f64 {
        let facets = &scene.facets;
        let radiance = |f: &Facet, p: P2| scene.light.at(p.0, p.1) * f.shade.full(p.0, p.1);
        let (area, cx, cy) = poly::area_centroid(quad);
        let area = area.abs();
        if area.is_nan() || area <= 1e-12 {
            return 0.0;
        }
        let qb = quad.iter().fold(
            [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY],
            |b, p| [b[0].min(p.0), b[1].min(p.1), b[2].max(p.0), b[3].max(p.1)],
        );
        self.pieces.clear();
        let mut whole = true;
        let mut v = 0.0;
        for &fi in index.at(quad[0]) {
            let f = &facets[fi as usize];
            let b = f.poly.bbox;
            if b[0] > qb[2] || b[2] < qb[0] || b[1] > qb[3] || b[3] < qb[1] {
                continue;
            }
            let rel = f.poly.relation(quad);
            if rel == Relation::Outside {
                continue;
            }
            if whole {
                if rel == Relation::Inside {
                    return radiance(f, (cx, cy));
                }
                self.pieces.push(quad.to_vec());
                whole = false;
            }
            self.next.clear();
            for piece in &self.pieces {
                if rel == Relation::Inside {
                    let (a, px, py) = poly::area_centroid(piece);
                    v += a.abs() * radiance(f, (px, py));
                    continue;
                }
                poly::split(
                    piece,
                    &f.poly,
                    &mut self.inside,
                    &mut self.next,
                    &mut self.tmp,
                );
                if !self.inside.is_empty() {
                    let (a, px, py) = poly::area_centroid(&self.inside);
                    v += a.abs() * radiance(f, (px, py));
                }
            }
            std::mem::swap(&mut self.pieces, &mut self.next);
            if self.pieces.is_empty() {
                break;
            }
        }
        // Whatever no facet covers (outside the floor) is black.
        v / area
    }
}

/// The pillbox defocus: a disk of radius 2σ, each tap its area in the pixel
/// (16 × 16 samples), normalised; borders repeat the edge pixel.
pub fn defocus(img: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
    if !(sigma > 0.0 && sigma.is_finite()) || w == 0 || h == 0 {
        return img.to_vec();
    }
    let radius = 2.0 * sigma;
    let r = (radius + 0.5).ceil() as i64;
    let n = 16;
    let mut taps: Vec<(i64, i64, f64)> = Vec::new();
    for dy in -r..=r {
        for dx in -r..=r {
            let mut c = 0;
            for j in 0..n {
                for i in 0..n {
                    let x = dx as f64 - 0.5 + (i as f64 + 0.5) / n as f64;
                    let y = dy as f64 - 0.5 + (j as f64 + 0.5) / n as f64;
                    if x * x + y * y <= radius * radius {
                        c += 1;
                    }
                }
            }
            if c > 0 {
                taps.push((dx, dy, c as f64));
            }
        }
    }
    let s: f64 = taps.iter().map(|t| t.2).sum();
    taps.iter_mut().for_each(|t| t.2 /= s);
    let (wi, hi) = (w as i64, h as i64);
    let mut out = vec![0.0; w * h];
    for y in 0..hi {
        for x in 0..wi {
            let mut a = 0.0;
            for &(dx, dy, k) in &taps {
                let (sx, sy) = ((x + dx).clamp(0, wi - 1), (y + dy).clamp(0, hi - 1));
                a += k * img[(sy * wi + sx) as usize];
            }
            out[(y * wi + x) as usize] = a;
        }
    }
    out
}

/// Sensor noise and 8-bit quantisation of a defocused render.
pub fn expose(img: &[f64], w: usize, h: usize, noise: YardNoise, seed: u64) -> GreyImage {
    let mut rng = Pcg32::new(seed, 0x0153);
    let data: Vec<u8> = img
        .iter()
        .map(|&v| {
            let v = v.max(0.0);
            let sd = match noise {
                YardNoise::Gauss(s) if s.is_finite() && s > 0.0 => s,
                YardNoise::Signal { gain, read } => (gain.max(0.0) * v + read * read).sqrt(),
                _ => 0.0,
            };
            let n = if sd > 0.0 { sd * rng.gauss() } else { 0.0 };
            (v + n).round().clamp(0.0, 255.0) as u8
        })
        .collect();
    GreyImage::new(w, h, data).unwrap_or_else(|_| GreyImage::filled(1, 1, 0).unwrap_or_default())
}
