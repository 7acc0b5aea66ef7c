//! SVG output: the same content as the PostScript report, for the screen and
//! the browser. One document per image; the `viewBox` is the image's pixel
//! frame (`0 0 W H`), the grey image is an embedded PNG, and every layer is a
//! `<g id=…>` that a viewer can toggle: `grey` (the first lighting; the others
//! are `grey-2`, `grey-3`, … hidden), `edges-h`, `edges-v`, `lines-raw`,
//! `lines`. The notes (parameters, counts, timings) are the `<desc>`.
//!
//! LLV coordinates put the origin at the *centre* of the top-left pixel, SVG
//! at its corner: the vector layers are shifted by half a pixel so lines sit
//! on the pixels they were found on. Lines are clipped, and edge points far
//! off the picture left out, by the same [`DrawBox`] as the PostScript, so
//! no coordinate written is far beyond the picture.

use std::io::{self, Write};

use super::clip::DrawBox;
use super::{ImageReport, encode, printable};
use crate::llv::{EdgePoints, GreyImage, Point, Segment};

/// Escapes text for XML content and attributes.
fn xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in printable(s).chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

/// An SVG document of one image: grey image (the first of `r.greys`), edge
/// points, raw lines and connected lines, each in its own group.
pub fn image_svg(r: &ImageReport) -> String {
    in_memory(|v| write_image_svg(v, r))
}

/// Writes the SVG document of one image ([`image_svg`]) to `out`, layer by
/// layer: no layer's text is held whole.
pub fn write_image_svg<W: Write>(mut out: W, r: &ImageReport) -> io::Result<W> {
    let (w, h) = (r.width.max(1), r.height.max(1));
    head(&mut out, &r.title, &r.notes, w, h)?;
    for (i, (caption, img)) in r.greys.iter().enumerate() {
        // The first lighting shows; the others are there to switch on.
        let (id, hidden) = if i == 0 {
            ("grey".to_string(), false)
        } else {
            (format!("grey-{}", i + 1), true)
        };
        grey_layer(&mut out, &id, caption, img, hidden)?;
    }
    let bx = DrawBox::around(w, h);
    if let Some(e) = &r.edges_h {
        edge_layer(&mut out, "edges-h", e, "#00a0ff", &bx)?;
    }
    if let Some(e) = &r.edges_v {
        edge_layer(&mut out, "edges-v", e, "#ff8000", &bx)?;
    }
    if let Some(l) = &r.lines_raw {
        lines_layer(&mut out, "lines-raw", l, "#00c000", 1.0, &bx)?;
    }
    if let Some(l) = &r.lines {
        lines_layer(&mut out, "lines", l, "#ff0000", 1.0, &bx)?;
    }
    out.write_all(b"</svg>\n")?;
    Ok(out)
}

/// The XML declaration, the `<svg>` element, title, notes and white paper.
fn head(out: &mut impl Write, title: &str, notes: &[String], w: usize, h: usize) -> io::Result<()> {
    writeln!(
        out,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}">
<title>{}</title>"#,
        xml(title)
    )?;
    if !notes.is_empty() {
        // The parameters, counts and timings travel with the picture.
        let notes: Vec<String> = notes.iter().map(|n| xml(n)).collect();
        writeln!(out, "<desc>{}</desc>", notes.join("\n"))?;
    }
    writeln!(
        out,
        "<rect id=\"paper\" width=\"{w}\" height=\"{h}\" fill=\"white\"/>"
    )
}

/// A document written into a `Vec` (which cannot fail on output), as text.
fn in_memory(write: impl FnOnce(Vec<u8>) -> io::Result<Vec<u8>>) -> String {
    match write(Vec::new()) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        Err(e) => format!("<!-- {} -->\n", xml(&e.to_string())),
    }
}

/// An SVG of a line set alone (the `ldr2ps` equivalent): a frame and the
/// lines in black on white.
pub fn lines_svg(title: &str, lines: &[Segment], width: usize, height: usize) -> String {
    in_memory(|v| write_lines_svg(v, title, lines, width, height))
}

/// Writes [`lines_svg`] to `out`.
pub fn write_lines_svg<W: Write>(
    mut out: W,
    title: &str,
    lines: &[Segment],
    width: usize,
    height: usize,
) -> io::Result<W> {
    let (w, h) = (width.max(1), height.max(1));
    head(&mut out, title, &[], w, h)?;
    // Black lines and a frame, like the printed page.
    lines_layer(
        &mut out,
        "lines",
        lines,
        "#000000",
        1.0,
        &DrawBox::around(w, h),
    )?;
    writeln!(
        out,
        "<rect id=\"frame\" x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" fill=\"none\" stroke=\"black\" stroke-width=\"1\"/>\n</svg>"
    )?;
    Ok(out)
}

/// An SVG of a grey image alone.
pub fn grey_svg(caption: &str, img: &GreyImage) -> String {
    in_memory(|v| write_grey_svg(v, caption, img))
}

/// Writes [`grey_svg`] to `out`.
pub fn write_grey_svg<W: Write>(mut out: W, caption: &str, img: &GreyImage) -> io::Result<W> {
    let (w, h) = (img.width().max(1), img.height().max(1));
    head(&mut out, caption, &[], w, h)?;
    grey_layer(&mut out, "grey", caption, img, false)?;
    out.write_all(b"</svg>\n")?;
    Ok(out)
}

fn grey_layer(
    out: &mut impl Write,
    id: &str,
    caption: &str,
    img: &GreyImage,
    hidden: bool,
) -> io::Result<()> {
    let Ok(png) = encode::png_grey(img) else {
        return Ok(());
    };
    let vis = if hidden { " visibility=\"hidden\"" } else { "" };
    write!(
        out,
        "<g id=\"{id}\"{vis}><title>{}</title><image x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" style=\"image-rendering:pixelated\" xlink:href=\"data:image/png;base64,",
        xml(caption),
        img.width(),
        img.height(),
    )?;
    encode::write_base64(out, &png)?;
    out.write_all(b"\"/></g>\n")
}

fn edge_layer(
    out: &mut impl Write,
    id: &str,
    e: &EdgePoints,
    colour: &str,
    bx: &DrawBox,
) -> io::Result<()> {
    writeln!(
        out,
        "<g id=\"{id}\" fill=\"{colour}\" transform=\"translate(0.5 0.5)\">"
    )?;
    for p in &e.points {
        if bx.contains(Point::new(f64::from(p.x), f64::from(p.y))) {
            writeln!(
                out,
                "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"0.8\" height=\"0.8\"/>",
                p.x - 0.4,
                p.y - 0.4
            )?;
        }
    }
    out.write_all(b"</g>\n")
}

fn lines_layer(
    out: &mut impl Write,
    id: &str,
    lines: &[Segment],
    colour: &str,
    width: f64,
    bx: &DrawBox,
) -> io::Result<()> {
    writeln!(
        out,
        "<g id=\"{id}\" stroke=\"{colour}\" stroke-width=\"{width}\" stroke-linecap=\"round\" fill=\"none\" transform=\"translate(0.5 0.5)\">"
    )?;
    for s in lines.iter().filter_map(|s| bx.clip(s)) {
        let dash = if s.shadow {
            " stroke-dasharray=\"2 2\""
        } else {
            ""
        };
        writeln!(
            out,
            "<line x1=\"{:.3}\" y1=\"{:.3}\" x2=\"{:.3}\" y2=\"{:.3}\"{dash}/>",
            s.a.x, s.a.y, s.b.x, s.b.y
        )?;
    }
    out.write_all(b"</g>\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_have_ids_and_view_box_is_pixels() {
        let img = GreyImage::filled(40, 30, 90).unwrap();
        let r = ImageReport {
            title: "cube<1>".into(),
            width: 40,
            height: 30,
            greys: vec![
                ("cube1a.img".into(), img.clone()),
                ("cube1b.img".into(), img),
            ],
            edges_h: Some(EdgePoints::default()),
            edges_v: Some(EdgePoints::default()),
            lines_raw: Some(vec![]),
            lines: Some(vec![Segment::new(
                Point::new(1.0, 2.0),
                Point::new(3.0, 4.0),
            )]),
            notes: vec!["edges.floor = 2 & more".into()],
            problems: Vec::new(),
        };
        let s = image_svg(&r);
        assert!(s.contains("<desc>edges.floor = 2 &amp; more</desc>"));
        assert!(s.contains("<g id=\"grey-2\" visibility=\"hidden\">"));
        for id in ["grey", "edges-h", "edges-v", "lines-raw", "lines"] {
            assert!(s.contains(&format!("<g id=\"{id}\"")), "{id}");
        }
        assert!(s.contains("viewBox=\"0 0 40 30\""));
        assert!(s.contains("cube&lt;1&gt;"));
        assert!(s.contains("x1=\"1.000\" y1=\"2.000\""));
    }
}
