//! The Lee convolution of one output row, shared by the single-image
//! response ([`super::response_into`]) and the photometric combination
//! (`photometric.rs`), so both compute the same `f32` bit for bit.
//!
//! By antisymmetry, `E = (Σ_{s=1..A-1} c_s (hi_s − lo_s)) / A³` with
//! `c_s = 6 s (A − s)` (`c_A = 0`), where `hi_s`/`lo_s` are the pixels `s`
//! steps after/before along the scan. Each output is computed in registers
//! over all taps (the half-width is a const generic, so the tap loop is
//! unrolled) in blocks of [`BLK`] outputs, then scaled once. The integer sum
//! is exact, so it is the same whatever the lane type:
//! - `A ≤ 5`: `Σ c_s · 255 ≤ 30 600 < 2¹⁵`, so `i16` lanes (eight per SSE2
//!   register, no widening per tap);
//! - `A = 6, 7`: up to `336 · 255`, so `i32` lanes.
//!
//! `(sum as f32) · (1/A³)` is then one rounding, the same as the former
//! `f32` accumulation of whole numbers followed by the same scaling.
//!
//! For `A ≤ 5` the single-image path keeps the sums themselves
//! ([`lee_row_exact`]): the `i16` sum and its magnitude, without the
//! conversion to `f32`, which the peak finder then does only at candidates.

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

/// Writes the Lee response with half-width `a` (3–7) of every output of
/// `out` (its length is the number of outputs). Leaves `out` untouched if
/// the taps are too short (a caller's bug, never reached from the stages).
pub(crate) fn lee_row(taps: &Taps, a: usize, out: &mut [f32]) {
    if !taps.covers(a, out.len()) {
        debug_assert!(false, "taps shorter than the output row");
        return;
    }
    match a {
        3 => row_i16::<3>(taps, out),
        4 => row_i16::<4>(taps, out),
        5 => row_i16::<5>(taps, out),
        6 => row_i32::<6>(taps, out),
        7 => row_i32::<7>(taps, out),
        _ => debug_assert!(false, "half-width {a} outside 3..=7"),
    }
}

/// Writes the exact Lee sums `S` (the response is `S · 1/A³`) of every
/// output of `sums` and their magnitudes `|S|` into `keys` (as long), for a
/// half-width `a` of 3–5, whose sums fit `i16`; false (nothing written) for
/// any other, or if the taps are too short.
pub(crate) fn lee_row_exact(taps: &Taps, a: usize, sums: &mut [i16], keys: &mut [i16]) -> bool {
    if sums.len() != keys.len() || !taps.covers(a, sums.len()) {
        return false;
    }
    match a {
        3 => row_exact::<3>(taps, sums, keys),
        4 => row_exact::<4>(taps, sums, keys),
        5 => row_exact::<5>(taps, sums, keys),
        _ => return false,
    }
    true
}

/// `c_s = 6 s (A − s)` for `s = 0..8` (only `1..A` is used).
const fn coef(a: usize, s: usize) -> i32 {
    if s == 0 || s >= a {
        0
    } else {
        (6 * s * (a - s)) as i32
    }
}

pub(crate) fn scale(a: usize) -> f32 {
    1.0 / (a * a * a) as f32
}

/// One output, exactly: the fallback for rows shorter than a block.
#[inline]
fn one(taps: &Taps, a: usize, j: usize) -> f32 {
    one_sum(taps, a, j) as f32 * scale(a)
}

/// The exact sum of output `j`.
#[inline]
fn one_sum(taps: &Taps, a: usize, j: usize) -> i32 {
    (1..a)
        .map(|s| coef(a, s) * (i32::from(taps.hi[s][j]) - i32::from(taps.lo[s][j])))
        .sum()
}

/// Runs `block(i, out)` on blocks of [`BLK`] outputs starting at `i` that
/// cover the row, the last one overlapping its predecessor (recomputed
/// outputs are identical); rows shorter than a block go output by output.
#[inline(always)]
fn by_blocks(taps: &Taps, a: usize, out: &mut [f32], mut block: impl FnMut(usize, &mut [f32])) {
    let n = out.len();
    if n < BLK {
        for (j, o) in out.iter_mut().enumerate() {
            *o = one(taps, a, j);
        }
        return;
    }
    for i in block_starts(n) {
        block(i, out);
    }
}

fn row_exact<const A: usize>(taps: &Taps, sums: &mut [i16], keys: &mut [i16]) {
    let n = sums.len();
    if n < BLK {
        for (j, (s, k)) in sums.iter_mut().zip(keys.iter_mut()).enumerate() {
            // |acc| ≤ 30 600 for A ≤ 5.
            let acc = one_sum(taps, A, j);
            *s = acc as i16;
            *k = acc.unsigned_abs() as i16;
        }
        return;
    }
    for i in block_starts(n) {
        let acc = sums_i16::<A>(taps, i);
        sums[i..i + BLK].copy_from_slice(&acc);
        for (k, &v) in keys[i..i + BLK].iter_mut().zip(&acc) {
            *k = v.wrapping_abs();
        }
    }
}

/// The exact sums of the [`BLK`] outputs from `i`, in `i16` lanes (`A ≤
/// 5`; the taps cover them).
#[inline(always)]
fn sums_i16<const A: usize>(taps: &Taps, i: usize) -> [i16; BLK] {
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

fn row_i16<const A: usize>(taps: &Taps, out: &mut [f32]) {
    let sc = scale(A);
    by_blocks(taps, A, out, |i, out| {
        let acc = sums_i16::<A>(taps, i);
        for (o, &v) in out[i..i + BLK].iter_mut().zip(&acc) {
            *o = v as f32 * sc;
        }
    });
}

fn row_i32<const A: usize>(taps: &Taps, out: &mut [f32]) {
    let sc = scale(A);
    by_blocks(taps, A, out, |i, out| {
        let mut acc = [0i32; BLK];
        for s in 1..A {
            let c = coef(A, s);
            let h = &taps.hi[s][i..i + BLK];
            let l = &taps.lo[s][i..i + BLK];
            for ((o, &h), &l) in acc.iter_mut().zip(h).zip(l) {
                *o += c * (i32::from(h) - i32::from(l));
            }
        }
        for (o, &v) in out[i..i + BLK].iter_mut().zip(&acc) {
            *o = v as f32 * sc;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_rows_scale_to_the_float_rows_bit_for_bit() {
        let mut rng = crate::llv::synth::rng::SplitMix64::new(11);
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
                let mut want = vec![f32::NAN; n];
                lee_row(&Taps::horizontal(row, a), a, &mut want);
                let (mut sums, mut keys) = (vec![0i16; n], vec![0i16; n]);
                let done = lee_row_exact(&Taps::horizontal(row, a), a, &mut sums, &mut keys);
                assert_eq!(done, a <= 5, "a={a}");
                if !done {
                    continue;
                }
                for j in 0..n {
                    let e = sums[j] as f32 * scale(a);
                    assert_eq!(e.to_bits(), want[j].to_bits(), "a={a} len={len} j={j}");
                    assert_eq!(i32::from(keys[j]), i32::from(sums[j]).abs());
                }
            }
        }
    }

    #[test]
    fn rows_equal_the_tap_by_tap_float_sum_for_every_length() {
        let mut rng = crate::llv::synth::rng::SplitMix64::new(7);
        let src: Vec<u8> = (0..200).map(|_| rng.next_u64() as u8).collect();
        for a in 3..=7 {
            for len in 2 * a + 1..=200 {
                let row = &src[..len];
                let n = len - 2 * a;
                let mut out = vec![f32::NAN; n];
                lee_row(&Taps::horizontal(row, a), a, &mut out);
                for (j, &v) in out.iter().enumerate() {
                    let x = j + a;
                    let mut want = 0f32;
                    for s in 1..=a {
                        let c = (6 * s * (a - s)) as f32;
                        want += c * (row[x + s] as f32 - row[x - s] as f32);
                    }
                    want *= 1.0 / (a * a * a) as f32;
                    assert_eq!(v.to_bits(), want.to_bits(), "a={a} len={len} j={j}");
                }
            }
        }
    }
}
