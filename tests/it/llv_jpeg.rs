//! JPEG photographs in: `vss llv photo.jpg`, `vss convert photo.jpg out.png`,
//! and the JPEGs that go wrong — truncated, CMYK, 12-bit, progressive,
//! EXIF-rotated, a header claiming 20 000 × 20 000 — each giving lines or a
//! clear error, never a panic. Fixtures: `data/progressive.jpg`,
//! `data/colour.jpg` (OpenCV), `data/cmyk.jpg` (written by hand: Adobe
//! APP14, four flat components); the others are made here from a JPEG the
//! `image` crate encodes.

use std::path::{Path, PathBuf};

use crate::support::vss;
use assert_cmd::assert::OutputAssertExt;
use vss::formats::FormatErrorKind as K;
use vss::formats::imageio::read_any_noted;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/it/data")
        .join(name)
}

/// A 96 × 64 grey scene (a bright square on a dark floor) as a baseline
/// JPEG.
fn baseline() -> Vec<u8> {
    let (w, h) = (96u32, 64u32);
    let px: Vec<u8> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (20..70).contains(&x) && (15..50).contains(&y) {
                200
            } else {
                40
            }
        })
        .collect();
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 95)
        .encode(&px, w, h, image::ExtendedColorType::L8)
        .unwrap();
    out
}

/// The offset of the start-of-frame segment's precision byte.
fn sof(bytes: &[u8]) -> usize {
    bytes
        .windows(2)
        .position(|m| m[0] == 0xFF && (0xC0..=0xC2).contains(&m[1]))
        .unwrap()
        + 4
}

/// `bytes` with an APP1 segment after SOI holding `payload` after an
/// `Exif` header, as a camera stores its thumbnail.
fn with_app1(bytes: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut out = bytes[..2].to_vec();
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&((payload.len() + 8) as u16).to_be_bytes());
    out.extend_from_slice(b"Exif\x00\x00");
    out.extend_from_slice(payload);
    out.extend_from_slice(&bytes[2..]);
    out
}

/// `bytes` with an EXIF APP1 segment giving orientation `o` after SOI.
fn with_orientation(bytes: &[u8], o: u16) -> Vec<u8> {
    let mut tiff = b"MM\x00\x2a\x00\x00\x00\x08".to_vec();
    tiff.extend_from_slice(&1u16.to_be_bytes()); // one entry
    tiff.extend_from_slice(&0x0112u16.to_be_bytes()); // Orientation
    tiff.extend_from_slice(&3u16.to_be_bytes()); // SHORT
    tiff.extend_from_slice(&1u32.to_be_bytes());
    tiff.extend_from_slice(&o.to_be_bytes());
    tiff.extend_from_slice(&[0, 0, 0, 0, 0, 0]); // pad, next IFD 0
    let mut app1 = b"Exif\x00\x00".to_vec();
    app1.extend_from_slice(&tiff);
    let mut out = bytes[..2].to_vec();
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&((app1.len() + 2) as u16).to_be_bytes());
    out.extend_from_slice(&app1);
    out.extend_from_slice(&bytes[2..]);
    out
}

#[test]
fn a_baseline_jpeg_reads_as_its_pixels() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("a.jpg");
    std::fs::write(&p, baseline()).unwrap();
    let (f, notes) = read_any_noted(&p).unwrap();
    assert_eq!(f.image.size(), (96, 64));
    assert!(notes.is_empty(), "{notes:?}");
    let at = |x, y| i32::from(f.image.get(x, y).unwrap());
    assert!((at(45, 30) - 200).abs() <= 3 && (at(5, 5) - 40).abs() <= 3);
}

#[test]
fn colour_progressive_and_cmyk_jpegs_read() {
    // Colour: the JPEG's luma (BT.601), as OpenCV's grey reader gives it.
    let (f, notes) = read_any_noted(&data("colour.jpg")).unwrap();
    assert_eq!(f.image.size(), (64, 48));
    assert!(notes.iter().any(|n| n.contains("BT.601")), "{notes:?}");
    // OpenCV: IMREAD_GRAYSCALE gives 83 at (10, 10) and 97 at (50, 10).
    let (a, b) = (f.image.get(10, 10).unwrap(), f.image.get(50, 10).unwrap());
    assert!(a.abs_diff(83) <= 1 && b.abs_diff(97) <= 1, "{a} {b}");
    // Progressive: the same picture as a baseline file would give.
    let (f, _) = read_any_noted(&data("progressive.jpg")).unwrap();
    assert_eq!(f.image.size(), (64, 48));
    let (a, b) = (f.image.get(10, 10).unwrap(), f.image.get(50, 10).unwrap());
    // OpenCV: 60 and 182.
    assert!(a.abs_diff(60) <= 1 && b.abs_diff(182) <= 1, "{a} {b}");
    // CMYK (Adobe): converted through RGB; OpenCV's grey is 12 everywhere.
    let (f, _) = read_any_noted(&data("cmyk.jpg")).unwrap();
    assert_eq!(f.image.size(), (16, 16));
    let v = f.image.get(8, 8).unwrap();
    assert!(v.abs_diff(12) <= 3, "{v}");
}

#[test]
fn an_exif_rotation_is_applied_and_said() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("r.jpg");
    // 6: the camera was turned; shown rotated 90° clockwise.
    std::fs::write(&p, with_orientation(&baseline(), 6)).unwrap();
    let (f, notes) = read_any_noted(&p).unwrap();
    assert_eq!(f.image.size(), (64, 96));
    assert!(
        notes.iter().any(|n| n.contains("EXIF orientation")),
        "{notes:?}"
    );
    // The bright square (x 20..70, y 15..50) now spans x 14..49, y 20..70.
    assert!(f.image.get(30, 45).unwrap() > 150);
    assert!(f.image.get(30, 10).unwrap() < 100);
    // `vss llv` says so too, and finds the square's lines in the picture
    // as shown.
    let o = vss()
        .arg("llv")
        .arg(&p)
        .current_dir(d.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("EXIF orientation"), "{err}");
    // Its lines print on a picture the photograph's size as shown, found
    // beside them: `vss report --ldr r.ldr` (it was 512 × 512).
    let o = vss()
        .args(["report", "--ldr", "r.ldr", "--svg", "r.svg"])
        .current_dir(d.path())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("picture 64 × 96, the size of r.jpg"), "{out}");
    let svg = std::fs::read_to_string(d.path().join("r.svg")).unwrap();
    assert!(svg.contains(r#"width="64" height="96""#), "{svg}");
}

#[test]
fn bad_jpegs_give_clear_errors() {
    let d = tempfile::tempdir().unwrap();
    let good = baseline();
    let mut cases: Vec<(&str, Vec<u8>, K, &str)> = Vec::new();
    // Truncated in the middle of the scan.
    cases.push((
        "cut.jpg",
        good[..good.len() / 2].to_vec(),
        K::Truncated,
        "truncated",
    ));
    // Truncated in the scan of a camera's file, whose EXIF thumbnail (a
    // whole JPEG inside APP1, before the picture's scan) keeps its own
    // end-of-image marker: the picture's own must follow its last scan.
    let with_thumb = with_app1(&good, &good);
    let whole = d.path().join("thumb.jpg");
    std::fs::write(&whole, &with_thumb).unwrap();
    assert_eq!(read_any_noted(&whole).unwrap().0.image.size(), (96, 64));
    cases.push((
        "cut-thumb.jpg",
        with_thumb[..with_thumb.len() - good.len() / 2].to_vec(),
        K::Truncated,
        "truncated",
    ));
    // Cut in the header.
    cases.push(("head.jpg", good[..30].to_vec(), K::Syntax, "JPEG"));
    // 12-bit samples.
    let mut twelve = good.clone();
    let at = sof(&twelve);
    twelve[at - 3] = 0xC1;
    twelve[at] = 12;
    cases.push(("twelve.jpg", twelve, K::Syntax, "12 bits"));
    // A header claiming 20000 × 20000: refused from it, not decoded.
    let mut huge = good.clone();
    let at = sof(&huge);
    huge[at + 1..at + 3].copy_from_slice(&20000u16.to_be_bytes());
    huge[at + 3..at + 5].copy_from_slice(&20000u16.to_be_bytes());
    cases.push(("huge.jpg", huge, K::Range, "20000 × 20000"));
    for (name, bytes, kind, says) in cases {
        let p = d.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        let e = read_any_noted(&p).unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with(&format!("{}: ", p.display())), "{msg}");
        assert!(msg.contains(says), "{name}: {msg}");
        if name != "head.jpg" {
            assert_eq!(e.kind, kind, "{name}: {msg}");
        }
        // The CLI: an error naming the file, exit 1, no panic.
        let o = vss()
            .arg("llv")
            .arg(&p)
            .current_dir(d.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(name) && !err.contains("panicked"), "{err}");
    }
}

#[test]
fn vss_llv_and_convert_take_a_photograph() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("square.jpg");
    std::fs::write(&p, baseline()).unwrap();
    let o = vss()
        .arg("llv")
        .arg(&p)
        .current_dir(d.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The lines file beside the photograph, with the square's four sides.
    let ldr = std::fs::read_to_string(d.path().join("square.ldr")).unwrap();
    assert!(ldr.lines().count() >= 4, "{ldr}");
    // convert: JPEG in, PNG out; JPEG out is refused and writes nothing.
    let png = d.path().join("square.png");
    vss().arg("convert").arg(&p).arg(&png).assert().success();
    let (f, _) = read_any_noted(&png).unwrap();
    assert_eq!(f.image.size(), (96, 64));
    let o = vss()
        .arg("convert")
        .arg(&png)
        .arg(d.path().join("back.jpg"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not write"));
    assert!(!d.path().join("back.jpg").exists());
}
