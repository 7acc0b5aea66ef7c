//! Drawing the console: the frame every screen shares (top bar with the
//! screen keys, log pane, status bar with the current keys, help overlay,
//! questions) and, under `screens/`, one file per screen with its own state,
//! its `handle_key` and its drawing. Drawing only reads the [`App`].

use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Widget, Wrap};

use super::app::{App, Level, LogView, Modal};
use super::keymap::{self, Action, Scope, ScreenId};
use super::widgets::preview::Viewport;

mod calibrate;
mod capture;
mod edit;
mod pipeline;
mod session;
mod survey;

pub use calibrate::CalibrateScreen;
pub use capture::CaptureScreen;
pub use edit::EditScreen;
pub use pipeline::{PipelineScreen, StageView};
pub use session::SessionScreen;
pub use survey::SurveyScreen;

/// Styles that respect `NO_COLOR`: without colour only bold, reverse and
/// dim are used.
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

/// A bordered block with a title; plain ASCII borders in ASCII mode.
pub fn block(app: &App, title: &str) -> Block<'static> {
    let b = Block::default()
        .borders(Borders::ALL)
        .title(Span::styled(format!(" {title} "), app.theme().title()));
    if app.look.mode == super::widgets::preview::PreviewMode::Ascii {
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

/// Zoom, pan and a cursor over a preview: shared by Pipeline and Edit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviewNav {
    pub view: Viewport,
    /// Pixel under the cursor (`None` = image centre).
    pub cursor: Option<(usize, usize)>,
}

impl PreviewNav {
    /// Applies a navigation action; false if it is not one.
    pub fn apply(&mut self, a: Action, size: Option<(usize, usize)>) -> bool {
        let Some((w, h)) = size else {
            return matches!(
                a,
                Action::ZoomIn
                    | Action::ZoomOut
                    | Action::CursorLeft
                    | Action::CursorRight
                    | Action::CursorUp
                    | Action::CursorDown
                    | Action::PanLeft
                    | Action::PanRight
                    | Action::PanUp
                    | Action::PanDown
            );
        };
        let (cx, cy) = self.cursor_or_centre((w, h));
        // One press moves about a sixty-fourth of the visible width.
        let step = ((w as f64 / 64.0 / self.view.zoom).round() as usize).max(1);
        let mv = |c: usize, d: isize, max: usize| -> usize {
            (c as isize + d * step as isize).clamp(0, max as isize - 1) as usize
        };
        match a {
            Action::ZoomIn => {
                self.view.zoom_in();
                self.view.centre = Some((cx as f64 + 0.5, cy as f64 + 0.5));
            }
            Action::ZoomOut => self.view.zoom_out(),
            Action::CursorLeft => self.cursor = Some((mv(cx, -1, w), cy)),
            Action::CursorRight => self.cursor = Some((mv(cx, 1, w), cy)),
            Action::CursorUp => self.cursor = Some((cx, mv(cy, -1, h))),
            Action::CursorDown => self.cursor = Some((cx, mv(cy, 1, h))),
            Action::PanLeft => self.view.pan(-0.25, 0.0, (w, h)),
            Action::PanRight => self.view.pan(0.25, 0.0, (w, h)),
            Action::PanUp => self.view.pan(0.0, -0.25, (w, h)),
            Action::PanDown => self.view.pan(0.0, 0.25, (w, h)),
            _ => return false,
        }
        true
    }

    pub fn cursor_or_centre(&self, (w, h): (usize, usize)) -> (usize, usize) {
        let (x, y) = self.cursor.unwrap_or((w / 2, h / 2));
        (x.min(w.saturating_sub(1)), y.min(h.saturating_sub(1)))
    }
}

impl App {
    pub fn theme(&self) -> Theme {
        Theme {
            colour: self.look.colour,
        }
    }

    /// The preview mode as the operator would ask for it.
    pub fn look_name(&self) -> &'static str {
        use super::widgets::preview::PreviewMode as M;
        match (self.look.mode, self.look.colour) {
            (M::Ascii, _) => "ascii",
            (M::Braille, _) => "braille",
            (M::Blocks, true) => "blocks",
            (M::Blocks, false) => "blocks, no colour",
        }
    }
}

impl Widget for &App {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.width < 10 || area.height < 4 {
            Paragraph::new("vss: window too small").render(area, buf);
            return;
        }
        let log_rows = match self.log_view {
            LogView::Hidden => 0,
            LogView::Line => 1,
            LogView::Expanded => (area.height / 2).max(3),
        };
        let [top, body, log, status] = Layout::vertical([
            Constraint::Length(1),
            Constraint::Min(1),
            Constraint::Length(log_rows),
            Constraint::Length(1),
        ])
        .areas(area);
        self.top_bar(top, buf);
        match self.screen {
            ScreenId::Survey => survey::render(self, body, buf),
            ScreenId::Capture => capture::render(self, body, buf),
            ScreenId::Pipeline => pipeline::render(self, body, buf),
            ScreenId::Edit => edit::render(self, body, buf),
            ScreenId::Session => session::render(self, body, buf),
            ScreenId::Calibrate => calibrate::render(self, body, buf),
        }
        self.log_pane(log, buf);
        self.status_bar(status, buf);
        if let Some(m) = &self.modal {
            self.modal_box(m, area, buf);
        }
        if self.help {
            self.help_overlay(area, buf);
        }
        if self.look.mode == super::widgets::preview::PreviewMode::Ascii {
            asciify(area, buf);
        }
    }
}

/// Replaces every non-ASCII symbol with an ASCII look-alike, for terminals
/// without Unicode (the ASCII preview mode promises plain ASCII output).
fn asciify(area: Rect, buf: &mut Buffer) {
    for y in area.top()..area.bottom() {
        for x in area.left()..area.right() {
            let Some(cell) = buf.cell_mut((x, y)) else {
                continue;
            };
            if cell.symbol().is_ascii() {
                continue;
            }
            let c = match cell.symbol().chars().next().unwrap_or(' ') {
                '—' | '–' | '─' | '━' => '-',
                '│' | '┃' => '|',
                '…' | '·' => '.',
                '×' => 'x',
                '←' => '<',
                '→' => '>',
                '↑' => '^',
                '↓' => 'v',
                '°' => 'o',
                '┌' | '┐' | '└' | '┘' | '├' | '┤' | '┬' | '┴' | '┼' => '+',
                _ => '?',
            };
            cell.set_char(c);
        }
    }
}

impl App {
    fn top_bar(&self, area: Rect, buf: &mut Buffer) {
        let t = self.theme();
        let mut spans = vec![Span::styled(" vss ", t.title())];
        for (i, s) in ScreenId::ALL.iter().enumerate() {
            let label = format!(" {} {} ", i + 1, s.title());
            let st = if *s == self.screen {
                t.selected()
            } else {
                Style::new()
            };
            spans.push(Span::styled(label, st));
        }
        if let Some(s) = &self.session {
            let bar = if self.look.mode == super::widgets::preview::PreviewMode::Ascii {
                '|'
            } else {
                '│'
            };
            spans.push(Span::styled(format!(" {bar} {}", s.name), t.title()));
        }
        Line::from(spans).render(area, buf);
    }

    fn log_pane(&self, area: Rect, buf: &mut Buffer) {
        if area.height == 0 {
            return;
        }
        let t = self.theme();
        let rows = area.height as usize;
        let (inner, show) = if rows >= 3 {
            let b = block(self, "log");
            let inner = b.inner(area);
            b.render(area, buf);
            (inner, inner.height as usize)
        } else {
            (area, rows)
        };
        let n = self.log.len();
        let lines: Vec<Line> = self
            .log
            .entries()
            .skip(n.saturating_sub(show))
            .map(|e| {
                Line::from(vec![
                    Span::styled(format!("{} ", e.time), t.dim()),
                    Span::styled(e.text.clone(), t.level(e.level)),
                ])
            })
            .collect();
        Paragraph::new(lines).render(inner, buf);
    }

    fn status_bar(&self, area: Rect, buf: &mut Buffer) {
        let t = self.theme();
        let mut spans = Vec::new();
        if let Some(lost) = &self.device.lost {
            spans.push(Span::styled(format!("DEVICE LOST: {lost} "), t.error()));
        } else if !self.device.connected {
            spans.push(Span::styled("connecting… ", t.warn()));
        }
        if let Some((_, done, total)) = self.device.transfer {
            spans.push(Span::styled(
                format!("transfer {} ", gauge_text(done, total, 18)),
                t.warn(),
            ));
        }
        if self.pipeline_busy() {
            spans.push(Span::styled("running… ", t.warn()));
        }
        // The keys that always work come first, so a narrow terminal cuts
        // the screen's own hints rather than how to get help or out.
        let scope = self.scope();
        let mut hints = if matches!(scope, Scope::Screen(_)) {
            keymap::hints(Scope::Global)
        } else {
            Vec::new()
        };
        hints.extend(keymap::hints(scope));
        for (k, d) in hints {
            spans.push(Span::styled(k, t.key()));
            spans.push(Span::raw(format!(" {d} ")));
        }
        Line::from(spans).render(area, buf);
    }

    fn modal_box(&self, m: &Modal, area: Rect, buf: &mut Buffer) {
        let t = self.theme();
        let w = area.width.min(64);
        let r = Rect::new(
            area.x + (area.width - w) / 2,
            area.y + area.height / 2 - 2,
            w,
            4.min(area.height),
        );
        Clear.render(r, buf);
        let (title, body) = match m {
            Modal::Prompt { title, text, .. } => (
                "type, Enter accepts, Esc cancels",
                Line::from(vec![
                    Span::styled(format!("{title} "), t.title()),
                    Span::raw(text.clone()),
                    Span::styled("_", t.key()),
                ]),
            ),
            Modal::Confirm { question, .. } => (
                "y / n",
                Line::from(vec![Span::styled(question.clone(), t.warn())]),
            ),
        };
        Paragraph::new(body)
            .wrap(Wrap { trim: true })
            .block(block(self, title))
            .render(r, buf);
    }

    fn help_overlay(&self, area: Rect, buf: &mut Buffer) {
        let t = self.theme();
        let r = Rect::new(
            area.x + 1,
            area.y + 1,
            area.width.saturating_sub(2),
            area.height.saturating_sub(2),
        );
        Clear.render(r, buf);
        let mut lines = vec![Line::styled(
            format!("{} screen", self.screen.title()),
            t.title(),
        )];
        let row = |(k, d): (String, &str)| {
            Line::from(vec![
                Span::styled(format!("{k:>9} "), t.key()),
                Span::raw(d.to_string()),
            ])
        };
        lines.extend(
            keymap::describe(Scope::Screen(self.screen))
                .into_iter()
                .map(row),
        );
        lines.push(Line::styled("Everywhere", t.title()));
        lines.extend(keymap::describe(Scope::Global).into_iter().map(row));
        let b = block(self, "help — any key closes");
        let inner = b.inner(r);
        b.render(r, buf);
        // Too many rows for one column (80 x 24): flow into two.
        let rows = inner.height.max(1) as usize;
        let cols = lines.len().div_ceil(rows).clamp(1, 3);
        let areas = Layout::horizontal(vec![Constraint::Ratio(1, cols as u32); cols]).split(inner);
        for (i, a) in areas.iter().enumerate() {
            let part: Vec<Line> = lines.iter().skip(i * rows).take(rows).cloned().collect();
            Paragraph::new(part).render(*a, buf);
        }
    }
}

/// Two areas side by side: a panel of `panel` columns (at most half) and the rest.
pub fn split_panel(area: Rect, panel: u16) -> (Rect, Rect) {
    let p = panel.min(area.width / 2);
    let [a, b] = Layout::horizontal([Constraint::Length(p), Constraint::Min(1)]).areas(area);
    (a, b)
}
