//! Finding a checkerboard by its inner corners: the points where four
//! squares meet, dark and light in turn. Outer squares, the board's frame or
//! margin, text, clips or hands around it do not matter, since only the
//! inner corners are looked for, and they are what a checkerboard is
//! calibrated with (as OpenCV, MATLAB and Kalibr do).
//!
//! 1. **Saddle points.** Where four squares meet, the image (smoothed a
//!    little) is a saddle: its Hessian has one positive and one negative
//!    curvature, so `−det H = I_xy² − I_xx I_yy` is large there, zero along
//!    a straight edge (one curvature only) and negative on a blob. Its local
//!    maxima above a fraction of the strongest are the candidates.
//! 2. **The grid.** From a candidate whose nearest neighbours make a
//!    parallelogram (the seed), the lattice is grown one neighbour at a
//!    time: each next corner is predicted from the two before it along the
//!    row or column (or a homography of those found), and the nearest
//!    candidate within a third of a square takes it, but only if the four
//!    squares round it alternate dark, light, dark, light. That test keeps
//!    the board's outer corners, a frame's corners and text out.
//! 3. **Subpixel.** Each corner is refined as OpenCV's `cornerSubPix`
//!    does: the point where every image gradient in a window round it
//!    (Gaussian-weighted, 11 × 11 at most, smaller for small squares) is
//!    perpendicular to the line from the point, iterated until it moves
//!    less than a thousandth of a pixel.
//!
//! The grid found is then compared with the plate file: its count of inner
//! corners, whether it reaches the image's edge (a board partly out of the
//! frame), whether a second board is in view, and how sharp its edges are.
//! Each mismatch is a [`DetectError`] that says what was found.

use std::collections::{HashMap, VecDeque};

use nalgebra::Matrix3;

use super::found::{Corner, DetectError, Detection, MAX_EDGE_WIDTH};
use super::plate::{Plate, PlateCorner};
use super::zhang;
use crate::llv::GreyImage;

mod pixels;
use pixels::*;

/// Candidates kept at most (the strongest).
const MAX_CANDIDATES: usize = 600;
/// A candidate's response, as a fraction of the strongest.
const MIN_RESPONSE: f32 = 0.02;
/// Smallest grey-level difference between the dark and light squares
/// round a corner.
const MIN_CONTRAST: f64 = 12.0;
/// A corner's saddle response, as a fraction of the seed's (a corner in a
/// shadow with a quarter of the contrast has a sixteenth; the saddles noise
/// and JPEG blocks leave along a side are about a fiftieth).
const WEAK: f32 = 0.05;

/// One candidate: position (px) and response.
#[derive(Clone, Copy, Debug)]
struct Cand {
    p: [f64; 2],
    r: f32,
}

/// The lattice: `(i, j)` → candidate index.
type Lattice = HashMap<(i32, i32), usize>;

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

/// Finds candidates near a point quickly: a grid of buckets.
struct Index {
    cell: f64,
    w: usize,
    h: usize,
    buckets: Vec<Vec<usize>>,
}

impl Index {
    fn new(c: &[Cand], width: usize, height: usize, cell: f64) -> Index {
        let w = (width as f64 / cell).ceil().max(1.0) as usize;
        let h = (height as f64 / cell).ceil().max(1.0) as usize;
        let mut buckets = vec![Vec::new(); w * h];
        for (k, q) in c.iter().enumerate() {
            let bx = ((q.p[0] / cell) as usize).min(w - 1);
            let by = ((q.p[1] / cell) as usize).min(h - 1);
            buckets[by * w + bx].push(k);
        }
        Index {
            cell,
            w,
            h,
            buckets,
        }
    }

    /// The strongest candidate within `r` of `p`, not used (a corner's
    /// saddle is far stronger than the small ones JPEG blocks and noise
    /// leave along a square's side).
    fn nearest(&self, c: &[Cand], used: &[bool], p: [f64; 2], r: f64) -> Option<usize> {
        let lo = |v: f64| ((v - r) / self.cell).floor().max(0.0) as usize;
        let hi = |v: f64, n: usize| (((v + r) / self.cell).floor().max(0.0) as usize).min(n - 1);
        if !(p[0].is_finite() && p[1].is_finite()) {
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        for by in lo(p[1]).min(self.h - 1)..=hi(p[1], self.h) {
            for bx in lo(p[0]).min(self.w - 1)..=hi(p[0], self.w) {
                for &k in &self.buckets[by * self.w + bx] {
                    if used[k] {
                        continue;
                    }
                    let d = norm(sub(c[k].p, p));
                    let strength = f64::from(c[k].r);
                    if d < r && best.is_none_or(|b| strength > b.1) {
                        best = Some((k, strength));
                    }
                }
            }
        }
        best.map(|b| b.0)
    }
}

/// A grid grown from one seed: lattice and the X-test's contrast per point.
struct Grown {
    lattice: Lattice,
    contrast: HashMap<(i32, i32), f64>,
}

fn homography_of(lat: &Lattice, c: &[Cand]) -> Option<Matrix3<f64>> {
    if lat.len() < 4 {
        return None;
    }
    let (mut pl, mut im) = (Vec::new(), Vec::new());
    for (&(i, j), &k) in lat {
        pl.push([f64::from(i), f64::from(j)]);
        im.push(c[k].p);
    }
    zhang::homography(&pl, &im)
}

/// Grows the lattice from seed `s` with steps to neighbours `a` and `b`.
fn grow(
    img: &GreyImage,
    c: &mut [Cand],
    idx: &Index,
    used: &mut [bool],
    s: usize,
    a: usize,
    b: usize,
) -> Grown {
    let mut lat = Lattice::new();
    let mut contrast = HashMap::new();
    lat.insert((0, 0), s);
    lat.insert((1, 0), a);
    lat.insert((0, 1), b);
    let mut taken = vec![s, a, b];
    // The seed's saddle sets the scale of a corner's response.
    let floor = c[s].r;
    for &k in &taken {
        used[k] = true;
    }
    let mut queue: VecDeque<(i32, i32)> = VecDeque::from([(0, 0), (1, 0), (0, 1)]);
    let pos = |lat: &Lattice, c: &[Cand], key: (i32, i32)| lat.get(&key).map(|&k| c[k].p);
    while let Some((i, j)) = queue.pop_front() {
        let Some(p0) = pos(&lat, c, (i, j)) else {
            continue;
        };
        for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let key = (i + di, j + dj);
            if lat.contains_key(&key) || key.0.abs() > 80 || key.1.abs() > 80 {
                continue;
            }
            // Prediction: along the row or column from behind, else by
            // the step of a parallel neighbour (never a homography of
            // points that may still lie on one line).
            let back = pos(&lat, c, (i - di, j - dj));
            let back2 = pos(&lat, c, (i - 2 * di, j - 2 * dj));
            let parallel = || {
                let (oi, oj) = (dj, di);
                [-1, 1].into_iter().find_map(|s| {
                    let a = pos(&lat, c, (i + s * oi, j + s * oj))?;
                    let b = pos(&lat, c, (i + s * oi + di, j + s * oj + dj))?;
                    Some(sub(b, a))
                })
            };
            let pred = match (back, back2) {
                (Some(b1), Some(b2)) => [
                    2.5 * p0[0] - 2.0 * b1[0] + 0.5 * b2[0],
                    2.5 * p0[1] - 2.0 * b1[1] + 0.5 * b2[1],
                ],
                (Some(b1), None) => [2.0 * p0[0] - b1[0], 2.0 * p0[1] - b1[1]],
                _ => match parallel() {
                    Some(v) => [p0[0] + v[0], p0[1] + v[1]],
                    None => continue,
                },
            };
            let step = norm(sub(pred, p0));
            if !(step.is_finite() && step > 2.0) {
                continue;
            }
            let Some(k) = idx.nearest(c, used, pred, 0.3 * step) else {
                continue;
            };
            // A corner's saddle is of the board's contrast; the small
            // ones noise leaves along a side are a few hundredths of it.
            if c[k].r < WEAK * floor {
                continue;
            }
            // The candidate refined as the final corners are: a weak
            // saddle a few pixels off a corner whose own was lost goes to
            // the corner, anything else is let go.
            let win = ((0.25 * step).floor() as i32).clamp(2, 5);
            let Some(q) = subpixel(img, c[k].p, win) else {
                continue;
            };
            if norm(sub(q, pred)) > 0.3 * step {
                continue;
            }
            // The lattice steps at the new corner, for the X-test.
            let d = sub(q, p0);
            let (u, v) = if di != 0 {
                let u = [d[0] * f64::from(di), d[1] * f64::from(di)];
                (u, side_step(&lat, c, key, false).unwrap_or([-u[1], u[0]]))
            } else {
                let v = [d[0] * f64::from(dj), d[1] * f64::from(dj)];
                (side_step(&lat, c, key, true).unwrap_or([v[1], -v[0]]), v)
            };
            let Some(x) = x_test(img, q, u, v) else {
                continue;
            };
            used[k] = true;
            taken.push(k);
            c[k].p = q;
            lat.insert(key, k);
            contrast.insert(key, x);
            queue.push_back(key);
        }
    }
    // The seed's three: X-tested with the grown lattice's steps.
    for key in [(0, 0), (1, 0), (0, 1)] {
        let Some(&k) = lat.get(&key) else { continue };
        let u = side_step(&lat, c, key, true);
        let v = side_step(&lat, c, key, false);
        match (u, v) {
            (Some(u), Some(v)) => match x_test(img, c[k].p, u, v) {
                Some(x) => {
                    contrast.insert(key, x);
                }
                None => {
                    lat.remove(&key);
                }
            },
            _ => {
                lat.remove(&key);
            }
        }
    }
    trim(&mut lat);
    // Free what this grid did not keep.
    for k in taken {
        used[k] = lat.values().any(|&v| v == k);
    }
    Grown {
        lattice: lat,
        contrast,
    }
}

/// Removes outer rows and columns of the lattice that are less than half
/// filled: a corner of the frame, a clip or text that passed the test next
/// to the board, not a row of the board.
fn trim(lat: &mut Lattice) {
    loop {
        let Some(i0) = lat.keys().map(|k| k.0).min() else {
            return;
        };
        let i1 = lat.keys().map(|k| k.0).max().unwrap_or(i0);
        let j0 = lat.keys().map(|k| k.1).min().unwrap_or(0);
        let j1 = lat.keys().map(|k| k.1).max().unwrap_or(j0);
        let (ni, nj) = ((i1 - i0 + 1) as usize, (j1 - j0 + 1) as usize);
        let lines = [
            (true, i0, nj),
            (true, i1, nj),
            (false, j0, ni),
            (false, j1, ni),
        ];
        let worst = lines
            .iter()
            .map(|&(col, at, len)| {
                let n = lat
                    .keys()
                    .filter(|k| if col { k.0 == at } else { k.1 == at })
                    .count();
                (col, at, n as f64 / len as f64)
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        match worst {
            Some((col, at, fill)) if fill < 0.5 && ni > 1 && nj > 1 => {
                lat.retain(|k, _| if col { k.0 != at } else { k.1 != at });
            }
            _ => return,
        }
    }
}

/// The step along `i` (`along_i`) or `j` at lattice point `key`, from a
/// neighbour found on either side.
fn side_step(lat: &Lattice, c: &[Cand], key: (i32, i32), along_i: bool) -> Option<[f64; 2]> {
    let (di, dj) = if along_i { (1, 0) } else { (0, 1) };
    let p = lat.get(&key).map(|&k| c[k].p);
    let f = lat.get(&(key.0 + di, key.1 + dj)).map(|&k| c[k].p);
    let b = lat.get(&(key.0 - di, key.1 - dj)).map(|&k| c[k].p);
    match (p, f, b) {
        (Some(p), Some(f), _) => Some(sub(f, p)),
        (Some(p), None, Some(b)) => Some(sub(p, b)),
        _ => {
            // Not yet placed: from the neighbours' rows or columns.
            let (oi, oj) = if along_i { (0, 1) } else { (1, 0) };
            for s in [-1, 1] {
                let a = lat.get(&(key.0 + s * oi, key.1 + s * oj)).map(|&k| c[k].p);
                let n = lat
                    .get(&(key.0 + s * oi + di, key.1 + s * oj + dj))
                    .map(|&k| c[k].p);
                if let (Some(a), Some(n)) = (a, n) {
                    return Some(sub(n, a));
                }
            }
            None
        }
    }
}

/// Seeds: a candidate and two of its nearest neighbours that make a
/// parallelogram with candidates at the other two places, the four squares
/// round the seed alternating.
fn seed(
    img: &GreyImage,
    c: &[Cand],
    idx: &Index,
    used: &[bool],
    s: usize,
) -> Option<(usize, usize)> {
    let p = c[s].p;
    let mut near: Vec<(usize, f64)> = c
        .iter()
        .enumerate()
        .filter(|(k, q)| *k != s && !used[*k] && q.r >= 0.25 * c[s].r)
        .map(|(k, q)| (k, norm(sub(q.p, p))))
        .filter(|(_, d)| *d > 3.0)
        .collect();
    near.sort_by(|a, b| a.1.total_cmp(&b.1));
    near.truncate(6);
    for x in 0..near.len() {
        for y in 0..near.len() {
            if x == y {
                continue;
            }
            let (a, b) = (near[x].0, near[y].0);
            let u = sub(c[a].p, p);
            let v = sub(c[b].p, p);
            let (lu, lv) = (norm(u), norm(v));
            let cos = (u[0] * v[0] + u[1] * v[1]) / (lu * lv);
            // A right-handed pair (image y down), not too skew or unequal.
            if cos.abs() > 0.7 || u[0] * v[1] - u[1] * v[0] <= 0.0 || lu > 2.0 * lv || lv > 2.0 * lu
            {
                continue;
            }
            let tol = 0.25 * lu.min(lv);
            let others = [
                [p[0] - u[0], p[1] - u[1]],
                [p[0] - v[0], p[1] - v[1]],
                [p[0] + u[0] + v[0], p[1] + u[1] + v[1]],
            ];
            let mut fake = used.to_vec();
            fake[s] = true;
            fake[a] = true;
            fake[b] = true;
            if others
                .iter()
                .any(|o| idx.nearest(c, &fake, *o, tol).is_none())
            {
                continue;
            }
            if x_test(img, p, u, v).is_some() {
                return Some((a, b));
            }
        }
    }
    None
}

/// One grid found: lattice size `ni × nj`, the points (row-major by `j`
/// then `i`, all present or `None`), the colour vote, whether it reaches
/// the image's edge.
struct Grid {
    ni: usize,
    nj: usize,
    pts: Vec<Option<[f64; 2]>>,
    /// Positive when the square towards `+i+j` of point `(i, j)` is dark
    /// for `i + j` even.
    colour: f64,
    at_edge: bool,
    contrast: Vec<f64>,
}

fn grid_of(g: &Grown, c: &[Cand], w: usize, h: usize) -> Grid {
    let lat = &g.lattice;
    let i0 = lat.keys().map(|k| k.0).min().unwrap_or(0);
    let i1 = lat.keys().map(|k| k.0).max().unwrap_or(-1);
    let j0 = lat.keys().map(|k| k.1).min().unwrap_or(0);
    let j1 = lat.keys().map(|k| k.1).max().unwrap_or(-1);
    let ni = (i1 - i0 + 1).max(0) as usize;
    let nj = (j1 - j0 + 1).max(0) as usize;
    let mut pts = vec![None; ni * nj];
    let mut colour = 0.0;
    let mut contrast = Vec::new();
    for (&(i, j), &k) in lat {
        pts[(j - j0) as usize * ni + (i - i0) as usize] = Some(c[k].p);
        if let Some(&x) = g.contrast.get(&(i, j)) {
            // x > 0: the square towards +i+j is lighter than towards +i−j.
            let even = (i - i0 + j - j0) % 2 == 0;
            colour += if even { -x } else { x };
            contrast.push(x.abs());
        }
    }
    // Does the next row or column out fall outside the image?
    let mut at_edge = false;
    if let Some(hm) = homography_of(lat, c) {
        let margin = 0.0;
        'o: for j in j0 - 1..=j1 + 1 {
            for i in i0 - 1..=i1 + 1 {
                let inside = i >= i0 && i <= i1 && j >= j0 && j <= j1;
                if inside {
                    continue;
                }
                let p = zhang::map(&hm, [f64::from(i), f64::from(j)]);
                if p[0] < margin || p[1] < margin || p[0] > (w - 1) as f64 || p[1] > (h - 1) as f64
                {
                    at_edge = true;
                    break 'o;
                }
            }
        }
    }
    Grid {
        ni,
        nj,
        pts,
        colour,
        at_edge,
        contrast,
    }
}

/// Finds the checkerboard `plate` in `img` by its inner corners.
pub fn detect(img: &GreyImage, plate: &Plate) -> Result<Detection, DetectError> {
    let want = (plate.columns as usize - 1, plate.rows as usize - 1);
    match find(img, want) {
        Ok(g) => label(img, plate, &g),
        Err(Missed { error, best }) => {
            // A part of the board found whose edges are smeared: the blur
            // is why the rest was not (a motion blur breaks the lattice
            // across the motion), not the plate file's size.
            if let Some(b) = best {
                let width = grid_edge_width(img, &b, |p| p);
                if width > MAX_EDGE_WIDTH {
                    return Err(DetectError::Blurred {
                        width,
                        corners: b.pts.iter().flatten().count(),
                    });
                }
            }
            Err(blurred(img, want).unwrap_or(error))
        }
    }
}

/// When no board is found: the board found at half the size (where a
/// blur is half as wide), with edges wider than [`MAX_EDGE_WIDTH`]
/// measured in the image itself, is a blurred board.
fn blurred(img: &GreyImage, want: (usize, usize)) -> Option<DetectError> {
    let (w, h) = img.size();
    let (hw, hh) = (w / 2, h / 2);
    if hw < 16 || hh < 16 {
        return None;
    }
    let d = img.data();
    let half: Vec<u8> = (0..hh)
        .flat_map(|y| {
            (0..hw).map(move |x| {
                let s = u32::from(d[2 * y * w + 2 * x])
                    + u32::from(d[2 * y * w + 2 * x + 1])
                    + u32::from(d[(2 * y + 1) * w + 2 * x])
                    + u32::from(d[(2 * y + 1) * w + 2 * x + 1]);
                ((s + 2) / 4) as u8
            })
        })
        .collect();
    let small = GreyImage::new(hw, hh, half).ok()?;
    let g = find(&small, want).ok()?;
    let width = grid_edge_width(img, &g, |p| [2.0 * p[0] + 0.5, 2.0 * p[1] + 0.5]);
    // Edges that measure sharp are not called blurred ("5.6 px wide (at
    // most 6 px)" would contradict itself): the full size's reason stands.
    (width > MAX_EDGE_WIDTH).then(|| DetectError::Blurred {
        width,
        corners: g.pts.iter().flatten().count(),
    })
}

/// Why [`find`] found no whole grid, with the largest part of one it
/// found (if any), whose edges tell a blurred board.
struct Missed {
    error: DetectError,
    best: Option<Box<Grid>>,
}

/// The one whole grid of `want` inner corners in `img`, or why not.
fn find(img: &GreyImage, want: (usize, usize)) -> Result<Grid, Missed> {
    let (w, h) = img.size();
    let s = smooth(img);
    let r = saddle_response(&s, w, h, 2);
    let mut c = candidates(&r, w, h);
    let not_found = |found: usize| Missed {
        error: DetectError::NoGrid {
            saddles: found,
            columns: want.0,
            rows: want.1,
        },
        best: None,
    };
    if c.len() < 4 {
        return Err(not_found(c.len()));
    }
    let idx = Index::new(&c, w, h, 16.0);
    let mut used = vec![false; c.len()];
    let full = want.0 * want.1;
    let count = |g: &Grid| g.pts.iter().flatten().count();
    let complete =
        |g: &Grid| ((g.ni, g.nj) == want || (g.nj, g.ni) == want) && count(g) * 10 >= full * 9;
    let mut grids: Vec<Grid> = Vec::new();
    let mut tries = 0;
    for sd in 0..c.len() {
        if used[sd] {
            continue;
        }
        tries += 1;
        if tries > 60 {
            break;
        }
        let Some((a, b)) = seed(img, &c, &idx, &used, sd) else {
            continue;
        };
        let g = grow(img, &mut c, &idx, &mut used, sd, a, b);
        let grid = grid_of(&g, &c, w, h);
        // Only a whole board keeps its corners from other seeds: a part
        // of one may grow whole from another seed.
        if !complete(&grid) {
            for &k in g.lattice.values() {
                used[k] = false;
            }
        }
        if g.lattice.len() >= 4 {
            grids.push(grid);
        }
        if grids.iter().filter(|g| complete(g)).count() >= 2 {
            break;
        }
    }
    let whole = grids.iter().filter(|g| complete(g)).count();
    if whole >= 2 {
        let mut it = grids.into_iter().filter(&complete);
        if let (Some(first), Some(second)) = (it.next(), it.next()) {
            // A smeared board can also grow twice: its edges tell.
            return Err(Missed {
                error: DetectError::TwoBoards {
                    first: (first.ni, first.nj),
                    second: (second.ni, second.nj),
                },
                best: Some(Box::new(first)),
            });
        }
        return Err(not_found(c.len()));
    }
    match grids.iter().position(complete) {
        Some(k) => Ok(grids.swap_remove(k)),
        None => {
            let Some(k) = (0..grids.len()).max_by_key(|&k| count(&grids[k])) else {
                return Err(not_found(c.len()));
            };
            let best = grids.swap_remove(k);
            if count(&best) < 6 {
                return Err(not_found(c.len()));
            }
            let fits_in = best.ni <= want.0.max(want.1) && best.nj <= want.0.max(want.1);
            let error = if best.at_edge && fits_in {
                DetectError::PartlyOut {
                    columns: best.ni,
                    rows: best.nj,
                    want_columns: want.0,
                    want_rows: want.1,
                }
            } else {
                DetectError::GridSize {
                    columns: best.ni,
                    rows: best.nj,
                    want_columns: want.0,
                    want_rows: want.1,
                }
            };
            Err(Missed {
                error,
                best: Some(Box::new(best)),
            })
        }
    }
}

/// The grid's corners with the plate's labels, refined to subpixel.
fn label(img: &GreyImage, plate: &Plate, g: &Grid) -> Result<Detection, DetectError> {
    let (ni, nj) = (g.ni as i32, g.nj as i32);
    let at = |i: i32, j: i32| -> Option<[f64; 2]> {
        if i < 0 || j < 0 || i >= ni || j >= nj {
            return None;
        }
        g.pts[(j * ni + i) as usize]
    };
    // The eight ways of laying the grid on the plate's inner corners:
    // (i, j) → plate key (1 + a, 1 + b).
    let (pc, pr) = (plate.columns as i32 - 1, plate.rows as i32 - 1);
    let mut fits = Vec::new();
    for t in 0..8 {
        let swap = t >= 4;
        let (gi, gj) = if swap { (nj, ni) } else { (ni, nj) };
        if (gi, gj) != (pc, pr) {
            continue;
        }
        let map = move |i: i32, j: i32| -> (i32, i32) {
            let (a, b) = if swap { (j, i) } else { (i, j) };
            match t % 4 {
                0 => (a, b),
                1 => (pc - 1 - a, b),
                2 => (a, pr - 1 - b),
                _ => (pc - 1 - a, pr - 1 - b),
            }
        };
        // Handedness: plate x → y must turn as the plate's origin says.
        let (mut cross, mut n) = (0.0, 0);
        for j in 0..nj {
            for i in 0..ni {
                let Some(p) = at(i, j) else { continue };
                // Image steps along plate x and y from this point.
                let step = |da: i32, db: i32| -> Option<[f64; 2]> {
                    let (a, b) = map(i, j);
                    for (ii, jj) in [(i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)] {
                        let (a2, b2) = map(ii, jj);
                        if (a2 - a, b2 - b) == (da, db) {
                            return at(ii, jj).map(|q| sub(q, p));
                        }
                    }
                    None
                };
                if let (Some(x), Some(y)) = (step(1, 0), step(0, 1)) {
                    cross += x[0] * y[1] - x[1] * y[0];
                    n += 1;
                }
            }
        }
        if n == 0 || cross * plate.origin.handedness() <= 0.0 {
            continue;
        }
        // Colour: plate cell (a+1, b+1) (between keys (a+1, b+1) and
        // (a+2, b+2)) is dark when a + b is even. The grid's colour vote
        // says whether the square towards +i+j of an even point is dark;
        // map that square's plate cell.
        let (a0, b0) = map(0, 0);
        let (a1, b1) = map(1, 1);
        let cell = (a0.min(a1), b0.min(b1));
        let plate_dark = (cell.0 + 1 + cell.1 + 1) % 2 == 0;
        let grid_dark = g.colour > 0.0;
        if plate_dark != grid_dark {
            continue;
        }
        fits.push(map);
    }
    let Some(map) = fits.first().copied() else {
        return Err(DetectError::GridSize {
            columns: g.ni,
            rows: g.nj,
            want_columns: pc as usize,
            want_rows: pr as usize,
        });
    };
    let oriented = fits.len() == 1;
    // Subpixel window: a quarter of the smallest step, 2 to 5 px.
    let mut steps = Vec::new();
    for j in 0..nj {
        for i in 0..ni {
            if let (Some(p), Some(q)) = (at(i, j), at(i + 1, j)) {
                steps.push(norm(sub(q, p)));
            }
            if let (Some(p), Some(q)) = (at(i, j), at(i, j + 1)) {
                steps.push(norm(sub(q, p)));
            }
        }
    }
    steps.sort_by(f64::total_cmp);
    let small = steps.get(steps.len() / 10).copied().unwrap_or(8.0);
    let win = ((0.25 * small).floor() as i32).clamp(2, 5);
    let mut corners = Vec::new();
    let mut by_key = HashMap::new();
    for j in 0..nj {
        for i in 0..ni {
            let Some(p) = at(i, j) else { continue };
            let q = subpixel(img, p, win).unwrap_or(p);
            let (a, b) = map(i, j);
            let key = ((a + 1) as u32, (b + 1) as u32);
            by_key.insert(key, q);
            corners.push(Corner {
                corner: PlateCorner {
                    key,
                    xy: [
                        f64::from(key.0) * plate.square,
                        f64::from(key.1) * plate.square,
                    ],
                },
                px: q,
            });
        }
    }
    corners.sort_by_key(|c| (c.corner.key.1, c.corner.key.0));
    // Edge sharpness, along both of the grid's directions.
    let width = grid_edge_width(img, g, |p| p);
    if width > MAX_EDGE_WIDTH {
        return Err(DetectError::Blurred {
            width,
            corners: corners.len(),
        });
    }
    // The cells between inner corners, for drawing.
    let mut cells = Vec::new();
    for (&(a, b), &p) in &by_key {
        if let (Some(&q1), Some(&q2), Some(&q3)) = (
            by_key.get(&(a + 1, b)),
            by_key.get(&(a + 1, b + 1)),
            by_key.get(&(a, b + 1)),
        ) {
            cells.push([p, q1, q2, q3]);
        }
    }
    Ok(Detection {
        corners,
        cells,
        oriented,
        segments: 0,
    })
}
