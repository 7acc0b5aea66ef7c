//! The a-contrario test of a tracked segment (Desolneux, Moisan & Morel,
//! "Meaningful alignments", IJCV 40, 2000; the test LSD uses): a segment is
//! kept when noise alone would give fewer than `ε` segments as good in an
//! image, `ε = 10^log_nfa`. No threshold depends on the scene: the noise is
//! measured ([`NoiseMap`](crate::edges::NoiseMap)), the rest is
//! counting.
//!
//! The event on one scan line of the segment's span: "there is a peak of
//! the segment's polarity within the search window (`2·search_width + 1`
//! pixels) whose magnitude exceeds `z` noise sigmas". On white Gaussian
//! noise filtered by the Lee kernel its probability per pixel is `q_A(z)`
//! (the table below, measured once by simulation: 2·10⁸ samples a
//! half-width). A segment spanning `n` scan lines with a point on `k` of
//! them at level `z` has the binomial tail `B(n, k, p)`, `p = (2 sw + 1)
//! q_A(z)`, as its probability under noise; the test takes the best of a
//! few levels (strong short segments and weak long ones both qualify) and
//! counts every level and every segment the image could hold:
//! `NFA = N_tests · min_z B(n, k_z, p_z)`, `N_tests = 2 · levels · (w h)²`.
//!
//! A level counts only where its points cover most of the span: `k_z ≥
//! ⅔ n`. The binomial model takes the lines as independent,
//! but a track is not placed at random: it takes the nearest peak, and
//! where it crosses a strong edge that edge gives it two or three points
//! of 8 σ and more. Without the rule, those few points alone made any
//! track through flat ground significant (tracks crossing cube edges at
//! 30–60°; docs/llv.md, "Measurements behind the design"). A true edge has
//! its points on most of its lines at its own level, so the rule costs it
//! nothing there.

/// Noise sigmas of the table's levels.
const TABLE_Z: [f64; 9] = [1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0];

/// `q_A(z)`: per pixel, the probability that a pixel is a peak along the
/// scan (`|E|` above the previous pixel's, at least the next one's) of one
/// given sign with `|E| > z σ_r`, on white Gaussian noise, for A = 3..=7.
const TABLE_Q: [[f64; 9]; 5] = [
    [
        0.09633, 0.0485, 0.01868, 0.005537, 0.001269, 2.246e-4, 3.084e-5, 3.46e-6, 2.925e-7,
    ],
    [
        0.07525, 0.03845, 0.01527, 0.004687, 0.001112, 2.034e-4, 2.924e-5, 3.133e-6, 2.4e-7,
    ],
    [
        0.06171, 0.03167, 0.01274, 0.00398, 9.653e-4, 1.813e-4, 2.666e-5, 3.075e-6, 2.975e-7,
    ],
    [
        0.05248, 0.02689, 0.01087, 0.003424, 8.381e-4, 1.59e-4, 2.358e-5, 2.615e-6, 2.475e-7,
    ],
    [
        0.04584, 0.02343, 0.009469, 0.003004, 7.409e-4, 1.426e-4, 2.157e-5, 2.493e-6, 2.15e-7,
    ],
];

/// The levels tested besides the tracking threshold itself.
const LEVELS: [f32; 7] = [2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 8.0];

/// Whether `k` points of a level on a span of `n` lines are dense enough
/// for the level to count: `k ≥ ⅔ n` (module doc).
fn dense(n: usize, k: usize) -> bool {
    3 * k >= 2 * n
}

/// `q_A(z)` for half-width `a` (clamped to 3–7): log-linear between the
/// table's levels, the Gaussian tail `exp(-z²/2)` beyond them.
pub fn q(a: usize, z: f64) -> f64 {
    let row = &TABLE_Q[a.clamp(3, 7) - 3];
    if z.is_nan() || z <= TABLE_Z[0] {
        return row[0];
    }
    let last = TABLE_Z.len() - 1;
    if z >= TABLE_Z[last] {
        let z0 = TABLE_Z[last];
        return row[last] * (-(z * z - z0 * z0) / 2.0).exp();
    }
    let j = TABLE_Z
        .iter()
        .rposition(|&t| t <= z)
        .unwrap_or(0)
        .min(last - 1);
    let f = (z - TABLE_Z[j]) / (TABLE_Z[j + 1] - TABLE_Z[j]);
    (row[j].ln() * (1.0 - f) + row[j + 1].ln() * f).exp()
}

/// The test for one image and one parameter set.
#[derive(Clone, Debug, Default)]
pub struct Nfa {
    log10_tests: f64,
    /// Per level, the noise sigmas and the per-line event's `p` with the
    /// logarithms the tail needs (a fixed array: no allocation per image).
    levels: [(f32, Chance); LEVELS.len() + 1],
    count: usize,
}

impl Nfa {
    /// For a `w × h` image, half-width `a`, search half-width `sw` and the
    /// tracker's least level `track_sigmas`.
    pub fn new(w: usize, h: usize, a: usize, sw: f64, track_sigmas: f64) -> Self {
        let window = 2.0 * sw.max(0.0) + 1.0;
        let mut t = Nfa::default();
        let first = track_sigmas as f32;
        for z in std::iter::once(first).chain(LEVELS.iter().copied().filter(|&z| z > first)) {
            let p = (window * q(a, f64::from(z))).min(1.0);
            t.levels[t.count] = (z, Chance::new(p));
            t.count += 1;
        }
        let px = (w.max(1) * h.max(1)) as f64;
        t.log10_tests = (2.0 * t.count as f64).log10() + 2.0 * px.log10();
        t
    }

    /// Per level, how many of `z` reach it (one pass over the points;
    /// the levels ascend, so the counts descend).
    fn counts(&self, z: &[f32]) -> [usize; LEVELS.len() + 1] {
        let mut at = [f32::INFINITY; LEVELS.len() + 1];
        for (a, l) in at.iter_mut().zip(&self.levels[..self.count]) {
            *a = l.0;
        }
        let mut k = [0u32; LEVELS.len() + 1];
        for &v in z {
            for (k, &a) in k.iter_mut().zip(&at) {
                *k += u32::from(v >= a);
            }
        }
        k.map(|k| k as usize)
    }

    /// Whether a segment spanning `n` scan lines whose points have the
    /// noise sigmas `z` has `log10 NFA ≤ log_eps`: the levels are tried
    /// from the most selective down, and the first that suffices decides
    /// (most edges are significant at their own level at once).
    pub fn significant(&self, n: usize, z: &[f32], log_eps: f64) -> bool {
        let need = log_eps - self.log10_tests;
        let k = self.counts(z);
        (0..self.count)
            .rev()
            .any(|j| dense(n, k[j]) && self.levels[j].1.tail_at_most(n, k[j], need))
    }

    /// `log10 NFA` of a segment spanning `n` scan lines whose points have
    /// the noise sigmas `z` (one point a scan line at most).
    pub fn log10_nfa(&self, n: usize, z: &[f32]) -> f64 {
        let mut best = 0f64;
        let k = self.counts(z);
        for (j, (_, c)) in self.levels[..self.count].iter().enumerate() {
            if dense(n, k[j]) {
                best = best.min(c.log10_tail(n, k[j]));
            }
        }
        self.log10_tests + best
    }
}

/// `ln n!`: exact below 16, Stirling's series above (error below 1e-9);
/// from a table made once below [`LN_FACTORIALS`].
fn ln_factorial(n: usize) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    let t = TABLE.get_or_init(|| (0..LN_FACTORIALS).map(ln_factorial_of).collect());
    t.get(n).copied().unwrap_or_else(|| ln_factorial_of(n))
}

/// The `ln n!` [`ln_factorial`] keeps in its table (scan lines of all
/// but large images).
const LN_FACTORIALS: usize = 2048;

/// [`ln_factorial`], computed.
fn ln_factorial_of(n: usize) -> f64 {
    if n < 16 {
        return (2..=n).map(|i| (i as f64).ln()).sum();
    }
    let x = n as f64;
    x * x.ln() - x + 0.5 * (2.0 * std::f64::consts::PI * x).ln() + 1.0 / (12.0 * x)
        - 1.0 / (360.0 * x * x * x)
}

/// A per-line chance `p` with the logarithms of its binomial tail, made
/// once per level rather than once per segment.
#[derive(Clone, Copy, Debug, Default)]
struct Chance {
    p: f64,
    ln_p: f64,
    ln_q: f64,
    odds: f64,
}

impl Chance {
    fn new(p: f64) -> Self {
        Chance {
            p,
            ln_p: p.ln(),
            ln_q: (-p).ln_1p(),
            odds: p / (1.0 - p),
        }
    }

    /// The tail's value where no sum is needed (`Err`), else the log of
    /// its first term (`Ok`).
    fn first_term(&self, n: usize, k: usize) -> Result<f64, f64> {
        let p = self.p;
        if k == 0 || p >= 1.0 {
            return Err(0.0);
        }
        if k > n || p.is_nan() || p <= 0.0 {
            return Err(f64::NEG_INFINITY);
        }
        if (k as f64) <= n as f64 * p {
            // At or below the mean: the tail is at least about one half.
            return Err(0.0);
        }
        Ok(ln_factorial(n) - ln_factorial(k) - ln_factorial(n - k)
            + k as f64 * self.ln_p
            + (n - k) as f64 * self.ln_q)
    }

    /// `log10 Σ_{i ≥ k} C(n, i) pⁱ (1 − p)ⁿ⁻ⁱ`, from the log of its first
    /// term.
    fn summed(&self, n: usize, k: usize, ln_first: f64) -> f64 {
        // The later terms fall geometrically: term(i + 1) / term(i) =
        // (n − i) / (i + 1) · p / (1 − p) < 1 above the mean.
        let (mut sum, mut term) = (1.0f64, 1.0f64);
        for i in k..n {
            term *= (n - i) as f64 / (i + 1) as f64 * self.odds;
            sum += term;
            if term < sum * 1e-12 {
                break;
            }
        }
        (ln_first + sum.ln()) / std::f64::consts::LN_10
    }

    fn log10_tail(&self, n: usize, k: usize) -> f64 {
        match self.first_term(n, k) {
            Ok(ln_first) => self.summed(n, k, ln_first),
            Err(v) => v,
        }
    }

    /// `log10_tail(n, k) <= need`, without the sum where the first term
    /// alone exceeds `need` (the sum is at least 1, and adding its
    /// logarithm and dividing by `ln 10` cannot lower the value).
    fn tail_at_most(&self, n: usize, k: usize, need: f64) -> bool {
        match self.first_term(n, k) {
            Ok(ln_first) if ln_first / std::f64::consts::LN_10 > need => false,
            Ok(ln_first) => self.summed(n, k, ln_first) <= need,
            Err(v) => v <= need,
        }
    }
}

/// `log10 Σ_{i ≥ k} C(n, i) pⁱ (1 − p)ⁿ⁻ⁱ`.
pub fn log10_binomial_tail(n: usize, k: usize, p: f64) -> f64 {
    Chance::new(p).log10_tail(n, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tail_direct(n: usize, k: usize, p: f64) -> f64 {
        let mut c = 1.0f64;
        let mut s = 0.0;
        for i in 0..=n {
            if i > 0 {
                c *= (n - i + 1) as f64 / i as f64;
            }
            if i >= k {
                s += c * p.powi(i as i32) * (1.0 - p).powi((n - i) as i32);
            }
        }
        s.log10()
    }

    #[test]
    fn the_binomial_tail_matches_the_sum() {
        for (n, k, p) in [(10, 8, 0.1), (40, 20, 0.07), (60, 60, 0.01), (30, 5, 0.05)] {
            let (a, b) = (log10_binomial_tail(n, k, p), tail_direct(n, k, p));
            assert!((a - b).abs() < 1e-6, "{n} {k} {p}: {a} vs {b}");
        }
        assert_eq!(log10_binomial_tail(10, 0, 0.3), 0.0);
        assert_eq!(log10_binomial_tail(10, 11, 0.3), f64::NEG_INFINITY);
        assert_eq!(log10_binomial_tail(10, 2, 0.5), 0.0);
    }

    /// The shortcut of the significance test (no sum where the first
    /// term already fails) decides as the whole tail does, and the table
    /// of `ln n!` holds what the formula gives.
    #[test]
    fn the_tail_shortcut_decides_as_the_tail() {
        for p in [1e-4, 0.003, 0.05, 0.3] {
            let c = Chance::new(p);
            for n in 1..90 {
                for k in 0..=n {
                    let full = c.log10_tail(n, k);
                    for need in [-40.0, -12.5, -3.0, -0.5, 0.0] {
                        assert_eq!(
                            c.tail_at_most(n, k, need),
                            full <= need,
                            "{p} {n} {k} {need}"
                        );
                    }
                }
            }
        }
        for n in [0, 1, 15, 16, 639, LN_FACTORIALS - 1, LN_FACTORIALS, 5000] {
            assert_eq!(
                ln_factorial(n).to_bits(),
                ln_factorial_of(n).to_bits(),
                "{n}"
            );
        }
    }

    #[test]
    fn q_is_monotone_and_continuous() {
        for a in 3..=7 {
            let mut last = 1.0;
            for i in 0..200 {
                let z = 0.5 + i as f64 * 0.05;
                let v = q(a, z);
                assert!(v > 0.0 && v <= last * (1.0 + 1e-12), "A {a} z {z}");
                last = v;
            }
        }
        assert!((q(4, 3.0) - 0.001112).abs() < 1e-9);
    }

    /// Strong short segments and long weak ones pass; short weak ones and
    /// sparse chains fail, in a 512² image.
    #[test]
    fn meaningful_segments() {
        let t = Nfa::new(512, 512, 4, 2.0, 2.0);
        let ok = |n: usize, z: &[f32]| t.log10_nfa(n, z) < 0.0;
        assert!(ok(10, &[6.0; 10]));
        assert!(!ok(10, &[2.2; 10]));
        assert!(ok(40, &[2.2; 40]));
        assert!(!ok(60, &[2.2; 12]));
        assert!(ok(80, &[3.0; 54]));
        // Sparse: points on under two thirds of the span do not count.
        assert!(!ok(80, &[3.0; 50]));
    }

    /// A track through flat noise that crosses a strong edge takes two of
    /// its points there (9 σ) and noise peaks at the tracking level on 14
    /// of its other 18 lines: the two strong points alone must not make it
    /// significant.
    #[test]
    fn a_track_crossing_a_strong_edge_is_not_significant() {
        let t = Nfa::new(512, 512, 4, 2.0, 1.5);
        let mut z = vec![1.6f32; 16];
        z[7] = 9.0;
        z[8] = 9.0;
        assert!(t.log10_nfa(20, &z) > 0.0, "{}", t.log10_nfa(20, &z));
        assert!(!t.significant(20, &z, 0.0));
        // The same span with the edge's level on every line is an edge.
        assert!(t.significant(20, &[9.0; 20], 0.0));
        // The early-exit test agrees with the full count.
        for (n, z) in [
            (10, vec![6.0f32; 10]),
            (10, vec![2.2; 10]),
            (60, vec![2.6; 30]),
        ] {
            for eps in [-5.0, 0.0, 5.0] {
                assert_eq!(
                    t.significant(n, &z, eps),
                    t.log10_nfa(n, &z) <= eps,
                    "{n} {eps}"
                );
            }
        }
    }

    /// The table itself: a fresh simulation of the peak test on white noise
    /// (smaller than the one that made it) agrees within its sampling error.
    #[test]
    fn the_table_matches_a_simulation() {
        use crate::edges::kernel;
        use crate::rng::SplitMix64;
        let mut rng = SplitMix64::new(11);
        for a in [3usize, 5, 7] {
            let k = kernel(a);
            let norm = k.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>().sqrt();
            let n = 2_000_000;
            let x: Vec<f64> = (0..n + 2 * a).map(|_| rng.gauss()).collect();
            let r: Vec<f64> = (a..n + a)
                .map(|i| {
                    let s: f64 = (0..=2 * a).map(|t| f64::from(k[t]) * x[i + a - t]).sum();
                    s / norm
                })
                .collect();
            for (j, z) in [(2usize, 2.0), (4, 3.0)] {
                let hits = (1..r.len() - 1)
                    .filter(|&i| {
                        let m = r[i].abs();
                        m > r[i - 1].abs() && m >= r[i + 1].abs() && r[i] > z
                    })
                    .count();
                let got = hits as f64 / (r.len() - 2) as f64;
                let want = TABLE_Q[a - 3][j];
                assert!(
                    (got / want - 1.0).abs() < 0.1,
                    "A {a} z {z}: {got} vs {want}"
                );
            }
        }
    }
}
