//! The cell's hardware behind traits: the VSG/1 frame grabber
//! ([`FrameGrabber`], [`grabber::VsgClient`]), the relay board that switches
//! the lights ([`LightSwitch`], Numato and LCUS drivers), and the simulated
//! cell that speaks both protocols over real pseudo-terminals ([`sim`]).
//!
//! [`Cell`] ties them to a profile: it opens the serial ports the profile
//! names, or starts the embedded simulator and connects the very same drivers
//! to its pseudo-terminals, and it always knows which lights are on.

use std::io::{self, Read, Write};
use std::time::Duration;

pub mod cell;
#[cfg(feature = "genicam")]
pub mod genicam;
pub mod grabber;
pub mod holder;
pub mod lights;
pub mod protocol;
pub mod replay;
#[cfg(test)]
mod script;
pub mod sim;

pub use cell::{Capture, Cell};
pub use grabber::{FrameGrabber, VsgClient, WireStats};
pub use lights::{LcusBoard, LightSwitch, NumatoBoard};
pub use protocol::{ErrCode, FrameInfo, GrabberInfo, GrabberStatus};

/// Everything that can go wrong with the cell's devices. Each variant names
/// the port and says what to do.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    #[error(
        "{port}: cannot open the serial port: {source} — check the cable and the profile's port"
    )]
    Open {
        port: String,
        source: serialport::Error,
    },
    /// The port exists and another open file holds it (its lock): another
    /// console on this cell, a terminal program. `holder` is what
    /// [`holder::describe`] found.
    #[error("{port}: in use by {holder} — quit it there to use the port here")]
    Busy { port: String, holder: String },
    #[error(
        "{port}: the device vanished ({source}); everything saved so far is kept — \
         plug it back in and reconnect"
    )]
    Vanished { port: String, source: io::Error },
    #[error(
        "{port}: no reply to `{command}` within {timeout_ms} ms ({}) — \
         is the device on, and is the baud rate right?",
        tries(*attempts)
    )]
    Timeout {
        port: String,
        command: String,
        timeout_ms: u64,
        attempts: u32,
    },
    #[error("{port}: `{command}` was refused: ERR {code} {text}")]
    Device {
        port: String,
        command: String,
        code: ErrCode,
        text: String,
    },
    #[error(
        "{port}: garbled reply to `{command}` ({detail}) after {} — check the cable and the baud rate",
        tries(*attempts)
    )]
    Garbled {
        port: String,
        command: String,
        detail: String,
        attempts: u32,
    },
    #[error(
        "{port}: the block at byte {offset} failed its CRC {attempts} times — \
         the line is too noisy; check the cable"
    )]
    BlockCrc {
        port: String,
        offset: usize,
        attempts: u32,
    },
    #[error(
        "{port}: the frame's CRC {got:08X} does not match FREEZE's {expected:08X}; \
         nothing was saved — freeze again"
    )]
    FrameCrc {
        port: String,
        expected: u32,
        got: u32,
    },
    #[error("{port}: the grabber has no frozen frame (it may have been reset) — freeze again")]
    NoFrame { port: String },
    #[error("{port}: transfer cancelled at byte {done} of {total}; nothing was saved")]
    Cancelled {
        port: String,
        done: usize,
        total: usize,
    },
    #[error(
        "{port}: relay {relay} reads back {got}, expected {expected} — is the board's relay count right?"
    )]
    RelayMismatch {
        port: String,
        relay: String,
        expected: String,
        got: String,
    },
    #[error("{port}: {detail}")]
    Board { port: String, detail: String },
    #[error(
        "{port}: the board echoed `{command}` but sent no `>` prompt within {timeout_ms} ms ({}) — \
         raise the relay board's timeout_ms in the profile",
        tries(*attempts)
    )]
    NoPrompt {
        port: String,
        command: String,
        timeout_ms: u64,
        attempts: u32,
    },
    /// A GenICam camera (`src/rig/genicam.rs`, feature `genicam`): `gone`
    /// when it does not answer or sends nothing (the console then
    /// reconnects, as for a vanished port).
    #[error("{port}: {detail}")]
    Camera {
        port: String,
        detail: String,
        gone: bool,
    },
    #[error("{0}")]
    Config(String),
    #[error("simulator: {0}")]
    Sim(String),
}

/// "1 attempt", "3 attempts".
fn tries(n: u32) -> String {
    if n == 1 {
        "1 attempt".into()
    } else {
        format!("{n} attempts")
    }
}

impl RigError {
    /// Whether another program holds the port ([`RigError::Busy`]).
    pub fn is_busy(&self) -> bool {
        matches!(self, RigError::Busy { .. })
    }

    /// Whether the device has gone away (unplugged, powered off).
    pub fn is_vanished(&self) -> bool {
        matches!(
            self,
            RigError::Vanished { .. } | RigError::Camera { gone: true, .. }
        )
    }
}

/// A camera's identity and settings as it reports them (GenICam cameras;
/// the VSG/1 grabber does not say).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraState {
    /// The profile's id or address for it.
    pub id: String,
    pub vendor: String,
    pub model: String,
    pub serial: String,
    pub pixel_format: String,
    /// Exposure time (µs); NaN when the camera has none.
    pub exposure_us: f64,
    /// Gain (dB); NaN when the camera has none.
    pub gain_db: f64,
    /// Region of interest `[x, y, width, height]` (px).
    pub roi: [u32; 4],
    /// The camera's own frame rate (AcquisitionFrameRate, frames/s); NaN
    /// when it has none.
    pub frame_rate_hz: f64,
}

impl CameraState {
    /// One line for the console and the log: vendor, model, serial, pixel
    /// format, exposure, gain.
    pub fn summary(&self) -> String {
        let num = |v: f64, unit: &str, digits: usize| {
            if v.is_finite() {
                format!("{v:.digits$} {unit}")
            } else {
                format!("— {unit}")
            }
        };
        format!(
            "{} {} #{} {} exp {} gain {}",
            self.vendor,
            self.model,
            self.serial,
            self.pixel_format,
            num(self.exposure_us, "µs", 0),
            num(self.gain_db, "dB", 1)
        )
    }

    /// The exposure and gain as a frame's record in a session keeps them.
    pub fn frame_settings(&self) -> crate::session::FrameSettings {
        crate::session::FrameSettings::new(self.exposure_us, self.gain_db)
    }
}

/// A byte stream to a device with a settable read timeout: a serial port, a
/// pseudo-terminal, or scripted bytes in tests.
pub trait Link: Read + Write + Send {
    fn set_timeout(&mut self, timeout: Duration) -> io::Result<()>;
}

impl Link for Box<dyn serialport::SerialPort> {
    fn set_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        serialport::SerialPort::set_timeout(self.as_mut(), timeout).map_err(io::Error::from)
    }
}

#[cfg(unix)]
impl Link for serialport::TTYPort {
    fn set_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        serialport::SerialPort::set_timeout(self, timeout).map_err(io::Error::from)
    }
}

/// The serial port type the drivers use on real devices and ptys.
pub type SerialLink = Box<dyn serialport::SerialPort>;

/// How long [`open_serial`] waits for a port another open file holds
/// locked.
pub const BUSY_WAIT: Duration = Duration::from_millis(300);

/// Opens a serial device 8N1, no flow control, exclusively (serialport's
/// `TIOCEXCL` and `flock`).
///
/// A port found locked is tried again every 10 ms for [`BUSY_WAIT`]
/// before "in use" is the answer. The lock belongs to an open file, and a
/// process that starts a program copies its open files into the child
/// until the program is loaded (close-on-exec acts only then): a port
/// closed and opened again at once (a reconnect, a board opened twice in a
/// row) can find its own last lock still held by a child of some other
/// thread for that moment. Another program that holds the port is still
/// refused, after the wait.
pub fn open_serial(path: &str, baud: u32, timeout: Duration) -> Result<SerialLink, RigError> {
    if path.is_empty() {
        return Err(RigError::Config(
            "no serial port given: set `port` in the profile's [grabber] or [relay] section"
                .to_string(),
        ));
    }
    let start = std::time::Instant::now();
    loop {
        let r = serialport::new(path, baud)
            .timeout(timeout)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .open();
        match r {
            Err(e) if is_locked(&e) && start.elapsed() < BUSY_WAIT => {
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(e) if is_locked(&e) => {
                return Err(RigError::Busy {
                    port: path.to_string(),
                    holder: holder::describe(std::path::Path::new(path)),
                });
            }
            r => {
                return r.map_err(|source| RigError::Open {
                    port: path.to_string(),
                    source,
                });
            }
        }
    }
}

/// Whether serialport refused a port because another open file holds it:
/// its `flock` ("… exclusive lock …") or, for a caller without root, its
/// `TIOCEXCL` (`EBUSY`). serialport's only way of saying so is this kind
/// and text.
fn is_locked(e: &serialport::Error) -> bool {
    let d = e.description.to_ascii_lowercase();
    e.kind() == serialport::ErrorKind::NoDevice && (d.contains("lock") || d.contains("busy"))
}
