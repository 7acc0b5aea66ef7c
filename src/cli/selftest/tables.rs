//! `vss selftest`'s tables for people: the cube family's (subpixel and
//! whole-pixel rows, lens straightness), the yard family's (breakdowns,
//! lens check by F) and the comparison of detectors from `--score`.

use std::fmt::Write;

use crate::synth::Metrics;
use crate::synth::compare::FamilyScores;
use crate::synth::eval::EvalReport;
use crate::synth::eval::yard::YardReport;

/// The breakdown columns' header: strong recall, close recall, off-angle.
const BREAKDOWN: &str = "strong R close R off-angle";

/// The three breakdowns; "—" where there is nothing to measure (no strong
/// edges, no close pairs: the cube scenes keep edges 8 px apart).
fn breakdown(m: &Metrics) -> String {
    let frac = |v: f64, len: f64| {
        if len > 0.0 {
            format!("{v:.3}")
        } else {
            "—".into()
        }
    };
    format!(
        "{:>8} {:>7} {:>8.2} %",
        frac(m.recall_strong, m.strong_length),
        frac(m.recall_close, m.close_length),
        100.0 * m.off_angle
    )
}

/// Recall, precision, F, endpoint mean / p95, angle and the breakdowns.
fn scores(m: &Metrics) -> String {
    format!(
        "{:>6.3} {:>9.3} {:>6.3}  {:>6.3} / {:<5.3}  {:>7.3}  {}",
        m.recall,
        m.precision,
        m.f_score(),
        m.endpoint_mean,
        m.endpoint_p95,
        m.angle_mean_deg,
        breakdown(m)
    )
}

/// The cube family's report as a table.
pub fn table(r: &EvalReport, profile: &str) -> String {
    let c = &r.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "cubes: {} scenes of {}×{} px, blur σ = {}, seed {}, profile {profile}; true edges: contrast ≥ {} grey levels, fainter ones don't-care",
        c.scenes, c.size, c.size, c.blur, c.seed, c.min_contrast
    );
    let _ = writeln!(
        s,
        "{:>6}  {:<11} {:>6} {:>9} {:>6}  {:>13}  {:>7}  {BREAKDOWN}  {:>6} {:>6}",
        "noise",
        "positions",
        "recall",
        "precision",
        "F",
        "endpoint px",
        "angle °",
        "points",
        "lines"
    );
    for l in &r.levels {
        for (name, m) in [("subpixel", &l.subpixel), ("whole-pixel", &l.whole_pixel)] {
            let _ = writeln!(
                s,
                "{:>6}  {:<11} {}  {:>6.0} {:>6.1}",
                l.noise,
                name,
                scores(m),
                l.edge_points,
                l.lines
            );
        }
    }
    for l in &r.levels {
        let _ = writeln!(
            s,
            "noise {}: edge points lie {:.3} px (RMS) from their true edges with subpixel positions, {:.3} px with whole pixels",
            l.noise, l.point_rms_subpixel, l.point_rms_whole_pixel
        );
    }
    let lr = &r.lens;
    let rel = |a: f64, b: f64| if b > 0.0 { 100.0 * (a / b - 1.0) } else { 0.0 };
    let _ = writeln!(
        s,
        "lens (noise σ = {}): mean line-fit residual {:.4} px undistorted, {:.4} px distorted, {:.4} px corrected ({:+.1} %)",
        c.lens_noise,
        lr.residual_undistorted,
        lr.residual_distorted,
        lr.residual_corrected,
        rel(lr.residual_corrected, lr.residual_undistorted)
    );
    let _ = writeln!(
        s,
        "lens (distortion ×{}): edge-point straightness {:.4} px undistorted, {:.4} px distorted, {:.4} px corrected ({:+.1} %, {} edges)",
        c.lens_scale,
        lr.straightness_undistorted,
        lr.straightness_distorted,
        lr.straightness_corrected,
        rel(lr.straightness_corrected, lr.straightness_undistorted),
        lr.straightness_edges
    );
    let _ = writeln!(
        s,
        "lens: endpoint mean {:.3} px and angle {:.3}° corrected, {:.3} px and {:.3}° uncorrected",
        lr.corrected.endpoint_mean,
        lr.corrected.angle_mean_deg,
        lr.uncorrected.endpoint_mean,
        lr.uncorrected.angle_mean_deg
    );
    s
}

/// The yard family's report as a table.
pub fn yard_table(r: &YardReport, profile: &str) -> String {
    let c = &r.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "yard: {} scenes of {}×{} px (welding-yard parts, defocus σ 0.7–1.5), seed {}, profile {profile}; true edges: contrast ≥ {} grey levels, fainter ones and the 8-px border band don't-care",
        c.scenes, c.size, c.size, c.seed, c.min_contrast
    );
    let _ = writeln!(
        s,
        "{:>6}  {:>6} {:>9} {:>6}  {:>13}  {:>7}  {BREAKDOWN}  {:>6} {:>6}",
        "noise", "recall", "precision", "F", "endpoint px", "angle °", "points", "lines"
    );
    for l in &r.levels {
        let m = &l.metrics;
        let _ = writeln!(
            s,
            "{:>6}  {}  {:>6.0} {:>6.1}",
            l.noise.to_string(),
            scores(m),
            l.edge_points,
            l.lines
        );
    }
    for lr in &r.lens {
        let _ = writeln!(
            s,
            "lens (noise {}, each scene through its own lens): F {:.4} undistorted, {:.4} distorted and corrected with its .cdf ({:+.4}), {:.4} uncorrected",
            lr.noise,
            lr.undistorted.f_score(),
            lr.corrected.f_score(),
            lr.f_difference,
            lr.uncorrected.f_score()
        );
    }
    s
}

fn ms(v: Option<f64>) -> String {
    v.map_or_else(|| "—".to_string(), |t| format!("{t:.3}"))
}

/// Every detector's scores, one table per family and noise level.
pub fn compare_table(families: &[FamilyScores]) -> String {
    let mut s = String::new();
    for fam in families {
        for l in &fam.levels {
            let _ = writeln!(
                s,
                "{}, noise {} ({} scenes of {}×{} px)",
                fam.name, l.level, fam.scenes, fam.size, fam.size
            );
            let _ = writeln!(
                s,
                "  {:<10} {:>6} {:>6} {:>9}  {:>13}  {:>7}  {BREAKDOWN}  {:>18}",
                "detector",
                "F",
                "recall",
                "precision",
                "endpoint px",
                "angle °",
                "ms fastest / median"
            );
            for d in &l.detectors {
                let m = &d.metrics;
                let _ = writeln!(
                    s,
                    "  {:<10} {:>6.3} {:>6.3} {:>9.3}  {:>6.3} / {:<5.3}  {:>7.3}  {}  {:>8} / {:<8}",
                    d.detector,
                    d.f,
                    m.recall,
                    m.precision,
                    m.endpoint_mean,
                    m.endpoint_p95,
                    m.angle_mean_deg,
                    breakdown(m),
                    ms(d.fastest_ms),
                    ms(d.median_ms)
                );
            }
            let shared: Vec<String> = l
                .detectors
                .iter()
                .filter_map(|d| {
                    d.shared_with_vss.map(|sh| {
                        format!(
                            "{} {:.3} / {:.3} ({} edges)",
                            d.detector, sh.first_mean, sh.second_mean, sh.edges
                        )
                    })
                })
                .collect();
            if !shared.is_empty() {
                let _ = writeln!(
                    s,
                    "  endpoint px on the true edges both support, vss / peer: {}",
                    shared.join(", ")
                );
            }
            let _ = writeln!(s);
        }
    }
    s
}
