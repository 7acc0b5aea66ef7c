//! [`detect_into`](super::detect_into) on a response made a strip of rows
//! at a time (`edges/band.rs`): the same noise map, peak map, edge points
//! and starts, without the whole response.

use super::super::band::{PixelSums, Strips};
use super::{
    Peak, PeakMap, PeakScratch, Shape, Starts, Thresholds, point_of, regions, scan_rows,
    tile_floors,
};
use crate::edges::NoiseMap;
use crate::params::EdgeParams;
use crate::{EdgePoints, GreyImage, LlvError, ScanDir};

/// Rows of a strip of the peak pass.
const STRIP: usize = 64;

/// The noise map, peak map (peaks above `p.floor` and `track_sigmas`),
/// edge points and starts of `img`'s response along `dir` with half-width
/// `a`, as [`detect_into`](super::detect_into) makes them of the whole
/// response; returns the response, to be read at pixels. The candidates'
/// buffer is freed.
#[allow(clippy::too_many_arguments)]
pub fn detect_strips<'a>(
    img: &'a GreyImage,
    dir: ScanDir,
    a: usize,
    p: &EdgeParams,
    track_sigmas: f64,
    noise: &mut NoiseMap,
    map: &mut PeakMap,
    out: &mut EdgePoints,
    starts: &mut Starts,
    s: &mut PeakScratch,
) -> Result<PixelSums<'a>, LlvError> {
    let src = PixelSums::new(img, dir, a)?;
    let (w, h, scale) = (src.w, src.h, src.scale());
    let mut ns = std::mem::take(&mut s.noise);
    noise.estimate_rows(w, h, scale, &mut Strips::new(src), &mut ns);
    noise.bound(p.noise_percentile, p.noise_cap, &mut ns);
    s.noise = ns;
    let shape = Shape { w, h, dir };
    map.reset_for(shape, p.floor, track_sigmas);
    out.dir = Some(dir);
    out.width = w;
    out.height = h;
    out.points.clear();
    starts.clear();
    s.cand.clear();
    if w < 3 || h < 3 || p.floor.is_nan() {
        return Ok(src);
    }
    tile_floors(scale, noise, p.floor, p.noise_sigmas, &mut s.thr);
    tile_floors(scale, noise, map.floor, map.sigmas, &mut s.track_thr);
    let (thr, track) = (std::mem::take(&mut s.thr), std::mem::take(&mut s.track_thr));
    let th = Thresholds {
        start: Some(&thr),
        track: &track,
    };
    let mut pass = Pass {
        strips: Strips::new(src),
        shape,
        noise,
        th,
        map,
    };
    // The candidates are not kept (on a texture there are millions): a
    // pass counts them per region, one more gathers the keys of regions
    // with more than `M` where there are any, the last makes the points.
    let (region, nreg, m) = regions(shape, p);
    let mut count = vec![0u32; nreg];
    pass.run(s, &mut |c| count[region(&c)] += 1);
    let mut lim = vec![0i16; nreg];
    let mut kept: usize = count.iter().map(|&c| c as usize).sum();
    if count.iter().any(|&c| c as usize > m) {
        let mut keys: Vec<Vec<i16>> = count
            .iter()
            .map(|&c| Vec::with_capacity(if c as usize > m { c as usize } else { 0 }))
            .collect();
        pass.run(s, &mut |c| {
            let r = region(&c);
            if count[r] as usize > m {
                keys[r].push(c.key);
            }
        });
        for (r, g) in keys.iter_mut().enumerate() {
            if g.len() > m {
                let (_, kth, _) = g.select_nth_unstable_by(m - 1, |a, b| b.cmp(a));
                lim[r] = *kth;
                kept -= g.iter().filter(|&&k| k < lim[r]).count();
            }
        }
    }
    out.points.reserve_exact(kept);
    starts.reserve_exact(kept);
    pass.run(s, &mut |c| {
        if c.key >= lim[region(&c)] {
            out.points.push(point_of(&c, shape, scale));
            starts.push([c.x, c.y]);
        }
    });
    (s.thr, s.track_thr) = (thr, track);
    s.cand = Vec::new();
    Ok(src)
}

/// One peak pass over a response made a strip at a time: every candidate
/// to a sink, in image order, and the peak map (the same each pass).
struct Pass<'a, 'b> {
    strips: Strips<'a>,
    shape: Shape,
    noise: &'b NoiseMap,
    th: Thresholds<'b>,
    map: &'b mut PeakMap,
}

impl Pass<'_, '_> {
    fn run(&mut self, s: &mut PeakScratch, sink: &mut impl FnMut(Peak)) {
        let h = self.shape.h;
        let all = if self.shape.dir == ScanDir::Vertical {
            1..h - 1
        } else {
            0..h
        };
        for y0 in all.clone().step_by(STRIP) {
            let ys = y0..(y0 + STRIP).min(all.end);
            let (sh, n, th) = (self.shape, self.noise, self.th);
            scan_rows(&mut self.strips, sh, ys, n, th, s, sink, self.map);
        }
    }
}
