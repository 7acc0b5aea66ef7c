//! A realistic test image for benchmarks and allocation tests, until the
//! synthetic scenes of `synth` are available everywhere: anti-aliased
//! convex polygons of different brightness on a shaded ground, slightly
//! blurred by the anti-aliasing ramp, with seeded noise. Shared by the
//! tests (`support::llv_scene`), `benches/llv.rs` and `examples/llv_count.rs`
//! (through `#[path]`).

#![allow(dead_code)]

use vss::llv::GreyImage;
use vss::llv::rng::SplitMix64;

/// Approximately normal (Irwin–Hall of 4), unit variance: test noise.
fn normal(rng: &mut SplitMix64) -> f64 {
    let s: f64 = (0..4).map(|_| rng.uniform()).sum();
    (s - 2.0) * 3f64.sqrt()
}

/// Convex polygons in unit coordinates (0..1 across the image) and grey level.
fn polygons() -> Vec<(Vec<(f64, f64)>, f64)> {
    vec![
        // A box seen at an angle: three faces.
        (
            vec![(0.12, 0.30), (0.32, 0.22), (0.46, 0.33), (0.26, 0.42)],
            210.0,
        ),
        (
            vec![(0.12, 0.30), (0.26, 0.42), (0.27, 0.70), (0.13, 0.57)],
            140.0,
        ),
        (
            vec![(0.26, 0.42), (0.46, 0.33), (0.45, 0.60), (0.27, 0.70)],
            95.0,
        ),
        // A plate and a bracket.
        (
            vec![(0.55, 0.62), (0.92, 0.58), (0.95, 0.80), (0.58, 0.88)],
            170.0,
        ),
        (
            vec![(0.62, 0.15), (0.85, 0.12), (0.84, 0.45), (0.64, 0.47)],
            60.0,
        ),
        (
            vec![(0.66, 0.20), (0.80, 0.19), (0.79, 0.38), (0.67, 0.39)],
            190.0,
        ),
        // A triangle.
        (vec![(0.10, 0.80), (0.40, 0.76), (0.22, 0.95)], 220.0),
    ]
}

/// The scene at `w × h` with noise of `sigma` grey levels.
pub fn scene(w: usize, h: usize, sigma: f64, seed: u64) -> GreyImage {
    let polys: Vec<(Vec<(f64, f64)>, f64)> = polygons()
        .into_iter()
        .map(|(p, g)| {
            (
                p.into_iter()
                    .map(|(x, y)| (x * w as f64, y * h as f64))
                    .collect(),
                g,
            )
        })
        .collect();
    let mut rng = SplitMix64::new(seed);
    let mut d = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (px, py) = (x as f64, y as f64);
            let mut v = 40.0 + 30.0 * px / w as f64 + 10.0 * py / h as f64;
            for (poly, g) in &polys {
                // Signed distance inside a convex polygon (clockwise on
                // screen), clamped to a 1-px anti-aliasing ramp.
                let mut inside = f64::INFINITY;
                for k in 0..poly.len() {
                    let (x0, y0) = poly[k];
                    let (x1, y1) = poly[(k + 1) % poly.len()];
                    let (dx, dy) = (x1 - x0, y1 - y0);
                    let len = dx.hypot(dy);
                    let sd = ((px - x0) * dy - (py - y0) * dx) / len;
                    inside = inside.min(-sd);
                }
                let cover = (inside + 0.5).clamp(0.0, 1.0);
                v = v * (1.0 - cover) + g * cover;
            }
            v += sigma * normal(&mut rng);
            d.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    GreyImage::new(w, h, d).expect("sizes agree")
}
