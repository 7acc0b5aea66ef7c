//! Several lightings on the yard family, the hold-out the engine is not
//! tuned on: each scene's defocused render lit three ways as
//! `real::three_exposures_…` lights the photographs (dimmed to 70 %; a
//! shadow to 35 % over its left half through a ramp a fifth of the width
//! wide; the same from the right), each lit image a new exposure with noise
//! of its own. The goal: the combination (`llv::photometric`) at
//! least as good as the best single image in recall and F, the best chosen
//! afterwards for each scene. Printed by `cargo test --test accuracy
//! lightings:: -- --nocapture`.

use super::{default_params, lighting_gain};
use vss::llv::pipeline::{Input, run};
use vss::llv::rng::mix;
use vss::llv::{GreyImage, Segment};
use vss::synth::eval::yard::{YardConfig, yard_cases};
use vss::synth::yard::YardNoise;
use vss::synth::{Metrics, Tally};

/// Best single (chosen per scene), combined, and each lighting alone.
fn yard_lightings(noise: YardNoise) -> (Metrics, Metrics, [Metrics; 3]) {
    let cfg = YardConfig {
        scenes: 6,
        size: 512,
        seed: 1,
        ..Default::default()
    };
    let p = default_params();
    let (mut best, mut combined) = (Tally::default(), Tally::default());
    let mut singles: [Tally; 3] = Default::default();
    for (k, c) in yard_cases(&cfg).iter().enumerate() {
        let (w, h) = (c.scene.width, c.scene.height);
        let lit: Vec<GreyImage> = (0..3)
            .map(|l| {
                let v: Vec<f64> = (0..w * h)
                    .map(|i| c.blurred[i] * lighting_gain(l, w, i % w))
                    .collect();
                c.scene
                    .expose(&v, noise, mix(k as u64, 0x11_0000 + l as u64))
            })
            .collect();
        let lines = |imgs: &[GreyImage]| -> Vec<Segment> {
            let input = Input {
                images: imgs,
                ambient: None,
                lens: None,
            };
            run(&input, &p).unwrap().lines
        };
        let (truth, dc) = (&c.truth.edges, &c.truth.dont_care);
        let score = |l: &[Segment]| {
            let mut t = Tally::default();
            t.add_with(l, truth, dc);
            t.metrics().f_score()
        };
        let alone: Vec<Vec<Segment>> = lit.iter().map(|i| lines(std::slice::from_ref(i))).collect();
        for (t, l) in singles.iter_mut().zip(&alone) {
            t.add_with(l, truth, dc);
        }
        let top = alone
            .iter()
            .max_by(|a, b| score(a).total_cmp(&score(b)))
            .unwrap();
        best.add_with(top, truth, dc);
        combined.add_with(&lines(&lit), truth, dc);
    }
    let out = (
        best.metrics(),
        combined.metrics(),
        singles.map(|t| t.metrics()),
    );
    let rf = |m: &Metrics| {
        format!(
            "R {:.4} P {:.4} F {:.4}",
            m.recall,
            m.precision,
            m.f_score()
        )
    };
    eprintln!(
        "yard, three lightings, {noise:?} each: best single {}; combined {}; each alone {} / {} / {}",
        rf(&out.0),
        rf(&out.1),
        rf(&out.2[0]),
        rf(&out.2[1]),
        rf(&out.2[2])
    );
    out
}

fn at_least_the_best_single(noise: YardNoise) {
    let (best, combined, _) = yard_lightings(noise);
    assert!(
        combined.recall >= best.recall && combined.f_score() >= best.f_score(),
        "combined R {:.4} F {:.4} against the best single's R {:.4} F {:.4}",
        combined.recall,
        combined.f_score(),
        best.recall,
        best.f_score()
    );
}

#[test]
fn yard_three_exposures_at_noise_2_combine_above_the_best_single() {
    at_least_the_best_single(YardNoise::Gauss(2.0));
}

#[test]
fn yard_three_exposures_at_noise_5_combine_above_the_best_single() {
    at_least_the_best_single(YardNoise::Gauss(5.0));
}
