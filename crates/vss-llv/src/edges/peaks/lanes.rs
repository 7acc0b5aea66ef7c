//! The edge pass's peak test, a padded row at a time: magnitudes, then
//! the compares of each position with its neighbours and thresholds, whose
//! sign bits are the masks of candidates and of the peak map. AVX2 lanes
//! (`pulp`, chosen at run time, safe intrinsics) where the processor has
//! them; elsewhere, and as the tests' reference, the same test in plain
//! code.

use crate::edges::SUM_MAX;

/// `|s|` of every sum of `row` into `out` (as long), saturating: [`NONE`](crate::edges::NONE)
/// gives `i16::MAX`. Plain code the compiler vectorises (AVX2 at run time).
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
pub(super) fn key_row(row: &[i16], out: &mut [i16]) {
    for (k, &s) in out.iter_mut().zip(row) {
        *k = s.max(0i16.saturating_sub(s));
    }
}

/// The largest key a real sum has ([`SUM_MAX`]); `i16::MAX` is [`NONE`](crate::edges::NONE)'s.
pub(super) const REAL: i16 = SUM_MAX as i16;

/// The peak test of one padded row, for positions `x` in `0..sign.len()`
/// (a multiple of 64): with `k = mid[x]`, position `x` is a peak along the
/// scan when `k > lo[x]`, `k ≥ hi[x]` and `k` is a real magnitude (not
/// [`NONE`](crate::edges::NONE)'s); an edge point's candidate when also `k > thr[x]`, a peak a
/// track may take when `k > trk[x]`, positive or negative by `sign[x]`.
/// `bits` gets the three masks, each `sign.len() / 64` words. Thirty-two
/// positions an iteration with AVX2 where the processor has it (`pulp`,
/// chosen at run time), else [`row_masks_plain`], the reference the tests
/// compare with.
pub(super) fn row_masks(
    simd: Simd,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    bits: &mut [u64],
) {
    let n = sign.len();
    let words = n / 64;
    let ok = n.is_multiple_of(64)
        && [lo.len(), mid.len(), hi.len(), thr.len(), trk.len()]
            .iter()
            .all(|&l| l >= n)
        && bits.len() >= 3 * words;
    if !ok {
        debug_assert!(false, "row buffers not padded");
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = simd {
        simd.vectorize(
            #[inline(always)]
            || avx2_masks(simd, [lo, mid, hi], sign, thr, trk, bits),
        );
        return;
    }
    let _ = simd;
    for b in 0..n / 32 {
        let r = b * 32..b * 32 + 32;
        let m = row_masks_plain(
            [&lo[r.clone()], &mid[r.clone()], &hi[r.clone()]],
            &sign[r.clone()],
            &thr[r.clone()],
            &trk[r],
        );
        put32(bits, words, b, m);
    }
}

/// Stores the three 32-bit masks of block `b` (positions `32 b ..`) into
/// `bits` (three runs of `words` words).
#[inline(always)]
fn put32(bits: &mut [u64], words: usize, b: usize, m: [u32; 3]) {
    let (word, shift) = (b / 2, 32 * (b % 2));
    for (k, m) in m.into_iter().enumerate() {
        bits[k * words + word] |= u64::from(m) << shift;
    }
}

/// The vector unit [`row_masks`] uses: AVX2 where the processor has it
/// (asked once a pass), else none (plain code).
#[cfg(target_arch = "x86_64")]
pub(super) type Simd = Option<pulp::x86::V3>;
#[cfg(not(target_arch = "x86_64"))]
pub(super) type Simd = Option<()>;

/// Set to run the peak test in plain code even where AVX2 is there: for
/// measuring what the lanes save (`PLAIN=1 TIME=1 llv_count peaks`).
static PLAIN_ONLY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Runs the peak test in plain code from now on (`true`), or with AVX2
/// where the processor has it (`false`, the default): a switch for
/// benchmarks, which give the same results either way.
#[doc(hidden)]
pub fn plain_only(on: bool) {
    PLAIN_ONLY.store(on, std::sync::atomic::Ordering::Relaxed);
}

pub(super) fn simd() -> Simd {
    if PLAIN_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    {
        pulp::x86::V3::try_new()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// [`row_masks`] with AVX2. (Helpers are `inline(always)` functions, not
/// closures, so that they compile inside the AVX2 context.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_masks(
    simd: pulp::x86::V3,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    bits: &mut [u64],
) {
    let a = simd.avx2;
    let n = sign.len() / 64 * 64;
    let words = n / 64;
    let (lo, mid, hi, thr, trk) = (&lo[..n], &mid[..n], &hi[..n], &thr[..n], &trk[..n]);
    let (st_bits, rest) = bits.split_at_mut(words);
    let (pos_bits, neg_bits) = rest.split_at_mut(words);
    // Two blocks of 32 a word: each word of each mask is stored once.
    let it = lo
        .chunks_exact(64)
        .zip(mid.chunks_exact(64))
        .zip(hi.chunks_exact(64))
        .zip(sign[..n].chunks_exact(64))
        .zip(thr.chunks_exact(64).zip(trk.chunks_exact(64)))
        .zip(
            st_bits
                .iter_mut()
                .zip(pos_bits.iter_mut().zip(neg_bits.iter_mut())),
        );
    for (((((l, m), h), sg), (t, tk)), (sb, (pb, nb))) in it {
        let half = |o: usize| avx2_half(a, [l, m, h], sg, t, tk, o);
        let [s0, p0, n0] = half(0);
        let [s1, p1, n1] = half(16);
        let [s2, p2, n2] = half(32);
        let [s3, p3, n3] = half(48);
        let word = |x0, x1, y0, y1| {
            u64::from(avx2_bits(a, x0, x1)) | u64::from(avx2_bits(a, y0, y1)) << 32
        };
        *sb = word(s0, s1, s2, s3);
        *pb = word(p0, p1, p2, p3);
        *nb = word(n0, n1, n2, n3);
    }
}

#[cfg(target_arch = "x86_64")]
type Avx2 = pulp::core_arch::x86::Avx2;
#[cfg(target_arch = "x86_64")]
type V = core::arch::x86_64::__m256i;

/// Sixteen `i16` from `s[o..]`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_load(s: &[i16], o: usize) -> V {
    pulp::cast(*s[o..].first_chunk::<16>().expect("16 lanes"))
}

/// The candidate, positive-track and negative-track lanes of the sixteen
/// positions from `o` of a block.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_half(
    a: Avx2,
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
    o: usize,
) -> [V; 3] {
    let zero: V = pulp::cast([0i16; 16]);
    let real: V = pulp::cast([REAL + 1; 16]);
    let k = avx2_load(mid, o);
    let up = a._mm256_cmpgt_epi16(k, avx2_load(lo, o));
    let down = a._mm256_cmpgt_epi16(avx2_load(hi, o), k);
    let peak = a._mm256_and_si256(
        a._mm256_andnot_si256(down, up),
        a._mm256_cmpgt_epi16(real, k),
    );
    let st = a._mm256_and_si256(peak, a._mm256_cmpgt_epi16(k, avx2_load(thr, o)));
    let tr = a._mm256_and_si256(peak, a._mm256_cmpgt_epi16(k, avx2_load(trk, o)));
    let ng = a._mm256_and_si256(tr, a._mm256_cmpgt_epi16(zero, avx2_load(sign, o)));
    [st, a._mm256_andnot_si256(ng, tr), ng]
}

/// Two halves' lanes as 32 bits in order (the pack interleaves the 128-bit
/// lanes; the permute puts them back).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2_bits(a: Avx2, x: V, y: V) -> u32 {
    let p = a._mm256_permute4x64_epi64::<0b11_01_10_00>(a._mm256_packs_epi16(x, y));
    a._mm256_movemask_epi8(p) as u32
}

/// The masks of [`row_masks`] for one block of 32 positions, in plain
/// code (branch-free: no compare's outcome is guessed).
pub(super) fn row_masks_plain(
    [lo, mid, hi]: [&[i16]; 3],
    sign: &[i16],
    thr: &[i16],
    trk: &[i16],
) -> [u32; 3] {
    let (mut st, mut pos, mut neg) = (0u32, 0u32, 0u32);
    let n = mid.len().min(32);
    let (lo, hi, sign, thr, trk) = (&lo[..n], &hi[..n], &sign[..n], &thr[..n], &trk[..n]);
    for j in 0..n {
        let k = mid[j];
        let peak = (k > lo[j]) & (k >= hi[j]) & (k <= REAL);
        let tr = peak & (k > trk[j]);
        let ng = tr & (sign[j] < 0);
        st |= u32::from(peak & (k > thr[j])) << j;
        pos |= u32::from(tr & !ng) << j;
        neg |= u32::from(ng) << j;
    }
    [st, pos, neg]
}
