//! Drawing the console: the frame every screen shares (`screens/chrome.rs`:
//! top bar with the screen keys, session and profile; the newest message
//! wrapped over up to three rows, or the scrollable log pane; the hints of
//! the current keys; help, message window, questions) and, under
//! `screens/`, one file per screen. Drawing only reads the [`App`].

use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Widget, Wrap};

use super::app::{App, Level, LogView};
use super::keymap::ScreenId;
use super::widgets::preview::PreviewMode;

mod calibrate;
mod capture;
pub mod chrome;
mod edit;
mod pipeline;
pub mod session;
pub mod survey;

pub use crate::tui::app::MIN_SIZE;

/// Styles that respect `NO_COLOR`: without colour only bold, reverse and
/// dim are used; with colour only the sixteen basic colours, which every
/// colour terminal has (the Linux console included).
#[derive(Clone, Copy, Debug)]
pub struct Theme {
    pub colour: bool,
}

impl Theme {
    pub fn selected(self) -> Style {
        if self.colour {
            Style::new().fg(Color::Black).bg(Color::Cyan)
        } else {
            Style::new().add_modifier(Modifier::REVERSED)
        }
    }
    pub fn title(self) -> Style {
        Style::new().add_modifier(Modifier::BOLD)
    }
    pub fn error(self) -> Style {
        if self.colour {
            Style::new().fg(Color::Red).add_modifier(Modifier::BOLD)
        } else {
            Style::new().add_modifier(Modifier::BOLD)
        }
    }
    pub fn warn(self) -> Style {
        if self.colour {
            Style::new().fg(Color::Yellow)
        } else {
            Style::new()
        }
    }
    pub fn ok(self) -> Style {
        if self.colour {
            Style::new().fg(Color::Green)
        } else {
            Style::new()
        }
    }
    pub fn dim(self) -> Style {
        if self.colour {
            Style::new().fg(Color::DarkGray)
        } else {
            Style::new()
        }
    }
    pub fn key(self) -> Style {
        if self.colour {
            Style::new().fg(Color::Cyan).add_modifier(Modifier::BOLD)
        } else {
            Style::new().add_modifier(Modifier::BOLD)
        }
    }
    pub fn level(self, l: Level) -> Style {
        match l {
            Level::Info => Style::new(),
            Level::Warn => self.warn(),
            Level::Error => self.error(),
        }
    }
}

impl App {
    pub fn theme(&self) -> Theme {
        Theme {
            colour: self.chrome.look.colour,
        }
    }

    pub fn ascii(&self) -> bool {
        self.chrome.look.mode == PreviewMode::Ascii
    }
}

/// A bordered block with a title; plain ASCII borders in ASCII mode.
pub fn block(app: &App, title: &str) -> Block<'static> {
    let b = Block::default()
        .borders(Borders::ALL)
        .title(Span::styled(format!(" {title} "), app.theme().title()));
    if app.ascii() {
        b.border_set(ratatui::symbols::border::Set {
            top_left: "+",
            top_right: "+",
            bottom_left: "+",
            bottom_right: "+",
            vertical_left: "|",
            vertical_right: "|",
            horizontal_top: "-",
            horizontal_bottom: "-",
        })
    } else {
        b
    }
}

/// [`block`] with a second title on its bottom border (what a picture
/// shows: its stretch, where the view is).
pub fn block2(app: &App, title: &str, bottom: &str) -> Block<'static> {
    block(app, title).title_bottom(Span::styled(format!(" {bottom} "), app.theme().dim()))
}

/// A progress bar in text: `[#####.....] 52%`, ASCII in every mode.
pub fn gauge_text(done: usize, total: usize, width: usize) -> String {
    let w = width.saturating_sub(7).max(4);
    let frac = if total == 0 {
        0.0
    } else {
        (done as f64 / total as f64).clamp(0.0, 1.0)
    };
    let n = (frac * w as f64).round() as usize;
    format!(
        "[{}{}] {:>3}%",
        "#".repeat(n),
        ".".repeat(w - n),
        (frac * 100.0).round() as u32
    )
}

/// Two areas side by side: a panel of `panel` columns (at most half) and the rest.
pub fn split_panel(area: Rect, panel: u16) -> (Rect, Rect) {
    let p = panel.min(area.width / 2);
    let [a, b] = Layout::horizontal([Constraint::Length(p), Constraint::Min(1)]).areas(area);
    (a, b)
}

/// Which rows of a list of `n` a box of `room` rows shows around row
/// `focus`: the first shown, how many, and whether a "more" marker sits
/// above them (and so below, when they end before the list).
pub fn window_span(n: usize, focus: usize, room: usize) -> (usize, usize, bool) {
    if n <= room {
        return (0, n, false);
    }
    if room == 0 {
        return (0, 0, false);
    }
    let focus = focus.min(n - 1);
    let mut shown = room;
    loop {
        let start = focus.saturating_sub(shown / 2).min(n - shown);
        let (above, below) = (start > 0, start + shown < n);
        if shown + usize::from(above) + usize::from(below) <= room || shown == 1 {
            return (start, shown, above);
        }
        shown -= 1;
    }
}

/// Lines of a list cut to `room` rows around row `focus`, with a "more"
/// marker where rows are left out above or below.
pub fn window<'a>(rows: Vec<Line<'a>>, focus: usize, room: usize, t: Theme) -> Vec<Line<'a>> {
    let n = rows.len();
    let (start, shown, above) = window_span(n, focus, room);
    if shown == n {
        return rows;
    }
    let mut out = Vec::with_capacity(room);
    if above {
        out.push(Line::styled(format!("  ↑ {start} more"), t.dim()));
    }
    out.extend(rows.into_iter().skip(start).take(shown));
    if start + shown < n {
        out.push(Line::styled(
            format!("  ↓ {} more", n - start - shown),
            t.dim(),
        ));
    }
    out.truncate(room);
    out
}

/// The areas of the frame at `area`: top bar, body, message rows, hints.
pub struct Frame {
    pub top: Rect,
    pub body: Rect,
    pub message: Rect,
    pub hints: Rect,
}

impl App {
    /// How the frame divides the terminal (used by drawing and the mouse).
    pub fn frame(&self, area: Rect) -> Frame {
        let msg_rows = match self.chrome.log_view {
            LogView::Hidden if !self.chrome.hidden_shows_message() => 0,
            LogView::Hidden | LogView::Line => chrome::message_rows(self, area.width),
            LogView::Expanded => (area.height / 2).max(5),
        };
        let [top, body, message, hints] = Layout::vertical([
            Constraint::Length(1),
            Constraint::Min(1),
            Constraint::Length(msg_rows),
            Constraint::Length(chrome::hint_rows(self, area.width)),
        ])
        .areas(area);
        Frame {
            top,
            body,
            message,
            hints,
        }
    }
}

/// A terminal too small for the screens: what goes on, what is asked and
/// the answer to the last key stay in sight, with their keys on the
/// bottom rows as the hint row has them, so a window only a few rows high
/// still says how to answer or quit; why nothing else is drawn comes
/// after, in what room is left.
fn too_small(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let mut text = vec![Line::styled("terminal too small", t.error())];
    // A capture under way.
    if let Some((purpose, done, total)) = app.cell.device.transfer {
        let what = match purpose {
            crate::tui::event::FramePurpose::Survey { letter, .. } => {
                format!("image {} lighting {letter}", app.session.work.k)
            }
            _ => "a frame".to_string(),
        };
        let pct = (done * 100).checked_div(total).unwrap_or(0);
        text.push(Line::styled(
            format!("capturing {what}: {pct}% — Esc stops"),
            t.warn(),
        ));
    } else if app.session.work.phase == crate::tui::app::Phase::Capturing {
        text.push(Line::styled(
            format!("capturing image {} — Esc stops", app.session.work.k),
            t.warn(),
        ));
    }
    // The question asked, and its keys.
    let (keys, wait) = match &app.chrome.modal {
        Some(m @ crate::tui::app::Modal::Confirm { question, .. }) => {
            text.push(Line::styled(question.clone(), t.title()));
            let keys: Vec<String> = m
                .choices()
                .iter()
                .map(|(k, w)| format!("{k} {w}"))
                .collect();
            (keys.join("  "), "")
        }
        Some(crate::tui::app::Modal::Prompt(p)) => {
            text.push(Line::styled(format!("{} {}", p.title, p.text), t.title()));
            ("Enter accept  Esc cancel".to_string(), "")
        }
        None => ("q quits".to_string(), "other keys wait for a larger window"),
    };
    // The answer to the last key while it is held (Esc where it does
    // nothing says so here, not only once the window is larger again).
    if app.chrome.held.is_some()
        && let Some((e, _)) = app.chrome.shown_message()
    {
        text.push(Line::styled(e.shown(), t.level(e.level)));
    }
    text.push(Line::raw(format!(
        "now {} × {}, vss needs {} × {}: enlarge the window",
        area.width, area.height, MIN_SIZE.0, MIN_SIZE.1
    )));
    if !wait.is_empty() {
        text.push(Line::raw(wait));
    }
    let keys: Vec<Line> = chrome::wrap(&keys, usize::from(area.width))
        .into_iter()
        .map(Line::raw)
        .collect();
    let rows = u16::try_from(keys.len())
        .unwrap_or(u16::MAX)
        .min(area.height);
    let [upper, lower] =
        Layout::vertical([Constraint::Min(0), Constraint::Length(rows)]).areas(area);
    Paragraph::new(text)
        .wrap(Wrap { trim: true })
        .render(upper, buf);
    Paragraph::new(keys).render(lower, buf);
    if app.ascii() {
        chrome::asciify(area, buf);
    }
}

impl Widget for &App {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.width < MIN_SIZE.0 || area.height < MIN_SIZE.1 {
            too_small(self, area, buf);
            return;
        }
        let f = self.frame(area);
        chrome::top_bar(self, f.top, buf);
        match self.chrome.screen {
            ScreenId::Survey => survey::render(self, f.body, buf),
            ScreenId::Capture => capture::render(self, f.body, buf),
            ScreenId::Pipeline => pipeline::render(self, f.body, buf),
            ScreenId::Edit => edit::render(self, f.body, buf),
            ScreenId::Session => session::render(self, f.body, buf),
            ScreenId::Calibrate => calibrate::render(self, f.body, buf),
        }
        match self.chrome.log_view {
            LogView::Expanded => chrome::log_pane(self, f.message, buf),
            LogView::Line | LogView::Hidden => chrome::message(self, f.message, buf),
        }
        chrome::hints(self, f.hints, buf);
        // A question or field opened over the help (`/` there) is drawn
        // over it.
        if let Some(o) = self.chrome.overlay {
            // Over all but the hint rows, which say its keys.
            let over = Rect {
                height: area.height.saturating_sub(f.hints.height),
                ..area
            };
            chrome::overlay(self, o, over, buf);
        }
        if let Some(m) = &self.chrome.modal {
            chrome::modal_box(self, m, area, buf);
        }
        if self.ascii() {
            chrome::asciify(area, buf);
        }
    }
}

/// A signed readout with one decimal, never `-0.0`.
pub fn signed(v: f32) -> String {
    let s = format!("{v:+.1}");
    match s.as_str() {
        "-0.0" | "+0.0" => "0.0".into(),
        _ => s,
    }
}

/// The columns of a screen's left panel.
pub fn panel_width(s: ScreenId) -> u16 {
    match s {
        ScreenId::Survey | ScreenId::Session | ScreenId::Calibrate => 34,
        ScreenId::Capture | ScreenId::Pipeline => 32,
        ScreenId::Edit => 30,
    }
}

/// Where a mouse event falls on the console drawn at `area`.
pub fn pointer(
    app: &App,
    area: Rect,
    m: ratatui::crossterm::event::MouseEvent,
) -> Option<super::event::Pointer> {
    use super::event::Pointer;
    use ratatui::crossterm::event::{MouseButton, MouseEventKind};
    let (col, row) = (m.column, m.row);
    let inside = |r: Rect| col >= r.x && col < r.right() && row >= r.y && row < r.bottom();
    let f = app.frame(area);
    let wheel = match m.kind {
        MouseEventKind::ScrollUp => Some(true),
        MouseEventKind::ScrollDown => Some(false),
        MouseEventKind::Down(MouseButton::Left) => None,
        _ => return None,
    };
    if app.chrome.overlay.is_some() || inside(f.message) {
        return wheel.map(|up| Pointer::ScrollLog { up });
    }
    if !inside(f.body) {
        return None;
    }
    let screen = app.chrome.screen;
    let (panel, right) = split_panel(f.body, panel_width(screen));
    let inner = |r: Rect| Block::default().borders(Borders::ALL).inner(r);
    if inside(panel) {
        if let Some(up) = wheel {
            return Some(Pointer::ScrollList { up });
        }
        let p = inner(panel);
        let r = row.checked_sub(p.y)? as usize;
        return match screen {
            ScreenId::Survey if app.session.view.is_none() || app.screens.survey.picking => {
                let rows = survey::session_rows(app, p.width as usize);
                let focus = survey::selected_row(&rows, app.screens.survey.selected);
                let room = (p.height as usize).saturating_sub(4);
                let (start, shown, above) = window_span(rows.len(), focus, room);
                let i = r.checked_sub(1 + usize::from(above))?;
                (i < shown).then(|| rows.get(start + i).map(|row| Pointer::SessionRow(row.0)))?
            }
            ScreenId::Survey => {
                let ks = app.session.numbers();
                let sel = app.screens.survey.row(&app.session.work);
                let focus = ks.iter().position(|&k| k == sel).unwrap_or(0);
                let room = (p.height as usize).saturating_sub(survey::CHECKLIST_HEAD as usize);
                let (start, shown, above) = window_span(ks.len(), focus, room);
                let i = r.checked_sub(survey::CHECKLIST_HEAD as usize + usize::from(above))?;
                (i < shown).then(|| ks.get(start + i).copied().map(Pointer::Checklist))?
            }
            ScreenId::Pipeline => {
                let n = crate::llv::params::PARAMS.len();
                let inner_h = p.height as usize;
                let doc = app.screens.pipeline.param_spec().doc;
                let doc_rows = chrome::wrap(doc, p.width as usize).len();
                let room = inner_h
                    .saturating_sub((5 + doc_rows).min(inner_h / 2))
                    .max(1);
                let (start, shown, above) = window_span(n, app.screens.pipeline.param, room);
                let i = r.checked_sub(usize::from(above))?;
                (i < shown).then_some(Pointer::Param(start + i))
            }
            ScreenId::Capture | ScreenId::Edit | ScreenId::Session | ScreenId::Calibrate => None,
        };
    }
    if !inside(right) || !super::keymap::has_picture(screen) {
        return wheel.map(|up| Pointer::ScrollList { up });
    }
    if let Some(zoom_in) = wheel {
        return Some(Pointer::Zoom { zoom_in });
    }
    // The picture's cells: the right side below the survey's step box,
    // above the Pipeline's cursor line, inside the border.
    let pic = match screen {
        ScreenId::Survey => Rect {
            y: right.y + 5,
            height: right.height.saturating_sub(5),
            ..right
        },
        ScreenId::Pipeline if app.screens.pipeline.side_by_side => return None,
        ScreenId::Pipeline => Rect {
            height: right.height.saturating_sub(1),
            ..right
        },
        _ => right,
    };
    let pic = inner(pic);
    if !inside(pic) {
        return None;
    }
    let size = app.picture_size(screen)?;
    let nav = app.screens.nav(screen)?;
    let geo = super::widgets::preview::Geometry::new(pic, size, &nav.view);
    let (x, y) = geo.cell_to_pixel(col - pic.x, row - pic.y, size)?;
    Some(Pointer::Pixel(x, y))
}
