//! The PostScript writers, checked for real: Ghostscript renders every file
//! without error and the rendered pages show the lines and images where they
//! belong, on A4 and on Letter (device-independent scaling).

use crate::support::gs;

use vss::llv::{EdgePoint, EdgePoints, GreyImage, Point, ScanDir, Segment};
use vss::report::{ImageReport, ps};

fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
    Segment::new(Point::new(ax, ay), Point::new(bx, by))
}

/// Maps picture pixels to device pixels through the rendered frame box.
fn to_device(bx: (u32, u32, u32, u32), w: f64, h: f64, x: f64, y: f64) -> (f64, f64) {
    let (x0, y0, x1, y1) = (bx.0 as f64, bx.1 as f64, bx.2 as f64, bx.3 as f64);
    (x0 + x / w * (x1 - x0), y0 + y / h * (y1 - y0))
}

#[test]
fn lines_page_draws_lines_where_they_belong_on_any_paper() {
    gs::require_gs();
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (200.0, 100.0);
    let lines = [
        seg(20.0, 50.0, 180.0, 50.0),
        seg(100.0, 10.0, 100.0, 90.0),
        seg(30.0, 80.0, 70.0, 20.0),
    ];
    let text = ps::lines_page("test1.ldr", &lines, 200, 100);
    let path = dir.path().join("test1.ps");
    std::fs::write(&path, &text).unwrap();
    for paper in ["a4", "letter"] {
        let pages = gs::render(&path, paper, 72);
        assert_eq!(pages.len(), 1, "{paper}");
        let page = &pages[0];
        let bx = gs::long_run_box(page, 150).expect("the frame is drawn");
        // The frame keeps the picture's 2:1 aspect and fills most of the width.
        let (fw, fh) = ((bx.2 - bx.0) as f64, (bx.3 - bx.1) as f64);
        assert!((fw / fh - 2.0).abs() < 0.05, "{paper}: frame {bx:?}");
        assert!(fw > 0.8 * page.width() as f64, "{paper}: frame {bx:?}");
        for l in &lines {
            for i in 0..=10 {
                let t = f64::from(i) / 10.0;
                let (x, y) = (l.a.x + t * (l.b.x - l.a.x), l.a.y + t * (l.b.y - l.a.y));
                let (dx, dy) = to_device(bx, w, h, x, y);
                assert!(
                    gs::dark_near(page, dx, dy, 1),
                    "{paper}: ({x},{y}) on {l:?} not drawn"
                );
            }
        }
        for (x, y) in [(60.0, 25.0), (150.0, 75.0), (140.0, 30.0), (10.0, 10.0)] {
            let (dx, dy) = to_device(bx, w, h, x, y);
            assert!(
                !gs::dark_near(page, dx, dy, 1),
                "{paper}: ({x},{y}) should be blank"
            );
        }
    }
}

/// Black picture with a white square in the middle.
fn target(w: usize, h: usize) -> GreyImage {
    let mut img = GreyImage::filled(w, h, 0).unwrap();
    for y in h / 4..3 * h / 4 {
        for x in w / 4..3 * w / 4 {
            img.data_mut()[y * w + x] = 255;
        }
    }
    img
}

#[test]
fn grey_page_prints_pixels_in_place_and_six_per_page() {
    gs::require_gs();
    let dir = tempfile::tempdir().unwrap();
    let img = target(64, 48);
    let one = dir.path().join("one.ps");
    std::fs::write(&one, ps::grey_page("cube1a.img", &[("cube1a.img", &img)])).unwrap();
    let page = &gs::render(&one, "a4", 72)[0];
    let bx = gs::long_run_box(page, 60).expect("the black picture is printed");
    let (fw, fh) = ((bx.2 - bx.0) as f64, (bx.3 - bx.1) as f64);
    assert!((fw / fh - 64.0 / 48.0).abs() < 0.05, "picture box {bx:?}");
    let at = |x: f64, y: f64| to_device(bx, 64.0, 48.0, x, y);
    let (cx, cy) = at(32.0, 24.0);
    assert!(!gs::dark_near(page, cx, cy, 2), "centre is white");
    let (kx, ky) = at(4.0, 4.0);
    assert!(gs::dark(page, kx as u32, ky as u32), "corner is black");
    // The white square sits in the middle half, top and bottom not flipped.
    let (tx, ty) = at(32.0, 8.0);
    assert!(gs::dark(page, tx as u32, ty as u32));
    // The caption sits below the picture's lower-left corner.
    let below = (bx.3 + 2..page.height()).take(20);
    let caption_ink = below
        .flat_map(|y| (bx.0..bx.0 + 60).map(move |x| (x, y)))
        .filter(|&(x, y)| gs::dark(page, x, y))
        .count();
    assert!(caption_ink > 20, "caption printed under the picture");

    let seven: Vec<GreyImage> = (0..7).map(|i| target(32 + 8 * i, 32)).collect();
    let named: Vec<(String, GreyImage)> = seven
        .into_iter()
        .enumerate()
        .map(|(i, g)| (format!("cube1{}.img", (b'a' + i as u8) as char), g))
        .collect();
    let refs: Vec<(&str, &GreyImage)> = named.iter().map(|(n, g)| (n.as_str(), g)).collect();
    let many = dir.path().join("many.ps");
    let text = ps::grey_page("cube1", &refs);
    assert!(text.contains("%%Pages: 2"));
    std::fs::write(&many, text).unwrap();
    let pages = gs::render(&many, "letter", 36);
    assert_eq!(pages.len(), 2);
    assert!(
        gs::long_run_box(&pages[1], 20).is_some(),
        "seventh image on page 2"
    );
}

#[test]
fn survey_report_renders_every_page() {
    gs::require_gs();
    let dir = tempfile::tempdir().unwrap();
    let edges = |dir| EdgePoints {
        dir: Some(dir),
        width: 64,
        height: 48,
        points: (0..40)
            .map(|i| EdgePoint {
                x: 16.0,
                y: 4.0 + i as f32,
                response: 30.0,
            })
            .collect(),
    };
    let r = ImageReport {
        title: "cube1".into(),
        width: 64,
        height: 48,
        greys: vec![
            ("cube1a.img".into(), target(64, 48)),
            ("cube1b.img".into(), target(64, 48)),
        ],
        edges_h: Some(edges(ScanDir::Horizontal)),
        edges_v: Some(edges(ScanDir::Vertical)),
        lines_raw: Some(vec![
            seg(16.0, 4.0, 16.0, 44.0),
            seg(48.0, 12.0, 48.0, 36.0),
        ]),
        lines: Some(vec![seg(16.0, 4.0, 16.0, 44.0)]),
        notes: (0..70)
            .map(|i| format!("note {i}: (parenthesised) \\ text"))
            .collect(),
        problems: Vec::new(),
    };
    let text = ps::survey_report("cube", &[r.clone(), r]);
    let path = dir.path().join("cube.ps");
    std::fs::write(&path, &text).unwrap();
    // Per image: one image page, one lines page, one page of continued notes.
    assert!(text.contains("%%Pages: 6"), "{}", &text[..300]);
    let pages = gs::render(&path, "a4", 36);
    assert_eq!(pages.len(), 6);
    for (i, p) in pages.iter().enumerate() {
        assert!(
            p.pixels().any(|px| px.0[0] < 100),
            "page {} is blank",
            i + 1
        );
    }
}

/// An image's notes (its header lines and every parameter) print under its
/// lines on the same page, inside the page's margins on any paper: the
/// printer sizes the text to its cell. They used to spill five lines onto a
/// page of their own, and on a small page to run past its edges.
#[test]
fn an_image_s_notes_fit_under_its_lines_on_any_paper() {
    gs::require_gs();
    let dir = tempfile::tempdir().unwrap();
    let r = ImageReport {
        title: "deck1".into(),
        width: 64,
        height: 48,
        greys: Vec::new(),
        edges_h: None,
        edges_v: None,
        lines_raw: Some(vec![seg(16.0, 4.0, 16.0, 44.0)]),
        lines: Some(vec![seg(16.0, 4.0, 16.0, 44.0)]),
        notes: (0..36)
            .map(|i| format!("note {i:2}: {}", "counts and parameters ".repeat(5)))
            .collect(),
        problems: Vec::new(),
    };
    let text = ps::survey_report("deck", &[r]);
    assert!(text.contains("%%Pages: 1\n"), "{}", &text[..300]);
    let path = dir.path().join("deck.ps");
    std::fs::write(&path, &text).unwrap();
    // At 72 dpi a device pixel is a point; the page's margin is 36 pt.
    for paper in ["a4", "letter", "a5"] {
        let pages = gs::render(&path, paper, 72);
        assert_eq!(pages.len(), 1, "{paper}");
        let p = &pages[0];
        let (w, h) = (p.width(), p.height());
        let ink = |x0: u32, x1: u32, y0: u32, y1: u32| {
            (y0..y1).any(|y| (x0..x1).any(|x| gs::dark(p, x, y)))
        };
        assert!(!ink(0, w, h - 30, h), "{paper}: text below the margin");
        assert!(!ink(w - 30, w, 0, h), "{paper}: text past the right margin");
        // The last note is printed just above the bottom margin, and the
        // longest ones reach across most of the width.
        assert!(ink(0, w, h - 90, h - 36), "{paper}: the last note");
        assert!(ink(w * 2 / 3, w - 36, h / 2, h - 36), "{paper}: long notes");
    }
}
