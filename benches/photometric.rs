//! Photometric edges (llv.md §2.6, issue 6): four lit 512 × 512 images of a
//! synthetic view plus an ambient-only image (noise σ = 5), on one core.
//! Goal: five images to lines in ≤ 3 ms. Run: `cargo bench --bench photometric`.
//! `combined_edges_both_directions` is the edge part alone (combined
//! responses and peaks, warm buffers); the rest of `five_images_to_lines` is
//! line extraction and CONNECT.

use divan::{Bencher, black_box};
use vss::llv::edges::{NoiseMap, PeakMap, PeakScratch, Response, Starts, detect_into};
use vss::llv::photometric::{PhotoScratch, combined_response, combined_response_into};
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::{EdgePoints, GreyImage, Params, ScanDir};
use vss::synth::{self, PointLight, RenderOptions};

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

/// Warm buffers: the combined responses and their peaks, both directions,
/// as the pipeline's edge stage runs them.
#[divan::bench]
fn combined_edges_both_directions(b: Bencher) {
    let (lit, amb) = view();
    let p = Params::default();
    let mut s = PhotoScratch::default();
    let mut ps = PeakScratch::default();
    let (mut rh, mut rv) = (Response::default(), Response::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let (mut nh, mut nv) = (NoiseMap::default(), NoiseMap::default());
    let (mut mh, mut mv) = (PeakMap::default(), PeakMap::default());
    let (mut sh, mut sv) = (Starts::new(), Starts::new());
    let t = p.lines.track_sigmas;
    b.bench_local(|| {
        let (lit, amb) = (black_box(&lit), black_box(&amb));
        combined_response_into(
            lit,
            Some(amb),
            ScanDir::Horizontal,
            &p.edges,
            &mut rh,
            &mut s,
        )
        .expect("same size");
        combined_response_into(lit, Some(amb), ScanDir::Vertical, &p.edges, &mut rv, &mut s)
            .expect("same size");
        detect_into(
            &rh, &p.edges, t, &mut nh, &mut mh, &mut eh, &mut sh, &mut ps,
        );
        detect_into(
            &rv, &p.edges, t, &mut nv, &mut mv, &mut ev, &mut sv, &mut ps,
        );
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
