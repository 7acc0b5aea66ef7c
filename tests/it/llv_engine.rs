//! The line engine on inputs that break estimates: a flat image, an image of
//! pure noise, one edge, the smallest image the stages take and an image
//! whose valid area is a thin ring (what a strong lens correction leaves).
//! Each gives lines or none, never a panic, and nothing that is not a
//! number; and two threads give what one does.

use vss::llv::pipeline::{self, Input, StageOutputs};
use vss::llv::rng::SplitMix64;
use vss::llv::{GreyImage, Params};

fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f64) -> GreyImage {
    let d = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y).round().clamp(0.0, 255.0) as u8)
        .collect();
    GreyImage::new(w, h, d).unwrap()
}

fn noise(seed: u64, sigma: f64) -> impl Fn(usize, usize) -> f64 {
    move |x, y| {
        let mut r = SplitMix64::new(seed ^ ((x as u64) << 32 | y as u64));
        sigma * r.gauss()
    }
}

/// Every number the outputs hold is finite.
fn all_finite(o: &StageOutputs) -> Result<(), String> {
    for e in [&o.edges_h, &o.edges_v] {
        if let Some(p) = e
            .points
            .iter()
            .find(|p| !(p.x.is_finite() && p.y.is_finite() && p.response.is_finite()))
        {
            return Err(format!("edge point {p:?}"));
        }
    }
    for l in o.lines_raw.iter().chain(&o.lines) {
        let v = [l.a.x, l.a.y, l.b.x, l.b.y, l.response, l.residual];
        if v.iter().any(|v| !v.is_finite()) {
            return Err(format!("line {l:?}"));
        }
    }
    for n in [&o.noise_h, &o.noise_v] {
        if !n.global().is_finite() {
            return Err(format!("noise {n:?}"));
        }
    }
    Ok(())
}

fn run(img: &GreyImage) -> StageOutputs {
    let out = pipeline::run(&Input::single(img), &Params::default()).unwrap();
    if let Err(e) = all_finite(&out) {
        panic!("{e}");
    }
    out
}

#[test]
fn a_flat_image_gives_no_lines() {
    for v in [0.0, 128.0, 255.0] {
        let out = run(&image(64, 48, |_, _| v));
        assert!(out.lines.is_empty() && out.edges_h.points.is_empty());
        assert_eq!(out.noise_h.global(), 0.0);
    }
}

#[test]
fn pure_noise_gives_almost_no_lines() {
    let mut lines = 0;
    for (k, sigma) in [2.0, 10.0, 40.0].into_iter().enumerate() {
        let n = noise(k as u64, sigma);
        let out = run(&image(256, 256, |x, y| 128.0 + n(x, y)));
        // The noise scale is measured, not assumed: σ_r = σ √Σw² for the
        // kernel's weights w (0.889 σ at A = 3, 0.773 σ at A = 4).
        let gain = vss::llv::edges::kernel(Params::default().edges.half_width as usize)
            .iter()
            .map(|w| f64::from(*w).powi(2))
            .sum::<f64>()
            .sqrt();
        let est = f64::from(out.noise_h.global());
        let want = gain * sigma.min(128.0 / 2.5);
        assert!(
            (est / want - 1.0).abs() < 0.25,
            "σ {sigma}: {est} vs {want}"
        );
        lines += out.lines.len();
    }
    // The significance test allows about one false segment an image.
    assert!(lines <= 3, "{lines} lines on pure noise");
}

#[test]
fn one_edge_gives_one_line() {
    let n = noise(7, 3.0);
    let img = image(200, 160, |x, y| {
        let d = x as f64 - 80.0 - 0.3 * y as f64;
        60.0 + 100.0 / (1.0 + (-1.5 * d).exp()) + n(x, y)
    });
    let out = run(&img);
    assert_eq!(out.lines.len(), 1, "{:?}", out.lines);
    let l = out.lines[0];
    assert!(l.length() > 140.0, "{l:?}");
}

#[test]
fn the_smallest_image_runs() {
    for f in [
        Box::new(|x: usize, _y: usize| if x < 8 { 30.0 } else { 200.0 })
            as Box<dyn Fn(usize, usize) -> f64>,
        Box::new(|x, y| ((x * 37 + y * 91) % 256) as f64),
        Box::new(|_, _| 9.0),
    ] {
        run(&image(16, 16, f));
    }
}

#[test]
fn a_thin_ring_of_valid_pixels_runs() {
    let n = noise(3, 4.0);
    let mut img = image(256, 256, |x, y| {
        let b = if x + y > 256 { 170.0 } else { 60.0 };
        b + n(x, y)
    });
    // Valid only between radii 100 and 104 around the centre.
    let mask = (0..256 * 256)
        .map(|i| {
            let (x, y) = ((i % 256) as f64 - 128.0, (i / 256) as f64 - 128.0);
            (100.0..104.0).contains(&x.hypot(y))
        })
        .collect();
    img.set_valid_mask(Some(mask)).unwrap();
    let out = run(&img);
    // Whatever is found lies on the ring, none of it beyond its edges.
    let on_ring = |p: vss::llv::Point| (96.0..108.0).contains(&(p.x - 128.0).hypot(p.y - 128.0));
    for e in out.edges_h.points.iter().chain(&out.edges_v.points) {
        let p = vss::llv::Point::new(f64::from(e.x), f64::from(e.y));
        assert!(on_ring(p), "{e:?}");
    }
    // A wider ring holds the edge where it crosses.
    let mask = (0..256 * 256)
        .map(|i| {
            let (x, y) = ((i % 256) as f64 - 128.0, (i / 256) as f64 - 128.0);
            (90.0..120.0).contains(&x.hypot(y))
        })
        .collect();
    img.set_valid_mask(Some(mask)).unwrap();
    run(&img);
}

/// `edges.threads = 2` runs the scan directions on two threads: the same
/// outputs as one, for one image and for several lightings.
#[test]
fn two_threads_give_what_one_does() {
    let (scene, cam, lights) = vss::synth::test_scenes(1, 256, 256, 11).remove(0);
    let o = vss::synth::RenderOptions {
        noise_sigma: 4.0,
        ..Default::default()
    };
    let imgs: Vec<GreyImage> = lights
        .iter()
        .map(|l| vss::synth::render(&scene, &cam, std::slice::from_ref(l), &o))
        .collect();
    let mut p = Params::default();
    for n in [1, imgs.len()] {
        let input = Input {
            images: &imgs[..n],
            ambient: None,
            lens: None,
        };
        p.edges.threads = 1;
        let one = pipeline::run(&input, &p).unwrap();
        p.edges.threads = 2;
        let two = pipeline::run(&input, &p).unwrap();
        assert!(!one.lines.is_empty());
        assert_eq!(one.edges_h, two.edges_h);
        assert_eq!(one.edges_v, two.edges_v);
        assert_eq!(one.lines_raw, two.lines_raw);
        assert_eq!(one.lines, two.lines);
    }
}
