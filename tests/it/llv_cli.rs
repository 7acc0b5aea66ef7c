//! `vss llv` as a user runs it: outputs written where asked, lightings of one
//! view combined, JSON with stable keys, `--from-edges`, bad inputs reported.

use std::path::Path;

use crate::support::vss;
use assert_cmd::assert::OutputAssertExt;
use vss::formats::img::{ImgFile, write_img};
use vss::llv::GreyImage;

fn write(dir: &Path, name: &str, f: impl Fn(usize, usize) -> u8) {
    let (w, h) = (96, 80);
    let d = (0..w * h).map(|i| f(i % w, i / w)).collect();
    let img = GreyImage::new(w, h, d).unwrap();
    write_img(&dir.join(name), &ImgFile::new(img)).unwrap();
}

fn rect(x: usize, y: usize, hi: u8, lo: u8) -> u8 {
    if (20..70).contains(&x) && (15..60).contains(&y) {
        hi
    } else {
        lo
    }
}

#[test]
fn images_give_edge_and_line_files_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "cube1a.img", |x, y| rect(x, y, 200, 40));
    write(d, "cube1b.img", |x, y| rect(x, y, 120, 70));
    write(d, "plate2.img", |x, y| if x + y > 90 { 170 } else { 60 });
    let out = d.join("out");
    let r = vss()
        .args(["llv", "--json", "--out"])
        .arg(&out)
        .arg(d.join("cube1a.img"))
        .arg(d.join("cube1b.img"))
        .arg(d.join("plate2.img"))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let text = String::from_utf8(r.stdout).unwrap();
    let objs: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(
        objs.len(),
        2,
        "two lightings of one view are one input: {text}"
    );
    assert_eq!(objs[0]["image"], "cube1");
    assert_eq!(objs[0]["lines"], 4, "{}", objs[0]);
    for o in &objs {
        for k in ["edges_h", "edges_v", "lines_raw", "lines"] {
            assert!(o[k].as_u64().is_some(), "{k} in {o}");
        }
        for k in ["lens", "edges", "lines", "connect"] {
            assert!(o["timings_us"][k].as_u64().is_some(), "timings_us.{k}");
        }
        let attrs = o["line_attributes"].as_array().unwrap();
        assert_eq!(attrs.len() as u64, o["lines"].as_u64().unwrap());
    }
    for f in [
        "cube1.hpo",
        "cube1.vpo",
        "cube1.lex",
        "cube1.ldr",
        "plate2.ldr",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    assert!(!out.join("cube1a.imc").exists(), ".imc only with --cdf");

    // The line stages again from the edge files alone give the same lines.
    let out2 = d.join("again");
    vss()
        .args(["llv", "--out"])
        .arg(&out2)
        .arg("--from-edges")
        .arg(out.join("cube1.hpo"))
        .arg(out.join("cube1.vpo"))
        .assert()
        .success();
    assert_eq!(
        std::fs::read(out.join("cube1.ldr")).unwrap(),
        std::fs::read(out2.join("cube1.ldr")).unwrap()
    );
}

#[test]
fn a_missing_image_fails_but_the_others_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "plate2.img", |x, y| if x + y > 90 { 170 } else { 60 });
    let r = vss()
        .args(["llv", "--set", "edges.per_region=4"])
        .arg(d.join("nothere.img"))
        .arg(d.join("plate2.img"))
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("nothere.img"), "{err}");
    assert!(d.join("plate2.ldr").is_file(), "written beside the input");
    let r = vss()
        .args(["llv", "--set", "edges.half_width=9"])
        .arg(d.join("plate2.img"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("edges.half_width"));
}

/// A hand-made edge file with a stray point far outside its image (ten
/// million scan lines down) runs like any other: the line stages once
/// tried to size their bitmaps by it and aborted on a 3.7 TB allocation.
#[test]
fn a_stray_edge_point_far_outside_the_image_is_no_crash() {
    use vss::formats::edgefile::write_edges;
    use vss::llv::{EdgePoint, EdgePoints, ScanDir};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let point = |x: f32, y: f32| EdgePoint {
        x,
        y,
        response: 25.0,
    };
    let mut h: Vec<EdgePoint> = (0..40)
        .map(|y| point(30.0 + 0.25 * y as f32, y as f32))
        .collect();
    h.push(point(1_000_000.0, 9_999_990.0));
    let v: Vec<EdgePoint> = (0..40)
        .map(|x| point(x as f32, 20.0 + 0.5 * x as f32))
        .collect();
    let edges = |dir, points| EdgePoints {
        dir: Some(dir),
        width: 64,
        height: 48,
        points,
    };
    write_edges(&d.join("stray.hpo"), &edges(ScanDir::Horizontal, h)).unwrap();
    write_edges(&d.join("stray.vpo"), &edges(ScanDir::Vertical, v)).unwrap();
    let r = vss()
        .args(["llv", "--json", "--out"])
        .arg(d)
        .arg("--from-edges")
        .arg(d.join("stray.hpo"))
        .arg(d.join("stray.vpo"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    let o: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(o["lines"], 2, "the steep line and the shallow one: {o}");
    assert!(d.join("stray.ldr").is_file());
}

/// A small file that decodes to an image beyond what the stages take (a PNG
/// of zeros, 8200 × 8200 pixels in under a megabyte) is refused with its
/// size and the limit, before a lens map or the stages take memory for it.
#[test]
fn an_image_beyond_the_stages_limit_is_refused_up_front() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge1.png");
    let (w, h) = (8200u32, 8200u32);
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row = vec![0u8; w as usize];
    for _ in 0..h {
        stream.write_all(&row).unwrap();
    }
    stream.finish().unwrap();
    writer.finish().unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() < 1 << 20);
    let cdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/sim/cam1.cdf");
    let r = vss()
        .args(["llv", "--cdf"])
        .arg(&cdf)
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("huge1.png") && err.contains("8200 × 8200") && err.contains("too large"),
        "{err}"
    );
    assert!(!dir.path().join("huge1.ldr").exists());
}

/// Issue 34, N12: `--json` names the profile file in use — `built-in`
/// for the compiled-in default, else the file's absolute path — on the
/// image runs and on `--from-edges`, and so does `vss selftest --json`.
#[test]
fn json_names_the_profile_file_in_use() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let home = d.join("home");
    std::fs::create_dir_all(&home).unwrap();
    write(d, "box1.img", |x, y| rect(x, y, 200, 40));
    std::fs::write(d.join("cell.toml"), vss::profile::BUILTIN_TOML).unwrap();
    let json = |args: &[&str]| -> Vec<serde_json::Value> {
        let r = vss()
            .current_dir(d)
            .env("HOME", &home)
            .env("XDG_CONFIG_HOME", home.join(".config"))
            .args(args)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        String::from_utf8(r.stdout)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let file = d.join("cell.toml").display().to_string();
    let o = json(&["llv", "--json", "--out", "a", "box1.img"]);
    assert_eq!(o[0]["profile"], "built-in", "{}", o[0]);
    let o = json(&[
        "--profile",
        "cell.toml",
        "llv",
        "--json",
        "--out",
        "b",
        "box1.img",
    ]);
    assert_eq!(o[0]["profile"], file.as_str(), "{}", o[0]);
    let o = json(&[
        "--profile",
        "cell.toml",
        "llv",
        "--json",
        "--out",
        "c",
        "--from-edges",
        "b/box1.hpo",
        "b/box1.vpo",
    ]);
    assert_eq!(o[0]["profile"], file.as_str(), "{}", o[0]);
    let o = json(&[
        "--profile",
        "cell.toml",
        "selftest",
        "--json",
        "--family",
        "cubes",
        "--noise",
        "2",
        "--scenes",
        "1",
        "--size",
        "64",
    ]);
    assert_eq!(o[0]["profile"], file.as_str());
}

/// Issue 34, N5: `vss llv` of an image at the picture bound (8192², a
/// 64 MiB `.img`) within 5 × the file's size of address space (`ulimit
/// -v`, so a run over it fails to allocate whatever the machine). It held
/// the image twice and both scan directions' responses and buffers at once
/// (480 MiB resident, 384 MiB of address space too little); it now holds
/// one copy of the pixels and one direction's buffers at a time (247 MiB
/// resident, runs in 272 MiB).
#[test]
fn llv_of_the_largest_picture_holds_one_direction_at_a_time() {
    let dir = tempfile::tempdir().unwrap();
    let side = 8192usize;
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut px = vec![0u8; side * side];
    for (i, p) in px.iter_mut().enumerate() {
        let (x, y) = (i % side, i / side);
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let noise = (seed % 7) as i32 - 3;
        let base = if (1000..3000).contains(&x) && (1200..3500).contains(&y) {
            190
        } else if (2500..6100).contains(&x) && (4800..7400).contains(&y) {
            30
        } else {
            60 + (40 * x / side) as i32
        };
        *p = (base + noise).clamp(0, 255) as u8;
    }
    let img = ImgFile::new(GreyImage::new(side, side, px).unwrap());
    write_img(&dir.path().join("max1.img"), &img).unwrap();
    drop(img);
    let limit_kib = 5 * (side * side) as u64 / 1024;
    let o = crate::support::limited::vss_under(
        dir.path(),
        &format!("ulimit -v {limit_kib}"),
        ["llv", "--json", "max1.img"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success(),
        "{:?}, most likely an allocation over the limit: {err}",
        o.status
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["lines"].as_u64().unwrap() >= 8, "{v}");
    assert!(dir.path().join("max1.ldr").is_file());
}

/// Writes the 8192² `STEM.img` of `px` into `dir` and runs `vss llv ARGS
/// --out out STEM.img` there under `ulimit -v` of the start-up baseline + 4
/// × the file: its output and that limit (KiB).
fn llv_within_four_times(
    dir: &Path,
    stem: &str,
    px: Vec<u8>,
    args: &[&str],
) -> (std::process::Output, u64) {
    let file = dir.join(format!("{stem}.img"));
    write_img(
        &file,
        &ImgFile::new(GreyImage::new(8192, 8192, px).unwrap()),
    )
    .unwrap();
    let len = std::fs::metadata(&file).unwrap().len();
    let limit_kib = crate::support::limited::baseline_kib() + 4 * len / 1024;
    let name = format!("{stem}.img");
    let all: Vec<&str> = std::iter::once("llv")
        .chain(args.iter().copied())
        .chain(["--out", "out", &name])
        .collect();
    let o = crate::support::limited::vss_under(dir, &format!("ulimit -v {limit_kib}"), all);
    (o, limit_kib)
}

/// Issue 34: `vss llv` of an 8192² image of uniform random pixels (pure
/// texture: about 1.7 million edge points a direction) within 4 × the
/// file above what vss needs to start. It needed 4.8 × (307 MiB) while it
/// held a scan direction's response whole; made a strip at a time and
/// read at the peaks, without keeping the candidates, it needs 2.0 ×, the
/// same outputs.
#[test]
fn llv_of_a_pure_texture_at_the_picture_bound_fits_four_times_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let side = 8192usize;
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut px = vec![0u8; side * side];
    for chunk in px.chunks_exact_mut(8) {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        chunk.copy_from_slice(&seed.to_le_bytes());
    }
    let (o, limit_kib) = llv_within_four_times(dir.path(), "rnd1", px, &["--json"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success(),
        "{:?} in {limit_kib} KiB, most likely an allocation over the limit: {err}",
        o.status
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Edge points by the million in each direction, each file 12 bytes a
    // point past its header.
    for ext in ["hpo", "vpo"] {
        let len = std::fs::metadata(dir.path().join("out").join(format!("rnd1.{ext}")))
            .unwrap()
            .len();
        assert!(len > 12_000_000, "{ext}: {len} bytes, {v}");
    }
}

/// An image where every pixel is an edge (pixel `i` = `i mod 251`): its
/// scan directions find more edge points than an edge file holds, so `vss
/// llv` refuses it, and now as soon as the first direction has them: within
/// 4 × the file, writing nothing. It used to finish both directions' lines
/// and CONNECT first, at 5.1 × the file, and refuse the same after.
#[test]
fn llv_of_an_image_of_edges_everywhere_is_refused_at_once_within_four_times_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let side = 8192usize;
    let px = (0..side * side).map(|i| (i % 251) as u8).collect();
    let (o, _) = llv_within_four_times(dir.path(), "mod1", px, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("scan are more than the 4194304 an edge file holds"),
        "{err}"
    );
    assert!(!dir.path().join("out").join("mod1.hpo").exists());
}

/// `--from-edges` of the two files swapped, of one file twice, or of the
/// edge files of two images of different sizes ran and wrote lines mixing
/// them, exit 0. Each is now refused, naming the file, and writes nothing.
#[test]
fn from_edges_refuses_swapped_or_mismatched_files() {
    use vss::formats::edgefile::write_edges;
    use vss::llv::{EdgePoint, EdgePoints, ScanDir};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let points: Vec<EdgePoint> = (0..40)
        .map(|y| EdgePoint {
            x: 30.0,
            y: y as f32,
            response: 50.0,
        })
        .collect();
    let edges = |dir, width| EdgePoints {
        dir: Some(dir),
        width,
        height: 48,
        points: points.clone(),
    };
    write_edges(&d.join("a.hpo"), &edges(ScanDir::Horizontal, 64)).unwrap();
    write_edges(&d.join("a.vpo"), &edges(ScanDir::Vertical, 64)).unwrap();
    write_edges(&d.join("b.vpo"), &edges(ScanDir::Vertical, 96)).unwrap();
    let run = |h: &str, v: &str| {
        vss()
            .current_dir(d)
            .args(["llv", "--from-edges", h, v])
            .output()
            .unwrap()
    };
    for (h, v, names, says) in [
        ("a.vpo", "a.hpo", "a.vpo: byte 10", "direction V"),
        ("a.hpo", "a.hpo", "a.hpo: byte 10", "direction H"),
        ("a.hpo", "b.vpo", "b.vpo", "96 × 48"),
    ] {
        let r = run(h, v);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{h} {v}: {err}");
        assert!(err.contains(names) && err.contains(says), "{h} {v}: {err}");
        assert!(!d.join("a.lex").exists() && !d.join("a.ldr").exists());
    }
    let r = run("a.hpo", "a.vpo");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
}

/// Lightings of one view, or an `--ambient` image, of different sizes were
/// refused with "image sizes differ: (96, 80) and (40, 30)", naming neither
/// file; the file of the other size is now named with both sizes.
#[test]
fn images_of_different_sizes_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "cube1a.img", |x, y| rect(x, y, 200, 40));
    let small = GreyImage::new(40, 30, vec![90; 40 * 30]).unwrap();
    write_img(&d.join("cube1b.img"), &ImgFile::new(small.clone())).unwrap();
    write_img(&d.join("amb.img"), &ImgFile::new(small)).unwrap();
    for args in [
        vec!["llv", "cube1a.img", "cube1b.img"],
        vec!["llv", "--ambient", "amb.img", "cube1a.img"],
    ] {
        let r = vss().current_dir(d).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?}: {err}");
        let other = if args.len() == 3 {
            "cube1b.img"
        } else {
            "amb.img"
        };
        assert!(
            err.contains(other) && err.contains("40 × 30") && err.contains("96 × 80"),
            "{args:?}: {err}"
        );
    }
}

/// `--set lens.enabled=maybe` said "`maybe` is not a number" of a parameter
/// that takes true or false, and `--set bogus=abc` blamed the value, not the
/// unknown key.
#[test]
fn set_names_what_a_value_should_be_and_an_unknown_key_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "cube1a.img", |x, y| rect(x, y, 200, 40));
    for (set, says) in [
        ("lens.enabled=maybe", "`maybe` is not true or false"),
        ("bogus.key=abc", "unknown parameter `bogus.key`"),
        ("edges.floor=abc", "`abc` is not a number"),
    ] {
        let r = vss()
            .current_dir(d)
            .args(["llv", "cube1a.img", "--set", set])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{set}: {err}");
        assert!(err.contains(says), "{set}: {err}");
    }
}

/// An output that cannot be staged (a folder at its name) replaces none,
/// and the refusal does not speak of a previous run's files where there
/// were none: it said "the files on disk are the previous run's".
#[test]
fn an_output_that_cannot_be_written_replaces_none_and_claims_no_earlier_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "cube1a.img", |x, y| rect(x, y, 200, 40));
    let out = d.join("out");
    std::fs::create_dir_all(out.join("cube1.ldr")).unwrap();
    let r = vss()
        .args(["llv", "--out"])
        .arg(&out)
        .arg(d.join("cube1a.img"))
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("cube1.ldr") && err.contains("no output was replaced"),
        "{err}"
    );
    assert!(!err.contains("previous run"), "{err}");
    assert!(!err.contains("--out DIR"), "--out was given: {err}");
    let mut left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["cube1.ldr"], "nothing else written");
}

/// Beside the input (no `--out`), the refusal also says how to write the
/// outputs elsewhere: a photograph's folder is often not the operator's.
#[test]
fn an_output_that_cannot_be_written_beside_the_input_points_to_out() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "cube1a.img", |x, y| rect(x, y, 200, 40));
    std::fs::create_dir_all(d.join("cube1.ldr")).unwrap();
    let r = vss().arg("llv").arg(d.join("cube1a.img")).output().unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("cube1.ldr")
            && err.contains("no output was replaced")
            && err.contains("--out DIR writes the outputs to another folder"),
        "{err}"
    );
}
