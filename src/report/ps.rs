//! PostScript output (spec/formats.md §7): `img2ps` grey-image pages,
//! `ldr2ps` line pages and the multi-page survey report.
//!
//! Layout is computed by the printer, not here: every page starts with
//! `clippath pathbbox` and divides the printable area into cells, so one file
//! fits A4, Letter or any other page (the device-independent scaling of the
//! original `ldr2ps`). Inside a cell the picture is the unit square, as in the
//! original: a grey image is drawn with `W H 8 [W 0 0 -H 0 H]` and a line
//! `(x1,y1)-(x2,y2)` becomes `x1/W 1-y1/H x2/W 1-y2/H l`.

use std::io::{self, Write};

use super::clip::DrawBox;
use super::{ImageReport, edge_image, edge_image_size, encode, printable};
use crate::llv::{EdgePoints, GreyImage, Segment};

/// Images per grey-image page, as in `img2ps`.
pub const IMAGES_PER_PAGE: usize = 6;
/// Text lines in the notes area under a line page: an image's header lines,
/// every LLV parameter and a few edits, so that a report takes two pages an
/// image (its text is made smaller where a page is too small to hold them).
const NOTES_ON_LINE_PAGE: usize = 40;
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
/textcell { cellbox /tmax exch 1 max def /tn exch 1 max def
  /step ch 10 sub tn div 9.5 min def
  /fs step 8 mul 9.5 div cw 8 sub tmax 0.6 mul div min def
  /ty cy0 ch add 10 sub def /Courier findfont fs scalefont setfont } def
/t { cx0 4 add ty moveto show /ty ty step sub def } def
end
"#;

/// A PostScript document written page by page to `W` (the report's
/// temporary file, or a `Vec<u8>`): nothing but the page being drawn is held
/// in memory, so a report of any length costs what one page's pictures cost.
///
/// The DSC header comes first and states the page count, so the caller
/// counts the pages before writing them ([`image_report_pages`] and the
/// other `*_pages` functions, the same plan the writer follows); [`finish`]
/// checks that the pages written are the pages declared, so a session that
/// changed between the count and the writing gives an error, not a file that
/// lies about its pages.
///
/// [`finish`]: PsWriter::finish
#[derive(Debug)]
pub struct PsWriter<W: Write> {
    out: W,
    declared: usize,
    written: usize,
}

impl<W: Write> PsWriter<W> {
    /// Writes the header and prolog of a document of `pages` pages titled
    /// `title`. A document without pages gets one page saying so (declared
    /// here, written by [`PsWriter::finish`]), so every file prints.
    pub fn begin(mut out: W, title: &str, pages: usize) -> io::Result<PsWriter<W>> {
        let declared = pages.max(1);
        out.write_all(b"%!PS-Adobe-2.0\n")?;
        writeln!(out, "%%Title: {}", printable(title))?;
        writeln!(out, "%%Creator: vss {}", env!("CARGO_PKG_VERSION"))?;
        writeln!(out, "%%Pages: {declared}")?;
        out.write_all(b"%%DocumentFonts: Helvetica Helvetica-Bold Courier\n")?;
        out.write_all(b"%%EndComments\n")?;
        out.write_all(PROLOG.as_bytes())?;
        out.write_all(b"%%EndProlog\n")?;
        Ok(PsWriter {
            out,
            declared,
            written: 0,
        })
    }

    /// Writes one page whose body `body` draws with the prolog's procedures.
    fn page(&mut self, body: impl FnOnce(&mut W) -> io::Result<()>) -> io::Result<()> {
        self.written += 1;
        writeln!(self.out, "%%Page: {} {}", self.written, self.written)?;
        self.out.write_all(b"vssdict begin\npagebox\n")?;
        body(&mut self.out)?;
        self.out.write_all(b"showpage\nend\n")
    }

    /// Writes a page whose body another module drew with this prolog's
    /// procedures (`crate::report::calibration`).
    pub(super) fn raw_page(&mut self, body: &[u8]) -> io::Result<()> {
        self.page(|o| o.write_all(body))
    }

    /// `img2ps`: grey images with their captions, up to six per page (two
    /// columns, three rows), as many pages as needed
    /// ([`grey_pages_count`]).
    pub fn grey_pages(&mut self, heading: &str, images: &[(&str, &GreyImage)]) -> io::Result<()> {
        let n = grey_pages_count(images.len());
        for (i, chunk) in images.chunks(IMAGES_PER_PAGE).enumerate() {
            self.page(|o| {
                o.write_all(page_heading(heading, i, n).as_bytes())?;
                for (j, (caption, img)) in chunk.iter().enumerate() {
                    image_cell(o, img, caption, (j % 2, j / 2), (2, 3))?;
                }
                Ok(())
            })?;
        }
        Ok(())
    }

    /// `ldr2ps`: one page, a picture of `width × height` pixels with its
    /// lines.
    pub fn lines_page(
        &mut self,
        caption: &str,
        lines: &[Segment],
        width: usize,
        height: usize,
    ) -> io::Result<()> {
        self.page(|o| {
            o.write_all(page_heading(caption, 0, 1).as_bytes())?;
            lines_cell(o, lines, width, height, caption, (0, 0), (1, 1))
        })
    }

    /// Pages of plain text (parameters, counts, timings)
    /// ([`text_pages_count`]).
    pub fn text_pages(&mut self, heading: &str, text: &[String]) -> io::Result<()> {
        let n = text_pages_count(text.len());
        for (i, chunk) in text.chunks(NOTES_PER_PAGE).enumerate() {
            self.page(|o| {
                o.write_all(page_heading(heading, i, n).as_bytes())?;
                text_cell(o, chunk, (0, 0), (1, 1))
            })?;
        }
        Ok(())
    }

    /// The survey report pages of one image ([`image_report_pages`]): its
    /// grey and edge images, then the raw and connected lines side by side
    /// with the notes below. An edge image is drawn when its page is
    /// written and dropped after it: at most one is in memory.
    pub fn image_report(&mut self, r: &ImageReport) -> io::Result<()> {
        let plan = Plan::of(r);
        if !plan.cells.is_empty() {
            let heading = format!("{}: grey and edge images", r.title);
            let n = grey_pages_count(plan.cells.len());
            for (i, chunk) in plan.cells.chunks(IMAGES_PER_PAGE).enumerate() {
                self.page(|o| {
                    o.write_all(page_heading(&heading, i, n).as_bytes())?;
                    for (j, cell) in chunk.iter().enumerate() {
                        let at = ((j % 2, j / 2), (2, 3));
                        match cell {
                            Cell::Grey(caption, img) => image_cell(o, img, caption, at.0, at.1)?,
                            Cell::Edges(caption, e) => {
                                // Checked by the plan: the size is drawable.
                                let img =
                                    edge_image(e, r.width, r.height).map_err(io::Error::other)?;
                                image_cell(o, &img, caption, at.0, at.1)?;
                            }
                        }
                    }
                    Ok(())
                })?;
            }
        }
        let (w, h) = (r.width.max(1), r.height.max(1));
        let (first, rest) = plan
            .notes
            .split_at(plan.notes.len().min(NOTES_ON_LINE_PAGE));
        self.page(|o| {
            o.write_all(page_heading(&format!("{}: lines", r.title), 0, 1).as_bytes())?;
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
                    o,
                    lines.map_or(&[][..], |l| l.as_slice()),
                    w,
                    h,
                    &caption,
                    (col, 0),
                    (2, 2),
                )?;
            }
            text_cell(o, first, (0, 1), (1, 2))
        })?;
        if !rest.is_empty() {
            self.text_pages(&format!("{}: notes (continued)", r.title), rest)?;
        }
        Ok(())
    }

    /// Writes the trailer and hands back the output. A document without
    /// pages gets its one page saying so here. An error when the pages
    /// written are not the pages the header declared.
    pub fn finish(mut self) -> io::Result<W> {
        if self.written == 0 {
            self.page(|o| o.write_all(page_heading("(nothing to show)", 0, 1).as_bytes()))?;
        }
        if self.written != self.declared {
            return Err(io::Error::other(format!(
                "the report declares {} pages but has {}: its files changed while it was \
                 written; write it again",
                self.declared, self.written
            )));
        }
        self.out.write_all(b"%%Trailer\n%%EOF\n")?;
        Ok(self.out)
    }
}

/// What the pages of one image show, in order: the one plan that both
/// [`image_report_pages`] counts and [`PsWriter::image_report`] writes.
struct Plan<'a> {
    cells: Vec<Cell<'a>>,
    notes: Vec<String>,
}

/// A picture cell of an image's grey-and-edge pages.
enum Cell<'a> {
    Grey(&'a str, &'a GreyImage),
    /// Edge points, drawn as an image only when their page is written.
    Edges(String, &'a EdgePoints),
}

impl<'a> Plan<'a> {
    fn of(r: &'a ImageReport) -> Plan<'a> {
        // An edge image that cannot be drawn is left out with a note, like a
        // file the report cannot read.
        let mut notes = r.notes.clone();
        let mut cells: Vec<Cell<'a>> = r
            .greys
            .iter()
            .map(|(c, i)| Cell::Grey(c.as_str(), i))
            .collect();
        for (e, what) in [
            (r.edges_h.as_ref(), "horizontal scan"),
            (r.edges_v.as_ref(), "vertical scan"),
        ] {
            let Some(e) = e else { continue };
            match edge_image_size(e, r.width, r.height) {
                Ok(_) => cells.push(Cell::Edges(
                    format!("{}: edges, {what} ({} points)", r.title, e.points.len()),
                    e,
                )),
                Err(err) => notes.push(format!("cannot show the edges, {what}: {err}")),
            }
        }
        Plan { cells, notes }
    }
}

/// Pages `img2ps` needs for `images` pictures.
pub fn grey_pages_count(images: usize) -> usize {
    images.div_ceil(IMAGES_PER_PAGE)
}

/// Pages of `lines` lines of text.
pub fn text_pages_count(lines: usize) -> usize {
    lines.div_ceil(NOTES_PER_PAGE)
}

/// Pages [`PsWriter::image_report`] writes for `r`.
pub fn image_report_pages(r: &ImageReport) -> usize {
    let plan = Plan::of(r);
    grey_pages_count(plan.cells.len())
        + 1
        + text_pages_count(plan.notes.len().saturating_sub(NOTES_ON_LINE_PAGE))
}

/// Writes a whole `img2ps` document to `out`.
pub fn write_grey_page<W: Write>(
    out: W,
    title: &str,
    images: &[(&str, &GreyImage)],
) -> io::Result<W> {
    let mut doc = PsWriter::begin(out, title, grey_pages_count(images.len()))?;
    doc.grey_pages(title, images)?;
    doc.finish()
}

/// Writes a whole `ldr2ps` document to `out`.
pub fn write_lines_page<W: Write>(
    out: W,
    caption: &str,
    lines: &[Segment],
    width: usize,
    height: usize,
) -> io::Result<W> {
    let mut doc = PsWriter::begin(out, caption, 1)?;
    doc.lines_page(caption, lines, width, height)?;
    doc.finish()
}

/// A document built in memory by `write` (which writes into a `Vec`, so
/// cannot fail on output), as text.
pub(super) fn in_memory(write: impl FnOnce(Vec<u8>) -> io::Result<Vec<u8>>) -> String {
    // The writers emit printable ASCII only (`printable`, hex, numbers).
    match write(Vec::new()) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        Err(e) => format!("%!PS-Adobe-2.0\n%% {}\n", printable(&e.to_string())),
    }
}

/// A whole `img2ps` document, in memory.
pub fn grey_page(title: &str, images: &[(&str, &GreyImage)]) -> String {
    in_memory(|v| write_grey_page(v, title, images))
}

/// A whole `ldr2ps` document, in memory.
pub fn lines_page(caption: &str, lines: &[Segment], width: usize, height: usize) -> String {
    in_memory(|v| write_lines_page(v, caption, lines, width, height))
}

/// The survey report of `images`, every image's pages in order, in memory
/// (a session's report is written by `crate::report::survey::write`, one
/// image at a time).
pub fn survey_report(title: &str, images: &[ImageReport]) -> String {
    in_memory(|v| {
        let pages = images.iter().map(image_report_pages).sum();
        let mut doc = PsWriter::begin(v, title, pages)?;
        for r in images {
            doc.image_report(r)?;
        }
        doc.finish()
    })
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
    out: &mut impl Write,
    img: &GreyImage,
    caption: &str,
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) -> io::Result<()> {
    let (w, h) = img.size();
    writeln!(out, "gsave\n{w} {h} {col} {row} {nc} {nr} place")?;
    writeln!(out, "/buf {w} string def")?;
    writeln!(
        out,
        "{w} {h} 8 [{w} 0 0 -{h} 0 {h}] {{currentfile buf readhexstring pop}} image"
    )?;
    encode::write_hex(out, img)?;
    writeln!(out, "grestore\n{} caption", ps_string(caption))
}

fn lines_cell(
    out: &mut impl Write,
    lines: &[Segment],
    width: usize,
    height: usize,
    caption: &str,
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) -> io::Result<()> {
    let (w, h) = (width.max(1) as f64, height.max(1) as f64);
    writeln!(out, "gsave\n{w} {h} {col} {row} {nc} {nr} place")?;
    out.write_all(b"0 setlinewidth\nframe stroke\nframe clip newpath\n")?;
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
            out.write_all(if gray {
                b"0.5 setgray\n"
            } else {
                b"0 setgray\n"
            })?;
        }
        writeln!(
            out,
            "{:.5} {:.5} {:.5} {:.5} l",
            coords[0], coords[1], coords[2], coords[3]
        )?;
    }
    writeln!(out, "grestore\n{} caption", ps_string(caption))
}

pub(super) fn text_cell(
    out: &mut impl Write,
    text: &[String],
    (col, row): (usize, usize),
    (nc, nr): (usize, usize),
) -> io::Result<()> {
    // The printer fits the text in its cell: the lines' count and the
    // longest line (Courier is 0.6 em a character) set the size, at most
    // 8 pt on 9.5 pt lines.
    let longest = text
        .iter()
        .map(|l| printable(l).chars().count())
        .max()
        .unwrap_or(0);
    writeln!(
        out,
        "{} {longest} {col} {row} {nc} {nr} textcell",
        text.len()
    )?;
    for line in text {
        writeln!(out, "{} t", ps_string(line))?;
    }
    Ok(())
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
    fn pages_that_do_not_match_the_header_are_an_error() {
        let img = GreyImage::filled(4, 3, 128).unwrap();
        // Declared two, written one: the header would lie.
        let mut doc = PsWriter::begin(Vec::new(), "t", 2).unwrap();
        doc.grey_pages("t", &[("x", &img)]).unwrap();
        let err = doc.finish().unwrap_err();
        assert!(
            err.to_string().contains("declares 2 pages but has 1"),
            "{err}"
        );
        // The count of an image's pages is the pages it writes, notes
        // overflowing onto pages of their own and an edge image that
        // cannot be drawn (a note) included.
        let r = ImageReport {
            title: "cube1".into(),
            width: 4,
            height: 3,
            greys: (0..7).map(|i| (format!("g{i}"), img.clone())).collect(),
            edges_h: Some(crate::llv::EdgePoints {
                width: 1 << 20,
                height: 1 << 20,
                ..Default::default()
            }),
            notes: (0..100).map(|i| format!("note {i}")).collect(),
            ..Default::default()
        };
        assert_eq!(image_report_pages(&r), 2 + 1 + 2);
        let ps = survey_report("s", &[r.clone(), r]);
        assert!(ps.contains("%%Pages: 10\n"));
        assert_eq!(ps.matches("%%Page: ").count(), 10);
        assert!(ps.contains("cannot show the edges, horizontal scan"));
    }

    #[test]
    fn empty_document_still_has_a_page() {
        let ps = survey_report("empty", &[]);
        assert!(ps.contains("%%Pages: 1\n"));
        assert!(ps.contains("showpage"));
    }
}
