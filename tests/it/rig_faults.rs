//! The fault matrix: the simulated grabber drops and corrupts bytes, stalls,
//! is unplugged mid-frame, greets with garbage, resets mid-transfer. Every
//! run must end within its timeouts, either with the very frame a clean line
//! gives (noise is off, so frames are comparable) or with a clear error —
//! never a hang.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use vss::llv::GreyImage;
use vss::profile::Profile;
use vss::rig::protocol::crc32;
use vss::rig::sim::{Faults, cell_profile};
use vss::rig::{Capture, Cell, RigError};

fn profile() -> Profile {
    let mut p = cell_profile(128, 128);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 0;
    // Short enough that recovering from a dropped byte is quick, long
    // enough for a loaded machine.
    p.grabber.timeout_ms = 400;
    p.grabber.retries = 3;
    // Four blocks per frame, so faults can strike mid-frame.
    p.grabber.block = 4096;
    p
}

/// Runs `f` on a thread; a hang fails the test instead of blocking it.
fn within<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(limit) {
        Ok(v) => v,
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("no result within {limit:?}: a hang"),
        Err(mpsc::RecvTimeoutError::Disconnected) => panic!("the run panicked (see above)"),
    }
}

fn capture(cell: &mut Cell) -> Result<Capture, RigError> {
    cell.capture(2, 'a', &mut |_, _| true)
}

fn reference() -> GreyImage {
    let mut cell = Cell::open(&profile()).expect("clean cell");
    capture(&mut cell).expect("clean capture").image
}

/// Opens a cell with `spec` faults (which may itself fail: HELLO can be
/// garbled beyond repair) and captures once.
fn try_faulty(spec: &str) -> (Result<(Capture, Cell), RigError>, Duration) {
    let faults = Faults::parse(spec).expect("fault spec");
    within(Duration::from_secs(60), move || {
        let t = Instant::now();
        let r = Cell::open_with_faults(&profile(), faults)
            .and_then(|mut cell| capture(&mut cell).map(|c| (c, cell)));
        (r, t.elapsed())
    })
}

/// Like [`try_faulty`] for faults the cell must get through to a capture.
fn faulty(spec: &str) -> (Result<Capture, RigError>, Duration, Cell) {
    faulty_with(spec, profile())
}

fn faulty_with(spec: &str, p: Profile) -> (Result<Capture, RigError>, Duration, Cell) {
    let faults = Faults::parse(spec).expect("fault spec");
    let spec = spec.to_string();
    within(Duration::from_secs(60), move || {
        let t = Instant::now();
        let mut cell =
            Cell::open_with_faults(&p, faults).unwrap_or_else(|e| panic!("{spec}: open: {e}"));
        let r = capture(&mut cell);
        (r, t.elapsed(), cell)
    })
}

fn assert_good(spec: &str, r: &Result<Capture, RigError>, want: &GreyImage) {
    match r {
        Ok(c) => {
            assert_eq!(crc32(c.image.data()), c.frame.crc, "{spec}: CRC");
            assert!(
                c.image == *want,
                "{spec}: the frame differs from a clean line's"
            );
        }
        Err(e) => panic!("{spec}: {e}"),
    }
}

#[test]
fn drops_at_1e3_still_deliver_the_frame() {
    let want = reference();
    let (r, took, cell) = faulty("drop=1e-3,seed=11");
    assert_good("drop", &r, &want);
    assert!(cell.grabber.wire_stats().bad_blocks > 0, "faults struck");
    assert!(took < Duration::from_secs(30), "{took:?}");
}

/// A lost byte used to cost a reply timeout and a re-sync (78 s a 512²
/// frame at 1e-3). Now a block that lost bytes runs into the next answer
/// and is asked for again at once: the frame comes with no re-sync for a
/// bad block, and an inter-byte wait for only a few of the hundreds of
/// blocks that failed — and at 1e-2 still whole.
#[test]
fn a_lossy_line_costs_no_wait_per_lost_byte() {
    let mut p = cell_profile(256, 256);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 0;
    let want = {
        let mut cell = Cell::open(&p).expect("clean cell");
        capture(&mut cell).expect("clean").image
    };
    for spec in [
        "drop=1e-3,seed=3",
        "drop=1e-2,seed=4",
        "drop=1e-2,corrupt=1e-3,seed=5",
    ] {
        let (r, _, cell) = faulty_with(spec, p.clone());
        assert_good(spec, &r, &want);
        let st = cell.grabber.wire_stats();
        assert!(st.bad_blocks > 20, "{spec}: faults struck: {st:?}");
        // Re-syncs: the one on connect, one after the transfer, and one per
        // retried command (a FREEZE reply damaged on its way) — none per
        // bad block.
        assert!(
            st.resyncs <= 2 + st.retries,
            "{spec}: re-synced per bad block: {st:?}"
        );
        assert!(
            st.stalls * 10 <= st.bad_blocks,
            "{spec}: most failures should cost no wait: {st:?}"
        );
    }
}

#[test]
fn corruption_at_1e3_still_delivers_the_frame() {
    let want = reference();
    let (r, took, cell) = faulty("corrupt=1e-3,seed=12");
    assert_good("corrupt", &r, &want);
    assert!(cell.grabber.wire_stats().bad_blocks > 0, "faults struck");
    assert!(took < Duration::from_secs(30), "{took:?}");
}

#[test]
fn drops_and_corruption_together() {
    let want = reference();
    for seed in [1, 2, 3] {
        let spec = format!("drop=1e-3,corrupt=1e-3,seed={seed}");
        let (r, _, _) = faulty(&spec);
        assert_good(&spec, &r, &want);
    }
}

#[test]
fn a_two_second_stall_is_ridden_out() {
    let want = reference();
    // The profile's default reply timeout: a 2 s stall outlasts one wait
    // but not the retries.
    let mut p = profile();
    p.grabber.timeout_ms = 1000;
    let (r, took, cell) = faulty_with("stall=2s", p);
    assert_good("stall", &r, &want);
    assert!(
        took >= Duration::from_secs(1),
        "the stall happened: {took:?}"
    );
    assert!(took < Duration::from_secs(15), "{took:?}");
    assert!(cell.grabber.wire_stats().resyncs > 1);
}

#[test]
fn unplug_mid_frame_is_a_clear_error_and_reconnect_works() {
    let want = reference();
    let (r, took, mut cell) = faulty("unplug-after=9000");
    let e = r.expect_err("the grabber vanished mid-frame");
    assert!(e.is_vanished(), "{e}");
    let port = cell.grabber.port_name().to_string();
    assert!(e.to_string().contains(&port), "names the port: {e}");
    assert!(took < Duration::from_secs(10), "{took:?}");
    // Plugged back in: the console reconnects and captures, and may
    // reconnect again while the grabber is there.
    let deadline = Instant::now() + Duration::from_secs(5);
    while cell.sim().is_some_and(|s| s.grabber_plugged()) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
    }
    cell.reconnect_grabber().expect("reconnect");
    cell.reconnect_grabber().expect("reconnect while present");
    let again = within(Duration::from_secs(30), move || {
        let r = capture(&mut cell);
        r.map(|c| c.image)
    });
    assert!(again.expect("capture after reconnect") == want);
}

/// A FREEZE answered after the reply timeout (a slow digitiser; the
/// simulator on a busy machine rendering a plate): the client freezes
/// again, and the first answer, arriving late, names the first frame while
/// the grabber holds the second. The transfer must check the frame the
/// grabber holds; it failed twice with "the frame's CRC … does not match
/// FREEZE's" (seen under load in `calib_cli` and in the audit's grabs).
#[test]
fn a_freeze_answered_late_transfers_the_frame_the_grabber_holds() {
    let mut p = profile();
    // Every freeze a new exposure, with a CRC of its own.
    p.sim.noise = 2.0;
    let (r, took, mut cell) = faulty_with("slow-freeze=700ms", p);
    let c = r.expect("a capture despite the late answer");
    let st = cell.grabber.status().expect("status");
    assert_eq!(st.frame, Some(crc32(c.image.data())));
    assert!(took < Duration::from_secs(10), "{took:?}");
}

#[test]
fn garbage_on_connect_is_skipped() {
    let want = reference();
    let (r, _, _) = faulty("garbage=3000,seed=5");
    assert_good("garbage", &r, &want);
}

#[test]
fn a_reset_mid_transfer_is_recovered_by_freezing_again() {
    let want = reference();
    let (r, _, _) = faulty("reset");
    assert_good("reset", &r, &want);
}

/// The driver itself, without the cell's help: a reset strikes after the
/// first block, the grabber forgets its frame and falls back to camera 1;
/// the transfer freezes again from camera 2, so the frame is camera 2's.
#[test]
fn the_driver_freezes_again_from_the_same_camera_after_a_reset() {
    let want = reference();
    let got = within(Duration::from_secs(60), || {
        let faults = Faults::parse("reset").expect("fault spec");
        let mut cell = Cell::open_with_faults(&profile(), faults).expect("open");
        cell.switch_lighting('a').expect("lights");
        let g = &mut cell.grabber;
        g.select_camera(2).expect("camera");
        let first = g.freeze().expect("freeze");
        let r = g.transfer(&mut |_, _| true);
        (r, first, g.frame(), g.wire_stats())
    });
    let (r, first, frame, stats) = got;
    let img = r.unwrap_or_else(|e| panic!("reset: {e}"));
    assert!(img == want, "the frame differs from camera 2's");
    assert_eq!(stats.refreezes, 1);
    // Noise is off: the new exposure is the same picture.
    assert_eq!(frame, Some(first));
}

#[test]
fn a_hopeless_line_ends_in_a_clear_error_not_a_hang() {
    let (r, took) = try_faulty("corrupt=0.01,seed=9");
    match r {
        Ok((c, _)) => assert_eq!(crc32(c.image.data()), c.frame.crc),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                matches!(
                    e,
                    RigError::BlockCrc { .. } | RigError::Garbled { .. } | RigError::Timeout { .. }
                ),
                "{msg}"
            );
            assert!(msg.contains("/dev/"), "names the port: {msg}");
        }
    }
    assert!(took < Duration::from_secs(45), "{took:?}");
}

#[test]
fn reconnect_reopens_the_same_port_name_when_the_device_is_back() {
    use vss::rig::grabber::{ClientConfig, FrameGrabber, VsgClient};
    use vss::rig::sim::{SimCell, SimOptions};
    let tmp = tempfile::tempdir().expect("tmp");
    let link = tmp.path().join("ttyVSG0");
    let mut o = SimOptions::new(64, 64);
    o.faults = Faults::parse("unplug-after=3000").expect("spec");
    let mut sim = SimCell::start(o).expect("sim");
    sim.link_grabber(&link).expect("link");
    let name = link.to_string_lossy().into_owned();
    let cfg = ClientConfig {
        timeout: std::time::Duration::from_millis(500),
        retries: 2,
        block: 1024,
        baud: 921_600,
    };
    let r = within(Duration::from_secs(30), move || {
        let mut g = VsgClient::open(&name, 921_600, cfg).expect("open by link");
        // Reconnecting to a device that is still there (after a timeout)
        // closes the exclusive port before reopening it.
        g.reconnect().expect("reconnect while present");
        let f = g.freeze().expect("freeze");
        let e = g
            .transfer(&mut |_, _| true)
            .expect_err("unplugged mid-frame");
        assert!(e.is_vanished() && e.to_string().contains(&name), "{e}");
        // Still gone (the name went with it): reconnect says so, naming it.
        while sim.grabber_plugged() {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert!(
            !std::path::Path::new(&name).exists(),
            "the device name is gone"
        );
        let gone = g.reconnect().expect_err("device is away");
        assert!(gone.to_string().contains(&name), "{gone}");
        // Back (power-cycled) under the same name: reopen, freeze again.
        sim.replug_grabber().expect("replug");
        g.reconnect().expect("reconnect");
        let f2 = g.freeze().expect("freeze");
        let img = g.transfer(&mut |_, _| true).expect("transfer");
        (f, f2, crc32(img.data()))
    });
    let (_, f2, crc) = r;
    assert_eq!(crc, f2.crc);
}

/// The lossy-line figures of docs/reliability.md: one 512² frame through a
/// cell whose grabber drops bytes at each rate, with the profile's default
/// grabber settings (block 16384, reply timeout 1 s), in process. Prints
/// the capture time (freeze included) and what went over the wire.
/// `cargo test --test it rig_faults::lossy_line_timings -- --ignored --nocapture`
#[test]
#[ignore = "a measurement: run by hand, see docs/reliability.md"]
fn lossy_line_timings() {
    let mut p = cell_profile(512, 512);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 0;
    let want = {
        let mut cell = Cell::open(&p).expect("clean cell");
        capture(&mut cell).expect("clean").image
    };
    println!(
        "| faults | capture | blocks bad | stalls | retries | re-syncs | wire bytes / payload |"
    );
    println!("|---|---|---|---|---|---|---|");
    for spec in [
        "seed=1",
        "drop=1e-4,seed=1",
        "drop=1e-3,seed=1",
        "drop=1e-3,seed=2",
        "drop=1e-2,seed=1",
        "drop=1e-2,seed=2",
    ] {
        let (r, _, cell) = faulty_with(spec, p.clone());
        let c = r.unwrap_or_else(|e| panic!("{spec}: {e}"));
        assert!(c.image == want, "{spec}: not the clean frame");
        let st = cell.grabber.wire_stats();
        println!(
            "| {spec} | {} ms | {} | {} | {} | {} | {:.3} |",
            c.elapsed.as_millis(),
            st.bad_blocks,
            st.stalls,
            st.retries,
            st.resyncs,
            st.overhead()
        );
    }
}

mod matrix;

/// Issue 34, N10: `vss sim --link PATH` never replaces nor deletes a
/// regular file at PATH (it did both); a link it left before is replaced,
/// and removed when the cell stops.
#[test]
fn sim_link_never_replaces_or_deletes_a_file() {
    use vss::rig::sim::{SimCell, SimOptions};
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join("notes.txt");
    std::fs::write(&file, "keep me").expect("file");
    let mut sim = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let e = sim.link_grabber(&file).expect_err("a file is not a link");
    assert!(e.to_string().contains("not a symbolic link"), "{e}");
    assert!(!e.to_string().contains("  "), "a run of spaces: {e}");
    sim.stop();
    assert_eq!(std::fs::read_to_string(&file).expect("kept"), "keep me");
    // A link left by an earlier run is replaced, and goes with the cell.
    let link = tmp.path().join("ttyVSG0");
    std::os::unix::fs::symlink("/dev/pts/nowhere", &link).expect("old link");
    let mut sim = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    sim.link_grabber(&link).expect("link");
    assert_eq!(
        std::fs::read_link(&link).expect("link"),
        std::path::Path::new(sim.grabber_path())
    );
    sim.stop();
    assert!(
        std::fs::symlink_metadata(&link).is_err(),
        "link left behind"
    );
    let names: Vec<_> = std::fs::read_dir(tmp.path())
        .expect("dir")
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// A second `vss sim --link PATH` while the first still serves PATH took
/// the link over without a word, and removed it when it stopped: the first
/// simulator, still running, was left without its stable name. A link to a
/// live terminal made before it is now refused and left as it is; a link
/// whose terminal number was reused after it was made (a killed simulator's)
/// is still replaced.
#[test]
fn sim_link_is_not_taken_from_a_running_simulator() {
    use vss::rig::sim::{SimCell, SimOptions};
    let tmp = tempfile::tempdir().expect("tmp");
    let link = tmp.path().join("ttyVSG0");
    let mut first = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    first.link_grabber(&link).expect("link");
    let mut second = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let e = second
        .link_grabber(&link)
        .expect_err("the first simulator's link is taken");
    assert!(e.to_string().contains(first.grabber_path()), "{e}");
    second.stop();
    assert_eq!(
        std::fs::read_link(&link).expect("link kept"),
        std::path::Path::new(first.grabber_path())
    );
    first.stop();
    // A link older than the terminal it names: the number was reused.
    let third = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let mut fourth = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let stale = tmp.path().join("ttyVSG1");
    std::os::unix::fs::symlink(third.grabber_path(), &stale).expect("stale link");
    let back = std::process::Command::new("touch")
        .args(["-h", "-d", "2001-01-01"])
        .arg(&stale)
        .status()
        .expect("touch");
    assert!(back.success());
    fourth
        .link_grabber(&stale)
        .expect("a stale link is replaced");
    assert_eq!(
        std::fs::read_link(&stale).expect("link"),
        std::path::Path::new(fourth.grabber_path())
    );
    fourth.stop();
    third.stop();
}
