//! The message log: every message of the run, time-stamped, so an operator
//! never loses one that flashed by in the status bar. The pane shows it
//! wrapped and scrollable; the store worker also appends it to a log file
//! (the session folder's, or the state folder's), which outlives a crash.

use std::collections::VecDeque;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    Info,
    Warn,
    Error,
}

impl Level {
    pub fn word(self) -> &'static str {
        match self {
            Level::Info => "info",
            Level::Warn => "warning",
            Level::Error => "ERROR",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct LogEntry {
    /// `HH:MM:SS` UTC.
    pub time: String,
    pub level: Level,
    pub text: String,
}

impl LogEntry {
    /// The entry as a line of the log file.
    pub fn file_line(&self) -> String {
        format!("{} {:7} {}", self.time, self.level.word(), self.text)
    }
}

/// Every message of the run (past [`Log::CAP`] the oldest drop off the
/// screen; the log file keeps them).
#[derive(Debug, Default)]
pub struct Log {
    entries: VecDeque<LogEntry>,
    /// Entries pushed so far, and how many of them went to the file.
    pushed: usize,
    written: usize,
    file: Option<PathBuf>,
}

impl Log {
    pub const CAP: usize = 100_000;

    pub fn push(&mut self, level: Level, text: impl Into<String>) {
        if self.entries.len() == Self::CAP {
            self.entries.pop_front();
        }
        self.entries.push_back(LogEntry {
            time: clock(),
            level,
            text: crate::tui::text::clean(&text.into()),
        });
        self.pushed += 1;
    }

    pub fn entries(&self) -> impl DoubleEndedIterator<Item = &LogEntry> + ExactSizeIterator {
        self.entries.iter()
    }

    pub fn last(&self) -> Option<&LogEntry> {
        self.entries.back()
    }

    /// How many entries were pushed in the run (the next one's number).
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// The entry pushed `n`-th (from 0), while it is kept.
    pub fn nth_pushed(&self, n: usize) -> Option<&LogEntry> {
        let first = self.pushed - self.entries.len();
        n.checked_sub(first).and_then(|i| self.entries.get(i))
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The lines not yet handed to the log file.
    pub fn take_unwritten(&mut self) -> Vec<String> {
        let new = self.pushed - self.written;
        self.written = self.pushed;
        let n = self.entries.len();
        self.entries
            .iter()
            .skip(n.saturating_sub(new))
            .map(LogEntry::file_line)
            .collect()
    }

    pub fn set_file(&mut self, path: PathBuf) {
        self.file = Some(path);
    }

    /// Where the log is written, once the store worker said so.
    pub fn file(&self) -> Option<&PathBuf> {
        self.file.as_ref()
    }
}

fn clock() -> String {
    let s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    format!("{:02}:{:02}:{:02}", (s / 3600) % 24, (s / 60) % 60, s % 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_run_cleans_text_and_hands_each_line_to_the_file_once() {
        let mut l = Log::default();
        for i in 0..1500 {
            l.push(Level::Info, format!("m{i}"));
        }
        assert_eq!(l.len(), 1500, "far more than a screen, all kept");
        assert_eq!(l.entries().next().unwrap().text, "m0");
        l.push(Level::Error, "bad\x1b[31m");
        assert_eq!(l.last().unwrap().text, "bad[31m");
        let first = l.take_unwritten();
        assert_eq!(first.len(), 1501);
        assert!(first[1500].ends_with("ERROR   bad[31m"), "{}", first[1500]);
        assert!(l.take_unwritten().is_empty());
        l.push(Level::Warn, "w");
        assert_eq!(l.take_unwritten().len(), 1);
    }
}
