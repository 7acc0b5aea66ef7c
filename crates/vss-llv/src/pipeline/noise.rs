//! The image's noise level, which picks the kernel's half-width of a run.

use crate::GreyImage;

/// The image's noise σ (grey levels) by Immerkær's method ("Fast noise
/// variance estimation", CVIU 64, 1996): the mean magnitude of the
/// difference of two Laplacians, `σ = √(π/2) / 6 · mean |I ∗ N|`, which
/// cancels straight edges and smooth shading and keeps what changes from
/// pixel to pixel. Texture raises it too, which is what a wider kernel is
/// also for; pixels whose 3 × 3 window is not all valid are left out.
///
/// `N` is separable, `[1 −2 1]` down times `[1 −2 1]` across: each row's
/// second difference across is made once and the three rows' are combined
/// down, in whole numbers, so the sum is exact and the loops run in vector
/// lanes.
pub fn noise_level(img: &GreyImage) -> f64 {
    noise_level_with(img, &mut Vec::new())
}

/// [`noise_level`] with the rows' buffer `buf` given (the pipeline's, so
/// that its warm runs allocate nothing).
pub fn noise_level_with(img: &GreyImage, buf: &mut Vec<i16>) -> f64 {
    let (w, h) = img.size();
    if w < 3 || h < 3 {
        return 0.0;
    }
    let d = img.data();
    let mask = img.valid_mask();
    let (mut sum, mut n) = (0u64, 0u64);
    // Second differences across of the three rows under the window.
    buf.clear();
    buf.resize(3 * (w - 2), 0);
    let (r0, rest) = buf.split_at_mut(w - 2);
    let (r1, r2) = rest.split_at_mut(w - 2);
    let mut across = [r0, r1, r2];
    for (y, row) in across.iter_mut().enumerate().take(2) {
        second_difference(&d[y * w..(y + 1) * w], row);
    }
    for y in 1..h - 1 {
        // Rows y − 1, y, y + 1 are in `across[(y − 1) % 3]`, … .
        second_difference(&d[(y + 1) * w..(y + 2) * w], across[(y + 1) % 3]);
        let (a, b, c) = (
            &*across[(y - 1) % 3],
            &*across[y % 3],
            &*across[(y + 1) % 3],
        );
        match mask {
            None => {
                // |v| ≤ 16 · 255 fits i16, and a chunk of 2¹⁶ of them sums
                // in u32.
                for ((a, b), c) in a
                    .chunks(1 << 16)
                    .zip(b.chunks(1 << 16))
                    .zip(c.chunks(1 << 16))
                {
                    let part: u32 = a
                        .iter()
                        .zip(b)
                        .zip(c)
                        .map(|((&a, &b), &c)| u32::from((a - 2 * b + c).unsigned_abs()))
                        .sum();
                    sum += u64::from(part);
                }
                n += (w - 2) as u64;
            }
            Some(m) => {
                for x in 1..w - 1 {
                    if !(y - 1..=y + 1)
                        .all(|v| m[v * w + x - 1] && m[v * w + x] && m[v * w + x + 1])
                    {
                        continue;
                    }
                    let v = i32::from(a[x - 1]) - 2 * i32::from(b[x - 1]) + i32::from(c[x - 1]);
                    sum += u64::from(v.unsigned_abs());
                    n += 1;
                }
            }
        }
    }
    if n == 0 {
        return 0.0;
    }
    (std::f64::consts::PI / 2.0).sqrt() / 6.0 * sum as f64 / n as f64
}

/// `out[x − 1] = r[x − 1] − 2 r[x] + r[x + 1]` for `x` in `1..r.len() − 1`.
fn second_difference(r: &[u8], out: &mut [i16]) {
    let (l, m, rt) = (&r[..r.len() - 2], &r[1..r.len() - 1], &r[2..]);
    for (((o, &l), &m), &rt) in out.iter_mut().zip(l).zip(m).zip(rt) {
        *o = i16::from(l) - 2 * i16::from(m) + i16::from(rt);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// The mean `|I ∗ N|` of the method, pixel by pixel, as the paper
    /// writes it.
    fn by_the_definition(img: &GreyImage) -> f64 {
        let (w, h) = img.size();
        let (d, mask) = (img.data(), img.valid_mask());
        let k = [[1, -2, 1], [-2, 4, -2], [1, -2, 1]];
        let (mut sum, mut n) = (0i64, 0i64);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let mut v = 0i64;
                let mut valid = true;
                for (dy, kr) in k.iter().enumerate() {
                    for (dx, kv) in kr.iter().enumerate() {
                        let i = (y + dy - 1) * w + x + dx - 1;
                        v += kv * i64::from(d[i]);
                        valid &= mask.is_none_or(|m| m[i]);
                    }
                }
                if valid {
                    sum += v.abs();
                    n += 1;
                }
            }
        }
        (std::f64::consts::PI / 2.0).sqrt() / 6.0 * sum as f64 / n.max(1) as f64
    }

    #[test]
    fn the_separable_sums_equal_the_kernel_pixel_by_pixel() {
        let mut rng = SplitMix64::new(7);
        for &(w, h) in &[(3, 3), (17, 5), (64, 40), (333, 21)] {
            let data: Vec<u8> = (0..w * h).map(|_| (rng.next_u64() % 256) as u8).collect();
            let mut img = GreyImage::new(w, h, data).unwrap();
            assert_eq!(noise_level(&img), by_the_definition(&img), "{w}×{h}");
            let mask: Vec<bool> = (0..w * h).map(|_| rng.below(7) != 0).collect();
            img.set_valid_mask(Some(mask)).unwrap();
            assert_eq!(noise_level(&img), by_the_definition(&img), "{w}×{h} masked");
        }
    }

    #[test]
    fn an_image_too_small_for_the_window_has_no_noise() {
        let img = GreyImage::new(2, 9, vec![200; 18]).unwrap();
        assert_eq!(noise_level(&img), 0.0);
    }
}
