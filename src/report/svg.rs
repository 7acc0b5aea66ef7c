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

use std::fmt::Write as _;

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
    let (w, h) = (r.width.max(1), r.height.max(1));
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}">
<title>{}</title>"#,
        xml(&r.title)
    );
    if !r.notes.is_empty() {
        // The parameters, counts and timings travel with the picture.
        let notes: Vec<String> = r.notes.iter().map(|n| xml(n)).collect();
        let _ = writeln!(out, "<desc>{}</desc>", notes.join("\n"));
    }
    let _ = writeln!(
        out,
        "<rect id=\"paper\" width=\"{w}\" height=\"{h}\" fill=\"white\"/>"
    );
    for (i, (caption, img)) in r.greys.iter().enumerate() {
        // The first lighting shows; the others are there to switch on.
        let (id, hidden) = if i == 0 {
            ("grey".to_string(), false)
        } else {
            (format!("grey-{}", i + 1), true)
        };
        grey_layer(&mut out, &id, caption, img, hidden);
    }
    let bx = DrawBox::around(w, h);
    if let Some(e) = &r.edges_h {
        edge_layer(&mut out, "edges-h", e, "#00a0ff", &bx);
    }
    if let Some(e) = &r.edges_v {
        edge_layer(&mut out, "edges-v", e, "#ff8000", &bx);
    }
    if let Some(l) = &r.lines_raw {
        lines_layer(&mut out, "lines-raw", l, "#00c000", 1.0, &bx);
    }
    if let Some(l) = &r.lines {
        lines_layer(&mut out, "lines", l, "#ff0000", 1.0, &bx);
    }
    out.push_str("</svg>\n");
    out
}

/// An SVG of a line set alone (the `ldr2ps` equivalent): a frame and the
/// lines in black on white.
pub fn lines_svg(title: &str, lines: &[Segment], width: usize, height: usize) -> String {
    let r = ImageReport {
        title: title.to_string(),
        width,
        height,
        lines: Some(lines.to_vec()),
        ..Default::default()
    };
    let mut s = image_svg(&r);
    // Black lines and a frame, like the printed page.
    s = s.replace(
        "<g id=\"lines\" stroke=\"#ff0000\"",
        "<g id=\"lines\" stroke=\"#000000\"",
    );
    let frame = format!(
        "<rect id=\"frame\" x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\" stroke-width=\"1\"/>\n</svg>\n",
        width.max(1),
        height.max(1)
    );
    s.replace("</svg>\n", &frame)
}

/// An SVG of a grey image alone.
pub fn grey_svg(caption: &str, img: &GreyImage) -> String {
    let r = ImageReport {
        title: caption.to_string(),
        width: img.width(),
        height: img.height(),
        greys: vec![(caption.to_string(), img.clone())],
        ..Default::default()
    };
    image_svg(&r)
}

fn grey_layer(out: &mut String, id: &str, caption: &str, img: &GreyImage, hidden: bool) {
    let Ok(png) = encode::png_grey(img) else {
        return;
    };
    let vis = if hidden { " visibility=\"hidden\"" } else { "" };
    let _ = writeln!(
        out,
        "<g id=\"{id}\"{vis}><title>{}</title><image x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" style=\"image-rendering:pixelated\" xlink:href=\"data:image/png;base64,{}\"/></g>",
        xml(caption),
        img.width(),
        img.height(),
        encode::base64(&png)
    );
}

fn edge_layer(out: &mut String, id: &str, e: &EdgePoints, colour: &str, bx: &DrawBox) {
    let _ = writeln!(
        out,
        "<g id=\"{id}\" fill=\"{colour}\" transform=\"translate(0.5 0.5)\">"
    );
    for p in &e.points {
        if bx.contains(Point::new(f64::from(p.x), f64::from(p.y))) {
            let _ = writeln!(
                out,
                "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"0.8\" height=\"0.8\"/>",
                p.x - 0.4,
                p.y - 0.4
            );
        }
    }
    out.push_str("</g>\n");
}

fn lines_layer(
    out: &mut String,
    id: &str,
    lines: &[Segment],
    colour: &str,
    width: f64,
    bx: &DrawBox,
) {
    let _ = writeln!(
        out,
        "<g id=\"{id}\" stroke=\"{colour}\" stroke-width=\"{width}\" stroke-linecap=\"round\" fill=\"none\" transform=\"translate(0.5 0.5)\">"
    );
    for s in lines.iter().filter_map(|s| bx.clip(s)) {
        let dash = if s.shadow {
            " stroke-dasharray=\"2 2\""
        } else {
            ""
        };
        let _ = writeln!(
            out,
            "<line x1=\"{:.3}\" y1=\"{:.3}\" x2=\"{:.3}\" y2=\"{:.3}\"{dash}/>",
            s.a.x, s.a.y, s.b.x, s.b.y
        );
    }
    out.push_str("</g>\n");
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
