//! Both relay protocols over real pseudo-terminals: the Numato driver
//! against the simulated board (and raw Numato commands typed into it), the
//! LCUS driver against a pty peer that reads its frames (and a fake LCUS
//! board that decodes them and can lose power between runs); and lighting
//! configurations through `Cell`.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use serialport::{SerialPort, TTYPort};
use vss::rig::lights::{LcusBoard, LightSwitch, NumatoBoard};
use vss::rig::sim::{SimCell, SimOptions, cell_profile};
use vss::rig::{Cell, RigError, open_serial};

fn read_until(port: &mut dyn Read, end: u8, want: usize) -> Vec<u8> {
    let deadline = Instant::now() + Duration::from_secs(3);
    let mut got = Vec::new();
    let mut buf = [0u8; 64];
    while !(got.len() >= want && got.last() == Some(&end)) {
        assert!(Instant::now() < deadline, "no reply: {got:?}");
        if let Ok(n) = port.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
    }
    got
}

#[test]
fn raw_numato_commands_on_the_simulated_board() {
    let sim = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let mut p = open_serial(sim.relay_path(), 19200, Duration::from_millis(50)).expect("open");
    let mut say = |cmd: &str| -> String {
        p.write_all(format!("{cmd}\r").as_bytes()).expect("write");
        String::from_utf8(read_until(&mut p, b'>', cmd.len() + 1)).expect("ascii")
    };
    assert_eq!(say("ver"), "ver\r\n\r00000008\n\r>");
    assert_eq!(say("relay on 1"), "relay on 1\r\n\r>");
    assert_eq!(say("relay read 1"), "relay read 1\r\n\ron\n\r>");
    assert_eq!(say("relay read 0"), "relay read 0\r\n\roff\n\r>");
    assert_eq!(say("relay writeall 0009"), "relay writeall 0009\r\n\r>");
    assert_eq!(say("relay readall"), "relay readall\r\n\r0009\n\r>");
    assert_eq!(say("relay off 3"), "relay off 3\r\n\r>");
    assert_eq!(say("relay readall"), "relay readall\r\n\r0001\n\r>");
    // Nonsense is ignored, as by the firmware.
    assert_eq!(say("relay dance"), "relay dance\r\n\r>");
    assert_eq!(sim.scene().relays(), 1);
}

#[test]
fn numato_driver_switches_and_reads_back() {
    let sim = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let mut b =
        NumatoBoard::open(sim.relay_path(), 19200, Duration::from_millis(300), None).expect("open");
    b.set(2, true).expect("on");
    b.set(10, true).expect("on A");
    assert_eq!(b.read_mask().expect("mask"), (1 << 2) | (1 << 10));
    assert!(b.read(10).expect("read"));
    b.set(2, false).expect("off");
    b.set_mask(0b1011).expect("mask");
    assert_eq!(sim.scene().relays(), 0b1011);
    // The simulated board has 16 relays: relay 20 does not switch, and the
    // driver's read-back says so rather than believing it.
    let e = b.set(20, true).expect_err("no relay 20");
    assert!(e.to_string().contains(sim.relay_path()), "{e}");
    // A 33rd relay cannot even be named.
    assert!(matches!(b.set(40, true), Err(RigError::Board { .. })));
}

/// A port whose lock is held for a moment is waited for: a port closed
/// and opened again at once found its own last lock still held, by the
/// copy of the open file a child process of another thread keeps until its
/// program is loaded (this test's next open failed "Unable to acquire
/// exclusive lock" under load). A port held on is refused after the wait,
/// naming the port.
#[test]
fn a_port_locked_for_a_moment_is_waited_for_and_one_held_is_refused() {
    let sim = SimCell::start(SimOptions::new(32, 32)).expect("sim");
    let path = sim.relay_path().to_string();
    let t = Duration::from_millis(100);
    let held = open_serial(&path, 19200, t).expect("the first open");
    let release = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(100));
        drop(held);
    });
    let again = open_serial(&path, 19200, t);
    release.join().expect("released");
    let again = again.expect("opened once the lock was let go");
    let start = Instant::now();
    let e = open_serial(&path, 19200, t).expect_err("a port held on");
    assert!(
        start.elapsed() >= vss::rig::BUSY_WAIT,
        "{:?}",
        start.elapsed()
    );
    assert!(e.to_string().contains(&path), "{e}");
    // Said as what it is: held, and by whom (here: this test itself).
    assert!(
        e.to_string().contains(&format!(
            "in use by this program itself (process {})",
            std::process::id()
        )),
        "{e}"
    );
    drop(again);
}

#[test]
fn writeall_sends_as_many_digits_as_the_board_has_relays_over_four() {
    for (relays, mask, typed) in [
        (8, 0x81, "relay writeall 81"),
        (16, 0x8001, "relay writeall 8001"),
        (32, 0x8000_0001, "relay writeall 80000001"),
    ] {
        let mut o = SimOptions::new(32, 32);
        o.relays = relays;
        let sim = SimCell::start(o).expect("sim");
        // The width learned from the board itself, and given by the profile.
        for channels in [None, Some(relays)] {
            let mut b = NumatoBoard::open(
                sim.relay_path(),
                19200,
                Duration::from_millis(300),
                channels,
            )
            .expect("open");
            b.set_mask(0).expect("off");
            b.set_mask(mask).expect(typed);
            assert_eq!(sim.scene().relays(), mask, "{typed}");
            assert_eq!(b.channels(), Some(relays));
        }
        if relays == 32 {
            let mut b =
                NumatoBoard::open(sim.relay_path(), 19200, Duration::from_millis(300), None)
                    .expect("open");
            b.set(31, false).expect("relay V");
            assert_eq!(sim.scene().relays(), 1);
        }
    }
    // What a Numato board types back, raw: 8 relays, 2 digits.
    let mut o = SimOptions::new(32, 32);
    o.relays = 8;
    let sim = SimCell::start(o).expect("sim");
    let mut p = open_serial(sim.relay_path(), 19200, Duration::from_millis(50)).expect("open");
    p.write_all(b"relay readall\r").expect("write");
    let got = String::from_utf8(read_until(&mut p, b'>', 16)).expect("ascii");
    assert_eq!(got, "relay readall\r\n\r00\n\r>");
}

#[test]
fn a_prompt_long_after_the_echo_keeps_the_numato_driver_in_step() {
    for delay_ms in [40, 60, 120] {
        let mut o = SimOptions::new(32, 32);
        o.prompt_delay = Duration::from_millis(delay_ms);
        let sim = SimCell::start(o).expect("sim");
        let mut b = NumatoBoard::open(sim.relay_path(), 19200, Duration::from_millis(500), None)
            .unwrap_or_else(|e| panic!("{delay_ms} ms: {e}"));
        b.set(2, true)
            .unwrap_or_else(|e| panic!("{delay_ms} ms: {e}"));
        b.set_mask(0b1001)
            .unwrap_or_else(|e| panic!("{delay_ms} ms: {e}"));
        assert_eq!(b.read_mask().expect("mask"), 0b1001, "{delay_ms} ms");
        assert_eq!(sim.scene().relays(), 0b1001);
    }
    // A prompt later than the reply timeout: the error says so, and counts
    // its attempts.
    let mut o = SimOptions::new(32, 32);
    o.prompt_delay = Duration::from_millis(400);
    let sim = SimCell::start(o).expect("sim");
    let e = match NumatoBoard::open(sim.relay_path(), 19200, Duration::from_millis(100), None) {
        Ok(_) => panic!("a 400 ms prompt within 100 ms"),
        Err(e) => e,
    };
    let msg = e.to_string();
    assert!(matches!(e, RigError::NoPrompt { attempts: 3, .. }), "{msg}");
    assert!(
        msg.contains("prompt") && msg.contains("3 attempts"),
        "{msg}"
    );
    assert!(
        !msg.contains("instead of") && !msg.contains("1 attempts"),
        "{msg}"
    );
}

/// A fake LCUS board on the device side of a pty: decodes the frames it is
/// sent into its relay mask, as the real board does, and can lose power
/// (every relay off) like a board replugged or power-cycled.
struct FakeLcus {
    mask: std::sync::Arc<std::sync::atomic::AtomicU32>,
    frames: std::sync::Arc<std::sync::atomic::AtomicUsize>,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FakeLcus {
    fn start(mut peer: TTYPort) -> FakeLcus {
        use std::sync::Arc;
        use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};
        peer.set_timeout(Duration::from_millis(10))
            .expect("timeout");
        let mask = Arc::new(AtomicU32::new(0));
        let frames = Arc::new(AtomicUsize::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let (m, f, st) = (mask.clone(), frames.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let mut buf = [0u8; 64];
            let mut rx: Vec<u8> = Vec::new();
            while !st.load(Ordering::SeqCst) {
                if let Ok(n) = peer.read(&mut buf) {
                    rx.extend_from_slice(&buf[..n]);
                }
                // Resynchronise on 0xA0, as the board's parser does.
                while rx.len() >= 4 {
                    if let Some((relay, on)) = vss::rig::protocol::lcus_parse(&rx[..4]) {
                        if on {
                            m.fetch_or(1 << relay, Ordering::SeqCst);
                        } else {
                            m.fetch_and(!(1 << relay), Ordering::SeqCst);
                        }
                        f.fetch_add(1, Ordering::SeqCst);
                        rx.drain(..4);
                    } else {
                        rx.remove(0);
                    }
                }
            }
        });
        FakeLcus {
            mask,
            frames,
            stop,
            thread: Some(thread),
        }
    }
    fn mask(&self) -> u32 {
        self.mask.load(std::sync::atomic::Ordering::SeqCst)
    }
    fn frames(&self) -> usize {
        self.frames.load(std::sync::atomic::Ordering::SeqCst)
    }
    /// The board loses power: every relay drops.
    fn power_cycle(&self) {
        self.mask.store(0, std::sync::atomic::Ordering::SeqCst);
    }
    /// Waits until `frames` frames in all have arrived (or 2 s).
    fn wait_frames(&self, frames: usize) {
        let end = Instant::now() + Duration::from_secs(2);
        while self.frames() < frames && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(Duration::from_millis(30));
    }
}

impl Drop for FakeLcus {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A profile whose relay board is the LCUS board on `port` (and whose
/// grabber is the simulated one), written into `dir`.
fn lcus_profile(dir: &std::path::Path, port: &str) -> (std::path::PathBuf, vss::profile::Profile) {
    let mut p = cell_profile(32, 32);
    p.relay.kind = vss::profile::RelayKind::Lcus;
    p.relay.port = port.to_string();
    p.relay.settle_ms = 0;
    let prof = dir.join("lcus.toml");
    std::fs::write(&prof, toml::to_string(&p).expect("toml")).expect("profile");
    (prof, p)
}

/// `vss --profile PROF ARGS` with its own state folder; stdout + stderr.
fn vss_with_state(prof: &std::path::Path, state: &std::path::Path, args: &[&str]) -> String {
    let o = std::process::Command::new(assert_cmd::cargo::cargo_bin("vss"))
        .arg("--profile")
        .arg(prof)
        .args(args)
        .env("XDG_STATE_HOME", state)
        .output()
        .expect("vss");
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{args:?}: {text}");
    text
}

#[test]
fn lcus_status_switches_nothing_and_set_sends_the_whole_mask() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (peer, dev) = TTYPort::pair().expect("pty");
    let port = dev.name().expect("pty name");
    let (prof, _) = lcus_profile(tmp.path(), &port);
    let state = tmp.path().join("state");
    let board = FakeLcus::start(peer);
    let lights = |action: &[&str]| {
        let mut args = vec!["lights"];
        args.extend_from_slice(action);
        vss_with_state(&prof, &state, &args)
    };
    let out = lights(&["status"]);
    assert!(out.contains("LCUS boards cannot be read"), "{out}");
    assert!(out.contains("nothing recorded"), "{out}");
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(board.frames(), 0, "status switched relays");
    // a: relay 0 on, and all 8 channels are sent.
    lights(&["set", "a"]);
    board.wait_frames(8);
    assert_eq!((board.frames(), board.mask()), (8, 0b1));
    // b: again every channel, though vss set a before.
    lights(&["set", "b"]);
    board.wait_frames(16);
    assert_eq!((board.frames(), board.mask()), (16, 0b10));
    let out = lights(&["status"]);
    assert!(
        out.contains("last set by vss: relays 0002") && out.contains("right-front"),
        "{out}"
    );
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(board.frames(), 16, "status switched relays");
    // A state file that does not fit the board is ignored, with a note.
    let file = std::fs::read_dir(state.join("vss/relays"))
        .expect("state folder")
        .flatten()
        .next()
        .expect("state file")
        .path();
    let text = std::fs::read_to_string(&file).expect("state");
    std::fs::write(&file, text.replace("mask = 2", "mask = 65535")).expect("plant");
    let out = lights(&["status"]);
    assert!(
        out.contains("ignored the LCUS state file") && out.contains("beyond"),
        "{out}"
    );
    assert!(out.contains("nothing recorded"), "{out}");
    drop(dev);
}

/// N1 of issue 34: an LCUS board that loses its relays between two runs of
/// vss (a USB replug, a power cycle) while its state file says otherwise.
/// Every run must leave the board as vss says: 0 wrong states.
#[test]
fn lcus_board_that_loses_power_between_runs_ends_as_vss_says() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (peer, dev) = TTYPort::pair().expect("pty");
    let port = dev.name().expect("pty name");
    let (prof, p) = lcus_profile(tmp.path(), &port);
    let state = tmp.path().join("state");
    let board = FakeLcus::start(peer);
    let mask_of = |letter: char| -> u32 {
        let cfg = p
            .lighting
            .iter()
            .find(|l| l.letter == letter)
            .expect("lighting");
        cfg.on
            .iter()
            .map(|n| 1u32 << p.lights.iter().find(|l| &l.name == n).expect("light").relay)
            .fold(0, |a, b| a | b)
    };
    let all_on = p.lights.iter().fold(0u32, |a, l| a | 1 << l.relay);
    // Runs, and whether the board loses power before each: the same
    // lighting again after a power loss is the case that went wrong.
    let runs: &[(&[&str], u32, bool)] = &[
        (&["set", "a"], mask_of('a'), false),
        (&["set", "a"], mask_of('a'), true),
        (&["set", "b"], mask_of('b'), false),
        (&["set", "b"], mask_of('b'), true),
        (&["on"], all_on, true),
        (&["on"], all_on, true),
        (&["set", "c"], mask_of('c'), false),
        (&["set", "c"], mask_of('c'), true),
        (&["set", "d"], mask_of('d'), true),
        (&["off"], 0, false),
        (&["set", "a"], mask_of('a'), true),
        (&["set", "a"], mask_of('a'), false),
    ];
    let mut wrong = Vec::new();
    for (i, (args, want, power_loss)) in runs.iter().enumerate() {
        if *power_loss {
            board.power_cycle();
        }
        let before = board.frames();
        let mut a = vec!["lights"];
        a.extend_from_slice(args);
        let out = vss_with_state(&prof, &state, &a);
        board.wait_frames(before + 8);
        if board.mask() != *want {
            wrong.push(format!(
                "run {i} {args:?} (power lost before: {power_loss}): board {:04x}, vss set {want:04x}; {out}",
                board.mask()
            ));
        }
    }
    // A capture sets its lighting's whole mask, whatever the state file
    // says: grab under `b` twice, the board losing power in between.
    let session = tmp.path().join("s/g");
    let session = session.to_str().expect("utf-8 path");
    for (image, power_loss) in [("1", false), ("2", true)] {
        if power_loss {
            board.power_cycle();
        }
        let before = board.frames();
        let out = vss_with_state(
            &prof,
            &state,
            &[
                "grab",
                "--session",
                session,
                "--image",
                image,
                "--camera",
                "1",
                "--lighting",
                "b",
            ],
        );
        board.wait_frames(before + 8);
        if board.mask() != mask_of('b') {
            wrong.push(format!(
                "grab {image} (power lost before: {power_loss}): board {:04x}; {out}",
                board.mask()
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{} wrong states:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    drop(dev);
}

#[test]
fn lcus_frames_over_a_pty() {
    let (mut peer, mut dev) = TTYPort::pair().expect("pty");
    dev.set_timeout(Duration::from_millis(200))
        .expect("timeout");
    peer.set_timeout(Duration::from_millis(200))
        .expect("timeout");
    let name = dev.name().unwrap_or_default();
    let mut b = LcusBoard::new(dev, &name, 4, Duration::from_millis(200));
    b.set_mask(0).expect("all off");
    b.set(0, true).expect("on");
    b.set(2, true).expect("on");
    b.set(0, false).expect("off");
    let mut got = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(3);
    let mut buf = [0u8; 64];
    while got.len() < 28 && Instant::now() < deadline {
        if let Ok(n) = peer.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
    }
    assert_eq!(
        got[16..],
        [0xA0, 1, 1, 0xA2, 0xA0, 3, 1, 0xA4, 0xA0, 1, 0, 0xA1],
        "A0 ch state sum"
    );
    assert_eq!(b.read_mask().expect("mask"), 0b100);
    // The peer hung up: the next switch reports a vanished board, by name.
    // (The hang-up reaches the board's side of the pty a moment later on
    // a loaded machine: a switch in that moment may still be written.)
    drop(peer);
    let deadline = Instant::now() + Duration::from_secs(3);
    let e = loop {
        match b.set(1, true) {
            Err(e) => break e,
            Ok(()) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(20)),
            Ok(()) => panic!("peer gone, but switches still succeed after 3 s"),
        }
    };
    assert!(e.is_vanished() && e.to_string().contains(&name), "{e}");
}

#[test]
fn cell_switches_lighting_configurations_and_knows_what_is_on() {
    let mut p = cell_profile(32, 32);
    p.relay.settle_ms = 120;
    let mut cell = Cell::open(&p).expect("cell");
    assert!(cell.lights_on().is_empty());
    let t = Instant::now();
    cell.switch_lighting('b').expect("b");
    assert!(
        t.elapsed() >= Duration::from_millis(120),
        "waits the settle time"
    );
    assert_eq!(cell.lights_on(), vec!["right-front".to_string()]);
    assert_eq!(cell.lighting(), Some('b'));
    let sim_mask = cell.sim().map(|s| s.scene().relays());
    assert_eq!(sim_mask, Some(0b10), "the board really switched");
    cell.switch_lighting('e').expect("e");
    assert!(cell.lights_on().is_empty());
    let e = cell.switch_lighting('z').expect_err("no z");
    assert!(e.to_string().contains("abcde"), "{e}");
}

/// Issue 34, N12: a relative `XDG_STATE_HOME` is ignored (XDG base
/// directory specification): the LCUS state goes under `~/.local/state`,
/// not into whatever folder vss runs in.
#[test]
fn a_relative_xdg_state_home_is_ignored() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (peer, dev) = TTYPort::pair().expect("pty");
    let port = dev.name().expect("pty name");
    let (prof, _) = lcus_profile(tmp.path(), &port);
    let _board = FakeLcus::start(peer);
    let (work, home) = (tmp.path().join("work"), tmp.path().join("home"));
    std::fs::create_dir_all(&work).expect("work");
    std::fs::create_dir_all(&home).expect("home");
    let o = std::process::Command::new(assert_cmd::cargo::cargo_bin("vss"))
        .arg("--profile")
        .arg(&prof)
        .args(["lights", "set", "a"])
        .current_dir(&work)
        .env("HOME", &home)
        .env("XDG_STATE_HOME", "rel/state")
        .output()
        .expect("vss");
    assert!(o.status.success(), "{o:?}");
    assert!(
        !work.join("rel").exists(),
        "state written under the working folder"
    );
    assert!(home.join(".local/state/vss/relays").is_dir());
    drop(dev);
}
