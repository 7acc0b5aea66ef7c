//! The command line against a shop floor's files and folders: a manifest
//! that is not a regular file, a report that fails part-way, a session
//! that cannot be made.

use std::path::Path;
use std::time::Duration;

use crate::support::files::{ReadOnly, mkfifo, sparse_img};

/// `vss` run in `cwd`: whether it succeeded, and stdout then stderr.
fn vss(cwd: &Path, args: &[&str]) -> (bool, String) {
    crate::support::run::run_in(cwd, args, Duration::from_secs(60))
}

/// A profile with one camera and one lighting.
const ONE_CAMERA: &str =
    "name = \"one camera\"\n[survey]\ncameras = 1\n[[lighting]]\nletter = \"a\"\non = []\n";

/// A new session `w` in `dir`.
fn new_session(dir: &Path) {
    std::fs::write(dir.join("p.toml"), ONE_CAMERA).expect("write profile");
    let (ok, out) = vss(
        dir,
        &["--profile", "p.toml", "session", "new", "w", "--dir", "."],
    );
    assert!(ok, "{out}");
}

/// A manifest replaced by a folder, a FIFO or a link to nothing is said as
/// what it is, naming it, by every command that reads it — not "not a
/// session folder: no manifest in it", which sent the operator to make a
/// new session over the old one's files — and `session new` of that name
/// is refused as existing.
#[test]
fn a_manifest_that_is_not_a_file_is_named_as_what_it_is() {
    type Case = (&'static str, fn(&Path), &'static str);
    let cases: [Case; 3] = [
        ("a folder", |p| std::fs::create_dir(p).unwrap(), "folder"),
        ("a FIFO", |p| mkfifo(p), "FIFO"),
        (
            "a link to nothing",
            |p| std::os::unix::fs::symlink("gone.toml", p).unwrap(),
            "symbolic link",
        ),
    ];
    for (what, make, said) in cases {
        let t = tempfile::tempdir().unwrap();
        new_session(t.path());
        let m = t.path().join("w/w.toml");
        std::fs::remove_file(&m).unwrap();
        make(&m);
        for args in [
            &["session", "show", "w"][..],
            &["session", "check", "w"],
            &["report", "w"],
        ] {
            let (ok, out) = vss(t.path(), args);
            assert!(!ok, "{what}, {args:?}: {out}");
            assert!(
                out.contains("w/w.toml") && out.contains(said),
                "{what}, {args:?} names the manifest and what it is:\n{out}"
            );
            assert!(
                !out.contains("not a session folder"),
                "{what}, {args:?}:\n{out}"
            );
        }
        let (ok, out) = vss(
            t.path(),
            &["--profile", "p.toml", "session", "new", "w", "--dir", "."],
        );
        assert!(!ok && out.contains("already exists"), "{what}: {out}");
    }
}

/// A session `s/g` of one image grabbed in lighting a on the simulated
/// cell (64² frames), with its outputs.
fn grabbed_session(dir: &Path) {
    crate::support::fixtures::quick_sim_profile(dir, "cell.toml");
    let grab = crate::support::fixtures::grab_args(Some("cell.toml"), "1", "1", "a");
    let (ok, out) = vss(dir, &grab);
    assert!(ok, "{out}");
    let (ok, out) = vss(
        dir,
        &[
            "--profile",
            "cell.toml",
            "session",
            "redo",
            "s/g",
            "--image",
            "1",
            "--from",
            "lens",
        ],
    );
    assert!(ok, "{out}");
}

/// A report that stops after some of its files are written (here an SVG
/// whose name is taken by a folder; a full disk alike) says which files it
/// did write: they replaced the old ones. Before, it said only "cannot
/// write all1.svg", as if the PostScript report on disk were still the old
/// one.
#[test]
fn a_report_stopped_part_way_names_what_it_wrote() {
    let t = tempfile::tempdir().unwrap();
    grabbed_session(t.path());
    std::fs::write(t.path().join("all.ps"), "the old report\n").unwrap();
    std::fs::create_dir(t.path().join("all1.svg")).unwrap();
    let (ok, out) = vss(
        t.path(),
        &["report", "s/g", "--ps", "all.ps", "--svg", "all.svg"],
    );
    assert!(!ok, "{out}");
    let ps = std::fs::read_to_string(t.path().join("all.ps")).unwrap();
    assert!(ps.starts_with("%!PS"), "all.ps is the new report");
    assert!(out.contains("cannot write all1.svg"), "{out}");
    assert!(
        !out.contains("all1.svg on disk is the OLD report"),
        "a folder is no report:\n{out}"
    );
    assert!(
        out.contains("written before it stopped (the NEW report): all.ps"),
        "says all.ps was replaced:\n{out}"
    );
}

/// A session asked for under a file (a survey folder that is a file, as a
/// profile's `dir` or `--dir`) is refused saying nothing was made; before,
/// it said "what it had made could not all be removed …: remove afile/w by
/// hand", sending the operator after a folder that never was.
#[test]
fn a_session_under_a_file_is_refused_without_sending_anyone_to_clean_up() {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(t.path().join("p.toml"), ONE_CAMERA).unwrap();
    std::fs::write(t.path().join("afile"), "a file\n").unwrap();
    for dir in ["afile", "afile/sub"] {
        let (ok, out) = vss(
            t.path(),
            &["--profile", "p.toml", "session", "new", "w", "--dir", dir],
        );
        assert!(!ok, "{out}");
        assert!(out.contains("Not a directory"), "why:\n{out}");
        assert!(
            out.contains("nothing of it is left") && !out.contains("by hand"),
            "{dir}:\n{out}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(t.path().join("afile")).unwrap(),
        "a file\n"
    );
}

/// A session's frame replaced by a huge one (a 40000² `.img`, 1.6 GB,
/// consistent with its own size) is refused from its header by `session
/// check` and `session redo`, within 256 MiB of address space: they read it
/// whole (check took 3.1 GB, redo 1.5 GB). A frame of another size than
/// the manifest records is refused by redo naming both sizes.
#[test]
fn a_frame_replaced_by_a_huge_one_is_refused_from_its_header() {
    let t = tempfile::tempdir().unwrap();
    grabbed_session(t.path());
    let frame = t.path().join("s/g/g1a.img");
    std::fs::remove_file(&frame).unwrap();
    sparse_img(&frame, 40000, 40000);
    for args in [
        &["session", "check", "s/g"][..],
        &["session", "redo", "s/g", "--image", "1", "--from", "lens"],
    ] {
        let o = super::support::limited::vss_under(t.path(), "ulimit -v 262144", args);
        let out =
            String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {out}");
        assert!(
            out.contains("g1a.img") && out.contains("40000") && out.contains("too large"),
            "{args:?}: {out}"
        );
    }
    // 80 × 64: a frame the stages take, but not the one recorded (64 × 64).
    std::fs::remove_file(&frame).unwrap();
    sparse_img(&frame, 80, 64);
    let (ok, out) = vss(
        t.path(),
        &["session", "redo", "s/g", "--image", "1", "--from", "lens"],
    );
    assert!(!ok, "{out}");
    assert!(
        out.contains("g1a.img") && out.contains("80 x 64") && out.contains("records 64 x 64"),
        "{out}"
    );
}

/// A command that would write a session whose folder cannot be written (a
/// read-only mount, an archive) says so and what can still be done; it
/// said only "s/g/g.lock: Read-only file system (os error 30)".
#[test]
fn writing_a_read_only_session_says_what_and_what_is_left() {
    let t = tempfile::tempdir().unwrap();
    grabbed_session(t.path());
    let Some(_ro) = ReadOnly::make(&t.path().join("s/g")) else {
        eprintln!("SKIPPED: root here cannot mount, and writes through permissions");
        return;
    };
    let (ok, out) = vss(
        t.path(),
        &[
            "--profile",
            "cell.toml",
            "session",
            "redo",
            "s/g",
            "--image",
            "1",
            "--from",
            "lines",
        ],
    );
    assert!(!ok, "{out}");
    assert!(
        out.contains("g.lock") && out.contains("the session folder cannot be written"),
        "{out}"
    );
    assert!(out.contains("vss session show"), "what is left:\n{out}");
}
