//! The SVG writer, checked with a real SVG library: every document parses
//! with `usvg`, has its toggleable layers, carries the grey image as PNG
//! data, and renders (resvg + tiny-skia) with the lines where they belong.

use resvg::{tiny_skia, usvg};
use vss::llv::{EdgePoint, EdgePoints, GreyImage, Point, ScanDir, Segment};
use vss::report::{ImageReport, svg};

fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
    Segment::new(Point::new(ax, ay), Point::new(bx, by))
}

fn render(text: &str) -> (usvg::Tree, tiny_skia::Pixmap) {
    let tree = usvg::Tree::from_str(text, &usvg::Options::default()).expect("SVG parses");
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    (tree, pixmap)
}

/// Pixel (x, y) of the rendering: LLV coordinates are pixel centres.
fn rgba(p: &tiny_skia::Pixmap, x: f64, y: f64) -> [u8; 4] {
    let c = p
        .pixel(x.round() as u32, y.round() as u32)
        .unwrap()
        .demultiply();
    [c.red(), c.green(), c.blue(), c.alpha()]
}

fn find_png(g: &usvg::Group) -> Option<Vec<u8>> {
    g.children().iter().find_map(|n| match n {
        usvg::Node::Image(img) => match img.kind() {
            usvg::ImageKind::PNG(data) => Some(data.to_vec()),
            _ => None,
        },
        usvg::Node::Group(sub) => find_png(sub),
        _ => None,
    })
}

#[test]
fn image_svg_has_layers_png_and_lines_in_place() {
    let mut grey = GreyImage::filled(80, 60, 0).unwrap();
    for (i, v) in grey.data_mut().iter_mut().enumerate() {
        *v = (i % 251) as u8;
    }
    let lines = vec![seg(10.0, 30.0, 70.0, 30.0), seg(40.0, 5.0, 40.0, 55.0)];
    let r = ImageReport {
        title: "cube1".into(),
        width: 80,
        height: 60,
        greys: vec![("cube1a.img".into(), grey.clone())],
        edges_h: Some(EdgePoints {
            dir: Some(ScanDir::Horizontal),
            width: 80,
            height: 60,
            points: vec![EdgePoint {
                x: 5.0,
                y: 5.0,
                response: 20.0,
            }],
        }),
        edges_v: Some(EdgePoints::default()),
        lines_raw: Some(vec![seg(12.0, 50.0, 30.0, 50.0)]),
        lines: Some(lines.clone()),
        notes: vec![],
        problems: Vec::new(),
    };
    let text = svg::image_svg(&r);
    let (tree, pix) = render(&text);
    assert_eq!((pix.width(), pix.height()), (80, 60));
    for id in ["grey", "edges-h", "edges-v", "lines-raw", "lines"] {
        assert!(tree.node_by_id(id).is_some(), "layer {id} missing");
    }
    // The embedded PNG is the grey image, pixel for pixel.
    let Some(usvg::Node::Group(g)) = tree.node_by_id("grey") else {
        panic!("grey layer is not a group");
    };
    let png = find_png(g).expect("PNG image in the grey layer");
    let back = image::load_from_memory(&png).unwrap().to_luma8();
    assert_eq!(back.into_raw(), grey.data());
    // Red connected lines on their pixels, green raw line, orange-free elsewhere.
    for l in &lines {
        for i in 0..=10 {
            let t = f64::from(i) / 10.0;
            let (x, y) = (l.a.x + t * (l.b.x - l.a.x), l.a.y + t * (l.b.y - l.a.y));
            let [r, g, b, _] = rgba(&pix, x, y);
            assert!(
                r > 200 && g < 80 && b < 80,
                "({x},{y}) is not red: {r} {g} {b}"
            );
        }
    }
    let [r, g, b, _] = rgba(&pix, 20.0, 50.0);
    assert!(
        g > 120 && r < 80 && b < 80,
        "raw line is green: {r} {g} {b}"
    );
    let [r, g, b, _] = rgba(&pix, 5.0, 5.0);
    assert!(b > 200 && r < 80, "edge point is blue: {r} {g} {b}");
    let [r, g, b, _] = rgba(&pix, 20.0, 15.0);
    assert!(!(r > 200 && g < 80), "off the lines no red: {r} {g} {b}");
}

#[test]
fn lines_svg_matches_the_line_page() {
    let lines = [seg(20.0, 50.0, 180.0, 50.0), seg(30.0, 80.0, 70.0, 20.0)];
    let text = svg::lines_svg("test1.ldr", &lines, 200, 100);
    let (tree, pix) = render(&text);
    assert!(tree.node_by_id("lines").is_some());
    assert!(tree.node_by_id("frame").is_some());
    for l in &lines {
        for i in 0..=8 {
            let t = f64::from(i) / 8.0;
            let (x, y) = (l.a.x + t * (l.b.x - l.a.x), l.a.y + t * (l.b.y - l.a.y));
            let [r, g, b, _] = rgba(&pix, x, y);
            assert!(r < 100 && g < 100 && b < 100, "({x},{y}) not black");
        }
    }
    let [r, ..] = rgba(&pix, 100.0, 20.0);
    assert!(r > 200, "blank paper between lines");
}

#[test]
fn grey_svg_of_hostile_caption_still_parses() {
    let img = GreyImage::filled(16, 16, 7).unwrap();
    let text = svg::grey_svg("a<b>&\"c\u{1}", &img);
    let (tree, _) = render(&text);
    assert!(tree.node_by_id("grey").is_some());
}
