//! The fuzz targets' seed corpus, `fuzz/seeds/TARGET/`: every target in
//! `fuzz/Cargo.toml` has seeds, and every seed is an input its reader takes,
//! so a campaign starts from inputs that reach deep into each parser. The
//! seeds are files `vss` itself wrote (a session grabbed from the embedded
//! simulated cell and processed, its images converted, parameters exported)
//! and the bytes the simulated grabber and relay board sent to the drivers.
//! They are made anew with
//! `cargo test --test it robust_fuzz::write_fuzz_seeds -- --ignored`.

use std::path::{Path, PathBuf};
use std::time::Duration;

use assert_cmd::Command;
use vss::formats::cdf::parse_cdf;
use vss::formats::edgefile::parse_edges;
use vss::formats::imageio::{ImageKind, decode_any};
use vss::formats::img::parse_img;
use vss::formats::lines::parse_lines;
use vss::formats::par::parse_par;
use vss::formats::ses::parse_ses;
use vss::profile::Profile;
use vss::rig::grabber::{ClientConfig, FrameGrabber, VsgClient};
use vss::rig::open_serial;
use vss::rig::protocol::{
    Command as VsgCommand, NumatoCommand, crc32, decode_line, find_reply, lcus_frame, lcus_parse,
    numato_reply,
};
use vss::rig::replay::{Replay, SEPARATOR, Tap, recording};
use vss::rig::sim::{Faults, SimCell, SimOptions, cell_profile};
use vss::session::manifest::Manifest;

/// The image kinds of the `image` target, picked by a seed's first byte
/// (as `fuzz/fuzz_targets/image.rs` lists them).
const KINDS: [ImageKind; 5] = [
    ImageKind::Png,
    ImageKind::Pgm,
    ImageKind::Tiff,
    ImageKind::Bmp,
    ImageKind::Jpeg,
];

/// The commands whose answers the `relay` target looks for.
const NUMATO_SENT: [&str; 4] = ["ver", "relay on 2", "relay read 2", "relay readall"];

/// The client settings of the `vsg_client` target (the seeds' READs must
/// be the ones it sends).
fn client_config() -> ClientConfig {
    ClientConfig {
        timeout: Duration::from_millis(1),
        retries: 1,
        block: 64,
        baud: 921_600,
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

fn targets() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("Cargo.toml")).expect("fuzz/Cargo.toml");
    let t: toml::Table = toml::from_str(&text).expect("fuzz/Cargo.toml is TOML");
    t.get("bin")
        .and_then(|b| b.as_array())
        .expect("[[bin]] targets")
        .iter()
        .filter_map(|b| b.get("name")?.as_str().map(str::to_string))
        .collect()
}

fn line_of(bytes: &[u8]) -> &[u8] {
    let b = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    b.strip_suffix(b"\r").unwrap_or(b)
}

/// Whether the reader of `target` takes `seed` (for the two device
/// targets: the drivers get what they asked for out of it).
fn taken(target: &str, seed: &[u8]) -> Result<(), String> {
    let p = Path::new("seed");
    let text = || std::str::from_utf8(seed).map_err(|e| e.to_string());
    let e = |e: &dyn std::fmt::Display| e.to_string();
    match target {
        "img" => parse_img(seed, p).map(drop).map_err(|x| e(&x)),
        "image" => {
            let (&pick, bytes) = seed.split_first().ok_or("empty")?;
            let kind = KINDS[usize::from(pick) % KINDS.len()];
            decode_any(bytes, kind, p).map(drop).map_err(|x| e(&x))
        }
        "cdf" => parse_cdf(text()?, p).map(drop).map_err(|x| e(&x)),
        "lines" => parse_lines(text()?, p).map(drop).map_err(|x| e(&x)),
        "edges" => parse_edges(seed, p).map(drop).map_err(|x| e(&x)),
        "par" => parse_par(text()?, p).map(drop).map_err(|x| e(&x)),
        "ses" => parse_ses(text()?, p).map(drop).map_err(|x| e(&x)),
        "manifest" => Manifest::parse(text()?, p).map(drop).map_err(|x| e(&x)),
        "profile" => Profile::from_toml(text()?, p).map(drop).map_err(|x| e(&x)),
        "vsg_line" => decode_line(line_of(seed)).map(drop).map_err(|x| e(&x)),
        "vsg_client" => {
            let (&head, bytes) = seed.split_first().ok_or("empty")?;
            let feed = Replay::new(bytes, b'\n', usize::from(head % 64) + 1);
            let mut c = VsgClient::new(feed, "/dev/seed", client_config());
            c.connect().map_err(|x| e(&x))?;
            if head & 0x40 != 0 {
                c.select_camera(2).map_err(|x| e(&x))?;
            }
            c.freeze().map_err(|x| e(&x))?;
            let img = c.transfer(&mut |_, _| true).map_err(|x| e(&x))?;
            if c.frame().is_some_and(|f| f.crc == crc32(img.data())) {
                Ok(())
            } else {
                Err("frame CRC".into())
            }
        }
        "relay" => {
            let by_text = std::str::from_utf8(seed)
                .ok()
                .and_then(NumatoCommand::parse)
                .is_some();
            let as_reply = NUMATO_SENT
                .iter()
                .any(|s| numato_reply(s, seed).is_some_and(|(_, r)| r.is_ok()));
            if by_text || as_reply || lcus_parse(seed).is_some() {
                Ok(())
            } else {
                Err("neither a Numato command, a Numato reply nor an LCUS frame".into())
            }
        }
        other => Err(format!("no check for the fuzz target {other}")),
    }
}

#[test]
fn every_fuzz_target_has_seeds_its_reader_takes() {
    let all = targets();
    assert!(all.len() >= 12, "{all:?}");
    for t in &all {
        let dir = root().join("seeds").join(t);
        let seeds: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|d| d.expect("entry").path())
            .collect();
        assert!(!seeds.is_empty(), "no seeds for {t}");
        for s in seeds {
            let bytes = std::fs::read(&s).expect("seed");
            if let Err(why) = taken(t, &bytes) {
                panic!("{} is not taken by its reader: {why}", s.display());
            }
        }
    }
}

fn vss(args: &[&str], cwd: &Path) {
    let o = Command::cargo_bin("vss")
        .expect("vss")
        .args(args)
        .current_dir(cwd)
        .timeout(Duration::from_secs(120))
        .output()
        .expect("run vss");
    assert!(
        o.status.success(),
        "vss {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Writes `bytes` as seed `name` of `target` (the folder is made anew by
/// the caller).
fn seed(target: &str, name: &str, bytes: &[u8]) {
    let dir = root().join("seeds").join(target);
    std::fs::create_dir_all(&dir).expect("seed dir");
    std::fs::write(dir.join(name), bytes).expect("seed");
}

fn copy_seed(target: &str, from: &Path) {
    let name = from
        .file_name()
        .expect("name")
        .to_string_lossy()
        .into_owned();
    seed(target, &name, &std::fs::read(from).expect("read"));
}

/// Files of `dir` whose extension is `ext`.
fn with_ext(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|d| d.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// Makes `fuzz/seeds/` anew.
#[test]
#[ignore = "writes fuzz/seeds/: run by hand when a format changes"]
fn write_fuzz_seeds() {
    let seeds = root().join("seeds");
    let _ = std::fs::remove_dir_all(&seeds);
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();

    // Files: a small session grabbed from the embedded simulated cell,
    // processed from the lens stage on.
    let mut p = cell_profile(64, 48);
    p.relay.settle_ms = 0;
    let profile = toml::to_string(&p).expect("profile");
    std::fs::write(d.join("cell.toml"), &profile).expect("profile");
    // The cameras' .cdf files the profile names, so the lens stage runs.
    let sim_cdfs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("profiles/sim");
    std::fs::create_dir_all(d.join("sim")).expect("sim dir");
    for f in with_ext(&sim_cdfs, "cdf") {
        std::fs::copy(&f, d.join("sim").join(f.file_name().expect("name"))).expect("cdf");
    }
    seed("profile", "cell.toml", profile.as_bytes());
    for f in ["default.toml", "real-cell.toml"] {
        copy_seed(
            "profile",
            &PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("profiles")
                .join(f),
        );
    }
    let cube = d.join("cube");
    let cube_s = cube.to_string_lossy().into_owned();
    vss(
        &[
            "--profile",
            "cell.toml",
            "grab",
            "--camera",
            "1",
            "--lighting",
            "a,b,c,d,e",
            "--image",
            "1",
            "--yes",
            "--session",
            &cube_s,
        ],
        d,
    );
    vss(
        &[
            "--profile",
            "cell.toml",
            "session",
            "redo",
            &cube_s,
            "--image",
            "1",
            "--from",
            "lens",
        ],
        d,
    );
    for (target, ext) in [
        ("img", "img"),
        ("img", "imc"),
        ("cdf", "cdf"),
        ("lines", "lex"),
        ("lines", "ldr"),
        ("edges", "hpo"),
        ("edges", "vpo"),
        ("ses", "ses"),
        ("manifest", "toml"),
    ] {
        let files = with_ext(&cube, ext);
        assert!(!files.is_empty(), "the session has no .{ext} file");
        for f in files {
            copy_seed(target, &f);
        }
    }
    for f in with_ext(&sim_cdfs, "cdf") {
        copy_seed("cdf", &f);
    }
    for (pick, ext) in ["png", "pgm", "tif", "bmp"].iter().enumerate() {
        let out = format!("cube1a.{ext}");
        vss(&["convert", "cube/cube1a.img", &out], d);
        let mut bytes = vec![pick as u8];
        bytes.extend(std::fs::read(d.join(&out)).expect("converted"));
        seed("image", &format!("cube1a.{ext}"), &bytes);
    }
    for set in ["lens", "edges", "lines", "connect", "all"] {
        let out = format!("{set}.par");
        vss(
            &["params", "export", "default", "--set", set, "--out", &out],
            d,
        );
        copy_seed("par", &d.join(out));
    }

    // The simulated grabber's answers to a connect, a freeze and a frame
    // (32 × 24, twelve blocks), as the client read them.
    let sim = SimCell::start(SimOptions::new(32, 24)).expect("sim");
    let port = open_serial(sim.grabber_path(), 921_600, Duration::from_millis(200)).expect("open");
    let (tap, heard) = Tap::new(port, b'\n');
    let mut cfg = client_config();
    cfg.timeout = Duration::from_millis(500);
    let mut c = VsgClient::new(tap, sim.grabber_path(), cfg.clone());
    c.connect().expect("connect");
    let f = c.freeze().expect("freeze");
    let img = c.transfer(&mut |_, _| true).expect("transfer");
    assert_eq!(crc32(img.data()), f.crc);
    let answers = heard.lock().expect("heard").clone();
    let stream = answers.concat();
    assert!(
        !stream.windows(SEPARATOR.len()).any(|w| w == SEPARATOR),
        "the separator occurs in the answers"
    );
    for chunk in [63u8, 6, 0] {
        let mut bytes = vec![chunk];
        bytes.extend_from_slice(&recording(&answers));
        taken("vsg_client", &bytes).expect("the recording plays back");
        seed("vsg_client", &format!("frame-{}", chunk + 1), &bytes);
    }
    // Camera 2 selected (bit 6 of the first byte), and the grabber reset
    // after the first block: the client freezes again by itself.
    let mut o = SimOptions::new(32, 24);
    o.faults = Faults::parse("reset").expect("faults");
    let reset = SimCell::start(o).expect("sim");
    let port =
        open_serial(reset.grabber_path(), 921_600, Duration::from_millis(200)).expect("open");
    let (tap, heard) = Tap::new(port, b'\n');
    let mut c = VsgClient::new(tap, reset.grabber_path(), cfg.clone());
    c.connect().expect("connect");
    c.select_camera(2).expect("camera");
    c.freeze().expect("freeze");
    c.transfer(&mut |_, _| true)
        .expect("transfer after a reset");
    assert_eq!(c.wire_stats().refreezes, 1);
    let answers = heard.lock().expect("heard").clone();
    for chunk in [63u8, 6, 0] {
        let mut bytes = vec![0x40 | chunk];
        bytes.extend_from_slice(&recording(&answers));
        taken("vsg_client", &bytes).expect("the recording plays back");
        seed("vsg_client", &format!("reset-{}", chunk + 1), &bytes);
    }
    let mut rest = &stream[..];
    let mut n = 0;
    while let Some((start, end, _)) = find_reply(rest) {
        if n < 8 {
            seed("vsg_line", &format!("reply-{n}"), &rest[start..end]);
        }
        n += 1;
        rest = &rest[end..];
    }
    for cmd in [
        VsgCommand::Hello,
        VsgCommand::Freeze,
        VsgCommand::Camera(2),
        VsgCommand::Read { off: 64, len: 64 },
        VsgCommand::Load {
            width: 32,
            height: 24,
            crc: f.crc,
        },
    ] {
        let name = cmd.to_string().to_lowercase().replace(' ', "-");
        seed("vsg_line", &format!("cmd-{name}"), &cmd.encode());
    }

    // The simulated Numato board's answers, echo to prompt, and the
    // commands and LCUS frames the drivers send.
    let mut r = open_serial(sim.relay_path(), 19_200, Duration::from_millis(50)).expect("relay");
    for (i, cmd) in NUMATO_SENT.iter().enumerate() {
        use std::io::{Read, Write};
        r.write_all(format!("{cmd}\r").as_bytes()).expect("write");
        let mut got = Vec::new();
        let deadline = std::time::Instant::now() + Duration::from_secs(3);
        let mut buf = [0u8; 64];
        while numato_reply(cmd, &got).is_none() {
            assert!(
                std::time::Instant::now() < deadline,
                "no reply to {cmd}: {got:?}"
            );
            if let Ok(k) = r.read(&mut buf) {
                got.extend_from_slice(&buf[..k]);
            }
        }
        seed("relay", &format!("reply-{i}"), &got);
    }
    for (i, cmd) in [
        "relay on 2",
        "relay off A",
        "relay writeall 0005",
        "relay readall",
    ]
    .iter()
    .enumerate()
    {
        let c = NumatoCommand::parse(cmd).expect("a Numato command");
        seed(
            "relay",
            &format!("cmd-{i}"),
            c.text().expect("text").as_bytes(),
        );
    }
    for (relay, on) in [(1, true), (4, false)] {
        let frame = lcus_frame(relay, on).expect("frame");
        seed("relay", &format!("lcus-{relay}-{on}"), &frame);
    }
}
