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

use crate::support::files::{mkfifo, sparse_img};

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
    // The report ends (it notes on the page what it could not read, and
    // says it: exit status 3, a report that is not whole).
    let (ok, out) = vss(root, &["report", "s/cube", "--ps", "r.ps"]);
    assert!(
        !ok && root.join("r.ps").is_file()
            && out.contains("vss: warning: cannot show cube1a.img")
            && out.contains("exit status 3"),
        "{out}"
    );
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
        out.contains("cube.toml") && out.contains(&vss::session::manifest::MAX_LEN.to_string()),
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

/// Issue 34 (residue of earlier fixes): a `.cdf` with a focal length of
/// 1e-300 mm or an image centre a billion pixels away is refused, naming
/// the file, the line and the field.
#[test]
fn a_cdf_with_an_absurd_focal_length_or_centre_is_refused() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    for (name, text, line, field) in [
        (
            "tiny_f.cdf",
            "S=A\n0.01\n0.01\nC=A\n32.0\n32.0\nf=A\n1e-300\n",
            ":8",
            "focal length",
        ),
        (
            "far_c.cdf",
            "S=A\n0.01\n0.01\nC=A\n1e9\n1e9\nf=A\n8.0\n",
            ":5",
            "image centre",
        ),
    ] {
        std::fs::write(root.join(name), text).expect("cdf");
        let (ok, out) = vss(root, &["info", name]);
        assert!(!ok, "{name} accepted: {out}");
        assert!(
            out.contains(&format!("{name}{line}")) && out.contains(field),
            "{out}"
        );
    }
}

/// Issue 34, N5: `vss info` of the largest `.img` there is (65535², sparse:
/// 4 GiB of pixels) reads the header and samples rows, within 512 MiB of
/// address space (it read the whole file: 8.4 GB, 47 s).
#[test]
fn info_of_the_largest_img_reads_its_header_and_samples() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    sparse_img(&root.join("huge1a.img"), u16::MAX, u16::MAX);
    let t = std::time::Instant::now();
    let (ok, out) = vss_limited(root, 512, &["info", "huge1a.img"]);
    assert!(ok, "{out}");
    assert!(
        out.contains("65535 × 65535")
            && out.contains("grey levels 0 to 0")
            && out.contains("sampled"),
        "{out}"
    );
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
}

/// Issue 34, N5: `report --img` of a 20000² image is refused from its
/// header, within 512 MiB (it cost 2 GB and wrote a 774 MB PostScript
/// file); a picture the report draws still prints.
#[test]
fn report_refuses_an_image_it_cannot_page_from_its_header() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    sparse_img(&root.join("big1a.img"), 20000, 20000);
    let (ok, out) = vss_limited(root, 512, &["report", "--img", "big1a.img"]);
    assert!(!ok, "{out}");
    assert!(
        out.contains("big1a.img") && out.contains("20000 x 20000"),
        "{out}"
    );
    assert!(!root.join("big1a.ps").exists());
    sparse_img(&root.join("small1a.img"), 640, 480);
    let (ok, out) = vss_limited(root, 512, &["report", "--img", "small1a.img"]);
    assert!(ok, "{out}");
    assert!(root.join("small1a.ps").exists());
}

/// `vss` in `work` with its own home (no config folder, no XDG variables
/// but `extra`).
fn vss_at_home(work: &Path, home: &Path, extra: &[(&str, &Path)], args: &[&str]) -> (bool, String) {
    let mut c = Command::cargo_bin("vss").expect("vss");
    c.args(args)
        .current_dir(work)
        .env("HOME", home)
        .env_remove("XDG_CONFIG_HOME")
        .env_remove("XDG_STATE_HOME")
        .timeout(Duration::from_secs(60));
    for (k, v) in extra {
        c.env(k, v);
    }
    let o = c.output().expect("vss");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

/// A profile named `name` that is the simulated cell.
fn named_profile(name: &str) -> String {
    let mut p = vss::rig::sim::cell_profile(32, 32);
    p.name = name.into();
    toml::to_string(&p).expect("toml")
}

/// Issue 34, N12: a `profiles/default.toml` in the working folder does not
/// replace the built-in profile of a bare `vss`; a profile found by name in
/// the working folder is named on stderr.
#[test]
fn a_default_profile_in_the_working_folder_is_not_taken_silently() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (work, home) = (tmp.path().join("work"), tmp.path().join("home"));
    std::fs::create_dir_all(work.join("profiles")).expect("work");
    std::fs::create_dir_all(&home).expect("home");
    std::fs::write(work.join("profiles/default.toml"), named_profile("planted")).expect("plant");
    std::fs::write(work.join("profiles/cell.toml"), named_profile("local cell")).expect("cell");
    let (ok, out) = vss_at_home(&work, &home, &[], &["session", "new", "s1", "--dir", "."]);
    assert!(ok, "{out}");
    let m = std::fs::read_to_string(work.join("s1/s1.toml")).expect("manifest");
    assert!(
        m.contains("simulated cell") && !m.contains("planted"),
        "{m}"
    );
    let (ok, out) = vss_at_home(
        &work,
        &home,
        &[],
        &["--profile", "cell", "session", "new", "s2", "--dir", "."],
    );
    assert!(ok, "{out}");
    assert!(
        out.contains("profiles/cell.toml") && out.contains("working folder"),
        "{out}"
    );
}

/// Issue 34, N6: a profile that is a symbolic link (as dotfile managers
/// install `~/.config`) is read through the link.
#[test]
fn a_profile_that_is_a_symbolic_link_is_read() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (work, home) = (tmp.path().join("work"), tmp.path().join("home"));
    let config = home.join(".config/vss/profiles");
    std::fs::create_dir_all(&config).expect("config");
    std::fs::create_dir_all(&work).expect("work");
    let dotfiles = tmp.path().join("dotfiles");
    std::fs::create_dir_all(&dotfiles).expect("dotfiles");
    std::fs::write(dotfiles.join("cell.toml"), named_profile("linked cell")).expect("profile");
    symlink(dotfiles.join("cell.toml"), config.join("cell.toml")).expect("link");
    let (ok, out) = vss_at_home(
        &work,
        &home,
        &[],
        &["--profile", "cell", "session", "new", "s1", "--dir", "."],
    );
    assert!(ok, "{out}");
    let m = std::fs::read_to_string(work.join("s1/s1.toml")).expect("manifest");
    assert!(m.contains("linked cell"), "{m}");
}

/// Issue 34, N13: a standard error that cannot be written (`/dev/full`,
/// closed) loses the message, not the exit status (it was 101, a panic).
#[test]
fn a_closed_stderr_keeps_the_exit_status() {
    let tmp = tempfile::tempdir().expect("tmp");
    let bin = assert_cmd::cargo::cargo_bin("vss");
    for redirect in ["2>/dev/full", "2>&-"] {
        let o = Command::new("bash")
            .args([
                "-c",
                &format!("'{}' info missing.img {redirect}", bin.display()),
            ])
            .current_dir(tmp.path())
            .timeout(Duration::from_secs(30))
            .output()
            .expect("bash");
        assert_eq!(o.status.code(), Some(1), "{redirect}: {o:?}");
    }
}

/// A session folder `name` whose manifest is `len` bytes of the costliest
/// TOML there is to parse: one-digit array values (76 bytes of memory per
/// byte of text).
fn costly_manifest(root: &Path, name: &str, len: usize) {
    let dir = root.join(name);
    std::fs::create_dir_all(&dir).expect("dir");
    let head = format!(
        "format = 1\n[session]\nname = \"{name}\"\ncreated = \"x\"\nmodified = \"x\"\n\
         version = \"0.1.0\"\nprofile = \"p\"\nplanned_images = 1\ncameras = 1\n\
         [[lighting]]\nletter = \"a\"\nnote = \"x\"\non = ["
    );
    let n = (len - head.len() - 2) / 2;
    let text = format!("{head}{}]\n", "1,".repeat(n));
    std::fs::write(dir.join(format!("{name}.toml")), text).expect("manifest");
}

/// Issue 34, N5: a manifest within the bound costs at most 512 MiB to read,
/// however it is written (a 16 MiB one of one-digit values took 1.27 GB);
/// one over the bound is refused unread.
#[test]
fn any_manifest_within_the_bound_reads_within_512_mib() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let max = vss::session::manifest::MAX_LEN;
    costly_manifest(root, "edge", max - 16);
    let (ok, out) = vss_limited(root, 512, &["session", "show", "edge"]);
    // One piece of 4 MiB outside the image records: refused before it is
    // parsed (its tree took 325 MB), naming its size and the cap.
    let cap = vss::session::manifest::MAX_RECORD_LEN;
    assert!(
        !ok && out.contains(&format!("takes {} bytes, more than the {cap}", max - 16)),
        "{out}"
    );
    // Within the cap, the same values are read and parsed, and refused:
    // they are not light names.
    costly_manifest(root, "edge", cap);
    let (ok, out) = vss_limited(root, 512, &["session", "show", "edge"]);
    assert!(!ok && out.contains("expected a string"), "{out}");
    costly_manifest(root, "over", 16 << 20);
    let (ok, out) = vss_limited(root, 512, &["session", "show", "over"]);
    assert!(!ok && out.contains("more than"), "{out}");
}

/// Issue 34, N5: `llv --from-edges` of a 600 MB `.hpo` (it cost 2.4 GB) is
/// refused unread; an edge file at the bound is read within 512 MiB.
#[test]
fn a_huge_edge_file_is_refused_unread() {
    use vss::formats::edgefile::MAX_POINTS;
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    // Sparse: the points are zeros (finite).
    let sparse_edges = |name: &str, dir: char, count: usize| {
        let head = format!("VSSEDGE 1 {dir} 4096 4096 {count}\n");
        let f = std::fs::File::create(root.join(name)).expect("create");
        use std::io::Write as _;
        (&f).write_all(head.as_bytes()).expect("header");
        f.set_len((head.len() + 12 * count) as u64).expect("sparse");
    };
    sparse_edges("big.hpo", 'H', 50_000_000);
    sparse_edges("big.vpo", 'V', 1);
    let (ok, out) = vss_limited(root, 512, &["llv", "--from-edges", "big.hpo", "big.vpo"]);
    assert!(
        !ok && out.contains("big.hpo") && out.contains("more than"),
        "{out}"
    );
    sparse_edges("edge.hpo", 'H', MAX_POINTS);
    let (ok, out) = vss_limited(root, 512, &["info", "edge.hpo"]);
    assert!(ok && out.contains(&format!("{MAX_POINTS} points")), "{out}");
}
