//! The console's device worker against the simulated cell with a fault: the
//! grabber is unplugged in the middle of a frame. The worker must say the
//! device is lost, keep running, reconnect on its own, and capture again.

use std::path::Path;
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use vss::profile::Profile;
use vss::rig::Cell;
use vss::rig::sim::Faults;
use vss::tui::event::{DeviceCmd, DeviceEvent, FramePurpose, Msg};
use vss::tui::workers::device;

const PROFILE: &str = r#"
[relay]
settle_ms = 5
[[lights]]
name = "left"
relay = 0
[[lighting]]
letter = "a"
on = ["left"]
[sim]
width = 128
height = 128
"#;

/// The next device event matching `f`, within `secs`.
fn next(
    rx: &Receiver<Msg>,
    secs: u64,
    what: &str,
    f: impl Fn(&DeviceEvent) -> bool,
) -> DeviceEvent {
    let end = Instant::now() + Duration::from_secs(secs);
    loop {
        let left = end.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(Msg::Device(e)) if f(&e) => return e,
            Ok(_) => {}
            Err(_) => panic!("no {what} within {secs} s"),
        }
    }
}

#[test]
fn an_unplugged_grabber_is_reported_and_reconnected() {
    let profile = Profile::from_toml(PROFILE, Path::new("t.toml")).unwrap();
    let (tx, rx) = channel();
    let faults = Faults {
        unplug_after: Some(6000),
        ..Default::default()
    };
    let h = device::spawn_with(
        Box::new(move || Cell::open_with_faults(&profile, faults.clone())),
        tx,
    )
    .unwrap();
    next(&rx, 10, "connection", |e| {
        matches!(e, DeviceEvent::Connected { .. })
    });
    let grab = DeviceCmd::Capture {
        purpose: FramePurpose::Snapshot,
        camera: 1,
        lighting: Some('a'),
    };
    h.send(grab.clone());
    next(&rx, 10, "failed capture", |e| {
        matches!(e, DeviceEvent::CaptureFailed { .. })
    });
    let lost = next(&rx, 10, "lost device", |e| {
        matches!(e, DeviceEvent::Lost { .. })
    });
    let DeviceEvent::Lost { error, .. } = lost else {
        unreachable!()
    };
    assert!(
        error.contains("vanished") || error.contains("no reply"),
        "{error}"
    );
    next(&rx, 15, "reconnection", |e| {
        matches!(e, DeviceEvent::Connected { .. })
    });
    h.send(grab);
    let frame = next(&rx, 15, "frame after reconnecting", |e| {
        matches!(e, DeviceEvent::Frame { .. })
    });
    let DeviceEvent::Frame { image, .. } = frame else {
        unreachable!()
    };
    assert_eq!(image.size(), (128, 128));
}

/// Exposure and gain keys on a grabber that cannot set them (the VSG/1
/// simulated one): a log line says so, nothing else changes.
#[test]
fn exposure_on_a_serial_grabber_says_it_cannot() {
    let profile = Profile::from_toml(PROFILE, Path::new("t.toml")).unwrap();
    let (tx, rx) = channel();
    let h = device::spawn(profile, tx).unwrap();
    next(&rx, 10, "connection", |e| {
        matches!(e, DeviceEvent::Connected { .. })
    });
    h.send(DeviceCmd::Exposure {
        camera: 1,
        factor: 1.25,
    });
    let note = next(&rx, 10, "a note", |e| matches!(e, DeviceEvent::Note(_)));
    let DeviceEvent::Note(n) = note else {
        unreachable!()
    };
    assert!(n.contains("does not set exposure or gain"), "{n}");
    h.send(DeviceCmd::Gain { camera: 1, db: 1.0 });
    let note = next(&rx, 10, "a note", |e| matches!(e, DeviceEvent::Note(_)));
    assert!(
        matches!(&note, DeviceEvent::Note(n) if n.contains("does not set")),
        "{note:?}"
    );
}
