//! LLV benchmarks (divan): each stage and the whole single-image pipeline at
//! 512² and 2048², on one core, on a realistic scene (anti-aliased polygons
//! with noise σ = 2, `tests/it/support/llv_scene.rs`). Lens correction uses a
//! precomputed map of a distorting camera. Run: `cargo bench --bench llv`.

use divan::{Bencher, black_box};
use vss::llv::connect::{ConnectScratch, connect_into};
use vss::llv::edges::{PeakScratch, Response, ResponseScratch, exact_response_into, peaks_into};
use vss::llv::lens::{CameraModel, LensMap, correct_into};
use vss::llv::lines::{LineScratch, extract_into};
use vss::llv::pipeline::{Input, StageOutputs, Workspace};
use vss::llv::{EdgePoints, GreyImage, Params, ScanDir};

#[path = "../tests/it/support/llv_scene.rs"]
mod llv_scene;

const SIZES: [usize; 2] = [512, 2048];

fn main() {
    divan::main();
}

fn image(n: usize) -> GreyImage {
    llv_scene::scene(n, n, 2.0, 42)
}

/// The cell camera of the spec's example, scaled to the image size.
fn lens_map(n: usize) -> LensMap {
    let s = 512.0 / n as f64;
    let m = CameraModel {
        cx: n as f64 / 2.0 + 3.0,
        cy: n as f64 / 2.0 - 2.0,
        sx: 0.0086 * s,
        sy: 0.0083 * s,
        f: 8.5,
        distortion: Some([-1.2e-3, 1.0e-4, -8.0e-5, 5.0e-5, 2.0e-5]),
    };
    LensMap::new(&m, n, n)
}

fn outputs(n: usize) -> StageOutputs {
    let img = image(n);
    let mut ws = Workspace::new();
    ws.run(&Input::single(&img), &Params::default())
        .expect("pipeline runs");
    ws.take_outputs()
}

#[divan::bench(args = SIZES)]
fn lens_correct(b: Bencher, n: usize) {
    let img = image(n);
    let map = lens_map(n);
    let mut out = GreyImage::default();
    b.bench_local(|| {
        correct_into(black_box(&img), &map, &mut out).expect("same size");
    });
}

#[divan::bench(args = SIZES)]
fn edges_both_directions(b: Bencher, n: usize) {
    let img = image(n);
    let p = Params::default();
    let (mut rh, mut rv) = (Response::default(), Response::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let mut counts = ResponseScratch::default();
    let mut ps = PeakScratch::default();
    b.bench_local(|| {
        let img = black_box(&img);
        exact_response_into(img, ScanDir::Horizontal, 4, &mut rh, &mut counts).expect("size");
        exact_response_into(img, ScanDir::Vertical, 4, &mut rv, &mut counts).expect("size");
        peaks_into(&rh, &p.edges, &mut eh, &mut ps);
        peaks_into(&rv, &p.edges, &mut ev, &mut ps);
    });
}

#[divan::bench(args = SIZES)]
fn lines_both_directions(b: Bencher, n: usize) {
    let o = outputs(n);
    let p = Params::default();
    let mut s = LineScratch::default();
    let (mut lh, mut lv) = (Vec::new(), Vec::new());
    b.bench_local(|| {
        extract_into(black_box(&o.edges_h), &p.lines, &mut lh, &mut s);
        extract_into(black_box(&o.edges_v), &p.lines, &mut lv, &mut s);
    });
}

#[divan::bench(args = SIZES)]
fn connect(b: Bencher, n: usize) {
    let o = outputs(n);
    let p = Params::default();
    let mut s = ConnectScratch::default();
    let mut out = Vec::new();
    b.bench_local(|| {
        connect_into(black_box(&o.lines_raw), &p.connect, &mut out, &mut s);
    });
}

/// Lens (precomputed map), edges, lines and CONNECT on one image.
#[divan::bench(args = SIZES)]
fn pipeline(b: Bencher, n: usize) {
    let img = image(n);
    let map = lens_map(n);
    let p = Params::default();
    let input = Input {
        images: std::slice::from_ref(&img),
        ambient: None,
        lens: Some(&map),
    };
    let mut ws = Workspace::new();
    ws.run(&input, &p).expect("runs");
    b.bench_local(|| {
        ws.run(black_box(&input), &p).expect("runs");
    });
}

/// The same without lens correction (identity: no cost, no copy).
#[divan::bench(args = SIZES)]
fn pipeline_no_lens(b: Bencher, n: usize) {
    let img = image(n);
    let p = Params::default();
    let input = Input::single(&img);
    let mut ws = Workspace::new();
    ws.run(&input, &p).expect("runs");
    b.bench_local(|| {
        ws.run(black_box(&input), &p).expect("runs");
    });
}
