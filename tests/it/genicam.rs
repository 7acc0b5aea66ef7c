//! The `genicam` grabber against Aravis's fake GigE Vision camera
//! (`arv-fake-gv-camera-0.8`), which speaks the real protocol (GVCP and GVSP
//! over UDP) on the loopback interface: `vss grab` on it, with lost packets,
//! with the camera killed mid-acquisition, and with no camera there.
//!
//! Every test starts its own fake camera, with its own serial number, and
//! kills it after. The fake camera listens on 127.0.0.1 port 3956 only
//! (it refuses other loopback addresses), so the tests take turns
//! ([`FakeCamera::start`] holds a lock while its camera runs).
//!
//! The fake camera draws a diagonal ramp that moves with the frame number:
//! a pixel's value depends on `x + y` alone within one frame, so a frame
//! patched from two (a lost packet filled from an older frame) shows as
//! rows whose diagonals do not continue ([`whole`]).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use assert_cmd::cargo::cargo_bin;
use vss::formats::img::read_img;
use vss::llv::GreyImage;
use vss::profile::{CameraSettings, GrabberKind, Profile};
use vss::rig::FrameGrabber;
use vss::rig::genicam::GenicamGrabber;
use vss::rig::sim::cell_profile;

static TURN: Mutex<()> = Mutex::new(());

/// A running `arv-fake-gv-camera-0.8`, killed when dropped.
pub struct FakeCamera {
    child: Option<Child>,
    serial: String,
    _turn: MutexGuard<'static, ()>,
}

/// Whether something is bound to 127.0.0.1 port 3956 (GVCP).
fn gvcp_bound() -> bool {
    std::fs::read_to_string("/proc/net/udp")
        .map(|t| t.lines().any(|l| l.contains(" 0100007F:0F74 ")))
        .unwrap_or(false)
}

impl FakeCamera {
    /// Starts a fake camera with serial number `serial`; `lost` is the
    /// GVSP lost-packet ratio per thousand.
    pub fn start(serial: &str, lost: Option<u32>) -> FakeCamera {
        let turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        let mut cam = FakeCamera {
            child: None,
            serial: serial.to_string(),
            _turn: turn,
        };
        cam.spawn(lost);
        cam
    }

    fn spawn(&mut self, lost: Option<u32>) {
        // A camera of an earlier test that is still going away.
        let deadline = Instant::now() + Duration::from_secs(5);
        while gvcp_bound() {
            assert!(Instant::now() < deadline, "127.0.0.1:3956 stays taken");
            std::thread::sleep(Duration::from_millis(20));
        }
        let mut cmd = Command::new("arv-fake-gv-camera-0.8");
        cmd.args(["-i", "127.0.0.1", "-s", &self.serial]);
        if let Some(r) = lost {
            cmd.args(["-r", &r.to_string()]);
        }
        let child = cmd
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("arv-fake-gv-camera-0.8 runs (apt-get install aravis-tools)");
        self.child = Some(child);
        let deadline = Instant::now() + Duration::from_secs(5);
        while !gvcp_bound() {
            assert!(
                Instant::now() < deadline,
                "the fake camera did not bind 127.0.0.1:3956"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Kills it (SIGKILL: a camera unplugged says nothing either).
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// Starts it again, as a camera plugged back in.
    pub fn restart(&mut self) {
        self.kill();
        self.spawn(None);
    }
}

impl Drop for FakeCamera {
    fn drop(&mut self) {
        self.kill();
    }
}

/// The simulated cell's relay board and lights, with the fake camera as
/// camera 1.
pub fn genicam_profile(settings: CameraSettings) -> Profile {
    let mut p = cell_profile(64, 64);
    p.relay.settle_ms = 5;
    p.grabber.kind = GrabberKind::Genicam;
    p.grabber.cameras = vec!["127.0.0.1".into()];
    p.grabber.camera = vec![settings];
    p.grabber.timeout_ms = 2000;
    p.survey.cameras = 1;
    p.survey.cdf.truncate(1);
    p
}

fn mono8() -> CameraSettings {
    CameraSettings {
        pixel_format: Some("Mono8".into()),
        exposure_us: Some(10_000.0),
        gain_db: Some(0.0),
        roi: None,
        packet_size: None,
    }
}

fn write_profile(dir: &Path, p: &Profile) -> PathBuf {
    let path = dir.join("genicam.toml");
    std::fs::write(&path, toml::to_string(p).expect("profile to toml")).expect("write profile");
    path
}

fn grab(profile: &Path, session: &Path, lighting: &str) -> Output {
    grab_camera(profile, session, lighting, "1")
}

fn grab_camera(profile: &Path, session: &Path, lighting: &str, camera: &str) -> Output {
    Command::new(cargo_bin("vss"))
        .arg("--profile")
        .arg(profile)
        .args([
            "grab",
            "--camera",
            camera,
            "--lighting",
            lighting,
            "--image",
            "1",
        ])
        .arg("--session")
        .arg(session)
        .output()
        .expect("vss grab runs")
}

/// Files in `dir` (none when it does not exist).
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Whether a fake-camera frame is one frame: every row continues the
/// diagonals of the row above (`p(x, y) == p(x + 1, y - 1)`).
pub fn whole(img: &GreyImage) -> Result<(), String> {
    let (w, h) = img.size();
    let d = img.data();
    for y in 1..h {
        for x in 0..w - 1 {
            let (a, b) = (d[y * w + x], d[(y - 1) * w + x + 1]);
            if a != b {
                return Err(format!("row {y} breaks the ramp at x {x}: {a} vs {b}"));
            }
        }
    }
    Ok(())
}

#[test]
fn the_fake_camera_draws_a_ramp_that_whole_can_check() {
    // `whole` must be able to fail: a frame patched from two.
    let ramp = |shift: usize| -> Vec<u8> {
        (0..64 * 64)
            .map(|i| ((i % 64 + i / 64 + shift) % 255) as u8)
            .collect()
    };
    let a = GreyImage::new(64, 64, ramp(0)).expect("image");
    assert!(whole(&a).is_ok());
    let mut patched = ramp(0);
    patched[20 * 64..25 * 64].copy_from_slice(&ramp(7)[20 * 64..25 * 64]);
    let b = GreyImage::new(64, 64, patched).expect("image");
    assert!(whole(&b).is_err());
}

#[test]
fn grab_saves_whole_frames_from_the_fake_camera() {
    let _cam = FakeCamera::start("GRAB1", None);
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), &genicam_profile(mono8()));
    let session = tmp.path().join("s/gen");
    let out = grab(&prof, &session, "a,b,c,d,e");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stderr}");
    let names: Vec<String> = "abcde".chars().map(|l| format!("gen1{l}.img")).collect();
    for n in &names {
        let f = read_img(&session.join(n)).expect("a saved frame reads");
        assert_eq!(f.image.size(), (512, 512), "{n}");
        whole(&f.image).unwrap_or_else(|e| panic!("{n}: {e}"));
        let crc = format!("crc {:08X}", vss::rig::protocol::crc32(f.image.data()));
        assert!(stdout.contains(&crc), "{n}: {crc} in {stdout}");
    }
    assert!(stdout.contains("lighting b (right-front)"), "{stdout}");
    let sess = vss::session::Session::inspect(&session).expect("grab made a session");
    let rec = sess.manifest().image(1).expect("image 1 recorded");
    assert_eq!(rec.camera, 1);
    // Each frame's record keeps the camera's exposure and gain.
    assert_eq!(rec.grey.len(), 5);
    for g in &rec.grey {
        assert_eq!(
            (g.exposure_us, g.gain_db),
            (Some(10_000.0), Some(0.0)),
            "{}",
            g.file
        );
    }
}

/// The fake camera offers BayerBG8, BayerGB8, BayerGR8, BayerRG8, Mono8,
/// RGB8 and Mono16; vss reads Mono8 and Mono16 of those. A profile that
/// asks for a format the camera lacks, and a camera left set to one vss
/// cannot reduce to 8 bits, are refused before any frame: the message
/// names the camera and the formats it offers that vss can use, and no
/// session is made.
#[test]
fn a_pixel_format_the_cell_cannot_use_is_named_and_nothing_is_saved() {
    use aravis::prelude::*;
    let _cam = FakeCamera::start("PIXFMT1", None);
    let tmp = tempfile::tempdir().expect("tmp");
    let session = tmp.path().join("s/gen");
    let refused = |p: &Profile, what: &str| {
        let out = grab(&write_profile(tmp.path(), p), &session, "a,b");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{what}: {err}");
        for part in [
            "camera 1 (127.0.0.1): the Aravis ",
            "#PIXFMT1",
            what,
            "of the formats vss can use it offers Mono8, Mono16: set pixel_format in \
             [[grabber.camera]] entry 1 to one of them",
            "nothing was grabbed",
        ] {
            assert!(err.contains(part), "{part:?} in {err}");
        }
        assert!(!session.exists(), "no session made: {:?}", files(&session));
    };
    // Mono12 passes the profile's check (vss reads it) but this camera has
    // none.
    let mono12 = genicam_profile(CameraSettings {
        pixel_format: Some("Mono12".into()),
        ..mono8()
    });
    refused(&mono12, "has no pixel format Mono12");
    // Left at Bayer by another program; the profile keeps the camera's own.
    let camera = aravis::Camera::new(Some("127.0.0.1")).expect("the fake camera opens");
    camera
        .set_pixel_format_from_string("BayerRG8")
        .expect("the fake camera takes BayerRG8");
    drop(camera);
    let own = genicam_profile(CameraSettings {
        pixel_format: None,
        ..mono8()
    });
    refused(
        &own,
        "is set to BayerRG8 pixels, which vss cannot reduce to 8-bit grey",
    );
    // Camera 2 of a cell is checked before the session is made too (it is
    // opened only when first used).
    let mut two = genicam_profile(mono8());
    // The same fake camera by its device id (a second entry may not
    // repeat the address).
    two.grabber.cameras.push("Aravis-Fake-PIXFMT1".into());
    two.grabber.camera.push(CameraSettings {
        pixel_format: Some("Mono12".into()),
        ..mono8()
    });
    two.survey.cameras = 2;
    let out = grab_camera(&write_profile(tmp.path(), &two), &session, "a", "2");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("camera 2 (Aravis-Fake-PIXFMT1): "), "{err}");
    assert!(err.contains("has no pixel format Mono12"), "{err}");
    assert!(!session.exists(), "no session made: {:?}", files(&session));
    // Set to one it offers, the same camera grabs.
    let out = grab(
        &write_profile(tmp.path(), &genicam_profile(mono8())),
        &session,
        "a",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn deeper_pixels_are_reduced_to_eight_bits_and_a_region_is_kept() {
    let _cam = FakeCamera::start("GRAB16", None);
    let p = genicam_profile(CameraSettings {
        pixel_format: Some("Mono16".into()),
        roi: Some([0, 0, 256, 128]),
        ..mono8()
    });
    let mut g = GenicamGrabber::open(&p.grabber).expect("the fake camera opens");
    let st = g.camera_state().expect("the camera says what it is");
    assert_eq!(st.pixel_format, "Mono16");
    assert_eq!(st.serial, "GRAB16");
    assert_eq!(st.roi, [0, 0, 256, 128]);
    let f = g.freeze().expect("a Mono16 frame");
    assert_eq!((f.width, f.height), (256, 128));
    let img = g.transfer(&mut |_, _| true).expect("the frozen frame");
    assert_eq!(vss::rig::protocol::crc32(img.data()), f.crc);
    whole(&img).expect("one frame");
    // The fake camera's Mono16 ramp is its Mono8 ramp in the top byte (the
    // reduction keeps the top eight bits): the values span the 8-bit range.
    let (lo, hi) = img
        .data()
        .iter()
        .fold((255u8, 0u8), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    assert!(lo < 10 && hi > 240, "8-bit range {lo}..{hi}");
}

/// `n` freezes on `g`: (frames whole, freezes refused). Every frame kept is
/// one whole frame; every refusal names the camera and keeps nothing.
fn freezes(g: &mut GenicamGrabber, n: usize) -> (usize, usize) {
    let (mut ok, mut refused) = (0, 0);
    for _ in 0..n {
        match g.freeze() {
            Ok(f) => {
                let img = g.transfer(&mut |_, _| true).expect("the frozen frame");
                assert_eq!(vss::rig::protocol::crc32(img.data()), f.crc);
                whole(&img).expect("a kept frame is one whole frame");
                ok += 1;
            }
            Err(e) => {
                let m = e.to_string();
                assert!(
                    m.starts_with("camera 1 (127.0.0.1): ")
                        && m.contains("came incomplete")
                        && m.contains("nothing was saved"),
                    "{m}"
                );
                assert!(!e.is_vanished(), "a lossy camera is still there: {m}");
                assert!(g.frame().is_none(), "no frame is kept after {m}");
                refused += 1;
            }
        }
    }
    (ok, refused)
}

#[test]
fn lost_packets_never_give_a_patched_frame() {
    // 1 % of the stream's packets are dropped by the camera, which does not
    // answer resend requests: whole frames come only from re-triggering.
    let _cam = FakeCamera::start("LOSS1", Some(10));
    // Its own 1400-byte packets: ~190 a frame, most frames lose one.
    let p = genicam_profile(mono8());
    let mut g = GenicamGrabber::open(&p.grabber).expect("the fake camera opens");
    let (ok, refused) = freezes(&mut g, 20);
    let bad = g.wire_stats().bad_blocks;
    eprintln!(
        "1 % lost, 1400-byte packets: {ok} of 20 freezes whole, {refused} refused, {bad} incomplete frames re-triggered"
    );
    assert!(ok > 0 && bad > 0, "{ok} whole, {bad} incomplete");
    // 16 kB packets (jumbo frames, as on loopback): ~18 a frame.
    let p = genicam_profile(CameraSettings {
        packet_size: Some(16_000),
        ..mono8()
    });
    drop(g);
    let mut g = GenicamGrabber::open(&p.grabber).expect("the fake camera opens");
    let (ok, refused) = freezes(&mut g, 20);
    let bad = g.wire_stats().bad_blocks;
    eprintln!(
        "1 % lost, 16000-byte packets: {ok} of 20 freezes whole, {refused} refused, {bad} incomplete frames re-triggered"
    );
    assert!(ok >= 18, "{ok} of 20 freezes whole");
}

#[test]
fn a_camera_killed_mid_acquisition_is_said_and_comes_back() {
    let mut cam = FakeCamera::start("KILL1", None);
    let p = genicam_profile(mono8());
    let mut g = GenicamGrabber::open(&p.grabber).expect("the fake camera opens");
    g.freeze().expect("a frame before the camera goes");
    cam.kill();
    let t = Instant::now();
    let e = g.freeze().expect_err("no frame from a killed camera");
    let m = e.to_string();
    assert!(e.is_vanished(), "the console reconnects on {m}");
    assert!(m.starts_with("camera 1 (127.0.0.1): "), "{m}");
    assert!(m.contains("Nothing was saved"), "{m}");
    assert!(g.frame().is_none(), "no frame kept");
    assert!(g.transfer(&mut |_, _| true).is_err(), "nothing to transfer");
    assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
    assert!(g.reconnect().is_err(), "not back yet");
    cam.restart();
    g.reconnect().expect("the camera is back");
    g.freeze().expect("frames again after reconnecting");
}

#[test]
fn grab_stops_when_the_camera_is_killed_and_keeps_what_was_saved() {
    let mut cam = FakeCamera::start("KILL2", None);
    let tmp = tempfile::tempdir().expect("tmp");
    let mut p = genicam_profile(mono8());
    p.relay.settle_ms = 400;
    let prof = write_profile(tmp.path(), &p);
    let session = tmp.path().join("s/gen");
    let child = Command::new(cargo_bin("vss"))
        .arg("--profile")
        .arg(&prof)
        .args(["grab", "--camera", "1", "--lighting", "a,b,c,d,e"])
        .args(["--image", "1", "--session"])
        .arg(&session)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("vss grab starts");
    // Kill the camera once the first frame is saved.
    let deadline = Instant::now() + Duration::from_secs(20);
    while !session.join("gen1a.img").exists() {
        assert!(Instant::now() < deadline, "no first frame");
        std::thread::sleep(Duration::from_millis(10));
    }
    cam.kill();
    let out = child.wait_with_output().expect("vss grab ends");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("camera 1 (127.0.0.1)"), "{err}");
    assert!(err.contains("nothing of it was saved"), "{err}");
    let saved: Vec<String> = files(&session)
        .into_iter()
        .filter(|n| n.ends_with(".img") || n.contains(".tmp"))
        .collect();
    assert!(
        !saved.is_empty() && saved.len() < 5 && saved.iter().all(|n| n.ends_with(".img")),
        "the frames before the kill are kept, no later one, no temporary file: {saved:?}"
    );
    for n in &saved {
        whole(&read_img(&session.join(n)).expect("reads").image).expect("whole");
    }
}

#[test]
fn a_camera_that_is_not_there_is_named_and_nothing_is_made() {
    let _turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
    assert!(!gvcp_bound(), "no camera runs");
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), &genicam_profile(mono8()));
    let session = tmp.path().join("s/gen");
    let t = Instant::now();
    let out = grab(&prof, &session, "a");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("camera 1 (127.0.0.1): not found"), "{err}");
    assert!(err.contains("[grabber] cameras"), "{err}");
    assert!(!session.exists(), "no session made: {:?}", files(&session));
    assert!(t.elapsed() < Duration::from_secs(15), "{:?}", t.elapsed());
}

#[test]
fn trigger_to_saved_img_within_two_frame_times() {
    let _cam = FakeCamera::start("TIME1", None);
    let tmp = tempfile::tempdir().expect("tmp");
    let mut p = genicam_profile(mono8());
    p.relay.settle_ms = 0;
    let mut cell = vss::rig::Cell::open(&p).expect("the cell opens");
    let st = cell.grabber.camera_state().expect("the camera's state");
    let frame = Duration::from_secs_f64(1.0 / st.frame_rate_hz);
    let mut sess = vss::session::Session::create(tmp.path(), "t", &p).expect("a session");
    let mut times = Vec::new();
    for k in 1..=4 {
        for l in ['a', 'b', 'c', 'd', 'e'] {
            let t = Instant::now();
            let cap = cell.capture(1, l, &mut |_, _| true).expect("a frame");
            let img = vss::formats::img::ImgFile::new(cap.image).with_comment(format!("t{k}{l}"));
            sess.save_image(k, l, &img).expect("saved");
            times.push(t.elapsed());
        }
    }
    times.sort();
    let (median, max) = (times[times.len() / 2], times[times.len() - 1]);
    eprintln!(
        "trigger to saved .img (512 x 512 Mono8, settle 0): median {:.1} ms, max {:.1} ms; \
         the camera's frame time {:.1} ms ({:.1} frames/s)",
        median.as_secs_f64() * 1e3,
        max.as_secs_f64() * 1e3,
        frame.as_secs_f64() * 1e3,
        st.frame_rate_hz
    );
    assert!(
        median <= 2 * frame,
        "median {median:?} vs frame time {frame:?}"
    );
}
