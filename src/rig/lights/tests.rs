//! The relay drivers against scripted bytes.

use super::*;
use crate::rig::script::Script;

fn board(answers: &[&str], channels: Option<u32>) -> NumatoBoard<Script> {
    let a = answers.iter().map(|s| s.as_bytes().to_vec()).collect();
    NumatoBoard::new(
        Script::new(b'\r', a),
        "/dev/relay0",
        Duration::from_millis(50),
        channels,
    )
}

#[test]
fn switch_checks_echo_and_reads_back() {
    let mut b = board(
        &["relay on 2\r\n\r>", "relay read 2\r\n\ron\n\r>"],
        Some(16),
    );
    assert!(b.set(2, true).is_ok());
    assert_eq!(b.port.sent_text(), "relay on 2\rrelay read 2\r");
}

#[test]
fn a_relay_that_did_not_switch_is_reported() {
    let mut b = board(&["relay on 2\r\n\r>", "relay read 2\r\n\roff\n\r>"], None);
    let e = b.set(2, true);
    assert!(
        matches!(&e, Err(RigError::RelayMismatch { port, expected, got, .. })
            if port == "/dev/relay0" && expected == "on" && got == "off"),
        "{e:?}"
    );
}

#[test]
fn stray_bytes_before_the_echo_are_skipped_and_a_wrong_echo_is_an_error() {
    let mut b = board(
        &["\x13\x00relay on 2\n\r>", "relay read 2\r\n\ron\n\r>"],
        None,
    );
    assert!(b.set(2, true).is_ok());
    let mut b = board(
        &["relay on 3\n\r>", "relay on 3\n\r>", "relay on 3\n\r>"],
        None,
    );
    let e = b.set(2, true);
    assert!(
        matches!(&e, Err(RigError::Garbled { detail, attempts: 3, .. }) if detail.contains("echoed")),
        "{e:?}"
    );
    assert!(e.is_err_and(|e| e.to_string().contains("3 attempts")));
    assert_eq!(b.port.sent_text().matches("relay on 2\r").count(), 3);
}

#[test]
fn mask_width_follows_the_board() {
    // 8 relays: two hex digits, learned from readall.
    let mut b = board(
        &[
            "relay readall\n\r00\n\r>",
            "relay writeall 05\n\r>",
            "relay readall\n\r05\n\r>",
        ],
        None,
    );
    assert!(b.set_mask(5).is_ok());
    assert_eq!(
        b.port.sent_text(),
        "relay readall\rrelay writeall 05\rrelay readall\r"
    );
    assert_eq!(b.channels(), Some(8));
    assert!(matches!(b.set_mask(0x100), Err(RigError::Board { .. })));
    // 32 relays from the profile: eight digits, relay V named.
    let mut b = board(
        &[
            "relay writeall 80000001\n\r>",
            "relay readall\n\r80000001\n\r>",
            "relay on V\n\r>",
            "relay read V\n\ron\n\r>",
        ],
        Some(32),
    );
    assert!(b.set_mask(0x8000_0001).is_ok());
    assert!(b.set(31, true).is_ok());
    // A profile that disagrees with the board is told so.
    let mut b = board(&["relay readall\n\r0000\n\r>"], Some(8));
    let e = b.read_mask().expect_err("16-relay board, profile says 8");
    assert!(e.to_string().contains("channels"), "{e}");
}

#[test]
fn no_answer_is_a_timeout_counted_right() {
    let mut b = board(&[], None);
    let e = b.read_mask().expect_err("silent");
    assert!(matches!(e, RigError::Timeout { attempts: 3, .. }), "{e:?}");
    assert!(e.to_string().contains("3 attempts"), "{e}");
    // The echo and no prompt: said so.
    let mut b = board(&["relay readall\n\r0005\n\r"; 3], None);
    let e = b.read_mask().expect_err("no prompt");
    assert!(matches!(e, RigError::NoPrompt { attempts: 3, .. }), "{e:?}");
}

#[test]
fn lcus_sends_the_whole_mask_and_single_switches_after_it() {
    let s = Script::new(b'\n', vec![]);
    let mut b = LcusBoard::new(s, "/dev/lcus", 4, Duration::from_millis(50));
    assert!(!b.reads_back() && b.last_set().is_none());
    // A mask: every channel, every time (the board may have lost it).
    let all = |m: u32| -> Vec<u8> {
        (0..4u32)
            .flat_map(|r| crate::rig::protocol::lcus_frame(r, m & 1 << r != 0).unwrap())
            .collect()
    };
    assert!(b.set_mask(0b0001).is_ok());
    assert_eq!(
        b.port_mut().sent,
        vec![
            0xA0, 1, 1, 0xA2, 0xA0, 2, 0, 0xA2, 0xA0, 3, 0, 0xA3, 0xA0, 4, 0, 0xA4
        ]
    );
    b.port_mut().sent.clear();
    assert!(b.set_mask(0b1001).is_ok());
    assert_eq!(b.port_mut().sent, all(0b1001));
    b.port_mut().sent.clear();
    // After a whole mask, one relay is one frame.
    assert!(b.set(0, false).is_ok());
    assert_eq!(b.port_mut().sent, vec![0xA0, 1, 0, 0xA1]);
    assert_eq!(b.read_mask().ok(), Some(0b1000));
    assert!(matches!(b.set(4, true), Err(RigError::Board { .. })));
    assert!(matches!(b.set_mask(1 << 6), Err(RigError::Board { .. })));
    // A process's first single switch sends the whole mask: the others off.
    let mut b = LcusBoard::new(Script::new(b'\n', vec![]), "/dev/lcus", 4, Duration::ZERO);
    assert!(b.set(2, true).is_ok());
    assert_eq!(b.port_mut().sent, all(0b0100));
}

#[test]
fn lcus_state_file_reports_and_never_decides_what_is_sent() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("relays/x.toml");
    let open = |port: &str| {
        LcusBoard::new(Script::new(b'\n', vec![]), port, 8, Duration::ZERO)
            .with_state_file(file.clone())
    };
    let mut b = open("/dev/lcus");
    assert!(b.set_mask(0b101).is_ok());
    let mut b2 = open("/dev/lcus");
    assert_eq!(b2.last_set().map(|l| l.mask), Some(0b101));
    assert!(b2.note().is_none());
    // The next process sets the same mask: all 8 channels go again.
    assert!(b2.set_mask(0b101).is_ok());
    assert_eq!(b2.port_mut().sent.len(), 8 * 4);
    // Another port's board is not this one: ignored, with a note.
    let b3 = open("/dev/other");
    assert!(b3.last_set().is_none());
    assert!(
        b3.note().is_some_and(|n| n.contains("/dev/other")),
        "{:?}",
        b3.note()
    );
    // Relays beyond the board, garbage: ignored, with a note.
    for (bad, why) in [
        (
            "port = \"/dev/lcus\"\nchannels = 8\nmask = 4095\nwhen = \"x\"\n",
            "beyond",
        ),
        ("\u{0}\u{1}garbage", "not a state file"),
    ] {
        std::fs::write(&file, bad).unwrap();
        let b = open("/dev/lcus");
        assert!(b.last_set().is_none(), "{bad:?}");
        assert!(
            b.note()
                .is_some_and(|n| n.contains(why) && n.contains("ignored")),
            "{bad:?}: {:?}",
            b.note()
        );
    }
    // No file: nothing recorded, nothing to note.
    std::fs::remove_file(&file).unwrap();
    let b = open("/dev/lcus");
    assert!(b.last_set().is_none() && b.note().is_none());
}

#[test]
fn state_files_are_named_after_the_port() {
    let f = lcus_state_file("/dev/serial/by-id/usb-1a86 x");
    if let Some(f) = f {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(name, "_dev_serial_by-id_usb-1a86_x.toml");
        assert!(f.parent().unwrap().ends_with("vss/relays"));
    }
}
