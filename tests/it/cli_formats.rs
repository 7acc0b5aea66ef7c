//! `vss convert`, `vss info` and `vss params` run as a user runs them: exit
//! codes, what goes to stdout and stderr, and that nothing is written when a
//! command fails.

use std::path::{Path, PathBuf};

use crate::support::vss;
use vss::formats::img::{ImgFile, encode_img, write_img};
use vss::llv::GreyImage;

fn profile() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/default.toml")
}

fn sample(comment: &str) -> ImgFile {
    let px: Vec<u8> = (0..32 * 24).map(|i| (i * 7 % 251) as u8).collect();
    ImgFile {
        image: GreyImage::new(32, 24, px).unwrap(),
        comment: comment.into(),
        x0: 16,
        y0: 8,
    }
}

struct Out {
    code: i32,
    stdout: String,
    stderr: String,
}

fn run(args: &[&str], cwd: &Path) -> Out {
    let o = vss().args(args).current_dir(cwd).output().unwrap();
    Out {
        code: o.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
    }
}

#[test]
fn img_to_png_and_back_gives_the_same_bytes() {
    let d = tempfile::tempdir().unwrap();
    write_img(&d.path().join("cube1a.img"), &sample("cube1a")).unwrap();
    let o = run(&["convert", "cube1a.img", "cube1a.png"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    let o = run(&["convert", "cube1a.png", "back.img"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert_eq!(
        std::fs::read(d.path().join("back.img")).unwrap(),
        std::fs::read(d.path().join("cube1a.img")).unwrap()
    );
    for ext in ["pgm", "tif", "bmp"] {
        let name = format!("x.{ext}");
        let o = run(&["convert", "cube1a.img", &name], d.path());
        assert_eq!(o.code, 0, "{ext}: {}", o.stderr);
        assert!(
            o.stderr.contains("comment and upper-left corner dropped"),
            "{ext}: {}",
            o.stderr
        );
        let o = run(&["convert", &name, &format!("{ext}.img")], d.path());
        assert_eq!(o.code, 0, "{}", o.stderr);
        let back = vss::formats::img::read_img(&d.path().join(format!("{ext}.img"))).unwrap();
        assert_eq!(back.image, sample("").image, "{ext}");
        assert_eq!(
            back.comment,
            format!("{ext}.img"),
            "a name is given to the image"
        );
    }
}

#[test]
fn colour_input_becomes_grey_with_a_note() {
    let d = tempfile::tempdir().unwrap();
    let rgb = image::RgbImage::from_fn(20, 20, |x, y| {
        image::Rgb([(x * 12) as u8, (y * 12) as u8, 200])
    });
    rgb.save(d.path().join("c.png")).unwrap();
    let o = run(&["convert", "c.png", "c.img"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stderr.contains("note") && o.stderr.contains("grey"),
        "{}",
        o.stderr
    );
    let f = vss::formats::img::read_img(&d.path().join("c.img")).unwrap();
    assert_eq!(f.image.size(), (20, 20));
}

#[test]
fn failed_conversions_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    let mut bad = encode_img(&sample("x")).unwrap();
    bad.truncate(bad.len() - 1);
    std::fs::write(d.path().join("bad.img"), &bad).unwrap();
    std::fs::write(d.path().join("keep.png"), b"previous").unwrap();
    write_img(&d.path().join("ok.img"), &sample("ok")).unwrap();
    for (args, says) in [
        (vec!["convert", "bad.img", "out.png"], "bad.img: byte 4"),
        (vec!["convert", "missing.img", "out.png"], "missing.img"),
        (vec!["convert", "ok.img", "out.jpg"], "does not write it"),
        (vec!["convert", "bad.img", "keep.png"], "but the file has"),
        (vec!["convert", "ok.img", "nodir/out.png"], "nodir/out.png"),
    ] {
        let o = run(&args, d.path());
        assert_eq!(o.code, 1, "{args:?}");
        assert!(o.stderr.starts_with("vss: error: "), "{}", o.stderr);
        assert!(o.stderr.contains(says), "{args:?}: {}", o.stderr);
        assert!(o.stdout.is_empty());
    }
    assert_eq!(
        std::fs::read(d.path().join("keep.png")).unwrap(),
        b"previous"
    );
    let mut names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["bad.img", "keep.png", "ok.img"],
        "no output, no temp file"
    );
}

#[test]
fn info_describes_every_kind_of_file() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    write_img(&p.join("cube1a.img"), &sample("cube1a\u{1b}[31m")).unwrap();
    std::fs::write(
        p.join("cam1.cdf"),
        "S=A\n0.01\n0.01\nC=E\n256\n240\nf=A\n12\nD=N\nX=S\n4\n",
    )
    .unwrap();
    std::fs::write(
        p.join("cube1.ldr"),
        "1 10 20\n2 30 40\n3 5 60\n4 30 40\nFaces:\n1 2\n3 4\n",
    )
    .unwrap();
    std::fs::write(p.join("cube.ses"), "2\n1\n5\n").unwrap();
    std::fs::write(
        p.join("e.par"),
        "1 \"vss edges\"\n0 5\n0 \"edges.half_width\" i\n",
    )
    .unwrap();
    let e = vss::llv::EdgePoints {
        dir: Some(vss::llv::ScanDir::Horizontal),
        width: 32,
        height: 24,
        points: vec![vss::llv::EdgePoint {
            x: 1.5,
            y: 2.0,
            response: -12.0,
        }],
    };
    vss::formats::edgefile::write_edges(&p.join("cube1.hpo"), &e).unwrap();
    let prof = profile();
    let o = run(
        &[
            "info",
            "cube1a.img",
            "cam1.cdf",
            "cube1.ldr",
            "cube.ses",
            "e.par",
            "cube1.hpo",
            prof.to_str().unwrap(),
        ],
        p,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    let s = &o.stdout;
    for want in [
        "cube1a.img: grey image (ITEX .img), 32 × 24 pixels",
        "upper-left (16, 8)",
        "comment: \"cube1a[31m\"",
        "image 1, lighting a",
        "S=A (calibrated)",
        "C=E (estimated)",
        "D=N (not available)",
        "X=S (stated)",
        "unknown to vss, kept",
        "no lens distortion",
        "2 segments",
        "bounding box (5.00, 20.00) to (30.00, 60.00)",
        "session \"cube\": 2 images, 1 cameras, 5 lighting configurations",
        "1 of 10 grey images",
        "parameter set \"vss edges\", 1 entries",
        "edges.half_width (i) = 5",
        "edge points (horizontal scan), 1 points, image 32 × 24",
        "profile \"simulated cell\"",
        "lighting e: all off",
    ] {
        assert!(s.contains(want), "missing {want:?} in\n{s}");
    }
    assert!(
        !s.contains('\u{1b}'),
        "control characters reach the terminal"
    );
}

#[test]
fn info_goes_on_after_a_bad_file_and_fails_at_the_end() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("bad.ldr"), "1 0 0\n2 1 1\nFaces:\n3 x\n").unwrap();
    std::fs::write(d.path().join("good.ses"), "1\n1\n1\n").unwrap();
    let o = run(&["info", "bad.ldr", "good.ses", "what.xyz"], d.path());
    assert_eq!(o.code, 1);
    assert!(
        o.stderr.contains("bad.ldr:4: expected an end vertex index"),
        "{}",
        o.stderr
    );
    assert!(
        o.stderr.contains("what.xyz: unknown kind of file"),
        "{}",
        o.stderr
    );
    assert!(o.stdout.contains("session \"good\""), "{}", o.stdout);
}

#[test]
fn info_reports_a_bad_profile_with_line_and_key() {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(profile())
        .unwrap()
        .replace("half_width = 3 ", "half_width = 11 ");
    std::fs::write(d.path().join("cell.toml"), &text).unwrap();
    let line = text[..text.find("half_width = 11").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let o = run(&["info", "cell.toml"], d.path());
    assert_eq!(o.code, 1);
    assert!(
        o.stderr
            .contains(&format!("cell.toml:{line}: key `llv.edges.half_width`")),
        "{}",
        o.stderr
    );
    assert!(o.stderr.contains("3 to 7"), "{}", o.stderr);
}

#[test]
fn params_list_shows_every_parameter() {
    let d = tempfile::tempdir().unwrap();
    let o = run(&["params", "list"], d.path());
    assert_eq!(o.code, 0);
    for sp in vss::llv::params::PARAMS {
        let line = o
            .stdout
            .lines()
            .find(|l| l.starts_with(sp.key))
            .unwrap_or_else(|| panic!("{}", sp.key));
        assert!(
            line.contains(&sp.range_text()) && line.contains(sp.doc),
            "{line}"
        );
    }
}

#[test]
fn params_export_then_import_into_a_profile() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let prof = p.join("cell.toml");
    std::fs::copy(profile(), &prof).unwrap();
    let o = run(&["params", "export", "cell.toml", "--set", "edges"], p);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.starts_with("10 \"vss edges\"\n0 3\n"),
        "{}",
        o.stdout
    );
    let o = run(
        &[
            "params",
            "export",
            "cell.toml",
            "--set",
            "edges",
            "--out",
            "e.par",
        ],
        p,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    let par = std::fs::read_to_string(p.join("e.par"))
        .unwrap()
        .replacen("\n0 3\n", "\n0 6\n", 1);
    std::fs::write(p.join("e.par"), par).unwrap();
    // Without --out: the [llv] tables on stdout.
    let o = run(&["--profile", "cell.toml", "params", "import", "e.par"], p);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.contains("[llv.edges]\nhalf_width = 6\n"),
        "{}",
        o.stdout
    );
    // With --out: the profile, comments kept, loads with the new value.
    let o = run(
        &[
            "--profile",
            "cell.toml",
            "params",
            "import",
            "e.par",
            "--out",
            "tuned.toml",
        ],
        p,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    let tuned = std::fs::read_to_string(p.join("tuned.toml")).unwrap();
    assert!(
        tuned.contains("half_width = 6              # px, 3 to 7"),
        "{tuned}"
    );
    let loaded = vss::profile::Profile::load(p.join("tuned.toml").to_str().unwrap()).unwrap();
    assert_eq!(loaded.llv.edges.half_width, 6);
}

#[test]
fn params_import_refuses_out_of_range_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    std::fs::copy(profile(), p.join("cell.toml")).unwrap();
    std::fs::write(
        p.join("e.par"),
        "2 \"vss edges\"\n0 4\n1 99\n0 \"edges.per_region\" i\n1 \"edges.half_width\" i\n",
    )
    .unwrap();
    let o = run(
        &[
            "--profile",
            "cell.toml",
            "params",
            "import",
            "e.par",
            "--out",
            "t.toml",
        ],
        p,
    );
    assert_eq!(o.code, 1);
    assert!(
        o.stderr
            .contains("e.par:3: parameter edges.half_width = 99 is out of range"),
        "{}",
        o.stderr
    );
    assert!(o.stderr.contains("3 to 7"), "{}", o.stderr);
    assert!(!p.join("t.toml").exists());
    // Entries that are not LLV parameters are noted, not fatal.
    std::fs::write(
        p.join("f.par"),
        "1 \"other\"\n0 2\n0 \"Number of cameras\" i\n",
    )
    .unwrap();
    let o = run(&["--profile", "cell.toml", "params", "import", "f.par"], p);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stderr.contains("not an LLV parameter"), "{}", o.stderr);
}

#[test]
fn params_export_of_an_unknown_set_is_a_usage_error() {
    let d = tempfile::tempdir().unwrap();
    let prof = profile();
    let o = run(
        &[
            "params",
            "export",
            prof.to_str().unwrap(),
            "--set",
            "colours",
            "--out",
            "x.par",
        ],
        d.path(),
    );
    assert_eq!(o.code, 2);
    assert!(!d.path().join("x.par").exists());
}

#[test]
fn info_on_a_session_manifest_and_a_bom() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("cube.toml"),
        "[session]\nname = \"cube\"\n[[image]]\nnumber = 1\n[[image]]\nnumber = 2\n",
    )
    .unwrap();
    std::fs::write(d.path().join("cam.cdf"), "\u{feff}f=A\r\n12\r\n").unwrap();
    let o = run(&["info", "cube.toml", "cam.cdf"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout
            .contains("session manifest (TOML): image (2), session"),
        "{}",
        o.stdout
    );
    assert!(o.stdout.contains("f=A (calibrated)"), "{}", o.stdout);
}

#[test]
fn info_warns_about_the_dos_name_rule_and_hides_control_characters() {
    let d = tempfile::tempdir().unwrap();
    write_img(&d.path().join("longname7a.img"), &sample("a\u{0}b\u{7}c")).unwrap();
    let o = run(&["convert", "longname7a.img", "x.png"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    let o = run(&["info", "longname7a.img", "x.png"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout
            .contains("session \"longname\", image 7, lighting a"),
        "{}",
        o.stdout
    );
    assert!(o.stdout.contains("at most 8"), "{}", o.stdout);
    assert_eq!(
        o.stdout.matches("comment: \"abc\"").count(),
        2,
        "{}",
        o.stdout
    );
    // The comment with its control characters still travels exactly.
    let o = run(&["convert", "x.png", "back.img"], d.path());
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert_eq!(
        std::fs::read(d.path().join("back.img")).unwrap(),
        std::fs::read(d.path().join("longname7a.img")).unwrap()
    );
}
