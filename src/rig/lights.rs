//! The relay board that switches the lights: [`LightSwitch`], the Numato
//! driver ([`NumatoBoard`]: echo, `\n\r`, `>` prompt, read-back after every
//! switch) and the LCUS/CH340 driver ([`LcusBoard`]: binary frames, no
//! replies, state tracked here). The board kind is a profile setting.

use std::io::{self, ErrorKind};
use std::time::{Duration, Instant};

use super::protocol::{
    NumatoCommand, lcus_frame, numato_parse_mask, numato_parse_state, numato_split,
};
use super::{Link, RigError, SerialLink, open_serial};

/// A board of relays, numbered from 0.
pub trait LightSwitch: Send {
    /// Switches one relay and confirms it (where the board can tell).
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError>;
    /// Sets all relays at once: bit N = relay N.
    fn set_mask(&mut self, mask: u32) -> Result<(), RigError>;
    /// The relays that are on.
    fn read_mask(&mut self) -> Result<u32, RigError>;
    fn port_name(&self) -> &str;
}

/// Repeats of a Numato command whose answer was garbled or missing.
const RETRIES: u32 = 2;
/// Longest reply before the prompt; anything longer is garbage.
const MAX_REPLY: usize = 256;

/// A Numato Lab USB relay module (or the simulated board).
pub struct NumatoBoard<P: Link> {
    port: P,
    name: String,
    timeout: Duration,
    rx: Vec<u8>,
}

impl NumatoBoard<SerialLink> {
    /// Opens the board on a serial device and checks that it answers `ver`.
    pub fn open(path: &str, baud: u32, timeout: Duration) -> Result<Self, RigError> {
        let port = open_serial(path, baud, timeout)?;
        let mut b = NumatoBoard::new(port, path, timeout);
        b.connect()?;
        Ok(b)
    }
}

impl<P: Link> NumatoBoard<P> {
    pub fn new(port: P, name: &str, timeout: Duration) -> Self {
        NumatoBoard {
            port,
            name: name.to_string(),
            timeout,
            rx: Vec::new(),
        }
    }

    /// Clears a half-typed command with a bare `\r`, discards the answer,
    /// and asks the firmware version.
    pub fn connect(&mut self) -> Result<String, RigError> {
        self.write(b"\r")?;
        self.drain()?;
        self.version()
    }

    /// The firmware version (`ver`).
    pub fn version(&mut self) -> Result<String, RigError> {
        let lines = self.command(&NumatoCommand::Ver)?;
        match lines.as_slice() {
            [v] => Ok(v.clone()),
            _ => Err(self.board_err(format!("unexpected reply to `ver`: {lines:?}"))),
        }
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

    /// Discards input until the line is quiet.
    fn drain(&mut self) -> Result<(), RigError> {
        let give_up = Instant::now() + self.timeout.max(Duration::from_millis(500));
        let mut buf = [0u8; 256];
        self.rx.clear();
        while Instant::now() < give_up {
            self.port
                .set_timeout(Duration::from_millis(30))
                .map_err(|e| self.vanished(e))?;
            match self.port.read(&mut buf) {
                Ok(0) => return Err(self.vanished(ErrorKind::UnexpectedEof.into())),
                Ok(_) => {}
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                    return Ok(());
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(self.vanished(e)),
            }
        }
        Ok(())
    }

    /// Sends a command and returns the reply lines between the echo and the
    /// `>` prompt. Every Numato command is safe to repeat (switching a relay
    /// to a state twice leaves it there), so a garbled or missing answer is
    /// retried after clearing the line.
    fn command(&mut self, cmd: &NumatoCommand) -> Result<Vec<String>, RigError> {
        let text = cmd
            .text()
            .ok_or_else(|| self.board_err(format!("{cmd:?}: no such relay on a Numato board")))?;
        let mut attempt = 0;
        loop {
            attempt += 1;
            match self.command_once(&text) {
                Err(RigError::Timeout { .. } | RigError::Board { .. }) if attempt <= RETRIES => {
                    // A bare CR ends any half-typed line; then drop the noise.
                    self.write(b"\r")?;
                    self.drain()?;
                }
                r => return r,
            }
        }
    }

    fn command_once(&mut self, text: &str) -> Result<Vec<String>, RigError> {
        let text = text.to_string();
        self.rx.clear();
        self.write(format!("{text}\r").as_bytes())?;
        let deadline = Instant::now() + self.timeout;
        let mut buf = [0u8; 256];
        loop {
            if let Some(i) = self.rx.iter().position(|&b| b == b'>') {
                let raw: Vec<u8> = self.rx.drain(..=i).collect();
                let body = raw.get(..i).unwrap_or_default();
                return numato_split(&text, body)
                    .map_err(|e| self.board_err(format!("`{text}`: {e}")));
            }
            if self.rx.len() > MAX_REPLY {
                let got = String::from_utf8_lossy(&self.rx).into_owned();
                self.drain()?;
                return Err(self.board_err(format!("`{text}`: no prompt in {got:?}")));
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(RigError::Timeout {
                    port: self.name.clone(),
                    command: text,
                    timeout_ms: self.timeout.as_millis() as u64,
                    attempts: 1,
                });
            }
            self.port.set_timeout(left).map_err(|e| self.vanished(e))?;
            match self.port.read(&mut buf) {
                Ok(0) => return Err(self.vanished(ErrorKind::UnexpectedEof.into())),
                Ok(n) => self.rx.extend_from_slice(buf.get(..n).unwrap_or_default()),
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(self.vanished(e)),
            }
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
}

impl<P: Link> LightSwitch for NumatoBoard<P> {
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
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
        let cmd = NumatoCommand::WriteAll(mask);
        let lines = self.command(&cmd)?;
        self.expect_empty(&cmd, &lines)?;
        let got = self.read_mask()?;
        if got != mask {
            return Err(RigError::RelayMismatch {
                port: self.name.clone(),
                relay: "mask".into(),
                expected: format!("{mask:04x}"),
                got: format!("{got:04x}"),
            });
        }
        Ok(())
    }

    fn read_mask(&mut self) -> Result<u32, RigError> {
        let lines = self.command(&NumatoCommand::ReadAll)?;
        numato_parse_mask(&lines).map_err(|e| self.board_err(format!("relay readall: {e}")))
    }

    fn port_name(&self) -> &str {
        &self.name
    }
}

/// An LCUS/CH340 board: it answers nothing, so the driver remembers what it
/// switched. Every relay is switched off on connect so that memory is true.
pub struct LcusBoard<P: Link> {
    port: P,
    name: String,
    timeout: Duration,
    channels: u32,
    mask: u32,
}

impl LcusBoard<SerialLink> {
    /// Opens an LCUS board (9600 8N1) with `channels` relays.
    pub fn open(path: &str, channels: u32, timeout: Duration) -> Result<Self, RigError> {
        let port = open_serial(path, 9600, timeout)?;
        let mut b = LcusBoard::new(port, path, channels, timeout);
        b.set_mask(0)?;
        Ok(b)
    }
}

impl<P: Link> LcusBoard<P> {
    pub fn new(port: P, name: &str, channels: u32, timeout: Duration) -> Self {
        LcusBoard {
            port,
            name: name.to_string(),
            timeout,
            channels: channels.clamp(1, 32),
            mask: 0,
        }
    }

    /// The stream (tests inspect what was sent).
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }
}

impl<P: Link> LightSwitch for LcusBoard<P> {
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
        let frame = match lcus_frame(relay, on) {
            Some(f) if relay < self.channels => f,
            _ => {
                return Err(RigError::Board {
                    port: self.name.clone(),
                    detail: format!(
                        "relay {relay} does not exist on this {}-channel LCUS board",
                        self.channels
                    ),
                });
            }
        };
        let r = self
            .port
            .set_timeout(self.timeout)
            .and_then(|()| self.port.write_all(&frame))
            .and_then(|()| self.port.flush());
        r.map_err(|source| RigError::Vanished {
            port: self.name.clone(),
            source,
        })?;
        if on {
            self.mask |= 1 << relay;
        } else {
            self.mask &= !(1 << relay);
        }
        Ok(())
    }

    fn set_mask(&mut self, mask: u32) -> Result<(), RigError> {
        if self.channels < 32 && mask >> self.channels != 0 {
            return Err(RigError::Board {
                port: self.name.clone(),
                detail: format!(
                    "relay mask {mask:04x} names relays beyond this {}-channel LCUS board",
                    self.channels
                ),
            });
        }
        for relay in 0..self.channels {
            self.set(relay, mask & (1 << relay) != 0)?;
        }
        Ok(())
    }

    fn read_mask(&mut self) -> Result<u32, RigError> {
        Ok(self.mask)
    }

    fn port_name(&self) -> &str {
        &self.name
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::script::Script;

    fn board(answers: &[&str]) -> NumatoBoard<Script> {
        let a = answers.iter().map(|s| s.as_bytes().to_vec()).collect();
        NumatoBoard::new(
            Script::new(b'\r', a),
            "/dev/relay0",
            Duration::from_millis(50),
        )
    }

    #[test]
    fn switch_checks_echo_and_reads_back() {
        let mut b = board(&["relay on 2\r\n\r>", "relay read 2\r\n\ron\n\r>"]);
        assert!(b.set(2, true).is_ok());
        assert_eq!(b.port.sent_text(), "relay on 2\rrelay read 2\r");
    }

    #[test]
    fn a_relay_that_did_not_switch_is_reported() {
        let mut b = board(&["relay on 2\r\n\r>", "relay read 2\r\n\roff\n\r>"]);
        let e = b.set(2, true);
        assert!(
            matches!(&e, Err(RigError::RelayMismatch { port, expected, got, .. })
                if port == "/dev/relay0" && expected == "on" && got == "off"),
            "{e:?}"
        );
    }

    #[test]
    fn a_garbled_answer_is_retried_and_a_wrong_echo_is_an_error() {
        let mut b = board(&[
            "\x13\x00relay on 2\n\r>",
            "relay on 2\r\n\r>",
            "relay read 2\r\n\ron\n\r>",
        ]);
        assert!(b.set(2, true).is_ok());
        let mut b = board(&["relay on 3\n\r>", "relay on 3\n\r>", "relay on 3\n\r>"]);
        let e = b.set(2, true);
        assert!(
            matches!(&e, Err(RigError::Board { detail, .. }) if detail.contains("echoed")),
            "{e:?}"
        );
        assert_eq!(b.port.sent_text().matches("relay on 2\r").count(), 3);
    }

    #[test]
    fn mask_round_trip_and_version() {
        let mut b = board(&[
            "relay writeall 0005\n\r>",
            "relay readall\n\r0005\n\r>",
            "ver\n\r00000008\n\r>",
        ]);
        assert!(b.set_mask(5).is_ok());
        assert_eq!(b.version().ok().as_deref(), Some("00000008"));
    }

    #[test]
    fn no_prompt_is_a_timeout() {
        let mut b = board(&["relay readall\n\r0005\n\r"]);
        assert!(matches!(b.read_mask(), Err(RigError::Timeout { .. })));
    }

    #[test]
    fn lcus_sends_frames_and_remembers() {
        let s = Script::new(b'\n', vec![]);
        let mut b = LcusBoard::new(s, "/dev/lcus", 4, Duration::from_millis(50));
        assert!(b.set(0, true).is_ok());
        assert!(b.set(3, true).is_ok());
        assert!(b.set(0, false).is_ok());
        assert_eq!(b.read_mask().ok(), Some(0b1000));
        assert_eq!(
            b.port.sent,
            vec![0xA0, 1, 1, 0xA2, 0xA0, 4, 1, 0xA5, 0xA0, 1, 0, 0xA1]
        );
        assert!(matches!(b.set(4, true), Err(RigError::Board { .. })));
        assert!(matches!(b.set_mask(1 << 6), Err(RigError::Board { .. })));
    }
}
