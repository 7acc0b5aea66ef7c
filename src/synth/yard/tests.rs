use super::poly::{Convex, P2};
use super::shade::{Light, Shade, Texture};
use super::truth::MIN_PIECE;
use super::*;
use crate::llv::Segment;

fn flat(level: f64) -> Shade {
    Shade {
        base: level,
        grad: (0.0, 0.0),
        origin: (0.0, 0.0),
        spots: Vec::new(),
        texture: Texture {
            waves: [(0.0, 0.0, 0.0); 3],
            wave_amplitude: 0.0,
            cell: 8.0,
            lattice_amplitude: 0.0,
            seed: 0,
        },
    }
}

fn facet(pts: Vec<P2>, level: f64) -> Facet {
    Facet {
        poly: Convex::new(pts).unwrap(),
        shade: flat(level),
    }
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<P2> {
    vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
}

/// A hand-made scene in an even light: floor 50, a plate 150 from
/// x = 20.3, a strip of 154 on it (faint edge), and in front a block of 150
/// whose left part lies on the floor.
fn hand_made() -> YardScene {
    let w = 64;
    YardScene {
        width: w,
        height: w,
        facets: vec![
            facet(rect(-10.0, -10.0, 80.0, 80.0), 50.0),
            facet(rect(20.3, 12.0, 70.0, 40.0), 150.0),
            facet(rect(30.0, 18.0, 40.0, 36.0), 154.0),
            facet(rect(14.0, 36.0, 26.0, 50.0), 150.0),
        ],
        light: Light {
            spot: (32.0, 32.0),
            spot_radius: 1e9,
            spot_floor: 1.0,
            centre: (32.0, 32.0),
            focal_px: 1e12,
        },
        defocus_sigma: 1.0,
        lens: CameraModel {
            cx: 31.5,
            cy: 31.5,
            sx: 0.08,
            sy: 0.08,
            f: 8.0,
            distortion: Some([1e-3, 0.0, 0.0, 0.0, 0.0]),
            radial: [0.0; 2],
        },
        kinds: vec!["hand-made"],
    }
}

#[test]
fn coverage_is_the_exact_area_of_each_facet() {
    let sc = hand_made();
    let img = sc.render_exact(false);
    let px = |x: usize, y: usize| img[y * sc.width + x];
    // Pixel 20 spans x 19.5–20.5: 0.2 of it is plate.
    assert!(
        (px(20, 30) - (50.0 + 0.2 * 100.0)).abs() < 1e-9,
        "{}",
        px(20, 30)
    );
    assert!((px(25, 30) - 150.0).abs() < 1e-9);
    assert!((px(10, 30) - 50.0).abs() < 1e-9);
    // A corner pixel of the plate: (20.5 - 20.3) × (12.5 - 12.0) of it.
    let corner = 50.0 + 0.2 * 0.5 * 100.0;
    assert!((px(20, 12) - corner).abs() < 1e-9, "{}", px(20, 12));
    // The block in front hides the plate's corner: pixel (21, 45) is all block.
    assert!((px(21, 45) - 150.0).abs() < 1e-9);
    // The mean grey level is the exact area-weighted sum.
    let sum: f64 = img.iter().sum();
    let plate = (70.0_f64.min(63.5) - 20.3) * 28.0;
    let strip = 10.0 * 18.0;
    let block_on_floor = (20.3 - 14.0) * 14.0 + (26.0 - 20.3) * (50.0 - 40.0);
    let expect = 50.0 * 64.0 * 64.0 + 100.0 * (plate + block_on_floor) + 4.0 * strip;
    assert!((sum - expect).abs() < 1e-6 * expect, "{sum} vs {expect}");
}

#[test]
fn truth_keeps_visible_boundaries_and_marks_the_faint_ones() {
    let sc = hand_made();
    let t = truth(&sc, false, 10.0);
    let find = |v: &[Segment], x: f64| -> f64 {
        v.iter()
            .filter(|s| (s.a.x - x).abs() < 1e-6 && (s.b.x - x).abs() < 1e-6)
            .map(Segment::length)
            .sum()
    };
    // The plate's left edge x = 20.3, y 12–40, minus the part the block
    // hides (y 36–40), contrast 100.
    assert!((find(&t.edges, 20.3) - 24.0).abs() < 1e-3, "{:?}", t.edges);
    assert!(t.edges.iter().all(|s| s.length() >= MIN_PIECE));
    // The strip shows 4 grey levels: don't-care, never a true edge.
    assert!(
        (find(&t.dont_care, 30.0) - 18.0).abs() < 1e-3,
        "{:?}",
        t.dont_care
    );
    assert_eq!(find(&t.edges, 30.0), 0.0);
    // The block's right side: on the floor below y = 40 (contrast 100), on
    // the plate of the same grey above it: no edge at all.
    assert!((find(&t.edges, 26.0) - 10.0).abs() < 1e-3, "{:?}", t.edges);
    assert_eq!(find(&t.dont_care, 26.0), 0.0);
    // The plate's right edge x = 70 is outside the image; its bottom edge
    // y = 40 runs into the 8-px border band at x = 55: don't-care there.
    assert_eq!(find(&t.edges, 70.0), 0.0);
    let bottom_dc: f64 = t
        .dont_care
        .iter()
        .filter(|s| (s.a.y - 40.0).abs() < 1e-6 && (s.b.y - 40.0).abs() < 1e-6)
        .map(Segment::length)
        .sum();
    assert!((bottom_dc - (63.5 - 55.0)).abs() < 1e-3, "{bottom_dc}");
    for s in &t.edges {
        assert!((s.response - 100.0).abs() < 1e-6, "{s:?}");
    }
}

#[test]
fn scenes_repeat_for_a_seed_and_differ_between_seeds() {
    let a = yard_scenes(2, 128, 3);
    let b = yard_scenes(2, 128, 3);
    assert_eq!(a, b);
    assert_ne!(a[0], yard_scenes(1, 128, 4)[0]);
    let i1 = a[0].image(YardNoise::Gauss(5.0), 9, false);
    let i2 = b[0].image(YardNoise::Gauss(5.0), 9, false);
    assert_eq!(i1, i2);
    assert_ne!(i1, a[0].image(YardNoise::Gauss(5.0), 10, false));
}

#[test]
fn signal_dependent_noise_grows_with_the_grey_level() {
    let (w, n) = (64usize, 64 * 64);
    let spread = |level: f64| {
        let img = render::expose(&vec![level; n], w, w, YardNoise::SIGNAL, 5);
        let v: Vec<f64> = img.data().iter().map(|&p| f64::from(p)).collect();
        let m = v.iter().sum::<f64>() / n as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n as f64).sqrt()
    };
    let (dark, bright) = (spread(40.0), spread(220.0));
    assert!((dark - 3.6).abs() < 0.4, "{dark}");
    assert!((bright - 7.0).abs() < 0.5, "{bright}");
}

/// Where a true edge is, the noise-free render changes by about its
/// contrast across it; where a detector sees nothing, nothing is claimed.
#[test]
fn generated_truth_sits_where_the_image_changes() {
    let mut checked = 0;
    let mut agree = 0;
    for sc in yard_scenes(6, 256, 11) {
        let img = sc.render_exact(false);
        let t = truth(&sc, false, 10.0);
        assert!(!t.edges.is_empty() && !t.dont_care.is_empty());
        let at = |x: f64, y: f64| {
            let (xi, yi) = (x.round() as usize, y.round() as usize);
            img[yi.min(sc.height - 1) * sc.width + xi.min(sc.width - 1)]
        };
        for e in t.edges.iter().filter(|e| e.length() > 12.0) {
            let (mx, my) = ((e.a.x + e.b.x) / 2.0, (e.a.y + e.b.y) / 2.0);
            let l = e.length();
            let (nx, ny) = (-(e.b.y - e.a.y) / l, (e.b.x - e.a.x) / l);
            let d = (at(mx + 1.6 * nx, my + 1.6 * ny) - at(mx - 1.6 * nx, my - 1.6 * ny)).abs();
            checked += 1;
            // Texture (≤ 2.5 each side) and a nearby edge may blur it.
            if (d - e.response).abs() < 0.25 * e.response + 6.0 {
                agree += 1;
            }
        }
    }
    assert!(checked > 60, "{checked}");
    assert!(
        agree as f64 >= 0.85 * checked as f64,
        "{agree} of {checked}"
    );
}

/// The family holds what it promises: close parallel edges 4–8 px apart,
/// near-collinear ones, low-contrast ones, and objects cut by the frame.
#[test]
fn the_family_has_close_parallel_low_contrast_and_cut_edges() {
    let (mut close, mut low, mut strong, mut cut) = (0, 0, 0, 0);
    let mut dont_care = 0.0;
    let mut all = 0.0;
    for sc in yard_scenes(12, 512, 1) {
        let t = truth(&sc, false, 10.0);
        for (i, e) in t.edges.iter().enumerate() {
            all += e.length();
            if (12.0..=30.0).contains(&e.response) {
                low += 1;
            }
            if e.response >= 30.0 {
                strong += 1;
            }
            let m = crate::llv::Point::new((e.a.x + e.b.x) / 2.0, (e.a.y + e.b.y) / 2.0);
            if t.edges.iter().enumerate().any(|(j, f)| {
                j != i
                    && crate::synth::score::angle_diff_deg(e, f) < 3.0
                    && (4.0..=8.0).contains(&crate::synth::score::line_distance(f, m))
                    && f.a.dist(m).min(f.b.dist(m)) < f.length()
            }) {
                close += 1;
            }
        }
        dont_care += t.dont_care.iter().map(Segment::length).sum::<f64>();
        let w = sc.width as f64;
        if t.dont_care.iter().any(|s| {
            [s.a.x, s.a.y, s.b.x, s.b.y]
                .iter()
                .any(|&v| v < 1.0 || v > w - 2.0)
        }) {
            cut += 1;
        }
    }
    assert!(
        close >= 24,
        "{close} edges with a parallel neighbour 4–8 px away"
    );
    assert!(low >= 40 && strong >= 40, "{low} low, {strong} strong");
    assert!(cut >= 10, "{cut} scenes cut by the frame");
    assert!(
        dont_care > 0.05 * all && dont_care < all,
        "{dont_care} of {all}"
    );
}

#[test]
fn the_distorted_render_shows_the_truth_through_the_lens() {
    let sc = &yard_scenes(1, 256, 2)[0];
    let straight = sc.render_exact(false);
    let bent = sc.render_exact(true);
    assert_ne!(straight, bent);
    let t = truth(sc, true, 10.0);
    let mut ok = 0;
    let mut n = 0;
    for e in t
        .edges
        .iter()
        .filter(|e| e.length() > 12.0 && e.response > 30.0)
    {
        let (mx, my) = ((e.a.x + e.b.x) / 2.0, (e.a.y + e.b.y) / 2.0);
        let l = e.length();
        let (nx, ny) = (-(e.b.y - e.a.y) / l, (e.b.x - e.a.x) / l);
        let obs = |d: f64| {
            sc.lens
                .ideal_to_observed_converged(mx + d * nx, my + d * ny)
        };
        let val = |(x, y): (f64, f64)| {
            bent[(y.round() as usize).min(sc.height - 1) * sc.width
                + (x.round() as usize).min(sc.width - 1)]
        };
        n += 1;
        if (val(obs(1.6)) - val(obs(-1.6))).abs() > 0.5 * e.response {
            ok += 1;
        }
    }
    assert!(n > 5 && ok as f64 >= 0.85 * n as f64, "{ok} of {n}");
    let model = sc.cdf().camera_model().unwrap();
    assert_eq!(model, sc.lens);
    // Corners move by a few pixels.
    let (x, y) = sc.lens.ideal_to_observed(0.0, 0.0);
    let moved = x.hypot(y);
    assert!((0.7..4.0).contains(&moved), "{moved}");
}
