//! Every VSG/1 command, good and bad, typed raw into the simulated grabber
//! over a real pseudo-terminal; then the client driver over the same pty
//! (LOAD and READ round trip).

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use vss::llv::GreyImage;
use vss::rig::grabber::{ClientConfig, FrameGrabber, VsgClient};
use vss::rig::open_serial;
use vss::rig::protocol::{crc32, decode_line, encode_line};
use vss::rig::sim::{SimCell, SimOptions};

/// A person at a terminal: types lines, reads lines and raw bytes.
struct Raw {
    port: Box<dyn serialport::SerialPort>,
    rx: Vec<u8>,
}

impl Raw {
    fn open(path: &str) -> Raw {
        let port = open_serial(path, 921_600, Duration::from_millis(100)).expect("open pty");
        Raw {
            port,
            rx: Vec::new(),
        }
    }

    fn fill(&mut self, deadline: Instant) {
        let mut buf = [0u8; 4096];
        assert!(Instant::now() < deadline, "no reply within 3 s");
        match self.port.read(&mut buf) {
            Ok(n) => self.rx.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("read: {e}"),
        }
    }

    fn line(&mut self) -> String {
        let deadline = Instant::now() + Duration::from_secs(3);
        loop {
            if let Some(i) = self.rx.iter().position(|&b| b == b'\n') {
                let raw: Vec<u8> = self.rx.drain(..=i).collect();
                let l = raw.strip_suffix(b"\r\n").expect("lines end in CR LF");
                return decode_line(l).expect("reply checksum").to_string();
            }
            self.fill(deadline);
        }
    }

    fn bytes(&mut self, n: usize) -> Vec<u8> {
        let deadline = Instant::now() + Duration::from_secs(3);
        while self.rx.len() < n {
            self.fill(deadline);
        }
        self.rx.drain(..n).collect()
    }

    fn send(&mut self, raw: &[u8]) {
        self.port.write_all(raw).expect("write");
    }

    fn cmd(&mut self, text: &str) -> String {
        self.send(&encode_line(text));
        self.line()
    }
}

fn sim() -> SimCell {
    let mut o = SimOptions::new(64, 48);
    o.maxblock = 1024;
    SimCell::start(o).expect("sim starts")
}

#[test]
fn every_command_good_and_bad() {
    let sim = sim();
    let mut t = Raw::open(sim.grabber_path());
    let hello = t.cmd("HELLO");
    assert!(hello.starts_with("OK VSG/1 model="), "{hello}");
    assert!(
        hello.contains(" width=64 height=48 depth=8 cameras=4 maxblock=1024"),
        "{hello}"
    );

    // Wrong checksum, no checksum: ERR CHECKSUM, and nothing happens.
    t.send(b"CAMERA 2*00\r\n");
    assert!(t.line().starts_with("ERR CHECKSUM"));
    t.send(b"CAMERA 2\r\n");
    assert!(t.line().starts_with("ERR CHECKSUM"));
    assert_eq!(t.cmd("STATUS"), "OK camera=1 live=0 frame=none");

    // Unknown and malformed commands.
    assert!(t.cmd("FOO").starts_with("ERR BADCMD"));
    assert!(t.cmd("CAMERA two").starts_with("ERR BADCMD"));
    assert!(t.cmd("READ 0").starts_with("ERR BADCMD"));
    // An empty line is a re-sync and gets no reply: the next reply is STATUS's.
    t.send(b"\r\n");

    // Cameras out of range.
    assert!(t.cmd("CAMERA 0").starts_with("ERR RANGE"));
    assert!(t.cmd("CAMERA 5").starts_with("ERR RANGE"));
    assert!(t.cmd("LIVE 9").starts_with("ERR RANGE"));
    assert_eq!(t.cmd("CAMERA 3"), "OK");
    assert_eq!(t.cmd("LIVE 2"), "OK");
    assert_eq!(t.cmd("STATUS"), "OK camera=2 live=1 frame=none");

    // READ before FREEZE.
    assert!(t.cmd("READ 0 16").starts_with("ERR NOFRAME"));

    // FREEZE, then READ whole and in part; bounds.
    let f = t.cmd("FREEZE");
    let w: Vec<&str> = f.split(' ').collect();
    assert_eq!(&w[..4], ["OK", "FRAME", "64", "48"], "{f}");
    let crc = u32::from_str_radix(w[4], 16).expect("crc");
    assert_eq!(
        t.cmd("STATUS"),
        format!("OK camera=2 live=0 frame={crc:08X}")
    );
    let mut frame = Vec::new();
    for off in (0..64 * 48).step_by(1024) {
        let d = t.cmd(&format!("READ {off} 1024"));
        let parts: Vec<&str> = d.split(' ').collect();
        assert_eq!(&parts[..3], ["DATA", &off.to_string(), "1024"], "{d}");
        let block = t.bytes(1024);
        assert_eq!(format!("{:08X}", crc32(&block)), parts[3]);
        frame.extend(block);
    }
    assert_eq!(crc32(&frame), crc, "the blocks make the frozen frame");
    assert!(t.cmd("READ 3000 200").starts_with("ERR RANGE"));
    assert!(t.cmd("READ 0 2048").starts_with("ERR RANGE"));

    // LOAD: a bad block is refused with ERR CRC, resent, and the last OK
    // comes once the whole image matches; READ then gives the loaded image.
    let img: Vec<u8> = (0..256u32).map(|i| (i * 7 % 251) as u8).collect();
    assert_eq!(t.cmd(&format!("LOAD 16 16 {:08X}", crc32(&img))), "OK");
    t.send(&encode_line(&format!(
        "WRITE 0 128 {:08X}",
        crc32(&img[..128]) ^ 1
    )));
    t.send(&img[..128]);
    assert!(t.line().starts_with("ERR CRC"));
    for off in [0usize, 128] {
        t.send(&encode_line(&format!(
            "WRITE {off} 128 {:08X}",
            crc32(&img[off..off + 128])
        )));
        t.send(&img[off..off + 128]);
        assert_eq!(t.line(), "OK");
    }
    assert_eq!(
        t.cmd("STATUS"),
        format!("OK camera=2 live=0 frame={:08X}", crc32(&img))
    );
    assert!(t.cmd("READ 0 256").starts_with("DATA 0 256"));
    assert_eq!(t.bytes(256), img);

    // A LOAD whose whole CRC is wrong ends in ERR CRC.
    assert_eq!(t.cmd("LOAD 16 8 00000000"), "OK");
    t.send(&encode_line(&format!(
        "WRITE 0 128 {:08X}",
        crc32(&img[..128])
    )));
    t.send(&img[..128]);
    assert!(t.line().starts_with("ERR CRC"));

    // INIT forgets the frame.
    assert_eq!(t.cmd("INIT"), "OK");
    assert!(t.cmd("STATUS").ends_with("frame=none"));
    assert!(t.cmd("READ 0 16").starts_with("ERR NOFRAME"));
}

#[test]
fn the_driver_loads_and_transfers_over_a_pty() {
    let sim = sim();
    let cfg = ClientConfig {
        timeout: Duration::from_millis(500),
        retries: 2,
        block: 700,
        baud: 921_600,
    };
    let mut g = VsgClient::open(sim.grabber_path(), 921_600, cfg).expect("connect");
    assert_eq!(g.info().map(|i| i.maxblock), Some(1024));
    let pixels: Vec<u8> = (0..40 * 30).map(|i| (i % 256) as u8).collect();
    let img = GreyImage::new(40, 30, pixels).expect("image");
    g.load(&img).expect("load");
    let back = g.transfer(&mut |_, _| true).expect("transfer");
    assert_eq!(back, img);
    assert!(g.status().expect("status").frame.is_some());
    // A frozen frame arrives whole, and STATUS knows its CRC.
    g.select_camera(3).expect("camera");
    let f = g.freeze().expect("freeze");
    let frame = g.transfer(&mut |_, _| true).expect("transfer");
    assert_eq!(crc32(frame.data()), f.crc);
    assert_eq!(g.status().expect("status").frame, Some(f.crc));
    let e = g.select_camera(7).expect_err("no camera 7");
    assert!(e.to_string().contains("ERR RANGE"), "{e}");
    assert!(e.to_string().contains(sim.grabber_path()), "{e}");
}

#[test]
fn wire_bytes_per_payload_byte_stay_below_1_01_with_the_default_block() {
    let sim = SimCell::start(SimOptions::new(256, 256)).expect("sim");
    let cfg = ClientConfig::from_profile(&vss::profile::GrabberConfig::default());
    assert_eq!(cfg.block, 16384, "the default block");
    let mut g = VsgClient::open(sim.grabber_path(), 921_600, cfg).expect("connect");
    let f = g.freeze().expect("freeze");
    let before = g.wire_stats();
    let img = g.transfer(&mut |_, _| true).expect("transfer");
    let after = g.wire_stats();
    assert_eq!(crc32(img.data()), f.crc);
    let wire = (after.tx + after.rx) - (before.tx + before.rx);
    let payload = after.payload - before.payload;
    assert_eq!(payload, 256 * 256);
    let ratio = wire as f64 / payload as f64;
    assert!(ratio <= 1.01, "{wire} wire bytes for {payload}: {ratio:.4}");
    assert!(ratio > 1.0, "headers and commands count too");
}
