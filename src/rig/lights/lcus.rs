//! The LCUS/CH340 relay boards: 9600 8N1, one frame `A0 ch state sum` per
//! switch, and no reply at all — the board cannot be read. So the driver
//! remembers what it set, and keeps that in a small state file per port,
//! so that the next `vss` (a `vss lights status`, the console started
//! again) knows what is on without switching anything:
//! `$XDG_STATE_HOME/vss/relays/PORT.toml` (`~/.local/state/vss/relays/`
//! without `XDG_STATE_HOME`; `PORT` is the device path with every
//! character but letters, digits, `.` and `-` made `_`), written
//! atomically after every switch. Opening the board sends nothing; a
//! mask is sent as the frames of the channels that change from what is
//! remembered (all of them when nothing is), so lights that stay on do not
//! flicker.

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
    let base = match std::env::var_os("XDG_STATE_HOME").filter(|v| !v.is_empty()) {
        Some(d) => PathBuf::from(d),
        None => {
            PathBuf::from(std::env::var_os("HOME").filter(|v| !v.is_empty())?).join(".local/state")
        }
    };
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
    last: Option<LastSet>,
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
            state_file: None,
        }
    }

    /// Keeps the state in `file` too, and starts from what it says (a
    /// missing or unreadable file, or one for another port or board size,
    /// means nothing is known).
    pub fn with_state_file(mut self, file: PathBuf) -> Self {
        self.last = load(&file, &self.name, self.channels);
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
            when: crate::session::stamp::now_rfc3339(),
        };
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
                file.display()
            ))
        };
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        crate::fsutil::write_atomic(file, text.as_bytes()).map_err(io)
    }
}

fn load(file: &Path, port: &str, channels: u32) -> Option<LastSet> {
    let text = crate::fsutil::read_input_text(file, MAX_STATE_LEN).ok()?;
    let s: StateFile = toml::from_str(&text).ok()?;
    (s.port == port && s.channels == channels).then_some(s.last)
}

impl<P: Link> LightSwitch for LcusBoard<P> {
    fn set(&mut self, relay: u32, on: bool) -> Result<(), RigError> {
        self.exists(relay)?;
        let base = self.last.as_ref().map_or(0, |l| l.mask);
        let mask = if on {
            base | 1 << relay
        } else {
            base & !(1 << relay)
        };
        if self.last.is_none() {
            // Nothing known: every channel is sent once, so it is.
            return self.set_mask(mask);
        }
        self.send(relay, on)?;
        self.remember(mask)
    }

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
        let known = self.last.as_ref().map(|l| l.mask);
        for relay in 0..self.channels {
            let want = mask & (1 << relay) != 0;
            if known.is_none_or(|k| (k & (1 << relay) != 0) != want) {
                self.send(relay, want)?;
            }
        }
        self.remember(mask)
    }

    fn read_mask(&mut self) -> Result<u32, RigError> {
        Ok(self.last.as_ref().map_or(0, |l| l.mask))
    }

    fn reads_back(&self) -> bool {
        false
    }

    fn last_set(&self) -> Option<LastSet> {
        self.last.clone()
    }

    fn port_name(&self) -> &str {
        &self.name
    }
}
