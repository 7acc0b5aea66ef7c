use super::*;
use crate::ScanDir;
use crate::edges::{PeakMap, PeakScratch, Starts, detect_into, response};
use crate::image::GreyImage;
use crate::params::Params;

/// A bright square on a dark ground, anti-aliased by 4 × 4 supersampling
/// (the pipeline's tests use it too).
pub(crate) fn square(w: usize, h: usize) -> GreyImage {
    let (x0, y0, x1, y1) = (
        w as f64 * 0.3 + 0.3,
        h as f64 * 0.25 + 0.1,
        w as f64 * 0.7,
        h as f64 * 0.75 - 0.2,
    );
    let mut d = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let mut c = 0;
            for sy in 0..4 {
                for sx in 0..4 {
                    let px = x as f64 - 0.5 + (sx as f64 + 0.5) / 4.0;
                    let py = y as f64 - 0.5 + (sy as f64 + 0.5) / 4.0;
                    c += u32::from(px >= x0 && px < x1 && py >= y0 && py < y1);
                }
            }
            d.push((40 + c * 150 / 16) as u8);
        }
    }
    GreyImage::new(w, h, d).unwrap()
}

/// The drawn segments of an image, before CONNECT.
fn drawn(img: &GreyImage, p: &Params) -> Vec<Segment> {
    let a = p.edges.half_width as usize;
    let mut dirs = Vec::new();
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        let r = response(img, dir, a).unwrap();
        let (mut noise, mut map) = (NoiseMap::default(), PeakMap::default());
        let (mut pts, mut starts) = (crate::EdgePoints::default(), Starts::new());
        let mut ps = PeakScratch::default();
        let t = p.lines.track_sigmas;
        detect_into(
            &r,
            &p.edges,
            t,
            &mut noise,
            &mut map,
            &mut pts,
            &mut starts,
            &mut ps,
        );
        dirs.push((r, noise, map, starts));
    }
    let d = |k: usize| DrawDir {
        resp: &dirs[k].0,
        noise: &dirs[k].1,
        starts: &dirs[k].3,
    };
    let mut out = Vec::new();
    let mut s = DrawScratch::default();
    draw_into(
        d(0),
        d(1),
        p.edges.floor,
        (a, false),
        &p.lines,
        &mut out,
        &mut s,
    );
    out
}

/// Each side of the square is drawn as one segment along it, before
/// CONNECT, and nothing else is.
#[test]
fn the_sides_of_a_square_are_drawn() {
    let img = square(128, 128);
    let segs = drawn(&img, &Params::default());
    let (x0, y0, x1, y1) = (38.7, 32.1, 89.6, 95.8);
    let sides = [
        ((x0, y0), (x0, y1)),
        ((x1, y0), (x1, y1)),
        ((x0, y0), (x1, y0)),
        ((x0, y1), (x1, y1)),
    ];
    for (a, b) in sides {
        let on = |q: crate::Point| {
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            ((q.x - a.0) * dy - (q.y - a.1) * dx).abs() / dx.hypot(dy) < 0.3
        };
        assert!(
            segs.iter().any(|s| on(s.a) && on(s.b) && s.length() > 40.0),
            "side {a:?}–{b:?} not drawn: {segs:#?}"
        );
    }
    assert!(segs.len() <= 8, "{segs:#?}");
}

/// A chain that turns by 45° is cut where it turns.
#[test]
fn a_bent_chain_is_cut_at_the_bend() {
    let pt = |u: f64, v: f64| TrackPoint {
        u,
        v,
        ..TrackPoint::default()
    };
    let chain: Vec<TrackPoint> = (0..40)
        .map(|v| {
            let v = f64::from(v);
            pt(if v < 20.0 { 10.0 } else { 10.0 + (v - 20.0) }, v)
        })
        .collect();
    let mut cuts = Vec::new();
    cut(&chain, false, &mut cuts);
    assert_eq!(cuts.len(), 2, "{cuts:?}");
    assert!((20..=23).contains(&cuts[0].end), "{cuts:?}");
    let mut straight = Vec::new();
    cut(&chain[..20], false, &mut straight);
    assert_eq!(straight, vec![0..20]);
}
