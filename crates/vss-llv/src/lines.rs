//! The line extractor: follows edges from scan line to scan line, predicting
//! the next point from the least-squares line of the points found so far
//! (llv.md §3), splits a track where two edges were joined, and keeps the
//! segments that noise alone would not make.
//!
//! The extractor works in *scan coordinates* `(u, v)`: `u` runs along the
//! scan, `v` counts scan lines. For `EdgeH` that is `(x, y)`; for `EdgeV` it
//! is `(y, x)` — "swap x and y" of §3.
//!
//! The method, and where it leaves §3:
//! - **Starts** are the edge points (`edges/peaks.rs`: peaks above
//!   `edges.noise_sigmas` noise sigmas), taken at the pixels the edge pass
//!   found them at, in lexical order of the scan frame; one already taken
//!   by a track is skipped.
//! - **Points** a track takes are peaks of the start's polarity above
//!   `lines.track_sigmas` noise sigmas — fewer sigmas than a start needs, so
//!   a weak edge is followed once it is found. In the pipeline they are the
//!   bits of the peak map the edge pass made in the same pass as the starts
//!   ([`PeakMap`], [`source::ResponsePeaks`]): a search window is a word of
//!   it, and a point's subpixel position, response and noise sigmas are
//!   read from the response only for the peaks in the window. From edge
//!   points alone ([`extract`]: edge files) every point is a candidate.
//! - **First step**: the strongest peak of the polarity on the next scan line
//!   within `search_width + cot(min_scan_angle)` (every slope the angle test
//!   admits), else on the next `max_gap` lines; no successor at all, no
//!   track. (§3.1's templates gave the same start for a fraction of the
//!   cost only because most starts were noise.)
//! - **Following**: on each of the next `max_gap` scan lines the unused
//!   peak nearest the prediction within `±search_width`; the prediction comes
//!   from the track's fitted line once it has two points (not from the last
//!   point, which lets tracks bend round corners); the slope is clamped to
//!   ±8 (7° from the scan). A track is followed forwards, then backwards from
//!   its start. Once a track has 8 points, a peak more than 1.5 px off its
//!   line, and more than 3 times the RMS distance of the track's points
//!   from it, is not taken (a stray noise peak is skipped like a missing
//!   point; where the edge turns the track ends after `max_gap` lines of
//!   them). The second bound is the track's own scatter: a faint edge in
//!   strong noise has points 0.5 px and more off its line, and a fixed
//!   1.5 px ended it at the first wide one (docs/llv.md, "Measurements
//!   behind the design").
//! - **Splitting** (`split.rs`): where two straight pieces fit the points
//!   significantly better than one line, the track is cut there.
//! - **Validation** (`nfa.rs`): a piece is kept when its number of false
//!   alarms is below `10^lines.log_nfa` — how many pieces as good noise alone
//!   would give in the image. This replaces the fixed `min_response` (kept,
//!   off by default) and needs no tuning per scene. Without a noise scale
//!   (edge points alone) the test cannot be made and is skipped.
//! - A piece must also be longer than `min_length` and further than
//!   `min_scan_angle` from the scan direction (§3). It runs from the
//!   projection of its first point to that of its last; `response` is the
//!   mean signed response of its points, `residual` their RMS distance from
//!   the line.

pub mod align;
pub mod draw;
pub mod nfa;
pub mod source;
mod split;
pub mod step;

use super::edges::band::PixelSums;
use super::edges::{NoiseMap, PeakMap, PeakScratch, Response};
use super::fit::LineFit;
use super::params::LineParams;
use super::{EdgePoints, Point, ScanDir, Segment};
use source::{Cand, Peaks, PointBufs, ResponseBufs, ResponsePeaks, SumAt};

/// Largest `|du/dv|` used for the prediction.
const MAX_SLOPE: f64 = 8.0;

/// Scan lines trimmed from each end of a piece before its line is fitted
/// (`segment_of`) when the kernel's half-width is not known: the default
/// `A`.
const DEFAULT_TRIM: usize = 4;

/// Points a track needs before the stray-point test applies; the distance
/// (px) from its fitted line beyond which a next point is a stray one, and
/// the square of the multiple of the track's RMS residual that widens it.
const STRAY_AFTER: usize = 8;
const STRAY_DISTANCE: f64 = 1.5;
const STRAY_SCATTER_SQ: f64 = 9.0;

/// A point of a track in scan coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackPoint {
    pub u: f64,
    pub v: f64,
    pub response: f32,
    /// Noise sigmas of the point's response (NaN: unknown).
    pub z: f32,
    /// The point's identity in its source.
    pub id: usize,
}

impl TrackPoint {
    fn of(c: &Cand) -> Self {
        TrackPoint {
            u: c.u,
            v: c.v as f64,
            response: c.response,
            z: c.z,
            id: c.id,
        }
    }
}

/// Reusable buffers of the extractor.
#[derive(Clone, Debug, Default)]
pub struct LineScratch {
    response: ResponseBufs,
    points: PointBufs,
    seeds: Vec<u64>,
    /// The counting sort's column counts.
    order: Vec<u32>,
    tracks: Tracks,
    /// The peak map, when the one given does not fit the parameters.
    map: PeakMap,
    peaks: PeakScratch,
}

/// Segments of one edge-point set alone (edge files): every point is a
/// candidate and no noise scale is known.
pub fn extract(e: &EdgePoints, p: &LineParams) -> Vec<Segment> {
    let mut out = Vec::new();
    extract_into(e, p, &mut out, &mut LineScratch::default());
    out
}

/// [`extract`] into reusable buffers (`out` is cleared first).
pub fn extract_into(e: &EdgePoints, p: &LineParams, out: &mut Vec<Segment>, s: &mut LineScratch) {
    out.clear();
    let vertical = e.dir == Some(ScanDir::Vertical);
    s.points.file(e);
    let mut src = s.points.peaks();
    s.seeds.clear();
    s.seeds.extend(0..src.len() as u64);
    follow(
        &mut src,
        s.seeds.iter().copied(),
        p,
        None,
        DEFAULT_TRIM,
        vertical,
        &mut s.tracks,
        out,
    );
}

/// Segments of one scan direction of an image: the pipeline's extractor.
/// `seeds` are the direction's edge points (`edges::detect_into`) and
/// `starts` their pixels (as it gives them; when they do not match the
/// points, each point's pixel is found again), `noise` its noise map,
/// `map` its peak map (made again here unless it holds the peaks above
/// `floor` and `p.track_sigmas`), `floor` the edges' floor `T`,
/// `half_width` the kernel's `A`.
#[allow(clippy::too_many_arguments)]
pub fn track_into(
    resp: &Response,
    noise: &NoiseMap,
    map: &PeakMap,
    seeds: &EdgePoints,
    starts: &[[u16; 2]],
    floor: f64,
    half_width: usize,
    p: &LineParams,
    out: &mut Vec<Segment>,
    s: &mut LineScratch,
) {
    out.clear();
    let (w, h) = (resp.width, resp.height);
    if w < 3 || h < 3 || !resp.covers(w, h) {
        return;
    }
    let vertical = resp.dir == ScanDir::Vertical;
    let mut own = std::mem::take(&mut s.map);
    let map = if map.fits(resp, floor, p.track_sigmas) {
        map
    } else {
        own.build_into(resp, noise, floor, p.track_sigmas, &mut s.peaks);
        &own
    };
    let src = ResponsePeaks::new(resp, noise, map, &mut s.response);
    track_from(src, (w, h), vertical, seeds, starts, half_width, p, out, s);
    s.map = own;
}

/// [`track_into`] on a response read at its pixels ([`PixelSums`]), with
/// the peak map the edge pass made of it at `p.track_sigmas`
/// (`edges::peaks::strips::detect_strips`), which the tracks use up, and
/// the starts it gave with `seeds`, which a vertical scan puts in column
/// order. Nothing the size of the seeds is made: on a texture there are
/// millions.
#[allow(clippy::too_many_arguments)]
pub(crate) fn track_pixels(
    sums: PixelSums,
    noise: &NoiseMap,
    map: PeakMap,
    seeds: &EdgePoints,
    starts: &mut [[u16; 2]],
    half_width: usize,
    p: &LineParams,
    out: &mut Vec<Segment>,
    s: &mut LineScratch,
) {
    out.clear();
    let (w, h, vertical) = (sums.w, sums.h, sums.dir == ScanDir::Vertical);
    if w < 3 || h < 3 {
        return;
    }
    let mut src = ResponsePeaks::of_pixels(sums, noise, map, &mut s.response);
    if starts.len() != seeds.points.len() {
        track_from(src, (w, h), vertical, seeds, &[], half_width, p, out, s);
        return;
    }
    // Scan order: image order along a horizontal scan, columns then rows
    // along a vertical one (each pixel once).
    if vertical {
        starts.sort_unstable_by_key(|&[x, y]| (x, y));
    }
    let scan = |&[x, y]: &[u16; 2]| {
        let (x, y) = (usize::from(x), usize::from(y));
        if vertical { (y, x) } else { (x, y) }
    };
    // Which starts are in the map, before tracks clear it: bit 63.
    let flags: Vec<u64> = starts
        .chunks(64)
        .map(|c| {
            c.iter().enumerate().fold(0u64, |b, (k, st)| {
                let (u, v) = scan(st);
                b | u64::from(src.in_map(u, v)) << k
            })
        })
        .collect();
    let ids = starts.iter().enumerate().map(|(k, st)| {
        let (u, v) = scan(st);
        pack(u, v) | (flags[k / 64] >> (k % 64) & 1) << 63
    });
    let nfa = nfa::Nfa::new(w, h, half_width, p.search_width, p.track_sigmas);
    follow(
        &mut src,
        ids,
        p,
        Some(&nfa),
        half_width,
        vertical,
        &mut s.tracks,
        out,
    );
    src.finish(&mut s.response);
}

/// The tracks of [`track_into`] from the peaks of `src`, a `size` response.
#[allow(clippy::too_many_arguments)]
fn track_from<S: SumAt>(
    mut src: ResponsePeaks<S>,
    size: (usize, usize),
    vertical: bool,
    seeds: &EdgePoints,
    starts: &[[u16; 2]],
    half_width: usize,
    p: &LineParams,
    out: &mut Vec<Segment>,
    s: &mut LineScratch,
) {
    let (w, h) = size;
    // Seeds are scan positions, packed `v << 32 | u`, in scan order.
    s.seeds.clear();
    if starts.len() == seeds.points.len() {
        // The starts are in image order, which is the horizontal scan's; a
        // vertical scan's are put in column order by a counting sort on
        // the column (stable, so rows stay ascending).
        if vertical {
            s.order.clear();
            s.order.resize(w + 1, 0);
            for &[x, _] in starts {
                s.order[usize::from(x) + 1] += 1;
            }
            for x in 0..w {
                s.order[x + 1] += s.order[x];
            }
            s.seeds.resize(starts.len(), 0);
            for &[x, y] in starts {
                let k = &mut s.order[usize::from(x)];
                s.seeds[*k as usize] = pack(usize::from(y), usize::from(x));
                *k += 1;
            }
        } else {
            s.seeds.extend(
                starts
                    .iter()
                    .map(|&[x, y]| pack(usize::from(x), usize::from(y))),
            );
        }
    } else {
        for e in &seeds.points {
            let (u, v) = if vertical { (e.y, e.x) } else { (e.x, e.y) };
            let r = (v + 0.5).floor();
            if !(u.is_finite() && r >= 0.0 && (r as usize) < src.lines()) {
                continue;
            }
            // The seed's pixel: the peak at or next to its position.
            if let Some(c) = src.strongest(r as usize, f64::from(u), 0.5, e.response > 0.0) {
                s.seeds.push(pack(c.pix as usize, c.v));
            }
        }
        s.seeds.sort_unstable();
    }
    s.seeds.dedup();
    let nfa = nfa::Nfa::new(w, h, half_width, p.search_width, p.track_sigmas);
    follow(
        &mut src,
        s.seeds.iter().copied(),
        p,
        Some(&nfa),
        half_width,
        vertical,
        &mut s.tracks,
        out,
    );
    src.finish(&mut s.response);
}

/// The per-track buffers.
#[derive(Clone, Debug, Default)]
struct Tracks {
    fwd: Vec<TrackPoint>,
    back: Vec<TrackPoint>,
    chain: Vec<TrackPoint>,
    split: split::SplitScratch,
    z: Vec<f32>,
}

/// Follows a track from every start not yet taken, and keeps its pieces.
#[allow(clippy::too_many_arguments)]
fn follow<P: Peaks>(
    src: &mut P,
    seeds: impl IntoIterator<Item = u64>,
    p: &LineParams,
    nfa: Option<&nfa::Nfa>,
    trim: usize,
    vertical: bool,
    t: &mut Tracks,
    out: &mut Vec<Segment>,
) {
    let sw = if p.search_width.is_finite() {
        p.search_width.max(0.0)
    } else {
        0.0
    };
    let min_angle = p.min_scan_angle_deg.to_radians();
    // Every slope the angle test admits, for the first step.
    let steep = (1.0 / min_angle.clamp(1e-3, std::f64::consts::FRAC_PI_2).tan()).min(MAX_SLOPE);
    let gap = p.max_gap.max(1) as usize;
    for id in seeds {
        if src.is_taken(id) {
            continue;
        }
        let Some(seed) = src.seed(id) else {
            continue;
        };
        let seed = &seed;
        src.take(seed);
        let positive = seed.response > 0.0;
        t.fwd.clear();
        t.back.clear();
        let mut fit = LineFit::new();
        fit.add_finite(Point::new(seed.u, seed.v as f64));
        // The first step fixes the initial slope.
        let mut slope = None;
        for (dir, list) in [(1i64, &mut t.fwd), (-1, &mut t.back)] {
            for i in 1..=gap {
                let Some(v) = line_at(seed.v, dir * i as i64, src.lines()) else {
                    break;
                };
                let reach = sw + i as f64 * steep;
                if let Some(c) = src.strongest(v, seed.u, reach, positive) {
                    src.take(&c);
                    fit.add_finite(Point::new(c.u, c.v as f64));
                    list.push(TrackPoint::of(&c));
                    slope = Some((c.u - seed.u) / (dir * i as i64) as f64);
                    break;
                }
            }
            if slope.is_some() {
                break;
            }
        }
        let Some(slope) = slope else { continue };
        let seed_point = TrackPoint::of(seed);
        let last_fwd = t.fwd.last().copied().unwrap_or(seed_point);
        walk(
            src, &mut fit, last_fwd, 1, slope, positive, sw, gap, &mut t.fwd,
        );
        let last_back = t.back.last().copied().unwrap_or(seed_point);
        walk(
            src,
            &mut fit,
            last_back,
            -1,
            slope,
            positive,
            sw,
            gap,
            &mut t.back,
        );
        t.chain.clear();
        t.chain.extend(t.back.iter().rev());
        t.chain.push(seed_point);
        t.chain.extend(t.fwd.iter());
        let chain = std::mem::take(&mut t.chain);
        keep_pieces(&chain, t, trim, p, nfa, min_angle, vertical, out);
        t.chain = chain;
    }
}

/// A scan position `(u, v)` as one seed: `v << 32 | u` (scan order is
/// numeric order).
fn pack(u: usize, v: usize) -> u64 {
    (v as u64) << 32 | u as u64
}

/// Scan line `v + d`, if it is one.
fn line_at(v: usize, d: i64, lines: usize) -> Option<usize> {
    let r = v as i64 + d;
    (r >= 0 && (r as usize) < lines).then_some(r as usize)
}

/// Follows a track from `last` in direction `dir` (+1 or −1 scan lines),
/// adding each point to `fit` and `list`.
#[allow(clippy::too_many_arguments)]
fn walk<P: Peaks>(
    src: &mut P,
    fit: &mut LineFit,
    last: TrackPoint,
    dir: i64,
    first_slope: f64,
    positive: bool,
    sw: f64,
    gap: usize,
    list: &mut Vec<TrackPoint>,
) {
    let lines = src.lines();
    let (mut last_u, mut last_v) = (last.u, last.v as usize);
    loop {
        let course = Course::of(fit);
        let mut found = None;
        for i in 1..=gap {
            let Some(v) = line_at(last_v, dir * i as i64, lines) else {
                break;
            };
            let pred = match &course {
                Some(k) => k.predict(v as f64),
                _ => last_u + (v as f64 - last_v as f64) * first_slope,
            };
            if !pred.is_finite() {
                break;
            }
            let Some(c) = src.nearest(v, pred, sw, positive) else {
                continue;
            };
            if course.is_some_and(|k| k.is_stray(fit, c.u, c.v as f64)) {
                continue;
            }
            found = Some(c);
            break;
        }
        let Some(c) = found else { break };
        src.take(&c);
        fit.add_finite(Point::new(c.u, c.v as f64));
        // (Only the position is kept: a copy of the whole point read back
        // at once stalled on the stores that made it.)
        (last_u, last_v) = (c.u, c.v);
        list.push(TrackPoint::of(&c));
    }
}

/// A track's line as its points give it: the prediction of its next point
/// and the test of a stray one (module doc, "Following"). The tracker and
/// the drawing front end (`draw.rs`) both follow an edge by it.
#[derive(Clone, Copy)]
pub(crate) struct Course {
    mean: Point,
    axis: (f64, f64),
    slope: f64,
    /// The fixed stray bound times `|axis|²`, once the track has
    /// [`STRAY_AFTER`] points.
    stray: Option<f64>,
}

impl Course {
    /// The course of the points in `fit` (none before two).
    #[inline]
    pub(crate) fn of(fit: &LineFit) -> Option<Course> {
        let (mean, (du, dv)) = fit.mean_and_axis()?;
        let slope = if dv.abs() * MAX_SLOPE > du.abs() {
            du / dv
        } else {
            MAX_SLOPE * du.signum() * dv.signum()
        };
        let stray = (fit.len() >= STRAY_AFTER)
            .then_some(STRAY_DISTANCE * STRAY_DISTANCE * (du * du + dv * dv));
        Some(Course {
            mean,
            axis: (du, dv),
            slope,
            stray,
        })
    }

    /// The position along the scan predicted on scan line `v`.
    #[inline]
    pub(crate) fn predict(&self, v: f64) -> f64 {
        self.mean.x + (v - self.mean.y) * self.slope
    }

    /// Whether the track is established (the stray test applies).
    #[inline]
    pub(crate) fn established(&self) -> bool {
        self.stray.is_some()
    }

    /// Whether a point at `(u, v)` is off the line of an established
    /// track: beyond both `STRAY_DISTANCE` and 3 RMS residuals of `fit`
    /// (the residual computed only for a point beyond the fixed bound; the
    /// distance, `|cross| / |axis|`, compared squared).
    #[inline]
    pub(crate) fn is_stray(&self, fit: &LineFit, u: f64, v: f64) -> bool {
        let Some(lim) = self.stray else { return false };
        let (du, dv) = self.axis;
        let cross = (u - self.mean.x) * dv - (v - self.mean.y) * du;
        cross * cross > lim
            && cross * cross > STRAY_SCATTER_SQ * fit.mean_square_residual() * (du * du + dv * dv)
    }
}

/// Splits a track (points in scan-line order) where it joins two edges and
/// keeps the pieces that pass the tests of the module doc.
/// `t` gives the buffers (its `chain` is not read).
#[allow(clippy::too_many_arguments)]
fn keep_pieces(
    chain: &[TrackPoint],
    t: &mut Tracks,
    trim: usize,
    p: &LineParams,
    nfa: Option<&nfa::Nfa>,
    min_angle: f64,
    vertical: bool,
    out: &mut Vec<Segment>,
) {
    if too_short(chain, p.min_length) {
        return;
    }
    let chain = trim_weak_ends(chain, &mut t.z);
    if chain.len() < 2 {
        return;
    }
    split::pieces(chain, trim, &mut t.split);
    for r in t.split.ranges() {
        let piece = &chain[r.clone()];
        if let Some(s) = segment_of(piece, p, nfa, trim, min_angle, vertical, &mut t.z) {
            out.push(s);
        }
    }
}

/// Whether no piece of a track (points in scan-line order) can pass the
/// length test of [`segment_of`]: each piece's `|du|` is at most the
/// track's spread in `u` and its `|dv|` at most the track's (rounding is
/// monotone, so the bound computed the same way bounds what it computes).
fn too_short(chain: &[TrackPoint], min_length: f64) -> bool {
    let (Some(first), Some(last)) = (chain.first(), chain.last()) else {
        return true;
    };
    let dv = last.v - first.v;
    let limit = min_length * min_length * (1.0 - 1e-9);
    if !(min_length > 0.0 && dv * dv < limit) {
        return false;
    }
    let (lo, hi) = chain
        .iter()
        .fold((first.u, first.u), |(lo, hi), q| (lo.min(q.u), hi.max(q.u)));
    let du = hi - lo;
    du * du + dv * dv < limit
}

/// Points near an end whose responses set the edge's level there.
const END_LEVEL_POINTS: usize = 32;

/// A track less the points at each end whose response is below half
/// the edge's level near that end (the median `|E|` of the
/// [`END_LEVEL_POINTS`] points nearest it): where the edge ends, a track
/// runs on over noise peaks or the flank of the next edge for a scan line
/// or two, and the edge itself ends where its response falls to half.
fn trim_weak_ends<'a>(chain: &'a [TrackPoint], buf: &mut Vec<f32>) -> &'a [TrackPoint] {
    let chain = &chain[weak_run(chain.iter(), buf)..];
    &chain[..chain.len() - weak_run(chain.iter().rev(), buf)]
}

/// How many points from the end that `pts` starts at are below half the
/// edge's level there ([`trim_weak_ends`]).
fn weak_run<'a>(pts: impl Iterator<Item = &'a TrackPoint> + Clone, buf: &mut Vec<f32>) -> usize {
    buf.clear();
    buf.extend(pts.clone().take(END_LEVEL_POINTS).map(|q| q.response.abs()));
    let Some(&first) = buf.first() else {
        return 0;
    };
    // Mostly the end point itself is at the level: it is kept, and the
    // median is not needed. Halving is monotone, so half the median is at
    // most `first` exactly when more than `mid` of the magnitudes, halved,
    // are (a NaN, last in `total_cmp`'s order, is never at most `first`).
    let mid = buf.len() / 2;
    if buf.iter().filter(|&&m| 0.5 * m <= first).count() > mid {
        return 0;
    }
    let half = 0.5 * *buf.select_nth_unstable_by(mid, f32::total_cmp).1;
    pts.take_while(|q| q.response.abs() < half).count()
}

/// The segment of a piece of track, if it passes the tests.
///
/// Its line is fitted to the piece's points less `trim` scan lines at each
/// end (fewer for a piece of under `4 trim + 8` points): there the
/// response of an edge meeting this one bends the points, and a fit to
/// all of them tilts the line (on the tuning scenes, endpoint distances
/// from the true lines fall from 0.089 px to 0.043 px at noise σ 2 with
/// `trim` = A = 4). The segment still runs from its first point to its
/// last, projected onto that line.
#[allow(clippy::too_many_arguments)]
fn segment_of(
    piece: &[TrackPoint],
    p: &LineParams,
    nfa: Option<&nfa::Nfa>,
    trim: usize,
    min_angle: f64,
    vertical: bool,
    z: &mut Vec<f32>,
) -> Option<Segment> {
    let (first, last) = (piece.first()?, piece.last()?);
    let (du, dv) = (last.u - first.u, last.v - first.v);
    // Projection never lengthens a segment.
    if p.min_length > 0.0 && du * du + dv * dv < p.min_length * p.min_length * (1.0 - 1e-9) {
        return None;
    }
    let resp: f64 = piece.iter().map(|q| f64::from(q.response)).sum::<f64>() / piece.len() as f64;
    if resp.abs() < p.min_response {
        return None;
    }
    if let Some(nfa) = nfa {
        z.clear();
        z.extend(piece.iter().map(|q| q.z));
        let n = (last.v - first.v).abs() as usize + 1;
        if !nfa.significant(n, z, p.log_nfa) {
            return None;
        }
    }
    let trim = trim.min(piece.len().saturating_sub(8) / 4) as f64;
    let mut fit = LineFit::new();
    for q in piece {
        if q.v >= first.v + trim && q.v <= last.v - trim {
            fit.add_finite(Point::new(q.u, q.v));
        }
    }
    let line = fit.line()?;
    let a = line.project(Point::new(first.u, first.v));
    let b = line.project(Point::new(last.u, last.v));
    let long = a.dist(b) > p.min_length;
    if !long {
        return None;
    }
    let scan_angle = line.a.abs().atan2(line.b.abs());
    if scan_angle <= min_angle {
        return None;
    }
    let swap = |q: Point| if vertical { Point::new(q.y, q.x) } else { q };
    Some(Segment {
        a: swap(a),
        b: swap(b),
        response: resp,
        residual: fit.rms_residual(),
        shadow: false,
    })
}

#[cfg(test)]
mod tests;
