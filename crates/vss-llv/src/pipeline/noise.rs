//! The image's noise level, which picks the kernel's half-width of a run.

use crate::GreyImage;

/// The image's noise σ (grey levels) by Immerkær's method ("Fast noise
/// variance estimation", CVIU 64, 1996): the mean magnitude of the
/// difference of two Laplacians, `σ = √(π/2) / 6 · mean |I ∗ N|`, which
/// cancels straight edges and smooth shading and keeps what changes from
/// pixel to pixel. Texture raises it too, which is what a wider kernel is
/// also for; pixels whose 3 × 3 window is not all valid are left out.
pub fn noise_level(img: &GreyImage) -> f64 {
    let (w, h) = img.size();
    if w < 3 || h < 3 {
        return 0.0;
    }
    let d = img.data();
    let mask = img.valid_mask();
    let (mut sum, mut n) = (0u64, 0u64);
    for y in 1..h - 1 {
        let (r0, r1, r2) = (
            &d[(y - 1) * w..y * w],
            &d[y * w..(y + 1) * w],
            &d[(y + 1) * w..(y + 2) * w],
        );
        for x in 1..w - 1 {
            if let Some(m) = mask
                && !(y - 1..=y + 1).all(|v| m[v * w + x - 1] && m[v * w + x] && m[v * w + x + 1])
            {
                continue;
            }
            let c = |r: &[u8], i: usize| i32::from(r[i]);
            let v = c(r0, x - 1) - 2 * c(r0, x) + c(r0, x + 1) - 2 * c(r1, x - 1) + 4 * c(r1, x)
                - 2 * c(r1, x + 1)
                + c(r2, x - 1)
                - 2 * c(r2, x)
                + c(r2, x + 1);
            sum += u64::from(v.unsigned_abs());
            n += 1;
        }
    }
    if n == 0 {
        return 0.0;
    }
    (std::f64::consts::PI / 2.0).sqrt() / 6.0 * sum as f64 / n as f64
}
