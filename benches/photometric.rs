//! Photometric edges (llv.md §2.6, issue 6): four lit 512 × 512 images of a
//! synthetic view plus an ambient-only image (noise σ = 5), on one core.
//! Goal: five images to lines in ≤ 3 ms. Run: `cargo bench --bench photometric`.

use divan::{Bencher, black_box};
use vss::llv::photometric::combined_response;
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::synth::{self, PointLight, RenderOptions};
use vss::llv::{GreyImage, Params, ScanDir};

fn main() {
    divan::main();
}

/// Four lit images and the ambient image of one seeded view.
fn view() -> (Vec<GreyImage>, GreyImage) {
    let (scene, cam, lights) = synth::test_scenes(1, 512, 512, 2026)
        .pop()
        .expect("a scene");
    let p = lights.first().map_or([0.0, 0.0, 1000.0], |l| l.position);
    let o = |seed| RenderOptions {
        noise_sigma: 5.0,
        seed,
        ..RenderOptions::default()
    };
    let lit = (0..4)
        .map(|k| {
            let (s, c) = (k as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
            let l = PointLight {
                position: [p[0] * c - p[1] * s, p[0] * s + p[1] * c, p[2]],
                intensity: 0.8,
            };
            synth::render(&scene, &cam, &[l], &o(k))
        })
        .collect();
    (lit, synth::render(&scene, &cam, &[], &o(9)))
}

#[divan::bench]
fn combined_response_both_directions(b: Bencher) {
    let (lit, amb) = view();
    let p = Params::default();
    b.bench_local(|| {
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            black_box(combined_response(&lit, Some(&amb), dir, &p.edges).expect("same size"));
        }
    });
}

#[divan::bench(args = [3.0, 5.0])]
fn five_images_to_lines(b: Bencher, noise_factor: f64) {
    let (lit, amb) = view();
    let mut p = Params::default();
    p.edges.noise_factor = noise_factor;
    let input = Input {
        images: &lit,
        ambient: Some(&amb),
        lens: None,
    };
    let mut ws = Workspace::new();
    b.bench_local(|| {
        black_box(ws.run(&input, &p).expect("pipeline runs").lines.len());
    });
}
