//! LLV benchmarks (divan): each stage and the whole single-image pipeline at
//! 512² and 2048², on one thread (`edges.threads = 1`, the default) and, for
//! the pipeline, on two; on a realistic scene (anti-aliased polygons with
//! noise σ = 2, `tests/it/support/llv_scene.rs`). Lens correction uses a
//! precomputed map of a distorting camera. `pipeline_five_lightings` is the
//! same view under four lightings plus an ambient image, so that one run
//! gives both sides of the several-lightings goal (five images ≤ 2.5 × one).
//! Run: `cargo bench --bench llv`.

use divan::{Bencher, black_box};
use vss::llv::connect::{ConnectScratch, connect_into};
use vss::llv::edges::{
    NoiseMap, PeakMap, PeakScratch, Response, ResponseScratch, Starts, detect_into, response_into,
};
use vss::llv::lens::{CameraModel, LensMap, correct_into};
use vss::llv::lines::{LineScratch, track_into};
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
        radial: [0.0; 2],
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

/// Response, noise scale, peak map and edge points, both directions.
#[divan::bench(args = SIZES)]
fn edges_both_directions(b: Bencher, n: usize) {
    let img = image(n);
    let p = Params::default();
    let t = p.lines.track_sigmas;
    let (mut rh, mut rv) = (Response::default(), Response::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let (mut nh, mut nv) = (NoiseMap::default(), NoiseMap::default());
    let (mut mh, mut mv) = (PeakMap::default(), PeakMap::default());
    let (mut sh, mut sv) = (Starts::new(), Starts::new());
    let mut counts = ResponseScratch::default();
    let mut ps = PeakScratch::default();
    b.bench_local(|| {
        let img = black_box(&img);
        response_into(img, ScanDir::Horizontal, 4, &mut rh, &mut counts).expect("size");
        response_into(img, ScanDir::Vertical, 4, &mut rv, &mut counts).expect("size");
        detect_into(
            &rh, &p.edges, t, &mut nh, &mut mh, &mut eh, &mut sh, &mut ps,
        );
        detect_into(
            &rv, &p.edges, t, &mut nv, &mut mv, &mut ev, &mut sv, &mut ps,
        );
    });
}

/// The line extractor on both directions' responses and edge points.
#[divan::bench(args = SIZES)]
fn lines_both_directions(b: Bencher, n: usize) {
    let o = outputs(n);
    let p = Params::default();
    let mut s = LineScratch::default();
    let (mut lh, mut lv) = (Vec::new(), Vec::new());
    // The peak maps and starts as the edge stage leaves them.
    let (mut mh, mut mv) = (PeakMap::default(), PeakMap::default());
    let (mut sh, mut sv) = (Starts::new(), Starts::new());
    let (mut nh, mut nv) = (NoiseMap::default(), NoiseMap::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let (t, mut ps) = (p.lines.track_sigmas, PeakScratch::default());
    detect_into(
        &o.response_h,
        &p.edges,
        t,
        &mut nh,
        &mut mh,
        &mut eh,
        &mut sh,
        &mut ps,
    );
    detect_into(
        &o.response_v,
        &p.edges,
        t,
        &mut nv,
        &mut mv,
        &mut ev,
        &mut sv,
        &mut ps,
    );
    let (f, a) = (p.edges.floor, p.edges.half_width as usize);
    b.bench_local(|| {
        let (rh, rv) = (black_box(&o.response_h), black_box(&o.response_v));
        track_into(rh, &nh, &mh, &eh, &sh, f, a, &p.lines, &mut lh, &mut s);
        track_into(rv, &nv, &mv, &ev, &sv, f, a, &p.lines, &mut lv, &mut s);
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

/// The pipeline with lens correction on two threads, one for each scan
/// direction (`edges.threads = 2`).
#[divan::bench(args = SIZES)]
fn pipeline_two_threads(b: Bencher, n: usize) {
    let img = image(n);
    let map = lens_map(n);
    let mut p = Params::default();
    p.edges.threads = 2;
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

/// Five images of one view (four lightings and the ambient image, with lens
/// correction): the several-lightings path against `pipeline` beside it.
#[divan::bench(args = SIZES)]
fn pipeline_five_lightings(b: Bencher, n: usize) {
    // The same scene with independent noise for each lighting; the ambient
    // image is the scene at a fifth of its brightness.
    let lit: Vec<GreyImage> = (0..4)
        .map(|k| llv_scene::scene(n, n, 2.0, 42 + k))
        .collect();
    let amb = image(n);
    let (w, h) = amb.size();
    let dim = amb.data().iter().map(|&v| v / 5).collect();
    let amb = GreyImage::new(w, h, dim).expect("sizes agree");
    let map = lens_map(n);
    let p = Params::default();
    let input = Input {
        images: &lit,
        ambient: Some(&amb),
        lens: Some(&map),
    };
    let mut ws = Workspace::new();
    ws.run(&input, &p).expect("runs");
    b.bench_local(|| {
        ws.run(black_box(&input), &p).expect("runs");
    });
}
