//! The message log: every message of the run, time-stamped, so an operator
//! never loses one that flashed by in the status bar. The pane shows it
//! wrapped and scrollable; the store worker also appends it to a log file
//! (the session folder's, or the state folder's), which outlives a crash.
//!
//! A run of the same message (same level and text, one after another: a
//! key held whose answer is a refusal) is one entry with a count, shown
//! `03:01:12–03:14:55 … (×500)` (its first and last times); the file
//! gets its first line at once, at the first's time, and `last message
//! repeated 499 times` at the last's when the run ends (the next message,
//! the last one being the console's end), so a crash loses at most the
//! count.

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
    /// `HH:MM:SS` UTC, of the last of its run: when it last came.
    pub time: String,
    pub level: Level,
    pub text: String,
    /// How many times it came in a row (1: once).
    pub count: usize,
    /// The push number ([`Log::nth_pushed`]) of the first of its run.
    seq: usize,
    /// `HH:MM:SS` of the first of its run.
    first_time: String,
    /// How many of the run the log file has: 0 none yet, 1 its line,
    /// `count` once the repeats were said.
    filed: usize,
}

impl LogEntry {
    /// The entry as a line of the log file (the first of its run).
    pub fn file_line(&self) -> String {
        format!("{} {:7} {}", self.first_time, self.level.word(), self.text)
    }

    /// When it came, as the pane and the message line show it: a run
    /// over more than a second from its first to its last,
    /// `03:01:12–03:14:55`.
    pub fn when(&self) -> String {
        if self.first_time == self.time {
            self.time.clone()
        } else {
            format!("{}–{}", self.first_time, self.time)
        }
    }

    /// The entry as the pane and the message line show it: when it came
    /// ([`LogEntry::when`]), then its text ([`LogEntry::shown`]).
    pub fn dated(&self) -> String {
        format!("{} {}", self.when(), self.shown())
    }

    /// Its text as the pane and the message line show it: with the count
    /// of a run, `… (×500)`.
    pub fn shown(&self) -> String {
        if self.count > 1 {
            format!("{} (×{})", self.text, self.count)
        } else {
            self.text.clone()
        }
    }
}

/// Every message of the run (past [`Log::CAP`] the oldest drop off the
/// screen; the log file keeps them).
#[derive(Debug, Default)]
pub struct Log {
    entries: VecDeque<LogEntry>,
    /// Messages pushed so far, repeats included.
    pushed: usize,
    file: Option<PathBuf>,
}

impl Log {
    pub const CAP: usize = 100_000;

    /// Adds a message; the same as the newest (level and text) adds to
    /// its count instead.
    pub fn push(&mut self, level: Level, text: impl Into<String>) {
        self.push_at(clock(), level, text.into());
    }

    /// [`Log::push`] at the time `now` (`HH:MM:SS`).
    fn push_at(&mut self, now: String, level: Level, text: String) {
        let text = crate::tui::text::clean(&text);
        self.pushed += 1;
        if let Some(last) = self.entries.back_mut()
            && last.level == level
            && last.text == text
        {
            last.count += 1;
            last.time = now;
            return;
        }
        if self.entries.len() == Self::CAP {
            self.entries.pop_front();
        }
        self.entries.push_back(LogEntry {
            time: now.clone(),
            level,
            text,
            count: 1,
            seq: self.pushed - 1,
            first_time: now,
            filed: 0,
        });
    }

    pub fn entries(&self) -> impl DoubleEndedIterator<Item = &LogEntry> + ExactSizeIterator {
        self.entries.iter()
    }

    pub fn last(&self) -> Option<&LogEntry> {
        self.entries.back()
    }

    /// How many messages were pushed in the run, repeats included (the
    /// next one's number).
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// The entry of the message pushed `n`-th (from 0), while it is kept:
    /// a repeat's is the entry of its run.
    pub fn nth_pushed(&self, n: usize) -> Option<&LogEntry> {
        self.index_of(n).map(|i| &self.entries[i])
    }

    /// How many entries are newer than the one of push `n`.
    pub fn newer_than(&self, n: usize) -> usize {
        self.index_of(n).map_or(0, |i| self.entries.len() - 1 - i)
    }

    fn index_of(&self, n: usize) -> Option<usize> {
        if n >= self.pushed || self.entries.front().is_none_or(|e| n < e.seq) {
            return None;
        }
        Some(self.entries.partition_point(|e| e.seq <= n) - 1)
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The lines not yet handed to the log file: each entry's first line
    /// once, and the count of a run once a later message ended it.
    pub fn take_unwritten(&mut self) -> Vec<String> {
        let n = self.entries.len();
        // Entries the file has whole are followed by none it lacks.
        let mut start = n;
        while start > 0 {
            let e = &self.entries[start - 1];
            if start < n && e.filed == e.count {
                break;
            }
            start -= 1;
        }
        let mut out = Vec::new();
        for (i, e) in self.entries.iter_mut().enumerate().skip(start) {
            if e.filed == 0 {
                out.push(e.file_line());
                e.filed = 1;
            }
            if i + 1 < n && e.filed < e.count {
                let times = e.count - e.filed;
                let s = if times == 1 { "" } else { "s" };
                out.push(format!(
                    "{} {:7} last message repeated {times} time{s}",
                    e.time,
                    e.level.word()
                ));
                e.filed = e.count;
            }
        }
        out
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

    /// 500 of the same message are one entry `(×500)`; every push still
    /// has its number, the repeats that of their run's entry; the file
    /// gets the first line at once and the count when the run ends.
    #[test]
    fn a_run_of_one_message_is_one_entry_and_its_count() {
        let mut l = Log::default();
        let at = |l: &mut Log, level, text: &str| l.push_at("03:01:12".into(), level, text.into());
        at(&mut l, Level::Info, "start");
        for _ in 0..500 {
            at(&mut l, Level::Warn, "F5 does nothing here");
        }
        assert_eq!((l.len(), l.pushed()), (2, 501));
        assert_eq!(l.last().unwrap().shown(), "F5 does nothing here (×500)");
        assert_eq!(l.nth_pushed(1), l.nth_pushed(500));
        assert_eq!(l.nth_pushed(0).unwrap().text, "start");
        assert!(l.nth_pushed(501).is_none());
        assert_eq!(l.newer_than(0), 1);
        let lines = l.take_unwritten();
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[1].ends_with("warning F5 does nothing here"));
        at(&mut l, Level::Warn, "F5 does nothing here");
        assert!(l.take_unwritten().is_empty(), "the run goes on");
        // Same text, another level: another entry.
        at(&mut l, Level::Info, "F5 does nothing here");
        let lines = l.take_unwritten();
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[0].ends_with("warning last message repeated 500 times"));
        assert!(lines[1].ends_with("info    F5 does nothing here"));
        assert_eq!(l.len(), 3);
    }

    /// A run that went on for minutes shows when it began and when it last
    /// came, in the pane and on the message line (both show
    /// [`LogEntry::dated`]); the file has the
    /// first line at the first's time and the count at the last's. The
    /// pane showed 03:01:12 for a message that still came at 03:14:55.
    #[test]
    fn a_run_shows_when_it_last_came() {
        let mut l = Log::default();
        let at = |l: &mut Log, time: &str, text: &str| {
            l.push_at(time.into(), Level::Warn, text.into());
        };
        at(&mut l, "03:01:12", "relay board not answering");
        at(&mut l, "03:07:40", "relay board not answering");
        at(&mut l, "03:14:55", "relay board not answering");
        let e = l.last().unwrap();
        assert_eq!(
            e.dated(),
            "03:01:12–03:14:55 relay board not answering (×3)"
        );
        assert_eq!(e.time, "03:14:55", "when it last came");
        at(&mut l, "03:15:00", "relay board answering again");
        let lines = l.take_unwritten();
        assert_eq!(
            lines,
            [
                "03:01:12 warning relay board not answering",
                "03:14:55 warning last message repeated 2 times",
                "03:15:00 warning relay board answering again",
            ]
        );
        // A run within one second has one time.
        at(&mut l, "03:15:00", "relay board answering again");
        assert_eq!(l.last().unwrap().when(), "03:15:00");
    }
}
