//! A table of malformed files across the formats: each is refused with the
//! right kind of error, and the message names the file and the line (text
//! formats) or byte offset (binary formats). Nothing here may panic.

use std::path::Path;

use vss::formats::{
    FormatError, FormatErrorKind as K, Location, cdf, edgefile, imageio, img, lines, par, ses,
};

/// A valid `.img` header for `w × h` with a 7-byte comment, then `pixels`
/// bytes of pixels.
fn img(w: u16, h: u16, pixels: usize) -> Vec<u8> {
    let mut b = vec![0u8; 64];
    b[0..2].copy_from_slice(b"IM");
    b[2..4].copy_from_slice(&8u16.to_le_bytes());
    b[4..6].copy_from_slice(&w.to_le_bytes());
    b[6..8].copy_from_slice(&h.to_le_bytes());
    b.extend_from_slice(b"cube1a\0\0");
    b.extend(std::iter::repeat_n(7u8, pixels));
    b
}

fn img_with(at: usize, v: u16) -> Vec<u8> {
    let mut b = img(4, 4, 16);
    b[at..at + 2].copy_from_slice(&v.to_le_bytes());
    b
}

fn edge(head: &str, body: &[u8]) -> Vec<u8> {
    let mut b = head.as_bytes().to_vec();
    b.extend_from_slice(body);
    b
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

const CDF_OK: &str = "S=A\n0.01\n0.01\nC=A\n256\n256\nf=A\n12\n";
const LEX_OK: &str = "1 0 0\n2 10 10\nFaces:\n1 2\n";
const PAR_OK: &str = "2 \"set\"\n0 3\n1 1\n0 \"a\" i\n1 \"b\" b\n";

/// (what, extension, content, expected kind, expected location)
fn cases() -> Vec<(&'static str, &'static str, Vec<u8>, K, Location)> {
    use Location::{Byte, Line};
    let t = |s: &str| s.as_bytes().to_vec();
    vec![
        // .img
        ("empty image", "img", vec![], K::Truncated, Byte(0)),
        (
            "truncated header",
            "img",
            img(4, 4, 16)[..30].to_vec(),
            K::Truncated,
            Byte(30),
        ),
        (
            "wrong magic",
            "img",
            {
                let mut b = img(4, 4, 16);
                b[0] = b'X';
                b
            },
            K::Syntax,
            Byte(0),
        ),
        (
            "compressed type",
            "img",
            img_with(12, 1),
            K::Unsupported,
            Byte(12),
        ),
        (
            "unknown file type",
            "img",
            img_with(12, 9),
            K::Unsupported,
            Byte(12),
        ),
        (
            "comment longer than 200",
            "img",
            img_with(2, 201),
            K::Range,
            Byte(2),
        ),
        (
            "one pixel short",
            "img",
            img(4, 4, 15),
            K::SizeMismatch,
            Byte(4),
        ),
        (
            "one byte too many",
            "imc",
            img(4, 4, 17),
            K::SizeMismatch,
            Byte(4),
        ),
        (
            "60000 x 60000 in 100 bytes",
            "img",
            img(60000, 60000, 28),
            K::SizeMismatch,
            Byte(4),
        ),
        ("zero width", "img", img(0, 4, 0), K::Range, Byte(4)),
        // .hpo / .vpo
        ("empty edge file", "hpo", vec![], K::Truncated, Byte(0)),
        (
            "edge file wrong magic",
            "hpo",
            edge("VSSEDGX 1 H 4 4 0\n", &[]),
            K::Syntax,
            Byte(0),
        ),
        (
            "edge file version 2",
            "vpo",
            edge("VSSEDGE 2 V 4 4 0\n", &[]),
            K::Unsupported,
            Byte(8),
        ),
        (
            "edge file bad direction",
            "vpo",
            edge("VSSEDGE 1 X 4 4 0\n", &[]),
            K::Syntax,
            Byte(0),
        ),
        (
            "edge file count as text",
            "hpo",
            edge("VSSEDGE 1 H 4 4 many\n", &[]),
            K::Syntax,
            Byte(0),
        ),
        (
            "edge points truncated",
            "hpo",
            edge("VSSEDGE 1 H 4 4 2\n", &f32s(&[1.0, 2.0, 3.0])),
            K::Truncated,
            Byte(18),
        ),
        (
            "edge file trailing bytes",
            "hpo",
            edge("VSSEDGE 1 H 4 4 1\n", &f32s(&[1.0, 2.0, 3.0, 4.0])),
            K::SizeMismatch,
            Byte(18),
        ),
        (
            "edge point NaN",
            "hpo",
            edge(
                "VSSEDGE 1 H 4 4 2\n",
                &f32s(&[1.0, 2.0, 3.0, f32::NAN, 1.0, 1.0]),
            ),
            K::Range,
            Byte(30),
        ),
        (
            "edge header without newline",
            "hpo",
            vec![b'V'; 300],
            K::Syntax,
            Byte(128),
        ),
        // .cdf
        ("empty cdf", "cdf", vec![], K::Missing, Line(1)),
        (
            "value before any parameter",
            "cdf",
            t("0.5\nS=A\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "unknown status letter",
            "cdf",
            t("S=Q\n1\n1\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "text where a number belongs",
            "cdf",
            t("S=A\n0.01\nabc\n"),
            K::Syntax,
            Line(3),
        ),
        ("NaN in cdf", "cdf", t("f=A\nNaN\n"), K::Range, Line(2)),
        (
            "infinity in cdf",
            "cdf",
            t("C=A\n1\ninf\n"),
            K::Range,
            Line(3),
        ),
        (
            "T row of three",
            "cdf",
            t("T=A\n1 0 0 5\n0 1 0\n"),
            K::Syntax,
            Line(3),
        ),
        (
            "D with four values",
            "cdf",
            t("D=A\n1\n2\n3\n4\nf=A\n12\n"),
            K::Missing,
            Line(1),
        ),
        (
            "parameter twice",
            "cdf",
            t(&format!("{CDF_OK}S=E\n1\n1\n")),
            K::Syntax,
            Line(9),
        ),
        (
            "too many values for f",
            "cdf",
            t("f=A\n12\n13\n"),
            K::Syntax,
            Line(3),
        ),
        (
            "non-UTF-8 cdf",
            "cdf",
            b"S=A\n0.01\n\xff\xfe\n".to_vec(),
            K::Encoding,
            Line(3),
        ),
        // .lex / .ldr
        (
            "missing Faces:",
            "ldr",
            t("1 0 0\n2 10 10\n"),
            K::Missing,
            Line(2),
        ),
        ("empty line file", "lex", vec![], K::Missing, Line(1)),
        (
            "Faces: index out of range",
            "ldr",
            t("1 0 0\n2 10 10\nFaces:\n1 3\n"),
            K::Range,
            Line(4),
        ),
        (
            "text in a face",
            "ldr",
            t("1 0 0\n2 10 10\nFaces:\n3 x\n"),
            K::Syntax,
            Line(4),
        ),
        (
            "face with three indices",
            "ldr",
            t(&format!("{LEX_OK}1 2 1\n")),
            K::Syntax,
            Line(5),
        ),
        (
            "NaN vertex",
            "lex",
            t("1 NaN 0\nFaces:\n"),
            K::Range,
            Line(1),
        ),
        (
            "vertex index 0",
            "lex",
            t("0 1 1\nFaces:\n"),
            K::Range,
            Line(1),
        ),
        (
            "vertex with two numbers",
            "lex",
            t("1 0 0\n2 10\nFaces:\n"),
            K::Syntax,
            Line(2),
        ),
        (
            "vertex defined twice",
            "lex",
            t("1 0 0\n1 10 10\nFaces:\n"),
            K::Syntax,
            Line(2),
        ),
        (
            "non-UTF-8 line file",
            "lex",
            b"1 0 0\n2 \xe9 0\nFaces:\n".to_vec(),
            K::Encoding,
            Line(2),
        ),
        // .par
        ("empty par", "par", vec![], K::Missing, Line(1)),
        (
            "par count as text",
            "par",
            t("two \"set\"\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "par name not quoted",
            "par",
            t("1 set\n0 1\n0 \"a\" i\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "par control character in a name",
            "par",
            t("1 \"set\"\n0 1\n0 \"c\u{1}nect.wl\" i\n"),
            K::Syntax,
            Line(3),
        ),
        (
            "par quote inside the set's name",
            "par",
            t("1 \"connect.c|\" f\"vss lens\"\n0 1\n0 \"lens.enabled\" b\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "par control character in a value",
            "par",
            t("1 \"v[s lsen\"\n0 \u{13}\u{13}0\u{13}2\n0 \"lens.esb\" s\n"),
            K::Syntax,
            Line(2),
        ),
        (
            "par control character in the set's name",
            "par",
            t("1 \"s\u{1b}[2Jet\"\n0 1\n0 \"a\" i\n"),
            K::Syntax,
            Line(1),
        ),
        (
            "par fewer lines than count",
            "par",
            t("3 \"set\"\n0 1\n0 \"a\" i\n"),
            K::Missing,
            Line(3),
        ),
        (
            "par bad type letter",
            "par",
            t("1 \"set\"\n0 1\n0 \"a\" x\n"),
            K::Syntax,
            Line(3),
        ),
        (
            "par index out of range",
            "par",
            t("1 \"set\"\n5 1\n0 \"a\" i\n"),
            K::Range,
            Line(2),
        ),
        (
            "par bool 2",
            "par",
            t("1 \"set\"\n0 2\n0 \"a\" b\n"),
            K::Syntax,
            Line(2),
        ),
        (
            "par int as text",
            "par",
            t("1 \"set\"\n0 x\n0 \"a\" i\n"),
            K::Syntax,
            Line(2),
        ),
        (
            "par value twice",
            "par",
            t("2 \"set\"\n0 1\n0 2\n0 \"a\" i\n1 \"b\" i\n"),
            K::Syntax,
            Line(3),
        ),
        (
            "par extra line",
            "par",
            t(&format!("{PAR_OK}junk\n")),
            K::Syntax,
            Line(6),
        ),
        // .ses
        ("empty ses", "ses", vec![], K::Missing, Line(1)),
        ("ses two numbers", "ses", t("4\n2\n"), K::Missing, Line(2)),
        (
            "ses four numbers",
            "ses",
            t("4\n2\n5\n1\n"),
            K::Syntax,
            Line(4),
        ),
        ("ses text", "ses", t("4\ntwo\n5\n"), K::Syntax, Line(2)),
        (
            "ses 27 lightings",
            "ses",
            t("4\n2\n27\n"),
            K::Range,
            Line(3),
        ),
        ("ses zero images", "ses", t("0\n2\n5\n"), K::Range, Line(1)),
        ("ses negative", "ses", t("4\n-2\n5\n"), K::Syntax, Line(2)),
    ]
}

fn read(path: &Path, ext: &str) -> Result<(), FormatError> {
    match ext {
        "img" | "imc" => img::read_img(path).map(drop),
        "hpo" | "vpo" => edgefile::read_edges(path).map(drop),
        "cdf" => cdf::read_cdf(path).map(drop),
        "lex" | "ldr" => lines::read_lines(path).map(drop),
        "par" => par::read_par(path).map(drop),
        "ses" => ses::read_ses(path).map(drop),
        _ => imageio::read_any(path).map(drop),
    }
}

#[test]
fn malformed_files_are_refused_saying_where() {
    let dir = tempfile::tempdir().unwrap();
    let cases = cases();
    assert!(cases.len() >= 30);
    let mut failures = Vec::new();
    for (i, (what, ext, bytes, kind, loc)) in cases.into_iter().enumerate() {
        let path = dir.path().join(format!("bad{i}.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        let err = match read(&path, ext) {
            Ok(()) => {
                failures.push(format!("{what}: accepted"));
                continue;
            }
            Err(e) => e,
        };
        let msg = err.to_string();
        let where_ = match loc {
            Location::Line(n) => format!("{}:{n}: ", path.display()),
            Location::Byte(b) => format!("{}: byte {b}: ", path.display()),
            Location::None => format!("{}: ", path.display()),
        };
        if err.kind != kind || err.location != loc || !msg.starts_with(&where_) || err.path != path
        {
            failures.push(format!(
                "{what}: expected {kind:?} at {loc:?}, got {:?} at {:?}: {msg}",
                err.kind, err.location
            ));
        }
        // The message says what was expected or found, not just where.
        if msg.len() < where_.len() + 15 {
            failures.push(format!("{what}: message too terse: {msg}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn foreign_images_that_are_not_images() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [
        ("a.png", b"not a png at all".to_vec()),
        ("b.pgm", b"P5\n4 4\n255\n\x01\x02".to_vec()),
        ("c.bmp", b"BM\x00".to_vec()),
        ("d.tif", b"II*\x00\xff\xff\xff\xff".to_vec()),
        ("e.jpg", b"\xff\xd8\xff".to_vec()),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        let e = imageio::read_any(&p).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!("{}: ", p.display())),
            "{e}"
        );
        assert_ne!(e.kind, K::Io, "{name}: {e}");
    }
}

#[test]
fn png_claiming_a_huge_image_is_refused_before_allocating() {
    // A PNG whose header claims 60000 × 60000 RGBA (14 GB decoded), with a
    // small IDAT chunk: the header alone must be enough to refuse it.
    fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        let mut h = crc32fast::Hasher::new();
        h.update(kind);
        h.update(data);
        out.extend_from_slice(&h.finalize().to_be_bytes());
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&60000u32.to_be_bytes());
    ihdr.extend_from_slice(&60000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(
        &mut out,
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    );
    chunk(&mut out, b"IEND", &[]);
    assert!(out.len() < 100);
    let e = imageio::decode_any(&out, imageio::ImageKind::Png, Path::new("big.png")).unwrap_err();
    assert_eq!(e.kind, K::Range, "{e}");
}

mod never_panic {
    //! Any bytes, and valid files with bytes changed, give a value or an
    //! error — never a panic.
    use super::*;
    use proptest::prelude::*;

    fn all_parsers(bytes: &[u8]) {
        let p = Path::new("x");
        let _ = img::parse_img(bytes, p);
        let _ = edgefile::parse_edges(bytes, p);
        for k in [
            imageio::ImageKind::Png,
            imageio::ImageKind::Pgm,
            imageio::ImageKind::Tiff,
            imageio::ImageKind::Bmp,
        ] {
            let _ = imageio::decode_any(bytes, k, p);
        }
        let text = String::from_utf8_lossy(bytes);
        let _ = cdf::parse_cdf(&text, p);
        let _ = lines::parse_lines(&text, p);
        let _ = par::parse_par(&text, p);
        let _ = par::import_params(&text, p, &vss::llv::Params::default());
        let _ = ses::parse_ses(&text, p);
        let _ = vss::profile::Profile::from_toml(&text, p);
        let _ = vss::formats::names::VssFile::parse(&text);
        let _ = vss::formats::names::SessionName::new(&text);
    }

    fn valid_files() -> Vec<Vec<u8>> {
        let f = img::ImgFile {
            image: vss::llv::GreyImage::new(6, 5, (0..30).collect()).unwrap(),
            comment: "cube1a".into(),
            x0: 1,
            y0: 2,
        };
        let e = vss::llv::EdgePoints {
            dir: Some(vss::llv::ScanDir::Vertical),
            width: 6,
            height: 5,
            points: vec![
                vss::llv::EdgePoint {
                    x: 1.0,
                    y: 2.0,
                    response: 3.0
                };
                3
            ],
        };
        let mut v = vec![
            img::encode_img(&f).unwrap(),
            edgefile::encode_edges(&e),
            CDF_OK.as_bytes().to_vec(),
            LEX_OK.as_bytes().to_vec(),
            PAR_OK.as_bytes().to_vec(),
            b"4\n2\n5\n".to_vec(),
            std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/default.toml"))
                .unwrap(),
        ];
        for k in [
            imageio::ImageKind::Png,
            imageio::ImageKind::Pgm,
            imageio::ImageKind::Tiff,
            imageio::ImageKind::Bmp,
        ] {
            v.push(imageio::encode_any(&f, k).unwrap());
        }
        v
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn any_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
            all_parsers(&bytes);
        }

        #[test]
        fn valid_files_with_bytes_changed(
            which in 0usize..11,
            edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
            cut in proptest::option::of(any::<prop::sample::Index>()),
        ) {
            let files = valid_files();
            let mut b = files[which % files.len()].clone();
            for (i, v) in edits {
                let i = i.index(b.len());
                b[i] = v;
            }
            if let Some(c) = cut {
                b.truncate(c.index(b.len() + 1));
            }
            all_parsers(&b);
        }
    }
}
