//! Runs one LLV stage N times on the bench scene (512² or `SIZE`², noise σ 2, seed 42),
//! for instruction counts that do not depend on the machine's other load:
//!
//! ```text
//! cargo build --release --example llv_count
//! for n in 5 15; do valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.$n \
//!     target/release/examples/llv_count pipeline $n; done
//! ```
//!
//! Instructions per run = (total at N = 15 − total at N = 5) / 10, which
//! takes out the scene's rendering and the warm-up. With `TIME=1` in the
//! environment each run is timed and the fastest and median are printed
//! (`TIME=1 llv_count pipeline 500`); with `PLAIN=1` as well, the edge
//! pass's peak test runs in plain code instead of AVX2 lanes. Under
//! valgrind the AVX2 paths are not taken (its CPU lacks features they
//! need): count instructions for the plain paths, time the machine's own.
//! With `DRAW=1` the runs use the drawing front end (`lines.draw`).
//!
//! Stages: `pipeline` (edges, lines, CONNECT; no lens), `pipelinelens` (the
//! same after lens correction from a precomputed map), `pipeline2` (no
//! lens, a thread for each scan direction: time it, its instruction count
//! means little), `edges` (response, noise scale and edge points, both
//! directions), `response`, `noise`, `peaks` (the peak map and the edge
//! points, as two passes), `lines` (`linesh`, `linesv`: one direction),
//! `connect`, `lens` (the correction alone), `five` (four lightings and the
//! ambient image to lines); `scene FILE.pgm` writes the scene. With
//! `IMAGE=photo.pgm` (any image `vss llv` reads) that image replaces the
//! bench scene for the stages of one image (`TIME=1 IMAGE=photo.pgm
//! llv_count connect 200`: a photograph has hundreds of lines where a
//! synthetic scene has tens).

use vss::llv::connect::{ConnectScratch, connect_into};
use vss::llv::edges::{
    NoiseMap, NoiseScratch, PeakMap, PeakScratch, Response, ResponseScratch, Starts, detect_into,
    response_into,
};
use vss::llv::lines::{LineScratch, track_into};
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::{EdgePoints, Params, ScanDir};

#[path = "../tests/it/support/llv_scene.rs"]
mod llv_scene;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(stage), Some(n)) = (args.get(1), args.get(2)) else {
        eprintln!(
            "usage: llv_count pipeline|pipeline2|edges|response|noise|peaks|lines|connect|five N | scene FILE.pgm"
        );
        std::process::exit(2);
    };
    // With SIZE set (say `SIZE=2048`), the scene and the lens are that size
    // instead of 512² (the lens scaled as `benches/llv.rs` scales it).
    let size: usize = match std::env::var("SIZE") {
        Ok(v) => v.parse().unwrap_or_else(|_| {
            eprintln!("SIZE must be a whole number, not {v:?}");
            std::process::exit(2);
        }),
        Err(_) => 512,
    };
    let img = match std::env::var_os("IMAGE") {
        Some(path) => match vss::formats::imageio::read_any(std::path::Path::new(&path)) {
            Ok(f) => f.image,
            Err(e) => {
                eprintln!("IMAGE: {e}");
                std::process::exit(2);
            }
        },
        None => llv_scene::scene(size, size, 2.0, 42),
    };
    if stage == "scene" {
        // Writes the bench scene as a binary PGM to `N` (a path here).
        let (w, h) = img.size();
        let mut f = format!("P5\n{w} {h}\n255\n").into_bytes();
        f.extend_from_slice(img.data());
        std::fs::write(n, f).expect("write the scene");
        return;
    }
    let Ok(n) = n.parse::<usize>() else {
        eprintln!("N must be a whole number, not {n:?}");
        std::process::exit(2);
    };
    let mut p = Params::default();
    if stage == "pipeline2" {
        p.edges.threads = 2;
    }
    // With DRAW=1 the drawing front end replaces the trackers.
    p.lines.draw = std::env::var_os("DRAW").is_some();
    let a = p.edges.half_width as usize;
    let mut ws = Workspace::new();
    ws.run(&Input::single(&img), &p).expect("the scene runs");
    let warm = ws.outputs().clone();
    let (mut rh, mut rv) = (Response::default(), Response::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let (mut nh, mut nv) = (NoiseMap::default(), NoiseMap::default());
    let (mut sh, mut sv) = (Starts::new(), Starts::new());
    // The starts of the warm outputs, for the line stage alone.
    let (mut wsh, mut wsv) = (Starts::new(), Starts::new());
    let (mut wmh, mut wmv) = (PeakMap::default(), PeakMap::default());
    let (mut mh, mut mv) = (PeakMap::default(), PeakMap::default());
    let t = p.lines.track_sigmas;
    for (r, e, st, m) in [
        (
            &warm.response_h,
            &mut EdgePoints::default(),
            &mut wsh,
            &mut wmh,
        ),
        (
            &warm.response_v,
            &mut EdgePoints::default(),
            &mut wsv,
            &mut wmv,
        ),
    ] {
        let mut nm = NoiseMap::default();
        detect_into(
            r,
            &p.edges,
            t,
            &mut nm,
            m,
            e,
            st,
            &mut PeakScratch::default(),
        );
    }
    let mut rs = ResponseScratch::default();
    let mut ps = PeakScratch::default();
    let mut ns = NoiseScratch::default();
    let mut ls = LineScratch::default();
    let (mut lh, mut lv) = (Vec::new(), Vec::new());
    let (mut joined, mut cs) = (Vec::new(), ConnectScratch::default());
    // Five images of the view (`five`): four lightings with their own
    // noise and the ambient image at a fifth of the brightness, as
    // `benches/llv.rs` has them.
    let lit: Vec<_> = (0..4)
        .map(|k| llv_scene::scene(size, size, 2.0, 42 + k))
        .collect();
    let (w, h) = img.size();
    let amb = vss::llv::GreyImage::new(w, h, img.data().iter().map(|&v| v / 5).collect())
        .expect("sizes agree");
    let five_input = Input {
        images: &lit,
        ambient: Some(&amb),
        lens: None,
    };
    let mut five = Workspace::new();
    // The bench's distorting camera (`benches/llv.rs`), for `lens` and
    // `pipelinelens`.
    let scale = 512.0 / size as f64;
    let lens = vss::llv::lens::LensMap::new(
        &vss::llv::lens::CameraModel {
            cx: size as f64 / 2.0 + 3.0,
            cy: size as f64 / 2.0 - 2.0,
            sx: 0.0086 * scale,
            sy: 0.0083 * scale,
            f: 8.5,
            distortion: Some([-1.2e-3, 1.0e-4, -8.0e-5, 5.0e-5, 2.0e-5]),
            radial: [0.0; 2],
        },
        size,
        size,
    );
    let mut corrected = vss::llv::GreyImage::default();
    let lens_input = Input {
        images: std::slice::from_ref(&img),
        ambient: None,
        lens: Some(&lens),
    };
    let mut lensed = Workspace::new();
    let mut check = 0usize;
    // With TIME set, each run is timed and the fastest and median
    // microseconds are printed (a stage's own time, without the setup).
    let timed = std::env::var_os("TIME").is_some();
    // With PLAIN set, the edge pass's peak test runs in plain code.
    vss::llv::edges::peaks::plain_only(std::env::var_os("PLAIN").is_some());
    let mut times = Vec::with_capacity(n);
    for _ in 0..n {
        let t0 = std::time::Instant::now();
        match stage.as_str() {
            "pipeline" | "pipeline2" => {
                ws.run(&Input::single(&img), &p).expect("the scene runs");
                check += ws.outputs().lines.len();
            }
            "edges" | "response" => {
                response_into(&img, ScanDir::Horizontal, a, &mut rh, &mut rs).expect("size");
                response_into(&img, ScanDir::Vertical, a, &mut rv, &mut rs).expect("size");
                if stage == "edges" {
                    detect_into(
                        &rh, &p.edges, t, &mut nh, &mut mh, &mut eh, &mut sh, &mut ps,
                    );
                    detect_into(
                        &rv, &p.edges, t, &mut nv, &mut mv, &mut ev, &mut sv, &mut ps,
                    );
                }
                check += eh.points.len() + ev.points.len();
            }
            "noise" => {
                nh.estimate_into(&warm.response_h, &mut ns);
                nv.estimate_into(&warm.response_v, &mut ns);
                check += nh.tiles().0;
            }
            "peaks" => {
                for (r, nm, m, e, st) in [
                    (&warm.response_h, &warm.noise_h, &mut mh, &mut eh, &mut sh),
                    (&warm.response_v, &warm.noise_v, &mut mv, &mut ev, &mut sv),
                ] {
                    m.build_into(r, nm, p.edges.floor, t, &mut ps);
                    vss::llv::edges::peaks::points_into(r, nm, &p.edges, None, e, st, &mut ps);
                    check += e.points.len();
                }
            }
            "lens" => {
                vss::llv::lens::correct_into(&img, &lens, &mut corrected).expect("same size");
                check += corrected.data()[1000] as usize;
            }
            "pipelinelens" => {
                lensed.run(&lens_input, &p).expect("the scene runs");
                check += lensed.outputs().lines.len();
            }
            "lines" | "linesh" | "linesv" => {
                // Both directions, or the one named.
                for horizontal in [true, false] {
                    if stage == if horizontal { "linesv" } else { "linesh" } {
                        continue;
                    }
                    let (r, nm, m, e, st, out) = if horizontal {
                        (
                            &warm.response_h,
                            &warm.noise_h,
                            &wmh,
                            &warm.edges_h,
                            &wsh,
                            &mut lh,
                        )
                    } else {
                        (
                            &warm.response_v,
                            &warm.noise_v,
                            &wmv,
                            &warm.edges_v,
                            &wsv,
                            &mut lv,
                        )
                    };
                    track_into(r, nm, m, e, st, p.edges.floor, a, &p.lines, out, &mut ls);
                    check += out.len();
                }
            }
            "connect" => {
                connect_into(&warm.lines_raw, &p.connect, &mut joined, &mut cs);
                check += joined.len();
            }
            "five" => {
                let out = five.run(&five_input, &p).expect("the view runs");
                check += out.lines.len();
                let t = out.timings;
                if !timed {
                    eprintln!(
                        "five: edge points {} + {}, lines {} raw, {} after CONNECT; edges {} us, lines {} us",
                        out.edges_h.points.len(),
                        out.edges_v.points.len(),
                        out.lines_raw.len(),
                        out.lines.len(),
                        t.edges_us,
                        t.lines_us
                    );
                }
            }
            other => {
                eprintln!("unknown stage {other}");
                std::process::exit(2);
            }
        }
        times.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    if timed && !times.is_empty() {
        times.sort_by(f64::total_cmp);
        println!(
            "{stage}: fastest {:.1} us, median {:.1} us over {n} runs",
            times[0],
            times[times.len() / 2]
        );
    }
    println!("{stage} x{n}: {check}");
}
