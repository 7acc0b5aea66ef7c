//! A manifest near its 4 MiB bound (issue 34, N5), read by `vss session
//! show`: 1 114 fully processed images (five greys, outputs with their
//! parameters and line attributes, an edit each). Parsed whole into one
//! TOML document it took 120 MB resident; it is now read record by record
//! (`vss::session::manifest`), so `show` runs in an address space a
//! whole-file parse does not fit. Errors in a late
//! record, and after the records, still name their line in the file.
//!
//! With `VSS_BIG_SESSION_DIR=DIR` the session is also written to `DIR/r4`
//! (and the one-record manifest to `DIR/huge`) and kept, to measure by hand: `/usr/bin/time -v target/debug/vss
//! session show DIR/r4`.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

use vss::llv::Params;
use vss::session::Manifest;
use vss::session::manifest::{
    CalibrationRecord, Counts, EditRecord, FileRecord, GreyRecord, ImageRecord, LightingInfo,
    LineAttributes, MAX_LEN, MAX_RECORD_LEN, OutputRecord, SessionInfo, TimingsRecord,
};

const STAMP: &str = "2026-12-04T19:30:00Z";

fn file(f: String) -> FileRecord {
    FileRecord {
        file: f,
        hash: "crc32:89abcdef:262144".into(),
    }
}

/// Line attributes of `n` lines, with values as the pipeline writes them.
fn attributes(n: usize) -> LineAttributes {
    LineAttributes {
        response: (0..n).map(|i| -10.0 - i as f64 * 0.731_25).collect(),
        residual: (0..n).map(|i| 0.05 + i as f64 * 0.003_906_25).collect(),
        shadow: vec![1, 4],
    }
}

/// Image `k` of session `name`, captured in lightings a–e and processed.
fn image(name: &str, k: u32) -> ImageRecord {
    let greys: Vec<GreyRecord> = "abcde"
        .chars()
        .map(|l| GreyRecord {
            letter: l,
            file: format!("{name}{k}{l}.img"),
            hash: "crc32:01234567:262144".into(),
            width: 512,
            height: 512,
            exposure_us: Some(10_000.0),
            gain_db: Some(0.0),
            saved: STAMP.into(),
            version: "0.1.0".into(),
        })
        .collect();
    let inputs = greys
        .iter()
        .map(|g| file(g.file.clone()))
        .chain([file(format!("{name}{k}.cdf"))])
        .collect();
    ImageRecord {
        number: k,
        camera: (k - 1) % 4 + 1,
        location: (k - 1) / 4 + 1,
        cdf: Some(file(format!("{name}{k}.cdf"))),
        grey: greys,
        outputs: Some(OutputRecord {
            made: STAMP.into(),
            version: "0.1.0".into(),
            inputs,
            files: ["imc", "hpo", "vpo", "lex", "ldr"]
                .iter()
                .map(|e| file(format!("{name}{k}.{e}")))
                .collect(),
            counts: Counts {
                edges_h: 4_210,
                edges_v: 3_987,
                lines_raw: 24,
                lines: 12,
            },
            timings: TimingsRecord {
                lens_us: 2_100,
                edges_us: 5_400,
                lines_us: 1_300,
                connect_us: 200,
            },
            lex_attributes: Some(attributes(24)),
            ldr_attributes: Some(attributes(12)),
            params: Params::default(),
        }),
        edit: vec![EditRecord {
            at: STAMP.into(),
            version: "0.1.0".into(),
            op: "connect 3 7".into(),
            lines: 11,
            hash: "crc32:fedcba98:1200".into(),
        }],
    }
}

/// The manifest of session `name` with images 1 to `n`.
fn manifest(name: &str, n: u32) -> Manifest {
    Manifest {
        format: vss::session::manifest::FORMAT,
        session: SessionInfo {
            name: name.into(),
            created: STAMP.into(),
            modified: STAMP.into(),
            version: "0.1.0".into(),
            profile: "simulated cell".into(),
            planned_images: n,
            cameras: 4,
        },
        lighting: "abcde"
            .chars()
            .map(|l| LightingInfo {
                letter: l,
                on: vec![format!("light {l}")],
                note: String::new(),
            })
            .collect(),
        image: (1..=n).map(|k| image(name, k)).collect(),
        calibration: vec![CalibrationRecord {
            camera: 1,
            made: STAMP.into(),
            cdf: "profiles/sim/cam1.cdf".into(),
            views: 12,
            rms_px: 0.05,
            p95_px: 0.1,
            centre_stated: false,
        }],
    }
}

/// Session `name` in `root`: as many images as fit in the manifest's bound
/// (the manifest alone: `show` reads no other file). Returns the folder,
/// the image count and the manifest's text.
fn big_session(root: &Path, name: &str) -> (PathBuf, u32, String) {
    let len = |n: u32| manifest(name, n).to_toml().expect("toml").len();
    let per_image = (len(200) - len(100)) / 100;
    let mut n = u32::try_from(MAX_LEN / per_image).expect("count");
    let text = loop {
        let text = manifest(name, n).to_toml().expect("toml");
        if text.len() <= MAX_LEN {
            break text;
        }
        n -= 1;
    };
    assert!(text.len() > MAX_LEN - 2 * per_image, "{} bytes", text.len());
    let dir = root.join(name);
    std::fs::create_dir_all(&dir).expect("session folder");
    std::fs::write(dir.join(format!("{name}.toml")), &text).expect("manifest");
    if let Some(keep) = std::env::var_os("VSS_BIG_SESSION_DIR") {
        let kept = Path::new(&keep).join(name);
        std::fs::create_dir_all(&kept).expect("VSS_BIG_SESSION_DIR");
        std::fs::write(kept.join(format!("{name}.toml")), &text).expect("kept manifest");
    }
    (dir, n, text)
}

/// `vss session show DIR` with at most `mib` MiB of address space.
fn show(dir: &Path, mib: u64) -> Output {
    let args = [OsStr::new("session"), OsStr::new("show"), dir.as_os_str()];
    crate::support::limited::vss_under(dir, &format!("ulimit -v {}", mib * 1024), args)
}

fn text_of(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The least address space (MiB, in steps of 2) in which `vss session
/// show DIR` succeeds: what the binary and its libraries take, plus what
/// reading the manifest takes. (The binary's own share depends on the
/// build: the `genicam` feature links Aravis and GLib.)
fn least_mib(dir: &Path) -> u64 {
    let args = [OsStr::new("session"), OsStr::new("show"), dir.as_os_str()];
    crate::support::limited::least_kib(dir, args).div_ceil(2048) * 2
}

/// Issue 34, N5: read whole, this manifest (4 MiB, 1 114 images) took
/// 120 MB resident; record by record, reading it takes at most four times
/// its size (16 MiB) of address space more than a one-image manifest does
/// (it took about 8).
#[test]
fn a_big_manifest_is_read_record_by_record() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (dir, n, text) = big_session(tmp.path(), "r4");
    assert!(n > 1000, "{n} images");
    let one = tmp.path().join("one");
    std::fs::create_dir_all(&one).expect("folder");
    let small = manifest("one", 1).to_toml().expect("toml");
    std::fs::write(one.join("one.toml"), small).expect("manifest");
    let base = least_mib(&one);
    let allowed = base + 4 * (text.len() as u64).div_ceil(1 << 20);
    let o = show(&dir, allowed);
    let out = text_of(&o);
    assert!(
        o.status.code().is_some(),
        "vss was killed ({:?}) in {allowed} MiB ({base} for one image), most likely by an \
         allocation over the limit: {}",
        o.status,
        &out[..out.len().min(500)]
    );
    assert!(o.status.success(), "{}", &out[..out.len().min(500)]);
    assert!(
        out.contains(&format!("of {n} images done")),
        "{}",
        &out[..300]
    );
    let edits = out
        .lines()
        .filter(|l| l.contains(": edit connect 3 7"))
        .count();
    assert_eq!(edits, n as usize, "every image's edit is listed");
    assert!(
        out.contains(&format!("  image {n}: 4210 + 3987 edge points")),
        "the last image is read"
    );
}

/// A damaged late record, and a damaged table after the records, are named
/// with their line in the file, as a parse of the whole file named them.
#[test]
fn errors_in_a_big_manifest_name_their_line() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (dir, n, good) = big_session(tmp.path(), "r4");
    let path = dir.join("r4.toml");
    let line_of = |text: &str, needle: &str| {
        text.lines()
            .position(|l| l == needle)
            .unwrap_or_else(|| panic!("{needle:?} in the manifest"))
            + 1
    };
    // A value of the wrong type in the last image.
    let last = format!("number = {n}");
    let bad = good.replace(&last, &format!("number = \"{n}\""));
    std::fs::write(&path, &bad).expect("write");
    let out = text_of(&show(&dir, 1024));
    let line = line_of(&bad, &format!("number = \"{n}\""));
    assert!(
        out.contains(&format!("r4.toml:{line}:")),
        "line {line}: {out}"
    );
    assert!(out.contains("invalid type"), "{out}");
    // A syntax error in the calibration record after the images.
    let bad = good.replace("views = 12", "views = 12 12");
    std::fs::write(&path, &bad).expect("write");
    let out = text_of(&show(&dir, 1024));
    let line = line_of(&bad, "views = 12 12");
    assert!(
        out.contains(&format!("r4.toml:{line}:")),
        "line {line}: {out}"
    );
    // An unknown key in an image in the middle.
    let mid = format!("number = {}", n / 2);
    let bad = good.replace(&mid, &format!("{mid}\ncolour = \"red\""));
    std::fs::write(&path, &bad).expect("write");
    let out = text_of(&show(&dir, 1024));
    let line = line_of(&bad, "colour = \"red\"");
    assert!(
        out.contains(&format!("r4.toml:{line}:")),
        "line {line}: {out}"
    );
    assert!(out.contains("unknown field `colour`"), "{out}");
}

/// Image 1 as a real cell could make it at its largest: 26 lightings,
/// every parameter changed from the profile's, 100 lines' attributes and
/// ten hand edits.
fn largest_real_image() -> ImageRecord {
    let mut r = image("big", 1);
    let grey = r.grey[0].clone();
    r.grey = ('a'..='z')
        .map(|l| GreyRecord {
            letter: l,
            file: format!("big1{l}.img"),
            ..grey.clone()
        })
        .collect();
    let out = r.outputs.as_mut().expect("outputs");
    out.lex_attributes = Some(attributes(100));
    out.ldr_attributes = Some(attributes(100));
    let mut p = Params::default();
    for d in vss::llv::params::PARAMS {
        let v = if p.get(d.key) == Some(d.max) {
            d.min
        } else {
            d.max
        };
        p.set(d.key, v).expect("a value in range");
    }
    out.params = p;
    r.edit = vec![r.edit[0].clone(); 10];
    r
}

/// Issue 34: a 4 MiB manifest of one `[[image]]` record (its line
/// attributes a million numbers) took 325 MB to read (77 times the file):
/// a record is now refused past [`MAX_RECORD_LEN`], with the record's line,
/// its size and the cap, in the address space a one-image manifest needs
/// plus 16 MiB (the old build does not fit). The cap is at least 16 times
/// the largest record a real image makes (12 822 bytes: about 20 times).
#[test]
fn a_manifest_of_one_huge_record_is_refused() {
    let tmp = tempfile::tempdir().expect("tmp");
    let one = |m: &Manifest| {
        let mut m = m.clone();
        m.image.clear();
        m
    };
    let real = {
        let mut m = one(&manifest("big", 1));
        let bare = m.to_toml().expect("toml").len();
        m.image = vec![largest_real_image()];
        m.to_toml().expect("toml").len() - bare
    };
    assert!(
        MAX_RECORD_LEN >= 16 * real,
        "the largest real record takes {real} bytes"
    );
    println!("largest real record: {real} bytes, cap {MAX_RECORD_LEN}");
    // As many lines' attributes as the manifest's bound holds.
    let huge = |n: usize| {
        let mut m = one(&manifest("huge", 1));
        let mut r = image("huge", 1);
        r.outputs.as_mut().expect("outputs").lex_attributes = Some(attributes(n));
        m.image = vec![r];
        m.to_toml().expect("toml")
    };
    let (l1, l2) = (huge(1000).len(), huge(2000).len());
    let per = (l2 - l1) / 1000;
    let mut n = 1000 + (MAX_LEN - l1) / per;
    let text = loop {
        let text = huge(n);
        if text.len() <= MAX_LEN {
            break text;
        }
        n -= 1 + (text.len() - MAX_LEN) / per;
    };
    assert!(text.len() > MAX_LEN / 16 * 15, "{} bytes", text.len());
    let dir = tmp.path().join("huge");
    std::fs::create_dir_all(&dir).expect("folder");
    std::fs::write(dir.join("huge.toml"), &text).expect("manifest");
    if let Some(keep) = std::env::var_os("VSS_BIG_SESSION_DIR") {
        let kept = Path::new(&keep).join("huge");
        std::fs::create_dir_all(&kept).expect("VSS_BIG_SESSION_DIR");
        std::fs::write(kept.join("huge.toml"), &text).expect("kept manifest");
    }
    let small = tmp.path().join("one");
    std::fs::create_dir_all(&small).expect("folder");
    std::fs::write(
        small.join("one.toml"),
        manifest("one", 1).to_toml().unwrap(),
    )
    .unwrap();
    let allowed = least_mib(&small) + 16;
    let o = show(&dir, allowed);
    let out = text_of(&o);
    assert!(
        o.status.code().is_some(),
        "vss was killed ({:?}) in {allowed} MiB: {}",
        o.status,
        &out[..out.len().min(500)]
    );
    assert!(!o.status.success(), "{out}");
    let line = text.lines().position(|l| l == "[[image]]").expect("record") + 1;
    assert!(
        out.contains(&format!("huge.toml:{line}:")),
        "line {line}: {out}"
    );
    // The record: from its header to the next table's (the calibration).
    let start = text.find("[[image]]").unwrap();
    let end = text[start..]
        .find("\n[[calibration]]")
        .map_or(text.len(), |e| start + e + 1);
    let len = end - start;
    assert!(
        out.contains(&format!(
            "takes {len} bytes, more than the {MAX_RECORD_LEN}"
        )),
        "{len}: {out}"
    );
}
