//! What the simulated cameras deliver changes as a person expects: a top
//! face lit by any one light is brighter than under ambient light alone,
//! every light brightens every camera's view, the four cameras see the
//! workpiece differently, and a seeded run repeats exactly.

use vss::llv::GreyImage;
use vss::rig::Cell;
use vss::rig::sim::cell_profile;
use vss::synth;

const SIZE: u32 = 128;

fn mean(img: &GreyImage) -> f64 {
    img.data().iter().map(|&v| f64::from(v)).sum::<f64>() / img.data().len() as f64
}

/// Mean grey of the 3 × 3 pixels around an observed pixel.
fn patch(img: &GreyImage, x: f64, y: f64) -> f64 {
    let (cx, cy) = (x.round() as i64, y.round() as i64);
    let mut sum = 0.0;
    let mut n = 0.0;
    for dy in -1..=1 {
        for dx in -1..=1 {
            if let Some(v) = img.get((cx + dx) as usize, (cy + dy) as usize) {
                sum += f64::from(v);
                n += 1.0;
            }
        }
    }
    assert!(n > 0.0, "({x}, {y}) is outside the image");
    sum / n
}

#[test]
fn lights_brighten_faces_and_views_of_every_camera() {
    let mut p = cell_profile(SIZE, SIZE);
    p.relay.settle_ms = 0;
    let mut cell = Cell::open(&p).expect("simulated cell");
    let scene = synth::cell_scene();
    let cams = synth::cell_cameras(SIZE as usize, SIZE as usize);
    let mut ambient_views = Vec::new();
    for (k, cam) in cams.iter().enumerate() {
        let k = k as u32 + 1;
        let ambient = cell
            .capture(k, 'e', &mut |_, _| true)
            .expect("ambient")
            .image;
        for object in &scene.objects {
            // The centre of the object's top face, where the camera sees it.
            let vs = object.vertices();
            let top = vs.iter().map(|v| v[2]).fold(f64::MIN, f64::max);
            let ring: Vec<_> = vs.iter().filter(|v| (v[2] - top).abs() < 1e-6).collect();
            let c = ring
                .iter()
                .fold([0.0; 3], |a, v| [a[0] + v[0], a[1] + v[1], a[2] + v[2]]);
            let n = ring.len() as f64;
            let ideal = cam
                .project([c[0] / n, c[1] / n, c[2] / n])
                .expect("in front");
            let (x, y) = cam.model.ideal_to_observed(ideal.x, ideal.y);
            let dark = patch(&ambient, x, y);
            for letter in ['a', 'b', 'c', 'd'] {
                let lit = cell
                    .capture(k, letter, &mut |_, _| true)
                    .expect("lit")
                    .image;
                let bright = patch(&lit, x, y);
                assert!(
                    bright > dark + 10.0,
                    "camera {k}, {} top face: lit by {letter} {bright:.1}, ambient {dark:.1}",
                    object.name
                );
                assert!(
                    mean(&lit) > mean(&ambient) + 5.0,
                    "camera {k}: lighting {letter} does not brighten the view"
                );
            }
        }
        ambient_views.push(ambient);
    }
    // The ambient image is dim and flat.
    for (k, a) in ambient_views.iter().enumerate() {
        assert!(mean(a) < 60.0, "camera {}: ambient mean {}", k + 1, mean(a));
    }
    // Each camera sees the workpiece from elsewhere.
    for i in 0..ambient_views.len() {
        for j in i + 1..ambient_views.len() {
            let (a, b) = (&ambient_views[i], &ambient_views[j]);
            let lit_a = cell
                .capture(i as u32 + 1, 'a', &mut |_, _| true)
                .expect("a")
                .image;
            let lit_b = cell
                .capture(j as u32 + 1, 'a', &mut |_, _| true)
                .expect("a")
                .image;
            let diff: f64 = lit_a
                .data()
                .iter()
                .zip(lit_b.data())
                .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs())
                .sum::<f64>()
                / lit_a.data().len() as f64;
            assert!(
                diff > 5.0,
                "cameras {} and {} see alike ({diff:.1})",
                i + 1,
                j + 1
            );
            assert_ne!(a, b);
        }
    }
}

#[test]
fn noise_is_seeded_and_redrawn_per_frame() {
    let mut p = cell_profile(64, 64);
    p.relay.settle_ms = 0;
    p.sim.noise = 3.0;
    let shots = |p: &vss::profile::Profile| {
        let mut cell = Cell::open(p).expect("cell");
        let one = cell.capture(1, 'a', &mut |_, _| true).expect("1").image;
        let two = cell.capture(1, 'a', &mut |_, _| true).expect("2").image;
        (one, two)
    };
    let (a1, a2) = shots(&p);
    let (b1, b2) = shots(&p);
    assert!(a1 == b1 && a2 == b2, "same seed, same frames");
    assert!(a1 != a2, "each freeze draws new noise");
    p.sim.seed += 1;
    let (c1, _) = shots(&p);
    assert!(c1 != a1, "another seed, other noise");
    // Noise of σ 3 around the same clean frame: small mean difference.
    let d: f64 = a1
        .data()
        .iter()
        .zip(a2.data())
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs())
        .sum::<f64>()
        / a1.data().len() as f64;
    assert!((1.0..6.0).contains(&d), "{d}");
}
