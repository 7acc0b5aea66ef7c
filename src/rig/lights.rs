//! The relay board that switches the lights: [`LightSwitch`], the Numato
//! driver ([`NumatoBoard`]) and the LCUS/CH340 driver ([`LcusBoard`], in
//! `lights/lcus.rs`: binary frames, no replies, so every process sends the
//! whole mask and the remembered state only reports). The
//! board kind is a profile setting.
//!
//! Numato: every command is sent, then the reply is read up to the `>`
//! prompt that follows *this command's echo* — a prompt may come tens of
//! milliseconds after the echo, and a late prompt of an earlier command is
//! skipped rather than taken for this one's. A re-sync (after silence or a
//! garbled answer) ends any half-typed line with a bare CR and waits for the
//! board's prompt before the line goes quiet. The mask width of `readall`
//! and `writeall` follows the board's size (relays / 4 hex digits, at least
//! 2), from the profile's `channels` or learned from `readall`; every switch
//! is read back and compared.

use std::io::{self, ErrorKind};
use std::time::{Duration, Instant};

use super::protocol::{
    NumatoCommand, numato_channels_of_digits, numato_mask_digits, numato_parse_mask,
    numato_parse_state, numato_reply, numato_split,
};
use super::{Link, RigError, SerialLink, open_serial};

mod lcus;
#[cfg(test)]
mod tests;

pub use lcus::{LastSet, LcusBoard, lcus_state_file};

/// A board of relays, numbered from 0.
pub trait LightSwitch: Send {
    /// Switches one relay and confirms it (where the board can tell).
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError>;
    /// Sets all relays at once: bit N = relay N.
    fn set_mask(&mut self, mask: u32) -> Result<(), RigError>;
    /// The relays that are on: read from the board, or, for a board that
    /// cannot be read ([`LightSwitch::reads_back`] false), what vss last set
    /// (none when that is not known).
    fn read_mask(&mut self) -> Result<u32, RigError>;
    /// Whether [`LightSwitch::read_mask`] asks the board.
    fn reads_back(&self) -> bool {
        true
    }
    /// For a board that cannot be read: what vss last set on it, and when.
    fn last_set(&self) -> Option<LastSet> {
        None
    }
    /// Something the operator should know about the board's remembered
    /// state (an LCUS state file that was ignored, and why).
    fn note(&self) -> Option<String> {
        None
    }
    fn port_name(&self) -> &str;
}

/// Attempts of a Numato command whose answer was garbled or missing.
const ATTEMPTS: u32 = 3;
/// Longest reply before the prompt; anything longer is garbage.
const MAX_REPLY: usize = 256;
/// Quiet time that ends a drain.
const QUIET: Duration = Duration::from_millis(30);

/// Why one try of a Numato command got no usable answer.
enum Miss {
    /// Nothing came back.
    Silent,
    /// The echo came, the prompt did not.
    NoPrompt,
    /// Something else came: what.
    Garbled(String),
}

/// A Numato Lab USB relay module (or the simulated board).
pub struct NumatoBoard<P: Link> {
    port: P,
    name: String,
    timeout: Duration,
    rx: Vec<u8>,
    /// The relay count the profile gives (`channels`), if it does.
    channels: Option<u32>,
    /// Hex digits of `readall`/`writeall`: from `channels`, else learned
    /// from the first `readall`.
    digits: Option<usize>,
}

impl NumatoBoard<SerialLink> {
    /// Opens the board on a serial device, checks that it answers `ver` and
    /// learns (or checks against `channels`) its size from `readall`.
    pub fn open(
        path: &str,
        baud: u32,
        timeout: Duration,
        channels: Option<u32>,
    ) -> Result<Self, RigError> {
        let port = open_serial(path, baud, timeout)?;
        let mut b = NumatoBoard::new(port, path, timeout, channels);
        b.connect()?;
        Ok(b)
    }
}

/// Where `needle` first occurs in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    if needle.is_empty() {
        return Some(0);
    }
    hay.windows(needle.len()).position(|w| w == needle)
}

impl<P: Link> NumatoBoard<P> {
    pub fn new(port: P, name: &str, timeout: Duration, channels: Option<u32>) -> Self {
        NumatoBoard {
            port,
            name: name.to_string(),
            timeout,
            rx: Vec::new(),
            channels,
            digits: channels.map(numato_mask_digits),
        }
    }

    /// Re-syncs, asks the firmware version and learns the board's size.
    pub fn connect(&mut self) -> Result<String, RigError> {
        self.sync()?;
        let v = self.version()?;
        self.read_mask()?;
        Ok(v)
    }

    /// The firmware version (`ver`).
    pub fn version(&mut self) -> Result<String, RigError> {
        let lines = self.command(&NumatoCommand::Ver)?;
        match lines.as_slice() {
            [v] => Ok(v.clone()),
            _ => Err(self.board_err(format!("unexpected reply to `ver`: {lines:?}"))),
        }
    }

    /// The relays of the board, as the profile gives them or `readall`
    /// showed (`None` before the first `readall` without `channels`).
    pub fn channels(&self) -> Option<u32> {
        self.channels.or(self.digits.map(numato_channels_of_digits))
    }

    fn board_err(&self, detail: String) -> RigError {
        RigError::Board {
            port: self.name.clone(),
            detail,
        }
    }

    fn vanished(&self, source: io::Error) -> RigError {
        RigError::Vanished {
            port: self.name.clone(),
            source,
        }
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), RigError> {
        let r = self
            .port
            .set_timeout(self.timeout)
            .and_then(|()| self.port.write_all(bytes))
            .and_then(|()| self.port.flush());
        r.map_err(|e| self.vanished(e))
    }

    /// Reads what arrives within `wait` into `rx`; `false` on silence.
    fn fill(&mut self, wait: Duration) -> Result<bool, RigError> {
        let mut buf = [0u8; 256];
        self.port
            .set_timeout(wait.max(Duration::from_millis(1)))
            .map_err(|e| self.vanished(e))?;
        loop {
            match self.port.read(&mut buf) {
                Ok(0) => return Err(self.vanished(ErrorKind::UnexpectedEof.into())),
                Ok(n) => {
                    self.rx.extend_from_slice(buf.get(..n).unwrap_or_default());
                    return Ok(true);
                }
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                    return Ok(false);
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(self.vanished(e)),
            }
        }
    }

    /// Discards input until the line is quiet.
    fn drain(&mut self) -> Result<(), RigError> {
        let give_up = Instant::now() + self.timeout.max(Duration::from_millis(500));
        while Instant::now() < give_up {
            self.rx.clear();
            if !self.fill(QUIET)? {
                break;
            }
        }
        self.rx.clear();
        Ok(())
    }

    /// Ends a half-typed line with a bare CR, waits (up to the reply
    /// timeout) for the prompt that answers it, then for quiet.
    fn sync(&mut self) -> Result<(), RigError> {
        self.write(b"\r")?;
        self.rx.clear();
        let deadline = Instant::now() + self.timeout;
        while !self.rx.contains(&b'>') {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            self.fill(left)?;
        }
        self.drain()
    }

    /// Sends a command and returns the reply lines between the echo and the
    /// `>` prompt. Every Numato command is safe to repeat (switching a relay
    /// to a state twice leaves it there), so a garbled or missing answer is
    /// tried again after a re-sync.
    fn command(&mut self, cmd: &NumatoCommand) -> Result<Vec<String>, RigError> {
        let text = cmd
            .text()
            .ok_or_else(|| self.board_err(format!("{cmd:?}: not a command this board takes")))?;
        let mut last = Miss::Silent;
        let mut echoed = false;
        for attempt in 1..=ATTEMPTS {
            if attempt > 1 {
                self.sync()?;
            }
            match self.command_once(&text)? {
                Ok(lines) => return Ok(lines),
                Err(m) => {
                    echoed |= matches!(m, Miss::NoPrompt);
                    last = m;
                }
            }
        }
        // A board that echoed the command in any try but never prompted in
        // time is slow, not silent: say that, not "no reply".
        if echoed && matches!(last, Miss::Silent) {
            last = Miss::NoPrompt;
        }
        let (port, timeout_ms) = (self.name.clone(), self.timeout.as_millis() as u64);
        Err(match last {
            Miss::Silent => RigError::Timeout {
                port,
                command: text,
                timeout_ms,
                attempts: ATTEMPTS,
            },
            Miss::NoPrompt => RigError::NoPrompt {
                port,
                command: text,
                timeout_ms,
                attempts: ATTEMPTS,
            },
            Miss::Garbled(detail) => RigError::Garbled {
                port,
                command: text,
                detail,
                attempts: ATTEMPTS,
            },
        })
    }

    /// One try: the reply is what lies between this command's echo and the
    /// next prompt; whatever came before the echo (a late answer to an
    /// earlier command) is skipped.
    fn command_once(&mut self, text: &str) -> Result<Result<Vec<String>, Miss>, RigError> {
        self.rx.clear();
        self.write(format!("{text}\r").as_bytes())?;
        let deadline = Instant::now() + self.timeout;
        loop {
            if let Some((used, reply)) = numato_reply(text, &self.rx) {
                self.rx.drain(..used);
                return Ok(reply.map_err(|e| Miss::Garbled(e.to_string())));
            }
            if self.rx.len() > MAX_REPLY {
                let got = String::from_utf8_lossy(&self.rx).into_owned();
                self.drain()?;
                return Ok(Err(Miss::Garbled(format!("no prompt in {got:?}"))));
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(Err(self.miss(text)));
            }
            self.fill(left)?;
        }
    }

    /// What a try that timed out got.
    fn miss(&self, text: &str) -> Miss {
        if find(&self.rx, text.as_bytes()).is_some() {
            return Miss::NoPrompt;
        }
        if self.rx.is_empty() {
            return Miss::Silent;
        }
        let got = || format!("{:?} without a prompt", String::from_utf8_lossy(&self.rx));
        // A prompt after something else than the echo: the echo was wrong.
        let Some(last) = self.rx.iter().rposition(|&b| b == b'>') else {
            return Miss::Garbled(got());
        };
        let upto = self.rx.get(..last).unwrap_or_default();
        let start = upto.iter().rposition(|&b| b == b'>').map_or(0, |j| j + 1);
        match numato_split(text, upto.get(start..).unwrap_or_default()) {
            Err(e) => Miss::Garbled(e.to_string()),
            Ok(_) => Miss::Garbled(got()),
        }
    }

    fn expect_empty(&self, cmd: &NumatoCommand, lines: &[String]) -> Result<(), RigError> {
        if lines.is_empty() {
            Ok(())
        } else {
            Err(self.board_err(format!("unexpected reply to {cmd:?}: {lines:?}")))
        }
    }

    /// `relay read N`.
    pub fn read(&mut self, relay: u32) -> Result<bool, RigError> {
        let lines = self.command(&NumatoCommand::Read(relay))?;
        numato_parse_state(&lines).map_err(|e| self.board_err(format!("relay read {relay}: {e}")))
    }

    /// The width of the board's masks: known, or learned now.
    fn digits(&mut self) -> Result<usize, RigError> {
        match self.digits {
            Some(d) => Ok(d),
            None => {
                self.read_mask()?;
                self.digits
                    .ok_or_else(|| self.board_err("`relay readall` gave no mask width".into()))
            }
        }
    }
}

impl<P: Link> LightSwitch for NumatoBoard<P> {
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
        if let Some(c) = self.channels().filter(|&c| relay >= c) {
            return Err(self.board_err(format!(
                "relay {relay} does not exist on this {c}-relay board"
            )));
        }
        let cmd = if on {
            NumatoCommand::On(relay)
        } else {
            NumatoCommand::Off(relay)
        };
        let lines = self.command(&cmd)?;
        self.expect_empty(&cmd, &lines)?;
        let got = self.read(relay)?;
        if got != on {
            let s = |b: bool| if b { "on" } else { "off" }.to_string();
            return Err(RigError::RelayMismatch {
                port: self.name.clone(),
                relay: relay.to_string(),
                expected: s(on),
                got: s(got),
            });
        }
        Ok(())
    }

    fn set_mask(&mut self, mask: u32) -> Result<(), RigError> {
        let digits = self.digits()?;
        let cmd = NumatoCommand::WriteAll { mask, digits };
        if cmd.text().is_none() {
            return Err(self.board_err(format!(
                "relay mask {mask:x} names relays beyond this {}-relay board",
                numato_channels_of_digits(digits)
            )));
        }
        let lines = self.command(&cmd)?;
        self.expect_empty(&cmd, &lines)?;
        let got = self.read_mask()?;
        if got != mask {
            return Err(RigError::RelayMismatch {
                port: self.name.clone(),
                relay: "mask".into(),
                expected: format!("{mask:0digits$x}"),
                got: format!("{got:0digits$x}"),
            });
        }
        Ok(())
    }

    fn read_mask(&mut self) -> Result<u32, RigError> {
        let lines = self.command(&NumatoCommand::ReadAll)?;
        let (mask, digits) =
            numato_parse_mask(&lines).map_err(|e| self.board_err(format!("relay readall: {e}")))?;
        match self.channels {
            Some(c) if digits != numato_mask_digits(c) => {
                return Err(self.board_err(format!(
                    "the profile gives channels = {c}, but `relay readall` answers {} hex digits, \
                     as a {}-relay board does: set [relay] channels to the board's relay count",
                    digits,
                    numato_channels_of_digits(digits)
                )));
            }
            Some(_) => {}
            None => self.digits = Some(digits),
        }
        Ok(mask)
    }

    fn port_name(&self) -> &str {
        &self.name
    }
}
