//! `/`: search the help window, the message log or the Session screen's
//! file list (what is in front), as lazygit, k9s and helix do. The text is
//! typed in a field (case ignored); Enter shows the first match, `n` and
//! `N` the next and previous, `Esc` ends the search. What is searched is
//! each entry's whole text (a message, a key's description, a file's
//! state), whether it is scrolled out of view, wrapped over several rows or
//! cut at the terminal's width; the drawing's own functions make the
//! entries with their rows, so the match is scrolled into view and its rows
//! marked where they are drawn, and the hint row says "match 2 of 5".

use super::chrome::{Search, SearchTarget};
use super::{App, LogView, Modal, Overlay, PromptPurpose};
use crate::tui::keymap::{ScreenId, SearchAction};

/// The longest text searched for.
pub const MAX_QUERY: usize = 80;

impl App {
    /// What `/` searches now: the help window when it is open, the file
    /// list on the Session screen, else the log.
    fn search_target(&self) -> Option<SearchTarget> {
        match self.chrome.overlay {
            Some(Overlay::Help { .. }) => Some(SearchTarget::Help),
            Some(Overlay::Message { .. }) => None,
            None if self.chrome.screen == ScreenId::Session && self.session.view.is_some() => {
                Some(SearchTarget::Files)
            }
            None => Some(SearchTarget::Log),
        }
    }

    /// Whether the search on is about what is in front (the help still
    /// open, the Session screen still shown, the log still expanded).
    pub fn search_in_front(&self) -> bool {
        let Some(s) = &self.chrome.search else {
            return false;
        };
        match s.target {
            SearchTarget::Help => matches!(self.chrome.overlay, Some(Overlay::Help { .. })),
            SearchTarget::Files => {
                self.chrome.overlay.is_none() && self.chrome.screen == ScreenId::Session
            }
            SearchTarget::Log => {
                self.chrome.overlay.is_none() && self.chrome.log_view == LogView::Expanded
            }
        }
    }

    /// The entries of `target` (a message, a key, a file) with the row
    /// each begins at and its rows, top down, at the terminal's size: a match is looked
    /// for in an entry's whole text, not in the rows it is drawn as.
    pub fn search_items(&self, target: SearchTarget) -> Vec<(String, usize, usize)> {
        use crate::tui::screens::chrome;
        let (w, _) = self.chrome.size;
        let inner = w.saturating_sub(2) as usize;
        let items = match target {
            SearchTarget::Help => chrome::help_items(self, inner),
            SearchTarget::Log => chrome::log_items(self, inner),
            SearchTarget::Files => {
                let panel = crate::tui::screens::panel_width(ScreenId::Session).min(w / 2);
                crate::tui::screens::session::file_items(self, w.saturating_sub(panel + 2) as usize)
            }
        };
        let mut row = 0;
        items
            .into_iter()
            .map(|i| {
                let first = row;
                row += i.rows.len();
                (i.text, first, i.rows.len())
            })
            .collect()
    }

    pub(super) fn search(&mut self, a: SearchAction) {
        match a {
            SearchAction::Start => {
                let Some(target) = self.search_target() else {
                    self.ctx().info(
                        "/ searches the help (?), the log (m) and the Session screen's file list",
                    );
                    return;
                };
                let old = self
                    .chrome
                    .search
                    .as_ref()
                    .map(|s| s.query.clone())
                    .unwrap_or_default();
                self.chrome.modal = Some(
                    Modal::prompt(
                        format!("search {} for:", target.name()),
                        "any text, case ignored · Enter shows the first match, then n the next, \
                         N the previous, Esc ends the search",
                        old,
                        MAX_QUERY,
                        PromptPurpose::Search(target),
                    )
                    .selected(),
                );
            }
            SearchAction::Next | SearchAction::Prev => {
                if let Some(s) = self.chrome.search.as_mut() {
                    let n = s.count.max(1);
                    s.current = if a == SearchAction::Next {
                        (s.current + 1) % n
                    } else {
                        (s.current + n - 1) % n
                    };
                }
                self.show_match();
            }
            SearchAction::Clear => self.chrome.search = None,
        }
    }

    /// Starts the search for `query` typed in the field; why not when
    /// nothing matches (the field stays open to change it).
    pub(super) fn search_submitted(
        &mut self,
        target: SearchTarget,
        query: &str,
    ) -> Result<(), String> {
        let query = query.trim();
        if query.is_empty() {
            return Err("type a text to search for (Esc: no search)".into());
        }
        let s = Search {
            target,
            query: query.to_string(),
            current: 0,
            count: 0,
        };
        if !self
            .search_items(target)
            .iter()
            .any(|(text, ..)| s.matches(text))
        {
            return Err(format!("no match for \"{query}\" in {}", target.name()));
        }
        if target == SearchTarget::Log {
            self.chrome.log_view = LogView::Expanded;
        }
        self.chrome.search = Some(s);
        self.show_match();
        Ok(())
    }

    /// Scrolls what is searched to the current match.
    fn show_match(&mut self) {
        let Some(s) = self.chrome.search.clone() else {
            return;
        };
        let items = self.search_items(s.target);
        let total = items.last().map_or(0, |&(_, first, n)| first + n);
        let mut hits: Vec<(usize, usize)> = items
            .into_iter()
            .filter(|(text, ..)| s.matches(text))
            .map(|(_, first, n)| (first, n))
            .collect();
        if s.target == SearchTarget::Log {
            // The newest first, as the log is read.
            hits.reverse();
        }
        let count = hits.len();
        let current = if count == 0 { 0 } else { s.current % count };
        if let Some(search) = self.chrome.search.as_mut() {
            search.count = count;
            search.current = current;
        }
        let Some(&(row, n)) = hits.get(current) else {
            return;
        };
        match s.target {
            // A row of context above the match.
            SearchTarget::Help => {
                self.chrome.overlay = Some(Overlay::Help {
                    scroll: row.saturating_sub(1),
                })
            }
            SearchTarget::Files => self.screens.files.scroll = row,
            SearchTarget::Log => {
                // The pane shows the rows up to `total - scroll`, its last
                // row a "more" marker when scrolled: the match's last row
                // goes just above it.
                self.chrome.log_scroll = total.saturating_sub(row + n).saturating_sub(1);
            }
        }
    }
}
