//! Sessions against hostile input, as a person would meet it: an image
//! number far beyond any survey (from `vss grab` or a hand-edited manifest)
//! is refused with an error naming the limit instead of sizing the
//! checklist, a refused grab leaves no session behind, and a bad session
//! name is reported once.

use std::path::Path;
use std::time::Duration;

use assert_cmd::Command;
use vss::rig::sim::cell_profile;
use vss::session::MAX_IMAGE_NUMBER;

/// `vss` run in `cwd`. The timeout turns a regression into a failure, not
/// a hang (the checklist of image 30 000 000 took over a minute).
fn vss(cwd: &Path, args: &[&str]) -> (bool, String) {
    crate::support::run::run_in(cwd, args, Duration::from_secs(60))
}

/// A simulated cell with small frames: cameras 1 to 4, lightings a to e.
fn write_profile(dir: &Path) {
    crate::support::fixtures::quick_sim_profile(dir, "p.toml");
}

fn grab(dir: &Path, image: &str, camera: &str, lighting: &str) -> (bool, String) {
    vss(
        dir,
        &crate::support::fixtures::grab_args(Some("p.toml"), image, camera, lighting),
    )
}

/// A profile with one camera and one lighting.
const ONE_CAMERA: &str =
    "name = \"one camera\"\n[survey]\ncameras = 1\n[[lighting]]\nletter = \"a\"\non = []\n";

/// A new session `w` in `dir`, planning one image; its manifest text.
fn new_session(dir: &Path) -> String {
    std::fs::write(dir.join("p.toml"), ONE_CAMERA).expect("write profile");
    let (ok, out) = vss(
        dir,
        &["--profile", "p.toml", "session", "new", "w", "--dir", "."],
    );
    assert!(ok, "{out}");
    std::fs::read_to_string(dir.join("w/w.toml")).expect("manifest")
}

#[test]
fn grab_refuses_a_huge_image_number_and_creates_nothing() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    write_profile(d);
    let (ok, out) = grab(d, "4294967295", "1", "a");
    assert!(!ok, "image 4294967295 accepted: {out}");
    assert!(
        out.contains("image number 4294967295") && out.contains(&MAX_IMAGE_NUMBER.to_string()),
        "{out}"
    );
    assert!(
        !d.join("s").exists(),
        "a refused grab made {:?}",
        d.join("s")
    );
}

#[test]
fn grab_refuses_image_0_and_bad_arguments_before_making_the_session() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    write_profile(d);
    for (image, camera, lighting, says) in [
        ("0", "1", "a", "image number 0"),
        ("1", "9", "a", "camera 9 does not exist"),
        ("1", "1", "a,q", "no lighting configuration `q`"),
    ] {
        let (ok, out) = grab(d, image, camera, lighting);
        assert!(
            !ok,
            "image {image} camera {camera} lighting {lighting}: {out}"
        );
        assert!(out.contains(says), "{out}");
        assert!(
            !d.join("s").exists(),
            "image {image} camera {camera} lighting {lighting} left {:?} behind",
            d.join("s")
        );
    }
}

#[test]
fn show_reports_a_manifest_planning_too_many_images() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    let good = new_session(d);
    let bad = good.replace("planned_images = 1", "planned_images = 4294967295");
    assert_ne!(bad, good, "the manifest plans one image: {good}");
    std::fs::write(d.join("w/w.toml"), &bad).expect("edit manifest");
    let (ok, out) = vss(d, &["session", "show", "w"]);
    assert!(!ok, "{out}");
    let line = bad
        .lines()
        .position(|l| l.starts_with("planned_images"))
        .expect("planned_images line")
        + 1;
    assert!(out.contains(&format!("w.toml:{line}:")), "{out}");
    assert!(
        out.contains("planned_images 4294967295") && out.contains(&MAX_IMAGE_NUMBER.to_string()),
        "{out}"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("w/w.toml")).expect("manifest"),
        bad,
        "manifest kept as it was"
    );

    // The limit itself is a survey like any other.
    let edge = good.replace(
        "planned_images = 1",
        &format!("planned_images = {MAX_IMAGE_NUMBER}"),
    );
    std::fs::write(d.join("w/w.toml"), &edge).expect("edit manifest");
    let (ok, out) = vss(d, &["session", "show", "w"]);
    assert!(ok, "{out}");
    assert!(
        out.contains(&format!("0 of {MAX_IMAGE_NUMBER} images done")),
        "{out}"
    );
}

#[test]
fn show_reports_an_image_record_beyond_the_limit() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    let good = new_session(d);
    let beyond = MAX_IMAGE_NUMBER + 1;
    let bad = format!("{good}\n[[image]]\nnumber = {beyond}\ncamera = 1\nlocation = 1\n");
    std::fs::write(d.join("w/w.toml"), &bad).expect("edit manifest");
    let (ok, out) = vss(d, &["session", "show", "w"]);
    assert!(!ok, "{out}");
    let line = bad
        .lines()
        .position(|l| l == format!("number = {beyond}"))
        .expect("number line")
        + 1;
    assert!(out.contains(&format!("w.toml:{line}:")), "{out}");
    assert!(
        out.contains(&format!("image number {beyond}"))
            && out.contains(&MAX_IMAGE_NUMBER.to_string()),
        "{out}"
    );
}

#[test]
fn a_bad_session_name_is_reported_once() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    std::fs::write(d.join("p.toml"), ONE_CAMERA).expect("write profile");
    for bad in ["../x", "..", "9lives"] {
        let (ok, out) = vss(
            d,
            &["--profile", "p.toml", "session", "new", bad, "--dir", "."],
        );
        assert!(!ok, "{bad:?} accepted");
        assert_eq!(
            out.matches(&format!("session name {bad:?}")).count(),
            1,
            "{bad:?}: the error once: {out}"
        );
    }
}

/// Issue 34, N4: two cell PCs write one survey folder. The second takes
/// the session over (the first holder is on another host, as its lock
/// file says); the displaced writer's next save fails, says so, and
/// writes nothing; every data file on disk is recorded: 0 lost records.
#[test]
fn a_displaced_writer_cannot_save_and_no_record_is_lost() {
    use vss::formats::img::ImgFile;
    use vss::llv::GreyImage;
    use vss::session::{Session, SessionError, lock};
    let tmp = tempfile::tempdir().expect("tmp");
    let p = cell_profile(32, 32);
    let grey = |v: u8| ImgFile::new(GreyImage::filled(16, 16, v).expect("image"));
    let mut a = Session::create(tmp.path(), "tw", &p).expect("create");
    a.save_image(1, 'a', &grey(1)).expect("a saves 1");
    // Writer A's lock as the other PC wrote it: another host.
    let lock_path = a.dir().join("tw.lock");
    let mut holder = lock::read_holder(&lock_path).expect("lock");
    holder.host = "cell-pc-1".into();
    std::fs::write(&lock_path, toml::to_string(&holder).expect("toml")).expect("lock");
    let mut b = Session::open_take_over(a.dir()).expect("take over a foreign lock");
    b.save_image(2, 'a', &grey(2)).expect("b saves 2");
    let e = a
        .save_image(3, 'a', &grey(3))
        .expect_err("the displaced writer saved");
    assert!(matches!(e, SessionError::LockLost { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("taken over") && msg.contains("NOT saved") && msg.contains("tw.lock"),
        "{msg}"
    );
    assert!(
        !a.dir().join("tw3a.img").exists(),
        "the refused image was written"
    );
    assert!(
        a.set_image_info(1, 1, 1, None).is_err(),
        "any write is refused"
    );
    b.save_image(4, 'a', &grey(4)).expect("b saves 4");
    drop(a);
    drop(b);
    // Every image on disk is recorded, and check finds nothing unrecorded.
    let s = Session::inspect(&tmp.path().join("tw")).expect("inspect");
    let recorded: Vec<u32> = s.manifest().image.iter().map(|r| r.number).collect();
    assert_eq!(recorded, [1, 2, 4]);
    let on_disk: Vec<String> = std::fs::read_dir(s.dir())
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".img"))
        .collect();
    assert_eq!(on_disk.len(), 3, "{on_disk:?}");
    let r = s.check();
    assert!(r.is_ok() && r.warnings.is_empty(), "{r:?}");
}

/// `session check` lists a data file under the session's names that the
/// manifest does not record (it said "ok" before).
#[test]
fn check_lists_files_the_manifest_does_not_record() {
    let tmp = tempfile::tempdir().expect("tmp");
    write_profile(tmp.path());
    let (ok, out) = grab(tmp.path(), "1", "1", "a");
    assert!(ok, "{out}");
    let dir = tmp.path().join("s/g");
    std::fs::copy(dir.join("g1a.img"), dir.join("g2b.img")).expect("plant");
    std::fs::write(dir.join("notes.txt"), "not a VSS name").expect("plant");
    let (ok, out) = vss(tmp.path(), &["session", "check", "s/g"]);
    assert!(ok, "{out}");
    assert!(
        out.contains("g2b.img") && out.contains("does not record"),
        "{out}"
    );
    assert!(!out.contains("notes.txt"), "{out}");
    let (ok, out) = vss(tmp.path(), &["session", "check", "--strict", "s/g"]);
    assert!(!ok, "{out}");
}

/// Issue 34, N14: a session whose files' paths would exceed PATH_MAX is
/// refused before anything is made (it was made, then "no manifest").
#[test]
fn a_session_path_beyond_path_max_is_refused_up_front() {
    use vss::session::{Session, SessionError};
    let tmp = tempfile::tempdir().expect("tmp");
    // Folders of 200 bytes, down to about 4000 bytes of path: still a path
    // the system takes, but not with the session's names under it.
    let mut deep = tmp.path().to_path_buf();
    while deep.as_os_str().len() < 3900 {
        deep = deep.join("d".repeat(200));
    }
    std::fs::create_dir_all(&deep).expect("deep folders");
    let name = "s".repeat(32);
    let e = Session::create(&deep, &name, &cell_profile(32, 32)).expect_err("too long");
    assert!(matches!(e, SessionError::PathTooLong { .. }), "{e:?}");
    assert!(e.to_string().contains("shorter path"), "{e}");
    assert!(!deep.join(&name).exists(), "the session folder was made");
}

/// Issue 34, N9: a save whose record cannot be written (a full disk fails
/// there: the image went, the manifest did not; here the manifest's name is
/// taken by a folder) leaves no image the manifest does not record, and
/// keeps the recorded image it would have replaced.
#[test]
fn a_save_that_cannot_be_recorded_leaves_the_folder_as_it_was() {
    use vss::formats::img::{ImgFile, encode_img};
    use vss::llv::GreyImage;
    use vss::session::Session;
    let tmp = tempfile::tempdir().expect("tmp");
    let grey = |v: u8| ImgFile::new(GreyImage::filled(16, 16, v).expect("image"));
    let mut s = Session::create(tmp.path(), "fd", &cell_profile(32, 32)).expect("create");
    s.save_image(1, 'a', &grey(1)).expect("save 1");
    let dir = s.dir().to_path_buf();
    std::fs::remove_file(dir.join("fd.toml")).expect("manifest");
    std::fs::create_dir(dir.join("fd.toml")).expect("a folder in its place");
    let e = s
        .save_image(2, 'a', &grey(2))
        .expect_err("recorded nowhere");
    assert!(e.to_string().contains("fd.toml"), "{e}");
    assert!(
        !dir.join("fd2a.img").exists(),
        "an unrecorded image is left"
    );
    let e = s
        .save_image(1, 'a', &grey(9))
        .expect_err("recorded nowhere");
    assert!(e.to_string().contains("fd.toml"), "{e}");
    assert_eq!(
        std::fs::read(dir.join("fd1a.img")).expect("image 1"),
        encode_img(&grey(1)).expect("bytes"),
        "the recorded image was replaced"
    );
    let left: Vec<String> = std::fs::read_dir(&dir)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Issue 34, N9/N6: an I/O error is told once ("(os error 28)" and the
/// profile's "more than" were printed twice: the wrapper's message and its
/// source).
#[test]
fn an_io_error_is_told_once() {
    let tmp = tempfile::tempdir().expect("tmp");
    std::fs::write(tmp.path().join("big.toml"), "#".repeat(2 << 20)).expect("profile");
    let (ok, out) = vss(tmp.path(), &["--profile", "big.toml", "lights", "status"]);
    assert!(!ok, "{out}");
    assert_eq!(out.matches("more than").count(), 1, "{out}");
}

/// Every file of session folder `dir` with its bytes, in name order.
fn files_of(dir: &Path) -> Vec<(std::ffi::OsString, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .expect("session folder")
        .map(|e| {
            let e = e.expect("entry");
            (e.file_name(), std::fs::read(e.path()).unwrap_or_default())
        })
        .collect();
    v.sort();
    v
}

/// A hand-edited manifest naming a camera its session does not have
/// (camera 9 of 4) is refused where it is read, naming the record, the
/// camera and the line, and nothing is written; it was accepted, and the
/// image's camera went to the report and to the console's next capture.
#[test]
fn a_manifest_naming_a_camera_the_session_lacks_is_refused() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    write_profile(d);
    let (ok, out) = vss(
        d,
        &["--profile", "p.toml", "session", "new", "w", "--dir", "."],
    );
    assert!(ok, "{out}");
    let m = d.join("w/w.toml");
    let good = std::fs::read_to_string(&m).expect("manifest");
    let bad = format!("{good}\n[[image]]\nnumber = 2\ncamera = 9\nlocation = 1\n");
    std::fs::write(&m, &bad).expect("edit manifest");
    let before = files_of(&d.join("w"));
    let line = bad.lines().position(|l| l == "camera = 9").expect("line") + 1;
    for args in [
        &["session", "show", "w"][..],
        &["session", "check", "w"][..],
        &[
            "--profile",
            "p.toml",
            "session",
            "redo",
            "w",
            "--image",
            "2",
        ][..],
        &["report", "w"][..],
    ] {
        let o = Command::cargo_bin("vss")
            .expect("the vss binary")
            .args(args)
            .current_dir(d)
            .timeout(Duration::from_secs(60))
            .output()
            .expect("run vss");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(&format!(
                "w.toml:{line}: [[image]] number 2: camera 9 is not one of the session's \
                 cameras, which run from 1 to 4"
            )),
            "{args:?}: {err}"
        );
        assert_eq!(
            files_of(&d.join("w")),
            before,
            "{args:?} changed the session"
        );
    }
}

/// `vss grab` into a session made with fewer cameras than the profile's
/// grabber has is refused before it records the camera: it wrote camera 3
/// into a one-camera session, whose manifest then no longer read.
#[test]
fn grab_does_not_record_a_camera_the_session_lacks() {
    let tmp = tempfile::tempdir().expect("tmp");
    let d = tmp.path();
    new_session(d);
    write_profile(d);
    let (ok, out) = vss(
        d,
        &[
            "--profile",
            "p.toml",
            "grab",
            "--session",
            "w",
            "--image",
            "2",
            "--camera",
            "3",
            "--lighting",
            "a",
        ],
    );
    assert!(!ok, "{out}");
    assert!(
        out.contains("camera 3 is not one of the session's cameras, which run from 1 to 1"),
        "{out}"
    );
    let (ok, out) = vss(d, &["session", "show", "w"]);
    assert!(ok, "the session still reads: {out}");
}
