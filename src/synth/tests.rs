//! Unit tests of the generator: determinism, the lighting model, visibility
//! and the true edges against the rendered pixels.

use super::*;
use crate::llv::Segment;

fn one_cube() -> (Scene, Camera, Vec<PointLight>) {
    let scene = Scene {
        objects: vec![Polyhedron::cuboid(
            "cube",
            [0.0, 0.0, 0.0],
            [80.0, 80.0, 80.0],
            0.4,
            200.0,
        )],
        plate: Some(Polyhedron::cuboid(
            "plate",
            [0.0, 0.0, -10.0],
            [3000.0, 3000.0, 10.0],
            0.0,
            70.0,
        )),
        background: 10.0,
    };
    let cams = cell_cameras(256, 256);
    let mut cam = cams[0].clone();
    cam.pose = look_at([300.0, -350.0, 400.0], [0.0, 0.0, 40.0]);
    let lights = vec![PointLight {
        position: [800.0, -800.0, 900.0],
        intensity: 0.9,
    }];
    (scene, cam, lights)
}

#[test]
fn rendering_is_deterministic_and_seeded() {
    let (s, c, l) = one_cube();
    let o = RenderOptions {
        noise_sigma: 5.0,
        seed: 3,
        ..Default::default()
    };
    let a = render(&s, &c, &l, &o);
    assert_eq!(a, render(&s, &c, &l, &o));
    let b = render(&s, &c, &l, &RenderOptions { seed: 4, ..o });
    assert_ne!(a, b);
}

#[test]
fn without_lights_the_image_is_dim_and_flat_per_surface() {
    let (s, c, _) = one_cube();
    let o = RenderOptions {
        blur_sigma: 0.0,
        ..Default::default()
    };
    let img = render(&s, &c, &[], &o);
    // Only ambient: cube 200·0.2 = 40, plate 70·0.2 = 14.
    let max = img.data().iter().copied().max().unwrap_or(0);
    assert!(max <= 40, "max {max}");
    let lit = render(&s, &c, &one_cube().2, &o);
    let sum = |g: &GreyImage| g.data().iter().map(|&v| v as u64).sum::<u64>();
    assert!(sum(&lit) > 2 * sum(&img));
}

#[test]
fn an_edge_lit_equally_from_both_faces_vanishes() {
    // A light straight above the cube's vertical edge bisects the two side
    // faces meeting there: under it they are equally bright.
    let cube = Polyhedron::cuboid("c", [0.0, 0.0, 0.0], [80.0, 80.0, 80.0], 0.0, 200.0);
    let scene = Scene {
        objects: vec![cube],
        plate: None,
        background: 0.0,
    };
    let (_, cam0, _) = one_cube();
    let cam = Camera {
        pose: look_at([-400.0, -400.0, 300.0], [0.0, 0.0, 40.0]),
        ..cam0
    };
    let sym = vec![PointLight {
        position: [-800.0, -800.0, 500.0],
        intensity: 1.0,
    }];
    let o = RenderOptions::default();
    let edges = true_edges(&scene, &cam, &sym, &o, 1.0);
    // The edge from (-40,-40,0) to (-40,-40,80) faces the camera head-on.
    let a = cam.project([-40.0, -40.0, 5.0]).unwrap();
    let b = cam.project([-40.0, -40.0, 75.0]).unwrap();
    let near = |e: &Segment| score::line_distance(e, a) < 0.5 && score::line_distance(e, b) < 0.5;
    assert!(!edges.iter().any(near), "the bisected edge should vanish");
    // Under a light off to one side it is there.
    let side = vec![PointLight {
        position: [-900.0, -300.0, 500.0],
        intensity: 1.0,
    }];
    let edges = true_edges(&scene, &cam, &side, &o, 1.0);
    assert!(edges.iter().any(near));
}

#[test]
fn true_edges_sit_where_the_image_changes() {
    let (s, c, l) = one_cube();
    let o = RenderOptions {
        blur_sigma: 0.0,
        ..Default::default()
    };
    let img = render(&s, &c, &l, &o);
    let edges = true_edges(&s, &c, &l, &o, 10.0);
    // A cube seen from above-diagonal shows 9 edges.
    assert_eq!(edges.len(), 9, "{edges:?}");
    for e in &edges {
        // Midpoint: 2 px to each side the grey levels differ by the contrast.
        let m = Point::new(0.5 * (e.a.x + e.b.x), 0.5 * (e.a.y + e.b.y));
        let l = e.length();
        let (nx, ny) = (-(e.b.y - e.a.y) / l, (e.b.x - e.a.x) / l);
        let px = |x: f64, y: f64| img.get(x.round() as usize, y.round() as usize).unwrap() as f64;
        let d = (px(m.x + 2.0 * nx, m.y + 2.0 * ny) - px(m.x - 2.0 * nx, m.y - 2.0 * ny)).abs();
        assert!(
            (d - e.response).abs() < 0.15 * e.response + 3.0,
            "{e:?}: {d}"
        );
    }
    let corners = visible_corners(&s, &c, &l, &o, 10.0);
    assert_eq!(corners.len(), 7, "{corners:?}");
}

#[test]
fn anti_aliasing_puts_an_edge_at_its_subpixel_place() {
    // A vertical silhouette edge: the grey level of the pixel it crosses is
    // the area-weighted mix of the two sides.
    // Ambient light only, so each face is uniformly bright.
    let (s, c, _) = one_cube();
    let o = RenderOptions {
        blur_sigma: 0.0,
        ambient: 1.0,
        ..Default::default()
    };
    let exact = render_exact(&s, &c, &[], &o);
    let edges = true_edges(&s, &c, &[], &o, 10.0);
    let e = edges
        .iter()
        .find(|e| (e.b.x - e.a.x).abs() < 0.3 * e.length())
        .expect("a steep edge");
    // Walk a row through its middle: the total "excess" over the left value
    // divided by the step locates the edge within 0.02 px.
    let y = (0.5 * (e.a.y + e.b.y)).round();
    let t = (y - e.a.y) / (e.b.y - e.a.y);
    let xe = e.a.x + t * (e.b.x - e.a.x);
    let x0 = xe.floor() as usize - 3;
    let row = |x: usize| exact[y as usize * c.width + x];
    let (left, right) = (row(x0), row(x0 + 7));
    let mut area = 0.0;
    for x in x0..=x0 + 7 {
        area += (row(x) - left) / (right - left);
    }
    // Pixels x0..x0+7 cover [x0-0.5, x0+7.5]; the right side's share is the
    // distance from the edge to the right border.
    let est = x0 as f64 + 7.5 - area;
    assert!((est - xe).abs() < 0.01, "edge at {xe}, area says {est}");
}

#[test]
fn distortion_moves_corners_by_a_few_pixels() {
    for cam in cell_cameras(512, 512) {
        let (x, y) = cam.model.ideal_to_observed(0.0, 0.0);
        let moved = (x).hypot(y);
        assert!((1.0..3.0).contains(&moved), "{moved}");
    }
}

#[test]
fn every_cell_light_brightens_every_camera() {
    let scene = cell_scene();
    let lights = cell_lights();
    let o = RenderOptions {
        distort: true,
        ..Default::default()
    };
    for cam in cell_cameras(96, 96) {
        let dark: f64 = render_exact(&scene, &cam, &[], &o).iter().sum();
        for l in &lights {
            let lit: f64 = render_exact(&scene, &cam, std::slice::from_ref(l), &o)
                .iter()
                .sum();
            assert!(lit > 1.5 * dark, "{lit} vs {dark}");
        }
    }
}

#[test]
fn odd_cameras_give_images_not_panics() {
    let (s, c, l) = one_cube();
    let o = RenderOptions {
        noise_sigma: 3.0,
        distort: true,
        ..Default::default()
    };
    // Zero size: a 1 × 1 image.
    let zero = Camera {
        width: 0,
        height: 0,
        ..c.clone()
    };
    assert_eq!(render(&s, &zero, &l, &o).size(), (1, 1));
    assert!(true_edges(&s, &zero, &l, &o, 10.0).is_empty());
    // Degenerate intrinsics (f = 0, sx = 0) and a camera inside the cube.
    let mut flat = c.clone();
    flat.model.f = 0.0;
    flat.model.sx = 0.0;
    let inside = Camera {
        pose: look_at([0.0, 0.0, 40.0], [100.0, 0.0, 40.0]),
        ..c.clone()
    };
    for cam in [flat, inside] {
        let img = render(&s, &cam, &l, &o);
        assert_eq!(img.size(), (cam.width, cam.height));
        let _ = true_edges(&s, &cam, &l, &o, 10.0);
        let _ = visible_corners(&s, &cam, &l, &o, 10.0);
    }
    // An empty scene is the background, plus noise.
    let empty = Scene {
        objects: vec![],
        plate: None,
        background: 50.0,
    };
    let img = render(&empty, &c, &[], &RenderOptions::default());
    assert!(img.data().iter().all(|&v| v == 50));
}

#[test]
fn test_scenes_repeat_and_keep_their_promises() {
    let a = test_scenes(6, 384, 384, 3);
    assert_eq!(a, test_scenes(6, 384, 384, 3));
    assert_ne!(a, test_scenes(6, 384, 384, 4));
    let o = RenderOptions::default();
    for (scene, cam, lights) in &a {
        assert!(!scene.objects.is_empty() && scene.objects.len() <= 6);
        let edges = true_edges(scene, cam, lights, &o, 4.0);
        let long: Vec<&Segment> = edges.iter().filter(|e| e.length() >= 10.0).collect();
        assert!(long.len() >= 5, "{} edges", long.len());
        for e in &long {
            assert!(e.response >= 30.0, "weak edge {e:?}");
        }
        // The objects fill a good part of the frame: their edges span at
        // least half of it one way or the other.
        let (mut lo, mut hi) = (Point::new(1e9, 1e9), Point::new(-1e9, -1e9));
        for e in &long {
            for p in [e.a, e.b] {
                lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
                hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
            }
        }
        assert!((hi.x - lo.x).max(hi.y - lo.y) > 0.5 * 384.0);
    }
}
