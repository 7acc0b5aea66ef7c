//! The rasters behind a preview: area-averaged grey samples (stretched
//! from the image's 1st to its 99th percentile), the ordered (Bayer)
//! threshold that turns grey into Braille dots, and the dot raster of edge
//! points and line segments (clipped to the image, so no dot lies outside
//! it), with a mark per dot saying how the line is drawn.

use ratatui::layout::Rect;

use super::Geometry;
use crate::llv::edit::point_segment_distance;
use crate::llv::{EdgePoints, GreyImage, Point, Segment};

/// Sub-cells per cell (columns, rows) of a drawing style.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    pub sx: usize,
    pub sy: usize,
}

pub const BRAILLE_GRID: Grid = Grid { sx: 2, sy: 4 };
pub const BLOCK_GRID: Grid = Grid { sx: 1, sy: 2 };

/// How a dot of a line is drawn; a higher mark wins where lines cross.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Mark {
    #[default]
    None,
    Line,
    /// Made or moved by the last edit.
    Result,
    Selected,
    /// The line the Edit keys point at.
    Highlighted,
}

/// The grey levels mapped to black and white: the image's 1st and 99th
/// percentiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stretch {
    pub lo: u8,
    pub hi: u8,
}

impl Stretch {
    pub fn apply(self, g: u8) -> u8 {
        if self.hi <= self.lo {
            return g;
        }
        let v = (g.saturating_sub(self.lo) as u32 * 255) / (self.hi - self.lo) as u32;
        v.min(255) as u8
    }
}

/// The 1st–99th percentile stretch of the image's valid pixels, from a
/// regular sample of at most about 16 000 of them (a draw computes it for
/// every view; the percentiles of a sample that size are as good on screen).
pub fn stretch_of(img: &GreyImage) -> Stretch {
    let mut hist = [0u64; 256];
    let mask = img.valid_mask();
    let data = img.data();
    let (w, h) = img.size();
    let step = ((w * h / 16_384) as f64).sqrt().floor().max(1.0) as usize;
    let mut n = 0u64;
    for y in (0..h).step_by(step) {
        for x in (0..w).step_by(step) {
            let i = y * w + x;
            if mask.is_none_or(|m| m.get(i).copied().unwrap_or(false))
                && let Some(&g) = data.get(i)
            {
                hist[g as usize] += 1;
                n += 1;
            }
        }
    }
    if n == 0 {
        return Stretch { lo: 0, hi: 255 };
    }
    let at = |q: u64| -> u8 {
        let mut acc = 0;
        for (g, &c) in hist.iter().enumerate() {
            acc += c;
            if acc > q {
                return g as u8;
            }
        }
        255
    };
    let (lo, hi) = (at(n / 100), at(n - 1 - n / 100));
    if hi > lo {
        Stretch { lo, hi }
    } else {
        Stretch { lo: 0, hi: 255 }
    }
}

/// The nearest colour of the xterm 256-colour palette's greys: 16 (black),
/// 232–255 (levels 8, 18, …, 238) and 231 (white).
pub fn grey_index(g: u8) -> u8 {
    match g {
        0..=3 => 16,
        247..=255 => 231,
        _ => 232 + (((g as u16).saturating_sub(3)) / 10).min(23) as u8,
    }
}

/// Area-averaged, stretched grey of every sub-cell of the area (`None`
/// outside the image or where every pixel is invalid).
pub fn sample_grey(img: &GreyImage, g: &Geometry, grid: Grid, stretch: Stretch) -> Vec<Option<u8>> {
    let cols = g.area.width as usize * grid.sx;
    let rows = g.area.height as usize * grid.sy;
    let sub_w = g.ppu / grid.sx as f64;
    let sub_h = 2.0 * g.ppu / grid.sy as f64;
    let span = |origin: f64, step: f64, i: usize, len: usize| -> Option<(usize, usize)> {
        let a = origin + i as f64 * step;
        let b = a + step;
        if b <= 0.0 || a >= len as f64 {
            return None;
        }
        // A sub-cell smaller than a pixel samples the pixel under its centre.
        if step < 1.0 {
            let c = (a + step / 2.0).floor();
            if c < 0.0 || c >= len as f64 {
                return None;
            }
            return Some((c as usize, c as usize + 1));
        }
        let lo = a.max(0.0).floor() as usize;
        let hi = (b.min(len as f64).ceil() as usize).max(lo + 1).min(len);
        Some((lo, hi))
    };
    let (w, h) = img.size();
    let xs: Vec<_> = (0..cols).map(|i| span(g.ox, sub_w, i, w)).collect();
    let ys: Vec<_> = (0..rows).map(|j| span(g.oy, sub_h, j, h)).collect();
    let data = img.data();
    let mask = img.valid_mask();
    let mut out = Vec::with_capacity(cols * rows);
    for yr in &ys {
        for xr in &xs {
            let v = match (yr, xr) {
                (Some((y0, y1)), Some((x0, x1))) => {
                    let (mut sum, mut n) = (0u64, 0u64);
                    for y in *y0..*y1 {
                        let row = y * w;
                        for x in *x0..*x1 {
                            if mask.is_none_or(|m| m.get(row + x).copied().unwrap_or(false)) {
                                sum += data.get(row + x).copied().unwrap_or(0) as u64;
                                n += 1;
                            }
                        }
                    }
                    (n > 0).then(|| stretch.apply(((sum + n / 2) / n) as u8))
                }
                _ => None,
            };
            out.push(v);
        }
    }
    out
}

/// The 8 × 8 Bayer matrix: thresholds spread so that a flat grey lights an
/// even scatter of dots, not the same dots of every cell.
const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// The Braille bits of cell `(c, r)` lit by its grey samples (`at(i, j)`
/// of the sub-cell grid) under the ordered threshold.
pub fn dither_bits(c: usize, r: usize, at: &impl Fn(usize, usize) -> Option<u8>) -> u8 {
    let mut bits = 0;
    for (dx, col) in BRAILLE_BITS.iter().enumerate() {
        for (dy, bit) in col.iter().enumerate() {
            let (i, j) = (c * 2 + dx, r * 4 + dy);
            let t = BAYER8[j % 8][i % 8] as u16 * 4 + 2;
            if at(i, j).is_some_and(|g| g as u16 > t) {
                bits |= bit;
            }
        }
    }
    bits
}

pub const BRAILLE_BITS: [[u8; 4]; 2] = [[0x01, 0x02, 0x04, 0x40], [0x08, 0x10, 0x20, 0x80]];

pub fn braille(bits: u8) -> char {
    char::from_u32(0x2800 + bits as u32).unwrap_or(' ')
}

/// A dot raster of the area's sub-cells.
pub struct Dots {
    cols: usize,
    rows: usize,
    grid: Grid,
    on: Vec<Mark>,
}

impl Dots {
    pub fn new(area: Rect, grid: Grid) -> Dots {
        let cols = area.width as usize * grid.sx;
        let rows = area.height as usize * grid.sy;
        Dots {
            cols,
            rows,
            grid,
            on: vec![Mark::None; cols * rows],
        }
    }
    fn set(&mut self, i: i64, j: i64, m: Mark) {
        if i >= 0 && j >= 0 && (i as usize) < self.cols && (j as usize) < self.rows {
            let k = j as usize * self.cols + i as usize;
            self.on[k] = self.on[k].max(m);
        }
    }
    fn get(&self, i: usize, j: usize) -> Mark {
        self.on.get(j * self.cols + i).copied().unwrap_or_default()
    }
    /// The Braille bits lit in cell `(c, r)` and the highest mark among them.
    pub fn cell_bits(&self, c: usize, r: usize) -> (u8, Mark) {
        let mut bits = 0u8;
        let mut top = Mark::None;
        for dx in 0..self.grid.sx {
            for dy in 0..self.grid.sy {
                let m = self.get(c * self.grid.sx + dx, r * self.grid.sy + dy);
                if m != Mark::None {
                    top = top.max(m);
                    bits |= BRAILLE_BITS
                        .get(dx)
                        .and_then(|c| c.get(dy))
                        .copied()
                        .unwrap_or(0);
                }
            }
        }
        (bits, top)
    }
}

fn sub_pos(g: &Geometry, grid: Grid, x: f64, y: f64) -> (f64, f64) {
    (
        (x + 0.5 - g.ox) / g.ppu * grid.sx as f64,
        (y + 0.5 - g.oy) / (2.0 * g.ppu) * grid.sy as f64,
    )
}

pub fn plot_edges(d: &mut Dots, e: &EdgePoints, g: &Geometry, grid: Grid, size: (usize, usize)) {
    let (w, h) = (size.0 as f32, size.1 as f32);
    for p in &e.points {
        if !(p.x >= 0.0 && p.y >= 0.0 && p.x < w && p.y < h) {
            continue;
        }
        let (i, j) = sub_pos(g, grid, p.x as f64, p.y as f64);
        if i.is_finite() && j.is_finite() {
            d.set(i.floor() as i64, j.floor() as i64, Mark::Line);
        }
    }
}

/// The part of `s` inside the image `[0, w - 1] × [0, h - 1]` (pixel
/// centres), if any (Liang–Barsky).
fn clip(s: &Segment, (w, h): (usize, usize)) -> Option<(Point, Point)> {
    let (x0, y0, x1, y1) = (s.a.x, s.a.y, s.b.x, s.b.y);
    if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (x1 - x0, y1 - y0);
    let (xmax, ymax) = (w as f64 - 1.0, h as f64 - 1.0);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, x0), (dx, xmax - x0), (-dy, y0), (dy, ymax - y0)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then(|| {
        (
            Point::new(x0 + t0 * dx, y0 + t0 * dy),
            Point::new(x0 + t1 * dx, y0 + t1 * dy),
        )
    })
}

pub fn plot_lines(
    d: &mut Dots,
    lines: &[Segment],
    mark: &impl Fn(usize) -> Mark,
    g: &Geometry,
    grid: Grid,
    size: (usize, usize),
) {
    for (k, s) in lines.iter().enumerate() {
        let Some((a, b)) = clip(s, size) else {
            continue;
        };
        let m = mark(k);
        let (i0, j0) = sub_pos(g, grid, a.x, a.y);
        let (i1, j1) = sub_pos(g, grid, b.x, b.y);
        // Clip the walk to a generous box around the area so a far-off
        // segment (deep zoom) costs nothing.
        let lim = (d.cols.max(d.rows) * 4) as f64;
        if (i0 < -lim && i1 < -lim)
            || (j0 < -lim && j1 < -lim)
            || (i0 > lim && i1 > lim)
            || (j0 > lim && j1 > lim)
        {
            continue;
        }
        let n = ((i1 - i0).abs().max((j1 - j0).abs()).ceil() as usize).clamp(1, 1 << 16);
        for t in 0..=n {
            let f = t as f64 / n as f64;
            d.set(
                (i0 + (i1 - i0) * f).floor() as i64,
                (j0 + (j1 - j0) * f).floor() as i64,
                m,
            );
        }
    }
}

/// An ASCII stroke for a cell on a line: `-`, `|`, `/` or `\` after the
/// direction of the nearest line through it.
pub fn ascii_stroke(lines: &[Segment], geo: &Geometry, c: u16, r: u16) -> char {
    let x = geo.ox + (c as f64 + 0.5) * geo.ppu - 0.5;
    let y = geo.oy + (r as f64 + 0.5) * 2.0 * geo.ppu - 0.5;
    let p = Point::new(x, y);
    let best = lines
        .iter()
        .map(|s| (point_segment_distance(p, s), s))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let Some((_, s)) = best else { return '*' };
    // Screen aspect: a cell is twice as tall as wide.
    let dx = (s.b.x - s.a.x) / geo.ppu;
    let dy = (s.b.y - s.a.y) / (2.0 * geo.ppu);
    let ang = dy.atan2(dx).to_degrees().rem_euclid(180.0);
    match ang {
        a if !(22.5..157.5).contains(&a) => '-',
        a if (67.5..112.5).contains(&a) => '|',
        a if a < 67.5 => '\\',
        _ => '/',
    }
}
