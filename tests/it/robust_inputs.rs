//! Readers against what can be planted in a session folder or handed to a
//! command: a FIFO (which blocked `check`, `report` and `info` for ever), a
//! link to `/dev/zero` (which made `check` read 2 GB), a link to a file
//! outside (whose first bytes reached an error message), files far larger
//! than their format allows (a 20000² `.img` read whole before its size was
//! refused, TOML files that cost 25–50 times their size to parse), and a
//! camera description that makes no sense (focal length 0: a black `.imc`
//! and 0 lines, exit 0). Memory is bounded with `ulimit -v` in the child, so
//! a reader that allocates what a file claims fails the test by crashing.

use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::time::Duration;

use assert_cmd::Command;
use vss::formats::img::{ImgFile, write_img};
use vss::llv::GreyImage;
use vss::session::Session;

/// Runs `vss ARGS` in `cwd` with at most `mem_mb` of address space and a
/// time limit (a reader blocked on a FIFO fails the test instead of hanging
/// it).
fn vss_limited(cwd: &Path, mem_mb: u64, args: &[&str]) -> (bool, String) {
    let bin = assert_cmd::cargo::cargo_bin("vss");
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!(
        "ulimit -v {}; exec '{}' {}",
        mem_mb * 1024,
        bin.display(),
        quoted.join(" ")
    );
    let o = Command::new("bash")
        .args(["-c", &script])
        .current_dir(cwd)
        .timeout(Duration::from_secs(60))
        .output()
        .expect("run vss");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    // Killed (by the time limit: a hang; or by an abort: memory) is never
    // an answer.
    assert!(
        o.status.code().is_some(),
        "vss {args:?} was killed ({:?}): {text}",
        o.status
    );
    (o.status.success(), text)
}

fn vss(cwd: &Path, args: &[&str]) -> (bool, String) {
    vss_limited(cwd, 1024, args)
}

fn grey(w: usize, h: usize) -> ImgFile {
    let px = (0..w * h).map(|i| (i * 7 % 251) as u8).collect();
    ImgFile::new(GreyImage::new(w, h, px).expect("image"))
}

/// A session `s/cube` with image 1 under lighting a saved; returns the
/// image's path.
fn session_with_image(root: &Path) -> PathBuf {
    let profile = vss::rig::sim::cell_profile(64, 64);
    let mut s = Session::create(&root.join("s"), "cube", &profile).expect("session");
    s.set_image_info(1, 1, 1, None).expect("image info");
    s.save_image(1, 'a', &grey(64, 64)).expect("save")
}

fn mkfifo(p: &Path) {
    let ok = std::process::Command::new("mkfifo")
        .arg(p)
        .status()
        .expect("mkfifo")
        .success();
    assert!(ok, "mkfifo {}", p.display());
}

#[test]
fn a_fifo_in_a_session_blocks_no_reader() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let img = session_with_image(root);
    std::fs::remove_file(&img).expect("rm");
    mkfifo(&img);
    let (ok, out) = vss(root, &["session", "check", "s/cube"]);
    assert!(!ok, "check passed a FIFO: {out}");
    assert!(out.contains("cube1a.img") && out.contains("FIFO"), "{out}");
    let (ok, out) = vss(root, &["info", "s/cube/cube1a.img"]);
    assert!(!ok && out.contains("FIFO"), "{out}");
    // The report ends (it notes on the page what it could not read).
    let (ok, out) = vss(root, &["report", "s/cube", "--ps", "r.ps"]);
    assert!(ok && root.join("r.ps").is_file(), "{out}");
}

#[test]
fn links_to_devices_and_outside_files_are_not_read() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let img = session_with_image(root);
    std::fs::remove_file(&img).expect("rm");
    symlink("/dev/zero", &img).expect("link");
    // 256 MB of address space: reading /dev/zero for 2 GB cannot fit.
    let (ok, out) = vss_limited(root, 256, &["session", "check", "s/cube"]);
    assert!(!ok, "{out}");
    assert!(
        out.contains("cube1a.img") && out.contains("symbolic link"),
        "{out}"
    );

    let secret = root.join("secret.txt");
    std::fs::write(&secret, "TOP-SECRET-BYTES of another user\n").expect("secret");
    let cdf = root.join("s/cube/cube1.cdf");
    symlink(&secret, &cdf).expect("link");
    for args in [
        &["info", "s/cube/cube1.cdf"][..],
        &["llv", "s/cube/cube1a.img", "--cdf", "s/cube/cube1.cdf"][..],
    ] {
        let (ok, out) = vss(root, args);
        assert!(!ok, "{args:?}: {out}");
        assert!(
            !out.contains("TOP-SECRET"),
            "{args:?} leaked the file: {out}"
        );
        assert!(out.contains("symbolic link"), "{args:?}: {out}");
    }
}

/// A sparse `.img` whose header and size agree on `w` × `h` pixels.
fn sparse_img(p: &Path, w: u16, h: u16) {
    let mut head = vec![0u8; 64];
    head[0] = b'I';
    head[1] = b'M';
    head[4..6].copy_from_slice(&w.to_le_bytes());
    head[6..8].copy_from_slice(&h.to_le_bytes());
    std::fs::write(p, &head).expect("header");
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(p)
        .expect("open");
    f.set_len(64 + u64::from(w) * u64::from(h)).expect("grow");
}

#[test]
fn llv_refuses_a_huge_consistent_image_from_its_header() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    sparse_img(&root.join("big1a.img"), 20000, 20000);
    // 400 MB of pixels; with 256 MB of address space only a reader that
    // checks the header first can answer.
    let (ok, out) = vss_limited(root, 256, &["llv", "big1a.img"]);
    assert!(!ok, "{out}");
    assert!(
        out.contains("big1a.img") && out.contains("20000") && out.contains("8192"),
        "{out}"
    );
    assert!(!out.contains("memory allocation"), "{out}");
}

#[test]
fn oversized_profiles_and_manifests_are_refused_unread() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    // A valid profile padded to 12 MB with comments.
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/default.toml"),
    )
    .expect("default profile");
    let pad = "# padding padding padding padding padding padding padding padding\n";
    let big = format!("{base}{}", pad.repeat(12_000_000 / pad.len()));
    std::fs::write(root.join("big.toml"), &big).expect("write");
    let (ok, out) = vss(
        root,
        &["--profile", "big.toml", "session", "new", "n", "--dir", "."],
    );
    assert!(
        !ok,
        "a 12 MB profile was read: {}",
        &out[..out.len().min(300)]
    );
    assert!(out.contains("big.toml") && out.contains("1048576"), "{out}");

    session_with_image(root);
    let m = root.join("s/cube/cube.toml");
    let text = std::fs::read_to_string(&m).expect("manifest");
    let big = format!("{text}{}", pad.repeat(17_000_000 / pad.len()));
    std::fs::write(&m, big).expect("write");
    let (ok, out) = vss(root, &["session", "show", "s/cube"]);
    assert!(!ok, "a 17 MB manifest was read");
    assert!(
        out.contains("cube.toml") && out.contains("16777216"),
        "{out}"
    );
}

const CDF_F0: &str = "S=A\n0.011250\n0.007800\nC=E\n32.0\n32.0\nf=A\n0\nD=N\n0\n0\n0\n0\n0\n";

#[test]
fn a_nonsensical_cdf_is_refused_naming_file_and_field() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    write_img(&root.join("q1a.img"), &grey(64, 64)).expect("img");
    std::fs::write(root.join("f0.cdf"), CDF_F0).expect("cdf");
    let (ok, out) = vss(root, &["llv", "q1a.img", "--cdf", "f0.cdf"]);
    assert!(!ok, "f = 0 accepted: {out}");
    assert!(
        out.contains("f0.cdf:8") && out.contains("focal length"),
        "{out}"
    );
    assert!(!root.join("q1a.imc").exists(), "an .imc was written");

    // Scale and centre valid, but a distortion that sends every pixel
    // outside the picture.
    let wild = "S=A\n0.01\n0.01\nC=A\n32.0\n32.0\nf=A\n8.0\nD=A\n50\n0\n0\n0\n0\n";
    std::fs::write(root.join("wild.cdf"), wild).expect("cdf");
    let (ok, out) = vss(root, &["llv", "q1a.img", "--cdf", "wild.cdf"]);
    assert!(!ok, "a model leaving no picture accepted: {out}");
    assert!(
        out.contains("wild.cdf") && out.contains("distortion"),
        "{out}"
    );
}
