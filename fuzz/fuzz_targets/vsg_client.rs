//! The VSG/1 client against a device that answers whatever the fuzzer
//! chooses: the first byte sets how many bytes each read gets (its low six
//! bits) and whether camera 2 is selected before FREEZE (bit 6), the rest
//! is a recording (answers separated by `\n~~\n`, one released per command
//! the client sends). Connect, freeze and transfer end without a panic, and
//! a frame the client hands over has the size and CRC its FREEZE reply
//! promised — or, when the device said it lost the frame and the client
//! froze again by itself (only with a camera selected), the size of the
//! first and the CRC of the FREEZE that made it. The played-back device
//! answers at once and falls silent at the end, so a run is quick.
#![no_main]

use std::time::Duration;

use libfuzzer_sys::fuzz_target;
use vss::rig::grabber::{ClientConfig, FrameGrabber, VsgClient};
use vss::rig::protocol::crc32;
use vss::rig::replay::Replay;

/// The settings the seeds were recorded with (see tests/it/robust_fuzz.rs).
const CFG: ClientConfig = ClientConfig {
    timeout: Duration::from_millis(1),
    retries: 1,
    block: 64,
    baud: 921_600,
};

fuzz_target!(|data: &[u8]| {
    let Some((&head, bytes)) = data.split_first() else {
        return;
    };
    let feed = Replay::new(bytes, b'\n', usize::from(head % 64) + 1);
    let mut c = VsgClient::new(feed, "/dev/fuzz", CFG);
    if c.connect().is_err() {
        return;
    }
    let camera = head & 0x40 != 0;
    if camera && c.select_camera(2).is_err() {
        return;
    }
    let Ok(f) = c.freeze() else {
        return;
    };
    if let Ok(img) = c.transfer(&mut |_, _| true) {
        let held = c.frame();
        assert!(held.is_some(), "a transfer without a frame");
        let held = held.unwrap_or(f);
        assert_eq!(img.size(), (f.width as usize, f.height as usize));
        assert_eq!(crc32(img.data()), held.crc);
        if held != f {
            assert!(camera, "frozen again without a camera selected");
            assert!(c.wire_stats().refreezes > 0, "another frame, not frozen");
        }
    }
});
