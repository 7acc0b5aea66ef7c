//! The Session/Report screen: the session's summary with a one-line count
//! of its problems, every file with its state (damaged ones with why), and
//! the reports written.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, split_panel, window};
use crate::tui::app::App;

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
            let name = e.text.rsplit('/').next().unwrap_or(&e.text);
            info.push(Line::raw(format!(" {} {name}", e.time)));
        }
    }
    Paragraph::new(info)
        .wrap(Wrap { trim: true })
        .block(block(app, "session"))
        .render(panel, buf);
    let problems = s.problems();
    let mut lines = vec![if problems > 0 {
        Line::styled(
            format!("{problems} problem(s): the files in red do not read or are missing"),
            t.error(),
        )
    } else if s.checked {
        Line::styled("every file reads", t.ok())
    } else {
        Line::styled("no problems known (c checks every file)", t.ok())
    }];
    let inner_w = right.width.saturating_sub(2) as usize;
    let rows: Vec<Line> = s
        .files
        .iter()
        .map(|f| {
            let st = if f.ok { t.ok() } else { t.error() };
            let text = format!("{:<16} {}", f.name, f.state);
            let text: String = if text.chars().count() > inner_w {
                text.chars()
                    .take(inner_w.saturating_sub(1))
                    .collect::<String>()
                    + "…"
            } else {
                text
            };
            Line::styled(text, st)
        })
        .collect();
    let room = right.height.saturating_sub(3) as usize;
    lines.extend(window(rows, app.screens.files.scroll, room, t));
    Paragraph::new(lines)
        .block(block(app, &format!("files ({})", s.files.len())))
        .render(right, buf);
}
