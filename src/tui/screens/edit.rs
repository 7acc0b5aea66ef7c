//! The Edit screen: the lines over the grey image with the selection
//! highlighted, the selected lines' figures, and the edit keys (connect,
//! extend, delete, undo/redo) that go into the session's log.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{PreviewNav, block, split_panel};
use crate::llv::Point;
use crate::tui::app::App;
use crate::tui::keymap::{self, Action, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview};

/// The Edit screen's own state: selected line indices, zoom and cursor.
#[derive(Clone, Debug, Default)]
pub struct EditScreen {
    pub selected: Vec<usize>,
    pub nav: PreviewNav,
}

impl EditScreen {
    pub fn handle_key(&mut self, key: KeyEvent, size: Option<(usize, usize)>) -> Option<Action> {
        let a = keymap::lookup(Scope::Screen(ScreenId::Edit), &key)?;
        if self.nav.apply(a, size) {
            None
        } else {
            Some(a)
        }
    }

    /// The cursor as an image point (image centre before it moves).
    pub fn cursor_point(&self, size: Option<(usize, usize)>) -> Point {
        let (x, y) = self.nav.cursor_or_centre(size.unwrap_or((1, 1)));
        Point::new(x as f64, y as f64)
    }
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 30);
    let cur = app.current.as_ref();
    let lines = cur.and_then(|c| c.editor.as_ref()).map(|e| e.lines());
    let mut info = Vec::new();
    match (cur, lines) {
        (Some(c), Some(ls)) => {
            info.push(Line::styled(
                format!("image {}: {} lines", c.k, ls.len()),
                t.title(),
            ));
            info.push(Line::raw(format!("edits this run {}", c.edits)));
            let (x, y) = app
                .edit
                .nav
                .cursor_or_centre(app.preview_size().unwrap_or((1, 1)));
            info.push(Line::raw(format!("cursor {x} {y}")));
            info.push(Line::styled("selected", t.title()));
            if app.edit.selected.is_empty() {
                info.push(Line::styled(" none (n . k Space)", t.dim()));
            }
            for &i in app.edit.selected.iter().take(6) {
                if let Some(s) = ls.get(i) {
                    info.push(Line::raw(format!(
                        "#{i} ({:.0},{:.0})-({:.0},{:.0}) {:.0}px",
                        s.a.x,
                        s.a.y,
                        s.b.x,
                        s.b.y,
                        s.length()
                    )));
                }
            }
            if let Some(ed) = c.editor.as_ref() {
                let log = ed.log();
                if !log.is_empty() {
                    info.push(Line::styled("log", t.title()));
                    for op in log.iter().rev().take(4) {
                        info.push(Line::raw(format!(" {op:?}")));
                    }
                }
            }
        }
        _ => info.push(Line::raw(
            "No lines yet: capture and run an image (Survey, 1).",
        )),
    }
    Paragraph::new(info)
        .wrap(Wrap { trim: true })
        .block(block(app, "lines"))
        .render(panel, buf);
    let [view, _] = Layout::vertical([Constraint::Min(1), Constraint::Length(0)]).areas(right);
    let title = match app.outputs_stale() {
        Some(why) => format!("lines over grey — {why}"),
        None => "lines over grey".to_string(),
    };
    let b = block(app, &title);
    let inner = b.inner(view);
    b.render(view, buf);
    if let (Some(c), Some(ls)) = (cur, lines)
        && let Some((_, grey)) = c.frames.first()
    {
        let bg = c
            .outputs
            .as_ref()
            .and_then(|o| o.corrected.first())
            .unwrap_or(grey);
        let mut p = Preview::new(Layer::LinesOver(bg, ls), app.look.mode, app.look.colour);
        p.view = app.edit.nav.view;
        p.selected = &app.edit.selected;
        p.cursor = Some(app.edit.nav.cursor_or_centre(grey.size()));
        p.render(inner, buf);
    }
}
