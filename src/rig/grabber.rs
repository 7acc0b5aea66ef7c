//! The frame grabber: [`FrameGrabber`] (the six basic operations of the
//! original access program, plus STATUS) and [`VsgClient`], the VSG/1 client
//! over any [`Link`] (serial port, pseudo-terminal, scripted bytes).
//!
//! What the shop floor needs from it (hardware.md §1): a timeout on every
//! reply, bounded retries of commands that are safe to repeat, a re-sync
//! after garbage, CRC checks per block and per frame with bad blocks re-read
//! at once (in blocks sized to the line's error rate: [`transfer`]),
//! progress with cancel, and a clear error naming the port when the device
//! vanishes.

use std::io::{self, ErrorKind};
use std::time::{Duration, Instant};

use super::protocol::{
    Command, ErrCode, FrameInfo, GrabberInfo, GrabberStatus, Reply, crc32, decode_line,
};
use super::{CameraState, Link, RigError, SerialLink, open_serial};
use crate::llv::GreyImage;

/// The operations every grabber offers.
pub trait FrameGrabber: Send {
    /// Identifies the grabber (model, frame size, cameras, largest block).
    fn hello(&mut self) -> Result<GrabberInfo, RigError>;
    /// 0: initialise.
    fn init(&mut self) -> Result<(), RigError>;
    /// 1: live picture from camera `cam` (1-based) on the grabber's monitor.
    fn live(&mut self, cam: u32) -> Result<(), RigError>;
    /// 2: digitise into the grabber's memory.
    fn freeze(&mut self) -> Result<FrameInfo, RigError>;
    /// 3: select camera `cam` (1-based).
    fn select_camera(&mut self, cam: u32) -> Result<(), RigError>;
    /// Checks, before anything is saved, that camera `cam` can deliver
    /// frames the cell uses. A GenICam camera is opened and its pixel
    /// format checked; a serial grabber's cameras need nothing beyond
    /// their count, which the caller checks from [`FrameGrabber::hello`].
    fn check_camera(&mut self, _cam: u32) -> Result<(), RigError> {
        Ok(())
    }
    /// 4: load an image into the grabber's memory.
    fn load(&mut self, img: &GreyImage) -> Result<(), RigError>;
    /// 5: transfer the frozen frame to the PC. `progress(done, total)` is
    /// called after every block; returning `false` cancels.
    fn transfer(
        &mut self,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError>;
    fn status(&mut self) -> Result<GrabberStatus, RigError>;
    /// The frame in the grabber's memory as the driver knows it: what the
    /// last FREEZE (or LOAD) reported, or the FREEZE a transfer made itself
    /// after a reset ([`VsgClient`]'s `transfer`). A transferred image has
    /// this frame's size and CRC.
    fn frame(&self) -> Option<FrameInfo>;
    /// The device path, for messages.
    fn port_name(&self) -> &str;
    /// Reopens the port after the device came back.
    fn reconnect(&mut self) -> Result<(), RigError>;
    /// Bytes moved so far.
    fn wire_stats(&self) -> WireStats;
    /// The selected camera's identity and settings, when the grabber can
    /// say (GenICam cameras); `None` for a VSG/1 grabber.
    fn camera_state(&self) -> Option<CameraState> {
        None
    }
    /// Sets the selected camera's exposure time (µs).
    fn set_exposure(&mut self, us: f64) -> Result<CameraState, RigError> {
        let _ = us;
        Err(self.no_settings())
    }
    /// Sets the selected camera's gain (dB).
    fn set_gain(&mut self, db: f64) -> Result<CameraState, RigError> {
        let _ = db;
        Err(self.no_settings())
    }
    /// Least time between two live-view frames, when the grabber sets it
    /// (the console's own otherwise).
    fn live_interval(&self) -> Option<Duration> {
        None
    }
    /// Why exposure and gain cannot be set here.
    fn no_settings(&self) -> RigError {
        RigError::Config(format!(
            "{}: this grabber does not set exposure or gain: set them on the camera",
            self.port_name()
        ))
    }
}

/// Counters of what went over the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WireStats {
    /// Bytes sent to the device.
    pub tx: u64,
    /// Bytes received from the device.
    pub rx: u64,
    /// Frame bytes delivered (good blocks only).
    pub payload: u64,
    /// Commands sent again after a timeout or garbage.
    pub retries: u64,
    /// Blocks that failed their CRC or came short.
    pub bad_blocks: u64,
    pub resyncs: u64,
    /// Times a block's answer stopped and the inter-byte timeout was waited.
    pub stalls: u64,
    /// Frames frozen again by a transfer after the grabber lost its frame.
    pub refreezes: u64,
}

impl WireStats {
    /// Bytes on the wire (both ways) per payload byte.
    pub fn overhead(&self) -> f64 {
        if self.payload == 0 {
            return f64::NAN;
        }
        (self.tx + self.rx) as f64 / self.payload as f64
    }
}

/// Settings of a [`VsgClient`].
#[derive(Clone, Debug)]
pub struct ClientConfig {
    /// Wait for the first byte of a reply.
    pub timeout: Duration,
    /// Retries of a command that is safe to repeat.
    pub retries: u32,
    /// Bytes per READ (capped by the grabber's maxblock); a noisy line
    /// gets smaller ones.
    pub block: u32,
    /// The line's baud rate: the inter-byte timeout inside an answer is a
    /// few byte times at it ([`transfer::inter_byte_for`]).
    pub baud: u32,
}

impl ClientConfig {
    pub fn from_profile(g: &crate::profile::GrabberConfig) -> ClientConfig {
        ClientConfig {
            timeout: Duration::from_millis(g.timeout_ms.max(1)),
            retries: g.retries,
            block: g.block.max(1),
            baud: g.baud.max(1),
        }
    }
}

/// A reply line longer than this is garbage.
const MAX_LINE: usize = 256;
/// Quiet time that ends a re-sync.
const QUIET: Duration = Duration::from_millis(40);
/// Tries of a command safe to repeat whose answers come garbled.
const GARBLED_TRIES: u32 = 12;
/// Late replies tolerated while waiting for the one to a command.
const MAX_STALE: u32 = 8;
/// The largest frame a reply may announce (guards allocations).
const MAX_FRAME: usize = 1 << 28;
/// Times one transfer gets its frame back after the grabber answered
/// NOFRAME ([`VsgClient::recover_frame`]): a grabber that loses the frame
/// more often than this within one transfer is failing.
const FRAME_RECOVERIES: u32 = 2;

/// Why reading a reply failed, before it becomes a [`RigError`].
enum ReadFail {
    Timeout,
    Vanished(io::Error),
    Garbage(String),
}

type Reopen<P> = Box<dyn FnMut() -> Result<P, RigError> + Send>;

/// A VSG/1 client over a byte stream.
pub struct VsgClient<P: Link> {
    /// `None` only while reconnecting: the old port is closed before the
    /// new one opens, since a serial port is opened exclusively.
    port: Option<P>,
    name: String,
    cfg: ClientConfig,
    /// Longest silence inside a reply line once it has started.
    gap: Duration,
    /// Longest silence inside a block's answer ([`transfer`]), and what
    /// it starts from (it doubles when the line's gaps prove longer).
    inter_byte: Duration,
    base_inter_byte: Duration,
    /// When bytes last came in.
    last_rx: Option<Instant>,
    /// Requests were given up on during a transfer: their answers may
    /// still be on the way.
    untracked: bool,
    info: Option<GrabberInfo>,
    frame: Option<FrameInfo>,
    /// The camera this client last selected (CAMERA or LIVE answered OK);
    /// `None` while the grabber's own choice is unknown (after connecting
    /// or INIT).
    camera: Option<u32>,
    /// The camera `frame` was digitised from by this client's own FREEZE;
    /// `None` for a frame it did not freeze itself (a LOAD, or one frozen
    /// by someone else) or froze with the camera unknown.
    frozen_from: Option<u32>,
    /// Received, not yet consumed bytes.
    rx: Vec<u8>,
    buf: Vec<u8>,
    stats: WireStats,
    reopen: Option<Reopen<P>>,
}

impl VsgClient<SerialLink> {
    /// Opens the grabber on a serial device (or a pseudo-terminal) and says
    /// HELLO. The client remembers the path for [`FrameGrabber::reconnect`].
    pub fn open(path: &str, baud: u32, cfg: ClientConfig) -> Result<Self, RigError> {
        let port = open_serial(path, baud, cfg.timeout)?;
        let (p, t) = (path.to_string(), cfg.timeout);
        let mut c = VsgClient::new(port, path, cfg);
        c.reopen = Some(Box::new(move || open_serial(&p, baud, t)));
        c.connect()?;
        Ok(c)
    }
}

impl<P: Link> VsgClient<P> {
    /// Wraps a stream; call [`VsgClient::connect`] before use.
    pub fn new(port: P, name: &str, cfg: ClientConfig) -> Self {
        let gap = (cfg.timeout / 5).clamp(Duration::from_millis(50), Duration::from_millis(500));
        let inter_byte = transfer::inter_byte_for(cfg.baud).min(gap);
        VsgClient {
            port: Some(port),
            name: name.to_string(),
            cfg,
            gap,
            inter_byte,
            base_inter_byte: inter_byte,
            last_rx: None,
            untracked: false,
            info: None,
            frame: None,
            camera: None,
            frozen_from: None,
            rx: Vec::new(),
            buf: vec![0; 65536],
            stats: WireStats::default(),
            reopen: None,
        }
    }

    /// Discards whatever the line holds (garbage on connect), then HELLO.
    pub fn connect(&mut self) -> Result<GrabberInfo, RigError> {
        self.camera = None;
        self.resync()?;
        self.hello()
    }

    /// The grabber as HELLO described it.
    pub fn info(&self) -> Option<&GrabberInfo> {
        self.info.as_ref()
    }

    /// The stream (tests inspect what was sent).
    pub fn port_mut(&mut self) -> Option<&mut P> {
        self.port.as_mut()
    }

    fn port(&mut self) -> io::Result<&mut P> {
        self.port
            .as_mut()
            .ok_or_else(|| io::Error::new(ErrorKind::NotConnected, "the port is closed"))
    }

    fn vanished(&self, source: io::Error) -> RigError {
        RigError::Vanished {
            port: self.name.clone(),
            source,
        }
    }

    /// Reads whatever arrives within `wait` into `rx`.
    fn fill(&mut self, wait: Duration) -> Result<(), ReadFail> {
        let port = self.port.as_mut().ok_or_else(|| {
            ReadFail::Vanished(io::Error::new(
                ErrorKind::NotConnected,
                "the port is closed",
            ))
        })?;
        port.set_timeout(wait.max(Duration::from_millis(1)))
            .map_err(ReadFail::Vanished)?;
        loop {
            match port.read(&mut self.buf) {
                Ok(0) => {
                    return Err(ReadFail::Vanished(io::Error::new(
                        ErrorKind::UnexpectedEof,
                        "end of file",
                    )));
                }
                Ok(n) => {
                    self.last_rx = Some(Instant::now());
                    self.stats.rx += n as u64;
                    self.rx
                        .extend_from_slice(self.buf.get(..n).unwrap_or_default());
                    return Ok(());
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                    return Err(ReadFail::Timeout);
                }
                Err(e) => return Err(ReadFail::Vanished(e)),
            }
        }
    }

    /// One line (without `\r\n`): the first byte may take `timeout`, the
    /// rest must follow without a gap.
    fn read_line(&mut self) -> Result<Vec<u8>, ReadFail> {
        let deadline = Instant::now() + self.cfg.timeout;
        // `rx[..seen]` holds no line end: after a read only the new bytes
        // are looked at.
        let mut seen = 0;
        loop {
            let found = self
                .rx
                .get(seen..)
                .and_then(|b| b.iter().position(|&b| b == b'\n'));
            if let Some(i) = found.map(|i| seen + i) {
                let mut line: Vec<u8> = self.rx.drain(..=i).collect();
                line.pop();
                if line.last() == Some(&b'\r') {
                    line.pop();
                }
                // Stray bytes before a line (a dropped `\n` earlier) make it
                // garbage; the checksum catches them.
                return Ok(line);
            }
            if self.rx.len() > MAX_LINE {
                return Err(ReadFail::Garbage(format!(
                    "{} bytes without a line end",
                    self.rx.len()
                )));
            }
            seen = self.rx.len();
            let wait = if self.rx.is_empty() {
                deadline.saturating_duration_since(Instant::now())
            } else {
                self.gap
            };
            if wait.is_zero() {
                return Err(ReadFail::Timeout);
            }
            match self.fill(wait) {
                Err(ReadFail::Timeout) if !self.rx.is_empty() => {
                    return Err(ReadFail::Garbage(format!(
                        "a line stopped after {} bytes",
                        self.rx.len()
                    )));
                }
                r => r?,
            }
        }
    }

    /// Exactly `n` raw bytes following a DATA line, without a gap.
    fn read_exact(&mut self, n: usize) -> Result<Vec<u8>, ReadFail> {
        while self.rx.len() < n {
            match self.fill(self.gap) {
                Err(ReadFail::Timeout) => {
                    return Err(ReadFail::Garbage(format!(
                        "a block stopped after {} of {n} bytes",
                        self.rx.len()
                    )));
                }
                r => r?,
            }
        }
        Ok(self.rx.drain(..n).collect())
    }

    fn read_reply(&mut self) -> Result<Reply, ReadFail> {
        let line = self.read_line()?;
        let text = decode_line(&line).map_err(|e| {
            ReadFail::Garbage(format!("{e} in {:?}", String::from_utf8_lossy(&line)))
        })?;
        Reply::parse(text).ok_or_else(|| ReadFail::Garbage(format!("unknown reply {text:?}")))
    }

    fn send_raw(&mut self, bytes: &[u8]) -> Result<(), RigError> {
        let timeout = self.cfg.timeout;
        let r = self.port().and_then(|p| {
            p.set_timeout(timeout)?;
            p.write_all(bytes)?;
            p.flush()
        });
        match r {
            Ok(()) => {
                self.stats.tx += bytes.len() as u64;
                Ok(())
            }
            Err(e) => Err(self.vanished(e)),
        }
    }

    fn send(&mut self, cmd: &Command) -> Result<(), RigError> {
        self.send_raw(&cmd.encode())
    }

    /// Re-sync after garbage: an empty line ends whatever the device was
    /// receiving, then everything is discarded until the line is quiet.
    pub fn resync(&mut self) -> Result<(), RigError> {
        self.stats.resyncs += 1;
        self.send_raw(b"\r\n")?;
        self.rx.clear();
        // A device that never stops talking is not waited on for ever.
        let give_up = Instant::now() + self.cfg.timeout.max(Duration::from_secs(2));
        while Instant::now() < give_up {
            match self.fill(QUIET) {
                Ok(()) => self.rx.clear(),
                Err(ReadFail::Timeout) => return Ok(()),
                Err(ReadFail::Vanished(e)) => return Err(self.vanished(e)),
                Err(ReadFail::Garbage(_)) => self.rx.clear(),
            }
        }
        self.rx.clear();
        Ok(())
    }

    /// Skips the payload of a DATA reply that answered an earlier command
    /// (it arrived late, after a stall).
    fn skip_stale(&mut self, len: u32) -> Result<(), ReadFail> {
        self.read_exact(len as usize).map(|_| ())
    }

    /// Sends `cmd` and returns the first reply `accept` takes (ERR replies
    /// are always taken). Retries commands safe to repeat after a timeout,
    /// garbage, or `ERR CHECKSUM` (the command was garbled on its way).
    fn exchange(
        &mut self,
        cmd: Command,
        accept: impl Fn(&Reply) -> bool,
    ) -> Result<Reply, RigError> {
        // Silence costs a reply timeout and gets the profile's retries; a
        // garbled answer proves the grabber is there and costs a re-sync
        // only, so a noisy line (a long HELLO reply is damaged more often
        // than not at a byte loss of 1e-2) gets more tries.
        let (max_silent, max_garbled) = if cmd.is_idempotent() {
            (
                self.cfg.retries + 1,
                (self.cfg.retries + 1).max(GARBLED_TRIES),
            )
        } else {
            (1, 1)
        };
        let (mut silent, mut garbled) = (0, 0);
        let mut last = None;
        let mut attempts = 0;
        while silent < max_silent && garbled < max_garbled {
            attempts += 1;
            if attempts > 1 {
                self.stats.retries += 1;
            }
            self.send(&cmd)?;
            let mut stale = 0;
            let fail = loop {
                match self.read_reply() {
                    // Late replies are few (one per earlier timeout); a flood
                    // of them is a confused device.
                    Ok(r)
                        if stale > MAX_STALE && !matches!(r, Reply::Err { .. }) && !accept(&r) =>
                    {
                        break ReadFail::Garbage(format!(
                            "{stale} replies that do not fit `{cmd}`"
                        ));
                    }
                    Ok(Reply::Data { len, .. }) => {
                        stale += 1;
                        if let Err(f) = self.skip_stale(len) {
                            break f;
                        }
                    }
                    Ok(Reply::Err {
                        code: ErrCode::Checksum,
                        text,
                    }) => break ReadFail::Garbage(format!("device saw a bad checksum {text}")),
                    // Only a READ is answered NOFRAME (hardware.md §1): this
                    // answers one given up on earlier (a transfer stopped by
                    // the first of several, its re-sync outwaited by the
                    // rest on a busy machine).
                    Ok(Reply::Err {
                        code: ErrCode::NoFrame,
                        ..
                    }) if !matches!(cmd, Command::Read { .. }) => {
                        stale += 1;
                        if stale > MAX_STALE {
                            break ReadFail::Garbage(format!(
                                "{stale} replies that do not fit `{cmd}`"
                            ));
                        }
                    }
                    Ok(r @ Reply::Err { .. }) => return self.device_err(&cmd, r),
                    Ok(r) if accept(&r) => return Ok(r),
                    // A late OK to an earlier command: keep listening.
                    Ok(_) => stale += 1,
                    Err(f) => break f,
                }
            };
            match fail {
                ReadFail::Vanished(e) => return Err(self.vanished(e)),
                ReadFail::Timeout => {
                    silent += 1;
                    last = None;
                }
                ReadFail::Garbage(d) => {
                    garbled += 1;
                    last = Some(d);
                }
            }
            self.resync()?;
        }
        Err(match last {
            None => RigError::Timeout {
                port: self.name.clone(),
                command: cmd.to_string(),
                timeout_ms: self.cfg.timeout.as_millis() as u64,
                attempts,
            },
            Some(detail) => RigError::Garbled {
                port: self.name.clone(),
                command: cmd.to_string(),
                detail,
                attempts,
            },
        })
    }

    fn device_err<T>(&self, cmd: &Command, r: Reply) -> Result<T, RigError> {
        match r {
            Reply::Err {
                code: ErrCode::NoFrame,
                ..
            } => Err(RigError::NoFrame {
                port: self.name.clone(),
            }),
            Reply::Err { code, text } => Err(RigError::Device {
                port: self.name.clone(),
                command: cmd.to_string(),
                code,
                text,
            }),
            other => Err(RigError::Garbled {
                port: self.name.clone(),
                command: cmd.to_string(),
                detail: format!("unexpected reply `{other}`"),
                attempts: 1,
            }),
        }
    }

    fn ok_plain(&mut self, cmd: Command) -> Result<(), RigError> {
        self.exchange(cmd, |r| matches!(r, Reply::Ok(s) if s.is_empty()))
            .map(|_| ())
    }

    fn garbled(&self, cmd: &str, r: &Reply) -> RigError {
        RigError::Garbled {
            port: self.name.clone(),
            command: cmd.to_string(),
            detail: format!("unexpected reply `{r}`"),
            attempts: 1,
        }
    }
}

impl<P: Link> FrameGrabber for VsgClient<P> {
    fn hello(&mut self) -> Result<GrabberInfo, RigError> {
        let r = self.exchange(
            Command::Hello,
            |r| matches!(r, Reply::Ok(s) if GrabberInfo::parse(s).is_some()),
        )?;
        let info = match &r {
            Reply::Ok(s) => GrabberInfo::parse(s),
            _ => None,
        }
        .ok_or_else(|| self.garbled("HELLO", &r))?;
        self.info = Some(info.clone());
        Ok(info)
    }

    fn init(&mut self) -> Result<(), RigError> {
        self.frame = None;
        self.frozen_from = None;
        self.camera = None;
        self.ok_plain(Command::Init)
    }

    fn live(&mut self, cam: u32) -> Result<(), RigError> {
        self.camera = None;
        self.ok_plain(Command::Live(cam))?;
        self.camera = Some(cam);
        Ok(())
    }

    /// FREEZE. When it had to be sent again, the answer taken may be the
    /// first FREEZE's, arriving late, while the grabber holds the second's
    /// frame (each freeze is a new exposure): STATUS then says which CRC
    /// the frame held now has, and the transfer checks that one.
    fn freeze(&mut self) -> Result<FrameInfo, RigError> {
        self.frame = None;
        self.frozen_from = None;
        let retries = self.stats.retries;
        let r = self.exchange(
            Command::Freeze,
            |r| matches!(r, Reply::Ok(s) if FrameInfo::parse(s).is_some()),
        )?;
        let mut f = match &r {
            Reply::Ok(s) => FrameInfo::parse(s),
            _ => None,
        }
        .ok_or_else(|| self.garbled("FREEZE", &r))?;
        if self.stats.retries > retries {
            // The answer to the last FREEZE, if it is still on its way, is
            // passed over as late by STATUS's exchange.
            let held = self.status()?.frame;
            f.crc = held.ok_or_else(|| RigError::NoFrame {
                port: self.name.clone(),
            })?;
        }
        self.frame = Some(f);
        self.frozen_from = self.camera;
        Ok(f)
    }

    fn select_camera(&mut self, cam: u32) -> Result<(), RigError> {
        self.camera = None;
        self.ok_plain(Command::Camera(cam))?;
        self.camera = Some(cam);
        Ok(())
    }

    fn load(&mut self, img: &GreyImage) -> Result<(), RigError> {
        self.frozen_from = None;
        let (w, h) = img.size();
        let data = img.data();
        let crc = crc32(data);
        let cmd = Command::Load {
            width: w as u32,
            height: h as u32,
            crc,
        };
        self.ok_plain(cmd)?;
        let maxblock = self.info.as_ref().map_or(u32::MAX, |i| i.maxblock.max(1));
        let block = self.cfg.block.min(maxblock).max(1) as usize;
        let mut off = 0;
        while off < data.len() {
            let chunk = data
                .get(off..(off + block).min(data.len()))
                .unwrap_or_default();
            let wcmd = Command::Write {
                off: off as u32,
                len: chunk.len() as u32,
                crc: crc32(chunk),
            };
            let mut bytes = wcmd.encode();
            bytes.extend_from_slice(chunk);
            self.send_raw(&bytes)?;
            match self.read_reply() {
                Ok(Reply::Ok(_)) => off += chunk.len(),
                Ok(r @ Reply::Err { .. }) => return self.device_err(&wcmd, r),
                Ok(r) => return Err(self.garbled(&wcmd.to_string(), &r)),
                Err(ReadFail::Vanished(e)) => return Err(self.vanished(e)),
                Err(ReadFail::Timeout) => {
                    return Err(RigError::Timeout {
                        port: self.name.clone(),
                        command: wcmd.to_string(),
                        timeout_ms: self.cfg.timeout.as_millis() as u64,
                        attempts: 1,
                    });
                }
                Err(ReadFail::Garbage(detail)) => {
                    return Err(RigError::Garbled {
                        port: self.name.clone(),
                        command: wcmd.to_string(),
                        detail,
                        attempts: 1,
                    });
                }
            }
        }
        self.frame = Some(FrameInfo {
            width: w as u32,
            height: h as u32,
            crc,
        });
        Ok(())
    }

    fn transfer(
        &mut self,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        let frame = match self.frame {
            Some(f) => f,
            None => {
                // Someone else froze (a second console, the front panel):
                // the grabber knows the CRC, HELLO the size.
                let st = self.status()?;
                let info = match &self.info {
                    Some(i) => i.clone(),
                    None => self.hello()?,
                };
                let crc = st.frame.ok_or_else(|| RigError::NoFrame {
                    port: self.name.clone(),
                })?;
                FrameInfo {
                    width: info.width,
                    height: info.height,
                    crc,
                }
            }
        };
        self.read_frame_recovering(frame, progress)
    }

    fn status(&mut self) -> Result<GrabberStatus, RigError> {
        let r = self.exchange(
            Command::Status,
            |r| matches!(r, Reply::Ok(s) if GrabberStatus::parse(s).is_some()),
        )?;
        match &r {
            Reply::Ok(s) => GrabberStatus::parse(s),
            _ => None,
        }
        .ok_or_else(|| self.garbled("STATUS", &r))
    }

    fn frame(&self) -> Option<FrameInfo> {
        self.frame
    }

    fn port_name(&self) -> &str {
        &self.name
    }

    fn reconnect(&mut self) -> Result<(), RigError> {
        let Some(reopen) = self.reopen.as_mut() else {
            return Err(RigError::Config(format!(
                "{}: this grabber connection cannot be reopened",
                self.name
            )));
        };
        // Close first: the port is held exclusively.
        self.port = None;
        self.port = Some(reopen()?);
        self.rx.clear();
        self.frame = None;
        self.frozen_from = None;
        self.connect().map(|_| ())
    }

    fn wire_stats(&self) -> WireStats {
        self.stats
    }
}

#[cfg(test)]
mod tests;
pub mod transfer;
