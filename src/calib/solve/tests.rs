//! The solver's unit tests on synthetic views.

use super::*;
use crate::calib::plate::PlateCorner;

/// Views of a 9 × 7 grid of 20 mm through `cam`, tilted every way,
/// with the corners moved by seeded noise of `sigma` px.
fn views(cam: &CameraModel, sigma: f64, seed: u64) -> Vec<View> {
    let mut state = seed;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gauss = move || {
        let (a, b) = (uniform(), uniform());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    };
    let mut out = Vec::new();
    for k in 0..12 {
        let a = f64::from(k) * std::f64::consts::TAU / 12.0;
        let pose = Pose {
            rotation: Vector3::new(0.5 * a.cos(), 0.5 * a.sin(), 0.1 * f64::from(k % 3)),
            translation: Vector3::new(-80.0 + 10.0 * a.sin(), -60.0, 450.0 + 10.0 * f64::from(k)),
        };
        let mut corners = Vec::new();
        for j in 0..7u32 {
            for i in 0..9u32 {
                let xy = [f64::from(i) * 20.0, f64::from(j) * 20.0];
                let p = model::project(cam, &pose, &Vector3::new(xy[0], xy[1], 0.0)).unwrap();
                corners.push(Corner {
                    corner: PlateCorner { key: (i, j), xy },
                    px: [p.px.x + sigma * gauss(), p.px.y + sigma * gauss()],
                });
            }
        }
        out.push(View {
            name: format!("v{k}"),
            corners,
        });
    }
    out
}

fn options(cam: &CameraModel) -> Options {
    Options {
        width: 640,
        height: 480,
        sx: cam.sx,
        sy: cam.sy,
        estimate_scale: false,
        centre: None,
        full_model: false,
    }
}

/// A 640 × 480 camera of 6 µm pixels and a 4.2 mm lens with `distortion`.
fn camera(distortion: [f64; 5]) -> CameraModel {
    CameraModel {
        cx: 322.0,
        cy: 236.0,
        sx: 0.006,
        sy: 0.006,
        f: 4.2,
        distortion: Some(distortion),
        radial: [0.0; 2],
    }
}

#[test]
fn a_term_the_views_cannot_tell_from_zero_is_fixed_not_refused() {
    // A lens with radial distortion only: p1 and p2 are noise.
    let cam = camera([-0.004, 0.0, 0.0, 0.0, 0.0]);
    let v = views(&cam, 0.2, 7);
    let c = calibrate(&v, &options(&cam)).unwrap_or_else(|e| panic!("{e}"));
    assert!(!c.fixed.is_empty(), "{:?}", c.params);
    for f in &c.fixed {
        assert!(["p1", "p2"].contains(&f.name), "{f:?}");
        assert!(f.se >= f.value.abs());
        assert!(
            c.warnings
                .iter()
                .any(|w| w.starts_with(&format!("{} = ", f.name)))
        );
    }
    // What is left is determined, and the camera is found.
    for p in &c.params {
        assert!(p.se < p.value.abs(), "{p:?}");
    }
    assert!((c.model.cx - cam.cx).hypot(c.model.cy - cam.cy) < 2.0);
    assert!((c.model.f - cam.f).abs() / cam.f < 0.005);
    let lines = crate::calib::parameter_lines(&c, "+-");
    assert!(lines.iter().any(|l| l.contains("(fixed:")), "{lines:?}");
}

#[test]
fn the_projection_uncertainty_grows_towards_the_corners() {
    let cam = camera(model::fold(-0.004, 2e-4, -1e-4, 0.0, 0.0));
    let v = views(&cam, 0.1, 3);
    let c = calibrate(&v, &options(&cam)).unwrap();
    assert_eq!(c.uncertainty.len(), 5);
    let mid = c.uncertainty[0].1;
    assert!(mid > 0.0 && mid < 0.2, "{:?}", c.uncertainty);
    assert!(
        c.uncertainty[1..].iter().all(|u| u.1 > mid),
        "{:?}",
        c.uncertainty
    );
    // Twice the noise, twice the uncertainty.
    let c2 = calibrate(&views(&cam, 0.2, 3), &options(&cam)).unwrap();
    let ratio = c2.uncertainty[0].1 / mid;
    assert!((1.6..2.4).contains(&ratio), "{ratio}");
}
