//! The Edit screen: the lines over the grey image — the highlighted line,
//! the selection and the last edit's result each in their own colour —
//! the figures of the highlighted and selected lines, and the edits of
//! this image in words.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, block2, split_panel};
use crate::llv::Segment;
use crate::llv::edit::point_words;
use crate::tui::app::App;
use crate::tui::widgets::preview::{Layer, Preview, stretch_of};

fn describe_line(i: usize, s: &Segment) -> String {
    format!(
        "#{i} {}-{} {:.0}px",
        point_words(s.a),
        point_words(s.b),
        s.length()
    )
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 30);
    let cur = app.tracker.current.as_ref();
    let lines = cur.and_then(|c| c.lines());
    let ed = &app.screens.edit;
    let mut info = Vec::new();
    match (cur, lines) {
        (Some(c), Some(ls)) => {
            let state = if c.accepted {
                "accepted"
            } else {
                "not accepted"
            };
            info.push(Line::styled(
                format!("image {}: {} lines, {state}", c.k, ls.len()),
                t.title(),
            ));
            let size = app.tracker.preview_size().unwrap_or((1, 1));
            let (x, y) = ed.nav.cursor_or_centre(size);
            info.push(Line::raw(format!("cursor {x} {y}")));
            info.push(Line::styled("highlighted (n p . Tab)", t.title()));
            match ed.highlighted.and_then(|i| ls.get(i).map(|s| (i, s))) {
                Some((i, s)) => info.push(Line::styled(describe_line(i, s), t.warn())),
                None => info.push(Line::styled(" none", t.dim())),
            }
            info.push(Line::styled("selected (Space, v corner)", t.title()));
            if ed.selected.is_empty() {
                info.push(Line::styled(" none", t.dim()));
            }
            for &i in ed.selected.iter().take(4) {
                if let Some(s) = ls.get(i) {
                    info.push(Line::raw(describe_line(i, s)));
                }
            }
            let edits: Vec<_> = app
                .chrome
                .log
                .entries()
                .rev()
                .filter(|e| {
                    e.text.starts_with(&format!("image {}: ", c.k))
                        && ["connected", "extended", "deleted", "undone", "redone"]
                            .iter()
                            .any(|w| e.text.contains(w))
                })
                .take(3)
                .collect();
            if !edits.is_empty() {
                info.push(Line::styled("last edits", t.title()));
                for e in edits {
                    let text = e.text.split_once(": ").map_or(&e.text[..], |x| x.1);
                    info.push(Line::raw(format!(" {text}")));
                }
            }
        }
        _ => info.push(Line::raw(
            "No lines yet: capture and run an image, or go to one (Survey, 1).",
        )),
    }
    Paragraph::new(info)
        .wrap(Wrap { trim: true })
        .block(block(app, "lines"))
        .render(panel, buf);
    let (Some(c), Some(ls)) = (cur, lines) else {
        block(app, "lines over grey").render(right, buf);
        return;
    };
    let Some((letter, grey)) = c.frames.first() else {
        block(app, "lines over grey").render(right, buf);
        return;
    };
    let bg = c
        .outputs
        .as_ref()
        .and_then(|o| o.corrected.first())
        .unwrap_or(grey);
    let s = stretch_of(bg);
    let stale = app
        .tracker
        .stale()
        .map(|w| format!("{w} · "))
        .unwrap_or_default();
    let title = format!(
        "{stale}image {}{letter} · lines over grey {}",
        c.k,
        ls.len()
    );
    let size = grey.size();
    let b = block2(
        app,
        &title,
        &format!(
            "grey {}–{} stretched · {}",
            s.lo,
            s.hi,
            ed.nav.position(size)
        ),
    );
    let inner = b.inner(right);
    b.render(right, buf);
    let mut p = Preview::new(
        Layer::LinesOver(bg, ls),
        app.chrome.look.mode,
        app.chrome.look.colour,
    );
    p.palette.c256 = app.chrome.look.c256;
    p.view = ed.nav.view;
    p.selected = &ed.selected;
    p.highlighted = ed.highlighted;
    p.result = &ed.result;
    p.cursor = Some(ed.nav.cursor_or_centre(grey.size()));
    p.render(inner, buf);
}
