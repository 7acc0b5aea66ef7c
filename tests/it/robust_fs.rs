//! Where vss writes, others can plant links: a symbolic link under a
//! temporary file's name, or under the output's own name, must never make
//! vss write outside its folder. Every writer is tried — `llv --out`,
//! `convert`, `report`, the session lock and the manifest — with a link to
//! a file outside the folder, which must come out untouched. And the
//! temporary files a killed run leaves are swept by the next write there.

use std::os::unix::fs::symlink;
use std::path::Path;
use std::time::Duration;

use vss::formats::img::{ImgFile, write_img};
use vss::llv::{GreyImage, Point, Segment};

const PRECIOUS: &[u8] = b"precious: not vss's to write";

/// A 64 × 64 grey square on a dark ground: the stages find lines in it.
fn square() -> ImgFile {
    let px = (0..64 * 64)
        .map(|i| {
            let (x, y) = (i % 64, i / 64);
            if (16..48).contains(&x) && (16..48).contains(&y) {
                200
            } else {
                30
            }
        })
        .collect();
    ImgFile::new(GreyImage::new(64, 64, px).expect("image")).with_comment("sq1a")
}

fn vss(cwd: &Path, args: &[&str]) -> (bool, String) {
    crate::support::run::run_in(cwd, args, Duration::from_secs(120))
}

/// `outside/secret`, the file a planted link points at.
fn outside(root: &Path) -> std::path::PathBuf {
    let d = root.join("outside");
    std::fs::create_dir_all(&d).expect("outside dir");
    let p = d.join("secret");
    std::fs::write(&p, PRECIOUS).expect("secret");
    p
}

fn assert_untouched(secret: &Path, what: &str) {
    assert_eq!(
        std::fs::read(secret).expect("secret still there"),
        PRECIOUS,
        "{what} wrote through a planted link"
    );
}

fn is_regular(p: &Path) -> bool {
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_file())
}

/// The name the writers used for their temporary file before it was made
/// random: `.NAME.tmp.PID` in the target's folder. A link planted there
/// (for this process, whose pid is known) was written through.
fn plant_old_temp(target: &Path, secret: &Path) {
    let name = target.file_name().expect("name").to_string_lossy();
    let tmp = target.with_file_name(format!(".{name}.tmp.{}", std::process::id()));
    symlink(secret, tmp).expect("plant the link");
}

#[test]
fn links_planted_at_temporary_names_are_never_written_through() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let secret = outside(root);
    let out = root.join("out");
    std::fs::create_dir(&out).expect("out");

    // convert's writer (every image format) and llv's outputs.
    let png = out.join("sq1a.png");
    plant_old_temp(&png, &secret);
    vss::formats::imageio::write_any(&png, &square()).expect("write png");
    assert_untouched(&secret, "convert (PNG)");
    assert!(is_regular(&png), "the output is a file, not the link");
    let ldr = out.join("sq1.ldr");
    plant_old_temp(&ldr, &secret);
    let seg = Segment::new(Point::new(1.0, 2.0), Point::new(30.0, 2.0));
    vss::formats::lines::write_lines(&ldr, &[seg]).expect("write ldr");
    assert_untouched(&secret, "llv (.ldr)");
    assert!(is_regular(&ldr));

    // report's writer.
    let ps = out.join("sq.ps");
    plant_old_temp(&ps, &secret);
    vss::fsutil::write_atomic(&ps, b"%!PS\n").expect("write ps");
    assert_untouched(&secret, "report (.ps)");
    assert!(is_regular(&ps));

    // The session: its lock and its manifest.
    let sess = root.join("s");
    std::fs::create_dir(sess.join("").parent().expect("dir")).ok();
    let dir = sess.join("cube");
    std::fs::create_dir_all(&dir).expect("session dir");
    plant_old_temp(&dir.join("cube.lock"), &secret);
    plant_old_temp(&dir.join("cube.toml"), &secret);
    plant_old_temp(&dir.join("cube.ses"), &secret);
    let profile = vss::rig::sim::cell_profile(64, 64);
    let s = vss::session::Session::create(&sess, "cube", &profile).expect("create session");
    assert_untouched(&secret, "the session lock or manifest");
    assert!(is_regular(&dir.join("cube.toml")) && is_regular(&dir.join("cube.lock")));
    drop(s);
}

#[test]
fn a_link_as_the_output_name_is_refused_by_every_command() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let secret = outside(root);
    let work = root.join("w");
    std::fs::create_dir(&work).expect("work");
    write_img(&work.join("sq1a.img"), &square()).expect("img");

    // convert
    symlink(&secret, work.join("sq1a.png")).expect("link");
    let (ok, out) = vss(&work, &["convert", "sq1a.img", "sq1a.png"]);
    assert!(!ok, "convert wrote through a link: {out}");
    assert!(
        out.contains("sq1a.png") && out.contains("symbolic link"),
        "{out}"
    );
    assert_untouched(&secret, "convert");

    // llv --out: the .ldr (named after the view, sq1) is a link
    std::fs::create_dir(work.join("o")).expect("o");
    symlink(&secret, work.join("o/sq1.ldr")).expect("link");
    let (ok, out) = vss(&work, &["llv", "sq1a.img", "--out", "o"]);
    assert!(!ok, "llv wrote through a link: {out}");
    assert!(
        out.contains("sq1.ldr") && out.contains("symbolic link"),
        "{out}"
    );
    assert_untouched(&secret, "llv --out");

    // report
    let seg = Segment::new(Point::new(1.0, 2.0), Point::new(30.0, 2.0));
    vss::formats::lines::write_lines(&work.join("t1.ldr"), &[seg]).expect("ldr");
    symlink(&secret, work.join("t1.ps")).expect("link");
    let (ok, out) = vss(&work, &["report", "--ldr", "t1.ldr", "--ps", "t1.ps"]);
    assert!(!ok, "report wrote through a link: {out}");
    assert!(
        out.contains("t1.ps") && out.contains("symbolic link"),
        "{out}"
    );
    assert_untouched(&secret, "report");
}

#[test]
fn a_planted_lock_link_is_not_written_through() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let secret = outside(root);
    let profile = vss::rig::sim::cell_profile(64, 64);
    let s = vss::session::Session::create(root, "cube", &profile).expect("create");
    drop(s);
    let lock = root.join("cube/cube.lock");
    symlink(&secret, &lock).expect("link");
    // The holder cannot be read through the link: refused, not followed.
    let e = vss::session::Session::open(&root.join("cube")).expect_err("a link as the lock");
    assert!(e.to_string().contains("cube.lock"), "{e}");
    assert_untouched(&secret, "the lock");
}

#[test]
fn a_killed_runs_temporary_files_are_swept_by_the_next_write() {
    let tmp = tempfile::tempdir().expect("tmp");
    let work = tmp.path();
    write_img(&work.join("sq1a.img"), &square()).expect("img");
    // What a run killed while writing leaves: its temporary file, named
    // after its pid, which is gone now.
    let mut child = std::process::Command::new("true").spawn().expect("true");
    let dead = child.id();
    child.wait().expect("wait");
    let left = [
        work.join(format!(".sq1a.png.tmp.{dead}")),
        work.join(format!(".sq1.ldr.tmp.{dead}")),
    ];
    for p in &left {
        std::fs::write(p, b"half a file").expect("leftover");
    }
    // A live writer's temporary file is not touched.
    let live = work.join(format!(".sq1.hpo.tmp.{}", std::process::id()));
    std::fs::write(&live, b"being written").expect("live");
    let (ok, out) = vss(work, &["convert", "sq1a.img", "sq1a.png"]);
    assert!(ok, "{out}");
    for p in &left {
        assert!(!p.exists(), "{} was not swept", p.display());
    }
    assert!(live.exists(), "a live writer's temporary file was removed");
}
