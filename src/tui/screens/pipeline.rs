//! The Pipeline screen: the stage outputs one at a time or side by side,
//! the parameter panel (arrows, `+`/`-`, typed values; each change re-runs
//! only the affected stages off the UI thread), counts and per-stage times,
//! and a zoomable preview with a cursor reporting pixel, grey and response.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget};

use super::{PreviewNav, block, split_panel};
use crate::llv::params::{PARAMS, ParamSpec};
use crate::tui::app::{App, Loaded, fmt_value};
use crate::tui::keymap::{self, Action, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview};

/// The stage views, in Tab order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageView {
    Grey,
    Corrected,
    EdgesH,
    EdgesV,
    LinesRaw,
    Lines,
    Overlay,
}

impl StageView {
    pub const ALL: [StageView; 7] = [
        StageView::Grey,
        StageView::Corrected,
        StageView::EdgesH,
        StageView::EdgesV,
        StageView::LinesRaw,
        StageView::Lines,
        StageView::Overlay,
    ];
    pub fn title(self) -> &'static str {
        match self {
            StageView::Grey => "grey",
            StageView::Corrected => "corrected",
            StageView::EdgesH => "edges H",
            StageView::EdgesV => "edges V",
            StageView::LinesRaw => "raw lines",
            StageView::Lines => "connected lines",
            StageView::Overlay => "lines over grey",
        }
    }
    fn index(self) -> usize {
        Self::ALL.iter().position(|&v| v == self).unwrap_or(0)
    }
}

/// The Pipeline screen's own state.
#[derive(Clone, Debug)]
pub struct PipelineScreen {
    /// Index into [`PARAMS`].
    pub param: usize,
    pub view: StageView,
    pub side_by_side: bool,
    pub nav: PreviewNav,
}

impl Default for PipelineScreen {
    fn default() -> Self {
        PipelineScreen {
            param: 0,
            view: StageView::Overlay,
            side_by_side: false,
            nav: PreviewNav::default(),
        }
    }
}

impl PipelineScreen {
    pub fn param_spec(&self) -> &'static ParamSpec {
        PARAMS.get(self.param).unwrap_or(&PARAMS[0])
    }

    /// Handles the screen's own keys (selection, views, zoom, cursor);
    /// returns what the App must do.
    pub fn handle_key(&mut self, key: KeyEvent, size: Option<(usize, usize)>) -> Option<Action> {
        let a = keymap::lookup(Scope::Screen(ScreenId::Pipeline), &key)?;
        let n = StageView::ALL.len();
        match a {
            Action::ParamPrev => self.param = self.param.saturating_sub(1),
            Action::ParamNext => self.param = (self.param + 1).min(PARAMS.len() - 1),
            Action::ViewNext => self.view = StageView::ALL[(self.view.index() + 1) % n],
            Action::ViewPrev => self.view = StageView::ALL[(self.view.index() + n - 1) % n],
            Action::SideBySide => self.side_by_side = !self.side_by_side,
            other if self.nav.apply(other, size) => {}
            other => return Some(other),
        }
        None
    }
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let (panel, right) = split_panel(area, 32);
    params_panel(app, panel, buf);
    let [views, info] = Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(right);
    let Some(cur) = app.current.as_ref().filter(|c| !c.frames.is_empty()) else {
        Paragraph::new("No image yet: capture one on the Survey screen (1).")
            .block(block(app, "preview"))
            .render(views, buf);
        return;
    };
    if app.pipeline.side_by_side {
        let cols = if views.width >= 120 { 4 } else { 3 };
        let rows = StageView::ALL.len().div_ceil(cols);
        let row_areas =
            Layout::vertical(vec![Constraint::Ratio(1, rows as u32); rows]).split(views);
        for (r, ra) in row_areas.iter().enumerate() {
            let cells =
                Layout::horizontal(vec![Constraint::Ratio(1, cols as u32); cols]).split(*ra);
            for (c, ca) in cells.iter().enumerate() {
                if let Some(v) = StageView::ALL.get(r * cols + c) {
                    stage_view(app, cur, *v, *ca, buf);
                }
            }
        }
    } else {
        stage_view(app, cur, app.pipeline.view, views, buf);
    }
    cursor_line(app, cur, info, buf);
}

fn stage_view(app: &App, cur: &Loaded, v: StageView, area: Rect, buf: &mut Buffer) {
    let grey = &cur.frames[0].1;
    let out = cur.outputs.as_deref();
    let layer = match (v, out) {
        (StageView::Grey, _) => Some(Layer::Grey(grey)),
        (StageView::Corrected, Some(o)) => Some(Layer::Grey(o.corrected.first().unwrap_or(grey))),
        (StageView::EdgesH, Some(o)) => Some(Layer::Edges(&o.edges_h)),
        (StageView::EdgesV, Some(o)) => Some(Layer::Edges(&o.edges_v)),
        (StageView::LinesRaw, Some(o)) => Some(Layer::Lines(&o.lines_raw)),
        (StageView::Lines, Some(o)) => Some(Layer::Lines(&o.lines)),
        (StageView::Overlay, Some(o)) => Some(Layer::LinesOver(
            o.corrected.first().unwrap_or(grey),
            &o.lines,
        )),
        _ => None,
    };
    let count = match (v, out) {
        (StageView::EdgesH, Some(o)) => format!(" {}", o.edges_h.points.len()),
        (StageView::EdgesV, Some(o)) => format!(" {}", o.edges_v.points.len()),
        (StageView::LinesRaw, Some(o)) => format!(" {}", o.lines_raw.len()),
        (StageView::Lines | StageView::Overlay, Some(o)) => format!(" {}", o.lines.len()),
        _ => String::new(),
    };
    let stale = match (v, app.outputs_stale()) {
        (StageView::Grey, _) | (_, None) => String::new(),
        (_, Some(why)) => format!(" — {why}"),
    };
    let b = block(app, &format!("{}{count}{stale}", v.title()));
    let inner = b.inner(area);
    b.render(area, buf);
    match layer {
        Some(layer) => {
            let mut p = Preview::new(layer, app.look.mode, app.look.colour);
            // Edge and line layers keep the grey image's frame, so the
            // cursor and zoom line up across views.
            p.view = app.pipeline.nav.view;
            let size = grey.size();
            p.frame = Some(size);
            p.cursor = Some(app.pipeline.nav.cursor_or_centre(size));
            p.render(inner, buf);
        }
        None => Paragraph::new("running…").render(inner, buf),
    }
}

fn params_panel(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let inner_h = area.height.saturating_sub(2) as usize;
    let stats_rows = 7usize.min(inner_h / 2);
    let room = inner_h.saturating_sub(stats_rows).max(1);
    let sel = app.pipeline.param;
    let skip = (sel + 1).saturating_sub(room);
    let mut lines: Vec<Line> = PARAMS
        .iter()
        .enumerate()
        .skip(skip)
        .take(room)
        .map(|(i, sp)| {
            let v = app.params.get(sp.key).map(fmt_value).unwrap_or_default();
            let w = (area.width as usize)
                .saturating_sub(3 + sp.key.len())
                .max(v.len());
            let text = format!("{} {v:>w$}", sp.key);
            if i == sel {
                Line::styled(text, t.selected())
            } else {
                Line::raw(text)
            }
        })
        .collect();
    let cur = app.current.as_ref();
    match cur.and_then(|c| c.outputs.as_ref()) {
        Some(o) => {
            let ms = |us: u64| us as f64 / 1000.0;
            lines.push(Line::styled(
                format!(
                    "edges H {} V {}",
                    o.edges_h.points.len(),
                    o.edges_v.points.len()
                ),
                t.title(),
            ));
            lines.push(Line::styled(
                format!("lines {} raw {}", o.lines.len(), o.lines_raw.len()),
                t.title(),
            ));
            lines.push(Line::raw(format!(
                "ms lens {:.1} edges {:.1}",
                ms(o.timings.lens_us),
                ms(o.timings.edges_us)
            )));
            lines.push(Line::raw(format!(
                "   lines {:.1} connect {:.1}",
                ms(o.timings.lines_us),
                ms(o.timings.connect_us)
            )));
        }
        None => lines.push(Line::styled("no outputs yet", t.dim())),
    }
    let sp = app.pipeline.param_spec();
    lines.push(Line::from(vec![
        Span::styled(format!("{} ", sp.range_text()), t.dim()),
        Span::styled(sp.unit, t.dim()),
    ]));
    lines.push(Line::styled(sp.doc, t.dim()));
    let title = if app.pipeline_busy() {
        "parameters (running)"
    } else {
        "parameters"
    };
    Paragraph::new(lines)
        .wrap(ratatui::widgets::Wrap { trim: true })
        .block(block(app, title))
        .render(area, buf);
}

fn cursor_line(app: &App, cur: &Loaded, area: Rect, buf: &mut Buffer) {
    let grey = &cur.frames[0].1;
    let (x, y) = app.pipeline.nav.cursor_or_centre(grey.size());
    let g = grey.get(x, y).map_or("-".into(), |v| v.to_string());
    let resp = |r: Option<&crate::llv::edges::Response>| -> String {
        r.and_then(|r| r.get(x, y))
            .filter(|v| v.is_finite())
            .map_or("-".into(), |v| format!("{v:+.1}"))
    };
    let out = cur.outputs.as_deref();
    let text = format!(
        "x{x} y{y} grey {g} H{} V{} zoom {} [{}]",
        resp(out.map(|o| &o.response_h)),
        resp(out.map(|o| &o.response_v)),
        app.pipeline.nav.view.zoom,
        app.look_name()
    );
    Paragraph::new(text).render(area, buf);
}
