//! Recorded device traffic: [`Tap`] keeps every byte a driver reads from a
//! real link (the simulated cell's pseudo-terminals), each answer after the
//! command line the driver had written last, and [`Replay`] plays such
//! answers back as a device that answers each command line at once and
//! falls silent when they run out. The fuzz targets feed the drivers
//! through [`Replay`], and their seeds are what [`Tap`] heard from the
//! simulator, so fuzzing starts from real conversations.
//!
//! A recording is one byte string: the answers, in order, separated by
//! [`SEPARATOR`] (the first one comes before any command, as a device's
//! greeting or leftovers would).

use std::io::{self, ErrorKind, Read, Write};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use super::Link;

/// What separates the answers of a recording.
pub const SEPARATOR: &[u8] = b"\n~~\n";

/// Counts the complete, non-empty command lines in what a driver writes
/// (an empty line, as a re-sync sends, is no command).
struct Lines {
    eol: u8,
    open: bool,
}

impl Lines {
    /// How many command lines `buf` completes.
    fn feed(&mut self, buf: &[u8]) -> usize {
        let mut n = 0;
        for &b in buf {
            if b == self.eol {
                n += usize::from(self.open);
                self.open = false;
            } else if b != b'\r' && b != b'\n' {
                self.open = true;
            }
        }
        n
    }
}

/// The answers a [`Tap`] has heard so far, shared with its owner.
pub type Heard = Arc<Mutex<Vec<Vec<u8>>>>;

/// A link that records what is read through it, answer by answer.
pub struct Tap<L> {
    inner: L,
    lines: Lines,
    heard: Heard,
}

impl<L: Link> Tap<L> {
    /// Wraps `inner`, whose commands end with `eol` (`\n` for VSG/1, `\r`
    /// for Numato); the returned answers fill as the driver reads.
    pub fn new(inner: L, eol: u8) -> (Tap<L>, Heard) {
        let heard = Arc::new(Mutex::new(vec![Vec::new()]));
        let tap = Tap {
            inner,
            lines: Lines { eol, open: false },
            heard: Arc::clone(&heard),
        };
        (tap, heard)
    }
}

/// The recording of `answers`: joined by [`SEPARATOR`].
pub fn recording(answers: &[Vec<u8>]) -> Vec<u8> {
    answers.join(SEPARATOR)
}

impl<L: Link> Read for Tap<L> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut heard = self.heard.lock().unwrap_or_else(PoisonError::into_inner);
        if let (Some(got), Some(last)) = (buf.get(..n), heard.last_mut()) {
            last.extend_from_slice(got);
        }
        Ok(n)
    }
}

impl<L: Link> Write for Tap<L> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        let new = self.lines.feed(buf.get(..n).unwrap_or_default());
        let mut heard = self.heard.lock().unwrap_or_else(PoisonError::into_inner);
        heard.extend(std::iter::repeat_n(Vec::new(), new));
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

impl<L: Link> Link for Tap<L> {
    fn set_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.inner.set_timeout(timeout)
    }
}

/// A recording played back: the first answer is there at once, and each
/// command line the driver writes releases the next; reads get at most
/// `chunk` bytes (to exercise reassembly) and time out when nothing is
/// released, like a silent device.
pub struct Replay {
    answers: std::collections::VecDeque<Vec<u8>>,
    /// Released bytes; those before `read` have been read.
    readable: Vec<u8>,
    read: usize,
    lines: Lines,
    chunk: usize,
}

impl Replay {
    /// Plays back `recording` (answers joined by [`SEPARATOR`]) to a driver
    /// whose commands end with `eol`.
    pub fn new(recording: &[u8], eol: u8, chunk: usize) -> Replay {
        let mut answers = split(recording).into_iter();
        let readable = answers.next().unwrap_or_default();
        Replay {
            answers: answers.collect(),
            readable,
            read: 0,
            lines: Lines { eol, open: false },
            chunk: chunk.max(1),
        }
    }
}

/// The answers of a recording.
fn split(recording: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut rest = recording;
    while let Some(p) = rest.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
        out.push(rest.get(..p).unwrap_or_default().to_vec());
        rest = rest.get(p + SEPARATOR.len()..).unwrap_or_default();
    }
    out.push(rest.to_vec());
    out
}

impl Read for Replay {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let left = self.readable.get(self.read..).unwrap_or_default();
        if left.is_empty() {
            return Err(ErrorKind::TimedOut.into());
        }
        let n = left.len().min(self.chunk).min(buf.len());
        if let (Some(dst), Some(src)) = (buf.get_mut(..n), left.get(..n)) {
            dst.copy_from_slice(src);
        }
        self.read += n;
        Ok(n)
    }
}

impl Write for Replay {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for _ in 0..self.lines.feed(buf) {
            if let Some(a) = self.answers.pop_front() {
                self.readable.drain(..self.read);
                self.read = 0;
                self.readable.extend(a);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Link for Replay {
    fn set_timeout(&mut self, _: Duration) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_command_line_releases_the_next_answer() {
        let rec = recording(&[b"hi".to_vec(), b"one".to_vec(), b"two".to_vec()]);
        let mut r = Replay::new(&rec, b'\n', 2);
        let mut buf = [0u8; 8];
        assert_eq!(r.read(&mut buf).ok(), Some(2));
        assert_eq!(&buf[..2], b"hi");
        assert!(r.read(&mut buf).is_err(), "silent until a command");
        // An empty line (a re-sync) is no command.
        r.write_all(b"\r\n").ok();
        assert!(r.read(&mut buf).is_err());
        r.write_all(b"A*00\r\nB").ok();
        assert_eq!(r.read(&mut buf).ok(), Some(2));
        assert_eq!(r.read(&mut buf).ok(), Some(1));
        assert_eq!(&buf[..1], b"e");
        assert!(r.read(&mut buf).is_err());
        r.write_all(b"*01\r\n").ok();
        assert_eq!(r.read(&mut buf).ok(), Some(2));
        assert_eq!(&buf[..2], b"tw");
    }

    #[test]
    fn a_recording_splits_back_into_its_answers() {
        let answers = vec![Vec::new(), b"OK\r\n".to_vec(), b"x\n~".to_vec()];
        assert_eq!(split(&recording(&answers)), answers);
        assert_eq!(split(b""), vec![Vec::<u8>::new()]);
    }
}
