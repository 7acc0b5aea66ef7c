//! A drawing front end (`lines.draw`, experimental): instead of following
//! every peak of each scan direction's response with its own tracker, edge
//! chains are drawn from anchors over both responses at once, in the
//! manner of EDLines and ELSED, and their straight pieces go to the
//! tracker's validation (`keep_pieces`: weak ends, split, NFA, fit), so the
//! same segments come out and CONNECT runs unchanged.
//!
//! - **Which response**: a pixel whose `|E_H|` is at least its `|E_V|`
//!   lies on a steep edge (within 45° of the columns) and is drawn on the
//!   horizontal response, row by row; the others on the vertical one,
//!   column by column. A chain keeps the response it started on, so its
//!   points are one a scan line, in the tracker's scan coordinates.
//! - **Anchors** are the edge points (peaks above `edges.noise_sigmas`
//!   noise sigmas) of every [`ANCHOR_EVERY`]-th scan line whose response
//!   is the dominant one there, strongest first (by half-sigma buckets).
//! - **Drawing**: from the anchor both ways, each step goes to the
//!   strongest pixel of the anchor's polarity among the three ahead on the
//!   next scan line, then up the ridge along the scan to its peak; it must
//!   beat `lines.track_sigmas` noise sigmas of its tile (and the floor).
//!   The three are those around the last pixel until the chain has the
//!   tracker's `STRAY_AFTER` points; from then on, around the position its
//!   fitted line predicts (one fit for both ways, as the tracker's), and a
//!   pixel off that line (`Course::is_stray`) or drawn before is skipped
//!   like a missing one. Stepping from the last pixel, a chain along a
//!   faint edge wandered onto the noise beside it for a few scan lines and
//!   was cut there into pieces too short to pass validation; the fitted
//!   line keeps it on the edge, and unlike a looser cut it does not follow
//!   an arch or bridge a row of windows (docs/performance.md).
//!   Where no pixel is found, up to `lines.max_gap` further scan lines are
//!   tried at the predicted position. A chain stops there,
//!   and at a pixel a chain of its own response has drawn. Chains of the
//!   other response may cross it: a diagonal edge is drawn on both, as
//!   both trackers followed it, and CONNECT merges the two (a mask shared
//!   by both responses lost recall; docs/performance.md).
//! - **Pieces**: a least-squares line `u = a + b v` grows with the chain;
//!   once it has `CUT_AFTER` points, `CUT_RUN` points in a row more
//!   than `CUT_DISTANCE` px from it end the piece, and the next starts
//!   at them (ELSED's rule). In a noisy image (`edges.noisy_sigma`, which
//!   also widens the kernel) "off" is also beyond 3 RMS residuals of the
//!   piece, as the tracker's stray test: a faint edge in strong noise
//!   scatters more than 1 px, while on clean images the wider bound lets
//!   pieces run round corners (docs/performance.md has the figures). A
//!   piece shorter than `lines.min_length`
//!   between its ends is dropped at once; the others go to `keep_pieces`.
//! - Points carry the peak's parabolic subpixel position across the edge,
//!   its response and noise sigmas, as the tracker's do.

use super::nfa::Nfa;
use super::{Course, STRAY_SCATTER_SQ, TrackPoint, Tracks, keep_pieces, pack};
use crate::edges::peaks::{key_floor, subpixel};
use crate::edges::{NONE, NoiseMap, Response, key};
use crate::fit::LineFit;
use crate::params::LineParams;
use crate::{Point, Segment};

/// Anchors are taken on every this many scan lines.
pub const ANCHOR_EVERY: usize = 4;

/// Points a piece needs before points may end it; the distance (px) from
/// its line beyond which a point is off it; the points off it in a row
/// that end it.
const CUT_AFTER: usize = 8;
const CUT_DISTANCE: f64 = 1.0;
const CUT_RUN: usize = 5;

/// Points of a chain whose slope predicts the position across a gap.
const SLOPE_POINTS: usize = 8;

/// Strength buckets of the anchors (half a noise sigma each).
const BUCKETS: usize = 64;

/// One scan direction's input: its response, noise map and edge points'
/// pixels.
#[derive(Clone, Copy)]
pub struct DrawDir<'a> {
    pub resp: &'a Response,
    pub noise: &'a NoiseMap,
    pub starts: &'a [[u16; 2]],
}

/// Reusable buffers of [`draw_into`].
#[derive(Clone, Debug, Default)]
pub struct DrawScratch {
    planes: [PlaneBufs; 2],
    /// Per response, the pixels a chain on it has drawn.
    drawn: [Drawn; 2],
    /// Anchors packed `dir << 63 | v << 32 | u`, and per bucket counts.
    anchors: Vec<u64>,
    sorted: Vec<u64>,
    counts: Vec<u32>,
    fwd: Vec<TrackPoint>,
    back: Vec<TrackPoint>,
    chain: Vec<TrackPoint>,
    cuts: Vec<std::ops::Range<usize>>,
    tracks: Tracks,
}

/// The per-tile tables of a [`Plane`].
#[derive(Clone, Debug, Default)]
struct PlaneBufs {
    inv_sigma: Vec<f32>,
    thr: Vec<i32>,
    tile_u: Vec<u32>,
    tile_v: Vec<u32>,
}

/// One response read in scan coordinates `(u, v)`, with per tile its
/// `scale / σ` and the largest key that does not pass the tracking level.
struct Plane<'a> {
    sums: &'a [i16],
    scale: f32,
    step_u: usize,
    step_v: usize,
    len_u: usize,
    lines: usize,
    b: PlaneBufs,
}

impl<'a> Plane<'a> {
    fn new(d: &DrawDir<'a>, floor: f64, sigmas: f64, mut b: PlaneBufs) -> Self {
        let (r, noise) = (d.resp, d.noise);
        let (w, h, scale) = (r.width, r.height, r.scale());
        let vertical = r.dir == crate::ScanDir::Vertical;
        let (nx, ny) = noise.tiles();
        b.inv_sigma.clear();
        b.thr.clear();
        for t in 0..nx * ny {
            let sg = noise.sigma(t);
            b.inv_sigma
                .push(if sg > 0.0 { scale / sg } else { f32::INFINITY });
            b.thr
                .push(key_floor((floor as f32).max(sigmas as f32 * sg), scale));
        }
        let (cols, rows) = if vertical {
            (&mut b.tile_v, &mut b.tile_u)
        } else {
            (&mut b.tile_u, &mut b.tile_v)
        };
        noise.columns_into(w, cols);
        rows.clear();
        rows.extend((0..h).map(|y| noise.row_of(y) as u32));
        let (step_u, step_v, len_u, lines) = if vertical { (w, 1, h, w) } else { (1, w, w, h) };
        Plane {
            sums: r.sums(),
            scale,
            step_u,
            step_v,
            len_u,
            lines,
            b,
        }
    }

    #[inline]
    fn tile(&self, u: usize, v: usize) -> usize {
        (self.b.tile_u[u] + self.b.tile_v[v]) as usize
    }

    /// The key at image index `i` if its sign is `positive`'s (0 otherwise
    /// and where there is no response).
    #[inline]
    fn signed_key(&self, i: usize, positive: bool) -> i16 {
        // Negated for the negative polarity, a sum of the other sign is
        // at most 0, and `NONE` (`i16::MIN`) stays itself: no branch.
        let s = self.sums[i];
        if positive { s } else { s.wrapping_neg() }.max(0)
    }

    /// The point at `(u, v)`, image index `i` (`1 ≤ u < len_u − 1`).
    #[inline]
    fn point(&self, u: usize, v: usize, i: usize) -> TrackPoint {
        self.point_in(u, v, i, self.tile(u, v))
    }

    /// [`Plane::point`] with its tile known (inlined: built in place, a
    /// point returned through the stack stalled its copy into the list).
    #[inline(always)]
    fn point_in(&self, u: usize, v: usize, i: usize, tile: usize) -> TrackPoint {
        let at = |j: usize| mag(self.sums[j]);
        let k0 = at(i);
        let d = subpixel(at(i - self.step_u), k0, at(i + self.step_u));
        TrackPoint {
            u: f64::from(u as f32 + d),
            v: v as f64,
            response: f32::from(self.sums[i]) * self.scale,
            z: k0 * self.b.inv_sigma[tile],
            id: i,
        }
    }

    /// The pixel drawn next on scan line `v`, around `u`: the strongest of
    /// `u − 1 ..= u + 1` of the polarity, moved to the peak of the ridge
    /// along the scan if a neighbour is stronger, if it passes the
    /// tracking level (`(u, image index, tile)`).
    #[inline]
    fn step(&self, u: usize, v: usize, positive: bool) -> Option<(usize, usize, usize)> {
        if v >= self.lines || u < 1 || u + 1 >= self.len_u {
            return None;
        }
        let base = v * self.step_v;
        let k = |u: usize| self.signed_key(base + u * self.step_u, positive);
        let (mut best, mut kb) = (u, k(u));
        for c in [u - 1, u + 1] {
            let kc = k(c);
            if kc > kb {
                (best, kb) = (c, kc);
            }
        }
        // Climb to the ridge's peak (at most two pixels).
        for _ in 0..2 {
            if best < 2 || best + 2 >= self.len_u {
                break;
            }
            let (l, r) = (k(best - 1), k(best + 1));
            if l > kb && l >= r {
                (best, kb) = (best - 1, l);
            } else if r > kb {
                (best, kb) = (best + 1, r);
            } else {
                break;
            }
        }
        let tile = self.tile(best, v);
        (i32::from(kb) > self.b.thr[tile]).then_some((best, base + best * self.step_u, tile))
    }
}

/// Segments of an image drawn from its two responses (module doc),
/// appended to `out`: those of the horizontal response in image
/// coordinates like the tracker's. `floor` is the edges' floor `T`,
/// `half_width` the kernel's `A`.
#[allow(clippy::too_many_arguments)]
pub fn draw_into(
    h: DrawDir,
    v: DrawDir,
    floor: f64,
    (half_width, noisy): (usize, bool),
    p: &LineParams,
    out: &mut Vec<Segment>,
    s: &mut DrawScratch,
) {
    let (w, ht) = (h.resp.width, h.resp.height);
    if w < 3 || ht < 3 || !h.resp.covers(w, ht) || !v.resp.covers(w, ht) {
        return;
    }
    let [bh, bv] = std::mem::take(&mut s.planes);
    let planes = [
        Plane::new(&h, floor, p.track_sigmas, bh),
        Plane::new(&v, floor, p.track_sigmas, bv),
    ];
    anchors(h, v, &planes, s);
    for (d, pl) in s.drawn.iter_mut().zip(&planes) {
        d.reset(pl.len_u, pl.lines);
    }
    let nfa = Nfa::new(w, ht, half_width, p.search_width, p.track_sigmas);
    let min_angle = p.min_scan_angle_deg.to_radians();
    let min_sq = p.min_length * p.min_length * (1.0 - 1e-9);
    let gap = p.max_gap.max(1) as usize;
    let sorted = std::mem::take(&mut s.sorted);
    for &a in &sorted {
        let vertical = a >> 63 != 0;
        let (u, line) = ((a & 0xFFFF_FFFF) as usize, (a >> 32 & 0x7FFF_FFFF) as usize);
        let pl = &planes[usize::from(vertical)];
        let i = u * pl.step_u + line * pl.step_v;
        let drawn = &mut s.drawn[usize::from(vertical)];
        if drawn.take(u, line) {
            continue;
        }
        let seed = pl.point(u, line, i);
        let positive = seed.response > 0.0;
        let mut fit = LineFit::new();
        fit.add(Point::new(seed.u, seed.v));
        for (dir, list) in [(1, &mut s.fwd), (-1, &mut s.back)] {
            draw_half(pl, (u, line), dir, positive, gap, drawn, &mut fit, list);
        }
        s.chain.clear();
        s.chain.extend(s.back.iter().rev());
        s.chain.push(seed);
        s.chain.extend(s.fwd.iter());
        cut(&s.chain, noisy, &mut s.cuts);

        for r in s.cuts.drain(..) {
            let piece = &s.chain[r];
            let (a, b) = (piece[0], piece[piece.len() - 1]);
            // `segment_of` refuses it (weak ends only shorten a piece).
            if (b.u - a.u).powi(2) + (b.v - a.v).powi(2) < min_sq {
                continue;
            }
            let t = &mut s.tracks;
            keep_pieces(
                piece,
                t,
                half_width,
                p,
                Some(&nfa),
                min_angle,
                vertical,
                out,
            );
        }
    }
    s.sorted = sorted;
    let [ph, pv] = planes;
    s.planes = [ph.b, pv.b];
}

/// The anchors of both responses, strongest bucket first, into `s.sorted`.
fn anchors(h: DrawDir, v: DrawDir, planes: &[Plane; 2], s: &mut DrawScratch) {
    let (sh, sv) = (h.resp.sums(), v.resp.sums());
    let (kh, kv) = (h.resp.scale(), v.resp.scale());
    let w = h.resp.width;
    s.anchors.clear();
    s.counts.clear();
    s.counts.resize(BUCKETS + 1, 0);
    for (d, dir) in [h, v].iter().enumerate() {
        let vertical = d == 1;
        let pl = &planes[d];
        for &[x, y] in dir.starts {
            let (x, y) = (usize::from(x), usize::from(y));
            let (u, line) = if vertical { (y, x) } else { (x, y) };
            if line % ANCHOR_EVERY != 0 || u < 1 || u + 1 >= pl.len_u {
                continue;
            }
            let i = y * w + x;
            let (eh, ev) = (mag(sh[i]) * kh, mag(sv[i]) * kv);
            // The dominant response draws the pixel.
            if (eh >= ev) == vertical {
                continue;
            }
            let z = mag(pl.sums[i]) * pl.b.inv_sigma[pl.tile(u, line)];
            let b = ((2.0 * z) as usize).min(BUCKETS - 1);
            s.counts[BUCKETS - b] += 1;
            s.anchors
                .push(pack(u, line) | u64::from(vertical) << 63 | (b as u64) << 56);
        }
    }
    // Counting sort, strongest bucket first, stable (scan order within).
    for k in 0..BUCKETS {
        s.counts[k + 1] += s.counts[k];
    }
    s.sorted.clear();
    s.sorted.resize(s.anchors.len(), 0);
    for &a in &s.anchors {
        let b = (a >> 56 & 0x3F) as usize;
        let k = &mut s.counts[BUCKETS - 1 - b];
        s.sorted[*k as usize] = a & !(0x3F << 56);
        *k += 1;
    }
}

/// `|E|` of a sum in units, 0 where there is none.
fn mag(s: i16) -> f32 {
    if s == NONE { 0.0 } else { f32::from(key(s)) }
}

/// Draws from the anchor at `at` in direction `dir` (+1 or −1 scan
/// lines) into `list`, adding each point to `fit` (the chain's, both
/// ways); `drawn` is the response's.
#[allow(clippy::too_many_arguments)]
fn draw_half(
    pl: &Plane,
    at: (usize, usize),
    dir: i64,
    positive: bool,
    gap: usize,
    drawn: &mut Drawn,
    fit: &mut LineFit,
    list: &mut Vec<TrackPoint>,
) {
    list.clear();
    let (mut pix, mut v) = at;
    let mut u = pix as f64;
    loop {
        // An established chain steps around its fitted line's prediction
        // and skips a stray pixel, or one drawn before, as a gap (the
        // tracker's rule, `Course`); a young one around its last pixel.
        let course = Course::of(fit).filter(Course::established);
        let mut found = None;
        for i in 1..=gap as i64 {
            let next = v as i64 + dir * i;
            if next < 0 || next as usize >= pl.lines {
                break;
            }
            let next = next as usize;
            let c = if let Some(k) = &course {
                let pred = k.predict(next as f64);
                if !(pred >= 1.0 && pred < (pl.len_u - 1) as f64) {
                    break;
                }
                pred.round() as usize
            } else if i == 1 {
                pix
            } else {
                let pred = u + slope(list, u, v) * (next as f64 - v as f64);
                if !(pred >= 1.0 && pred < (pl.len_u - 1) as f64) {
                    break;
                }
                pred.round() as usize
            };
            if let Some(q) = pl.step(c, next, positive) {
                let off =
                    |k: &Course| drawn.has(q.0, next) || k.is_stray(fit, q.0 as f64, next as f64);
                if course.as_ref().is_some_and(off) {
                    continue;
                }
                found = Some((q, next));
                break;
            }
        }
        let Some(((np, i, tile), nv)) = found else {
            break;
        };
        if drawn.take(np, nv) {
            break;
        }
        let q = pl.point_in(np, nv, i, tile);
        (pix, u, v) = (np, q.u, nv);
        fit.add(Point::new(q.u, q.v));
        list.push(q);
    }
}

/// The pixels of one response drawn by its chains, a bit each, scan
/// line by scan line (small enough that a step's test stays in
/// cache).
#[derive(Clone, Debug, Default)]
struct Drawn {
    /// Words a scan line.
    wpl: usize,
    bits: Vec<u64>,
}

impl Drawn {
    /// None drawn, on `lines` scan lines of `len_u` pixels.
    fn reset(&mut self, len_u: usize, lines: usize) {
        self.wpl = len_u.div_ceil(64);
        self.bits.clear();
        self.bits.resize(self.wpl * lines, 0);
    }

    /// Whether `(u, v)` was drawn.
    #[inline]
    fn has(&self, u: usize, v: usize) -> bool {
        self.bits[v * self.wpl + u / 64] & 1u64 << (u % 64) != 0
    }

    /// Whether `(u, v)` was drawn; it is now.
    #[inline]
    fn take(&mut self, u: usize, v: usize) -> bool {
        let (w, b) = (&mut self.bits[v * self.wpl + u / 64], 1u64 << (u % 64));
        let was = *w & b != 0;
        *w |= b;
        was
    }
}

/// The slope `du/dv` of the last [`SLOPE_POINTS`] points of `list`, whose
/// last is at `(u, v)` (0 with fewer than two).
fn slope(list: &[TrackPoint], u: f64, v: usize) -> f64 {
    let k = list.len().min(SLOPE_POINTS);
    if k < 2 {
        return 0.0;
    }
    let q = &list[list.len() - k];
    let dv = v as f64 - q.v;
    if dv == 0.0 { 0.0 } else { (u - q.u) / dv }
}

/// The straight pieces of a chain (module doc), as ranges into `chain`;
/// `noisy`: the image is, and the piece's own scatter widens the limit.
fn cut(chain: &[TrackPoint], noisy: bool, out: &mut Vec<std::ops::Range<usize>>) {
    out.clear();
    let Some(o) = chain.first() else { return };
    let (u0, v0) = (o.u, o.v);
    let mut start = 0;
    // Sums of the piece's points kept in its line: n, v, u, vv, vu, uu.
    let mut f = [0f64; 6];
    let add = |f: &mut [f64; 6], q: &TrackPoint| {
        let (u, v) = (q.u - u0, q.v - v0);
        f[0] += 1.0;
        f[1] += v;
        f[2] += u;
        f[3] += v * v;
        f[4] += v * u;
        f[5] += u * u;
    };
    let mut run = 0;
    for (j, q) in chain.iter().enumerate() {
        if f[0] >= CUT_AFTER as f64 {
            let den = f[0] * f[3] - f[1] * f[1];
            let b = if den > 0.0 {
                (f[0] * f[4] - f[1] * f[2]) / den
            } else {
                0.0
            };
            let a = (f[2] - b * f[1]) / f[0];
            let d = (q.u - u0 - a - b * (q.v - v0)).abs();
            let lim = if noisy {
                let rss = (f[5] - a * f[2] - b * f[4]).max(0.0);
                (CUT_DISTANCE * CUT_DISTANCE).max(STRAY_SCATTER_SQ * rss / f[0])
            } else {
                CUT_DISTANCE * CUT_DISTANCE
            };
            if d * d > lim * (1.0 + b * b) {
                run += 1;
                if run >= CUT_RUN {
                    let first = j + 1 - run;
                    out.push(start..first);
                    start = first;
                    f = [0.0; 6];
                    for q in &chain[first..=j] {
                        add(&mut f, q);
                    }
                    run = 0;
                }
                continue;
            }
        }
        run = 0;
        add(&mut f, q);
    }
    out.push(start..chain.len());
}

#[cfg(test)]
pub(crate) mod tests;
