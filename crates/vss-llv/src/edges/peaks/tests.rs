use super::*;
use crate::GreyImage;
use crate::edges::response;

fn params() -> EdgeParams {
    EdgeParams::default()
}

fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
    let d = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y));
    GreyImage::new(w, h, d.collect()).unwrap()
}

#[test]
fn a_step_gives_one_point_a_row_and_a_flat_image_none() {
    let img = image(40, 30, |x, _| if x < 20 { 50 } else { 150 });
    let e = peaks(&response(&img, ScanDir::Horizontal, 4).unwrap(), &params());
    assert_eq!(e.points.len(), 30);
    for p in &e.points {
        assert!((p.x - 19.5).abs() < 1e-3 && p.response > 90.0, "{p:?}");
    }
    assert!(
        peaks(&response(&img, ScanDir::Vertical, 4).unwrap(), &params())
            .points
            .is_empty()
    );
    let flat = image(16, 16, |_, _| 7);
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        assert!(
            peaks(&response(&flat, dir, 4).unwrap(), &params())
                .points
                .is_empty()
        );
    }
}

#[test]
fn m_keeps_the_strongest_of_a_region() {
    // Five steps of rising contrast along each row.
    let img = image(120, 20, |x, _| {
        let steps = [10u8, 30, 60, 100, 150, 210];
        steps[(x / 20).min(5)]
    });
    let r = response(&img, ScanDir::Horizontal, 4).unwrap();
    let mut p = params();
    p.per_region = 2;
    let e = peaks(&r, &p);
    assert_eq!(e.points.len(), 2 * 20);
    assert!(
        e.points.iter().all(|q| q.response > 45.0),
        "{:?}",
        e.points[0]
    );
    p.per_region = 8;
    assert_eq!(peaks(&r, &p).points.len(), 5 * 20);
    // Regions of ten rows: the two strongest of 50 candidates are a tie
    // of ten each.
    p.per_region = 2;
    p.region_lines = 10;
    assert_eq!(peaks(&r, &p).points.len(), 20);
}

#[test]
fn vertical_points_are_in_image_order_with_subpixel_y() {
    let img = image(30, 40, |_, y| if 2 * y < 41 { 40 } else { 200 });
    let e = peaks(&response(&img, ScanDir::Vertical, 4).unwrap(), &params());
    assert_eq!(e.points.len(), 30);
    assert!(e.points.windows(2).all(|w| w[0].x < w[1].x));
    assert!(e.points.iter().all(|p| (p.y - 20.0).abs() <= 0.5));
}

/// The starts are the pixels of the points.
#[test]
fn starts_are_the_points_pixels() {
    let img = image(40, 30, |x, y| if x + y / 3 < 20 { 50 } else { 150 });
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        let r = response(&img, dir, 4).unwrap();
        let (mut noise, mut out, mut starts) =
            (NoiseMap::default(), EdgePoints::default(), Starts::new());
        detect_into(
            &r,
            &params(),
            2.0,
            &mut noise,
            &mut PeakMap::default(),
            &mut out,
            &mut starts,
            &mut PeakScratch::default(),
        );
        assert_eq!(out.points.len(), starts.len());
        for (p, &[x, y]) in out.points.iter().zip(&starts) {
            assert!((p.x - f32::from(x)).abs() <= 0.5 && (p.y - f32::from(y)).abs() <= 0.5);
        }
    }
}

/// The lane-wise candidate test finds what the plain one does, on
/// noise with edges, a validity mask, thresholds per tile and widths
/// that are no multiple of sixteen.
#[test]
fn wide_candidates_equal_the_plain_ones() {
    use crate::rng::SplitMix64;
    let mut rng = SplitMix64::new(3);
    for (w, h) in [(16, 16), (37, 53), (130, 70), (200, 131)] {
        let mut img = image(w, h, |x, y| {
            let base = if x * 3 + y > w { 160.0 } else { 60.0 };
            (base + 4.0 * ((x * 7 + y * 13) % 11) as f64) as u8
        });
        let noisy: Vec<u8> = img
            .data()
            .iter()
            .map(|&v| (f64::from(v) + 6.0 * rng.gauss()).clamp(0.0, 255.0) as u8)
            .collect();
        img = GreyImage::new(w, h, noisy).unwrap();
        let mask: Vec<bool> = (0..w * h).map(|i| i % 97 != 5).collect();
        img.set_valid_mask(Some(mask)).unwrap();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            for (a, plain) in [(4, false), (7, false), (4, true)] {
                // (`plain`: the fallback for processors without AVX2,
                // which other tests may meet meanwhile: the results
                // are the same either way.)
                plain_only(plain);
                let r = response(&img, dir, a).unwrap();
                let noise = NoiseMap::estimate(&r);
                let (nx, ny) = noise.tiles();
                let top = r
                    .sums()
                    .iter()
                    .map(|&v| i32::from(key(v)))
                    .filter(|&k| k < 32_000)
                    .max()
                    .unwrap_or(0);
                let thr: Vec<i32> = (0..nx * ny).map(|t| top / 20 + 7 * t as i32).collect();
                let (mut fast, mut reference) = (Vec::new(), Vec::new());
                candidates(&r, &noise, &thr, &mut fast);
                plain_only(false);
                candidates_plain(&r, &noise, &thr, &mut reference);
                // (A = 7 leaves a 16-pixel image almost no response.)
                assert!(!reference.is_empty() || (a == 7 && w.min(h) < 20));
                assert_eq!(fast, reference, "{w}x{h} {dir:?} A {a} plain {plain}");
            }
        }
    }
}

/// The peak map (made by the lane-wise pass where the machine has
/// AVX2) holds exactly the plain test's peaks above the tracking
/// threshold, by polarity, and its windows read them in scan order
/// for both directions.
#[test]
fn the_peak_map_holds_the_plain_peaks() {
    use crate::rng::SplitMix64;
    let mut rng = SplitMix64::new(5);
    for (w, h) in [(16, 16), (37, 53), (130, 70), (200, 131)] {
        let mut img = image(w, h, |x, y| if x * 2 + y > w { 150 } else { 70 });
        let noisy: Vec<u8> = img
            .data()
            .iter()
            .map(|&v| (f64::from(v) + 5.0 * rng.gauss()).clamp(0.0, 255.0) as u8)
            .collect();
        img = GreyImage::new(w, h, noisy).unwrap();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let r = response(&img, dir, 4).unwrap();
            let noise = NoiseMap::estimate(&r);
            let mut map = PeakMap::default();
            map.build_into(&r, &noise, 2.0, 1.5, &mut PeakScratch::default());
            // The copy in scan layout reads the same windows.
            let mut scan = PeakMap::default();
            scan.scan_copy_from(&map);
            let mut thr = Vec::new();
            tile_floors(r.scale(), &noise, 2.0, 1.5, &mut thr);
            let mut plain = Vec::new();
            candidates_plain(&r, &noise, &thr, &mut plain);
            assert!(plain.len() > 20 || w < 20, "{w}x{h} {dir:?}");
            let (len_u, lines) = match dir {
                ScanDir::Horizontal => (w, h),
                ScanDir::Vertical => (h, w),
            };
            let mut found = Vec::new();
            for v in 0..lines {
                for positive in [true, false] {
                    let mut lo = 0;
                    while lo < len_u {
                        let hi = (lo + 23).min(len_u);
                        let mut bits = map.window(positive, v, lo, hi);
                        assert_eq!(scan.window(positive, v, lo, hi), bits, "{dir:?}");
                        while bits != 0 {
                            let u = lo + bits.trailing_zeros() as usize;
                            bits &= bits - 1;
                            let (x, y) = if dir == ScanDir::Vertical {
                                (v, u)
                            } else {
                                (u, v)
                            };
                            let i = y * w + x;
                            assert_eq!(r.sums()[i] > 0, positive);
                            assert!(scan.is_set(u, v));
                            scan.clear(u, v);
                            assert!(!scan.is_set(u, v) && map.is_set(u, v));
                            found.push(i as u32);
                        }
                        lo = hi;
                    }
                }
            }
            found.sort_unstable();
            let want: Vec<u32> = plain
                .iter()
                .map(|c| u32::from(c.y) * w as u32 + u32::from(c.x))
                .collect();
            assert_eq!(found, want, "{w}x{h} {dir:?}");
        }
    }
}

#[test]
fn key_floors() {
    assert_eq!(key_floor(2.0, 0.5), 4);
    assert_eq!(key_floor(0.0, 0.5), -1);
    assert_eq!(key_floor(f32::NAN, 0.5), i32::from(i16::MAX));
    assert_eq!(key_floor(2.0, 0.0), i32::from(i16::MAX));
    assert_eq!(key_floor(1e9, 0.5), i32::from(i16::MAX));
}

/// The edge points of the batch path equal those made a point at a time
/// from the plain candidates, the response's sums and a sort per region,
/// to the bit, for limits `M` below, at and above what a region can hold
/// (the case in which the per-region count is skipped).
#[test]
fn points_equal_a_point_at_a_time() {
    use crate::rng::SplitMix64;
    let mut rng = SplitMix64::new(11);
    for (w, h) in [(37, 53), (130, 70)] {
        let d: Vec<u8> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let base = if (x / 11 + y / 9) % 2 == 0 {
                    150.0
                } else {
                    70.0
                };
                (base + 4.0 * rng.gauss()).clamp(0.0, 255.0) as u8
            })
            .collect();
        let img = GreyImage::new(w, h, d).unwrap();
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            let r = response(&img, dir, 4).unwrap();
            let (n, step) = match dir {
                ScanDir::Horizontal => (w, 1),
                ScanDir::Vertical => (h, w),
            };
            let most = n.div_ceil(2) as u32;
            for (rl, m) in [
                (1, 1),
                (1, 3),
                (3, 5),
                (1, most - 1),
                (1, most),
                (2, 2 * most),
            ] {
                let mut p = params();
                (p.region_lines, p.per_region, p.floor) = (rl, m, 1.0);
                p.noise_sigmas = 1.0;
                let got = peaks(&r, &p);
                // The same a point at a time.
                let mut noise = NoiseMap::default();
                let mut ns = crate::edges::NoiseScratch::default();
                noise.estimate_into(&r, &mut ns);
                noise.bound(p.noise_percentile, p.noise_cap, &mut ns);
                let mut thr = Vec::new();
                tile_floors(r.scale(), &noise, p.floor, p.noise_sigmas, &mut thr);
                let mut cand = Vec::new();
                candidates_plain(&r, &noise, &thr, &mut cand);
                let region = |c: &Peak| match dir {
                    ScanDir::Horizontal => usize::from(c.y) / rl as usize,
                    ScanDir::Vertical => usize::from(c.x) / rl as usize,
                };
                let mut keys = vec![Vec::new(); n.max(w).max(h)];
                for c in &cand {
                    keys[region(c)].push(c.key);
                }
                let lim: Vec<i16> = keys
                    .iter_mut()
                    .map(|k| {
                        k.sort_unstable_by(|a, b| b.cmp(a));
                        if k.len() > m as usize {
                            k[m as usize - 1]
                        } else {
                            0
                        }
                    })
                    .collect();
                let sums = r.sums();
                let mag = |i: usize| f32::from(key(sums[i]));
                let want: Vec<[u32; 3]> = cand
                    .iter()
                    .filter(|c| c.key >= lim[region(c)])
                    .map(|c| {
                        let i = usize::from(c.y) * w + usize::from(c.x);
                        let d = subpixel(mag(i - step), mag(i), mag(i + step));
                        let (mut x, mut y) = (f32::from(c.x), f32::from(c.y));
                        match dir {
                            ScanDir::Horizontal => x += d,
                            ScanDir::Vertical => y += d,
                        }
                        [x, y, f32::from(sums[i]) * r.scale()].map(f32::to_bits)
                    })
                    .collect();
                let bits: Vec<[u32; 3]> = got
                    .points
                    .iter()
                    .map(|q| [q.x, q.y, q.response].map(f32::to_bits))
                    .collect();
                assert!(want.len() > 20, "{w}x{h} {dir:?}: {} points", want.len());
                assert_eq!(bits, want, "{w}x{h} {dir:?} lines {rl} M {m}");
            }
        }
    }
}
