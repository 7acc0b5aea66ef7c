//! The LCUS/CH340 relay boards: 9600 8N1, one frame `A0 ch state sum` per
//! switch, and no reply at all — the board cannot be read, and it loses its
//! relays when it loses power (a USB replug, a power cycle of the cabinet)
//! while its port name stays.
//!
//! So nothing remembered decides what is sent: the first switch a process
//! makes on a board sends every channel (the whole mask), and so does every
//! [`LightSwitch::set_mask`] — a capture sets its lighting's whole mask.
//! Only a single-relay switch after that sends one frame. Re-sending a
//! relay's state does not toggle it, so lights that stay on do not flicker.
//!
//! What vss last set is kept in a small state file per port, for *reporting*
//! only (`vss lights status`, which switches nothing):
//! `$XDG_STATE_HOME/vss/relays/PORT.toml` (`~/.local/state/vss/relays/`
//! without an absolute `XDG_STATE_HOME`; `PORT` is the device path with
//! every character but letters, digits, `.` and `-` made `_`), written
//! atomically after every switch. A state file that does not fit the board
//! (another port, another channel count, relays beyond the board, not a
//! state file at all) is ignored, with a note saying why.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::rig::protocol::lcus_frame;
use crate::rig::{Link, RigError, SerialLink, open_serial};

use super::LightSwitch;

/// What vss last set on a board that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LastSet {
    /// The relays on (bit N = relay N).
    pub mask: u32,
    /// When (UTC, RFC 3339).
    pub when: String,
}

/// The state file's content.
#[derive(Serialize, Deserialize)]
struct StateFile {
    port: String,
    channels: u32,
    #[serde(flatten)]
    last: LastSet,
}

/// The largest state file read (a real one is about 100 bytes).
const MAX_STATE_LEN: u64 = 4096;

/// The state file of the LCUS board on `port` (see the module doc), or
/// `None` when neither `XDG_STATE_HOME` nor `HOME` is set.
pub fn lcus_state_file(port: &str) -> Option<PathBuf> {
    let base = crate::dirs::state_home()?;
    let name: String = port
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    Some(base.join("vss/relays").join(format!("{name}.toml")))
}

/// An LCUS/CH340 board of `channels` relays.
pub struct LcusBoard<P: Link> {
    port: P,
    name: String,
    timeout: Duration,
    channels: u32,
    /// What the state file says vss last set (reporting only).
    last: Option<LastSet>,
    /// What this process sent since it opened the board: `None` until its
    /// first switch, which therefore sends every channel.
    sent: Option<u32>,
    /// Why the state file was ignored, if it was.
    note: Option<String>,
    state_file: Option<PathBuf>,
}

impl LcusBoard<SerialLink> {
    /// Opens an LCUS board (9600 8N1) with `channels` relays, and reads
    /// what vss last set on it from its state file. Nothing is sent.
    pub fn open(path: &str, channels: u32, timeout: Duration) -> Result<Self, RigError> {
        let port = open_serial(path, 9600, timeout)?;
        let b = LcusBoard::new(port, path, channels, timeout);
        Ok(match lcus_state_file(path) {
            Some(f) => b.with_state_file(f),
            None => b,
        })
    }
}

impl<P: Link> LcusBoard<P> {
    /// A board on `port`, remembering in memory only.
    pub fn new(port: P, name: &str, channels: u32, timeout: Duration) -> Self {
        LcusBoard {
            port,
            name: name.to_string(),
            timeout,
            channels: channels.clamp(1, 32),
            last: None,
            sent: None,
            note: None,
            state_file: None,
        }
    }

    /// Keeps the state in `file` too, and reports what it says (a missing
    /// file means nothing is recorded; one that does not fit this board is
    /// ignored, and [`LightSwitch::note`] says why). What is sent never
    /// depends on it.
    pub fn with_state_file(mut self, file: PathBuf) -> Self {
        match load(&file, &self.name, self.channels) {
            Ok(last) => self.last = last,
            Err(why) => {
                self.note = Some(format!(
                    "{}: ignored the LCUS state file: {why}",
                    crate::text::path(&file)
                ));
            }
        }
        self.state_file = Some(file);
        self
    }

    /// The stream (tests inspect what was sent).
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }

    fn exists(&self, relay: u32) -> Result<[u8; 4], RigError> {
        match lcus_frame(relay, true) {
            Some(f) if relay < self.channels => Ok(f),
            _ => Err(RigError::Board {
                port: self.name.clone(),
                detail: format!(
                    "relay {relay} does not exist on this {}-channel LCUS board",
                    self.channels
                ),
            }),
        }
    }

    fn send(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
        self.exists(relay)?;
        let frame = lcus_frame(relay, on).unwrap_or_default();
        let r = self
            .port
            .set_timeout(self.timeout)
            .and_then(|()| self.port.write_all(&frame))
            .and_then(|()| self.port.flush());
        r.map_err(|source| RigError::Vanished {
            port: self.name.clone(),
            source,
        })
    }

    /// Remembers `mask` as set now, in memory and in the state file.
    fn remember(&mut self, mask: u32) -> Result<(), RigError> {
        let last = LastSet {
            mask,
            when: crate::clock::now_rfc3339(),
        };
        self.sent = Some(mask);
        self.last = Some(last.clone());
        let Some(file) = &self.state_file else {
            return Ok(());
        };
        let state = StateFile {
            port: self.name.clone(),
            channels: self.channels,
            last,
        };
        let text = toml::to_string(&state).map_err(|e| RigError::Config(e.to_string()))?;
        let io = |e: std::io::Error| {
            RigError::Config(format!(
                "{}: cannot keep the LCUS board's state: {e}",
                crate::text::path(file)
            ))
        };
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        crate::fsutil::write_atomic(file, text.as_bytes()).map_err(io)
    }
}

/// What the state file at `file` records for the board on `port` with
/// `channels` relays: `Ok(None)` when there is no file, `Err(why)` when
/// there is one that does not fit.
fn load(file: &Path, port: &str, channels: u32) -> Result<Option<LastSet>, String> {
    let text = match crate::fsutil::read_input_text(file, MAX_STATE_LEN) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e.to_string()),
    };
    let s: StateFile = toml::from_str(&text)
        .map_err(|e| format!("not a state file vss wrote ({})", e.message()))?;
    let clean = crate::formats::sanitize;
    if s.port != port {
        return Err(format!("it is for port {:?}, not {port:?}", clean(&s.port)));
    }
    if s.channels != channels {
        return Err(format!(
            "it is for a {}-channel board, this one has {channels}",
            s.channels
        ));
    }
    if channels < 32 && s.last.mask >> channels != 0 {
        return Err(format!(
            "its mask {:x} names relays beyond this {channels}-channel board",
            s.last.mask
        ));
    }
    if s.last.when.len() > 64 || s.last.when.chars().any(char::is_control) {
        return Err("its time stamp is not one vss writes".into());
    }
    Ok(Some(s.last))
}

impl<P: Link> LightSwitch for LcusBoard<P> {
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
        self.exists(relay)?;
        let Some(base) = self.sent else {
            // This process's first switch of the board: the whole mask
            // (the board may have lost power since the state file was
            // written; what vss last set is not what the board has).
            return self.set_mask(if on { 1 << relay } else { 0 });
        };
        let mask = if on {
            base | 1 << relay
        } else {
            base & !(1 << relay)
        };
        self.send(relay, on)?;
        self.remember(mask)
    }

    /// Sends every channel, whatever was set before.
    fn set_mask(&mut self, mask: u32) -> Result<(), RigError> {
        if self.channels < 32 && mask >> self.channels != 0 {
            return Err(RigError::Board {
                port: self.name.clone(),
                detail: format!(
                    "relay mask {mask:x} names relays beyond this {}-channel LCUS board",
                    self.channels
                ),
            });
        }
        // Sent or not, the board's state is now unknown until every frame
        // went out.
        self.sent = None;
        for relay in 0..self.channels {
            self.send(relay, mask & (1 << relay) != 0)?;
        }
        self.remember(mask)
    }

    /// What this process set, else what vss last set (the state file):
    /// an LCUS board cannot be asked.
    fn read_mask(&mut self) -> Result<u32, RigError> {
        Ok(self
            .sent
            .or(self.last.as_ref().map(|l| l.mask))
            .unwrap_or(0))
    }

    fn reads_back(&self) -> bool {
        false
    }

    fn last_set(&self) -> Option<LastSet> {
        self.last.clone()
    }

    fn note(&self) -> Option<String> {
        self.note.clone()
    }

    fn port_name(&self) -> &str {
        &self.name
    }
}
