//! Bilinear resampling through a [`LensMap`]: the hot loop of lens
//! correction, written so the compiler vectorises it on baseline x86-64.
//!
//! The fixed-point arithmetic is the reference one (kept as [`exact`] for
//! fixups and as the unit tests' reference):
//!
//! ```text
//! top = p00·256 + fx·(p10 − p00)          bot = p01·256 + fx·(p11 − p01)
//! v   = (top·256 + fy·(bot − top) + 32768) >> 16
//! ```
//!
//! [`pixel`] computes the same `v` in 16-bit lanes only. With fx, fy < 256:
//! `top = p00·(256 − fx) + p10·fx ≤ 65280` (a weighted mean of bytes times
//! 256), likewise `bot`. Split `top = 256·tH + tL`, `bot = 256·bH + bL`;
//! then `top·(256 − fy) + bot·fy = 256·H + L` with
//! `H = tH·(256 − fy) + bH·fy ≤ 65280` and `L = tL·(256 − fy) + bL·fy ≤ 65280`,
//! and `v = ⌊(256·H + L + 32768) / 65536⌋ = (H + (L >> 8) + 128) >> 8`
//! (floor of a floor). Since `256·H + L ≤ 65280·256`, `H + (L >> 8) + 128 ≤
//! 65408`: no step overflows 16 bits.

use super::map::{LensMap, OUTSIDE};

/// Pixels per vector step: 16 bytes in, two 8 × u16 halves of arithmetic.
const LANES: usize = 16;

/// The reference fixed-point bilinear sample (any fx, fy in 0..=256).
#[inline]
fn exact(p00: u8, p10: u8, p01: u8, p11: u8, fx: u16, fy: u16) -> u8 {
    let (fx, fy) = (fx as i32, fy as i32);
    let top = p00 as i32 * 256 + fx * (p10 as i32 - p00 as i32);
    let bot = p01 as i32 * 256 + fx * (p11 as i32 - p01 as i32);
    ((top * 256 + fy * (bot - top) + 32768) >> 16) as u8
}

/// [`exact`] for fx, fy < 256 in 16-bit arithmetic (module docs).
#[inline(always)]
fn pixel(p00: u8, p10: u8, p01: u8, p11: u8, fx: u8, fy: u8) -> u8 {
    let (fx, fy) = (fx as u16, fy as u16);
    let (gx, gy) = (256 - fx, 256 - fy);
    let top = p00 as u16 * gx + p10 as u16 * fx;
    let bot = p01 as u16 * gx + p11 as u16 * fx;
    let h = (top >> 8) * gy + (bot >> 8) * fy;
    let l = (top & 255) * gy + (bot & 255) * fy;
    ((h + (l >> 8) + 128) >> 8) as u8
}

/// `LANES` bytes of `s` from `k`, as an array (the compiler then knows the
/// length and emits one vector load).
#[inline(always)]
fn lanes(s: &[u8], k: usize) -> Option<&[u8; LANES]> {
    s.get(k..k + LANES)?.try_into().ok()
}

/// One vector step: `LANES` consecutive output pixels; `a0`, `a1` are the
/// top row at the pixels' left and right neighbours, `b0`, `b1` the bottom.
#[inline(always)]
fn step(
    [a0, a1, b0, b1]: [&[u8; LANES]; 4],
    fx: &[u8; LANES],
    fy: &[u8; LANES],
    out: &mut [u8; LANES],
) {
    for j in 0..LANES {
        out[j] = pixel(a0[j], a1[j], b0[j], b1[j], fx[j], fy[j]);
    }
}

/// Resamples one run: `out[k]` from `a[k..k + 2]` (top source row),
/// `b[k..k + 2]` (bottom row) and the fractions `fx[k]`, `fy[k]`.
/// `a` and `b` hold one pixel more than `out`; `fx`, `fy` as many.
#[inline(always)]
fn run(a: &[u8], b: &[u8], fx: &[u8], fy: &[u8], out: &mut [u8]) {
    let n = out.len();
    if n < LANES {
        for (k, o) in out.iter_mut().enumerate() {
            if let (Some(a), Some(b), Some(&fx), Some(&fy)) =
                (a.get(k..k + 2), b.get(k..k + 2), fx.get(k), fy.get(k))
            {
                *o = pixel(a[0], a[1], b[0], b[1], fx, fy);
            }
        }
        return;
    }
    let (Some(a0), Some(a1), Some(b0), Some(b1), Some(fx), Some(fy)) = (
        a.get(..n),
        a.get(1..n + 1),
        b.get(..n),
        b.get(1..n + 1),
        fx.get(..n),
        fy.get(..n),
    ) else {
        return;
    };
    // Whole steps, walking all seven slices in lockstep (no per-step
    // bounds checks) ...
    let steps = out
        .chunks_exact_mut(LANES)
        .zip(a0.chunks_exact(LANES))
        .zip(a1.chunks_exact(LANES))
        .zip(b0.chunks_exact(LANES))
        .zip(b1.chunks_exact(LANES))
        .zip(fx.chunks_exact(LANES))
        .zip(fy.chunks_exact(LANES));
    for ((((((o, a0), a1), b0), b1), fx), fy) in steps {
        // Exact chunks: the conversions cannot fail (and compile away).
        if let (Ok(o), Ok(a0), Ok(a1), Ok(b0), Ok(b1), Ok(fx), Ok(fy)) = (
            o.try_into(),
            a0.try_into(),
            a1.try_into(),
            b0.try_into(),
            b1.try_into(),
            fx.try_into(),
            fy.try_into(),
        ) {
            step([a0, a1, b0, b1], fx, fy, o);
        }
    }
    // ... then one step aligned to the end of the run for the remainder (it
    // recomputes a few pixels with the same result).
    if !n.is_multiple_of(LANES) {
        let k = n - LANES;
        let chunks = (
            lanes(a0, k),
            lanes(a1, k),
            lanes(b0, k),
            lanes(b1, k),
            lanes(fx, k),
            lanes(fy, k),
            out.get_mut(k..)
                .and_then(|s| <&mut [u8; LANES]>::try_from(s).ok()),
        );
        if let (Some(a0), Some(a1), Some(b0), Some(b1), Some(fx), Some(fy), Some(o)) = chunks {
            step([a0, a1, b0, b1], fx, fy, o);
        }
    }
}

/// The corrected pixels of `src` through `map` into `out` (every pixel is
/// written; outside ones are 0). `src` and `out` have the map's size.
/// Compiled for AVX2 too and chosen at run time (sixteen 16-bit lanes a
/// step instead of eight).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
pub(super) fn values(src: &[u8], map: &LensMap, out: &mut [u8]) {
    let w = map.width;
    for r in &map.runs {
        let Some(o) = out.get_mut(r.start..r.start + r.len) else {
            continue;
        };
        if r.src == OUTSIDE {
            o.fill(0);
            continue;
        }
        let (Some(a), Some(b), Some(fx), Some(fy)) = (
            src.get(r.src..r.src + r.len + 1),
            src.get(r.src + w..r.src + w + r.len + 1),
            map.fx.get(r.start..r.start + r.len),
            map.fy.get(r.start..r.start + r.len),
        ) else {
            continue;
        };
        run(a, b, fx, fy, o);
    }
    for f in &map.fixups {
        if let (Some(a), Some(b), Some(o)) = (
            src.get(f.src..f.src + 2),
            src.get(f.src + w..f.src + w + 2),
            out.get_mut(f.out),
        ) {
            *o = exact(a[0], a[1], b[0], b[1], f.fx, f.fy);
        }
    }
}

/// The validity mask of a corrected image whose source has no mask: a
/// property of the map alone (false where the source is outside).
pub(super) fn map_mask(map: &LensMap, mask: &mut [bool]) {
    // Fill maximal spans of equal validity (a few per row).
    let mut span = (0usize, true);
    let mut at = 0usize;
    for r in &map.runs {
        let v = r.src != OUTSIDE;
        if v != span.1 {
            if let Some(m) = mask.get_mut(span.0..at) {
                m.fill(span.1);
            }
            span = (at, v);
        }
        at = r.start + r.len;
    }
    if let Some(m) = mask.get_mut(span.0..at) {
        m.fill(span.1);
    }
}

/// The validity mask of a corrected image whose source has mask `smask`:
/// an output pixel is valid when its source is inside and all four source
/// pixels are valid. Invalid pixels of `out` are set to 0. Returns whether
/// any pixel is invalid.
pub(super) fn masked(smask: &[bool], map: &LensMap, mask: &mut [bool], out: &mut [u8]) -> bool {
    let w = map.width;
    for r in &map.runs {
        let Some(m) = mask.get_mut(r.start..r.start + r.len) else {
            continue;
        };
        if r.src == OUTSIDE {
            m.fill(false);
            continue;
        }
        let (Some(a), Some(b)) = (
            smask.get(r.src..r.src + r.len + 1),
            smask.get(r.src + w..r.src + w + r.len + 1),
        ) else {
            m.fill(false);
            continue;
        };
        let (a0, a1, b0, b1) = (&a[..r.len], &a[1..], &b[..r.len], &b[1..]);
        for ((((m, &a0), &a1), &b0), &b1) in m.iter_mut().zip(a0).zip(a1).zip(b0).zip(b1) {
            *m = a0 & a1 & b0 & b1;
        }
    }
    for f in map.fixups.iter().chain(&map.shifted) {
        if let (Some(a), Some(b), Some(m)) = (
            smask.get(f.src..f.src + 2),
            smask.get(f.src + w..f.src + w + 2),
            mask.get_mut(f.out),
        ) {
            *m = a[0] & a[1] & b[0] & b[1];
        }
    }
    let mut all = true;
    for (d, &m) in out.iter_mut().zip(mask.iter()) {
        *d = if m { *d } else { 0 };
        all &= m;
    }
    !all
}

#[cfg(test)]
mod tests {
    use super::super::{CameraModel, correct};
    use super::*;
    use crate::GreyImage;
    use crate::rng::SplitMix64;

    /// Today's straightforward implementation, kept as the reference: a
    /// per-pixel source index (`u32::MAX` outside) and 1/256 px offsets,
    /// validity checked per pixel.
    struct Reference {
        w: usize,
        h: usize,
        index: Vec<u32>,
        frac: Vec<[u16; 2]>,
    }

    impl Reference {
        fn new(w: usize, h: usize, source: impl Fn(usize, usize) -> (f64, f64)) -> Reference {
            let n = w * h;
            let mut r = Reference {
                w,
                h,
                index: Vec::new(),
                frac: Vec::new(),
            };
            let (xmax, ymax) = (w.saturating_sub(1) as f64, h.saturating_sub(1) as f64);
            let too_big = w < 2 || h < 2 || n >= u32::MAX as usize;
            for y in 0..h {
                for x in 0..w {
                    let (xs, ys) = source(x, y);
                    let inside =
                        xs >= -1e-3 && ys >= -1e-3 && xs <= xmax + 1e-3 && ys <= ymax + 1e-3;
                    if !inside || too_big {
                        r.index.push(u32::MAX);
                        r.frac.push([0, 0]);
                        continue;
                    }
                    let (xc, yc) = (xs.clamp(0.0, xmax), ys.clamp(0.0, ymax));
                    let x0 = (xc as usize).min(w - 2);
                    let y0 = (yc as usize).min(h - 2);
                    let fx = ((xc - x0 as f64) * 256.0).round() as u16;
                    let fy = ((yc - y0 as f64) * 256.0).round() as u16;
                    r.index.push((y0 * w + x0) as u32);
                    r.frac.push([fx, fy]);
                }
            }
            r
        }

        fn source(&self, x: usize, y: usize) -> Option<(f32, f32)> {
            let i = y * self.w + x;
            let idx = self.index[i];
            if idx == u32::MAX {
                return None;
            }
            let [fx, fy] = self.frac[i];
            let (x0, y0) = (idx as usize % self.w, idx as usize / self.w);
            Some((x0 as f32 + fx as f32 / 256.0, y0 as f32 + fy as f32 / 256.0))
        }

        fn correct(&self, img: &GreyImage) -> GreyImage {
            let (w, n) = (self.w, self.w * self.h);
            let src = img.data();
            let smask = img.valid_mask();
            let valid = |i: u32| -> bool {
                let i = i as usize;
                i != u32::MAX as usize
                    && i + w + 1 < n
                    && smask.is_none_or(|m| m[i] && m[i + 1] && m[i + w] && m[i + w + 1])
            };
            let mut data = vec![0u8; n];
            let mut any_invalid = false;
            for ((d, &i), &[fx, fy]) in data.iter_mut().zip(&self.index).zip(&self.frac) {
                if !valid(i) {
                    *d = 0;
                    any_invalid = true;
                    continue;
                }
                let i = i as usize;
                let (p00, p10, p01, p11) = (src[i], src[i + 1], src[i + w], src[i + w + 1]);
                let (fx, fy) = (fx as i32, fy as i32);
                let top = p00 as i32 * 256 + fx * (p10 as i32 - p00 as i32);
                let bot = p01 as i32 * 256 + fx * (p11 as i32 - p01 as i32);
                *d = ((top * 256 + fy * (bot - top) + 32768) >> 16) as u8;
            }
            let mut o = GreyImage::new(self.w, self.h, data).unwrap();
            if any_invalid {
                o.set_valid_mask(Some(self.index.iter().map(|&i| valid(i)).collect()))
                    .unwrap();
            }
            o
        }
    }

    /// Uniform in `0..n`: the generator's next value modulo `n`.
    fn below(rng: &mut SplitMix64, n: u64) -> u64 {
        rng.next_u64() % n
    }

    /// A random image; bytes often at the extremes 0 and 255 (the bounds of
    /// the 16-bit arithmetic), with a random validity mask when `masked`.
    fn random_image(w: usize, h: usize, seed: u64, masked: bool) -> GreyImage {
        let mut rng = SplitMix64::new(seed);
        let data = (0..w * h)
            .map(|_| match below(&mut rng, 4) {
                0 => 0,
                1 => 255,
                _ => below(&mut rng, 256) as u8,
            })
            .collect();
        let mut img = GreyImage::new(w, h, data).unwrap();
        if masked {
            let mask = (0..w * h).map(|_| below(&mut rng, 10) != 0).collect();
            img.set_valid_mask(Some(mask)).unwrap();
        }
        img
    }

    /// A random camera scaled to the image, distorting by several pixels,
    /// barrel or pincushion.
    fn random_camera(w: usize, h: usize, rng: &mut SplitMix64) -> CameraModel {
        let s = 512.0 / w.max(h) as f64;
        let mut c = |scale: f64| (rng.uniform() * 2.0 - 1.0) * scale;
        CameraModel {
            cx: w as f64 / 2.0 + c(5.0),
            cy: h as f64 / 2.0 + c(5.0),
            sx: 0.0086 * s,
            sy: 0.0083 * s,
            f: 8.5,
            distortion: Some([c(3e-3), c(3e-4), c(3e-4), c(2e-4), c(2e-4)]),
            radial: [0.0; 2],
        }
    }

    /// Per-pixel sources that stress every case of the map: near-integer
    /// fractions (rounding to 256/256), the exact borders and their
    /// tolerance, far outside, smooth shifts and random jumps.
    fn jitter_source(w: usize, h: usize, seed: u64) -> impl Fn(usize, usize) -> (f64, f64) + Copy {
        let (xmax, ymax) = (w as f64 - 1.0, h as f64 - 1.0);
        move |x, y| {
            let mut rng =
                SplitMix64::new(seed ^ ((y * w + x) as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
            let pick = |v: f64, max: f64, rng: &mut SplitMix64| match below(rng, 12) {
                0 => v.floor() + 0.999,
                1 => v.floor() + 255.5 / 256.0,
                2 => v.floor() + 255.49 / 256.0,
                3 => -1e-3,
                4 => -2e-3,
                5 => max + 1e-3,
                6 => max + 5e-4,
                7 => max,
                8 => rng.uniform() * (max + 4.0) - 2.0,
                _ => v,
            };
            let (dx, dy) = (
                0.3 + 0.7 * (y as f64 / h as f64),
                -0.4 + 0.2 * (x as f64 / w as f64),
            );
            let (xs, ys) = (x as f64 + dx, y as f64 + dy);
            if below(&mut rng, 3) == 0 {
                (pick(xs, xmax, &mut rng), pick(ys, ymax, &mut rng))
            } else {
                (xs, ys)
            }
        }
    }

    fn check(w: usize, h: usize, source: impl Fn(usize, usize) -> (f64, f64) + Copy, seed: u64) {
        let map = LensMap::from_sources(w, h, source);
        let reference = Reference::new(w, h, source);
        for y in 0..h {
            for x in 0..w {
                assert_eq!(
                    map.source(x, y),
                    reference.source(x, y),
                    "{w}×{h} seed {seed}: source of ({x}, {y})"
                );
            }
        }
        for masked in [false, true] {
            let img = random_image(w, h, seed.wrapping_add(masked as u64), masked);
            let want = reference.correct(&img);
            let got = correct(&img, &map).unwrap();
            assert_eq!(
                got.data(),
                want.data(),
                "{w}×{h} seed {seed} masked {masked}"
            );
            assert_eq!(
                got.valid_mask(),
                want.valid_mask(),
                "{w}×{h} seed {seed} masked {masked}: mask"
            );
        }
    }

    const SIZES: [(usize, usize); 9] = [
        (16, 16),
        (37, 53),
        (130, 17),
        (17, 130),
        (300, 3),
        (2, 2),
        (1, 5),
        (5, 1),
        (64, 48),
    ];

    #[test]
    fn matches_the_reference_on_camera_maps() {
        let mut rng = SplitMix64::new(7);
        for (w, h) in SIZES {
            for k in 0..4 {
                let m = random_camera(w, h, &mut rng);
                let src = |x: usize, y: usize| m.ideal_to_observed_converged(x as f64, y as f64);
                check(w, h, src, rng.next_u64() + k);
            }
        }
    }

    #[test]
    fn matches_the_reference_on_jittered_maps() {
        for (w, h) in SIZES {
            for seed in 0..6u64 {
                check(w, h, jitter_source(w, h, seed), seed);
            }
        }
    }

    #[test]
    fn matches_the_reference_on_shifts_with_whole_pixel_fractions() {
        // Fractions that round to 256/256 on every pixel of a row or column,
        // and shifts that keep every source inside (no mask at all).
        for (w, h) in SIZES {
            for (dx, dy) in [
                (0.999, 0.0),
                (0.0, 0.999),
                (0.999, 0.999),
                (-0.3, 0.25),
                (0.0, 0.0),
                (1.5, -2.25),
            ] {
                check(w, h, move |x, y| (x as f64 + dx, y as f64 + dy), 3);
            }
        }
    }

    #[test]
    fn the_16_bit_form_equals_the_reference_for_every_fraction() {
        // Every (fx, fy) below 256 with the extreme neighbourhoods (where an
        // overflow would show; the debug build also checks every step) and
        // random ones.
        let mut rng = SplitMix64::new(5);
        let mut quads: Vec<[u8; 4]> = (0..16u8)
            .map(|m| [0, 1, 2, 3].map(|b| if m >> b & 1 == 1 { 255 } else { 0 }))
            .collect();
        quads.extend((0..48).map(|_| [0; 4].map(|_: u8| below(&mut rng, 256) as u8)));
        for fx in 0..=255u8 {
            for fy in 0..=255u8 {
                for &[p00, p10, p01, p11] in &quads {
                    assert_eq!(
                        pixel(p00, p10, p01, p11, fx, fy),
                        exact(p00, p10, p01, p11, fx as u16, fy as u16),
                        "{p00} {p10} {p01} {p11} at ({fx}, {fy})"
                    );
                }
            }
        }
    }

    #[test]
    fn a_reused_output_is_the_same_as_a_fresh_one() {
        let (w, h) = (37, 53);
        let m = random_camera(w, h, &mut SplitMix64::new(11));
        let map = LensMap::new(&m, w, h);
        let mut out = GreyImage::filled(64, 64, 77).unwrap();
        for seed in 0..4 {
            let img = random_image(w, h, seed, seed % 2 == 1);
            super::super::correct_into(&img, &map, &mut out).unwrap();
            assert_eq!(out, correct(&img, &map).unwrap());
        }
    }
}
