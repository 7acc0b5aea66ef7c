//! [`detect_into`](super::detect_into) on a response made a strip of rows
//! at a time (`edges/band.rs`): the same noise map, peak map, edge points
//! and starts, without the whole response.

use super::super::band::{PixelSums, Strips};
use super::{PeakMap, PeakScratch, Shape, Starts, Thresholds, scan_rows, select, tile_floors};
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
    let mut strips = Strips::new(src);
    let mut ns = std::mem::take(&mut s.noise);
    noise.estimate_rows(w, h, scale, &mut strips, &mut ns);
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
    let mut cand = std::mem::take(&mut s.cand);
    let all = if dir == ScanDir::Vertical {
        1..h - 1
    } else {
        0..h
    };
    let th = Thresholds {
        start: Some(&thr),
        track: &track,
    };
    for y0 in all.clone().step_by(STRIP) {
        let ys = y0..(y0 + STRIP).min(all.end);
        scan_rows(&mut strips, shape, ys, noise, th, s, &mut cand, map);
    }
    drop(strips);
    (s.thr, s.track_thr) = (thr, track);
    select(shape, scale, p, &cand, |i| src.at(i), out, starts, s);
    s.cand = Vec::new();
    Ok(src)
}
