//! The accuracy floors on real photographs: the 51 York Urban photographs
//! of `../shared/data/yud-tune` (the tuning half; Cho et al.'s ground
//! truth), scored by the rule of that folder's README
//! (`vss::llv::synth::real`: 2 px, 5°, length-based, pooled), with the
//! default profile's parameters (tuned on these photographs,
//! docs/accuracy.md). Each floor is within 0.01 of what the engine
//! measures. A missing folder fails: the floors are only worth anything
//! when they run.

use std::path::PathBuf;
use std::sync::OnceLock;

use super::default_params;
use vss::llv::synth::real::{RealEvaluation, evaluate_real, photographs};

fn folder() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/yud-tune")
}

type Scores = RealEvaluation;

fn scores() -> &'static Scores {
    static SCORES: OnceLock<Scores> = OnceLock::new();
    SCORES.get_or_init(|| {
        let dir = folder();
        match evaluate_real(&dir, &default_params()) {
            Ok(s) => s,
            Err(e) => panic!(
                "the real photographs could not be scored ({}): {e}",
                dir.display()
            ),
        }
    })
}

#[test]
fn the_tune_set_is_all_there() {
    let list = match photographs(&folder()) {
        Ok(l) => l,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(list.len(), 51, "{} photographs", list.len());
}

#[test]
fn york_urban_tune_f_recall_precision() {
    let (m, each, _) = scores();
    let s = format!(
        "{} photographs: precision {:.4}, recall {:.4}, F {:.4} ({} segments)",
        m.images, m.precision, m.recall, m.f, m.segments
    );
    eprintln!("{s}");
    assert_eq!(each.len(), 51, "{s}");
    // Above every peer on this set (EDLines 0.721, ELSED 0.715, FLD 0.713,
    // pytlsd 0.704, LSD 0.703: the README there, reproduced by the scorer).
    assert!(m.f > 0.721, "{s}");
    assert!(m.f >= F, "{s}");
    assert!(m.recall >= RECALL, "{s}");
    assert!(m.precision >= PRECISION, "{s}");
}

/// The floors: within 0.01 of what the engine measures (`cargo test
/// --test accuracy real:: -- --nocapture` prints it).
const F: f64 = 0.726;
const RECALL: f64 = 0.722;
const PRECISION: f64 = 0.730;

/// Recall by the true lines' contrast (the breakdown): floors
/// within 0.01 of what the engine measures, printed by `cargo test --test
/// accuracy real:: -- --nocapture`.
#[test]
fn york_urban_tune_recall_by_contrast() {
    let (_, _, c) = scores();
    let r = c.recall();
    eprintln!("recall by contrast (< 10, 10-20, 20-40, >= 40 grey levels): {r:?}");
    for (i, floor) in BY_CONTRAST.iter().enumerate() {
        let got = r[i].unwrap_or(0.0);
        assert!(got >= *floor, "class {i}: recall {got:.4} (floor {floor})");
    }
}

const BY_CONTRAST: [f64; 4] = [0.540, 0.638, 0.753, 0.836];
