//! PostScript output (spec/formats.md §7): `img2ps` grey-image pages,
//! `ldr2ps` line pages and the multi-page survey report.
//!
//! Layout is computed by the printer, not here: every page starts with
//! `clippath pathbbox` and divides the printable area into cells, so one file
//! fits A4, Letter or any other page (the device-independent scaling of the
//! original `ldr2ps`). Inside a cell the picture is the unit square, as in the
//! original: a grey image is drawn with `W H 8 [W 0 0 -H 0 H]` and a line
//! `(x1,y1)-(x2,y2)` becomes `x1/W 1-y1/H x2/W 1-y2/H l`.

use std::fmt::Write as _;

use super::clip::DrawBox;
use super::{ImageReport, edge_image, encode, printable};
use crate::llv::{GreyImage, Segment};

/// Images per grey-image page, as in `img2ps`.
pub const IMAGES_PER_PAGE: usize = 6;
/// Text lines in the notes area under a line page.
const NOTES_ON_LINE_PAGE: usize = 28;
/// Text lines on a page of its own.
const NOTES_PER_PAGE: usize = 60;

/// The procedures every page uses. `place` maps the unit square onto a
/// picture of `W × H` in cell (col, row) of an `ncols × nrows` grid, keeping
/// the aspect ratio and leaving room for the caption below.
const PROLOG: &str = r#"/vssdict 64 dict def
vssdict begin
/m 36 def
/l { moveto lineto stroke } def
/pagebox { initclip clippath pathbbox /ury exch def /urx exch def /lly exch def /llx exch def newpath } def
/cellbox { /nr exch def /nc exch def /row exch def /col exch def
  /cw urx llx sub m 2 mul sub nc div def
  /ch ury lly sub m 2 mul sub 16 sub nr div def
  /cx0 llx m add col cw mul add def
  /cy0 ury m sub 16 sub row 1 add ch mul sub def } def
/place { cellbox /ph exch def /pw exch def
  /s cw 12 sub pw div ch 26 sub ph div 2 copy gt { exch } if pop def
  /px0 cx0 cw pw s mul sub 2 div add def
  /py0 cy0 18 add ch 26 sub ph s mul sub add def
  px0 py0 translate pw s mul ph s mul scale } def
/frame { newpath 0 0 moveto 1 0 lineto 1 1 lineto 0 1 lineto closepath } def
/caption { /Helvetica findfont 9 scalefont setfont px0 py0 11 sub moveto show } def
/title { /Helvetica-Bold findfont 12 scalefont setfont llx m add ury m sub 10 sub moveto show } def
/textcell { cellbox /ty cy0 ch add 10 sub def /Courier findfont 8 scalefont setfont } def
/t { cx0 4 add ty moveto show /ty ty 9.5 sub def } def
end
"#;

/// A PostScript document being assembled page by page.
#[derive(Debug, Default)]
pub struct PsDoc {
    title: String,
    pages: Vec<String>,
}

impl PsDoc {
    pub fn new(title: &str) -> PsDoc {
        PsDoc {
            title: printable(title),
            pages: Vec::new(),
        }
    }

    /// Appends a page whose body another module drew with this prolog's
    /// procedures (`crate::report::calibration`).
    pub(super) fn push_page(&mut self, body: String) {
        self.pages.push(body);
    }

    /// Number of pages so far.
    pub fn page_count(&self) -> usize {
        self.pages.len()
    }

    /// `img2ps`: grey images with their captions, up to six per page (two
    /// columns, three rows), as many pages as needed.
    pub fn grey_pages(&mut self, heading: &str, images: &[(&str, &GreyImage)]) {
        let chunks: Vec<_> = images.chunks(IMAGES_PER_PAGE).collect();
        let n = chunks.len();
        for (i, chunk) in chunks.into_iter().enumerate() {
            let mut body = page_heading(heading, i, n);
            for (j, (caption, img)) in chunk.iter().enumerate() {
                image_cell(&mut body, img, caption, (j % 2, j / 2), (2, 3));
            }
            self.pages.push(body);
        }
    }

    /// `ldr2ps`: one picture of `width × height` pixels with its lines.
    pub fn lines_page(&mut self, caption: &str, lines: &[Segment], width: usize, height: usize) {
        let mut body = page_heading(caption, 0, 1);
        lines_cell(&mut body, lines, width, height, caption, (0, 0), (1, 1));
        self.pages.push(body);
    }

    /// Pages of plain text (parameters, counts, timings).
    pub fn text_pages(&mut self, heading: &str, text: &[String]) {
        let chunks: Vec<_> = text.chunks(NOTES_PER_PAGE).collect();
        let n = chunks.len();
        for (i, chunk) in chunks.into_iter().enumerate() {
            let mut body = page_heading(heading, i, n);
            text_cell(&mut body, chunk, (0, 0), (1, 1));
            self.pages.push(body);
        }
    }

    /// The survey report pages of one image: its grey and edge images, then
    /// the raw and connected lines side by side with the notes below.
    pub fn image_report(&mut self, r: &ImageReport) {
        // An edge image that cannot be drawn is left out with a note, like a
        // file the report cannot read.
        let mut notes = r.notes.clone();
        let mut edges: Vec<(String, GreyImage)> = Vec::new();
        for (e, what) in [
            (r.edges_h.as_ref(), "horizontal scan"),
            (r.edges_v.as_ref(), "vertical scan"),
        ] {
            let Some(e) = e else { continue };
            match edge_image(e, r.width, r.height) {
                Ok(img) => edges.push((
                    format!("{}: edges, {what} ({} points)", r.title, e.points.len()),
                    img,
                )),
                Err(err) => notes.push(format!("cannot show the edges, {what}: {err}")),
            }
        }
        let cells: Vec<(&str, &GreyImage)> = r
            .greys
            .iter()
            .chain(edges.iter())
            .map(|(c, i)| (c.as_str(), i))
            .collect();
        if !cells.is_empty() {
            self.grey_pages(&format!("{}: grey and edge images", r.title), &cells);
        }
        let mut body = page_heading(&format!("{}: lines", r.title), 0, 1);
        let (w, h) = (r.width.max(1), r.height.max(1));
        let sets = [
            (r.lines_raw.as_ref(), "extracted (.lex)"),
            (r.lines.as_ref(), "post-processed (.ldr)"),
        ];
        for (col, (lines, what)) in sets.into_iter().enumerate() {
            let caption = match lines {
                Some(l) => format!("{}: {} lines, {what}", r.title, l.len()),
                None => format!("{}: no lines {what}", r.title),
            };
            lines_cell(
                &mut body,
                lines.map_or(&[][..], |l| l.as_slice()),
                w,
                h,
                &caption,
                (col, 0),
                (2, 2),
            );
        }
        let (first, rest) = notes.split_at(notes.len().min(NOTES_ON_LINE_PAGE));
        text_cell(&mut body, first, (0, 1), (1, 2));
        self.pages.push(body);
        if !rest.is_empty() {
            self.text_pages(&format!("{}: notes (continued)", r.title), rest);
        }
    }

    /// The finished document with its DSC header and trailer. A document
    /// without pages gets one page saying so, so every file prints.
    pub fn finish(mut self) -> String {
        if self.pages.is_empty() {
            self.pages.push(page_heading("(nothing to show)", 0, 1));
        }
        let mut out = String::new();
        out.push_str("%!PS-Adobe-2.0\n");
        let _ = writeln!(out, "%%Title: {}", self.title);
        let _ = writeln!(out, "%%Creator: vss {}", env!("CARGO_PKG_VERSION"));
        let _ = writeln!(out, "%%Pages: {}", self.pages.len());
        out.push_str("%%DocumentFonts: Helvetica Helvetica-Bold Courier\n");
        out.push_str("%%EndComments\n");
        out.push_str(PROLOG);
        out.push_str("%%EndProlog\n");
        for (i, body) in self.pages.iter().enumerate() {
            let _ = writeln!(out, "%%Page: {} {}", i + 1, i + 1);
            out.push_str("vssdict begin\npagebox\n");
            out.push_str(body);
            out.push_str("showpage\nend\n");
        }
        out.push_str("%%Trailer\n%%EOF\n");
        out
    }
}

/// A whole `img2ps` document.
pub fn grey_page(title: &str, images: &[(&str, &GreyImage)]) -> String {
    let mut doc = PsDoc::new(title);
    doc.grey_pages(title, images);
    doc.finish()
}

/// A whole `ldr2ps` document.
pub fn lines_page(caption: &str, lines: &[Segment], width: usize, height: usize) -> String {
    let mut doc = PsDoc::new(caption);
    doc.lines_page(caption, lines, width, height);
    doc.finish()
}

/// The survey report: every image's pages, in order.
pub fn survey_report(title: &str, images: &[ImageReport]) -> String {
    let mut doc = PsDoc::new(title);
    for r in images {
        doc.image_report(r);
    }
    doc.finish()
}

/// A PostScript string literal: `(`, `)` and `\` escaped, non-ASCII dropped.
pub(super) fn ps_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('(');
    for c in printable(s).chars() {
        if matches!(c, '(' | ')' | '\\') {
            out.push('\\');
        }
        out.push(c);
    }
    out.push(')');
    out
}

pub(super) fn page_heading(heading: &str, i: usize, n: usize) -> String {
    let text = if n > 1 {
        format!("{heading} ({}/{n})", i + 1)
    } else {
        heading.to_string()
    };
    format!("{} title\n", ps_string(&text))
}

fn image_cell(
    out: &mut String,
    img: &GreyImage,
    caption: &str,
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) {
    let (w, h) = img.size();
    let _ = writeln!(out, "gsave\n{w} {h} {col} {row} {nc} {nr} place");
    let _ = writeln!(out, "/buf {w} string def");
    let _ = writeln!(
        out,
        "{w} {h} 8 [{w} 0 0 -{h} 0 {h}] {{currentfile buf readhexstring pop}} image"
    );
    encode::push_hex(out, img);
    let _ = writeln!(out, "grestore\n{} caption", ps_string(caption));
}

fn lines_cell(
    out: &mut String,
    lines: &[Segment],
    width: usize,
    height: usize,
    caption: &str,
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) {
    let (w, h) = (width.max(1) as f64, height.max(1) as f64);
    let _ = writeln!(out, "gsave\n{w} {h} {col} {row} {nc} {nr} place");
    out.push_str("0 setlinewidth\nframe stroke\nframe clip newpath\n");
    // Clipped to the drawing box, every number written is within [-1, 2]:
    // Ghostscript refuses far larger ones (`/limitcheck`).
    let bx = DrawBox::around(width, height);
    let mut gray = false;
    for s in lines.iter().filter_map(|s| bx.clip(s)) {
        let coords = [s.a.x / w, 1.0 - s.a.y / h, s.b.x / w, 1.0 - s.b.y / h];
        // Shadow lines print grey: the operator sees them but they do not
        // read as object edges.
        if s.shadow != gray {
            gray = s.shadow;
            out.push_str(if gray { "0.5 setgray\n" } else { "0 setgray\n" });
        }
        let _ = writeln!(
            out,
            "{:.5} {:.5} {:.5} {:.5} l",
            coords[0], coords[1], coords[2], coords[3]
        );
    }
    let _ = writeln!(out, "grestore\n{} caption", ps_string(caption));
}

pub(super) fn text_cell(
    out: &mut String,
    text: &[String],
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) {
    let _ = writeln!(out, "{col} {row} {nc} {nr} textcell");
    for line in text {
        let _ = writeln!(out, "{} t", ps_string(line));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::Point;

    #[test]
    fn strings_are_escaped() {
        assert_eq!(ps_string(r"a(b)\c"), r"(a\(b\)\\c)");
    }

    #[test]
    fn dsc_page_count_matches_pages() {
        let img = GreyImage::filled(4, 3, 128).unwrap();
        let imgs: Vec<(&str, &GreyImage)> = (0..7).map(|_| ("x.img", &img)).collect();
        let ps = grey_page("t", &imgs);
        assert!(ps.starts_with("%!PS-Adobe-2.0\n"));
        assert!(ps.contains("%%Pages: 2\n"));
        assert_eq!(ps.matches("%%Page: ").count(), 2);
        assert_eq!(ps.matches("showpage").count(), 2);
        assert_eq!(ps.matches(" image\n").count(), 7);
        assert!(ps.contains("4 3 8 [4 0 0 -3 0 3] {currentfile buf readhexstring pop} image"));
    }

    #[test]
    fn lines_use_unit_square_coordinates() {
        let s = Segment::new(Point::new(50.0, 100.0), Point::new(100.0, 150.0));
        let ps = lines_page("test1.ldr", &[s], 200, 200);
        assert!(ps.contains("/l { moveto lineto stroke } def"));
        assert!(ps.contains("0 setlinewidth"));
        assert!(ps.contains("0.25000 0.50000 0.50000 0.25000 l"));
        assert!(ps.contains("clippath pathbbox"));
    }

    #[test]
    fn empty_document_still_has_a_page() {
        let ps = PsDoc::new("empty").finish();
        assert!(ps.contains("%%Pages: 1\n"));
        assert!(ps.contains("showpage"));
    }
}
