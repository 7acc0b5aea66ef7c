//! The simulated relay board: speaks the Numato protocol (hardware.md §2)
//! on the device side of its pseudo-terminal — echo as typed, `\n\r` line
//! breaks, `>` prompt (after [`super::SimOptions::prompt_delay`]), masks of
//! relays / 4 hex digits (at least 2), relay names in upper case — and
//! switches the relays of the shared scene.

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use serialport::TTYPort;

use super::Scene;
use crate::rig::protocol::{NumatoCommand, numato_mask_digits};

const POLL: Duration = Duration::from_millis(25);
/// The board's line buffer; longer input is cut, as on the real firmware.
const MAX_LINE: usize = 64;

/// Serves the board until stopped.
pub(super) fn serve(mut port: TTYPort, scene: &Scene, stop: &AtomicBool) {
    let _ = serialport::SerialPort::set_timeout(&mut port, POLL);
    let mut line = String::new();
    let mut buf = [0u8; 256];
    while !stop.load(Ordering::SeqCst) {
        let n = match port.read(&mut buf) {
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                ) =>
            {
                0
            }
            Err(_) => {
                std::thread::sleep(POLL);
                0
            }
        };
        let mut out = Vec::new();
        for &b in buf.get(..n).unwrap_or_default() {
            match b {
                b'\r' => {
                    out.push(b'\r');
                    let answer = respond(scene, line.trim());
                    line.clear();
                    if !scene.opts.prompt_delay.is_zero() {
                        // The echo now, the answer and prompt later.
                        send(&mut port, &out, stop);
                        out.clear();
                        std::thread::sleep(scene.opts.prompt_delay);
                    }
                    out.extend_from_slice(&answer);
                }
                b'\n' => {}
                _ => {
                    out.push(b);
                    if line.len() < MAX_LINE {
                        line.push(char::from(b));
                    }
                }
            }
        }
        send(&mut port, &out, stop);
    }
}

fn send(port: &mut TTYPort, bytes: &[u8], stop: &AtomicBool) {
    let mut rest = bytes;
    while !rest.is_empty() && !stop.load(Ordering::SeqCst) {
        match port.write(rest) {
            Ok(k) => rest = rest.get(k..).unwrap_or_default(),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                ) => {}
            Err(_) => break,
        }
    }
}

/// What the board sends after the echo of `line`.
fn respond(scene: &Scene, line: &str) -> Vec<u8> {
    let relays = scene.opts.relays.min(32);
    let exists = |n: u32| n < relays;
    let digits = numato_mask_digits(relays);
    let body = match NumatoCommand::parse(line) {
        _ if line.is_empty() => String::new(),
        Some(NumatoCommand::Ver) => "\n\r00000008".to_string(),
        Some(NumatoCommand::On(n)) if exists(n) => {
            scene.set_relays(scene.relays() | 1 << n);
            String::new()
        }
        Some(NumatoCommand::Off(n)) if exists(n) => {
            scene.set_relays(scene.relays() & !(1 << n));
            String::new()
        }
        Some(NumatoCommand::Read(n)) if exists(n) => {
            let on = scene.relays() & (1 << n) != 0;
            format!("\n\r{}", if on { "on" } else { "off" })
        }
        Some(NumatoCommand::ReadAll) => format!("\n\r{:0digits$x}", scene.relays()),
        // A mask of another width is not this board's: ignored, and the
        // driver's read-back notices.
        Some(NumatoCommand::WriteAll { mask, digits: d }) if d == digits => {
            let valid = if relays >= 32 {
                u32::MAX
            } else {
                (1 << relays) - 1
            };
            scene.set_relays(mask & valid);
            String::new()
        }
        // The firmware ignores what it does not understand, and relays it
        // does not have; the driver's read-back notices.
        _ => String::new(),
    };
    format!("{body}\n\r>").into_bytes()
}
