use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::widgets::Widget;

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

fn is_braille(s: &str) -> bool {
    s.chars()
        .next()
        .is_some_and(|c| ('\u{2800}'..='\u{28ff}').contains(&c))
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

/// A dim image (the simulated cell's greys are 16–113) uses the whole
/// ramp once stretched: every ASCII character shows up.
#[test]
fn a_dim_image_is_stretched_to_the_whole_ramp() {
    let data = (0..128 * 32)
        .map(|i| (16 + (i % 128) * 97 / 127) as u8)
        .collect();
    let img = GreyImage::new(128, 32, data).unwrap();
    let s = stretch_of(&img);
    assert!(s.lo <= 18 && s.hi >= 110 && s.hi <= 113, "{s:?}");
    let p = Preview::new(Layer::Grey(&img), PreviewMode::Ascii, false);
    let buf = render(&p, 64, 8);
    let used: std::collections::BTreeSet<String> = buf
        .content()
        .iter()
        .map(|c| c.symbol().to_string())
        .collect();
    assert_eq!(used.len(), ASCII_RAMP.len(), "{used:?}");
    for c in buf.content() {
        assert_eq!(c.fg, Color::Reset);
        assert!(c.symbol().is_ascii());
    }
}

/// Braille grey under the ordered (Bayer) threshold: black has no dot,
/// white every dot, mid-grey half of them, and a dark flat grey a sparse
/// scatter that is not the same dot repeated in every cell (a lattice).
#[test]
fn braille_grey_is_an_ordered_scatter() {
    let mut d = vec![0u8; 64 * 64];
    for (i, v) in d.iter_mut().enumerate() {
        *v = match i % 64 {
            0..=15 => 0,
            16..=31 => 24,
            32..=47 => 128,
            _ => 255,
        };
    }
    let img = GreyImage::new(64, 64, d).unwrap();
    let p = Preview::new(Layer::Grey(&img), PreviewMode::Braille, false);
    let buf = render(&p, 32, 16);
    let bits = |x: u16, y: u16| {
        buf[(x, y)]
            .symbol()
            .chars()
            .next()
            .map_or(0, |c| c as u32 - 0x2800)
    };
    let block = |x0: u16| -> Vec<u32> {
        (x0..x0 + 4)
            .flat_map(|x| (4..6).map(move |y| (x, y)))
            .map(|(x, y)| bits(x, y))
            .collect()
    };
    assert!(block(1).iter().all(|&b| b == 0), "black: no dots");
    assert!(block(26).iter().all(|&b| b == 0xff), "white: every dot");
    let mid: u32 = block(18).iter().map(|b| b.count_ones()).sum();
    assert_eq!(mid, 32, "mid-grey lights half the dots");
    let dark = block(10);
    let lit: u32 = dark.iter().map(|b| b.count_ones()).sum();
    assert!((2..=10).contains(&lit), "dark grey: a few dots, {lit}");
    assert!(
        dark.windows(2).any(|w| w[0] != w[1]),
        "not one dot repeated in every cell: {dark:x?}"
    );
}

#[test]
fn lines_become_braille_dots_along_the_segment() {
    // A horizontal line across a 100 × 50 image drawn in 50 × 25 cells.
    let ls = [Segment::new(Point::new(0.0, 24.0), Point::new(99.0, 24.0))];
    let mut p = Preview::new(Layer::Lines(&ls), PreviewMode::Braille, false);
    p.frame = Some((100, 50));
    let buf = render(&p, 50, 25);
    let row_with_dots: Vec<u16> = (0..25)
        .filter(|&y| (0..50).any(|x| buf[(x, y)].symbol() != " "))
        .collect();
    assert_eq!(row_with_dots.len(), 1, "one text row holds the line");
    let y = row_with_dots[0];
    let lit = (0..50).filter(|&x| buf[(x, y)].symbol() != " ").count();
    assert!(lit >= 48, "line spans the width: {lit}");
    assert!(is_braille(buf[(25, y)].symbol()));
}

#[test]
fn ascii_lines_get_direction_strokes() {
    let ls = [
        Segment::new(Point::new(0.0, 10.0), Point::new(79.0, 10.0)),
        Segment::new(Point::new(60.0, 20.0), Point::new(60.0, 79.0)),
    ];
    let mut p = Preview::new(Layer::Lines(&ls), PreviewMode::Ascii, false);
    p.frame = Some((80, 80));
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

/// In blocks mode a line over grey is Braille in the line's colour on the
/// cell's grey, so it is drawn at 2 × 4 dots a cell, not a half-block.
#[test]
fn lines_over_grey_are_coloured_braille_in_blocks_mode() {
    let mut d = vec![60u8; 64 * 64];
    for (i, v) in d.iter_mut().enumerate() {
        if i % 64 > 40 {
            *v = 200;
        }
    }
    let img = GreyImage::new(64, 64, d).unwrap();
    let ls = [Segment::new(Point::new(20.0, 0.0), Point::new(20.0, 63.0))];
    let p = Preview::new(Layer::LinesOver(&img, &ls), PreviewMode::Blocks, true);
    let buf = render(&p, 32, 16);
    let line_cells: Vec<_> = buf
        .content()
        .iter()
        .filter(|c| c.fg == Color::Indexed(196))
        .collect();
    assert!(line_cells.len() >= 15, "{}", line_cells.len());
    for c in &line_cells {
        assert!(is_braille(c.symbol()), "{:?}", c.symbol());
        assert!(
            matches!(c.bg, Color::Indexed(16 | 231 | 232..=255)),
            "{:?}",
            c.bg
        );
        let bits = c.symbol().chars().next().unwrap() as u32 - 0x2800;
        assert!(bits.count_ones() <= 4, "one column of dots: {bits:x}");
    }
    assert_eq!(buf[(2, 2)].symbol(), "▀");
}

/// A line running beyond the image, seen zoomed out at the edge, lights
/// no dot outside the image.
#[test]
fn no_line_dot_lies_outside_the_image() {
    let img = GreyImage::filled(100, 40, 90).unwrap();
    let ls = [
        Segment::new(Point::new(-50.0, 20.0), Point::new(150.0, 20.0)),
        Segment::new(Point::new(50.0, -30.0), Point::new(50.0, 90.0)),
    ];
    for mode in [
        PreviewMode::Blocks,
        PreviewMode::Braille,
        PreviewMode::Ascii,
    ] {
        let p = Preview::new(Layer::LinesOver(&img, &ls), mode, true);
        let (w, h) = (60u16, 20u16);
        let buf = render(&p, w, h);
        let geo = Geometry::new(Rect::new(0, 0, w, h), img.size(), &p.view);
        for y in 0..h {
            for x in 0..w {
                let inside = geo.cell_to_pixel(x, y, img.size()).is_some();
                let cell = &buf[(x, y)];
                if !inside {
                    assert!(
                        cell.symbol() == " " || cell.symbol() == "\u{2800}",
                        "{mode:?}: {:?} outside the image at ({x}, {y})",
                        cell.symbol()
                    );
                }
            }
        }
    }
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
