//! The VSG/1 client against a device that answers whatever the fuzzer
//! chooses: the first byte sets how many bytes each read gets, the rest is
//! a recording (answers separated by `\n~~\n`, one released per command
//! the client sends). Connect, freeze and transfer end without a panic, and
//! a frame the client hands over has the size and CRC its FREEZE reply
//! promised. The played-back device answers at once and falls silent at the
//! end, so a run is quick.
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
    let Some((&chunk, bytes)) = data.split_first() else {
        return;
    };
    let feed = Replay::new(bytes, b'\n', usize::from(chunk % 64) + 1);
    let mut c = VsgClient::new(feed, "/dev/fuzz", CFG);
    if c.connect().is_err() {
        return;
    }
    let Ok(f) = c.freeze() else {
        return;
    };
    if let Ok(img) = c.transfer(&mut |_, _| true) {
        assert_eq!(img.size(), (f.width as usize, f.height as usize));
        assert_eq!(crc32(img.data()), f.crc);
    }
});
