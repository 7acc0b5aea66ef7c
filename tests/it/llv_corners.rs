//! Corner closing measured on synthetic scenes (llv.md §6, several lightings): twelve
//! seeded scenes under their own lights with noise σ = 5, through the
//! pipeline with `connect.corner_radius` 0 (off) and on. Measured:
//! - endpoint→corner: the mean distance from the nearest true corner of the
//!   line endpoints within [`CAP`] px of one — what corner closing is for;
//! - corner→nearest endpoint (reported, not asserted): for every true corner
//!   the distance to its nearest endpoint, capped at [`CAP`]. Closing moves
//!   every endpoint of a corner to the lines' intersection, which is only as
//!   good as the lines: a single endpoint that happened to sit on the corner
//!   can move off it while the corner's other endpoints come much closer;
//! - precision and recall of the lines (synth's matching rule).
//!
//! `cargo test --test it llv_corners:: -- --nocapture` prints the figures.

use vss::llv::pipeline::{self, Input};
use vss::llv::{GreyImage, Params, Point, Segment};
use vss::synth::{self, RenderOptions};

const SCENES: usize = 12;
const SIZE: usize = 320;
/// Largest corner gap counted (px).
const CAP: f64 = 10.0;
/// The radius proposed as the default `connect.corner_radius` (px).
const PROPOSED_RADIUS: f64 = 5.0;

struct Scene {
    image: GreyImage,
    truth: Vec<Segment>,
    corners: Vec<Point>,
}

fn scenes() -> Vec<Scene> {
    synth::test_scenes(SCENES, SIZE, SIZE, 0xC0C0)
        .into_iter()
        .enumerate()
        .map(|(k, (scene, cam, lights))| {
            let o = RenderOptions {
                noise_sigma: 5.0,
                seed: 77 + k as u64,
                ..RenderOptions::default()
            };
            let clean = RenderOptions::default();
            Scene {
                image: synth::render(&scene, &cam, &lights, &o),
                truth: synth::true_edges(&scene, &cam, &lights, &clean, 10.0),
                corners: synth::visible_corners(&scene, &cam, &lights, &clean, 10.0),
            }
        })
        .collect()
}

/// Mean over true corners of the capped distance to the nearest endpoint.
fn corner_gap(lines: &[Segment], corners: &[Point]) -> (f64, usize) {
    let sum: f64 = corners
        .iter()
        .map(|c| {
            lines
                .iter()
                .flat_map(|l| [l.a, l.b])
                .map(|e| e.dist(*c))
                .fold(CAP, f64::min)
        })
        .sum();
    (sum, corners.len())
}

/// Mean distance to the nearest true corner of the endpoints within CAP of one.
fn endpoint_gap(lines: &[Segment], corners: &[Point]) -> (f64, usize) {
    let d: Vec<f64> = lines
        .iter()
        .flat_map(|l| [l.a, l.b])
        .map(|e| {
            corners
                .iter()
                .map(|c| e.dist(*c))
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|&d| d < CAP)
        .collect();
    (d.iter().sum(), d.len())
}

struct Measured {
    endpoint_gap: f64,
    endpoints: usize,
    corner_gap: f64,
    precision: f64,
    recall: f64,
}

impl std::fmt::Display for Measured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "endpoint→corner {:.2} px ({} endpoints)  corner→nearest endpoint {:.2} px  precision {:.3}  recall {:.3}",
            self.endpoint_gap, self.endpoints, self.corner_gap, self.precision, self.recall
        )
    }
}

/// The figures over all scenes for one radius.
fn measure(scenes: &[Scene], radius: f64) -> Measured {
    let mut p = Params::default();
    p.connect.corner_radius = radius;
    let mut tally = synth::Tally::default();
    let (mut gap, mut n) = (0.0, 0usize);
    let (mut egap, mut en) = (0.0, 0usize);
    for s in scenes {
        let input = Input {
            images: std::slice::from_ref(&s.image),
            ambient: None,
            lens: None,
        };
        let out = pipeline::run(&input, &p).unwrap();
        tally.add(&out.lines, &s.truth);
        let (g, k) = corner_gap(&out.lines, &s.corners);
        gap += g;
        n += k;
        let (g, k) = endpoint_gap(&out.lines, &s.corners);
        egap += g;
        en += k;
    }
    let m = tally.metrics();
    Measured {
        endpoint_gap: egap / en.max(1) as f64,
        endpoints: en,
        corner_gap: gap / n.max(1) as f64,
        precision: m.precision,
        recall: m.recall,
    }
}

/// Off and at the proposed radius, measured once for both tests.
fn off_and_on() -> &'static (Measured, Measured) {
    static FIGURES: std::sync::OnceLock<(Measured, Measured)> = std::sync::OnceLock::new();
    FIGURES.get_or_init(|| {
        let scenes = scenes();
        assert!(scenes.iter().map(|s| s.corners.len()).sum::<usize>() >= 30);
        let off = measure(&scenes, 0.0);
        eprintln!("radius off: {off}");
        for r in [3.0, 4.0, 6.0, 8.0] {
            eprintln!("radius {r:>3}: {}", measure(&scenes, r));
        }
        let on = measure(&scenes, PROPOSED_RADIUS);
        eprintln!("radius {PROPOSED_RADIUS:>3}: {on}");
        (off, on)
    })
}

#[test]
fn corner_closing_loses_no_precision_or_recall() {
    let (off, on) = off_and_on();
    assert!(
        on.precision >= off.precision,
        "precision {:.3} vs {:.3}",
        on.precision,
        off.precision
    );
    assert!(
        on.recall >= off.recall - 0.002,
        "recall {:.3} vs {:.3}",
        on.recall,
        off.recall
    );
}

/// With the current extractor many endpoints near corners belong to lines
/// that ran through a shallow corner (the gain is 3 %: 3.03 → 2.93 px); with
/// its stray-point check the gain is 17 % (2.63 → 2.19 px).
#[test]
fn corner_closing_brings_endpoints_to_the_corners() {
    let (off, on) = off_and_on();
    assert!(
        on.endpoint_gap < 0.9 * off.endpoint_gap,
        "endpoints {:.2} px from corners vs {:.2} px off",
        on.endpoint_gap,
        off.endpoint_gap
    );
}
