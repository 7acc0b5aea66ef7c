//! Pure encode/decode of the cell's wire protocols (hardware.md §1–2): VSG/1
//! command and reply lines (`TEXT*HH\r\n`, XOR checksum in uppercase hex),
//! CRC-32, Numato relay commands and replies, and LCUS/CH340 frames.
//!
//! Nothing here touches a port, so the drivers and the simulator share one
//! definition of every byte, and the unit tests below feed scripted bytes.

use std::fmt;

mod relay;

/// The XOR of all bytes of `text` (NMEA 0183 convention).
pub fn checksum(text: &[u8]) -> u8 {
    text.iter().fold(0, |acc, b| acc ^ b)
}

/// `TEXT*HH\r\n`.
pub fn encode_line(text: &str) -> Vec<u8> {
    let mut out = Vec::with_capacity(text.len() + 5);
    out.extend_from_slice(text.as_bytes());
    out.extend_from_slice(format!("*{:02X}\r\n", checksum(text.as_bytes())).as_bytes());
    out
}

/// Why a received line is not a valid `TEXT*HH` line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LineError {
    #[error("no `*HH` checksum at the end of the line")]
    NoChecksum,
    #[error("checksum field `{0}` is not two hex digits")]
    BadHex(String),
    #[error("checksum {found:02X} does not match the line's {computed:02X}")]
    Mismatch { found: u8, computed: u8 },
    #[error("the line holds non-ASCII or control bytes")]
    NotAscii,
}

/// Checks a line (without its `\r\n`) and returns its `TEXT`.
pub fn decode_line(line: &[u8]) -> Result<&str, LineError> {
    let star = line
        .iter()
        .rposition(|&b| b == b'*')
        .ok_or(LineError::NoChecksum)?;
    let (text, tail) = line.split_at(star);
    let hex = tail.get(1..).unwrap_or_default();
    let hex_str = String::from_utf8_lossy(hex).into_owned();
    if hex.len() != 2 || !hex.iter().all(u8::is_ascii_hexdigit) {
        return Err(LineError::BadHex(hex_str));
    }
    let found = u8::from_str_radix(&hex_str, 16).map_err(|_| LineError::BadHex(hex_str))?;
    let computed = checksum(text);
    if found != computed {
        return Err(LineError::Mismatch { found, computed });
    }
    if !text.iter().all(|&b| (0x20..0x7f).contains(&b)) {
        return Err(LineError::NotAscii);
    }
    std::str::from_utf8(text).map_err(|_| LineError::NotAscii)
}

/// The longest reply line looked for by [`find_reply`].
const MAX_REPLY_LINE: usize = 256;

/// The first complete reply line in `buf` that checks out (`TEXT*HH`, then
/// `\r\n` or `\n`) and parses as a [`Reply`], with whatever comes before it
/// skipped — the tail of a block given up on, or a line damaged on the way.
/// A line may start right after other bytes: its start is the last `OK`,
/// `ERR ` or `DATA ` before the line end whose line checks out (a DATA
/// line's text holds none of them). Returns where the line starts, where it
/// ends (after the `\n`) and the reply.
pub fn find_reply(buf: &[u8]) -> Option<(usize, usize, Reply)> {
    let mut from = 0;
    while let Some(nl) = buf.get(from..)?.iter().position(|&b| b == b'\n') {
        let end = from + nl + 1;
        let line = buf.get(..from + nl)?;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let lo = line.len().saturating_sub(MAX_REPLY_LINE);
        for s in (lo..line.len()).rev() {
            let t = line.get(s..).unwrap_or_default();
            if !(t.starts_with(b"OK") || t.starts_with(b"ERR ") || t.starts_with(b"DATA ")) {
                continue;
            }
            if let Some(r) = decode_line(t).ok().and_then(Reply::parse) {
                return Some((s, end, r));
            }
        }
        from = end;
    }
    None
}

/// CRC-32 (IEEE, as in zlib).
pub fn crc32(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

fn parse_crc(s: &str) -> Option<u32> {
    (s.len() == 8)
        .then(|| u32::from_str_radix(s, 16).ok())
        .flatten()
}

/// A VSG/1 command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    Hello,
    Init,
    Live(u32),
    Freeze,
    Camera(u32),
    Load { width: u32, height: u32, crc: u32 },
    Write { off: u32, len: u32, crc: u32 },
    Read { off: u32, len: u32 },
    Status,
}

impl fmt::Display for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Command::Hello => write!(f, "HELLO"),
            Command::Init => write!(f, "INIT"),
            Command::Live(n) => write!(f, "LIVE {n}"),
            Command::Freeze => write!(f, "FREEZE"),
            Command::Camera(n) => write!(f, "CAMERA {n}"),
            Command::Load { width, height, crc } => write!(f, "LOAD {width} {height} {crc:08X}"),
            Command::Write { off, len, crc } => write!(f, "WRITE {off} {len} {crc:08X}"),
            Command::Read { off, len } => write!(f, "READ {off} {len}"),
            Command::Status => write!(f, "STATUS"),
        }
    }
}

impl Command {
    /// The line that goes on the wire.
    pub fn encode(&self) -> Vec<u8> {
        encode_line(&self.to_string())
    }

    /// Whether sending it twice does no harm, so a lost reply may be retried.
    /// FREEZE qualifies: a second freeze replaces a frame nobody has read,
    /// and the CRC of the reply we accept is the CRC of the frame in memory.
    pub fn is_idempotent(&self) -> bool {
        matches!(
            self,
            Command::Hello
                | Command::Read { .. }
                | Command::Status
                | Command::Camera(_)
                | Command::Freeze
                | Command::Init
                | Command::Live(_)
        )
    }

    /// Parses a command's `TEXT`; `None` for anything not a VSG/1 command
    /// (answered `ERR BADCMD`).
    pub fn parse(text: &str) -> Option<Command> {
        let mut words = text.split(' ');
        let verb = words.next()?;
        let nums: Vec<&str> = words.collect();
        let num = |i: usize| nums.get(i).and_then(|s| s.parse::<u32>().ok());
        let crc = |i: usize| nums.get(i).and_then(|s| parse_crc(s));
        let cmd = match (verb, nums.len()) {
            ("HELLO", 0) => Command::Hello,
            ("INIT", 0) => Command::Init,
            ("LIVE", 1) => Command::Live(num(0)?),
            ("FREEZE", 0) => Command::Freeze,
            ("CAMERA", 1) => Command::Camera(num(0)?),
            ("LOAD", 3) => Command::Load {
                width: num(0)?,
                height: num(1)?,
                crc: crc(2)?,
            },
            ("WRITE", 3) => Command::Write {
                off: num(0)?,
                len: num(1)?,
                crc: crc(2)?,
            },
            ("READ", 2) => Command::Read {
                off: num(0)?,
                len: num(1)?,
            },
            ("STATUS", 0) => Command::Status,
            _ => return None,
        };
        Some(cmd)
    }
}

/// Error codes of `ERR CODE text`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ErrCode {
    BadCmd,
    Checksum,
    Range,
    NoFrame,
    Busy,
    Crc,
    Other(String),
}

impl ErrCode {
    pub fn parse(s: &str) -> ErrCode {
        match s {
            "BADCMD" => ErrCode::BadCmd,
            "CHECKSUM" => ErrCode::Checksum,
            "RANGE" => ErrCode::Range,
            "NOFRAME" => ErrCode::NoFrame,
            "BUSY" => ErrCode::Busy,
            "CRC" => ErrCode::Crc,
            other => ErrCode::Other(other.to_string()),
        }
    }
}

impl fmt::Display for ErrCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            ErrCode::BadCmd => "BADCMD",
            ErrCode::Checksum => "CHECKSUM",
            ErrCode::Range => "RANGE",
            ErrCode::NoFrame => "NOFRAME",
            ErrCode::Busy => "BUSY",
            ErrCode::Crc => "CRC",
            ErrCode::Other(s) => s,
        };
        f.write_str(s)
    }
}

/// A VSG/1 reply line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reply {
    /// `OK …`: the words after `OK` (possibly empty).
    Ok(String),
    /// `ERR CODE free text`.
    Err { code: ErrCode, text: String },
    /// `DATA off len CRC`, followed on the wire by `len` raw bytes.
    Data { off: u32, len: u32, crc: u32 },
}

impl fmt::Display for Reply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reply::Ok(rest) if rest.is_empty() => write!(f, "OK"),
            Reply::Ok(rest) => write!(f, "OK {rest}"),
            Reply::Err { code, text } if text.is_empty() => write!(f, "ERR {code}"),
            Reply::Err { code, text } => write!(f, "ERR {code} {text}"),
            Reply::Data { off, len, crc } => write!(f, "DATA {off} {len} {crc:08X}"),
        }
    }
}

impl Reply {
    pub fn encode(&self) -> Vec<u8> {
        encode_line(&self.to_string())
    }

    pub fn err(code: ErrCode, text: &str) -> Reply {
        Reply::Err {
            code,
            text: text.to_string(),
        }
    }

    /// Parses a reply's `TEXT`; `None` if it is neither OK, ERR nor DATA.
    pub fn parse(text: &str) -> Option<Reply> {
        if text == "OK" {
            return Some(Reply::Ok(String::new()));
        }
        if let Some(rest) = text.strip_prefix("OK ") {
            return Some(Reply::Ok(rest.to_string()));
        }
        if let Some(rest) = text.strip_prefix("ERR ") {
            let (code, msg) = rest.split_once(' ').unwrap_or((rest, ""));
            return Some(Reply::Err {
                code: ErrCode::parse(code),
                text: msg.to_string(),
            });
        }
        if let Some(rest) = text.strip_prefix("DATA ") {
            let w: Vec<&str> = rest.split(' ').collect();
            if let [off, len, crc] = w.as_slice() {
                return Some(Reply::Data {
                    off: off.parse().ok()?,
                    len: len.parse().ok()?,
                    crc: parse_crc(crc)?,
                });
            }
        }
        None
    }
}

/// Finds `key=value` in the words of an OK reply.
fn field<'a>(words: &'a str, key: &str) -> Option<&'a str> {
    words
        .split(' ')
        .find_map(|w| w.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
}

/// What `HELLO` says about the grabber.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GrabberInfo {
    pub model: String,
    pub width: u32,
    pub height: u32,
    pub depth: u32,
    pub cameras: u32,
    pub maxblock: u32,
}

impl GrabberInfo {
    /// The words after `OK` of a HELLO reply.
    pub fn format(&self) -> String {
        format!(
            "VSG/1 model={} width={} height={} depth={} cameras={} maxblock={}",
            self.model, self.width, self.height, self.depth, self.cameras, self.maxblock
        )
    }

    pub fn parse(words: &str) -> Option<GrabberInfo> {
        if !words.starts_with("VSG/1") {
            return None;
        }
        let n = |k: &str| field(words, k).and_then(|v| v.parse::<u32>().ok());
        Some(GrabberInfo {
            model: field(words, "model")?.to_string(),
            width: n("width")?,
            height: n("height")?,
            depth: n("depth")?,
            cameras: n("cameras")?,
            maxblock: n("maxblock")?,
        })
    }
}

/// The frozen frame as `FREEZE` reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameInfo {
    pub width: u32,
    pub height: u32,
    pub crc: u32,
}

impl FrameInfo {
    pub fn format(&self) -> String {
        format!("FRAME {} {} {:08X}", self.width, self.height, self.crc)
    }

    pub fn parse(words: &str) -> Option<FrameInfo> {
        let w: Vec<&str> = words.split(' ').collect();
        match w.as_slice() {
            ["FRAME", wd, ht, crc] => Some(FrameInfo {
                width: wd.parse().ok()?,
                height: ht.parse().ok()?,
                crc: parse_crc(crc)?,
            }),
            _ => None,
        }
    }

    /// Bytes of the frame (8-bit pixels).
    pub fn len(&self) -> usize {
        (self.width as usize).saturating_mul(self.height as usize)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// What `STATUS` says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GrabberStatus {
    pub camera: u32,
    pub live: bool,
    /// CRC of the frame in memory, `None` before any FREEZE/LOAD.
    pub frame: Option<u32>,
}

impl GrabberStatus {
    pub fn format(&self) -> String {
        let frame = match self.frame {
            Some(c) => format!("{c:08X}"),
            None => "none".to_string(),
        };
        format!(
            "camera={} live={} frame={frame}",
            self.camera,
            u8::from(self.live)
        )
    }

    pub fn parse(words: &str) -> Option<GrabberStatus> {
        let frame = match field(words, "frame")? {
            "none" => None,
            c => Some(parse_crc(c)?),
        };
        Some(GrabberStatus {
            camera: field(words, "camera")?.parse().ok()?,
            live: match field(words, "live")? {
                "0" => false,
                "1" => true,
                _ => return None,
            },
            frame,
        })
    }
}

pub use relay::*;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_round_trip_and_checksum_is_nmea_xor() {
        // NMEA's classic example sentence body.
        assert_eq!(checksum(b"GPGLL,5300.97914,N,00259.98174,E,125926,A"), 0x28);
        assert_eq!(encode_line("HELLO"), b"HELLO*42\r\n".to_vec());
        assert_eq!(decode_line(b"HELLO*42"), Ok("HELLO"));
        assert_eq!(
            decode_line(b"HELLO*43"),
            Err(LineError::Mismatch {
                found: 0x43,
                computed: 0x42
            })
        );
        assert_eq!(decode_line(b"HELLO"), Err(LineError::NoChecksum));
        assert!(matches!(decode_line(b"HELLO*2"), Err(LineError::BadHex(_))));
        assert!(matches!(
            decode_line(b"HELLO*zz"),
            Err(LineError::BadHex(_))
        ));
        let mut bad = b"HE\x01LO".to_vec();
        let c = checksum(&bad);
        bad.extend_from_slice(format!("*{c:02X}").as_bytes());
        assert_eq!(decode_line(&bad), Err(LineError::NotAscii));
    }

    #[test]
    fn commands_round_trip() {
        let all = [
            Command::Hello,
            Command::Init,
            Command::Live(2),
            Command::Freeze,
            Command::Camera(4),
            Command::Load {
                width: 512,
                height: 256,
                crc: 0xDEADBEEF,
            },
            Command::Write {
                off: 16384,
                len: 100,
                crc: 0x0000_00FF,
            },
            Command::Read { off: 0, len: 16384 },
            Command::Status,
        ];
        for c in all {
            let line = c.encode();
            let text = decode_line(line.strip_suffix(b"\r\n").unwrap_or(&line));
            assert_eq!(text.map(Command::parse), Ok(Some(c)), "{c}");
        }
        for bad in [
            "",
            "HELLO 1",
            "READ 1",
            "READ -1 5",
            "CAMERA x",
            "LOAD 1 2 xyz",
            "hello",
        ] {
            assert_eq!(Command::parse(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn replies_parse() {
        assert_eq!(Reply::parse("OK"), Some(Reply::Ok(String::new())));
        assert_eq!(
            Reply::parse("ERR RANGE camera 7 of 4"),
            Some(Reply::err(ErrCode::Range, "camera 7 of 4"))
        );
        assert_eq!(
            Reply::parse("DATA 0 10 0000ABCD"),
            Some(Reply::Data {
                off: 0,
                len: 10,
                crc: 0xABCD
            })
        );
        assert_eq!(Reply::parse("DATA 0 10"), None);
        assert_eq!(Reply::parse("NOPE"), None);
        let info = GrabberInfo {
            model: "SIM".into(),
            width: 512,
            height: 512,
            depth: 8,
            cameras: 4,
            maxblock: 65536,
        };
        assert_eq!(GrabberInfo::parse(&info.format()), Some(info));
        let st = GrabberStatus {
            camera: 2,
            live: true,
            frame: Some(0x1234_5678),
        };
        assert_eq!(GrabberStatus::parse(&st.format()), Some(st));
        assert_eq!(
            GrabberStatus::parse("camera=1 live=0 frame=none").map(|s| s.frame),
            Some(None)
        );
        let f = FrameInfo {
            width: 3,
            height: 2,
            crc: 7,
        };
        assert_eq!(FrameInfo::parse(&f.format()), Some(f));
    }

    #[test]
    fn replies_are_found_behind_junk() {
        let data = Reply::Data {
            off: 16,
            len: 4,
            crc: 0xABCD_EF01,
        };
        let mut buf = b"\x00\nxyz*OK".to_vec();
        let start = buf.len();
        buf.extend_from_slice(&data.encode());
        buf.extend_from_slice(b"rest");
        let (s, e, r) = find_reply(&buf).expect("found");
        assert_eq!((s, r), (start, data.clone()));
        assert_eq!(buf.get(e..), Some(&b"rest"[..]));
        // A damaged line is no line.
        let mut bad = data.encode();
        bad[3] ^= 1;
        assert_eq!(find_reply(&bad), None);
        assert_eq!(find_reply(b"DATA 1 2"), None);
    }

    #[test]
    fn crc_is_zlib_crc32() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }
}
