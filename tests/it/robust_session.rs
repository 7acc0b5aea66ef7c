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

/// A simulated cell with small frames: cameras 1 to 4, lightings a to e.
fn write_profile(dir: &Path) {
    let mut p = cell_profile(64, 64);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 5;
    std::fs::write(dir.join("p.toml"), toml::to_string(&p).expect("profile")).expect("write");
}

fn grab(dir: &Path, image: &str, camera: &str, lighting: &str) -> (bool, String) {
    vss(
        dir,
        &[
            "--profile",
            "p.toml",
            "grab",
            "--session",
            "s/g",
            "--image",
            image,
            "--camera",
            camera,
            "--lighting",
            lighting,
        ],
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
