//! The Session/Report screen: the session's summary with a one-line count
//! of its problems, every file with its state (damaged ones with why), and
//! the reports written.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::chrome::Item;
use super::{block, split_panel, window};
use crate::tui::app::{App, SearchTarget};

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 34);
    let Some(s) = &app.session.view else {
        Paragraph::new("No session open: create or open one on the Survey screen (1).")
            .wrap(Wrap { trim: true })
            .block(block(app, "session"))
            .render(area, buf);
        return;
    };
    let done = s.images.iter().filter(|i| i.outputs && !i.stale).count();
    let mut info = vec![
        Line::styled(s.name.clone(), t.title()),
        Line::raw(crate::text::path(&s.dir).to_string()),
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
        Line::raw("e writes the PostScript and SVG reports"),
        Line::raw("c reads and checks every file"),
    ];
    let reports: Vec<_> = app
        .chrome
        .log
        .entries()
        .filter(|e| e.text.starts_with("report written"))
        .collect();
    if !reports.is_empty() {
        info.push(Line::styled("reports written", t.title()));
        for e in reports.iter().rev().take(4) {
            let what = e.text.split(" — ").next().unwrap_or(&e.text);
            let name = what.rsplit('/').next().unwrap_or(what);
            info.push(Line::raw(format!(" {} {name}", e.time)));
        }
    }
    Paragraph::new(info)
        .wrap(Wrap { trim: true })
        .block(block(app, "session"))
        .render(panel, buf);
    let problems = s.problems();
    let inner_w = right.width.saturating_sub(2) as usize;
    let wrapped = |text: &str, st| -> Vec<Line<'static>> {
        super::chrome::wrap(text, inner_w)
            .into_iter()
            .map(|l| Line::styled(l, st))
            .collect()
    };
    let mut lines: Vec<Line> = if problems > 0 {
        wrapped(
            &format!(
                "{problems} problem(s), listed first: {} — R on the Survey screen (1) puts an \
                 image right",
                s.problem_list().join(", ")
            ),
            t.error(),
        )
    } else if s.checked {
        vec![Line::styled("every file reads", t.ok())]
    } else {
        vec![Line::styled(
            "no problems known (c checks every file)",
            t.ok(),
        )]
    };
    let rows = super::chrome::marked(app, SearchTarget::Files, file_items(app, inner_w));
    let room = (right.height.saturating_sub(2) as usize).saturating_sub(lines.len());
    lines.extend(window(rows, app.screens.files.scroll, room, t));
    Paragraph::new(lines)
        .block(block(app, &format!("files ({})", s.files.len())))
        .render(right, buf);
}

/// The file list's entries at `width`: problems first, each wrapped whole
/// (why a file is damaged is what the operator came for), then files that
/// read but changed since recorded, wrapped whole, then the files that
/// read, one row each, cut at the width (the drawing and `/` both use
/// them; `/` searches an entry's whole text).
pub fn file_items(app: &App, width: usize) -> Vec<Item> {
    let t = app.theme();
    let Some(s) = &app.session.view else {
        return Vec::new();
    };
    let mut files: Vec<&crate::tui::event::FileState> = s.files.iter().collect();
    files.sort_by_key(|f| (f.ok, !f.changed));
    let mut items: Vec<Item> = Vec::new();
    for f in files {
        let text = format!("{:<16} {}", f.name, f.state);
        let rows = if !f.ok {
            super::chrome::wrap(&text, width)
                .into_iter()
                .map(|l| Line::styled(l, t.error()))
                .collect()
        } else if f.changed {
            super::chrome::wrap(&text, width)
                .into_iter()
                .map(|l| Line::styled(l, t.warn()))
                .collect()
        } else if text.chars().count() > width {
            let cut = text
                .chars()
                .take(width.saturating_sub(1))
                .collect::<String>()
                + "…";
            vec![Line::styled(cut, t.ok())]
        } else {
            vec![Line::styled(text.clone(), t.ok())]
        };
        items.push(Item { text, rows });
    }
    items
}
