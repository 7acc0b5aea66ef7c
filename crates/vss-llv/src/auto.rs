//! Automatic parameters (llv.md §6): the operator names a target — "about
//! 200 lines", or "clean": the fewest lines without losing edges — and a
//! search re-runs the pipeline over the edge, line and CONNECT parameters
//! that decide how many lines survive, then proposes the best setting with
//! the list of what it changed. Cheap now: each candidate re-runs only from
//! the stage its change affects ([`Workspace::rerun`]).
//!
//! The search is a fixed grid (deterministic, no randomness), nested by
//! stage so that the expensive stages run least often:
//! `edges.per_region × edges.noise_sigmas` (edge stage: how many starts,
//! and how far above the noise) → `lines.min_aligned × lines.log_nfa` (line
//! stage: how significant a segment must be, and whether the orientation
//! test applies; `lines.min_length` is not searched, as CONNECT's
//! `min_line_length` decides the shortest lines kept) → `connect.min_line_length`
//! (CONNECT only). Each axis holds the base value and a ladder around it:
//! with the default base, 45 edge runs, 540 line runs and 5940 CONNECT runs
//! (CONNECT runs are cheap).
//!
//! **"clean", measurably.** The edges an operator must not lose are the
//! *trusted* lines of the base result: those at least [`TRUSTED_FACTOR`] ×
//! `connect.min_line_length` long (noise lines are short: random edge points
//! rarely chain that far). A candidate *keeps the edges* when its lines cover
//! at least [`KEEP_COVERAGE`] of the trusted lines' total length (a candidate
//! line covers the part of a trusted line it runs along, within
//! [`COVER_DISTANCE`] px and [`COVER_ANGLE_DEG`]). Among the candidates that
//! keep the edges, "clean" is the one with the fewest lines.
//!
//! Ties (same count distance, or same line count) go to the candidate that
//! changes fewest parameters, then to the one nearest the base setting
//! (sum of changes measured in each parameter's console steps).

use std::fmt;
use std::str::FromStr;

use super::params::{Params, Stage};
use super::pipeline::{Input, Workspace};
use super::{LlvError, Point, Segment};

/// Trusted lines are at least this many times `connect.min_line_length`.
pub const TRUSTED_FACTOR: f64 = 2.0;
/// "clean" must keep this fraction of the trusted lines' length.
pub const KEEP_COVERAGE: f64 = 0.95;
/// A line covers a trusted line within this perpendicular distance (px).
pub const COVER_DISTANCE: f64 = 2.0;
/// … and this direction difference (degrees).
pub const COVER_ANGLE_DEG: f64 = 5.0;

/// What the search aims for.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// As close as possible to this many lines.
    Lines(usize),
    /// The fewest lines that still cover the base result's trusted edges.
    Clean,
}

/// A target that cannot be parsed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unknown auto target `{0}`: use `lines=N` (e.g. lines=200) or `clean`")]
pub struct TargetError(pub String);

impl FromStr for Target {
    type Err = TargetError;
    /// `lines=200` or `clean`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        if t == "clean" {
            return Ok(Target::Clean);
        }
        t.strip_prefix("lines=")
            .and_then(|n| n.trim().parse::<usize>().ok())
            .filter(|&n| n > 0)
            .map(Target::Lines)
            .ok_or_else(|| TargetError(s.to_string()))
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Lines(n) => write!(f, "lines={n}"),
            Target::Clean => write!(f, "clean"),
        }
    }
}

/// One parameter the search changed: key, old value, new value.
pub type Change = (String, f64, f64);

/// The proposal of a search.
#[derive(Clone, Debug)]
pub struct AutoResult {
    /// The proposed parameters (the base with `changes` applied).
    pub params: Params,
    /// What differs from the base, in the order of the parameter table.
    pub changes: Vec<Change>,
    /// The lines the proposed parameters give.
    pub lines: Vec<Segment>,
    /// The line count of the base parameters.
    pub base_lines: usize,
    /// Pipeline runs (full or partial) the search made.
    pub runs: usize,
    /// For `clean`: the trusted-edge coverage of the proposal (0–1).
    pub coverage: f64,
}

/// Searches the parameter grid (module doc) for `target`, starting from
/// `base`. Errors only where the pipeline itself fails (bad image sizes or
/// parameters).
pub fn search(input: &Input, base: &Params, target: &Target) -> Result<AutoResult, LlvError> {
    let mut ws = Workspace::new();
    let first = ws.run(input, base)?;
    let base_lines = first.lines.len();
    let trusted: Vec<Segment> = first
        .lines
        .iter()
        .copied()
        .filter(|s| s.length() >= TRUSTED_FACTOR * base.connect.min_line_length)
        .collect();
    let trusted_len: f64 = trusted.iter().map(Segment::length).sum();

    let mut best: Option<Candidate> = None;
    let mut consider = |p: &Params, lines: &[Segment]| {
        let coverage = if trusted_len > 0.0 {
            covered_length(&trusted, lines) / trusted_len
        } else {
            1.0
        };
        let cost = match target {
            Target::Lines(n) => lines.len().abs_diff(*n) as f64,
            Target::Clean if coverage >= KEEP_COVERAGE => lines.len() as f64,
            Target::Clean => f64::INFINITY,
        };
        let key = (cost, changes(base, p).len() as f64, step_distance(base, p));
        if best.as_ref().is_none_or(|b| key < b.key) {
            best = Some(Candidate {
                key,
                params: p.clone(),
                lines: lines.to_vec(),
                coverage,
            });
        }
    };
    consider(base, &first.lines);
    let mut runs = 1usize;

    // One workspace, nested by stage: each re-run starts from the stage its
    // parameter belongs to and reuses the enclosing loops' earlier stages.
    let edge_grid = ladder(base.edges.per_region as f64, PER_REGION)
        .into_iter()
        .flat_map(|pr| {
            ladder(base.edges.noise_sigmas, NOISE_SIGMAS)
                .into_iter()
                .map(move |ns| (pr, ns))
        });
    for (per_region, noise_sigmas) in edge_grid {
        {
            let mut p = base.clone();
            p.edges.per_region = per_region as u32;
            p.edges.noise_sigmas = noise_sigmas;
            ws.rerun(Stage::Edges, input, &p)?;
            runs += 1;
            for (aligned, log_nfa) in ladder(base.lines.min_aligned, MIN_ALIGNED)
                .into_iter()
                .flat_map(|l| {
                    ladder(base.lines.log_nfa, LOG_NFA)
                        .into_iter()
                        .map(move |r| (l, r))
                })
            {
                let mut q = p.clone();
                q.lines.min_aligned = aligned;
                q.lines.log_nfa = log_nfa;
                ws.rerun(Stage::Lines, input, &q)?;
                runs += 1;
                for mll in ladder(base.connect.min_line_length, MIN_LINE_LENGTH) {
                    let mut r = q.clone();
                    r.connect.min_line_length = mll;
                    let out = ws.rerun(Stage::Connect, input, &r)?;
                    runs += 1;
                    consider(&r, &out.lines);
                }
            }
        }
    }
    let best = best.ok_or(LlvError::Param {
        name: "auto",
        value: 0.0,
        range: "a search with at least one candidate",
    })?;
    Ok(AutoResult {
        changes: changes(base, &best.params),
        params: best.params,
        lines: best.lines,
        base_lines,
        runs,
        coverage: best.coverage,
    })
}

/// The grid's ladders (module doc); the base value is always tried too.
const PER_REGION: &[f64] = &[3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0];
const NOISE_SIGMAS: &[f64] = &[2.0, 2.5, 3.5, 5.0, 7.0];
const MIN_ALIGNED: &[f64] = &[0.0];
const LOG_NFA: &[f64] = &[-10.0, -5.0, 0.0, 5.0, 10.0, 15.0];
const MIN_LINE_LENGTH: &[f64] = &[
    12.0, 16.0, 20.0, 30.0, 40.0, 60.0, 80.0, 100.0, 120.0, 140.0, 160.0,
];

struct Candidate {
    /// (target cost, parameters changed, distance in steps): smaller wins.
    key: (f64, f64, f64),
    params: Params,
    lines: Vec<Segment>,
    coverage: f64,
}

/// The base value followed by the ladder values that differ from it.
fn ladder(base: f64, ladder: &[f64]) -> Vec<f64> {
    let mut v = vec![base];
    v.extend(ladder.iter().copied().filter(|&x| x != base));
    v
}

/// The parameters that differ between `base` and `p`, in table order.
pub fn changes(base: &Params, p: &Params) -> Vec<Change> {
    super::params::PARAMS
        .iter()
        .filter_map(|sp| {
            let (a, b) = (base.get(sp.key)?, p.get(sp.key)?);
            (a != b).then(|| (sp.key.to_string(), a, b))
        })
        .collect()
}

/// Σ |change| / step over the parameters: how far `p` is from `base`.
fn step_distance(base: &Params, p: &Params) -> f64 {
    super::params::PARAMS
        .iter()
        .filter_map(|sp| Some(((base.get(sp.key)? - p.get(sp.key)?) / sp.step).abs()))
        .sum()
}

/// Total length of `trusted` covered by lines of `lines` (module doc).
/// Overlapping covers of one trusted line are merged, so nothing counts twice.
pub fn covered_length(trusted: &[Segment], lines: &[Segment]) -> f64 {
    let cos_max = COVER_ANGLE_DEG.to_radians().cos();
    let mut total = 0.0;
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for s in trusted {
        let len = s.length();
        if len <= 0.0 {
            continue;
        }
        let u = ((s.b.x - s.a.x) / len, (s.b.y - s.a.y) / len);
        let along = |q: Point| (q.x - s.a.x) * u.0 + (q.y - s.a.y) * u.1;
        let across = |q: Point| ((q.x - s.a.x) * -u.1 + (q.y - s.a.y) * u.0).abs();
        spans.clear();
        for t in lines {
            let tl = t.length();
            if tl <= 0.0 {
                continue;
            }
            let cos = (((t.b.x - t.a.x) * u.0 + (t.b.y - t.a.y) * u.1) / tl).abs();
            if cos < cos_max || across(t.a) > COVER_DISTANCE || across(t.b) > COVER_DISTANCE {
                continue;
            }
            let (p, q) = (along(t.a), along(t.b));
            let (lo, hi) = (p.min(q).max(0.0), p.max(q).min(len));
            if hi > lo {
                spans.push((lo, hi));
            }
        }
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (mut cur_lo, mut cur_hi) = (f64::NAN, f64::NAN);
        for &(lo, hi) in &spans {
            if cur_hi.is_nan() || lo > cur_hi {
                if !cur_hi.is_nan() {
                    total += cur_hi - cur_lo;
                }
                (cur_lo, cur_hi) = (lo, hi);
            } else {
                cur_hi = cur_hi.max(hi);
            }
        }
        if !cur_hi.is_nan() {
            total += cur_hi - cur_lo;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Point::new(ax, ay), Point::new(bx, by))
    }

    #[test]
    fn targets_parse_and_print() {
        assert_eq!("lines=200".parse::<Target>(), Ok(Target::Lines(200)));
        assert_eq!(" clean ".parse::<Target>(), Ok(Target::Clean));
        for bad in ["lines=", "lines=0", "lines=-3", "200", "tidy"] {
            assert!(bad.parse::<Target>().is_err(), "{bad}");
        }
        assert_eq!(Target::Lines(7).to_string(), "lines=7");
    }

    #[test]
    fn coverage_counts_overlaps_once_and_ignores_crossing_lines() {
        let trusted = [seg(0.0, 0.0, 100.0, 0.0)];
        let lines = [
            seg(10.0, 0.5, 40.0, 0.5),
            seg(30.0, -0.5, 60.0, -0.5),  // overlaps the first on 30–40
            seg(50.0, -10.0, 50.0, 10.0), // crosses: no cover
            seg(70.0, 5.0, 90.0, 5.0),    // parallel but too far
            seg(90.0, 0.0, 130.0, 0.0),   // clipped to 90–100
        ];
        assert!((covered_length(&trusted, &lines) - 60.0).abs() < 1e-9);
    }

    #[test]
    fn changes_list_only_what_differs() {
        let base = Params::default();
        let mut p = base.clone();
        p.edges.per_region = 12;
        p.connect.min_line_length = 20.0;
        assert_eq!(
            changes(&base, &p),
            vec![
                (
                    "edges.per_region".to_string(),
                    f64::from(base.edges.per_region),
                    12.0
                ),
                ("connect.min_line_length".to_string(), 12.0, 20.0)
            ]
        );
        assert!(step_distance(&base, &p) > 0.0);
        assert!(changes(&base, &base).is_empty());
    }
}
