//! `vss report` on files that state absurd sizes or coordinates, run as the
//! adversarial sweep ran it: the release binary under `ulimit -v 4000000`.
//! An edge header or a manifest record that promises a huge picture gives a
//! note naming the file, not an abort or a panic; a line vertex at 1e300
//! gives PostScript that Ghostscript renders and SVG without 300-digit
//! numbers.

use crate::support::gs;

use std::path::{Path, PathBuf};
use std::process::Output;

/// Runs `vss` in `cwd` with its address space limited to about 4 GB, as the
/// sweep did, so an allocation from an unchecked size fails fast instead of
/// filling the machine's memory.
fn vss_limited(cwd: &Path, args: &[&str]) -> Output {
    crate::support::limited::vss_under(cwd, "ulimit -v 4000000", args)
}

/// Asserts that `vss` ended normally and successfully: no abort (killed by a
/// signal), no panic (exit code 101).
fn assert_clean_success(out: &Output, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.code().is_some(),
        "{what}: vss was killed ({:?}):\n{stderr}",
        out.status
    );
    assert_ne!(
        out.status.code(),
        Some(101),
        "{what}: vss panicked:\n{stderr}"
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("memory allocation"),
        "{what}:\n{stderr}"
    );
    assert!(out.status.success(), "{what}: vss failed:\n{stderr}");
}

/// Asserts that `vss report` ended normally, wrote its files and says
/// `file` is not shown in them: exit status 3 (the report is not whole), a
/// warning naming it.
fn assert_written_marking(out: &Output, what: &str, file: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("memory allocation"),
        "{what}:\n{stderr}"
    );
    assert_eq!(out.status.code(), Some(3), "{what}:\n{stderr}");
    assert!(
        stderr.contains(&format!("vss: warning: cannot show {file}"))
            || stderr.contains(&format!("vss: warning: cannot use the size of {file}")),
        "{what}:\n{stderr}"
    );
}

/// `vss session new cube --dir sess` in `dir`; returns the session folder.
fn new_session(dir: &Path) -> PathBuf {
    let out = vss_limited(dir, &["session", "new", "cube", "--dir", "sess"]);
    assert_clean_success(&out, "session new");
    dir.join("sess/cube")
}

/// An edge file with the given header size and one point at (1, 1).
fn write_edge_file(path: &Path, width: &str, height: &str) {
    let mut b = format!("VSSEDGE 1 H {width} {height} 1\n").into_bytes();
    for v in [1.0f32, 1.0, 10.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, b).unwrap();
}

/// The longest run of decimal digits in `text`.
fn longest_digit_run(text: &str) -> usize {
    text.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

/// `vss report sess/cube --image 1 --ps r.ps --svg r.svg` in `dir`.
fn report_of_image_1(dir: &Path) -> Output {
    vss_limited(
        dir,
        &[
            "report",
            "sess/cube",
            "--image",
            "1",
            "--ps",
            "r.ps",
            "--svg",
            "r.svg",
        ],
    )
}

#[test]
fn huge_edge_header_size_is_a_note_naming_the_file_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let sess = new_session(dir.path());
    for (w, h, why) in [
        ("100000", "100000", "at most 65535"),
        ("1000000000000", "1000000000000", "at most 65535"),
        (
            "18446744073709551615",
            "18446744073709551615",
            "at most 65535",
        ),
        // Each side within the .img limit, but 4 GiB of pixels in all.
        ("65535", "65535", "cannot be drawn"),
    ] {
        write_edge_file(&sess.join("cube1.hpo"), w, h);
        let out = report_of_image_1(dir.path());
        assert_written_marking(&out, &format!("edge header {w} x {h}"), "cube1.hpo");
        let ps = std::fs::read_to_string(dir.path().join("r.ps")).unwrap();
        let note = ps
            .lines()
            .find(|l| l.contains("cannot show cube1.hpo"))
            .unwrap_or_else(|| panic!("{w} x {h}: no note about cube1.hpo in the report"));
        assert!(note.contains(why), "{w} x {h}: {note}");
        assert!(!ps.contains("edges, horizontal scan"), "{w} x {h}");
        let svg = std::fs::read_to_string(dir.path().join("r.svg")).unwrap();
        assert!(svg.contains("cannot show cube1.hpo"), "{w} x {h}");
    }
}

#[test]
fn huge_image_size_in_the_manifest_is_a_note_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let sess = new_session(dir.path());
    // A grey image record of image 1 whose file is missing and whose size is
    // absurd; the edge file gives no size, so the report falls back to it.
    let manifest = sess.join("cube.toml");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let at = text
        .find("[[image]]\nnumber = 2")
        .expect("image 2 in the manifest");
    let record = "[[image.grey]]\nletter = \"a\"\nfile = \"cube1a.img\"\n\
                  hash = \"crc32:00000000:0\"\nwidth = 4000000000\nheight = 4000000000\n\
                  saved = \"2026-01-01T00:00:00Z\"\nversion = \"0.1.0\"\n\n";
    let text = format!(
        "{}{record}{}",
        text[..at].replacen("grey = []\n", "", 1),
        &text[at..]
    );
    std::fs::write(&manifest, text).unwrap();
    write_edge_file(&sess.join("cube1.hpo"), "0", "0");
    let out = report_of_image_1(dir.path());
    assert_written_marking(&out, "manifest size 4000000000 x 4000000000", "cube1a.img");
    let ps = std::fs::read_to_string(dir.path().join("r.ps")).unwrap();
    let note = ps
        .lines()
        .find(|l| l.contains("cube1a.img recorded in the manifest"))
        .expect("a note about the manifest's size of cube1a.img");
    assert!(note.contains("4000000000 x 4000000000"), "{note}");
    assert!(ps.contains("cannot show the edges, horizontal scan"));
    let svg = std::fs::read_to_string(dir.path().join("r.svg")).unwrap();
    assert!(
        svg.contains("viewBox=\"0 0 1 1\""),
        "no picture size is used"
    );
}

#[test]
fn far_line_vertex_still_prints_in_ghostscript_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    // A diagonal from the middle off to (1e300, 1e300), a horizontal line
    // at y = 20 from x = 1e60 back to 20, and one wholly off the picture.
    let ldr = "1 50 50\n2 1e300 1e300\n3 1e60 20\n4 20 20\n\
               5 1e300 -1e300\n6 1e300 1e300\nFaces:\n1 2\n3 4\n5 6\n";
    std::fs::write(dir.path().join("test1.ldr"), ldr).unwrap();
    let out = vss_limited(
        dir.path(),
        &[
            "report",
            "--ldr",
            "test1.ldr",
            "--size",
            "100x100",
            "--ps",
            "test1.ps",
            "--svg",
            "test1.svg",
        ],
    );
    assert_clean_success(&out, "far vertex");
    let svg = std::fs::read_to_string(dir.path().join("test1.svg")).unwrap();
    assert!(longest_digit_run(&svg) < 10, "absurd number in the SVG");
    assert_eq!(svg.matches("<line ").count(), 2, "{svg}");
    resvg::usvg::Tree::from_str(&svg, &resvg::usvg::Options::default()).unwrap();
    let ps_path = dir.path().join("test1.ps");
    let ps = std::fs::read_to_string(&ps_path).unwrap();
    assert!(
        longest_digit_run(&ps) < 10,
        "absurd number in the PostScript"
    );
    gs::require_gs();
    let page = &gs::render(&ps_path, "a4", 72)[0];
    let bx = gs::long_run_box(page, 150).expect("frame");
    let (fw, fh) = ((bx.2 - bx.0) as f64, (bx.3 - bx.1) as f64);
    let at = |x: f64, y: f64| (bx.0 as f64 + x / 100.0 * fw, bx.1 as f64 + y / 100.0 * fh);
    // The drawn parts keep their direction up to the frame.
    for (x, y) in [(60.0, 60.0), (90.0, 90.0), (30.0, 20.0), (90.0, 20.0)] {
        let (dx, dy) = at(x, y);
        assert!(gs::dark_near(page, dx, dy, 1), "({x},{y}) drawn");
    }
    for (x, y) in [(30.0, 70.0), (70.0, 40.0), (10.0, 20.0)] {
        let (dx, dy) = at(x, y);
        assert!(!gs::dark_near(page, dx, dy, 2), "({x},{y}) blank");
    }
}
