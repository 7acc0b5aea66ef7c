use super::super::edges::{PeakScratch, Starts};
use super::*;
use crate::{EdgePoint, GreyImage};
use source::{PointBufs, ResponseBufs};

fn points(dir: ScanDir, pts: &[(f32, f32)]) -> EdgePoints {
    let mut v: Vec<EdgePoint> = pts
        .iter()
        .map(|&(x, y)| EdgePoint {
            x,
            y,
            response: 10.0,
        })
        .collect();
    v.sort_by(|a, b| a.y.total_cmp(&b.y).then(a.x.total_cmp(&b.x)));
    EdgePoints {
        dir: Some(dir),
        width: 200,
        height: 200,
        points: v,
    }
}

#[test]
fn a_drawn_line_is_extracted_in_every_steep_direction() {
    for deg in (-85..=85).step_by(5) {
        let ang = (deg as f64).to_radians();
        if ang.abs() > 1.1 {
            continue;
        }
        let slope = ang.tan();
        let pts: Vec<(f32, f32)> = (20..120)
            .map(|y| ((100.0 + slope * (y as f64 - 20.0) + 0.3) as f32, y as f32))
            .collect();
        let e = points(ScanDir::Horizontal, &pts);
        let segs = extract(&e, &LineParams::default());
        assert_eq!(segs.len(), 1, "{deg}°: {segs:?}");
        let s = segs[0];
        assert!((s.a.y - 20.0).abs() < 1e-3 && (s.b.y - 119.0).abs() < 1e-3);
        assert!(s.residual < 1e-3);
        assert!((s.response - 10.0).abs() < 1e-9);
        let pts: Vec<(f32, f32)> = pts.iter().map(|&(x, y)| (y, x)).collect();
        let e = points(ScanDir::Vertical, &pts);
        let segs = extract(&e, &LineParams::default());
        assert_eq!(segs.len(), 1, "V {deg}°");
        assert!((segs[0].a.x - 20.0).abs() < 1e-3);
    }
}

#[test]
fn gaps_short_lines_and_scan_parallel_lines() {
    // max_gap = 3: the next point may be up to 3 rows on (2 empty rows
    // bridged), not 4.
    let mut pts: Vec<(f32, f32)> = (0..20).map(|y| (50.0, y as f32)).collect();
    pts.extend((22..40).map(|y| (50.0, y as f32)));
    pts.extend((43..60).map(|y| (50.0, y as f32)));
    let segs = extract(&points(ScanDir::Horizontal, &pts), &LineParams::default());
    assert_eq!(segs.len(), 2, "{segs:?}");
    // Too short: 8 px is not > min_length.
    let pts: Vec<(f32, f32)> = (0..9).map(|y| (50.0, y as f32)).collect();
    assert!(extract(&points(ScanDir::Horizontal, &pts), &LineParams::default()).is_empty());
    // 20° from the scan direction.
    let pts: Vec<(f32, f32)> = (0..30).map(|y| (10.0 + y as f32 * 2.7, y as f32)).collect();
    let p = LineParams {
        search_width: 3.0,
        ..LineParams::default()
    };
    assert!(extract(&points(ScanDir::Horizontal, &pts), &p).is_empty());
    assert!(extract(&EdgePoints::default(), &p).is_empty());
}

/// A noisy 160 × 160 view of two dark convex polygons on a light ground (a
/// quadrilateral and a triangle: edges in six directions), each pixel the
/// mean of 4 × 4 samples, plus Gaussian noise of σ `noise` grey levels.
/// Drawn here, not by the synthetic scenes (`vss::synth`), which are
/// outside the core.
fn polygons_image(noise: f64) -> GreyImage {
    let shapes: [&[(f64, f64)]; 2] = [
        &[(22.0, 30.0), (92.0, 18.5), (104.0, 77.0), (31.0, 96.0)],
        &[(70.0, 140.0), (141.0, 96.0), (137.0, 148.0)],
    ];
    // Inside a convex polygon listed clockwise on the screen (y down):
    // left of no edge.
    let inside = |pts: &[(f64, f64)], x: f64, y: f64| {
        (0..pts.len()).all(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0) >= 0.0
        })
    };
    let mut rng = crate::rng::SplitMix64::new(9);
    let (w, h) = (160, 160);
    let mut data = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let mut dark = 0;
            for s in 0..16 {
                let (sx, sy) = (
                    x as f64 + (s % 4) as f64 / 4.0 - 0.375,
                    y as f64 + (s / 4) as f64 / 4.0 - 0.375,
                );
                dark += usize::from(shapes.iter().any(|p| inside(p, sx, sy)));
            }
            let v = 190.0 - 120.0 * dark as f64 / 16.0 + noise * rng.gauss();
            data.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    GreyImage::new(w, h, data).expect("160 × 160")
}

/// [`polygons_image`]'s horizontal or vertical response, noise map and peak
/// map at the tracking threshold.
fn scene_parts(
    dir: ScanDir,
    noise: f64,
) -> (
    crate::edges::Response,
    NoiseMap,
    PeakMap,
    EdgePoints,
    Starts,
) {
    use crate::edges::{ResponseScratch, detect_into, response_into};
    let img = polygons_image(noise);
    let mut r = crate::edges::Response::default();
    response_into(&img, dir, 4, &mut r, &mut ResponseScratch::default()).unwrap();
    let p = crate::Params::default();
    let (mut nm, mut map, mut seeds, mut starts) = (
        NoiseMap::default(),
        PeakMap::default(),
        EdgePoints::default(),
        Starts::new(),
    );
    let mut ps = PeakScratch::default();
    detect_into(
        &r,
        &p.edges,
        p.lines.track_sigmas,
        &mut nm,
        &mut map,
        &mut seeds,
        &mut starts,
        &mut ps,
    );
    (r, nm, map, seeds, starts)
}

/// The plain reference of the pipeline's extractor: every peak of the
/// peak map listed as an edge point (with its noise sigmas) and tracked
/// through the point source, from the same starts. It must give the same
/// segments, bit for bit, as reading the peaks from the response where the
/// tracks look.
#[test]
fn reading_peaks_where_tracks_look_equals_listing_them_all() {
    let p = LineParams::default();
    let mut kept = 0;
    for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
        for noise in [2.0, 8.0] {
            let (r, nm, map, seeds, starts) = scene_parts(dir, noise);
            let mut fast = Vec::new();
            let mut s = LineScratch::default();
            track_into(
                &r, &nm, &map, &seeds, &starts, 2.0, 4, &p, &mut fast, &mut s,
            );
            // The same from the points alone (no starts given): each
            // point's pixel found again.
            let mut again = Vec::new();
            track_into(&r, &nm, &map, &seeds, &[], 2.0, 4, &p, &mut again, &mut s);
            assert_eq!(fast, again, "{dir:?} σ {noise}");
            // Every peak of the map as a point, with the values the
            // response source gives it.
            let mut bufs = ResponseBufs::default();
            let src = ResponsePeaks::new(&r, &nm, &map, &mut bufs);
            let (w, h) = (r.width, r.height);
            let mut all = EdgePoints {
                dir: Some(dir),
                width: w,
                height: h,
                points: Vec::new(),
            };
            let mut zs = Vec::new();
            let (len_u, lines) = if dir == ScanDir::Vertical {
                (h, w)
            } else {
                (w, h)
            };
            for v in 0..lines {
                for u in 1..len_u - 1 {
                    for pos in [true, false] {
                        if let Some(c) = src.nearest(v, u as f64, 0.5, pos).filter(|c| {
                            (c.u - u as f64).abs() <= 0.5 && c.id == src_index(dir, w, u, v)
                        }) {
                            let (x, y) = if dir == ScanDir::Vertical {
                                (v as f32, c.u as f32)
                            } else {
                                (c.u as f32, v as f32)
                            };
                            all.points.push(crate::EdgePoint {
                                x,
                                y,
                                response: c.response,
                            });
                            zs.push(((x.to_bits(), y.to_bits()), c.z));
                        }
                    }
                }
            }
            src.finish(&mut bufs);
            let mut pb = PointBufs::default();
            pb.file(&all);
            // The noise sigmas, by position.
            zs.sort_by_key(|e| e.0);
            let vertical = dir == ScanDir::Vertical;
            let key_of = |u: f32, v: usize| {
                if vertical {
                    ((v as f32).to_bits(), u.to_bits())
                } else {
                    (u.to_bits(), (v as f32).to_bits())
                }
            };
            let lines_of: Vec<usize> = (0..pb.pts.len())
                .map(|i| pb.start.partition_point(|&s| s as usize <= i) - 1)
                .collect();
            for (i, f) in pb.pts.iter_mut().enumerate() {
                let key = key_of(f.u, lines_of[i]);
                let j = zs
                    .binary_search_by_key(&key, |e| e.0)
                    .expect("a listed peak");
                f.z = zs[j].1;
            }
            let mut src = pb.peaks();
            // The starts: the edge points, as point indices, in scan order.
            let mut starts = Vec::new();
            for e in &seeds.points {
                let (u, v) = if vertical { (e.y, e.x) } else { (e.x, e.y) };
                let v = (v + 0.5).floor() as usize;
                if let Some(c) = src.strongest(v, f64::from(u), 0.0, e.response > 0.0) {
                    starts.push(c);
                }
            }
            starts.sort_by(|a, b| a.v.cmp(&b.v).then(a.u.total_cmp(&b.u)));
            starts.dedup_by(|a, b| a.id == b.id);
            let starts: Vec<u64> = starts.iter().map(|c| c.id as u64).collect();
            let nfa = nfa::Nfa::new(w, h, 4, p.search_width, p.track_sigmas);
            let mut plain = Vec::new();
            let mut t = Tracks::default();
            follow(
                &mut src,
                starts.iter().copied(),
                &p,
                Some(&nfa),
                4,
                vertical,
                &mut t,
                &mut plain,
            );
            assert!(!fast.is_empty(), "{dir:?} σ {noise}");
            assert_eq!(fast, plain, "{dir:?} σ {noise}");
            kept += fast.len();
        }
    }
    assert!(kept >= 8, "{kept}");
}

/// The image index of scan position `(u, v)`.
/// A track that `too_short` rules out has no piece (no run of its
/// points) that passes `segment_of`'s length test; one it leaves has one
/// when its spread is along the scan lines.
#[test]
fn too_short_tracks_have_no_piece_long_enough() {
    let mut rng = crate::rng::SplitMix64::new(9);
    let min_length = 8.0;
    let limit = min_length * min_length * (1.0 - 1e-9);
    let (mut ruled, mut left) = (0, 0);
    for _ in 0..2000 {
        let n = 2 + (rng.next_u64() % 9) as usize;
        let spread = 12.0 * rng.uniform();
        let chain: Vec<TrackPoint> = (0..n)
            .map(|k| TrackPoint {
                u: 100.0 + spread * rng.uniform(),
                v: 50.0 + k as f64,
                ..TrackPoint::default()
            })
            .collect();
        if too_short(&chain, min_length) {
            ruled += 1;
            for a in 0..n {
                for b in a + 1..n {
                    let (du, dv) = (chain[b].u - chain[a].u, chain[b].v - chain[a].v);
                    assert!(du * du + dv * dv < limit, "{chain:?}");
                }
            }
        } else {
            left += 1;
            let long = (0..n).any(|a| {
                (a + 1..n).any(|b| {
                    let (du, dv) = (chain[b].u - chain[a].u, chain[b].v - chain[a].v);
                    du * du + dv * dv >= 0.5 * limit
                })
            });
            assert!(long, "{chain:?}");
        }
    }
    assert!(ruled > 100 && left > 100, "{ruled} {left}");
    assert!(!too_short(&[TrackPoint::default(); 3], 0.0));
}

fn src_index(dir: ScanDir, w: usize, u: usize, v: usize) -> usize {
    if dir == ScanDir::Vertical {
        u * w + v
    } else {
        v * w + u
    }
}
