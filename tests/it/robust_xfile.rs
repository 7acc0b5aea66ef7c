//! The command line against a shop floor's files and folders: a manifest
//! that is not a regular file, a report that fails part-way, a session
//! that cannot be made.

use std::path::Path;
use std::time::Duration;

use assert_cmd::Command;

/// `vss` run in `cwd`: whether it succeeded, and stdout then stderr.
fn vss(cwd: &Path, args: &[&str]) -> (bool, String) {
    let o = Command::cargo_bin("vss")
        .expect("the vss binary")
        .args(args)
        .current_dir(cwd)
        .timeout(Duration::from_secs(60))
        .output()
        .expect("run vss");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
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
        (
            "a FIFO",
            |p| {
                let ok = std::process::Command::new("mkfifo").arg(p).status();
                assert!(ok.unwrap().success(), "mkfifo");
            },
            "FIFO",
        ),
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
