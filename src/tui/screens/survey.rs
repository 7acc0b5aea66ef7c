//! The Survey screen: the session list (no session yet), then the
//! checklist of image numbers and lightings, the step the survey is at, and
//! a preview of the current image.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, gauge_text, split_panel};
use crate::tui::app::{App, Phase};
use crate::tui::event::FramePurpose;
use crate::tui::keymap::{self, Action, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview};

/// What the Survey screen remembers itself: the highlighted session.
#[derive(Clone, Debug, Default)]
pub struct SurveyScreen {
    pub selected: usize,
}

impl SurveyScreen {
    pub fn handle_key(&mut self, key: KeyEvent) -> Option<Action> {
        keymap::lookup(Scope::Screen(ScreenId::Survey), &key)
    }
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let (panel, right) = split_panel(area, 34);
    if app.session.is_none() {
        sessions(app, panel, buf);
    } else {
        checklist(app, panel, buf);
    }
    let [step, prev] = Layout::vertical([Constraint::Length(4), Constraint::Min(1)]).areas(right);
    step_box(app, step, buf);
    let b = block(app, "image");
    let inner = b.inner(prev);
    b.render(prev, buf);
    let cur = app
        .current
        .as_ref()
        .filter(|c| c.k == app.work.k || app.work.phase == Phase::Setup);
    if let Some(c) = cur
        && let Some((_, img)) = c.frames.last()
    {
        let layer = match (&c.outputs, app.work.phase) {
            (Some(o), Phase::Review) => Layer::LinesOver(img, &o.lines),
            _ => Layer::Grey(img),
        };
        Preview::new(layer, app.look.mode, app.look.colour).render(inner, buf);
    } else {
        Paragraph::new("no image yet").render(inner, buf);
    }
}

fn sessions(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let mut lines = vec![Line::raw("Sessions in the survey folder:")];
    if app.sessions.is_empty() {
        lines.push(Line::styled("  (none yet)", t.dim()));
    }
    for (i, (name, _, summary)) in app.sessions.iter().enumerate() {
        let st = if i == app.survey.selected {
            t.selected()
        } else {
            Default::default()
        };
        lines.push(Line::styled(format!(" {name:<12} {summary}"), st));
    }
    lines.push(Line::raw(""));
    lines.push(Line::from(vec![
        Span::styled("n", t.key()),
        Span::raw(" new session"),
    ]));
    lines.push(Line::from(vec![
        Span::styled("o", t.key()),
        Span::raw(" open the chosen one (↑↓)"),
    ]));
    Paragraph::new(lines)
        .block(block(app, "choose a session"))
        .render(area, buf);
}

fn checklist(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let Some(s) = &app.session else { return };
    let letters: String = s.letters.iter().collect();
    let mut lines = vec![
        Line::styled(format!("session {}", s.name), t.title()),
        Line::raw(format!("lightings {letters}")),
        Line::raw("img cam loc lights  out"),
    ];
    let mut ks: Vec<u32> = s.images.iter().map(|i| i.k).collect();
    if !ks.contains(&app.work.k) {
        ks.push(app.work.k);
    }
    ks.sort_unstable();
    let room = area.height.saturating_sub(2 + 3) as usize;
    // Keep the current image visible on a small terminal.
    let pos = ks.iter().position(|&k| k == app.work.k).unwrap_or(0);
    let skip = (pos + 1).saturating_sub(room);
    for &k in ks.iter().skip(skip).take(room) {
        let st = s.images.iter().find(|i| i.k == k);
        let captured: Vec<char> = match (&app.current, st) {
            (Some(c), _) if c.k == k => c.frames.iter().map(|f| f.0).collect(),
            (_, Some(i)) => i.captured.clone(),
            _ => Vec::new(),
        };
        let marks: String = s
            .letters
            .iter()
            .map(|l| if captured.contains(l) { *l } else { '.' })
            .collect();
        let (cam, loc) = st.map_or((app.work.camera, app.work.location), |i| {
            (i.camera, i.location)
        });
        let out = match st {
            Some(i) if i.stale => "stale",
            Some(i) if i.outputs => "done",
            _ => "-",
        };
        let line = format!("{k:>3} {cam:>3} {loc:>3} {marks:<7} {out}");
        let style = if k == app.work.k {
            t.selected()
        } else if out == "done" {
            t.ok()
        } else {
            Default::default()
        };
        lines.push(Line::styled(line, style));
    }
    Paragraph::new(lines)
        .block(block(app, "checklist"))
        .render(area, buf);
}

fn step_box(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let w = &app.work;
    let text: Vec<Line> = match w.phase {
        Phase::NoSession => vec![Line::raw("Create a session (n) or open one (o).")],
        Phase::Setup => {
            let missing: String = app.missing_letters().iter().collect();
            vec![
                Line::raw(format!(
                    "Image {}: camera {} (c), location {} (p)",
                    w.k, w.camera, w.location
                )),
                Line::from(vec![
                    Span::styled("Enter", t.key()),
                    Span::raw(if missing.is_empty() {
                        " runs the stages".to_string()
                    } else {
                        format!(" captures lightings {missing}")
                    }),
                ]),
            ]
        }
        Phase::Capturing => {
            let now = match app.device.transfer {
                Some((FramePurpose::Survey { letter, .. }, d, n)) => {
                    format!("lighting {letter} {}", gauge_text(d, n, 30))
                }
                _ => "switching lights…".into(),
            };
            vec![
                Line::raw(format!("Image {}: capturing", w.k)),
                Line::raw(now),
                Line::styled("Esc cancels", t.dim()),
            ]
        }
        Phase::Processing => vec![Line::raw(format!("Image {}: running the stages…", w.k))],
        Phase::Review => {
            let (n, raw) = app
                .current
                .as_ref()
                .and_then(|c| c.outputs.as_ref())
                .map_or((0, 0), |o| (o.lines.len(), o.lines_raw.len()));
            vec![
                Line::raw(format!("Image {}: {n} lines ({raw} before CONNECT)", w.k)),
                Line::from(vec![
                    Span::styled("a", t.key()),
                    Span::raw(" accept   "),
                    Span::styled("r", t.key()),
                    Span::raw(" redo   "),
                    Span::styled("3", t.key()),
                    Span::raw(" tune   "),
                    Span::styled("4", t.key()),
                    Span::raw(" edit"),
                ]),
            ]
        }
    };
    Paragraph::new(text)
        .wrap(Wrap { trim: true })
        .block(block(app, "next step"))
        .render(area, buf);
}
