//! The log pane's contents: every error and hardware event, time-stamped,
//! so an operator never loses a message that flashed by in the status bar.

use std::collections::VecDeque;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    Info,
    Warn,
    Error,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LogEntry {
    /// `HH:MM:SS` UTC.
    pub time: String,
    pub level: Level,
    pub text: String,
}

/// The newest entries (older ones drop off past the cap).
#[derive(Debug, Default)]
pub struct Log {
    entries: VecDeque<LogEntry>,
}

impl Log {
    pub const CAP: usize = 1000;

    pub fn push(&mut self, level: Level, text: impl Into<String>) {
        if self.entries.len() == Self::CAP {
            self.entries.pop_front();
        }
        self.entries.push_back(LogEntry {
            time: clock(),
            level,
            text: super::clean(&text.into()),
        });
    }

    pub fn entries(&self) -> impl DoubleEndedIterator<Item = &LogEntry> + ExactSizeIterator {
        self.entries.iter()
    }

    pub fn last(&self) -> Option<&LogEntry> {
        self.entries.back()
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
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
    fn keeps_the_newest_and_cleans_text() {
        let mut l = Log::default();
        for i in 0..Log::CAP + 5 {
            l.push(Level::Info, format!("m{i}"));
        }
        assert_eq!(l.len(), Log::CAP);
        assert_eq!(l.entries().next().unwrap().text, "m5");
        l.push(Level::Error, "bad\x1b[31m");
        assert_eq!(l.last().unwrap().text, "bad[31m");
    }
}
