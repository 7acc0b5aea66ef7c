//! Both relay protocols over real pseudo-terminals: the Numato driver
//! against the simulated board (and raw Numato commands typed into it), the
//! LCUS driver against a pty peer that reads its frames; and lighting
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

/// Reads LCUS frames from the device side of a pty for `wait`.
fn frames(peer: &mut TTYPort, wait: Duration) -> Vec<u8> {
    let deadline = Instant::now() + wait;
    let mut got = Vec::new();
    let mut buf = [0u8; 64];
    while Instant::now() < deadline {
        if let Ok(n) = peer.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
    }
    got
}

#[test]
fn lcus_status_switches_nothing_and_set_sends_only_what_changes() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (mut peer, dev) = TTYPort::pair().expect("pty");
    peer.set_timeout(Duration::from_millis(20))
        .expect("timeout");
    let port = dev.name().expect("pty name");
    let mut p = cell_profile(32, 32);
    p.relay.kind = vss::profile::RelayKind::Lcus;
    p.relay.port = port.clone();
    p.relay.settle_ms = 0;
    let prof = tmp.path().join("lcus.toml");
    std::fs::write(&prof, toml::to_string(&p).expect("toml")).expect("profile");
    let lights = |action: &[&str]| {
        let o = std::process::Command::new(assert_cmd::cargo::cargo_bin("vss"))
            .arg("--profile")
            .arg(&prof)
            .arg("lights")
            .args(action)
            .env("XDG_STATE_HOME", tmp.path().join("state"))
            .output()
            .expect("vss lights");
        let text =
            String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{action:?}: {text}");
        text
    };
    let out = lights(&["status"]);
    assert!(out.contains("LCUS boards cannot be read"), "{out}");
    assert!(out.contains("nothing recorded"), "{out}");
    assert!(
        frames(&mut peer, Duration::from_millis(300)).is_empty(),
        "status switched relays"
    );
    // a: relay 0 on. Nothing was known, so all 8 channels go once.
    lights(&["set", "a"]);
    let got = frames(&mut peer, Duration::from_millis(300));
    assert_eq!(got.len(), 8 * 4, "{got:02x?}");
    assert_eq!(&got[..4], &[0xA0, 1, 1, 0xA2]);
    // b: relay 0 off, relay 1 on; the rest stays as it is, unsent.
    lights(&["set", "b"]);
    let got = frames(&mut peer, Duration::from_millis(300));
    assert_eq!(got, [0xA0, 1, 0, 0xA1, 0xA0, 2, 1, 0xA3]);
    let out = lights(&["status"]);
    assert!(
        out.contains("last set by vss: relays 0002") && out.contains("right-front"),
        "{out}"
    );
    assert!(
        frames(&mut peer, Duration::from_millis(300)).is_empty(),
        "status switched relays"
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
    drop(peer);
    let e = b.set(1, true).expect_err("peer gone");
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
