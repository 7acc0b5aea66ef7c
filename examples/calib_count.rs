//! Runs the plate detector (or the whole 12-view calibration) N times on the
//! simulated camera 1's views, for instruction counts under callgrind:
//!
//! ```sh
//! cargo build --release --example calib_count
//! valgrind --tool=callgrind --callgrind-out-file=/tmp/cg5 target/release/examples/calib_count detect 5
//! valgrind --tool=callgrind --callgrind-out-file=/tmp/cg15 target/release/examples/calib_count detect 15
//! ```
//!
//! per run = (count at 15 − count at 5) / 10, which leaves out rendering
//! the views; `solve N` does the same for the calibration of 12 views.

use vss::calib::{self, Options, Plate, View};
use vss::llv::GreyImage;
use vss::rig::sim::plate::{Mode, PlateTarget};
use vss::rig::sim::{Scene, SimOptions};

fn main() {
    let mut args = std::env::args().skip(1);
    let what = args.next().unwrap_or_else(|| "detect".into());
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(5);
    let plate = Plate::load(&format!(
        "{}/profiles/plates/squares.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the squares plate");
    let scene = Scene::new(SimOptions::new(512, 512));
    scene.set_target(Some(PlateTarget {
        plate: plate.clone(),
        mode: Mode::Held,
    }));
    let imgs: Vec<GreyImage> = (1..=12)
        .map(|shot| GreyImage::new(512, 512, scene.frame(1, 0, shot)).expect("a frame"))
        .collect();
    let mut det = calib::Detector::new();
    let views: Vec<View> = imgs
        .iter()
        .enumerate()
        .map(|(i, img)| View {
            name: format!("view{}", i + 1),
            corners: det.detect(img, &plate).expect("the grid").corners,
        })
        .collect();
    let cdf = vss::rig::sim::camera_cdf(1, 512, 512).expect("camera 1");
    let m = cdf.camera_model().expect("a model");
    let o = Options {
        width: 512,
        height: 512,
        sx: m.sx,
        sy: m.sy,
        estimate_scale: false,
        centre: None,
        full_model: false,
    };
    let mut total = 0usize;
    for i in 0..n {
        match what.as_str() {
            "solve" => total += calib::calibrate(&views, &o).map_or(0, |c| c.views.len()),
            _ => {
                total += det
                    .detect(&imgs[i % imgs.len()], &plate)
                    .map_or(0, |d| d.corners.len())
            }
        }
    }
    println!("{what} × {n}: {total}");
}
