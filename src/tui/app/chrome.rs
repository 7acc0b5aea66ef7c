//! The frame around every screen: which screen is shown, the message log
//! and how its pane is shown and scrolled, the help and message windows,
//! the open question or text field, and whether to quit.

use std::time::{Duration, Instant};

use super::log::{Level, Log, LogEntry};
use super::modal::Modal;
use crate::tui::keymap::{GlobalAction, ScreenId, ViewerAction};
use crate::tui::mode::Look;

/// How the log pane is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogView {
    Hidden,
    Line,
    Expanded,
}

/// A window over the screen that takes the keys until closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlay {
    /// The key table and the checklist's marks, scrolled by `scroll` rows.
    Help { scroll: usize },
    /// The newest message in full.
    Message { scroll: usize },
}

/// The smallest terminal the screens are drawn in.
pub const MIN_SIZE: (u16, u16) = (64, 18);

/// How long the answer to a key stays on the message line at least, unless
/// the operator presses another key: time to read its three rows.
pub const HOLD: Duration = Duration::from_secs(3);

/// The answer to the operator's last key, held on the message line while
/// background messages (progress, saves, device notes) go to the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Held {
    /// The log entry's number ([`Log::nth_pushed`]).
    pub seq: usize,
    /// When background messages may take the line again.
    pub until: Instant,
}

/// What a search looks through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchTarget {
    Help,
    Log,
    Files,
}

impl SearchTarget {
    pub fn name(self) -> &'static str {
        match self {
            SearchTarget::Help => "the help",
            SearchTarget::Log => "the log",
            SearchTarget::Files => "the file list",
        }
    }
}

/// A search on: its text (case ignored) and which of its matches is shown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Search {
    pub target: SearchTarget,
    pub query: String,
    /// The match shown, counted in the order `n` goes (help and files top
    /// down, the log newest first).
    pub current: usize,
    /// How many rows match, when last looked.
    pub count: usize,
}

impl Search {
    /// Whether a row of text matches.
    pub fn matches(&self, row: &str) -> bool {
        row.to_lowercase().contains(&self.query.to_lowercase())
    }
}

#[derive(Debug)]
pub struct Chrome {
    pub look: Look,
    pub screen: ScreenId,
    pub log: Log,
    pub log_view: LogView,
    /// Rows the expanded log pane is scrolled back from its newest message.
    pub log_scroll: usize,
    /// [`Log::pushed`] when the log was last hidden (`m` to its third
    /// view): what came since may still need the message line.
    pub hidden_from: usize,
    pub overlay: Option<Overlay>,
    pub modal: Option<Modal>,
    /// The search on, if any (`/`).
    pub search: Option<Search>,
    /// The terminal's size (columns, rows), from the last resize.
    pub size: (u16, u16),
    /// The answer to the last key, held on the message line.
    pub held: Option<Held>,
    /// Start-up under way (until the store first lists the sessions):
    /// [`Log::pushed`] when it began.
    pub starting: Option<usize>,
    pub quit: bool,
    /// The operator asked to suspend the console (Ctrl-Z): the shell
    /// takes it ([`crate::tui::App::take_suspend`]).
    pub suspend: bool,
}

impl Chrome {
    pub fn new(look: Look) -> Chrome {
        Chrome {
            look,
            screen: ScreenId::Survey,
            log: Log::default(),
            log_view: LogView::Line,
            log_scroll: 0,
            hidden_from: 0,
            overlay: None,
            modal: None,
            search: None,
            size: (80, 24),
            held: None,
            starting: None,
            quit: false,
            suspend: false,
        }
    }

    /// The message the message line shows, and how many newer ones are in
    /// the log only: the answer to the last key while it is held, else
    /// the newest message. An error that comes after a held answer that is
    /// not one takes the line at once: it is the key's outcome (a save
    /// that failed after "saving…", an edit not written), not background.
    pub fn shown_message(&self) -> Option<(&LogEntry, usize)> {
        if let Some(h) = self.held
            && let Some(e) = self.log.nth_pushed(h.seq)
        {
            let pushed = self.log.pushed();
            let error = (e.level != Level::Error)
                .then(|| {
                    (h.seq + 1..pushed)
                        .rev()
                        .filter_map(|n| self.log.nth_pushed(n).map(|x| (n, x)))
                        .find(|(_, x)| x.level == Level::Error)
                })
                .flatten();
            let (n, e) = error.unwrap_or((h.seq, e));
            return Some((e, self.log.newer_than(n)));
        }
        self.log.last().map(|e| (e, 0))
    }

    /// After the operator's key: the last message it produced is held on
    /// the message line; a key that produced none lets the line show the
    /// newest again. `before` is [`Log::pushed`] before the key. While the
    /// message window (`!`) is open, what it shows stays.
    pub fn hold_answer(&mut self, before: usize, now: Instant) {
        if matches!(self.overlay, Some(Overlay::Message { .. })) {
            return;
        }
        let after = self.log.pushed();
        self.held = (after > before).then(|| Held {
            seq: after - 1,
            until: now + HOLD,
        });
    }

    /// Work a key asked for ended (a session opened or refused): its worst
    /// message since `since` ([`Log::pushed`] when it was asked), an error
    /// before a warning before the last note, is held like the key's own
    /// answer, so a device note arriving meanwhile does not push a damaged
    /// file's warning off the line. The answer to a later key stays.
    pub fn hold_outcome(&mut self, since: usize, now: Instant) {
        if self.held.is_some_and(|h| h.seq >= since)
            || matches!(self.overlay, Some(Overlay::Message { .. }))
        {
            return;
        }
        let pushed = self.log.pushed();
        let worst = [Level::Error, Level::Warn]
            .into_iter()
            .find_map(|level| {
                (since..pushed)
                    .rev()
                    .find(|&n| self.log.nth_pushed(n).is_some_and(|e| e.level == level))
            })
            .or((pushed > since).then(|| pushed - 1));
        if let Some(seq) = worst {
            self.held = Some(Held {
                seq,
                until: now + HOLD,
            });
        }
    }

    /// Start-up ended (the profile read, its cameras' descriptions, the
    /// sessions listed): its worst message, a warning or an error (a
    /// damaged `.cdf`), is held like an outcome, so the grabber's note
    /// arriving just after does not push it off the line. Notes alone
    /// hold nothing.
    pub fn started(&mut self, now: Instant) {
        let Some(since) = self.starting.take() else {
            return;
        };
        let worrying = (since..self.log.pushed())
            .filter_map(|n| self.log.nth_pushed(n))
            .any(|e| e.level != Level::Info);
        if worrying {
            self.hold_outcome(since, now);
        }
    }

    /// Lets the held answer go once its time is over (not while the
    /// message window shows it); whether the message line changes (in
    /// the hidden log, whether its row goes).
    pub fn release_held(&mut self, now: Instant) -> bool {
        let Some(h) = self.held else {
            return false;
        };
        if now < h.until || matches!(self.overlay, Some(Overlay::Message { .. })) {
            return false;
        }
        self.held = None;
        self.log.pushed() > h.seq + 1
            || (self.log_view == LogView::Hidden && !self.hidden_shows_message())
    }

    /// The terminal is below [`MIN_SIZE`]: the screens are not drawn.
    pub fn too_small(&self) -> bool {
        self.size.0 < MIN_SIZE.0 || self.size.1 < MIN_SIZE.1
    }

    pub fn cycle_log(&mut self) {
        self.log_view = match self.log_view {
            LogView::Hidden => LogView::Line,
            LogView::Line => LogView::Expanded,
            LogView::Expanded => LogView::Hidden,
        };
        self.log_scroll = 0;
        self.hidden_from = self.log.pushed();
    }

    /// Whether the hidden log still shows its message line: while the
    /// answer to a key (or a key's outcome) is held on it, or while the
    /// newest message is a warning or an error that came since the log
    /// was hidden. Notes stay out of sight; a key never goes unanswered
    /// and a failed save is never unseen.
    pub fn hidden_shows_message(&self) -> bool {
        self.held.is_some_and(|h| h.seq >= self.hidden_from)
            || (self.log.pushed() > self.hidden_from
                && self.log.last().is_some_and(|e| e.level != Level::Info))
    }

    /// PgUp/PgDn/Home/End: scroll the log pane, expanding it first.
    pub fn scroll_log(&mut self, g: GlobalAction) {
        if self.log_view != LogView::Expanded {
            self.log_view = LogView::Expanded;
        }
        let page = (self.size.1 as usize / 2).saturating_sub(3).max(1);
        self.log_scroll = match g {
            GlobalAction::LogUp => self.log_scroll + page,
            GlobalAction::LogDown => self.log_scroll.saturating_sub(page),
            // The drawing clamps to the first row.
            GlobalAction::LogTop => usize::MAX / 2,
            _ => 0,
        };
    }

    /// Scrolls or closes the help or message window.
    pub fn viewer(&mut self, v: ViewerAction) {
        let page = (self.size.1 as usize).saturating_sub(6).max(1);
        let Some(Overlay::Help { scroll } | Overlay::Message { scroll }) = self.overlay.as_mut()
        else {
            return;
        };
        match v {
            ViewerAction::Up => *scroll = scroll.saturating_sub(1),
            ViewerAction::Down => *scroll += 1,
            ViewerAction::PageUp => *scroll = scroll.saturating_sub(page),
            ViewerAction::PageDown => *scroll += page,
            ViewerAction::Top => *scroll = 0,
            // The drawing clamps to the last page.
            ViewerAction::Bottom => *scroll = usize::MAX / 2,
            ViewerAction::Close => self.overlay = None,
        }
    }
}
