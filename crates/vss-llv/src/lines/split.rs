//! Splitting a track where it joins two edges: the point where two
//! straight pieces fit the track significantly better than one line.
//!
//! For a track of `n` points, the best split `j` minimises the sum of the
//! two pieces' residual sums of squares (total least squares, from prefix
//! sums: O(n) a track). With the points' scatter `σ²` about the two
//! pieces, the drop `ΔRSS / σ²` of a straight edge is a χ² variable of two
//! degrees of freedom (the second line's angle and offset); searched over
//! `n` places, `n · exp(−c/2)` bounds the chance that noise alone exceeds
//! `c`. The track is split where the drop exceeds `c = 2 ln(n / α)`,
//! `α` = 10⁻³, and each piece is tested again.

use super::TrackPoint;

/// Points a piece needs on either side of a split.
const MIN_PIECE: usize = 24;

/// The chance that a straight track is split somewhere.
const ALPHA: f64 = 1e-3;

/// The least scatter assumed (px): quantised noise-free images give
/// points closer to their lines than the model means.
const SIGMA_FLOOR: f64 = 0.1;

/// Reusable buffers of [`pieces`].
#[derive(Clone, Debug, Default)]
pub struct SplitScratch {
    /// Prefix sums of `u, v, u², uv, v²` (relative to the first point).
    pre: Vec<[f64; 5]>,
    ranges: Vec<std::ops::Range<usize>>,
    stack: Vec<std::ops::Range<usize>>,
}

impl SplitScratch {
    /// The pieces of the last [`pieces`] call, in order.
    pub fn ranges(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.ranges.iter().cloned()
    }
}

/// Fills `s`'s ranges with the pieces of `chain`. Only its points beyond
/// `trim` of each end are tested (the ends bend where another edge meets
/// this one, which is no second edge of this track's).
pub fn pieces(chain: &[TrackPoint], trim: usize, s: &mut SplitScratch) {
    s.ranges.clear();
    s.pre.clear();
    s.stack.clear();
    let Some(o) = chain.first() else { return };
    if chain.len() < 2 * trim + 2 * MIN_PIECE {
        // Too short to split: no sums needed.
        s.ranges.push(0..chain.len());
        return;
    }
    let mut acc = [0f64; 5];
    s.pre.push(acc);
    for q in chain {
        let (u, v) = (q.u - o.u, q.v - o.v);
        acc[0] += u;
        acc[1] += v;
        acc[2] += u * u;
        acc[3] += u * v;
        acc[4] += v * v;
        s.pre.push(acc);
    }
    s.stack.push(trim..chain.len() - trim);
    while let Some(r) = s.stack.pop() {
        match best_split(&s.pre, r.clone()) {
            Some(j) => {
                s.stack.push(j..r.end);
                s.stack.push(r.start..j);
            }
            None => s.ranges.push(r),
        }
    }
    s.ranges.sort_by_key(|r| r.start);
    if let Some(f) = s.ranges.first_mut() {
        f.start = 0;
    }
    if let Some(l) = s.ranges.last_mut() {
        l.end = chain.len();
    }
}

/// Total-least-squares residual sum of squares of points `a..b`.
fn rss(pre: &[[f64; 5]], a: usize, b: usize) -> f64 {
    let n = (b - a) as f64;
    if n < 2.0 {
        return 0.0;
    }
    let d = |k: usize| pre[b][k] - pre[a][k];
    let (su, sv) = (d(0), d(1));
    let suu = d(2) - su * su / n;
    let suv = d(3) - su * sv / n;
    let svv = d(4) - sv * sv / n;
    let half = 0.5 * (suu - svv);
    // (`sqrt` of the sum, not `hypot`: a libm call, and nothing here is
    // near overflow.)
    (0.5 * (suu + svv) - (half * half + suv * suv).sqrt()).max(0.0)
}

/// Where to split points `r`, if anywhere.
fn best_split(pre: &[[f64; 5]], r: std::ops::Range<usize>) -> Option<usize> {
    let n = r.len();
    if n < 2 * MIN_PIECE {
        return None;
    }
    let total = rss(pre, r.start, r.end);
    let mut best = (f64::INFINITY, 0);
    for j in r.start + MIN_PIECE..=r.end - MIN_PIECE {
        let two = rss(pre, r.start, j) + rss(pre, j, r.end);
        if two < best.0 {
            best = (two, j);
        }
    }
    let var = (best.0 / (n - 4) as f64).max(SIGMA_FLOOR * SIGMA_FLOOR);
    let drop = (total - best.0) / var;
    (drop > 2.0 * (n as f64 / ALPHA).ln()).then_some(best.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain(f: impl Fn(f64) -> f64, n: usize, noise: f64) -> Vec<TrackPoint> {
        let mut r = crate::rng::SplitMix64::new(5);
        (0..n)
            .map(|i| TrackPoint {
                u: f(i as f64) + noise * r.gauss(),
                v: i as f64,
                response: 10.0,
                z: 5.0,
                id: i,
            })
            .collect()
    }

    #[test]
    fn a_straight_track_stays_whole_and_a_kinked_one_splits_at_the_kink() {
        let mut s = SplitScratch::default();
        for noise in [0.0, 0.1, 0.3] {
            pieces(&chain(|v| 10.0 + 0.3 * v, 120, noise), 4, &mut s);
            assert_eq!(s.ranges().count(), 1, "straight, noise {noise}");
        }
        // Two edges 6° apart meeting at v = 60.
        let kink = |v: f64| if v < 60.0 { 0.0 } else { (v - 60.0) * 0.105 };
        pieces(&chain(kink, 120, 0.1), 4, &mut s);
        let r: Vec<_> = s.ranges().collect();
        assert_eq!(r.len(), 2, "{r:?}");
        assert!((r[0].end as i64 - 60).abs() <= 3, "{r:?}");
        pieces(&[], 4, &mut s);
        assert_eq!(s.ranges().count(), 0);
    }
}
