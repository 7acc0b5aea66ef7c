//! Runs one LLV stage N times on the bench scene (512², noise σ 2, seed 42),
//! for instruction counts that do not depend on the machine's other load:
//!
//! ```text
//! cargo build --release --example llv_count
//! for n in 5 15; do valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.$n \
//!     target/release/examples/llv_count pipeline $n; done
//! ```
//!
//! Instructions per run = (total at N = 15 − total at N = 5) / 10, which
//! takes out the scene's rendering and the warm-up. Stages: `pipeline`
//! (edges, lines, CONNECT; no lens), `edges` (response and peaks, both
//! directions), `response`, `peaks` (`peaks_h`, `peaks_v`: one direction),
//! `lines`, `split` (the pipeline's stages with each scan direction on a
//! thread of its own, then CONNECT without corners: what two cores would
//! give; time it, its instruction count means nothing); `scene FILE.pgm`
//! writes the scene.

use vss::llv::connect::{ConnectScratch, connect_into};
use vss::llv::edges::{PeakScratch, Response, ResponseScratch, exact_response_into, peaks_into};
use vss::llv::lines::{LineScratch, extract_into};
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::{EdgePoints, Params, ScanDir};

#[path = "../tests/it/support/llv_scene.rs"]
mod llv_scene;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(stage), Some(n)) = (args.get(1), args.get(2)) else {
        eprintln!(
            "usage: llv_count pipeline|edges|response|peaks|peaks_h|peaks_v|lines|split N | scene FILE.pgm"
        );
        std::process::exit(2);
    };
    let img = llv_scene::scene(512, 512, 2.0, 42);
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
    let p = Params::default();
    let a = p.edges.half_width as usize;
    let mut ws = Workspace::new();
    ws.run(&Input::single(&img), &p).expect("the scene runs");
    let warm = ws.outputs().clone();
    let (mut rh, mut rv) = (Response::default(), Response::default());
    let (mut eh, mut ev) = (EdgePoints::default(), EdgePoints::default());
    let mut rs = ResponseScratch::default();
    let mut ps = PeakScratch::default();
    let mut ls = LineScratch::default();
    let (mut lh, mut lv) = (Vec::new(), Vec::new());
    let mut response = |rh: &mut Response, rv: &mut Response| {
        exact_response_into(&img, ScanDir::Horizontal, a, rh, &mut rs).expect("size");
        exact_response_into(&img, ScanDir::Vertical, a, rv, &mut rs).expect("size");
    };
    if stage.starts_with("peaks") {
        response(&mut rh, &mut rv);
    }
    let (mut split_h, mut split_v) = Default::default();
    let (mut joined, mut cs) = (Vec::new(), ConnectScratch::default());
    let mut check = 0usize;
    for _ in 0..n {
        match stage.as_str() {
            "pipeline" => {
                ws.run(&Input::single(&img), &p).expect("the scene runs");
                check += ws.outputs().lines.len();
            }
            "edges" | "response" | "peaks" | "peaks_h" | "peaks_v" => {
                if !stage.starts_with("peaks") {
                    response(&mut rh, &mut rv);
                }
                if stage != "response" && stage != "peaks_v" {
                    peaks_into(&rh, &p.edges, &mut eh, &mut ps);
                }
                if stage != "response" && stage != "peaks_h" {
                    peaks_into(&rv, &p.edges, &mut ev, &mut ps);
                }
                check += eh.points.len() + ev.points.len();
            }
            "lines" => {
                extract_into(&warm.edges_h, &p.lines, &mut lh, &mut ls);
                extract_into(&warm.edges_v, &p.lines, &mut lv, &mut ls);
                check += lh.len() + lv.len();
            }
            "split" => {
                // What two cores would give: each scan direction's response,
                // peaks and lines on a thread of its own (a scoped thread a
                // run, as a plain implementation would), then CONNECT.
                let img = &img;
                let one =
                    |dir,
                     r: &mut Response,
                     e: &mut EdgePoints,
                     l: &mut Vec<_>,
                     sc: &mut (ResponseScratch, PeakScratch, LineScratch)| {
                        exact_response_into(img, dir, a, r, &mut sc.0).expect("size");
                        peaks_into(r, &p.edges, e, &mut sc.1);
                        extract_into(e, &p.lines, l, &mut sc.2);
                    };
                std::thread::scope(|s| {
                    s.spawn(|| one(ScanDir::Vertical, &mut rv, &mut ev, &mut lv, &mut split_v));
                    one(ScanDir::Horizontal, &mut rh, &mut eh, &mut lh, &mut split_h);
                });
                lh.extend_from_slice(&lv);
                connect_into(&lh, &p.connect, &mut joined, &mut cs);
                check += joined.len();
            }
            other => {
                eprintln!("unknown stage {other}");
                std::process::exit(2);
            }
        }
    }
    println!("{stage} x{n}: {check}");
}
