//! The Session/Report screen: every file of the session with its state, and
//! exporting the PostScript and SVG survey reports.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget};

use super::{block, split_panel};
use crate::tui::app::App;
use crate::tui::keymap::{self, Action, Scope, ScreenId};

/// The Session screen's own state: how far the file list is scrolled.
#[derive(Clone, Debug, Default)]
pub struct SessionScreen {
    pub scroll: usize,
}

impl SessionScreen {
    pub fn handle_key(&mut self, key: KeyEvent) -> Option<Action> {
        let a = keymap::lookup(Scope::Screen(ScreenId::Session), &key);
        match a {
            Some(Action::SelectDown) => {
                self.scroll += 1;
                None
            }
            Some(Action::SelectUp) => {
                self.scroll = self.scroll.saturating_sub(1);
                None
            }
            other => other,
        }
    }
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 34);
    let Some(s) = &app.session else {
        Paragraph::new("No session open: create or open one on the Survey screen (1).")
            .block(block(app, "session"))
            .render(area, buf);
        return;
    };
    let done = s.images.iter().filter(|i| i.outputs && !i.stale).count();
    let mut info = vec![
        Line::styled(s.name.clone(), t.title()),
        Line::raw(format!("{}", s.dir.display())),
        Line::raw(format!("images {} (done {done})", s.images.len())),
        Line::raw(format!(
            "lightings {}",
            s.letters.iter().collect::<String>()
        )),
        Line::raw(format!(
            "edits {}",
            s.images.iter().map(|i| i.edits).sum::<usize>()
        )),
        Line::raw(""),
        Line::raw("e exports the PostScript"),
        Line::raw("  and SVG survey reports"),
    ];
    let reports: Vec<_> = app
        .log
        .entries()
        .filter(|e| e.text.starts_with("report written"))
        .collect();
    if !reports.is_empty() {
        info.push(Line::styled("reports", t.title()));
        for e in reports.iter().rev().take(4) {
            let name = e.text.rsplit('/').next().unwrap_or(&e.text);
            info.push(Line::raw(format!(" {name}")));
        }
    }
    Paragraph::new(info)
        .block(block(app, "session"))
        .render(panel, buf);
    let rows = right.height.saturating_sub(2) as usize;
    let skip = app.files.scroll.min(s.files.len().saturating_sub(rows));
    let lines: Vec<Line> = s
        .files
        .iter()
        .skip(skip)
        .take(rows)
        .map(|f| {
            let st = if f.ok { t.ok() } else { t.error() };
            Line::styled(format!("{:<20} {}", f.name, f.state), st)
        })
        .collect();
    Paragraph::new(lines)
        .block(block(app, &format!("files ({})", s.files.len())))
        .render(right, buf);
}
