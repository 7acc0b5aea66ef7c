//! The Lee convolution of one output row, shared by the single-image
//! response ([`super::response_into`]) and the photometric combination
//! (`photometric.rs`), so both compute the same sums.
//!
//! By antisymmetry, `E = (Σ_{s=1..A-1} c_s (hi_s − lo_s)) / A³` with
//! `c_s = 6 s (A − s)` (`c_A = 0`), where `hi_s`/`lo_s` are the pixels `s`
//! steps after/before along the scan. Each output is computed in registers
//! over all taps (the half-width is a const generic, so the tap loop is
//! unrolled) in blocks of [`BLK`] outputs. The integer sum is exact, so it
//! is the same whatever the lane type:
//! - `A ≤ 5`: `Σ c_s · 255 ≤ 30 600 < 2¹⁵`, so `i16` lanes (no widening per
//!   tap);
//! - `A = 6, 7`: up to `336 · 255`, so `i32` lanes.

use super::SUM_MAX;

/// Outputs per block: eight SSE2 registers of `i16` accumulators; fewer
/// outputs per block spend as much on slicing the taps as on arithmetic.
const BLK: usize = 64;

/// The source rows of one output row: tap `s` (1..A) reads `hi[s][j]` and
/// `lo[s][j]` for output `j`. Entries past `A` (and index 0) are unused.
#[derive(Clone, Copy)]
pub(crate) struct Taps<'a> {
    pub hi: [&'a [u8]; 8],
    pub lo: [&'a [u8]; 8],
}

impl<'a> Taps<'a> {
    /// Horizontal scan: output `j` is pixel `x = j + a` of `row`, so tap `s`
    /// reads `row[j + a ± s]`. Needs `row.len() > 2a`.
    pub fn horizontal(row: &'a [u8], a: usize) -> Self {
        let mut t = Taps {
            hi: [&[]; 8],
            lo: [&[]; 8],
        };
        for s in 1..=a.min(7) {
            t.hi[s] = row.get(a + s..).unwrap_or(&[]);
            t.lo[s] = row.get(a - s..).unwrap_or(&[]);
        }
        t
    }

    /// Vertical scan at row `y` of a `w`-wide image `px`: tap `s` reads rows
    /// `y ± s`. Needs `a ≤ y < h − a`.
    pub fn vertical(px: &'a [u8], w: usize, y: usize, a: usize) -> Self {
        let mut t = Taps {
            hi: [&[]; 8],
            lo: [&[]; 8],
        };
        for s in 1..=a.min(7) {
            t.hi[s] = px.get((y + s) * w..(y + s + 1) * w).unwrap_or(&[]);
            t.lo[s] = px.get((y - s) * w..(y - s + 1) * w).unwrap_or(&[]);
        }
        t
    }

    /// Whether every tap covers `n` outputs (so the kernels cannot index
    /// out of range).
    fn covers(&self, a: usize, n: usize) -> bool {
        (1..a).all(|s| self.hi[s].len() >= n && self.lo[s].len() >= n)
    }
}

/// `c_s = 6 s (A − s)` for `s = 0..8` (only `1..A` is used).
pub(crate) const fn coef(a: usize, s: usize) -> i32 {
    if s == 0 || s >= a {
        0
    } else {
        (6 * s * (a - s)) as i32
    }
}

/// Grey levels of one unit of an exact sum: `1/A³`.
pub(crate) fn scale(a: usize) -> f32 {
    1.0 / (a * a * a) as f32
}

/// The largest magnitude of an exact sum with half-width `a`: `255 Σ c_s`.
pub(crate) fn max_sum(a: usize) -> i64 {
    255 * (1..a).map(|s| i64::from(coef(a, s))).sum::<i64>()
}

/// The bits a sum of `terms` responses' magnitudes (each at most
/// [`max_sum`]) is shifted right by so that it fits [`SUM_MAX`]: 0 for
/// one image with `A ≤ 5`.
pub(crate) fn shift(a: usize, terms: u32) -> u32 {
    let top = max_sum(a) * i64::from(terms.max(1));
    let mut k = 0;
    while top > i64::from(SUM_MAX) << k {
        k += 1;
    }
    k
}

/// Writes the exact sums `S` (the response is `S / A³`) of every output of
/// `out` for a half-width `a` of 3–5, whose sums fit `i16`; false (nothing
/// written) for any other, or if the taps are too short.
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
pub(crate) fn sums_i16(taps: &Taps, a: usize, out: &mut [i16]) -> bool {
    if !taps.covers(a, out.len()) {
        return false;
    }
    match a {
        3 => row_exact::<3>(taps, out),
        4 => row_exact::<4>(taps, out),
        5 => row_exact::<5>(taps, out),
        _ => return false,
    }
    true
}

/// Writes the exact sums of every output of `out` for any half-width 3–7
/// (in `i16` lanes where they fit, then widened). Leaves `out` untouched
/// if the taps are too short (a caller's bug, never reached from the
/// stages).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
pub(crate) fn sums_i32(taps: &Taps, a: usize, out: &mut [i32]) {
    if !taps.covers(a, out.len()) {
        debug_assert!(false, "taps shorter than the output row");
        return;
    }
    match a {
        3 => widen_exact::<3>(taps, out),
        4 => widen_exact::<4>(taps, out),
        5 => widen_exact::<5>(taps, out),
        6 => row_wide::<6>(taps, out),
        7 => row_wide::<7>(taps, out),
        _ => debug_assert!(false, "half-width {a} outside 3..=7"),
    }
}

/// `v / 2^shift` rounded half away from zero and clamped to ±[`SUM_MAX`],
/// as `i16`.
#[inline(always)]
pub(crate) fn narrow_one(v: i32, shift: u32) -> i16 {
    let r = if shift == 0 {
        v
    } else {
        let half = 1 << (shift - 1);
        let m = (v.unsigned_abs() as i32 + half) >> shift;
        if v < 0 { -m } else { m }
    };
    r.clamp(-SUM_MAX, SUM_MAX) as i16
}

/// [`narrow_one`] of every value of `wide` into `out` (as long).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
pub(crate) fn narrow(wide: &[i32], shift: u32, out: &mut [i16]) {
    for (o, &v) in out.iter_mut().zip(wide) {
        *o = narrow_one(v, shift);
    }
}

/// The exact sum of output `j`.
#[inline(always)]
fn one_sum(taps: &Taps, a: usize, j: usize) -> i32 {
    (1..a)
        .map(|s| coef(a, s) * (i32::from(taps.hi[s][j]) - i32::from(taps.lo[s][j])))
        .sum()
}

// `row_exact`, `widen_exact` and `row_wide` are written out, not one
// helper taking closures: a closure is not inlined into the AVX2 clone that
// `multiversion` makes of its caller, so its loop runs without AVX2 (the
// response of both directions took 167 µs instead of 80 that way).
#[inline(always)]
fn row_exact<const A: usize>(taps: &Taps, out: &mut [i16]) {
    let n = out.len();
    if n < BLK {
        for (j, o) in out.iter_mut().enumerate() {
            // |acc| ≤ 30 600 for A ≤ 5.
            *o = one_sum(taps, A, j) as i16;
        }
        return;
    }
    for i in block_starts(n) {
        out[i..i + BLK].copy_from_slice(&block_i16::<A>(taps, i));
    }
}

#[inline(always)]
fn widen_exact<const A: usize>(taps: &Taps, out: &mut [i32]) {
    let n = out.len();
    if n < BLK {
        for (j, o) in out.iter_mut().enumerate() {
            *o = one_sum(taps, A, j);
        }
        return;
    }
    for i in block_starts(n) {
        let acc = block_i16::<A>(taps, i);
        for (o, &v) in out[i..i + BLK].iter_mut().zip(&acc) {
            *o = i32::from(v);
        }
    }
}

/// The exact sums of the [`BLK`] outputs from `i`, in `i16` lanes (`A ≤
/// 5`; the taps cover them).
#[inline(always)]
fn block_i16<const A: usize>(taps: &Taps, i: usize) -> [i16; BLK] {
    let mut acc = [0i16; BLK];
    for s in 1..A {
        let c = coef(A, s) as i16;
        let h = &taps.hi[s][i..i + BLK];
        let l = &taps.lo[s][i..i + BLK];
        for ((o, &h), &l) in acc.iter_mut().zip(h).zip(l) {
            *o = o.wrapping_add(c.wrapping_mul(h as i16 - l as i16));
        }
    }
    acc
}

/// The starts of the blocks of [`BLK`] outputs that cover a row of `n ≥
/// BLK`, the last one overlapping its predecessor.
fn block_starts(n: usize) -> impl Iterator<Item = usize> {
    let last = n.saturating_sub(BLK);
    (0..last).step_by(BLK).chain(std::iter::once(last))
}

#[inline(always)]
fn row_wide<const A: usize>(taps: &Taps, out: &mut [i32]) {
    let n = out.len();
    if n < BLK {
        for (j, o) in out.iter_mut().enumerate() {
            *o = one_sum(taps, A, j);
        }
        return;
    }
    for i in block_starts(n) {
        let mut acc = [0i32; BLK];
        for s in 1..A {
            let c = coef(A, s);
            let h = &taps.hi[s][i..i + BLK];
            let l = &taps.lo[s][i..i + BLK];
            for ((o, &h), &l) in acc.iter_mut().zip(h).zip(l) {
                *o += c * (i32::from(h) - i32::from(l));
            }
        }
        out[i..i + BLK].copy_from_slice(&acc);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_equal_the_tap_by_tap_sum_for_every_length() {
        let mut rng = crate::rng::SplitMix64::new(11);
        // Extremes too: 0/255 steps give the largest sums.
        let src: Vec<u8> = (0..300)
            .map(|i| match i % 50 {
                0..10 => 0,
                10..20 => 255,
                _ => rng.next_u64() as u8,
            })
            .collect();
        for a in 3..=7 {
            for len in 2 * a + 1..=300 {
                let row = &src[..len];
                let n = len - 2 * a;
                let want: Vec<i32> = (0..n)
                    .map(|j| {
                        let x = j + a;
                        (1..=a)
                            .map(|s| {
                                (6 * s * (a - s)) as i32 * (row[x + s] as i32 - row[x - s] as i32)
                            })
                            .sum()
                    })
                    .collect();
                let mut wide = vec![0i32; n];
                sums_i32(&Taps::horizontal(row, a), a, &mut wide);
                assert_eq!(wide, want, "a={a} len={len}");
                let mut narrow16 = vec![0i16; n];
                let done = sums_i16(&Taps::horizontal(row, a), a, &mut narrow16);
                assert_eq!(done, a <= 5, "a={a}");
                if done {
                    assert!(narrow16.iter().zip(&want).all(|(&s, &w)| i32::from(s) == w));
                }
            }
        }
    }

    #[test]
    fn shifts_fit_the_largest_sums_and_round_half_away_from_zero() {
        assert_eq!((shift(3, 1), shift(4, 1), shift(5, 1)), (0, 0, 0));
        assert_eq!((shift(6, 1), shift(7, 1)), (1, 2));
        assert_eq!(shift(4, 8), 2);
        assert_eq!(shift(5, 8), 3);
        for a in 3..=7 {
            for terms in 1..=10 {
                let k = shift(a, terms);
                assert!(max_sum(a) * i64::from(terms) <= i64::from(SUM_MAX) << k);
            }
        }
        assert_eq!(narrow_one(5, 1), 3);
        assert_eq!(narrow_one(-5, 1), -3);
        assert_eq!(narrow_one(4, 1), 2);
        assert_eq!(narrow_one(-6, 2), -2);
        assert_eq!(narrow_one(1_000_000, 0), SUM_MAX as i16);
        assert_eq!(narrow_one(-1_000_000, 3), -SUM_MAX as i16);
    }
}
