//! The edge points of the kept candidates: their subpixel positions and
//! responses, a batch of candidates at a time.
//!
//! A photograph has tens of thousands of edge points a direction. Made a
//! point at a time from the response, each read its sum and its two
//! neighbours' again after the scan had passed (rows long out of the
//! cache), the parabola's division waited on those loads and each push
//! checked its capacity. Here a candidate carries what its point needs
//! (its sum and its neighbours' keys, taken by the scan from the rows at
//! hand), the parabolas of a batch run as one loop the compiler
//! vectorises (AVX2 where the processor has it, chosen at run time), and
//! the points and starts are appended by length-exact iterators. The
//! operations and their order are those of [`subpixel`](super::subpixel),
//! so the positions are the same to the bit.
//!
//! Also here: whether a region can hold more than `M` candidates at all.
//! Two neighbours along the scan are never both peaks (a peak is above the
//! one before it and at least the one after), so a region of `L` scan
//! lines of `n` positions has at most `L·⌈n/2⌉`; when that is at most `M`
//! every candidate is kept and the per-region count is not needed.

use super::{Peak, PeakScratch, Shape, Starts, placed, response_of, subpixel};
use crate::params::EdgeParams;
use crate::{EdgePoints, ScanDir};

/// Candidates a batch.
const BATCH: usize = 64;

/// Whether some region of a response of this shape can have more than
/// `M` candidates (module doc): if not, every candidate is an edge point.
pub(super) fn crowdable(shape: Shape, p: &EdgeParams) -> bool {
    let rl = p.region_lines.max(1) as usize;
    let m = p.per_region.max(1) as usize;
    let n = match shape.dir {
        ScanDir::Horizontal => shape.w,
        ScanDir::Vertical => shape.h,
    };
    rl.saturating_mul(n.div_ceil(2)) > m
}

/// The edge points of the candidates `cs`, appended to `out` and their
/// pixels to `starts`, in their order.
pub(super) fn emit(
    shape: Shape,
    scale: f32,
    cs: &[Peak],
    out: &mut EdgePoints,
    starts: &mut Starts,
) {
    out.points.reserve(cs.len());
    starts.reserve(cs.len());
    let (mut em, mut e0, mut ep) = ([0f32; BATCH], [0f32; BATCH], [0f32; BATCH]);
    let (mut d, mut resp) = ([0f32; BATCH], [0f32; BATCH]);
    for chunk in cs.chunks(BATCH) {
        for (k, c) in chunk.iter().enumerate() {
            em[k] = f32::from(c.lo);
            e0[k] = f32::from(c.key);
            ep[k] = f32::from(c.hi);
            resp[k] = response_of(c, scale);
        }
        subpixels(&em, &e0, &ep, &mut d);
        out.points.extend(
            chunk
                .iter()
                .zip(&d)
                .zip(&resp)
                .map(|((c, &d), &r)| placed(c, d, r, shape)),
        );
        starts.extend(chunk.iter().map(|c| [c.x, c.y]));
    }
}

/// [`subpixel`] of every position of a batch: one loop of selects the
/// compiler vectorises.
#[multiversion::multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt", "x86_64+sse4.1"))]
fn subpixels(em: &[f32; BATCH], e0: &[f32; BATCH], ep: &[f32; BATCH], d: &mut [f32; BATCH]) {
    for k in 0..BATCH {
        d[k] = subpixel(em[k], e0[k], ep[k]);
    }
}

/// Per region, the smallest key kept: 0 where it has at most `m`
/// candidates, else its `m`-th largest key.
pub(super) fn region_limits(
    cand: &[Peak],
    nreg: usize,
    m: usize,
    region: impl Fn(&Peak) -> usize,
    s: &mut PeakScratch,
) {
    s.count.clear();
    s.count.resize(nreg, 0);
    s.lim.clear();
    s.lim.resize(nreg, 0);
    for c in cand {
        s.count[region(c)] += 1;
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
    s.fill.clone_from(&s.start);
    for c in cand {
        let r = region(c);
        if s.count[r] as usize > m {
            s.grouped[s.fill[r] as usize] = c.key;
            s.fill[r] += 1;
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
