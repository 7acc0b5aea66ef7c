//! End-to-end accuracy of the LLV pipeline on drawn straight edges: a
//! straight edge at any angle gives one line, on the edge, in its direction.

use vss::llv::pipeline::{Input, run};
use vss::llv::{GreyImage, Params, Point, Segment};

/// A `w × h` image split by the line through `c` with direction angle `deg`
/// (llv.md §0 convention), `lo` on one side and `hi` on the other, area
/// sampled (8 × 8 per pixel) so the edge is anti-aliased.
fn half_plane(w: usize, h: usize, c: Point, deg: f64, lo: f64, hi: f64) -> GreyImage {
    let (s, co) = deg.to_radians().sin_cos();
    // Direction in image coordinates (y down): (cos, -sin); normal (sin, cos).
    let (nx, ny) = (s, co);
    let mut d = Vec::with_capacity(w * h);
    const N: usize = 8;
    for y in 0..h {
        for x in 0..w {
            let mut inside = 0;
            for sy in 0..N {
                for sx in 0..N {
                    let px = x as f64 - 0.5 + (sx as f64 + 0.5) / N as f64;
                    let py = y as f64 - 0.5 + (sy as f64 + 0.5) / N as f64;
                    inside += usize::from((px - c.x) * nx + (py - c.y) * ny > 0.0);
                }
            }
            let f = inside as f64 / (N * N) as f64;
            d.push((lo + (hi - lo) * f).round() as u8);
        }
    }
    GreyImage::new(w, h, d).unwrap()
}

fn dist_to_line(p: Point, c: Point, deg: f64) -> f64 {
    let (s, co) = deg.to_radians().sin_cos();
    ((p.x - c.x) * s + (p.y - c.y) * co).abs()
}

fn angle_err_deg(l: &Segment, deg: f64) -> f64 {
    let d = (l.angle().to_degrees() - deg).rem_euclid(180.0);
    d.min(180.0 - d)
}

#[test]
fn a_straight_edge_at_any_angle_gives_one_accurate_line() {
    let c = Point::new(64.3, 63.8);
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..72 {
        let deg = k as f64 * 2.5 + 0.7;
        let img = half_plane(128, 128, c, deg, 50.0, 170.0);
        let out = run(&Input::single(&img), &Params::default()).unwrap();
        let long: Vec<&Segment> = out.lines.iter().filter(|l| l.length() > 20.0).collect();
        assert_eq!(long.len(), 1, "edge at {deg}°: {:#?}", out.lines);
        let l = long[0];
        assert!(
            l.length() > 90.0,
            "edge at {deg}°: only {:.1} px",
            l.length()
        );
        let e = dist_to_line(l.a, c, deg).max(dist_to_line(l.b, c, deg));
        let a = angle_err_deg(l, deg);
        worst = (worst.0.max(e), worst.1.max(a));
        assert!(e < 0.1, "edge at {deg}°: endpoint {e:.3} px off");
        assert!(a < 0.1, "edge at {deg}°: angle {a:.3}° off");
    }
    eprintln!(
        "worst endpoint {:.4} px, worst angle {:.4}°",
        worst.0, worst.1
    );
}

use crate::support::llv_scene;

#[test]
fn the_benchmark_scene_gives_its_polygon_edges() {
    let img = llv_scene::scene(512, 512, 2.0, 7);
    let out = run(&Input::single(&img), &Params::default()).unwrap();
    eprintln!(
        "edges {} + {}, raw {}, lines {}, {:?}",
        out.edges_h.points.len(),
        out.edges_v.points.len(),
        out.lines_raw.len(),
        out.lines.len(),
        out.timings
    );
    let long = out.lines.iter().filter(|l| l.length() > 40.0).count();
    assert!((20..=40).contains(&long), "{long} long lines");
}
