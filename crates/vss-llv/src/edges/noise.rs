//! The noise scale of a response, per tile of the image: what the edge
//! points' threshold and the line extractor's significance test measure
//! responses against, instead of a fixed number of grey levels.
//!
//! On pure noise the Lee response is a zero-mean normal variable with
//! standard deviation `σ_r = σ · ‖φ'‖` (σ the pixels' noise); its median
//! magnitude is `0.6745 σ_r`. Edges are sparse, so the median magnitude of
//! a tile's responses estimates `σ_r` robustly whatever the contrast of the
//! edges in it, and so does it for anything else that is not a straight
//! edge: surface texture, sensor patterns, the noise of the lens
//! correction's resampling — it measures what the detector sees, without a
//! model of the camera. Tiles follow the noise where it changes across the
//! image (signal-dependent noise, vignetting, a spot light); an edge
//! crossing a tile raises its estimate by a few percent, which errs on the
//! safe side.
//!
//! Cost: a histogram of the integer magnitudes of every second pixel of
//! every fourth line (1/8 of the pixels; 512 samples a 64 × 64 tile, for a
//! median within about 6 %). A sampled line's bins are computed at once in
//! SIMD lanes, and each tile of the row of tiles counts its samples from
//! them: the count is then two instructions a sample.

use super::band::{Rows, Whole};
use super::{NONE, Response, key};

/// Tile side (px) of the noise estimate; an image side shorter than two
/// tiles is one tile.
pub const TILE: usize = 64;

/// Samples a tile needs for its own estimate; tiles with fewer (mostly
/// outside the valid area) take the median of the others.
const MIN_SAMPLES: usize = 32;

/// Histogram bins: magnitudes above the last are counted in it (they are
/// edges, far above any median: the last bin is 28 grey levels at A = 3,
/// 16 at A = 5).
const BINS: usize = 2048;

/// Lines and pixels along them between two samples.
const ROW_STEP: usize = 4;
const COLUMN_STEP: usize = 2;

/// The median magnitude of a standard normal variable.
pub const MEDIAN_TO_SIGMA: f32 = 1.0 / 0.674_489_75;

/// Per tile, the estimated standard deviation of the response on noise
/// (grey levels), for one scan direction of one image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NoiseMap {
    width: usize,
    height: usize,
    /// Tiles across and down, and their sizes (px; the last tile of a row
    /// or column also takes the remainder).
    nx: usize,
    ny: usize,
    tw: usize,
    th: usize,
    sigma: Vec<f32>,
    /// The median of the tiles' estimates (0 if none had samples).
    global: f32,
}

/// Reusable buffers of the estimate.
#[derive(Clone, Debug, Default)]
pub struct NoiseScratch {
    /// A row of tiles' histograms.
    hist: Vec<u16>,
    /// One row's bins.
    bins: Vec<u16>,
    known: Vec<f32>,
}

impl NoiseMap {
    /// A map that puts every tile at `sigma` (tests, or a response whose
    /// noise is known).
    pub fn uniform(width: usize, height: usize, sigma: f32) -> Self {
        let mut m = NoiseMap::default();
        m.shape(width, height);
        m.sigma.iter_mut().for_each(|s| *s = sigma);
        m.global = sigma;
        m
    }

    fn shape(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.nx = (width / TILE).max(1);
        self.ny = (height / TILE).max(1);
        self.tw = (width / self.nx).max(1);
        self.th = (height / self.ny).max(1);
        self.sigma.clear();
        self.sigma.resize(self.nx * self.ny, 0.0);
    }

    /// Tiles across and down.
    pub fn tiles(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The tile of pixel `(x, y)` (clamped into the image).
    #[inline]
    pub fn tile_of(&self, x: usize, y: usize) -> usize {
        self.row_of(y) + self.column_of(x)
    }

    /// The tile column of image column `x` (clamped into the map).
    #[inline]
    fn column_of(&self, x: usize) -> usize {
        (x / self.tw.max(1)).min(self.nx.max(1) - 1)
    }

    /// The tile column of every image column `0..w` into `out` (the tile
    /// of `(x, y)` is `row_of(y) + out[x]`).
    pub fn columns_into(&self, w: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend((0..w).map(|x| self.column_of(x) as u32));
    }

    /// The first tile of the row of tiles of image row `y`.
    #[inline]
    pub fn row_of(&self, y: usize) -> usize {
        (y / self.th.max(1)).min(self.ny.max(1) - 1) * self.nx
    }

    /// σ of tile `t` (grey levels).
    #[inline]
    pub fn sigma(&self, t: usize) -> f32 {
        self.sigma.get(t).copied().unwrap_or(self.global)
    }

    /// σ at pixel `(x, y)` (grey levels).
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        if self.sigma.is_empty() {
            return self.global;
        }
        self.sigma(self.tile_of(x, y))
    }

    /// The median of the tiles' estimates (grey levels).
    pub fn global(&self) -> f32 {
        self.global
    }

    /// Estimates the map of a response (see the module doc).
    pub fn estimate(r: &Response) -> Self {
        let mut m = NoiseMap::default();
        m.estimate_into(r, &mut NoiseScratch::default());
        m
    }

    /// [`NoiseMap::estimate`] into reusable buffers.
    pub fn estimate_into(&mut self, r: &Response, s: &mut NoiseScratch) {
        let (w, h) = (r.width, r.height);
        if !r.covers(w, h) {
            self.shape(w, h);
            self.global = 0.0;
            return;
        }
        self.estimate_rows(w, h, r.scale(), &mut Whole(r.sums(), w), s);
    }

    /// [`NoiseMap::estimate_into`] of a `w × h` response of `scale` grey
    /// levels a unit whose rows `rows` gives, a row of tiles at a time.
    pub(crate) fn estimate_rows<R: Rows>(
        &mut self,
        w: usize,
        h: usize,
        scale: f32,
        rows: &mut R,
        s: &mut NoiseScratch,
    ) {
        self.shape(w, h);
        self.global = 0.0;
        if w == 0 || h == 0 {
            return;
        }
        s.known.clear();
        let nx = self.nx;
        // A histogram per tile of the row of tiles, and a bin more for
        // NONE.
        let stride = BINS + 1;
        s.hist.clear();
        s.hist.resize(nx * stride, 0);
        s.bins.clear();
        s.bins.resize(w, 0);
        for ty in 0..self.ny {
            let y0 = ty * self.th;
            let y1 = if ty + 1 == self.ny { h } else { y0 + self.th };
            s.hist.fill(0);
            rows.load(y0, y1);
            let mut y = y0 + 1;
            while y < y1 {
                // The row's bins at once (lanes), then each tile's samples
                // counted from them.
                bins_of(rows.row(y), &mut s.bins);
                for (tx, hist) in s.hist.chunks_exact_mut(stride).enumerate() {
                    let x0 = tx * self.tw;
                    let x1 = if tx + 1 == nx { w } else { x0 + self.tw };
                    for &b in s.bins[x0..x1].iter().step_by(COLUMN_STEP) {
                        hist[usize::from(b)] += 1;
                    }
                }
                y += ROW_STEP;
            }
            for (tx, hist) in s.hist.chunks_exact(stride).enumerate() {
                let x0 = tx * self.tw;
                let x1 = if tx + 1 == nx { w } else { x0 + self.tw };
                let rows = (y1.saturating_sub(y0 + 1)).div_ceil(ROW_STEP);
                let n = rows * (x1 - x0).div_ceil(COLUMN_STEP) - usize::from(hist[BINS]);
                let t = ty * nx + tx;
                self.sigma[t] = if n >= MIN_SAMPLES {
                    let sigma = median_bin(&hist[..BINS], n) * scale * MEDIAN_TO_SIGMA;
                    s.known.push(sigma);
                    sigma
                } else {
                    f32::NAN
                };
            }
        }
        if !s.known.is_empty() {
            let mid = s.known.len() / 2;
            let (_, m, _) = s.known.select_nth_unstable_by(mid, f32::total_cmp);
            self.global = *m;
        }
        let g = self.global;
        for v in &mut self.sigma {
            if v.is_nan() {
                *v = g;
            }
        }
    }
}

impl NoiseMap {
    /// Bounds every tile's σ to `[lo, cap · lo]`, `lo` the `pct`-th
    /// percentile of the tiles' estimates: the image's least textured
    /// tiles measure its sensor noise, so a flat tile (sky, a JPEG's
    /// quantised gradients) does not set a threshold below the camera's
    /// noise, and a textured one (gravel) not one far above it.
    /// `pct` ≤ 0 leaves the map as it is.
    pub fn bound(&mut self, pct: f64, cap: f64, s: &mut NoiseScratch) {
        if pct.is_nan() || pct <= 0.0 || self.sigma.is_empty() {
            return;
        }
        let v = &mut s.known;
        v.clear();
        v.extend_from_slice(&self.sigma);
        let k = ((pct / 100.0 * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
        let (_, lo, _) = v.select_nth_unstable_by(k, f32::total_cmp);
        let lo = *lo;
        let hi = if cap > 0.0 { lo * cap as f32 } else { f32::MAX };
        for s in &mut self.sigma {
            *s = s.clamp(lo, hi.max(lo));
        }
        self.global = self.global.clamp(lo, hi.max(lo));
    }
}

/// Each sum's histogram bin: its magnitude, at most `BINS - 1`, and `BINS`
/// for [`NONE`] (whose key, `i16::MAX`, no real sum has). Plain code the
/// compiler puts in lanes (AVX2 where the processor has it).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
fn bins_of(row: &[i16], out: &mut [u16]) {
    for (b, &v) in out.iter_mut().zip(row) {
        let k = key(v) as u16;
        *b = if v == NONE {
            BINS as u16
        } else {
            k.min(BINS as u16 - 1)
        };
    }
}

/// The median of `n` samples in a histogram of whole-number magnitudes
/// (the mean of the two middle samples' bins for an even count).
fn median_bin(hist: &[u16], n: usize) -> f32 {
    let (lo_rank, hi_rank) = ((n - 1) / 2, n / 2);
    let (mut cum, mut lo) = (0usize, None);
    for (b, &c) in hist.iter().enumerate() {
        cum += usize::from(c);
        if lo.is_none() && cum > lo_rank {
            lo = Some(b);
        }
        if cum > hi_rank {
            return 0.5 * (lo.unwrap_or(b) + b) as f32;
        }
    }
    lo.unwrap_or(0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::response;
    use crate::rng::SplitMix64;
    use crate::{GreyImage, ScanDir};

    fn noisy(w: usize, h: usize, sigma: impl Fn(usize, usize) -> f64, seed: u64) -> GreyImage {
        let mut rng = SplitMix64::new(seed);
        let mut d = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                d.push(
                    (128.0 + sigma(x, y) * rng.gauss())
                        .round()
                        .clamp(0.0, 255.0) as u8,
                );
            }
        }
        GreyImage::new(w, h, d).unwrap()
    }

    fn map_of(img: &GreyImage, dir: ScanDir) -> NoiseMap {
        NoiseMap::estimate(&response(img, dir, 4).unwrap())
    }

    /// Kernel norm ‖φ'‖ for A = 4.
    const NORM4: f64 = 0.773_1;

    #[test]
    fn the_estimate_follows_the_noise_per_tile() {
        // Noise σ 3 on the left half, 9 on the right.
        let img = noisy(256, 128, |x, _| if x < 128 { 3.0 } else { 9.0 }, 7);
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let m = map_of(&img, dir);
            assert_eq!(m.tiles(), (4, 2));
            for (x, s) in [(10, 3.0), (100, 3.0), (150, 9.0), (250, 9.0)] {
                let want = s * NORM4;
                let got = m.at(x, 70) as f64;
                assert!(
                    (got / want - 1.0).abs() < 0.12,
                    "{dir:?} x {x}: {got} vs {want}"
                );
            }
        }
    }

    /// The estimate the module doc describes, tile by tile with a sort: the
    /// reference for the row-wise histograms.
    fn reference(r: &crate::edges::Response) -> Vec<f32> {
        let m = NoiseMap::estimate(r);
        let (w, h) = (r.width, r.height);
        let mut out = Vec::new();
        for ty in 0..m.ny {
            let y0 = ty * m.th;
            let y1 = if ty + 1 == m.ny { h } else { y0 + m.th };
            for tx in 0..m.nx {
                let x0 = tx * m.tw;
                let x1 = if tx + 1 == m.nx { w } else { x0 + m.tw };
                let mut v: Vec<usize> = (y0 + 1..y1)
                    .step_by(ROW_STEP)
                    .flat_map(|y| (x0..x1).step_by(COLUMN_STEP).map(move |x| y * w + x))
                    .map(|i| r.sums()[i])
                    .filter(|&s| s != NONE)
                    .map(|s| (key(s) as usize).min(BINS - 1))
                    .collect();
                v.sort_unstable();
                let n = v.len();
                out.push(if n >= MIN_SAMPLES {
                    0.5 * (v[(n - 1) / 2] + v[n / 2]) as f32 * r.scale() * MEDIAN_TO_SIGMA
                } else {
                    f32::NAN
                });
            }
        }
        out
    }

    #[test]
    fn the_row_wise_histograms_give_each_tile_s_median() {
        for (w, h) in [(512, 512), (200, 130), (127, 300), (16, 16), (1000, 70)] {
            let mut img = noisy(w, h, |x, y| 2.0 + ((x * 7 + y * 3) % 11) as f64, 9);
            if w > 100 {
                // Some pixels without a response, as lens correction leaves.
                let mask: Vec<bool> = (0..w * h)
                    .map(|i| i % 13 != 0 && (i / w) % 50 > 3)
                    .collect();
                img.set_valid_mask(Some(mask)).unwrap();
            }
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let r = response(&img, dir, 4).unwrap();
                let m = NoiseMap::estimate(&r);
                let want = reference(&r);
                assert_eq!(want.len(), m.sigma.len());
                for (t, (&got, &want)) in m.sigma.iter().zip(&want).enumerate() {
                    let want = if want.is_nan() { m.global() } else { want };
                    assert_eq!(got, want, "{w}x{h} {dir:?} tile {t}");
                }
            }
        }
    }

    #[test]
    fn flat_tiny_and_empty_images_give_finite_scales() {
        let flat = GreyImage::filled(16, 16, 90).unwrap();
        let m = map_of(&flat, ScanDir::Horizontal);
        assert_eq!(m.tiles(), (1, 1));
        assert_eq!(m.at(3, 3), 0.0);
        let mut masked = noisy(100, 100, |_, _| 4.0, 3);
        masked.set_valid_mask(Some(vec![false; 100 * 100])).unwrap();
        let m = map_of(&masked, ScanDir::Vertical);
        assert_eq!(m.global(), 0.0);
        assert!(m.at(50, 50).is_finite());
        assert_eq!(NoiseMap::default().at(5, 5), 0.0);
    }

    #[test]
    fn median_of_a_histogram() {
        assert_eq!(median_bin(&[0, 3, 0, 2], 5), 1.0);
        assert_eq!(median_bin(&[1, 0, 0, 1], 2), 1.5);
        assert_eq!(median_bin(&[4], 4), 0.0);
    }
}
