//! The simulated VSG/1 grabber: the device side of its pseudo-terminal.
//! It answers exactly as hardware.md §1 says, digitises the shared scene at
//! FREEZE, and injects the faults it was started with.

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serialport::TTYPort;

use super::Scene;
use super::faults::{FaultState, Faults, Outgoing};
use crate::rig::protocol::{
    Command, ErrCode, FrameInfo, GrabberInfo, GrabberStatus, Reply, crc32, decode_line,
};

/// How often the device looks at its stop flag.
const POLL: Duration = Duration::from_millis(25);
/// A command line longer than this is noise and is dropped.
const MAX_LINE: usize = 1024;

/// The line went away (unplug fault or stop).
struct Gone;

struct Load {
    width: u32,
    height: u32,
    crc: u32,
    data: Vec<u8>,
    filled: usize,
}

struct Grabber<'a> {
    port: TTYPort,
    scene: &'a Scene,
    stop: &'a AtomicBool,
    faults: FaultState,
    camera: u32,
    live: bool,
    frame: Option<(FrameInfo, Vec<u8>)>,
    load: Option<Load>,
    /// A WRITE waiting for its raw bytes.
    pending: Option<(u32, u32, u32)>,
    shots: u64,
}

/// Serves the grabber until stopped or unplugged.
pub(super) fn serve(port: TTYPort, scene: &Scene, faults: Faults, stop: &AtomicBool) {
    let mut g = Grabber {
        port,
        scene,
        stop,
        faults: FaultState::new(faults, scene.opts.seed),
        camera: 1,
        live: false,
        frame: None,
        load: None,
        pending: None,
        shots: 0,
    };
    let _ = g.run();
}

impl Grabber<'_> {
    fn run(&mut self) -> Result<(), Gone> {
        let _ = serialport::SerialPort::set_timeout(&mut self.port, POLL);
        let garbage = self.faults.garbage();
        if !garbage.is_empty() {
            self.send_raw(&garbage)?;
        }
        let mut inbuf: Vec<u8> = Vec::new();
        let mut buf = vec![0u8; 65536];
        while !self.stop.load(Ordering::SeqCst) {
            match self.port.read(&mut buf) {
                Ok(0) => std::thread::sleep(POLL),
                Ok(n) => inbuf.extend_from_slice(buf.get(..n).unwrap_or_default()),
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                    ) => {}
                // No client has the line open: wait for one.
                Err(_) => std::thread::sleep(POLL),
            }
            self.process(&mut inbuf)?;
        }
        Ok(())
    }

    fn process(&mut self, inbuf: &mut Vec<u8>) -> Result<(), Gone> {
        loop {
            if let Some((off, len, crc)) = self.pending {
                if inbuf.len() < len as usize {
                    return Ok(());
                }
                let payload: Vec<u8> = inbuf.drain(..len as usize).collect();
                self.pending = None;
                let reply = self.write_block(off, crc, &payload);
                self.reply(&reply)?;
                continue;
            }
            let Some(i) = inbuf.iter().position(|&b| b == b'\n') else {
                if inbuf.len() > MAX_LINE {
                    inbuf.clear();
                }
                return Ok(());
            };
            let mut line: Vec<u8> = inbuf.drain(..=i).collect();
            line.pop();
            if line.last() == Some(&b'\r') {
                line.pop();
            }
            // An empty line is a re-sync: it only ends what came before.
            if line.is_empty() {
                continue;
            }
            let reply = match decode_line(&line) {
                Err(_) => Reply::err(ErrCode::Checksum, "bad line checksum"),
                Ok(text) => match Command::parse(text) {
                    None => Reply::err(ErrCode::BadCmd, "unknown command"),
                    Some(cmd) => match self.command(cmd)? {
                        Some(r) => r,
                        None => continue,
                    },
                },
            };
            self.reply(&reply)?;
        }
    }

    fn reply(&mut self, r: &Reply) -> Result<(), Gone> {
        self.send(&r.encode())
    }

    /// Runs one command; `None` when the reply comes later (WRITE) or was
    /// already sent (READ).
    fn command(&mut self, cmd: Command) -> Result<Option<Reply>, Gone> {
        let o = &self.scene.opts;
        let ok = |s: String| Some(Reply::Ok(s));
        let camera_ok = |n: u32| (1..=o.cameras).contains(&n);
        Ok(match cmd {
            Command::Hello => ok(GrabberInfo {
                model: "VSS-SIM".into(),
                width: o.width,
                height: o.height,
                depth: 8,
                cameras: o.cameras,
                maxblock: o.maxblock,
            }
            .format()),
            Command::Init => {
                self.live = false;
                self.frame = None;
                self.load = None;
                ok(String::new())
            }
            Command::Live(n) | Command::Camera(n) if !camera_ok(n) => Some(Reply::err(
                ErrCode::Range,
                &format!("camera {n} is not 1..{}", o.cameras),
            )),
            Command::Live(n) => {
                self.camera = n;
                self.live = true;
                ok(String::new())
            }
            Command::Camera(n) => {
                self.camera = n;
                ok(String::new())
            }
            Command::Freeze => {
                if let Some(d) = self
                    .faults
                    .faults
                    .slow_freeze
                    .filter(|_| !self.faults.slow_freeze_done)
                {
                    self.faults.slow_freeze_done = true;
                    self.pause(d);
                }
                self.live = false;
                self.shots += 1;
                let data = self
                    .scene
                    .frame(self.camera, self.scene.relays(), self.shots);
                let info = FrameInfo {
                    width: o.width,
                    height: o.height,
                    crc: crc32(&data),
                };
                self.frame = Some((info, data));
                ok(info.format())
            }
            Command::Status => ok(GrabberStatus {
                camera: self.camera,
                live: self.live,
                frame: self.frame.as_ref().map(|(f, _)| f.crc),
            }
            .format()),
            Command::Load { width, height, crc } => {
                let n = width as usize * height as usize;
                if width == 0 || height == 0 || width > o.width * 4 || height > o.height * 4 {
                    Some(Reply::err(ErrCode::Range, "image size"))
                } else {
                    self.load = Some(Load {
                        width,
                        height,
                        crc,
                        data: vec![0; n],
                        filled: 0,
                    });
                    ok(String::new())
                }
            }
            Command::Write { off, len, crc } => {
                let fits = self
                    .load
                    .as_ref()
                    .is_some_and(|l| (off as usize).saturating_add(len as usize) <= l.data.len());
                if len > o.maxblock {
                    Some(Reply::err(ErrCode::Range, "block larger than maxblock"))
                } else if !fits {
                    // The bytes still follow on the wire: swallow them.
                    self.pending = Some((off, len, crc));
                    self.load = None;
                    None
                } else {
                    self.pending = Some((off, len, crc));
                    None
                }
            }
            Command::Read { off, len } => {
                self.read(off, len)?;
                None
            }
        })
    }

    fn write_block(&mut self, off: u32, crc: u32, payload: &[u8]) -> Reply {
        let Some(load) = self.load.as_mut() else {
            return Reply::err(ErrCode::Range, "WRITE outside a LOAD");
        };
        if crc32(payload) != crc {
            return Reply::err(ErrCode::Crc, "block CRC");
        }
        let start = off as usize;
        if let Some(dst) = load.data.get_mut(start..start + payload.len()) {
            dst.copy_from_slice(payload);
        }
        if start == load.filled {
            load.filled += payload.len();
        }
        if load.filled < load.data.len() {
            return Reply::Ok(String::new());
        }
        let whole = crc32(&load.data);
        let info = FrameInfo {
            width: load.width,
            height: load.height,
            crc: load.crc,
        };
        if whole != load.crc {
            self.load = None;
            return Reply::err(ErrCode::Crc, "image CRC");
        }
        let data = std::mem::take(&mut load.data);
        self.load = None;
        self.frame = Some((info, data));
        Reply::Ok(String::new())
    }

    /// Goes silent for `d` (or until the simulator stops).
    fn pause(&self, d: Duration) {
        let until = Instant::now() + d;
        while Instant::now() < until && !self.stop.load(Ordering::SeqCst) {
            std::thread::sleep(POLL.min(until.saturating_duration_since(Instant::now())));
        }
    }

    fn read(&mut self, off: u32, len: u32) -> Result<(), Gone> {
        if off > 0 && self.faults.faults.stall.is_some() && !self.faults.stall_done {
            self.faults.stall_done = true;
            self.pause(self.faults.faults.stall.unwrap_or_default());
        }
        if off > 0 && self.faults.faults.reset && !self.faults.reset_done {
            self.faults.reset_done = true;
            self.camera = 1;
            self.live = false;
            self.frame = None;
            self.load = None;
        }
        let Some((_, data)) = &self.frame else {
            return self.reply(&Reply::err(ErrCode::NoFrame, "no frame frozen"));
        };
        if len > self.scene.opts.maxblock {
            return self.reply(&Reply::err(ErrCode::Range, "block larger than maxblock"));
        }
        let (s, e) = (off as usize, off as usize + len as usize);
        let Some(block) = data.get(s..e) else {
            return self.reply(&Reply::err(ErrCode::Range, "beyond the frame"));
        };
        let mut out = Reply::Data {
            off,
            len,
            crc: crc32(block),
        }
        .encode();
        out.extend_from_slice(block);
        self.send(&out)
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        match self.faults.outgoing(bytes) {
            Outgoing::Send(b) => self.send_raw(&b),
            Outgoing::SendThenUnplug(b) => {
                self.send_raw(&b)?;
                // Give the bytes time to reach the client before the line
                // goes dead, as a cable pulled mid-frame would.
                std::thread::sleep(Duration::from_millis(20));
                Err(Gone)
            }
        }
    }

    /// Writes everything, waiting while the client is slow to read.
    fn send_raw(&mut self, mut bytes: &[u8]) -> Result<(), Gone> {
        while !bytes.is_empty() {
            if self.stop.load(Ordering::SeqCst) {
                return Err(Gone);
            }
            match self.port.write(bytes) {
                Ok(n) => bytes = bytes.get(n..).unwrap_or_default(),
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                    ) => {}
                Err(_) => return Err(Gone),
            }
        }
        Ok(())
    }
}
