//! `vss sim`, `vss grab` and `vss lights` as a person runs them: the
//! simulator in its own process on pseudo-terminals, grab and lights
//! talking to it through the profile's ports; failed captures leave no
//! image (and no temporary file) behind.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::vss;
use assert_cmd::cargo::cargo_bin;
use vss::formats::img::read_img;
use vss::profile::{GrabberKind, Profile, RelayKind};
use vss::rig::sim::cell_profile;

fn base() -> Profile {
    let mut p = cell_profile(128, 128);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 5;
    p
}

fn write_profile(dir: &Path, name: &str, p: &Profile) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, toml::to_string(p).expect("profile to toml")).expect("write profile");
    path
}

/// `vss sim` in the background, and the two device paths it printed.
struct SimProcess {
    child: Child,
    grabber: String,
    relay: String,
}

impl SimProcess {
    fn start(profile: &Path) -> SimProcess {
        Self::start_with(profile, &[])
    }

    fn start_with(profile: &Path, args: &[&str]) -> SimProcess {
        let mut child = vss()
            .arg("--profile")
            .arg(profile)
            .arg("sim")
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start vss sim");
        let out = child.stdout.take().expect("stdout");
        let mut lines = BufReader::new(out).lines();
        let mut next = || lines.next().and_then(Result::ok).unwrap_or_default();
        let grabber = next().strip_prefix("grabber: ").map(str::to_string);
        let relay = next().strip_prefix("relay: ").map(str::to_string);
        let summary = next();
        assert!(summary.starts_with("simulated cell:"), "{summary}");
        SimProcess {
            child,
            grabber: grabber.expect("grabber path"),
            relay: relay.expect("relay path"),
        }
    }

    /// SIGTERM ends it cleanly.
    fn stop(mut self) {
        let pid = self.child.id().to_string();
        let ok = Command::new("kill").args(["-TERM", &pid]).status();
        assert!(ok.is_ok_and(|s| s.success()));
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            if let Ok(Some(st)) = self.child.try_wait() {
                assert!(st.success(), "vss sim exits 0 on SIGTERM: {st}");
                return;
            }
            assert!(Instant::now() < deadline, "vss sim did not stop on SIGTERM");
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for SimProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn imgs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".img"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn grab_and_lights_against_vss_sim() {
    let tmp = tempfile::tempdir().expect("tmp");
    let sim_profile = write_profile(tmp.path(), "sim.toml", &base());
    let sim = SimProcess::start(&sim_profile);
    let mut p = base();
    p.grabber.kind = GrabberKind::Vsg;
    p.grabber.port = sim.grabber.clone();
    p.relay.kind = RelayKind::Numato;
    p.relay.port = sim.relay.clone();
    let prof = write_profile(tmp.path(), "cell.toml", &p);
    let session = tmp.path().join("s/cube");

    let out = vss()
        .arg("--profile")
        .arg(&prof)
        .args([
            "grab",
            "--camera",
            "2",
            "--lighting",
            "a,b,e",
            "--image",
            "3",
            "--session",
        ])
        .arg(&session)
        .output()
        .expect("run grab");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("cube3a: 16384/16384 bytes (100%)"),
        "progress: {err}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("lighting b (right-front)"), "{stdout}");
    assert_eq!(imgs(&session), ["cube3a.img", "cube3b.img", "cube3e.img"]);
    let a = read_img(&session.join("cube3a.img")).expect("cube3a.img reads");
    assert_eq!(a.image.size(), (128, 128));
    assert_eq!(a.comment, "cube3a");
    let e = read_img(&session.join("cube3e.img")).expect("cube3e.img reads");
    assert!(a.image != e.image, "lighting changes the image");
    // The frames are the session's: in its manifest, and the session checks.
    let sess = vss::session::Session::inspect(&session).expect("grab made a session");
    let letters: Vec<char> = sess
        .load_images(3)
        .expect("the manifest's images read")
        .into_iter()
        .map(|(l, _)| l)
        .collect();
    assert_eq!(letters, ['a', 'b', 'e']);
    assert_eq!(sess.manifest().image(3).map(|r| r.camera), Some(2));
    // The serial grabber says nothing of exposure or gain: none recorded.
    let text = std::fs::read_to_string(session.join("cube.toml")).expect("manifest");
    assert!(
        !text.contains("exposure_us") && !text.contains("gain_db"),
        "{text}"
    );
    let check = vss()
        .args(["session", "check"])
        .arg(&session)
        .output()
        .expect("vss session check runs");
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stdout)
    );

    // Existing images are not overwritten without --yes.
    let again = vss()
        .arg("--profile")
        .arg(&prof)
        .args([
            "grab",
            "--camera",
            "1",
            "--lighting",
            "a",
            "--image",
            "3",
            "--session",
        ])
        .arg(&session)
        .output()
        .expect("run grab");
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--yes"));
    assert!(read_img(&session.join("cube3a.img")).expect("kept").image == a.image);

    // Lights: set a configuration, read it back, switch off.
    let lights = |args: &[&str]| {
        let o = vss()
            .arg("--profile")
            .arg(&prof)
            .arg("lights")
            .args(args)
            .output()
            .expect("lights");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    assert!(lights(&["set", "c"]).contains("relays 0004; on: left-back"));
    assert!(lights(&["status"]).contains("on: left-back"));
    assert!(lights(&["on"]).contains("relays 000f"));
    assert!(lights(&["off"]).contains("on: none"));
    sim.stop();
}

fn grab_embedded(profile: &Path, session: &Path, faults: Option<&str>) -> std::process::Output {
    let mut c = vss();
    c.arg("--profile").arg(profile).args([
        "grab",
        "--camera",
        "3",
        "--lighting",
        "a,b,c,e",
        "--image",
        "1",
        "--yes",
        "--session",
    ]);
    c.arg(session);
    if let Some(f) = faults {
        c.args(["--sim-faults", f]);
    }
    c.output().expect("run grab")
}

#[test]
fn faults_never_leave_a_corrupt_image_on_disk() {
    let tmp = tempfile::tempdir().expect("tmp");
    let mut p = base();
    p.grabber.block = 4096;
    p.grabber.timeout_ms = 400;
    let prof = write_profile(tmp.path(), "p.toml", &p);
    let clean = tmp.path().join("clean/ref");
    let out = grab_embedded(&prof, &clean, None);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names = ["ref1a.img", "ref1b.img", "ref1c.img", "ref1e.img"];
    let want: Vec<_> = names
        .iter()
        .map(|n| read_img(&clean.join(n)).expect("clean image").image)
        .collect();

    for (i, faults) in [
        "drop=1e-3,seed=4",
        "corrupt=1e-3,seed=4",
        "reset",
        "garbage=500",
    ]
    .iter()
    .enumerate()
    {
        let dir = tmp.path().join(format!("f{i}/ref"));
        let out = grab_embedded(&prof, &dir, Some(faults));
        assert!(
            out.status.success(),
            "{faults}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        for (n, w) in names.iter().zip(&want) {
            let got = read_img(&dir.join(n)).expect("image");
            assert!(
                got.image == *w,
                "{faults}: {n} differs from the clean capture"
            );
        }
        assert_eq!(imgs(&dir), names, "{faults}: no stray files");
    }

    // Unplugged during the third frame: the first two are kept, the third
    // is not written at all, and the error names the port.
    let dir = tmp.path().join("unplug/ref");
    let out = grab_embedded(&prof, &dir, Some("unplug-after=40000"));
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("ref1c") && err.contains("vanished") && err.contains("/dev/pts/"),
        "{err}"
    );
    assert_eq!(imgs(&dir), ["ref1a.img", "ref1b.img"]);
    for (n, w) in names.iter().zip(&want).take(2) {
        assert!(read_img(&dir.join(n)).expect("kept").image == *w);
    }
}

#[test]
fn grab_checks_camera_and_lightings_before_the_first_frame() {
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), "p.toml", &base());
    let session = tmp.path().join("s/chk");
    let run = |camera: &str, lighting: &str| {
        vss()
            .arg("--profile")
            .arg(&prof)
            .args([
                "grab",
                "--camera",
                camera,
                "--lighting",
                lighting,
                "--image",
                "2",
                "--session",
            ])
            .arg(&session)
            .output()
            .expect("run grab")
    };
    let out = run("5", "a");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cameras 1 to 4"));
    let out = run("1", "a,q");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no lighting configuration `q`"), "{err}");
    assert!(
        imgs(&session).is_empty(),
        "nothing captured: {:?}",
        imgs(&session)
    );
}

#[test]
fn grab_refuses_a_bad_session_name() {
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), "p.toml", &base());
    let out = grab_embedded(&prof, &tmp.path().join("bad name!"), None);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("session name"));
    assert!(!tmp.path().join("bad name!").exists());
}

#[test]
fn ctrl_c_cancels_a_transfer_and_saves_nothing_of_it() {
    let tmp = tempfile::tempdir().expect("tmp");
    let mut p = base();
    p.grabber.block = 4096;
    let prof = write_profile(tmp.path(), "p.toml", &p);
    let session = tmp.path().join("s/can");
    // The stall holds the first frame mid-transfer long enough to press Ctrl-C.
    let mut child = vss()
        .arg("--profile")
        .arg(&prof)
        .args([
            "grab",
            "--camera",
            "1",
            "--lighting",
            "a,b",
            "--image",
            "1",
            "--session",
        ])
        .arg(&session)
        .args(["--sim-faults", "stall=3s"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start grab");
    // Ctrl-C once the transfer is under way: the progress on stderr shows
    // bytes received (the stall comes after the first block).
    let stderr = std::sync::Arc::new(std::sync::Mutex::new(Vec::<u8>::new()));
    let reader = {
        let (buf, mut e) = (stderr.clone(), child.stderr.take().expect("stderr"));
        std::thread::spawn(move || {
            let mut chunk = [0u8; 4096];
            while let Ok(n) = std::io::Read::read(&mut e, &mut chunk) {
                if n == 0 {
                    break;
                }
                buf.lock().unwrap().extend_from_slice(&chunk[..n]);
            }
        })
    };
    let under_way = |text: &str| {
        text.split('\r').any(|row| {
            row.split_once(": ")
                .and_then(|(_, rest)| rest.split('/').next()?.parse::<u64>().ok())
                .is_some_and(|done| done > 0)
        })
    };
    let deadline = Instant::now() + Duration::from_secs(10);
    while !under_way(&String::from_utf8_lossy(&stderr.lock().unwrap())) {
        assert!(
            Instant::now() < deadline,
            "no transfer under way after 10 s: {}",
            String::from_utf8_lossy(&stderr.lock().unwrap())
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .is_ok_and(|s| s.success())
    );
    let t = Instant::now();
    let status = loop {
        if let Ok(Some(st)) = child.try_wait() {
            break st;
        }
        assert!(
            t.elapsed() < Duration::from_secs(10),
            "grab did not end after Ctrl-C"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    reader.join().expect("the stderr reader");
    let err = String::from_utf8_lossy(&stderr.lock().unwrap()).into_owned();
    assert!(!status.success());
    assert!(
        err.contains("cancelled") && err.contains("nothing"),
        "{err}"
    );
    assert!(imgs(&session).is_empty(), "{:?}", imgs(&session));
}

#[test]
fn a_grabber_pulled_and_plugged_back_is_found_under_its_name() {
    let tmp = tempfile::tempdir().expect("tmp");
    let sim_profile = write_profile(tmp.path(), "sim.toml", &base());
    let link = tmp.path().join("ttyVSG0");
    let link_s = link.to_string_lossy().into_owned();
    let sim = SimProcess::start_with(
        &sim_profile,
        &[
            "--faults",
            "unplug-after=20000",
            "--link",
            &link_s,
            "--replug-after",
            "0.3",
        ],
    );
    let mut p = base();
    p.grabber.kind = GrabberKind::Vsg;
    p.grabber.port = link_s.clone();
    p.relay.kind = RelayKind::Numato;
    p.relay.port = sim.relay.clone();
    let prof = write_profile(tmp.path(), "cell.toml", &p);
    let session = tmp.path().join("s/plug");
    let grab = |letters: &str| {
        vss()
            .arg("--profile")
            .arg(&prof)
            .args([
                "grab",
                "--camera",
                "1",
                "--lighting",
                letters,
                "--image",
                "1",
                "--session",
            ])
            .arg(&session)
            .output()
            .expect("run grab")
    };
    // The cable is pulled during the second frame: the first is kept.
    let out = grab("a,b");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&link_s) && err.contains("vanished"), "{err}");
    assert_eq!(imgs(&session), ["plug1a.img"]);
    // Back under the same name: the same profile works again.
    let deadline = Instant::now() + Duration::from_secs(10);
    while !link.exists() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = grab("b");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(imgs(&session), ["plug1a.img", "plug1b.img"]);
    sim.stop();
}

/// Started with nobody reading its report (`vss sim --link P | true`),
/// the simulator still serves: it printed "Broken pipe" and ended before.
#[test]
fn a_simulator_whose_reader_has_gone_still_serves() {
    let tmp = tempfile::tempdir().expect("tmp");
    let sim_profile = write_profile(tmp.path(), "sim.toml", &base());
    let link = tmp.path().join("ttyVSG0");
    let mut child = vss()
        .arg("--profile")
        .arg(&sim_profile)
        .arg("sim")
        .arg("--link")
        .arg(&link)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start vss sim");
    drop(child.stdout.take());
    let deadline = Instant::now() + Duration::from_secs(10);
    while !link.exists() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    let sim = SimProcess {
        child,
        grabber: link.to_string_lossy().into_owned(),
        relay: String::new(),
    };
    let mut p = base();
    p.grabber.kind = GrabberKind::Vsg;
    p.grabber.port = sim.grabber.clone();
    let prof = write_profile(tmp.path(), "cell.toml", &p);
    let session = tmp.path().join("s/gone");
    let out = grab_one(&prof, &session, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(imgs(&session), ["gone1a.img"]);
    sim.stop();
}

/// Starts `vss grab` with a long stall, waits until its transfer has begun
/// (progress on stderr) and SIGKILLs it: the session's lock stays behind.
/// The grab waits 30 s for each READ of the stall (its profile beside
/// `prof`), so it is still there when the kill comes on a loaded machine:
/// with the cell's short timeout it gave up, and released the lock, first.
fn kill_mid_grab(prof: &Path, session: &Path) {
    let mut p = base();
    p.grabber.timeout_ms = 30_000;
    // Four blocks a frame: the stall comes after the first.
    p.grabber.block = 4096;
    let dir = prof.parent().expect("the profile's folder");
    let stalled = write_profile(dir, "stalled.toml", &p);
    let (mut child, _, _) = start_stalled_grab(&stalled, session);
    child.kill().expect("SIGKILL");
    child.wait().expect("wait");
    let name = session.file_name().expect("name").to_string_lossy();
    assert!(
        session.join(format!("{name}.lock")).exists(),
        "the lock stayed"
    );
}

/// Starts `vss grab --image 1` of camera 1, lighting a, whose grabber
/// stalls for 60 s after the frame's first block, and returns once the
/// transfer has begun (progress on stderr): the child, its stderr and what
/// it has said so far.
fn start_stalled_grab(
    prof: &Path,
    session: &Path,
) -> (std::process::Child, std::process::ChildStderr, Vec<u8>) {
    use std::io::Read;
    let mut child = vss()
        .arg("--profile")
        .arg(prof)
        .args(["grab", "--camera", "1", "--lighting", "a", "--image", "1"])
        .args(["--yes", "--sim-faults", "stall=60s", "--session"])
        .arg(session)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start grab");
    let mut err = child.stderr.take().expect("stderr");
    let mut seen = Vec::new();
    let mut buf = [0u8; 256];
    let deadline = Instant::now() + Duration::from_secs(60);
    while !String::from_utf8_lossy(&seen).contains("bytes (") {
        assert!(Instant::now() < deadline, "no progress from grab");
        match err.read(&mut buf) {
            Ok(0) | Err(_) => panic!("grab ended early: {}", String::from_utf8_lossy(&seen)),
            Ok(n) => seen.extend_from_slice(&buf[..n]),
        }
    }
    // A frame of one block would end before the stall, and the grab with
    // it, racing whatever the test does next.
    assert!(
        !String::from_utf8_lossy(&seen).contains("(100%)"),
        "the frame ended before the stall (the profile's frame is one block): {}",
        String::from_utf8_lossy(&seen)
    );
    (child, err, seen)
}

fn grab_one(prof: &Path, session: &Path, extra: &[&str]) -> std::process::Output {
    vss()
        .arg("--profile")
        .arg(prof)
        .args([
            "grab",
            "--camera",
            "1",
            "--lighting",
            "a",
            "--image",
            "1",
            "--yes",
        ])
        .args(extra)
        .arg("--session")
        .arg(session)
        .stdin(Stdio::null())
        .output()
        .expect("run grab")
}

#[test]
fn a_killed_grab_leaves_a_lock_the_next_grab_can_take_over() {
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), "p.toml", &base());
    let session = tmp.path().join("s/kill");
    kill_mid_grab(&prof, &session);
    // Without a terminal and without the flag: refused, saying what to do.
    let out = grab_one(&prof, &session, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a stale lock was ignored");
    assert!(err.contains("gone") && err.contains("--take-over"), "{err}");
    // With it: taken over and captured.
    let out = grab_one(&prof, &session, &["--take-over"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(imgs(&session), ["kill1a.img"]);
    assert!(
        !session.join("kill.lock").exists(),
        "released after the grab"
    );
}

#[test]
fn a_terminal_is_asked_before_a_stale_lock_is_taken_over() {
    use portable_pty::{CommandBuilder, PtySize, native_pty_system};
    use std::io::{Read, Write};
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), "p.toml", &base());
    let session = tmp.path().join("s/ask");
    kill_mid_grab(&prof, &session);
    let pair = native_pty_system()
        .openpty(PtySize {
            rows: 24,
            cols: 80,
            pixel_width: 0,
            pixel_height: 0,
        })
        .expect("pty");
    let mut cmd = CommandBuilder::new(cargo_bin("vss"));
    cmd.arg("--profile");
    cmd.arg(&prof);
    cmd.args(["grab", "--camera", "1", "--lighting", "a", "--image", "1"]);
    cmd.args(["--yes", "--session"]);
    cmd.arg(&session);
    let mut child = pair.slave.spawn_command(cmd).expect("spawn");
    drop(pair.slave);
    let mut reader = pair.master.try_clone_reader().expect("reader");
    let mut writer = pair.master.take_writer().expect("writer");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut buf = [0u8; 1024];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 || tx.send(buf[..n].to_vec()).is_err() {
                break;
            }
        }
    });
    let mut screen = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(60);
    while !String::from_utf8_lossy(&screen).contains("[y/N]") {
        assert!(
            Instant::now() < deadline,
            "no question: {}",
            String::from_utf8_lossy(&screen)
        );
        if let Ok(b) = rx.recv_timeout(Duration::from_millis(100)) {
            screen.extend_from_slice(&b);
        }
    }
    writer.write_all(b"y\r").expect("answer");
    let status = loop {
        if let Ok(Some(st)) = child.try_wait() {
            break st;
        }
        assert!(Instant::now() < deadline, "grab did not finish");
        while let Ok(b) = rx.try_recv() {
            screen.extend_from_slice(&b);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let text = String::from_utf8_lossy(&screen).into_owned();
    assert!(status.success(), "{text}");
    assert!(text.contains("took over"), "{text}");
    assert_eq!(imgs(&session), ["ask1a.img"]);
}

/// Issue 34: a grab holding its session, asked to leave by a second grab
/// with `--take-over` (through `NAME.lock.leave`, checked every 0.2 s of a
/// transfer), stops the frame under way, saves nothing of it, releases the
/// lock and exits non-zero naming who took the session; the second grab
/// captures, and the manifest checks out.
#[test]
fn a_grab_asked_to_leave_by_a_take_over_stops_and_says_so() {
    use std::io::Read;
    let tmp = tempfile::tempdir().expect("tmp");
    // Four blocks a frame: the stall comes after the first.
    let mut p = base();
    p.grabber.block = 4096;
    let prof = write_profile(tmp.path(), "p.toml", &p);
    let session = tmp.path().join("s/leave");
    let (mut first, mut err, mut seen) = start_stalled_grab(&prof, &session);
    let pid = first.id();
    assert!(
        session.join("leave.lock").exists(),
        "the first grab holds it"
    );
    assert!(
        first.try_wait().expect("try_wait").is_none(),
        "the first grab runs"
    );
    let second = vss()
        .arg("--profile")
        .arg(&prof)
        .args(["grab", "--camera", "1", "--lighting", "a", "--image", "2"])
        .args(["--yes", "--take-over", "--session"])
        .arg(&session)
        .stdin(Stdio::null())
        .output()
        .expect("run the second grab");
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&second.stdout),
        String::from_utf8_lossy(&second.stderr)
    );
    assert!(second.status.success(), "{said}");
    assert!(said.contains(&format!("process {pid}")), "{said}");
    // The first grab has left: its stderr to the end, its exit status.
    err.read_to_end(&mut seen)
        .expect("read the first grab's stderr");
    let status = first.wait().expect("wait");
    let left = String::from_utf8_lossy(&seen);
    assert!(!status.success(), "{left}");
    assert!(
        status.code().is_some(),
        "it stopped by itself, not by a signal: {status:?} {left}"
    );
    assert!(
        left.contains("was taken over by") && left.contains("leave1a was not captured"),
        "{left}"
    );
    assert_eq!(imgs(&session), ["leave2a.img"]);
    assert!(
        !session.join("leave.lock").exists(),
        "released after the grab"
    );
    let check = vss()
        .args(["session", "check", "leave"])
        .current_dir(tmp.path().join("s"))
        .output()
        .expect("run session check");
    assert!(
        check.status.success(),
        "{}{}",
        String::from_utf8_lossy(&check.stdout),
        String::from_utf8_lossy(&check.stderr)
    );
}

#[test]
fn grab_refuses_a_lighting_named_twice() {
    // `--lighting a,a` captured lighting a twice: the second frame replaced
    // the first although the image did not exist before and --yes was not
    // given. Now refused before anything is made.
    let tmp = tempfile::tempdir().expect("tmp");
    let prof = write_profile(tmp.path(), "p.toml", &base());
    let session = tmp.path().join("s/twice");
    let out = vss()
        .arg("--profile")
        .arg(&prof)
        .args(["grab", "--camera", "1", "--lighting", "a,b,a"])
        .args(["--image", "1", "--session"])
        .arg(&session)
        .output()
        .expect("run grab");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("lighting a is named twice"), "{err}");
    assert!(!session.exists(), "nothing made: {:?}", imgs(&session));
}
