//! A scripted byte stream for driver unit tests: each complete, non-empty
//! line (or LCUS frame) the driver writes releases the next scripted answer;
//! reading with nothing left times out, like a silent device.

use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::time::Duration;

use super::Link;

pub(crate) struct Script {
    /// Answers, released one per command written.
    answers: VecDeque<Vec<u8>>,
    /// Bytes the driver may read now.
    readable: VecDeque<u8>,
    /// What the driver wrote.
    pub sent: Vec<u8>,
    pending_line: Vec<u8>,
    /// The line end that completes a command (`\n` for VSG/1, `\r` for Numato).
    eol: u8,
    /// After the script runs out: EOF (a vanished device) instead of silence.
    pub eof_at_end: bool,
    /// Bytes per read call, to exercise reassembly.
    pub chunk: usize,
}

impl Script {
    pub fn new(eol: u8, answers: Vec<Vec<u8>>) -> Script {
        Script {
            answers: answers.into(),
            readable: VecDeque::new(),
            sent: Vec::new(),
            pending_line: Vec::new(),
            eol,
            eof_at_end: false,
            chunk: 7,
        }
    }

    /// Bytes waiting before the first command (garbage on connect).
    pub fn with_initial(mut self, bytes: &[u8]) -> Script {
        self.readable.extend(bytes);
        self
    }

    pub fn sent_text(&self) -> String {
        String::from_utf8_lossy(&self.sent).into_owned()
    }
}

impl Read for Script {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.readable.is_empty() {
            if self.eof_at_end && self.answers.is_empty() {
                return Ok(0);
            }
            // A real port would wait its timeout; the test need not.
            std::thread::sleep(Duration::from_millis(1));
            return Err(ErrorKind::TimedOut.into());
        }
        let n = buf.len().min(self.chunk).min(self.readable.len());
        for b in buf.iter_mut().take(n) {
            *b = self.readable.pop_front().unwrap_or_default();
        }
        Ok(n)
    }
}

impl Write for Script {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.sent.extend_from_slice(buf);
        for &b in buf {
            if b == self.eol {
                let line = std::mem::take(&mut self.pending_line);
                let blank = line.iter().all(|c| c.is_ascii_whitespace());
                if !blank && let Some(a) = self.answers.pop_front() {
                    self.readable.extend(a);
                }
            } else {
                self.pending_line.push(b);
            }
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Link for Script {
    fn set_timeout(&mut self, _timeout: Duration) -> io::Result<()> {
        Ok(())
    }
}
