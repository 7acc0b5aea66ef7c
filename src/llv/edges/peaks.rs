//! Edge points: peaks of the response one pixel thick along the scan
//! (llv.md §2.3), with parabolic subpixel positions (§2.4), kept where they
//! stand out of the noise.
//!
//! The threshold (replacing §2.5's "at least `M` a region"): a peak is an
//! edge point when its magnitude `|E|`
//! - exceeds the floor `T` (grey levels), and
//! - exceeds `noise_sigmas` times the noise scale `σ_r` of its tile
//!   ([`NoiseMap`]: the robust scale of the response itself), and
//! - is among the `M` strongest of its region (ties kept).
//!
//! §2.5 kept *at least* `M` peaks a scan line: on a line that crosses no
//! edge that promotes the `M` largest noise peaks, and on the bench scene
//! 13 k of its 16 k points were noise, which the line extractor then paid
//! to follow and which became tilted, bent lines. Measured against the
//! noise, `M` only limits clutter (texture, a pattern) and noise is never
//! promoted; with the default 3.5 σ_r a tile of pure noise keeps about 4
//! points in 10 000 pixels. Edge points are where lines *start*: the line
//! extractor follows them through weaker peaks, read from the response
//! itself (`lines.rs`), so the threshold here can be high.
//!
//! The selection is written plainly: a pixel costs a few compares, and the
//! candidates past the first (the threshold) are rare.

use super::{Keys, NONE, NoiseMap, Response};
use crate::llv::params::EdgeParams;
use crate::llv::{EdgePoint, EdgePoints, ScanDir};

/// Reusable buffers of the edge-point selection.
#[derive(Clone, Debug, Default)]
pub struct PeakScratch {
    /// Candidates: pixel index and key, in image order.
    cand: Vec<(u32, i16)>,
    /// Per tile, the largest key that is not above the threshold; per
    /// column of a row of tiles, the same.
    thr: Vec<i32>,
    strong_thr: Vec<i32>,
    cols: Vec<i16>,
    /// Per region: candidate count, then the smallest key kept.
    count: Vec<u32>,
    lim: Vec<i16>,
    /// Candidates' keys grouped by region (regions with more than `M`).
    start: Vec<u32>,
    grouped: Vec<i16>,
    noise: super::NoiseScratch,
    keys: super::KeyBuf,
}

/// The largest key at or below `limit` grey levels with `scale` grey levels
/// a key: a key passes when it is above this.
pub(crate) fn key_floor(limit: f32, scale: f32) -> i32 {
    if limit.is_nan() || limit <= 0.0 {
        // (NaN: the caller refused it; 0 or less: every key passes.)
        return if limit.is_nan() { i32::MAX } else { -1 };
    }
    let k = (limit / scale).floor();
    if k >= f32::from(NONE) {
        i32::from(NONE)
    } else {
        k as i32
    }
}

/// Parabolic subpixel offset through `|E|` at a peak and its two neighbours,
/// clamped to ±0.5 (llv.md §2.4).
#[inline]
pub(crate) fn subpixel(em: f32, e0: f32, ep: f32) -> f32 {
    let den = 2.0 * (em - 2.0 * e0 + ep);
    if den < 0.0 {
        ((em - ep) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Edge points of a response (see the module doc), estimating its noise
/// map first.
pub fn peaks(resp: &Response, p: &EdgeParams) -> EdgePoints {
    let mut s = PeakScratch::default();
    let (mut noise, mut map) = (NoiseMap::default(), PeakMap::default());
    let mut out = EdgePoints::default();
    detect_into(
        resp,
        p,
        p.noise_sigmas,
        &mut noise,
        &mut map,
        &mut out,
        &mut s,
    );
    out
}

/// The noise map, the peak map and the edge points of a response, into
/// reusable buffers: what the pipeline does per scan direction. The peak
/// map holds the peaks above `track_sigmas` noise sigmas (the line
/// extractor's threshold) or `p.noise_sigmas`, whichever is lower; the
/// edge points are those of them above `p.noise_sigmas`.
pub fn detect_into(
    resp: &Response,
    p: &EdgeParams,
    track_sigmas: f64,
    noise: &mut NoiseMap,
    map: &mut PeakMap,
    out: &mut EdgePoints,
    s: &mut PeakScratch,
) {
    let mut buf = std::mem::take(&mut s.keys);
    detect_keys_into(&resp.keys(&mut buf), p, track_sigmas, noise, map, out, s);
    s.keys = buf;
}

/// [`detect_into`] on a response's keys ([`Response::keys`]), for a caller
/// that reads them more than once: an `f32` response (several lightings)
/// is then quantised once for the edge points and the line extractor.
pub fn detect_keys_into(
    k: &Keys,
    p: &EdgeParams,
    track_sigmas: f64,
    noise: &mut NoiseMap,
    map: &mut PeakMap,
    out: &mut EdgePoints,
    s: &mut PeakScratch,
) {
    let mut ns = std::mem::take(&mut s.noise);
    noise.estimate_into(k, &mut ns);
    let low = track_sigmas.min(p.noise_sigmas);
    map.build_into(k, noise, p.floor, low, p.noise_sigmas, s);
    peaks_into(k, noise, map, p, out, s);
    s.noise = ns;
}

/// The peaks of a response along its scan (§2.3) above a threshold: the
/// floor `T` and a number of noise sigmas of their tile. One bit a pixel
/// per polarity (bit `i` for image index `i`), found sixteen pixels at a
/// time ([`for_each_peak`]): the edge points are picked from it, and the
/// line extractor reads its next points from it where it looks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PeakMap {
    width: usize,
    height: usize,
    dir: Option<ScanDir>,
    floor: f64,
    sigmas: f64,
    strong_sigmas: f64,
    /// Positive and negative peaks.
    pub(crate) pos: Vec<u64>,
    pub(crate) neg: Vec<u64>,
    /// The peaks above the strong threshold (the edge points' candidates):
    /// image index and key, in image order.
    strong: Vec<(u32, i16)>,
}

impl PeakMap {
    /// Whether the map is that of a response of this size and direction
    /// at this threshold.
    pub fn fits(&self, k: &Keys, floor: f64, sigmas: f64) -> bool {
        (self.width, self.height, self.dir) == (k.width, k.height, Some(k.dir))
            && self.floor.to_bits() == floor.to_bits()
            && self.sigmas.to_bits() == sigmas.to_bits()
            && self.pos.len() == (k.width * k.height).div_ceil(64)
    }

    /// The peaks of `k` above `floor` grey levels and `sigmas` noise sigmas,
    /// and the list of those above `strong_sigmas` (with their keys).
    pub fn build_into(
        &mut self,
        k: &Keys,
        noise: &NoiseMap,
        floor: f64,
        sigmas: f64,
        strong_sigmas: f64,
        s: &mut PeakScratch,
    ) {
        self.width = k.width;
        self.height = k.height;
        self.dir = Some(k.dir);
        self.floor = floor;
        self.sigmas = sigmas;
        self.strong_sigmas = strong_sigmas;
        let words = (k.width * k.height).div_ceil(64);
        for bits in [&mut self.pos, &mut self.neg] {
            bits.clear();
            bits.resize(words, 0);
        }
        if floor.is_nan() || k.keys.len() != k.width * k.height {
            return;
        }
        let (nx, ny) = noise.tiles();
        s.thr.clear();
        s.strong_thr.clear();
        for t in 0..nx * ny {
            let limit = |n: f64| key_floor((floor as f32).max(n as f32 * noise.sigma(t)), k.scale);
            s.thr.push(limit(sigmas));
            s.strong_thr.push(limit(strong_sigmas));
        }
        self.strong.clear();
        let (pos, neg, strong) = (&mut self.pos, &mut self.neg, &mut self.strong);
        for_each_peak(
            k,
            noise,
            &s.thr,
            &s.strong_thr,
            &mut s.cols,
            |i, key, big| {
                let bits = if k.sums[i] > 0 { &mut *pos } else { &mut *neg };
                bits[i / 64] |= 1 << (i % 64);
                if big {
                    strong.push((i as u32, key));
                }
            },
        );
    }
}

/// Edge points of a response given its noise map and a peak map (at no
/// more noise sigmas than `p.noise_sigmas`), in image order (row by row,
/// left to right, for either direction).
///
/// Settled details: a peak needs both neighbours along the scan to have a
/// response (no edge at the border of the valid area); a region is
/// `region_lines` consecutive scan lines (rows for `Horizontal`, columns
/// for `Vertical`); where a region has more than `M` candidates, those at
/// least as strong as its `M`-th strongest are kept.
pub fn peaks_into(
    k: &Keys,
    noise: &NoiseMap,
    map: &PeakMap,
    p: &EdgeParams,
    out: &mut EdgePoints,
    s: &mut PeakScratch,
) {
    let (w, h) = (k.width, k.height);
    out.dir = Some(k.dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    s.cand.clear();
    if w < 3 || h < 3 || k.keys.len() != w * h || k.sums.len() != w * h || p.floor.is_nan() {
        return;
    }
    // The map's strong peaks, when it was made at these sigmas; else its
    // peaks above them, one tile lookup each.
    let mut cand = std::mem::take(&mut s.cand);
    if map.strong_sigmas.to_bits() == p.noise_sigmas.to_bits() {
        cand.extend_from_slice(&map.strong);
    } else {
        let (nx, ny) = noise.tiles();
        s.thr.clear();
        for t in 0..nx * ny {
            let limit = (p.floor as f32).max(p.noise_sigmas as f32 * noise.sigma(t));
            s.thr.push(key_floor(limit, k.scale));
        }
        for (j, (&a, &b)) in map.pos.iter().zip(&map.neg).enumerate() {
            let mut bits = a | b;
            while bits != 0 {
                let i = j * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let key = k.keys[i];
                if i32::from(key) > s.thr[noise.tile_of(i % w, i / w)] {
                    cand.push((i as u32, key));
                }
            }
        }
    }
    let rl = p.region_lines.max(1) as usize;
    let m = p.per_region.max(1) as usize;
    let region = |i: u32| -> usize {
        let i = i as usize;
        match k.dir {
            ScanDir::Horizontal => i / w / rl,
            ScanDir::Vertical => i % w / rl,
        }
    };
    let nreg = match k.dir {
        ScanDir::Horizontal => h.div_ceil(rl),
        ScanDir::Vertical => w.div_ceil(rl),
    };
    region_limits(&cand, nreg, m, region, s);
    let step = match k.dir {
        ScanDir::Horizontal => 1,
        ScanDir::Vertical => w,
    };
    for &(i, key) in &cand {
        if key < s.lim[region(i)] {
            continue;
        }
        let i = i as usize;
        let mag = |j: usize| f32::from(k.keys[j]);
        let d = subpixel(mag(i - step), mag(i), mag(i + step));
        let (x, y) = ((i % w) as f32, (i / w) as f32);
        let (x, y) = match k.dir {
            ScanDir::Horizontal => (x + d, y),
            ScanDir::Vertical => (x, y + d),
        };
        out.points.push(EdgePoint {
            x,
            y,
            response: f32::from(k.sums[i]) * k.scale,
        });
    }
    s.cand = cand;
}

/// Every pixel that is a peak along the scan (`|E|` above the left/upper
/// neighbour's, at least the right/lower one's) and above its tile's
/// threshold, in image order: sixteen pixels a step in `i16` lanes
/// (`wide`: SSE2 or NEON, a scalar fallback elsewhere), the compares'
/// sign bits taken at once; [`candidates_plain`] is the same in plain code,
/// kept as the reference the tests compare with.
#[cfg(test)]
fn candidates(
    k: &Keys,
    noise: &NoiseMap,
    thr: &[i32],
    cols: &mut Vec<i16>,
    cand: &mut Vec<(u32, i16)>,
) {
    for_each_peak(k, noise, thr, thr, cols, |i, key, _| {
        cand.push((i as u32, key))
    });
}

/// Calls `f(i, key, strong)`, in image order, for every pixel index `i`
/// that is a peak along the scan above its tile's threshold `thr` (per
/// tile of `noise`, as keys), with `strong` whether it is above `strong`
/// too (both thresholds in one pass); `cols` is a buffer.
pub(crate) fn for_each_peak(
    k: &Keys,
    noise: &NoiseMap,
    thr: &[i32],
    strong: &[i32],
    cols: &mut Vec<i16>,
    mut f: impl FnMut(usize, i16, bool),
) {
    let (w, h) = (k.width, k.height);
    let keys = k.keys;
    if w < 3 || h < 3 || keys.len() != w * h {
        return;
    }
    let mut tile_row = usize::MAX;
    let rows = match k.dir {
        ScanDir::Horizontal => 0..h,
        ScanDir::Vertical => 1..h - 1,
    };
    let as_key = |t: Option<&i32>| t.copied().unwrap_or(i32::MAX).clamp(-1, i32::from(NONE)) as i16;
    for y in rows {
        // The thresholds of every column of this row's tiles: `cols[..w]`
        // the peaks', `cols[w..]` the strong ones'.
        let t0 = noise.tile_of(0, y);
        if t0 != tile_row {
            tile_row = t0;
            cols.clear();
            cols.extend((0..w).map(|x| as_key(thr.get(noise.tile_of(x, y)))));
            cols.extend((0..w).map(|x| as_key(strong.get(noise.tile_of(x, y)))));
        }
        let (low, high) = cols.split_at(w);
        let at = y * w;
        match k.dir {
            ScanDir::Horizontal => {
                let row = &keys[at..at + w];
                let (lo, mid, hi) = (&row[..w - 2], &row[1..w - 1], &row[2..]);
                peak_bits([lo, mid, hi], &low[1..w - 1], &high[1..w - 1], |x, s| {
                    f(at + x + 1, row[x + 1], s);
                });
            }
            ScanDir::Vertical => {
                let (up, row, dn) = (
                    &keys[at - w..at],
                    &keys[at..at + w],
                    &keys[at + w..at + 2 * w],
                );
                peak_bits([up, row, dn], low, high, |x, s| f(at + x, row[x], s));
            }
        }
    }
}

/// Calls `f(i, strong)`, in order, for every `i` with `mid[i] > lo[i]`,
/// `mid[i] ≥ hi[i]`, `mid[i] > thr[i]` and `mid[i] ≠ NONE`, where `strong`
/// is `mid[i] > strong[i]` (all slices as long).
#[inline(always)]
fn peak_bits(
    [lo, mid, hi]: [&[i16]; 3],
    thr: &[i16],
    strong: &[i16],
    mut f: impl FnMut(usize, bool),
) {
    use wide::{CmpEq, CmpGt, i16x16};
    let n = mid
        .len()
        .min(lo.len())
        .min(hi.len())
        .min(thr.len())
        .min(strong.len());
    let load = |s: &[i16], i: usize| i16x16::new(*s[i..].first_chunk::<16>().expect("16 lanes"));
    let none = i16x16::splat(NONE);
    let mut i = 0;
    while i + 16 <= n {
        let k0 = load(mid, i);
        let c = k0.cmp_gt(load(lo, i)) & k0.cmp_gt(load(thr, i));
        let c = c & !(load(hi, i).cmp_gt(k0) | k0.cmp_eq(none));
        let mut bits = c.move_mask() as u32 & 0xFFFF;
        if bits != 0 {
            let big = (c & k0.cmp_gt(load(strong, i))).move_mask() as u32;
            while bits != 0 {
                let b = bits.trailing_zeros();
                f(i + b as usize, big >> b & 1 != 0);
                bits &= bits - 1;
            }
        }
        i += 16;
    }
    for j in i..n {
        let k0 = mid[j];
        if k0 > lo[j] && k0 >= hi[j] && k0 > thr[j] && k0 != NONE {
            f(j, k0 > strong[j]);
        }
    }
}

/// [`candidates`] in plain code, one pixel and tile at a time.
#[cfg(test)]
fn candidates_plain(k: &Keys, noise: &NoiseMap, thr: &[i32], cand: &mut Vec<(u32, i16)>) {
    let (w, h) = (k.width, k.height);
    let keys = k.keys;
    let step = match k.dir {
        ScanDir::Horizontal => 1,
        ScanDir::Vertical => w,
    };
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let inside = match k.dir {
                ScanDir::Horizontal => x >= 1 && x + 1 < w,
                ScanDir::Vertical => y >= 1 && y + 1 < h,
            };
            if !inside {
                continue;
            }
            let k0 = keys[i];
            let th = thr[noise.tile_of(x, y)];
            if i32::from(k0) > th && k0 > keys[i - step] && k0 >= keys[i + step] && k0 != NONE {
                cand.push((i as u32, k0));
            }
        }
    }
}

/// Per region, the smallest key kept: 0 where it has at most `m`
/// candidates, else its `m`-th largest key.
fn region_limits(
    cand: &[(u32, i16)],
    nreg: usize,
    m: usize,
    region: impl Fn(u32) -> usize,
    s: &mut PeakScratch,
) {
    s.count.clear();
    s.count.resize(nreg, 0);
    s.lim.clear();
    s.lim.resize(nreg, 0);
    for &(i, _) in cand {
        s.count[region(i)] += 1;
    }
    if s.count.iter().all(|&c| c as usize <= m) {
        return;
    }
    // Group the keys of the crowded regions, then select in each.
    s.start.clear();
    let mut at = 0u32;
    for &c in &s.count {
        s.start.push(at);
        if c as usize > m {
            at += c;
        }
    }
    s.grouped.clear();
    s.grouped.resize(at as usize, 0);
    let mut fill = s.start.clone();
    for &(i, key) in cand {
        let r = region(i);
        if s.count[r] as usize > m {
            s.grouped[fill[r] as usize] = key;
            fill[r] += 1;
        }
    }
    for r in 0..nreg {
        let c = s.count[r] as usize;
        if c > m {
            let g = &mut s.grouped[s.start[r] as usize..s.start[r] as usize + c];
            let (_, kth, _) = g.select_nth_unstable_by(m - 1, |a, b| b.cmp(a));
            s.lim[r] = *kth;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::GreyImage;
    use crate::llv::edges::{ResponseScratch, exact_response_into};

    fn params() -> EdgeParams {
        EdgeParams::default()
    }

    fn response(img: &GreyImage, dir: ScanDir) -> Response {
        let mut r = Response::default();
        exact_response_into(img, dir, 4, &mut r, &mut ResponseScratch::default()).unwrap();
        r
    }

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
        let d = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y));
        GreyImage::new(w, h, d.collect()).unwrap()
    }

    #[test]
    fn a_step_gives_one_point_a_row_and_a_flat_image_none() {
        let img = image(40, 30, |x, _| if x < 20 { 50 } else { 150 });
        let e = peaks(&response(&img, ScanDir::Horizontal), &params());
        assert_eq!(e.points.len(), 30);
        for p in &e.points {
            assert!((p.x - 19.5).abs() < 1e-3 && p.response > 90.0, "{p:?}");
        }
        assert!(
            peaks(&response(&img, ScanDir::Vertical), &params())
                .points
                .is_empty()
        );
        let flat = image(16, 16, |_, _| 7);
        for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
            assert!(peaks(&response(&flat, dir), &params()).points.is_empty());
        }
    }

    #[test]
    fn m_keeps_the_strongest_of_a_region() {
        // Five steps of rising contrast along each row.
        let img = image(120, 20, |x, _| {
            let steps = [10u8, 30, 60, 100, 150, 210];
            steps[(x / 20).min(5)]
        });
        let mut p = params();
        p.per_region = 2;
        let e = peaks(&response(&img, ScanDir::Horizontal), &p);
        assert_eq!(e.points.len(), 2 * 20);
        assert!(
            e.points.iter().all(|q| q.response > 45.0),
            "{:?}",
            e.points[0]
        );
        p.per_region = 8;
        assert_eq!(
            peaks(&response(&img, ScanDir::Horizontal), &p).points.len(),
            5 * 20
        );
        // Regions of ten rows: the two strongest of 50 candidates are a tie
        // of ten each.
        p.per_region = 2;
        p.region_lines = 10;
        assert_eq!(
            peaks(&response(&img, ScanDir::Horizontal), &p).points.len(),
            20
        );
    }

    #[test]
    fn vertical_points_are_in_image_order_with_subpixel_y() {
        let img = image(30, 40, |_, y| if 2 * y < 41 { 40 } else { 200 });
        let e = peaks(&response(&img, ScanDir::Vertical), &params());
        assert_eq!(e.points.len(), 30);
        assert!(e.points.windows(2).all(|w| w[0].x < w[1].x));
        assert!(e.points.iter().all(|p| (p.y - 20.0).abs() <= 0.5));
    }

    /// The lane-wise candidate test finds what the plain one does, on
    /// noise with edges, a validity mask, thresholds per tile and widths
    /// that are no multiple of sixteen.
    #[test]
    fn wide_candidates_equal_the_plain_ones() {
        use crate::llv::synth::rng::SplitMix64;
        let mut rng = SplitMix64::new(3);
        for (w, h) in [(16, 16), (37, 53), (130, 70), (200, 131)] {
            let mut img = image(w, h, |x, y| {
                let base = if x * 3 + y > w { 160.0 } else { 60.0 };
                (base + 4.0 * ((x * 7 + y * 13) % 11) as f64) as u8
            });
            let noisy: Vec<u8> = img
                .data()
                .iter()
                .map(|&v| (f64::from(v) + 6.0 * rng.gauss()).clamp(0.0, 255.0) as u8)
                .collect();
            img = GreyImage::new(w, h, noisy).unwrap();
            let mask: Vec<bool> = (0..w * h).map(|i| i % 97 != 5).collect();
            img.set_valid_mask(Some(mask)).unwrap();
            for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                let r = response(&img, dir);
                let mut buf = crate::llv::edges::KeyBuf::default();
                let k = r.keys(&mut buf);
                let noise = NoiseMap::estimate(&k);
                let (nx, ny) = noise.tiles();
                let thr: Vec<i32> = (0..nx * ny).map(|t| 20 + 37 * t as i32).collect();
                let (mut fast, mut plain, mut cols) = (Vec::new(), Vec::new(), Vec::new());
                candidates(&k, &noise, &thr, &mut cols, &mut fast);
                candidates_plain(&k, &noise, &thr, &mut plain);
                assert!(!plain.is_empty());
                assert_eq!(fast, plain, "{w}x{h} {dir:?}");
            }
        }
    }

    #[test]
    fn key_floors() {
        assert_eq!(key_floor(2.0, 0.5), 4);
        assert_eq!(key_floor(0.0, 0.5), -1);
        assert_eq!(key_floor(f32::NAN, 0.5), i32::MAX);
        assert_eq!(key_floor(1e9, 0.5), i32::from(NONE));
    }
}
