//! Finding the plate's grid in a grey image: a checkerboard by its inner
//! corners (`super::saddle`), a squares plate with the LLV engine as below.
//!
//! The squares' sides are long straight edges, which the pipeline's line
//! extractor fits to subpixel accuracy (`llv::pipeline`, total least squares
//! over every edge point of a side). A corner is where two sides' fitted
//! lines cross, so every corner rests on all the edge points of two sides,
//! not on the few pixels round the corner itself:
//!
//! 1. run the pipeline on the image as grabbed (no lens correction: that is
//!    what is being calibrated), keeping enough edge points a scan line for
//!    every side the plate puts on it;
//! 2. find each square's quadrilateral, its sides fitted to the engine's
//!    edge points along the segments (`quads`): dark ones on a squares
//!    plate, dark and light ones on a checkerboard;
//! 3. grow the plate's lattice from the quadrilateral nearest the middle:
//!    a homography from plate to image, refitted as cells are found,
//!    predicts each neighbouring cell, and the nearest quadrilateral takes
//!    it;
//! 4. turn the lattice until its cells are the plate's (the missing origin
//!    square or the checkerboard's colours pick one of the four turns), and
//!    average the corners several cells share.
//!
//! A view is refused, saying what was found, unless its cells span the
//! plate's whole grid, every one is a cell of the plate and at least nine in
//! ten are there (a square whose side the engine did not see whole is left
//! out with its corners), so no view enters the solution with a wrong label.
//! When a missing square leaves two turns possible, the view still serves
//! the intrinsics ([`Detection::oriented`] is false), not the extrinsics.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use nalgebra::Matrix3;

use super::found::{Corner, DetectError, Detection};
use super::plate::{Plate, PlateKind};
use super::quads::{EdgeIndex, Quad, quads};
use super::zhang;
use crate::llv::pipeline::{Input, Workspace};
use crate::llv::{GreyImage, Params, Segment};

/// The detector: the pipeline's buffers and parameters, kept between views.
#[derive(Debug, Default)]
pub struct Detector {
    ws: Workspace,
}

/// The pipeline parameters for a plate: the defaults, with enough edge
/// points a scan line for every side a row of squares puts on it, and no
/// CONNECT (the raw fitted segments are what the corners rest on).
pub fn params_for(plate: &Plate) -> Params {
    let mut p = Params::default();
    let sides = 2 * plate.columns.max(plate.rows);
    p.edges.per_region = (2 * sides + 8).min(4096);
    p.lens.enabled = false;
    p.connect.enabled = false;
    p.connect.corner_radius = 0.0;
    p
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Corners of seed-relative cell `(i, j)` in plate mm.
fn rel_corners(plate: &Plate, i: i32, j: i32) -> [[f64; 2]; 4] {
    let (s, p) = (plate.square, plate.pitch);
    [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .map(|(a, b)| [f64::from(i) * p + a * s, f64::from(j) * p + b * s])
}

/// Cells found, seed-relative, with their image corners.
type Lattice = BTreeMap<(i32, i32), ([[f64; 2]; 4], bool)>;

fn grow(plate: &Plate, quads: &[Quad], seed: usize) -> Lattice {
    let mut lattice = Lattice::new();
    let mut used = vec![false; quads.len()];
    lattice.insert((0, 0), (quads[seed].corners, quads[seed].dark));
    used[seed] = true;
    let fit = |lat: &Lattice| -> Option<Matrix3<f64>> {
        let (mut pl, mut im) = (Vec::new(), Vec::new());
        for (&(i, j), (c, _)) in lat {
            pl.extend(rel_corners(plate, i, j));
            im.extend(c);
        }
        zhang::homography(&pl, &im)
    };
    let Some(mut h) = fit(&lattice) else {
        return lattice;
    };
    let mut queue = VecDeque::from([(0, 0)]);
    let mut since_fit = 0;
    while let Some((i, j)) = queue.pop_front() {
        for (di, dj) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ] {
            let cell = (i + di, j + dj);
            if lattice.contains_key(&cell) || cell.0.abs() > 64 || cell.1.abs() > 64 {
                continue;
            }
            let pred = rel_corners(plate, cell.0, cell.1).map(|p| zhang::map(&h, p));
            let side = (0..4)
                .map(|k| dist(pred[k], pred[(k + 1) % 4]))
                .fold(f64::MAX, f64::min);
            let centre = [
                pred.iter().map(|p| p[0]).sum::<f64>() / 4.0,
                pred.iter().map(|p| p[1]).sum::<f64>() / 4.0,
            ];
            let best = quads
                .iter()
                .enumerate()
                .filter(|(k, _)| !used[*k])
                .map(|(k, q)| (k, dist(q.centre, centre)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let Some((k, d)) = best else { continue };
            if d.is_nan() || d >= 0.3 * side {
                continue;
            }
            // The turn of the quad's corners that fits the prediction.
            let q = &quads[k].corners;
            let (r, err) = (0..4)
                .map(|r| {
                    let e = (0..4)
                        .map(|m| dist(q[(m + r) % 4], pred[m]))
                        .fold(0.0, f64::max);
                    (r, e)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((0, f64::MAX));
            if err.is_nan() || err >= 0.3 * side {
                continue;
            }
            used[k] = true;
            lattice.insert(
                cell,
                (std::array::from_fn(|m| q[(m + r) % 4]), quads[k].dark),
            );
            queue.push_back(cell);
            since_fit += 1;
            if since_fit >= 4 {
                since_fit = 0;
                if let Some(nh) = fit(&lattice) {
                    h = nh;
                }
            }
        }
    }
    lattice
}

/// The plate's cells found: `(column, row)` → image corners, dark.
type Cells = BTreeMap<(u32, u32), ([[f64; 2]; 4], bool)>;

/// The four turns of a seed-relative lattice onto the plate's cells:
/// `(I, J)` and the cell-corner permutation, when the extents fit.
fn turns(plate: &Plate, lat: &Lattice) -> Vec<Cells> {
    let (i0, i1) = (lat.keys().map(|k| k.0).min(), lat.keys().map(|k| k.0).max());
    let (j0, j1) = (lat.keys().map(|k| k.1).min(), lat.keys().map(|k| k.1).max());
    let (Some(i0), Some(i1), Some(j0), Some(j1)) = (i0, i1, j0, j1) else {
        return Vec::new();
    };
    let (ni, nj) = ((i1 - i0 + 1) as u32, (j1 - j0 + 1) as u32);
    let want = plate.quad_cells();
    let mut out = Vec::new();
    for k in 0..4 {
        let fits = if k % 2 == 0 {
            (ni, nj) == (plate.columns, plate.rows)
        } else {
            (nj, ni) == (plate.columns, plate.rows)
        };
        if !fits {
            continue;
        }
        // Cell corner m = (a, b) in order (0,0) (1,0) (1,1) (0,1); a turn by
        // 90° moves it one place on in that order.
        let mut cells = BTreeMap::new();
        for (&(i, j), &(c, dark)) in lat {
            let (ci, cj) = match k {
                0 => (i - i0, j - j0),
                1 => (j - j0, i1 - i),
                2 => (i1 - i, j1 - j),
                _ => (j1 - j, i - i0),
            };
            let turned: [[f64; 2]; 4] = std::array::from_fn(|m| c[(m + k) % 4]);
            cells.insert((ci as u32, cj as u32), (turned, dark));
        }
        // Every cell found is one of the plate's, and few are missing (a
        // square whose side the engine did not see whole).
        let found: BTreeSet<_> = cells.keys().copied().collect();
        if found.is_subset(&want) && found.len() * 10 >= want.len() * 9 {
            out.push(cells);
        }
    }
    out
}

impl Detector {
    pub fn new() -> Detector {
        Detector::default()
    }

    /// Finds `plate` in `img`.
    pub fn detect(&mut self, img: &GreyImage, plate: &Plate) -> Result<Detection, DetectError> {
        if plate.kind == PlateKind::Checkerboard {
            img.check_stage_size()?;
            return super::saddle::detect(img, plate);
        }
        let params = params_for(plate);
        let out = self.ws.run(&Input::single(img), &params)?;
        let segs: Vec<Segment> = out.lines_raw.to_vec();
        let hand = plate.origin.handedness();
        let (w, h) = img.size();
        let edges = EdgeIndex::new(&out.edges_h, &out.edges_v, w, h);
        let all = quads(
            img,
            &segs,
            &edges,
            plate.kind == PlateKind::Checkerboard,
            hand,
        );
        let wanted: Vec<Quad> = match plate.kind {
            PlateKind::Squares => all.into_iter().filter(|q| q.dark).collect(),
            PlateKind::Checkerboard => all,
        };
        let expected = plate.quad_cells().len();
        if wanted.len() < 4.min(expected) || wanted.is_empty() {
            return Err(DetectError::NotFound {
                quads: wanted.len(),
                expected,
            });
        }
        // Seed: the quadrilateral nearest the middle of them all.
        let n = wanted.len() as f64;
        let mid = [
            wanted.iter().map(|q| q.centre[0]).sum::<f64>() / n,
            wanted.iter().map(|q| q.centre[1]).sum::<f64>() / n,
        ];
        let seed = (0..wanted.len())
            .min_by(|&a, &b| dist(wanted[a].centre, mid).total_cmp(&dist(wanted[b].centre, mid)))
            .unwrap_or(0);
        let lat = grow(plate, &wanted, seed);
        let mut fits = turns(plate, &lat);
        if plate.kind == PlateKind::Checkerboard {
            // The colours must match too: dark where the plate is dark.
            fits.retain(|cells| {
                cells
                    .iter()
                    .all(|(&(i, j), &(_, dark))| dark == plate.is_dark(i, j))
            });
        }
        let oriented = fits.len() == 1;
        let Some(cells) = fits.into_iter().next() else {
            let (i0, i1) = lat
                .keys()
                .fold((i32::MAX, i32::MIN), |a, k| (a.0.min(k.0), a.1.max(k.0)));
            let (j0, j1) = lat
                .keys()
                .fold((i32::MAX, i32::MIN), |a, k| (a.0.min(k.1), a.1.max(k.1)));
            return Err(DetectError::WrongCount {
                found: lat.len(),
                expected,
                columns: (i1 - i0 + 1).max(0) as usize,
                rows: (j1 - j0 + 1).max(0) as usize,
            });
        };
        // Average the corners cells share.
        let mut sums: BTreeMap<(u32, u32), ([f64; 2], f64)> = BTreeMap::new();
        for (&(i, j), (c, _)) in &cells {
            for (m, pc) in plate.cell_corners(i, j).iter().enumerate() {
                let e = sums.entry(pc.key).or_insert(([0.0, 0.0], 0.0));
                e.0[0] += c[m][0];
                e.0[1] += c[m][1];
                e.1 += 1.0;
            }
        }
        let corners = plate
            .corners()
            .into_iter()
            .filter_map(|pc| {
                let (s, n) = sums.get(&pc.key)?;
                Some(Corner {
                    corner: pc,
                    px: [s[0] / n, s[1] / n],
                })
            })
            .collect();
        Ok(Detection {
            corners,
            cells: cells.values().map(|c| c.0).collect(),
            oriented,
            segments: segs.len(),
        })
    }
}
