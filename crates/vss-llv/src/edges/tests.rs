//! The edge detector's tests: the fast responses against the plain reference
//! (`reference.rs`), the kernel, steps and subpixel positions, peaks, and
//! small, flat and invalid images.

use super::*;
use crate::rng::SplitMix64;

fn img_from(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
    let mut d = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            d.push(f(x, y));
        }
    }
    GreyImage::new(w, h, d).unwrap()
}

/// A random scene: a few steps of random height and direction, noise of
/// random amplitude, optionally a validity mask with random invalid
/// blobs and a few scattered invalid pixels.
pub(crate) fn random_image(rng: &mut SplitMix64, w: usize, h: usize, masked: bool) -> GreyImage {
    let (x0, y0) = (
        (rng.next_u64() % w as u64) as i64,
        (rng.next_u64() % h as u64) as i64,
    );
    let (lv0, lv1, lv2) = (
        rng.next_u64() % 256,
        rng.next_u64() % 256,
        rng.next_u64() % 256,
    );
    let noise = 1 + rng.next_u64() % 40;
    let mut img = img_from(w, h, |x, y| {
        let (x, y) = (x as i64, y as i64);
        let base = if x + y / 3 < x0 {
            lv0
        } else if y - x / 2 < y0 {
            lv1
        } else {
            lv2
        };
        let n = rng_at(x as u64, y as u64, noise);
        (base as i64 + n).clamp(0, 255) as u8
    });
    if masked {
        let mut mask = vec![true; w * h];
        for _ in 0..3 {
            let (cx, cy) = (rng.next_u64() % w as u64, rng.next_u64() % h as u64);
            let rad = 1 + rng.next_u64() % 6;
            for y in 0..h as u64 {
                for x in 0..w as u64 {
                    if x.abs_diff(cx).pow(2) + y.abs_diff(cy).pow(2) <= rad * rad {
                        mask[(y * w as u64 + x) as usize] = false;
                    }
                }
            }
        }
        for _ in 0..4 {
            mask[(rng.next_u64() % (w * h) as u64) as usize] = false;
        }
        img.set_valid_mask(Some(mask)).unwrap();
    }
    img
}

/// Deterministic noise in `-amp..=amp` at a pixel.
fn rng_at(x: u64, y: u64, amp: u64) -> i64 {
    let mut r = SplitMix64::new((x << 32 | y) ^ 0x9E37_79B9_7F4A_7C15);
    r.next_u64();
    (r.next_u64() % (2 * amp + 1)) as i64 - amp as i64
}

fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(u, v)| u.to_bits() == v.to_bits() || (u.is_nan() && v.is_nan()))
}

/// The stored sums read as the reference's `f32` values: bit for bit for
/// `A ≤ 5` (exact sums), within half a stored unit for `A` = 6, 7 (sums
/// halved or quartered); no response in the same places.
#[test]
fn fast_responses_equal_the_reference() {
    let mut rng = SplitMix64::new(0x1234_5678_9ABC_DEF1);
    let (mut fast, mut slow) = (Response::default(), Vec::new());
    let (mut fs, mut ss) = (
        ResponseScratch::default(),
        reference::ResponseScratch::default(),
    );
    for (w, h) in [(16, 16), (37, 53), (130, 17), (17, 130), (64, 40)] {
        for masked in [false, true] {
            let img = random_image(&mut rng, w, h, masked);
            for a in 3..=7 {
                for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                    response_into(&img, dir, a, &mut fast, &mut fs).unwrap();
                    reference::response_into(&img, dir, a, &mut slow, &mut ss).unwrap();
                    assert_eq!((fast.width, fast.height, fast.dir), (w, h, dir));
                    assert!(fast.covers(w, h));
                    let values: Vec<f32> = (0..w * h).map(|i| fast.value(i)).collect();
                    if a <= 5 {
                        assert!(
                            same_bits(&values, &slow),
                            "{w}x{h} masked={masked} a={a} {dir:?}"
                        );
                    } else {
                        for (u, v) in values.iter().zip(&slow) {
                            assert_eq!(u.is_nan(), v.is_nan());
                            if !u.is_nan() {
                                assert!((u - v).abs() <= 0.5 * fast.scale() + 1e-4, "{u} {v}");
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn kernel_sums_to_zero_and_step_gives_one_minus_inverse_square() {
    for a in 3..=7 {
        let k = kernel(a);
        assert_eq!(k.len(), 2 * a + 1);
        let sum: f64 = k.iter().map(|&v| v as f64).sum();
        assert!(sum.abs() < 1e-6, "A={a}: sum {sum}");
        // A unit step 0 → 1 at x: response = Σ_{t<0} φ'(t).
        let step: f64 = k[..a].iter().map(|&v| v as f64).sum();
        let want = 1.0 - 1.0 / (a * a) as f64;
        assert!((step - want).abs() < 1e-6, "A={a}: {step} vs {want}");
        for t in 0..=a {
            assert_eq!(k[a + t], -k[a - t], "antisymmetric");
        }
    }
}

#[test]
fn step_responses_have_the_right_sign_and_size() {
    let img = img_from(32, 20, |x, _| if x < 16 { 50 } else { 150 });
    let r = response(&img, ScanDir::Horizontal, 4).unwrap();
    let want = 100.0 * (1.0 - 1.0 / 16.0);
    assert!((r.get(15, 5).unwrap() - want).abs() < 1e-4);
    assert!((r.get(16, 5).unwrap() - want).abs() < 1e-4);
    assert!(r.get(3, 5).is_none() && r.get(28, 5).is_none());
    let rv = response(&img, ScanDir::Vertical, 4).unwrap();
    assert_eq!(rv.get(15, 10), Some(0.0));
    // Light → dark is negative, vertically too.
    let img = img_from(20, 32, |_, y| if y < 16 { 200 } else { 10 });
    let rv = response(&img, ScanDir::Vertical, 3).unwrap();
    assert!((rv.get(7, 15).unwrap() + 190.0 * (1.0 - 1.0 / 9.0)).abs() < 1e-4);
}

#[test]
fn a_step_gives_one_point_per_row_at_the_step() {
    let img = img_from(40, 30, |x, _| if x < 20 { 30 } else { 200 });
    let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
    assert_eq!(e.points.len(), 30);
    for p in &e.points {
        assert!((p.x - 19.5).abs() < 1e-6, "{p:?}");
        assert!(p.response > 150.0);
    }
    // Lexical order.
    assert!(e.points.windows(2).all(|w| w[0].y < w[1].y));
    let ev = detect(&img, ScanDir::Vertical, &EdgeParams::default()).unwrap();
    assert!(ev.points.is_empty());
}

#[test]
fn subpixel_follows_an_antialiased_edge() {
    // A step at x = 20.3 (pixel centres at integers): coverage-weighted.
    for &pos in &[20.0f64, 20.25, 20.5, 20.8] {
        let img = img_from(48, 20, |x, _| {
            let lo = x as f64 - 0.5;
            let cover = (x as f64 + 0.5 - pos.max(lo)).clamp(0.0, 1.0);
            (40.0 + 160.0 * cover).round() as u8
        });
        let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
        assert_eq!(e.points.len(), 20);
        let x = e.points[0].x as f64;
        assert!((x - pos).abs() < 0.12, "step at {pos}: found {x}");
    }
}

#[test]
fn peaks_are_one_pixel_thick_on_a_ramp_and_thresholded_per_row() {
    // A ramp of 4 px: one peak per row, at the ramp's centre.
    let img = img_from(40, 20, |x, _| (x.clamp(13, 17) * 10) as u8);
    let e = detect(&img, ScanDir::Horizontal, &EdgeParams::default()).unwrap();
    assert_eq!(e.points.len(), 20);
    assert!(e.points.iter().all(|p| (p.x - 15.0).abs() < 1e-5));
    // Noise-like alternating small peaks: M = 2 keeps the two strongest.
    let img = img_from(64, 16, |x, _| {
        if x % 8 < 4 {
            100
        } else {
            100 + (x / 8) as u8 * 3 + 6
        }
    });
    let p = EdgeParams {
        per_region: 2,
        noise_sigmas: 0.0,
        ..EdgeParams::default()
    };
    let e = detect(&img, ScanDir::Horizontal, &p).unwrap();
    for y in 0..16 {
        let n = e.points.iter().filter(|q| q.y == y as f32).count();
        assert!((2..=3).contains(&n), "row {y}: {n} points");
    }
}

#[test]
fn no_panic_on_small_flat_and_invalid_images() {
    let p = EdgeParams::default();
    let flat = GreyImage::filled(16, 16, 77).unwrap();
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        for a in 3..=7 {
            let r = response(&flat, dir, a).unwrap();
            assert_eq!(peaks(&r, &p).points.len(), 0);
        }
    }
    let mut img = img_from(16, 16, |x, y| ((x * 37 + y * 11) % 256) as u8);
    img.set_valid_mask(Some(vec![false; 256])).unwrap();
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        let r = response(&img, dir, 7).unwrap();
        assert!(r.sums().iter().all(|&v| v == NONE));
        assert!(peaks(&r, &p).points.is_empty());
    }
    assert!(response(&GreyImage::filled(15, 40, 0).unwrap(), ScanDir::Vertical, 4).is_err());
    assert!(response(&flat, ScanDir::Vertical, 8).is_err());
}

#[test]
fn invalid_pixels_suppress_responses_around_them() {
    let mut img = img_from(32, 32, |x, _| if x < 16 { 0 } else { 200 });
    let mut mask = vec![true; 32 * 32];
    mask[10 * 32 + 16] = false;
    img.set_valid_mask(Some(mask)).unwrap();
    let rh = response(&img, ScanDir::Horizontal, 4).unwrap();
    assert!(rh.get(15, 10).is_none() && rh.get(12, 10).is_none());
    assert!(rh.get(11, 10).is_some() && rh.get(15, 9).is_some());
    let rv = response(&img, ScanDir::Vertical, 4).unwrap();
    assert!(rv.get(16, 6).is_none() && rv.get(16, 14).is_none());
    assert!(rv.get(16, 5).is_some() && rv.get(16, 15).is_some());
    assert!(rv.get(17, 10).is_some());
}

/// The interval fills of a lens-like mask (one valid span a row: an
/// ellipse cut by the frame) mark exactly what the plain window count
/// marks, both directions, every half-width; a mask with holes takes the
/// plain path.
#[test]
fn interval_masks_equal_the_window_count() {
    let (w, h) = (90, 70);
    let ellipse: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64 - 44.0, (i / w) as f64 - 30.0);
            (x / 52.0).powi(2) + (y / 38.0).powi(2) <= 1.0
        })
        .collect();
    let mut holed = ellipse.clone();
    holed[35 * w + 40] = false;
    for mask in [ellipse, holed] {
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            for a in 3..=7 {
                let (mut fast, mut plain) = (vec![7i16; w * h], vec![7i16; w * h]);
                mask_invalid(&mask, w, h, dir, a, &mut fast, &mut MaskBufs::default());
                mask_invalid_plain(&mask, w, h, dir, a, &mut plain, &mut Vec::new());
                // The response itself leaves the image's border band none.
                for y in 0..h {
                    for x in 0..w {
                        let border = match dir {
                            ScanDir::Horizontal => x < a || x + a >= w,
                            ScanDir::Vertical => y < a || y + a >= h,
                        };
                        if !border {
                            let i = y * w + x;
                            assert_eq!(fast[i], plain[i], "{dir:?} A {a} ({x}, {y})");
                        }
                    }
                }
            }
        }
    }
}
