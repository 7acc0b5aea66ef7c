//! `vss report` end to end: single line and image files (ldr2ps, img2ps) and
//! a whole session, rendered by Ghostscript and parsed by usvg.

use crate::support::gs;

use std::path::Path;
use std::process::Command;

use vss::formats::img::ImgFile;
use vss::llv::{EdgePoint, EdgePoints, GreyImage, Params, Point, ScanDir, Segment};
use vss::profile::Profile;
use vss::session::{OutputSet, Session};

fn vss(args: &[&str], cwd: &Path) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_vss"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "vss {args:?} failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Thirty edge points down column 20 of a 64 × 48 picture.
fn edge_column() -> EdgePoints {
    EdgePoints {
        dir: Some(ScanDir::Horizontal),
        width: 64,
        height: 48,
        points: (0..30)
            .map(|i| EdgePoint {
                x: 20.0,
                y: i as f32 + 5.0,
                response: 25.0,
            })
            .collect(),
    }
}

fn svg_parses(p: &Path) -> resvg::usvg::Tree {
    let text = std::fs::read_to_string(p).unwrap();
    resvg::usvg::Tree::from_str(&text, &resvg::usvg::Options::default())
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn ldr_file_prints_with_its_image_size() {
    let dir = tempfile::tempdir().unwrap();
    let lines = vec![
        Segment::new(Point::new(50.0, 100.0), Point::new(250.0, 100.0)),
        Segment::new(Point::new(150.0, 20.0), Point::new(150.0, 180.0)),
    ];
    vss::formats::lines::write_lines(&dir.path().join("test1.ldr"), &lines).unwrap();
    // A grey image of the same name gives the picture size (300 × 200).
    let img = ImgFile::new(GreyImage::filled(300, 200, 128).unwrap());
    vss::formats::img::write_img(&dir.path().join("test1a.img"), &img).unwrap();
    vss(
        &[
            "report",
            "--ldr",
            "test1.ldr",
            "--ps",
            "test1.ps",
            "--svg",
            "test1.svg",
        ],
        dir.path(),
    );
    let tree = svg_parses(&dir.path().join("test1.svg"));
    assert_eq!(tree.size().width(), 300.0);
    gs::require_gs();
    let page = &gs::render(&dir.path().join("test1.ps"), "a4", 72)[0];
    let bx = gs::long_run_box(page, 150).expect("frame");
    let (fw, fh) = ((bx.2 - bx.0) as f64, (bx.3 - bx.1) as f64);
    assert!((fw / fh - 1.5).abs() < 0.05, "frame {bx:?} keeps 3:2");
    for (x, y) in [(60.0, 100.0), (240.0, 100.0), (150.0, 30.0), (150.0, 170.0)] {
        let (dx, dy) = (bx.0 as f64 + x / 300.0 * fw, bx.1 as f64 + y / 200.0 * fh);
        assert!(gs::dark_near(page, dx, dy, 1), "({x},{y}) drawn");
    }
    let (dx, dy) = (
        bx.0 as f64 + 100.0 / 300.0 * fw,
        bx.1 as f64 + 50.0 / 200.0 * fh,
    );
    assert!(!gs::dark_near(page, dx, dy, 2), "blank off the lines");
}

#[test]
fn img_files_print_six_per_page() {
    let dir = tempfile::tempdir().unwrap();
    let mut names = Vec::new();
    for i in 0..7u8 {
        let name = format!("cube1{}.img", (b'a' + i) as char);
        let img = ImgFile::new(GreyImage::filled(64, 48, 30 * i).unwrap()).with_comment(&name);
        vss::formats::img::write_img(&dir.path().join(&name), &img).unwrap();
        names.push(name);
    }
    let mut args = vec!["report"];
    for n in &names {
        args.extend(["--img", n.as_str()]);
    }
    args.extend(["--ps", "cube1.ps"]);
    vss(&args, dir.path());
    vss(&["report", "--img", "cube1a.img"], dir.path());
    assert!(
        dir.path().join("cube1a.ps").is_file(),
        "default output beside the input"
    );
    gs::require_gs();
    assert_eq!(
        gs::render(&dir.path().join("cube1.ps"), "letter", 36).len(),
        2
    );
    let page = &gs::render(&dir.path().join("cube1a.ps"), "a4", 72)[0];
    let bx = gs::long_run_box(page, 60).expect("the black image");
    assert!(((bx.2 - bx.0) as f64 / (bx.3 - bx.1) as f64 - 64.0 / 48.0).abs() < 0.05);
}

#[test]
fn session_report_has_every_image() {
    let dir = tempfile::tempdir().unwrap();
    let mut p = Profile::default();
    p.survey.cameras = 2;
    let mut s = Session::create(dir.path(), "cube", &p).unwrap();
    let e = edge_column();
    let l = [Segment::new(Point::new(20.0, 5.0), Point::new(20.0, 35.0))];
    for k in 1..=2 {
        s.save_image(
            k,
            'a',
            &ImgFile::new(GreyImage::filled(64, 48, 60).unwrap()),
        )
        .unwrap();
        let set = OutputSet {
            edges_h: Some(&e),
            edges_v: Some(&e),
            lines_raw: Some(&l),
            lines: Some(&l),
            ..Default::default()
        };
        s.save_output_set(k, &set, &Params::default()).unwrap();
    }
    let sdir = s.dir().to_path_buf();
    drop(s);
    let d = sdir.to_str().unwrap();
    vss(
        &["report", d, "--ps", "all.ps", "--svg", "all.svg"],
        dir.path(),
    );
    vss(
        &["report", d, "--image", "2", "--svg", "two.svg"],
        dir.path(),
    );
    vss(&["report", d], dir.path());
    assert!(
        dir.path().join("cube.ps").is_file(),
        "default NAME.ps in the current folder"
    );
    assert!(
        !sdir.join("cube.ps").exists(),
        "nothing written into the session"
    );
    for f in ["all1.svg", "all2.svg", "two.svg"] {
        let t = svg_parses(&dir.path().join(f));
        for id in ["grey", "edges-h", "edges-v", "lines-raw", "lines"] {
            assert!(t.node_by_id(id).is_some(), "{f}: {id}");
        }
    }
    let text = std::fs::read_to_string(dir.path().join("all.ps")).unwrap();
    // Per image: its grey page and its line page, with the notes (every
    // parameter) under the lines, not a page of their own.
    let pages = text
        .lines()
        .find_map(|l| l.strip_prefix("%%Pages: "))
        .unwrap_or("none");
    assert_eq!(pages, "4", "two pages per image");
    assert!(!text.contains("notes (continued)"), "no page for the notes");
    assert!(text.contains("edges.half_width = 3"), "parameters printed");
    gs::require_gs();
    assert_eq!(gs::render(&dir.path().join("all.ps"), "a4", 36).len(), 4);
    let cube = std::fs::read_to_string(dir.path().join("cube.ps")).unwrap();
    let declared = cube
        .lines()
        .find_map(|l| l.strip_prefix("%%Pages: "))
        .and_then(|n| n.trim().parse::<usize>().ok());
    assert_eq!(
        Some(gs::render(&dir.path().join("cube.ps"), "letter", 36).len()),
        declared
    );
}

/// The console's export and `vss report` call the same writer: the same
/// pages, with the edit log, the stale mark and a note for each file that
/// cannot be shown.
#[test]
fn the_console_s_export_and_vss_report_write_the_same_pages() {
    use vss::report::survey::{self, Targets};
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "cube", &Profile::default()).unwrap();
    let e = edge_column();
    let l = [
        Segment::new(Point::new(20.0, 5.0), Point::new(20.0, 35.0)),
        Segment::new(Point::new(30.0, 5.0), Point::new(30.0, 35.0)),
    ];
    let grey = |v| ImgFile::new(GreyImage::filled(64, 48, v).unwrap());
    for k in 1..=2 {
        s.save_image(k, 'a', &grey(60)).unwrap();
        let set = OutputSet {
            edges_h: Some(&e),
            edges_v: Some(&e),
            lines_raw: Some(&l),
            lines: Some(&l),
            ..Default::default()
        };
        s.save_output_set(k, &set, &Params::default()).unwrap();
    }
    s.record_edit(1, "delete 1", &l[..1]).unwrap();
    s.save_image(2, 'a', &grey(70)).unwrap(); // image 2's outputs are stale
    let sdir = s.dir().to_path_buf();
    drop(s);
    std::fs::remove_file(sdir.join("cube1.vpo")).unwrap();
    std::fs::write(sdir.join("cube2.lex"), "1 2 3\nnot a line file\n").unwrap();

    let d = sdir.to_str().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_vss"))
        .args(["report", d, "--ps", "cli.ps", "--svg", "cli.svg"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    // Written, but the two files it cannot show are said and the status
    // says the report is not whole.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    // What the console's `e` calls.
    let s = Session::inspect(&sdir).unwrap();
    let written = survey::write(&s, None, &Targets::in_session(&s)).unwrap();
    assert_eq!(written.problems.len(), 2, "{:?}", written.problems);
    for p in &written.problems {
        assert!(
            stderr.contains(&format!("vss: warning: {p}\n")),
            "{p}\n{stderr}"
        );
    }
    let names: Vec<String> = written
        .files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["cube.ps", "cube1.svg", "cube2.svg"]);

    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    let ps = read(&sdir.join("cube.ps"));
    assert!(
        ps == read(&dir.path().join("cli.ps")),
        "the same PostScript"
    );
    for k in 1..=2 {
        assert!(
            read(&sdir.join(format!("cube{k}.svg")))
                == read(&dir.path().join(format!("cli{k}.svg"))),
            "the same SVG of image {k}"
        );
    }
    for want in [
        "manual edits \\(1\\):",
        "delete 1 -> 1 lines",
        "STALE: ",
        "cannot show cube1.vpo: the manifest records it, but it is missing",
        "cannot show cube2.lex: ",
    ] {
        assert!(ps.contains(want), "{want:?} not in the report");
    }
}
