//! The relay boards' wire formats (hardware.md §2): Numato commands and
//! replies, LCUS/CH340 frames.
//!
//! Numato, as its makers document the USB relay modules: a relay is named by
//! one character, `0`–`9` then `A`…`V` in upper case (the firmware ignores
//! lower case); `relay readall` answers, and `relay writeall` takes, a hex
//! mask of as many digits as the board has relays / 4, at least 2 (2 for 8
//! relays, 4 for 16, 8 for 32). `ver` answers the firmware version only
//! (e.g. `00000008`), not the relay count, so the width comes from the
//! profile's `channels` or from the digits of a `readall` reply.

/// Hex digits of a Numato `readall`/`writeall` mask on a board of
/// `channels` relays: relays / 4, at least 2.
pub fn numato_mask_digits(channels: u32) -> usize {
    (channels.div_ceil(4) as usize).max(2)
}

/// The relays a mask of `digits` hex digits covers (2 digits → 8).
pub fn numato_channels_of_digits(digits: usize) -> u32 {
    (digits.min(8) * 4) as u32
}

/// The character naming relay `n` on a Numato board: `0`–`9`, then `A`…`V`.
pub fn numato_relay_char(n: u32) -> Option<char> {
    match n {
        0..=9 => char::from_digit(n, 10),
        10..=31 => char::from_u32('A' as u32 + n - 10),
        _ => None,
    }
}

/// The inverse of [`numato_relay_char`]: upper case only, as the firmware.
pub fn numato_relay_index(c: &str) -> Option<u32> {
    let mut chars = c.chars();
    let ch = chars.next()?;
    if chars.next().is_some() {
        return None;
    }
    match ch {
        '0'..='9' => ch.to_digit(10),
        'A'..='V' => Some(ch as u32 - 'A' as u32 + 10),
        _ => None,
    }
}

/// A hex mask of 1 to 8 digits (no sign, no prefix): the value and its
/// number of digits.
fn parse_hex_mask(s: &str) -> Option<(u32, usize)> {
    if s.is_empty() || s.len() > 8 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    u32::from_str_radix(s, 16).ok().map(|m| (m, s.len()))
}

/// A Numato command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NumatoCommand {
    Ver,
    On(u32),
    Off(u32),
    Read(u32),
    ReadAll,
    /// Set every relay: `mask` written with exactly `digits` hex digits.
    WriteAll {
        mask: u32,
        digits: usize,
    },
}

impl NumatoCommand {
    /// The text typed to the board (without the trailing `\r`); `None` if
    /// the relay number has no Numato character, or the mask does not fit
    /// its digits.
    pub fn text(&self) -> Option<String> {
        Some(match self {
            NumatoCommand::Ver => "ver".to_string(),
            NumatoCommand::On(n) => format!("relay on {}", numato_relay_char(*n)?),
            NumatoCommand::Off(n) => format!("relay off {}", numato_relay_char(*n)?),
            NumatoCommand::Read(n) => format!("relay read {}", numato_relay_char(*n)?),
            NumatoCommand::ReadAll => "relay readall".to_string(),
            NumatoCommand::WriteAll { mask, digits } => {
                let d = *digits;
                if !(2..=8).contains(&d) || (d < 8 && mask >> (4 * d) != 0) {
                    return None;
                }
                format!("relay writeall {mask:0d$x}")
            }
        })
    }

    pub fn parse(text: &str) -> Option<NumatoCommand> {
        let w: Vec<&str> = text.split_whitespace().collect();
        Some(match w.as_slice() {
            ["ver"] => NumatoCommand::Ver,
            ["relay", "on", n] => NumatoCommand::On(numato_relay_index(n)?),
            ["relay", "off", n] => NumatoCommand::Off(numato_relay_index(n)?),
            ["relay", "read", n] => NumatoCommand::Read(numato_relay_index(n)?),
            ["relay", "readall"] => NumatoCommand::ReadAll,
            ["relay", "writeall", m] => {
                let (mask, digits) = parse_hex_mask(m)?;
                NumatoCommand::WriteAll { mask, digits }
            }
            _ => return None,
        })
    }
}

/// Why a Numato reply is not what the command expects.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NumatoReplyError {
    #[error("the board echoed {echo:?} instead of {sent:?}")]
    Echo { sent: String, echo: String },
    #[error("unexpected reply {0:?}")]
    Unexpected(String),
}

/// Splits what the board sent up to (not including) the `>` prompt into the
/// echo check and the reply lines. The board echoes the command as typed,
/// possibly with its `\r`, then sends `\n\r`-separated lines.
pub fn numato_split(sent: &str, raw: &[u8]) -> Result<Vec<String>, NumatoReplyError> {
    let text = String::from_utf8_lossy(raw);
    // The echo ends at the first line break the board adds after it.
    let end = text.find(['\r', '\n']).unwrap_or(text.len());
    let (echo, rest) = text.split_at(end);
    if echo != sent {
        return Err(NumatoReplyError::Echo {
            sent: sent.to_string(),
            echo: echo.to_string(),
        });
    }
    Ok(rest
        .split(['\r', '\n'])
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().to_string())
        .collect())
}

/// The answer to `sent` in what the board has sent so far: the lines
/// between this command's echo and the next `>` prompt, and how many bytes
/// that took; `None` until a prompt has followed the echo. Whatever comes
/// before the echo (a late answer to an earlier command) is passed over.
pub fn numato_reply(
    sent: &str,
    rx: &[u8],
) -> Option<(usize, Result<Vec<String>, NumatoReplyError>)> {
    let echo = sent.as_bytes();
    let p = if echo.is_empty() {
        0
    } else {
        rx.windows(echo.len()).position(|w| w == echo)?
    };
    let after = rx.get(p..)?;
    let q = after.iter().position(|&b| b == b'>')?;
    Some((p + q + 1, numato_split(sent, after.get(..q)?)))
}

/// The state `relay read N` reports.
pub fn numato_parse_state(lines: &[String]) -> Result<bool, NumatoReplyError> {
    match lines {
        [s] if s == "on" => Ok(true),
        [s] if s == "off" => Ok(false),
        _ => Err(NumatoReplyError::Unexpected(lines.join("|"))),
    }
}

/// The mask `relay readall` reports, and its number of hex digits (which
/// tells the board's size).
pub fn numato_parse_mask(lines: &[String]) -> Result<(u32, usize), NumatoReplyError> {
    match lines {
        [s] => parse_hex_mask(s).ok_or_else(|| NumatoReplyError::Unexpected(s.clone())),
        _ => Err(NumatoReplyError::Unexpected(lines.join("|"))),
    }
}

/// The LCUS frame switching `relay` (0-based; channel `relay + 1` on the
/// wire) on or off: `A0 ch state sum`.
pub fn lcus_frame(relay: u32, on: bool) -> Option<[u8; 4]> {
    let ch = u8::try_from(relay.checked_add(1)?).ok()?;
    let state = u8::from(on);
    Some([0xA0, ch, state, 0xA0u8.wrapping_add(ch).wrapping_add(state)])
}

/// Decodes an LCUS frame into (relay, on); `None` if it is malformed.
pub fn lcus_parse(frame: &[u8]) -> Option<(u32, bool)> {
    match *frame {
        [0xA0, ch, state @ (0 | 1), sum]
            if ch >= 1 && sum == 0xA0u8.wrapping_add(ch).wrapping_add(state) =>
        {
            Some((u32::from(ch) - 1, state == 1))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numato_commands_and_replies() {
        assert_eq!(NumatoCommand::On(10).text().as_deref(), Some("relay on A"));
        assert_eq!(NumatoCommand::On(31).text().as_deref(), Some("relay on V"));
        assert_eq!(
            NumatoCommand::parse("relay off A"),
            Some(NumatoCommand::Off(10))
        );
        // The firmware knows upper case only.
        assert_eq!(NumatoCommand::parse("relay off a"), None);
        assert_eq!(NumatoCommand::Read(32).text(), None);
        assert_eq!(
            NumatoCommand::parse("relay writeall 00ff"),
            Some(NumatoCommand::WriteAll {
                mask: 0xff,
                digits: 4
            })
        );
        assert_eq!(NumatoCommand::parse("relay writeall +f"), None);
        let lines = numato_split("relay read 3", b"relay read 3\r\n\ron\n\r");
        assert_eq!(lines.as_deref().map(numato_parse_state), Ok(Ok(true)));
        let lines = numato_split("relay readall", b"relay readall\n\r0005\n\r");
        assert_eq!(lines.as_deref().map(numato_parse_mask), Ok(Ok((5, 4))));
        assert!(matches!(
            numato_split("relay on 1", b"relay on 2\n\r"),
            Err(NumatoReplyError::Echo { .. })
        ));
        assert_eq!(
            numato_split("ver", b"ver\r\n\r00000008\n\r"),
            Ok(vec!["00000008".to_string()])
        );
    }

    #[test]
    fn writeall_takes_as_many_digits_as_relays_over_four() {
        let w = |channels, mask| {
            NumatoCommand::WriteAll {
                mask,
                digits: numato_mask_digits(channels),
            }
            .text()
        };
        assert_eq!(w(1, 1).as_deref(), Some("relay writeall 01"));
        assert_eq!(w(8, 0x81).as_deref(), Some("relay writeall 81"));
        assert_eq!(w(16, 0x81).as_deref(), Some("relay writeall 0081"));
        assert_eq!(
            w(32, 0x8000_0001).as_deref(),
            Some("relay writeall 80000001")
        );
        // A mask wider than the board cannot be written.
        assert_eq!(w(8, 0x100), None);
        assert_eq!(numato_channels_of_digits(2), 8);
    }

    #[test]
    fn lcus_frames_match_the_spec_examples() {
        assert_eq!(lcus_frame(0, true), Some([0xA0, 0x01, 0x01, 0xA2]));
        assert_eq!(lcus_frame(0, false), Some([0xA0, 0x01, 0x00, 0xA1]));
        assert_eq!(lcus_parse(&[0xA0, 0x02, 0x01, 0xA3]), Some((1, true)));
        assert_eq!(lcus_parse(&[0xA0, 0x02, 0x01, 0xA4]), None);
        assert_eq!(lcus_frame(255, true), None);
    }
}
