//! Image previews in text cells: a grey image as half-blocks with the
//! 256-colour grey ramp, as Braille dots under an ordered (Bayer) threshold
//! or as an ASCII ramp, always stretched from its 1st to its 99th
//! percentile so a dim image shows its detail; edge points and line
//! segments as Braille dots (2 × 4 per cell) or ASCII strokes; lines over
//! the grey image in a contrasting colour — in blocks mode as coloured
//! Braille on the cell's grey, four times the resolution of half-blocks.
//! Area-averaged downscaling with zoom and pan, so any image fits any
//! terminal; nothing is drawn outside the image.
//!
//! Geometry: a terminal cell is taken as one unit wide and two units tall.
//! The image is fitted into the area in those square units, then divided by
//! the zoom; a view centre in image pixels pans it.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::widgets::Widget;

use crate::llv::{EdgePoints, GreyImage, Segment};

mod raster;

use raster::{BLOCK_GRID, BRAILLE_GRID, Dots, Grid, Mark, braille, plot_edges, plot_lines};
pub use raster::{Stretch, grey_index, stretch_of};

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

/// The colours of a preview: the 256-colour palette, or the 16 basic ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Palette {
    /// Colour attributes allowed at all (false under `NO_COLOR`).
    pub colour: bool,
    /// The 256-colour palette is there (not on a Linux console).
    pub c256: bool,
}

impl Palette {
    fn mark(self, m: Mark) -> Color {
        match (self.c256, m) {
            (true, Mark::Line) => Color::Indexed(196),
            (true, Mark::Selected) => Color::Indexed(51),
            (true, Mark::Highlighted) => Color::Indexed(226),
            (true, Mark::Result) => Color::Indexed(46),
            (false, Mark::Line) => Color::LightRed,
            (false, Mark::Selected) => Color::LightCyan,
            (false, Mark::Highlighted) => Color::LightYellow,
            (false, Mark::Result) => Color::LightGreen,
            (_, Mark::None) => Color::Reset,
        }
    }
}

/// A preview widget: one layer drawn into its area.
pub struct Preview<'a> {
    pub layer: Layer<'a>,
    pub view: Viewport,
    pub mode: PreviewMode,
    pub palette: Palette,
    /// Image pixel to mark as the cursor.
    pub cursor: Option<(usize, usize)>,
    /// Lines drawn as selected, the one highlighted, and those an edit made.
    pub selected: &'a [usize],
    pub highlighted: Option<usize>,
    pub result: &'a [usize],
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
            palette: Palette { colour, c256: true },
            cursor: None,
            selected: &[],
            highlighted: None,
            result: &[],
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

    fn mark_of(&self, k: usize) -> Mark {
        if self.highlighted == Some(k) {
            Mark::Highlighted
        } else if self.selected.contains(&k) {
            Mark::Selected
        } else if self.result.contains(&k) {
            Mark::Result
        } else {
            Mark::Line
        }
    }

    fn blocks(&self) -> bool {
        self.mode == PreviewMode::Blocks && self.palette.colour
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

fn ascii_char(g: u8) -> char {
    let i = (g as usize * ASCII_RAMP.len()) / 256;
    ASCII_RAMP[i.min(ASCII_RAMP.len() - 1)] as char
}

impl Widget for &Preview<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.width == 0 || area.height == 0 {
            return;
        }
        let size = self.image_size();
        let geo = Geometry::new(area, size, &self.view);
        let unicode = self.mode != PreviewMode::Ascii;
        let grid = if unicode {
            BRAILLE_GRID
        } else {
            Grid { sx: 1, sy: 1 }
        };
        let marks = |k: usize| self.mark_of(k);
        match self.layer {
            Layer::Grey(img) => self.draw_grey(img, None, &geo, buf),
            Layer::LinesOver(img, lines) => self.draw_grey(img, Some(lines), &geo, buf),
            Layer::Edges(e) => {
                let mut d = Dots::new(area, grid);
                plot_edges(&mut d, e, &geo, grid, size);
                self.draw_dots(&d, grid, &geo, buf, None);
            }
            Layer::Lines(ls) => {
                let mut d = Dots::new(area, grid);
                plot_lines(&mut d, ls, &marks, &geo, grid, size);
                self.draw_dots(&d, grid, &geo, buf, Some(ls));
            }
        }
        if let Some((x, y)) = self.cursor
            && let Some((c, r)) = geo.pixel_to_cell(x as f64, y as f64)
            && let Some(cell) = buf.cell_mut((area.x + c, area.y + r))
        {
            if self.blocks() {
                cell.set_char('+')
                    .set_fg(self.palette.mark(Mark::Highlighted));
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
        let blocks = self.blocks();
        let grid = if self.mode == PreviewMode::Ascii {
            Grid { sx: 1, sy: 1 }
        } else {
            BRAILLE_GRID
        };
        let stretch = stretch_of(img);
        // Blocks sample at half-block resolution for the grey, Braille
        // resolution for the lines over it.
        let grey_grid = if blocks { BLOCK_GRID } else { grid };
        let grey = raster::sample_grey(img, geo, grey_grid, stretch);
        let mut dots = Dots::new(area, grid);
        if let Some(ls) = lines {
            let marks = |k: usize| self.mark_of(k);
            plot_lines(&mut dots, ls, &marks, geo, grid, img.size());
        }
        let cols = area.width as usize * grey_grid.sx;
        let at = |i: usize, j: usize| grey.get(j * cols + i).copied().flatten();
        for r in 0..area.height as usize {
            for c in 0..area.width as usize {
                let Some(cell) = buf.cell_mut((area.x + c as u16, area.y + r as u16)) else {
                    continue;
                };
                cell.reset();
                let (bits, mark) = dots.cell_bits(c, r);
                if blocks {
                    let (top, bottom) = (at(c, 2 * r), at(c, 2 * r + 1));
                    let grey_of =
                        |g: Option<u8>| g.map_or(Color::Reset, |g| Color::Indexed(grey_index(g)));
                    if mark != Mark::None {
                        // Coloured Braille over the cell's mean grey.
                        let mean = match (top, bottom) {
                            (Some(a), Some(b)) => Some(((a as u16 + b as u16) / 2) as u8),
                            (a, b) => a.or(b),
                        };
                        cell.set_char(braille(bits))
                            .set_fg(self.palette.mark(mark))
                            .set_bg(grey_of(mean));
                    } else if top.is_none() && bottom.is_none() {
                        cell.set_char(' ');
                    } else {
                        cell.set_char('▀')
                            .set_fg(grey_of(top))
                            .set_bg(grey_of(bottom));
                    }
                } else if self.mode == PreviewMode::Ascii {
                    match (mark, at(c, r)) {
                        (Mark::None, Some(g)) => {
                            cell.set_char(ascii_char(g));
                        }
                        (Mark::None, None) => {
                            cell.set_char(' ');
                        }
                        (m, _) => {
                            cell.set_char('#');
                            cell.set_style(self.line_style(m));
                        }
                    }
                } else {
                    let shade = raster::dither_bits(c, r, &at);
                    cell.set_char(braille(bits | shade));
                    if mark != Mark::None {
                        cell.set_style(self.line_style(mark));
                    }
                }
            }
        }
    }

    fn line_style(&self, m: Mark) -> Style {
        if self.palette.colour {
            Style::new()
                .fg(self.palette.mark(m))
                .add_modifier(Modifier::BOLD)
        } else {
            match m {
                Mark::Selected | Mark::Highlighted | Mark::Result => {
                    Style::new().add_modifier(Modifier::REVERSED)
                }
                Mark::Line | Mark::None => Style::new().add_modifier(Modifier::BOLD),
            }
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
                let (bits, top) = d.cell_bits(c, r);
                if top == Mark::None {
                    cell.set_char(' ');
                    continue;
                }
                let ch = if grid.sx == 2 {
                    braille(bits)
                } else if let Some(ls) = lines {
                    raster::ascii_stroke(ls, geo, c as u16, r as u16)
                } else {
                    '*'
                };
                cell.set_char(ch);
                if top != Mark::Line {
                    cell.set_style(self.line_style(top));
                } else if self.palette.colour && lines.is_some() {
                    cell.set_fg(self.palette.mark(Mark::Result));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
