//! Image previews in text cells: a grey image as half-blocks with the
//! 256-colour grey ramp, as dithered Braille dots or as an ASCII ramp; edge
//! points and line segments as Braille dots (2 × 4 per cell) or ASCII strokes;
//! lines over the grey image in a contrasting colour. Area-averaged
//! downscaling with zoom and pan, so any image fits any terminal.
//!
//! Geometry: a terminal cell is taken as one unit wide and two units tall.
//! The image is fitted into the area in those square units, then divided by
//! the zoom; a view centre in image pixels pans it.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::widgets::Widget;

use crate::llv::{EdgePoints, GreyImage, Segment};

/// How previews are drawn, picked once at start (see [`super::super::mode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PreviewMode {
    /// Plain ASCII characters; safe on any terminal.
    Ascii,
    /// Unicode Braille dots for everything (grey images dithered).
    Braille,
    /// Grey images in half-blocks with 256-colour greys; edges and lines in Braille.
    Blocks,
}

/// The ASCII ramp, dark to bright.
pub const ASCII_RAMP: &[u8] = b" .:-=+*#%@";

/// Where the preview looks: zoom (1 = whole image fits) and the centre of
/// the view in image pixels (`None` = image centre).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub zoom: f64,
    pub centre: Option<(f64, f64)>,
}

impl Default for Viewport {
    fn default() -> Self {
        Viewport {
            zoom: 1.0,
            centre: None,
        }
    }
}

impl Viewport {
    pub const MAX_ZOOM: f64 = 64.0;

    pub fn zoom_in(&mut self) {
        self.zoom = (self.zoom * 2.0).min(Self::MAX_ZOOM);
    }
    pub fn zoom_out(&mut self) {
        self.zoom = (self.zoom / 2.0).max(1.0);
        if self.zoom <= 1.0 {
            self.centre = None;
        }
    }
    /// Pans by a fraction of the visible width/height.
    pub fn pan(&mut self, dx: f64, dy: f64, image: (usize, usize)) {
        let (w, h) = (image.0 as f64, image.1 as f64);
        let (cx, cy) = self.centre.unwrap_or((w / 2.0, h / 2.0));
        let step_x = w / self.zoom * dx;
        let step_y = h / self.zoom * dy;
        self.centre = Some(((cx + step_x).clamp(0.0, w), (cy + step_y).clamp(0.0, h)));
    }
}

/// What to draw.
#[derive(Clone, Copy, Debug)]
pub enum Layer<'a> {
    Grey(&'a GreyImage),
    Edges(&'a EdgePoints),
    Lines(&'a [Segment]),
    LinesOver(&'a GreyImage, &'a [Segment]),
}

/// The mapping between cells of an area and image pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    pub area: Rect,
    /// Image pixels per unit (a cell is 1 × 2 units).
    pub ppu: f64,
    /// Image position of the area's top-left corner (pixel edges: pixel x
    /// spans [x, x+1)).
    pub ox: f64,
    pub oy: f64,
}

impl Geometry {
    pub fn new(area: Rect, image: (usize, usize), view: &Viewport) -> Geometry {
        let (iw, ih) = (image.0.max(1) as f64, image.1.max(1) as f64);
        let (aw, ah) = (area.width.max(1) as f64, 2.0 * area.height.max(1) as f64);
        let ppu = (iw / aw).max(ih / ah) / view.zoom.max(1e-6);
        let (cx, cy) = view.centre.unwrap_or((iw / 2.0, ih / 2.0));
        Geometry {
            area,
            ppu,
            ox: cx - aw * ppu / 2.0,
            oy: cy - ah * ppu / 2.0,
        }
    }

    /// The image pixel under a cell's centre (`None` outside the image).
    pub fn cell_to_pixel(
        &self,
        col: u16,
        row: u16,
        image: (usize, usize),
    ) -> Option<(usize, usize)> {
        let x = self.ox + (col as f64 + 0.5) * self.ppu;
        let y = self.oy + (row as f64 + 0.5) * 2.0 * self.ppu;
        (x >= 0.0 && y >= 0.0 && (x as usize) < image.0 && (y as usize) < image.1)
            .then_some((x as usize, y as usize))
    }

    /// The cell (relative to the area) showing image pixel `(x, y)`.
    pub fn pixel_to_cell(&self, x: f64, y: f64) -> Option<(u16, u16)> {
        let c = ((x + 0.5 - self.ox) / self.ppu).floor();
        let r = ((y + 0.5 - self.oy) / (2.0 * self.ppu)).floor();
        (c >= 0.0 && r >= 0.0 && c < self.area.width as f64 && r < self.area.height as f64)
            .then_some((c as u16, r as u16))
    }
}

/// A preview widget: one layer drawn into its area.
pub struct Preview<'a> {
    pub layer: Layer<'a>,
    pub view: Viewport,
    pub mode: PreviewMode,
    /// Colour attributes allowed (false under `NO_COLOR`).
    pub colour: bool,
    /// Image pixel to mark as the cursor.
    pub cursor: Option<(usize, usize)>,
    /// Indices of lines to draw highlighted (Edit screen selection).
    pub selected: &'a [usize],
    /// The image size to frame the layer in (edges and lines of an image
    /// share its frame); `None` = the layer's own extent.
    pub frame: Option<(usize, usize)>,
}

impl<'a> Preview<'a> {
    pub fn new(layer: Layer<'a>, mode: PreviewMode, colour: bool) -> Self {
        Preview {
            layer,
            view: Viewport::default(),
            mode,
            colour,
            cursor: None,
            selected: &[],
            frame: None,
        }
    }

    /// The image size the layer refers to.
    pub fn image_size(&self) -> (usize, usize) {
        if let Some(f) = self.frame {
            return f;
        }
        match self.layer {
            Layer::Grey(g) | Layer::LinesOver(g, _) => g.size(),
            Layer::Edges(e) => (e.width.max(1), e.height.max(1)),
            Layer::Lines(ls) => lines_extent(ls),
        }
    }
}

/// The image size implied by bare lines (their bounding box from the origin).
pub fn lines_extent(lines: &[Segment]) -> (usize, usize) {
    let mut w: f64 = 1.0;
    let mut h: f64 = 1.0;
    for s in lines {
        for p in [s.a, s.b] {
            if p.x.is_finite() && p.y.is_finite() {
                w = w.max(p.x + 1.0);
                h = h.max(p.y + 1.0);
            }
        }
    }
    (w.min(1e6) as usize, h.min(1e6) as usize)
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

fn ascii_char(g: u8) -> char {
    let i = (g as usize * ASCII_RAMP.len()) / 256;
    ASCII_RAMP[i.min(ASCII_RAMP.len() - 1)] as char
}

/// Sub-cells per cell (columns, rows) of a drawing style.
#[derive(Clone, Copy)]
struct Grid {
    sx: usize,
    sy: usize,
}

const BRAILLE_GRID: Grid = Grid { sx: 2, sy: 4 };
const BLOCK_GRID: Grid = Grid { sx: 1, sy: 2 };
const ASCII_GRID: Grid = Grid { sx: 1, sy: 1 };

/// Area-averaged grey of every sub-cell of the area (`None` outside the
/// image or where every pixel is invalid).
fn sample_grey(img: &GreyImage, g: &Geometry, grid: Grid) -> Vec<Option<u8>> {
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
        let lo = a.max(0.0).floor() as usize;
        let hi = (b.min(len as f64).ceil() as usize).max(lo + 1).min(len);
        // A sub-cell smaller than a pixel samples the pixel under its centre.
        if step < 1.0 {
            let c = (a + step / 2.0).floor();
            if c < 0.0 || c >= len as f64 {
                return None;
            }
            return Some((c as usize, c as usize + 1));
        }
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
                    (n > 0).then(|| ((sum + n / 2) / n) as u8)
                }
                _ => None,
            };
            out.push(v);
        }
    }
    out
}

/// A dot raster of the area's sub-cells.
struct Dots {
    cols: usize,
    rows: usize,
    on: Vec<u8>, // 0 = off, 1 = normal, 2 = highlighted
}

impl Dots {
    fn new(area: Rect, grid: Grid) -> Dots {
        let cols = area.width as usize * grid.sx;
        let rows = area.height as usize * grid.sy;
        Dots {
            cols,
            rows,
            on: vec![0; cols * rows],
        }
    }
    fn set(&mut self, i: i64, j: i64, v: u8) {
        if i >= 0 && j >= 0 && (i as usize) < self.cols && (j as usize) < self.rows {
            let k = j as usize * self.cols + i as usize;
            self.on[k] = self.on[k].max(v);
        }
    }
    fn get(&self, i: usize, j: usize) -> u8 {
        self.on.get(j * self.cols + i).copied().unwrap_or(0)
    }
}

fn sub_pos(g: &Geometry, grid: Grid, x: f64, y: f64) -> (f64, f64) {
    (
        (x + 0.5 - g.ox) / g.ppu * grid.sx as f64,
        (y + 0.5 - g.oy) / (2.0 * g.ppu) * grid.sy as f64,
    )
}

fn plot_edges(d: &mut Dots, e: &EdgePoints, g: &Geometry, grid: Grid) {
    for p in &e.points {
        let (i, j) = sub_pos(g, grid, p.x as f64, p.y as f64);
        if i.is_finite() && j.is_finite() {
            d.set(i.floor() as i64, j.floor() as i64, 1);
        }
    }
}

fn plot_lines(d: &mut Dots, lines: &[Segment], sel: &[usize], g: &Geometry, grid: Grid) {
    for (k, s) in lines.iter().enumerate() {
        let v = if sel.contains(&k) { 2 } else { 1 };
        let (i0, j0) = sub_pos(g, grid, s.a.x, s.a.y);
        let (i1, j1) = sub_pos(g, grid, s.b.x, s.b.y);
        if !(i0.is_finite() && j0.is_finite() && i1.is_finite() && j1.is_finite()) {
            continue;
        }
        // Clip the walk to a generous box around the area so a far-off
        // segment costs nothing.
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
                v,
            );
        }
    }
}

fn braille(bits: u8) -> char {
    char::from_u32(0x2800 + bits as u32).unwrap_or(' ')
}

const BRAILLE_BITS: [[u8; 4]; 2] = [[0x01, 0x02, 0x04, 0x40], [0x08, 0x10, 0x20, 0x80]];
/// 2 × 4 ordered-dither thresholds for grey as Braille dots.
const DITHER: [[u8; 4]; 2] = [[16, 144, 48, 176], [208, 80, 240, 112]];

/// Colours of lines drawn over images.
const LINE_COLOUR: Color = Color::Indexed(196);
const SELECTED_COLOUR: Color = Color::Indexed(51);
const LINE_ONLY_COLOUR: Color = Color::Indexed(46);

impl Widget for &Preview<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.width == 0 || area.height == 0 {
            return;
        }
        let size = self.image_size();
        let geo = Geometry::new(area, size, &self.view);
        let unicode = self.mode != PreviewMode::Ascii;
        match self.layer {
            Layer::Grey(img) => self.draw_grey(img, None, &geo, buf),
            Layer::LinesOver(img, lines) => self.draw_grey(img, Some(lines), &geo, buf),
            Layer::Edges(e) => {
                let grid = if unicode { BRAILLE_GRID } else { ASCII_GRID };
                let mut d = Dots::new(area, grid);
                plot_edges(&mut d, e, &geo, grid);
                self.draw_dots(&d, grid, &geo, buf, None);
            }
            Layer::Lines(ls) => {
                let grid = if unicode { BRAILLE_GRID } else { ASCII_GRID };
                let mut d = Dots::new(area, grid);
                plot_lines(&mut d, ls, self.selected, &geo, grid);
                self.draw_dots(&d, grid, &geo, buf, Some(ls));
            }
        }
        if let Some((x, y)) = self.cursor
            && let Some((c, r)) = geo.pixel_to_cell(x as f64, y as f64)
            && let Some(cell) = buf.cell_mut((area.x + c, area.y + r))
        {
            if self.mode == PreviewMode::Blocks && self.colour {
                cell.set_char('+').set_fg(Color::Indexed(226));
            } else {
                cell.set_char('+')
                    .set_style(Style::new().add_modifier(Modifier::REVERSED));
            }
        }
    }
}

impl Preview<'_> {
    fn draw_grey(
        &self,
        img: &GreyImage,
        lines: Option<&[Segment]>,
        geo: &Geometry,
        buf: &mut Buffer,
    ) {
        let area = geo.area;
        let blocks = self.mode == PreviewMode::Blocks && self.colour;
        let grid = if blocks {
            BLOCK_GRID
        } else if self.mode == PreviewMode::Ascii {
            ASCII_GRID
        } else {
            BRAILLE_GRID
        };
        let grey = sample_grey(img, geo, grid);
        let mut dots = Dots::new(area, grid);
        if let Some(ls) = lines {
            plot_lines(&mut dots, ls, self.selected, geo, grid);
        }
        let cols = area.width as usize * grid.sx;
        let at = |i: usize, j: usize| grey.get(j * cols + i).copied().flatten();
        for r in 0..area.height as usize {
            for c in 0..area.width as usize {
                let Some(cell) = buf.cell_mut((area.x + c as u16, area.y + r as u16)) else {
                    continue;
                };
                cell.reset();
                if blocks {
                    let colour = |j: usize| match dots.get(c, j) {
                        2 => SELECTED_COLOUR,
                        1 => LINE_COLOUR,
                        _ => at(c, j).map_or(Color::Reset, |g| Color::Indexed(grey_index(g))),
                    };
                    let (top, bottom) = (colour(2 * r), colour(2 * r + 1));
                    if top == Color::Reset && bottom == Color::Reset {
                        cell.set_char(' ');
                    } else {
                        cell.set_char('▀').set_fg(top).set_bg(bottom);
                    }
                } else if self.mode == PreviewMode::Ascii {
                    let line = dots.get(c, r);
                    match (line, at(c, r)) {
                        (0, Some(g)) => {
                            cell.set_char(ascii_char(g));
                        }
                        (0, None) => {
                            cell.set_char(' ');
                        }
                        (v, _) => {
                            cell.set_char('#');
                            cell.set_style(self.line_style(v));
                        }
                    }
                } else {
                    let mut bits = 0u8;
                    let mut line = 0u8;
                    for (dx, col_bits) in BRAILLE_BITS.iter().enumerate() {
                        for (dy, bit) in col_bits.iter().enumerate() {
                            let (i, j) = (c * 2 + dx, r * 4 + dy);
                            let l = dots.get(i, j);
                            line = line.max(l);
                            if l > 0 || at(i, j).is_some_and(|g| g > DITHER[dx][dy]) {
                                bits |= bit;
                            }
                        }
                    }
                    cell.set_char(braille(bits));
                    if line > 0 {
                        cell.set_style(self.line_style(line));
                    }
                }
            }
        }
    }

    fn line_style(&self, v: u8) -> Style {
        match (self.colour, v) {
            (true, 2) => Style::new()
                .fg(SELECTED_COLOUR)
                .add_modifier(Modifier::BOLD),
            (true, _) => Style::new().fg(LINE_COLOUR).add_modifier(Modifier::BOLD),
            (false, 2) => Style::new().add_modifier(Modifier::REVERSED),
            (false, _) => Style::new().add_modifier(Modifier::BOLD),
        }
    }

    fn draw_dots(
        &self,
        d: &Dots,
        grid: Grid,
        geo: &Geometry,
        buf: &mut Buffer,
        lines: Option<&[Segment]>,
    ) {
        let area = geo.area;
        for r in 0..area.height as usize {
            for c in 0..area.width as usize {
                let Some(cell) = buf.cell_mut((area.x + c as u16, area.y + r as u16)) else {
                    continue;
                };
                cell.reset();
                let mut bits = 0u8;
                let mut top = 0u8;
                for dx in 0..grid.sx {
                    for dy in 0..grid.sy {
                        let v = d.get(c * grid.sx + dx, r * grid.sy + dy);
                        top = top.max(v);
                        if v > 0 && grid.sx == 2 {
                            bits |= BRAILLE_BITS
                                .get(dx)
                                .and_then(|c| c.get(dy))
                                .copied()
                                .unwrap_or(0);
                        }
                    }
                }
                if top == 0 {
                    cell.set_char(' ');
                    continue;
                }
                let ch = if grid.sx == 2 {
                    braille(bits)
                } else if let Some(ls) = lines {
                    ascii_stroke(ls, geo, c as u16, r as u16)
                } else {
                    '*'
                };
                cell.set_char(ch);
                if top == 2 {
                    cell.set_style(self.line_style(2));
                } else if self.colour && lines.is_some() {
                    cell.set_fg(LINE_ONLY_COLOUR);
                }
            }
        }
    }
}

/// An ASCII stroke for a cell on a line: `-`, `|`, `/` or `\` after the
/// direction of the nearest line through it.
fn ascii_stroke(lines: &[Segment], geo: &Geometry, c: u16, r: u16) -> char {
    let x = geo.ox + (c as f64 + 0.5) * geo.ppu - 0.5;
    let y = geo.oy + (r as f64 + 0.5) * 2.0 * geo.ppu - 0.5;
    let p = crate::llv::Point::new(x, y);
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

/// Distance from a point to a segment (pixels).
pub fn point_segment_distance(p: crate::llv::Point, s: &Segment) -> f64 {
    let (vx, vy) = (s.b.x - s.a.x, s.b.y - s.a.y);
    let len2 = vx * vx + vy * vy;
    let t = if len2 > 0.0 {
        (((p.x - s.a.x) * vx + (p.y - s.a.y) * vy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = crate::llv::Point::new(s.a.x + t * vx, s.a.y + t * vy);
    p.dist(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::Point;

    fn ramp(w: usize, h: usize) -> GreyImage {
        let data = (0..w * h)
            .map(|i| ((i % w) * 255 / (w - 1)) as u8)
            .collect();
        GreyImage::new(w, h, data).unwrap()
    }

    fn render(p: &Preview, w: u16, h: u16) -> Buffer {
        let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
        p.render(buf.area, &mut buf);
        buf
    }

    #[test]
    fn grey_ramp_maps_ends_to_black_and_white() {
        assert_eq!(grey_index(0), 16);
        assert_eq!(grey_index(255), 231);
        assert_eq!(grey_index(8), 232);
        assert_eq!(grey_index(238), 255);
        let mut last = 232;
        for g in 4..=246u8 {
            let i = grey_index(g);
            assert!((232..=255).contains(&i) && i >= last, "{g} -> {i}");
            last = i;
        }
    }

    #[test]
    fn blocks_show_a_left_to_right_ramp() {
        let img = ramp(64, 32);
        let p = Preview::new(Layer::Grey(&img), PreviewMode::Blocks, true);
        let buf = render(&p, 32, 8);
        let fg = |x: u16| match buf[(x, 4)].fg {
            Color::Indexed(i) => i,
            c => panic!("unexpected {c:?}"),
        };
        assert_eq!(buf[(0, 4)].symbol(), "▀");
        assert!(fg(0) <= 233 || fg(0) == 16, "left dark: {}", fg(0));
        assert!(fg(31) >= 254 || fg(31) == 231, "right bright: {}", fg(31));
        assert!(fg(10) < fg(20));
    }

    #[test]
    fn ascii_uses_the_ramp_and_no_colour() {
        let img = ramp(80, 40);
        let p = Preview::new(Layer::Grey(&img), PreviewMode::Ascii, false);
        let buf = render(&p, 40, 10);
        assert_eq!(buf[(0, 5)].symbol(), " ");
        assert_eq!(buf[(39, 5)].symbol(), "@");
        for c in buf.content() {
            assert_eq!(c.fg, Color::Reset);
            assert_eq!(c.bg, Color::Reset);
            assert!(c.symbol().is_ascii());
        }
    }

    #[test]
    fn lines_become_braille_dots_along_the_segment() {
        // A horizontal line across a 100 × 50 image drawn in 50 × 25 cells.
        let ls = [Segment::new(Point::new(0.0, 24.0), Point::new(99.0, 24.0))];
        let mut p = Preview::new(Layer::Lines(&ls), PreviewMode::Braille, false);
        p.view = Viewport::default();
        let buf = render(&p, 50, 25);
        let row_with_dots: Vec<u16> = (0..25)
            .filter(|&y| (0..50).any(|x| buf[(x, y)].symbol() != " "))
            .collect();
        assert_eq!(row_with_dots.len(), 1, "one text row holds the line");
        let y = row_with_dots[0];
        let lit = (0..50).filter(|&x| buf[(x, y)].symbol() != " ").count();
        assert!(lit >= 48, "line spans the width: {lit}");
        let ch = buf[(25, y)].symbol().chars().next().unwrap();
        assert!(('\u{2801}'..='\u{28ff}').contains(&ch));
    }

    #[test]
    fn ascii_lines_get_direction_strokes() {
        let ls = [
            Segment::new(Point::new(0.0, 10.0), Point::new(79.0, 10.0)),
            Segment::new(Point::new(60.0, 20.0), Point::new(60.0, 79.0)),
        ];
        let img = GreyImage::filled(80, 80, 0).unwrap();
        let e = EdgePoints {
            width: 80,
            height: 80,
            ..Default::default()
        };
        let _ = (&img, &e);
        let p = Preview::new(Layer::Lines(&ls), PreviewMode::Ascii, false);
        let buf = render(&p, 80, 40);
        let text: String = buf.content().iter().map(|c| c.symbol()).collect();
        assert!(text.contains("-----"), "horizontal strokes");
        assert!(text.matches('|').count() >= 20, "vertical strokes");
    }

    #[test]
    fn zoom_and_cursor_map_back_and_forth() {
        let img = ramp(512, 512);
        let area = Rect::new(0, 0, 80, 20);
        let mut v = Viewport::default();
        let g = Geometry::new(area, img.size(), &v);
        let (c, r) = g.pixel_to_cell(256.0, 256.0).unwrap();
        let (x, y) = g.cell_to_pixel(c, r, img.size()).unwrap();
        assert!((x as i64 - 256).abs() <= 13 && (y as i64 - 256).abs() <= 13);
        v.zoom_in();
        v.zoom_in();
        let g2 = Geometry::new(area, img.size(), &v);
        assert!((g2.ppu - g.ppu / 4.0).abs() < 1e-9);
        v.pan(1.0, 0.0, img.size());
        assert!(v.centre.unwrap().0 > 256.0);
        v.zoom_out();
        v.zoom_out();
        assert_eq!(v, Viewport::default());
    }

    #[test]
    fn lines_over_grey_use_a_contrasting_colour() {
        let img = GreyImage::filled(64, 64, 128).unwrap();
        let ls = [Segment::new(Point::new(32.0, 0.0), Point::new(32.0, 63.0))];
        let p = Preview::new(Layer::LinesOver(&img, &ls), PreviewMode::Blocks, true);
        let buf = render(&p, 32, 16);
        let red = buf.content().iter().filter(|c| c.fg == LINE_COLOUR).count();
        assert!(red >= 15, "{red}");
        assert_eq!(buf[(2, 2)].fg, Color::Indexed(grey_index(128)));
    }

    #[test]
    fn masked_and_outside_pixels_stay_blank_and_tiny_areas_do_not_panic() {
        let mut img = GreyImage::filled(16, 16, 200).unwrap();
        img.set_valid_mask(Some(vec![false; 256])).unwrap();
        for mode in [
            PreviewMode::Ascii,
            PreviewMode::Braille,
            PreviewMode::Blocks,
        ] {
            let p = Preview::new(Layer::Grey(&img), mode, true);
            let buf = render(&p, 10, 5);
            assert!(
                buf.content()
                    .iter()
                    .all(|c| c.symbol() == " " || c.symbol() == "\u{2800}")
            );
            let _ = render(&p, 1, 1);
        }
    }
}
