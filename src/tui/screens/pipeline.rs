//! The Pipeline screen: the stage outputs one at a time or side by side,
//! each titled with its image, lighting and what it shows (and "stale"
//! when the outputs are not the panel's); the parameter panel (values that
//! differ from the profile marked `*`, "more" where the list runs past
//! the box), counts and per-stage times; a cursor reporting pixel, grey
//! and responses, and where the view is.

use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, block2, signed, split_panel, window};
use crate::llv::GreyImage;
use crate::llv::params::{PARAMS, fmt_value};
use crate::tui::app::{App, GreySource, Loaded, StageView};
use crate::tui::widgets::preview::{Layer, Preview, stretch_of};

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let (panel, right) = split_panel(area, 32);
    params_panel(app, panel, buf);
    let [views, info] = Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(right);
    let Some(cur) = app
        .tracker
        .current
        .as_ref()
        .filter(|c| !c.frames.is_empty())
    else {
        Paragraph::new("No image yet: capture one, or go to one, on the Survey screen (1).")
            .wrap(Wrap { trim: true })
            .block(block(app, "preview"))
            .render(views, buf);
        return;
    };
    let grey = grey_image(app, cur);
    if app.screens.pipeline.side_by_side {
        let cols = if views.width >= 120 { 4 } else { 3 };
        let rows = StageView::ALL.len().div_ceil(cols);
        let row_areas =
            Layout::vertical(vec![Constraint::Ratio(1, rows as u32); rows]).split(views);
        for (r, ra) in row_areas.iter().enumerate() {
            let cells =
                Layout::horizontal(vec![Constraint::Ratio(1, cols as u32); cols]).split(*ra);
            for (c, ca) in cells.iter().enumerate() {
                if let Some(v) = StageView::ALL.get(r * cols + c) {
                    stage_view(app, cur, &grey, *v, *ca, true, buf);
                }
            }
        }
    } else {
        stage_view(
            app,
            cur,
            &grey,
            app.screens.pipeline.view,
            views,
            false,
            buf,
        );
    }
    cursor_line(app, cur, info, buf);
}

/// The image the grey views show: a lighting's frame, or the combined
/// response as grey. `None` when it is not there (the response of saved
/// outputs before a run).
pub struct GreyView<'a> {
    pub image: std::borrow::Cow<'a, GreyImage>,
    pub name: String,
    pub letter: Option<char>,
}

fn grey_image<'a>(app: &App, cur: &'a Loaded) -> GreyView<'a> {
    let letters = &app.cell.letters;
    let first = || {
        let (l, g) = &cur.frames[0];
        GreyView {
            image: std::borrow::Cow::Borrowed(g),
            name: format!("lighting {l}"),
            letter: Some(*l),
        }
    };
    match app.screens.pipeline.grey {
        GreySource::Lighting(i) => {
            let Some(&l) = letters.get(i) else {
                return first();
            };
            match cur.frame(l) {
                Some(g) => GreyView {
                    image: std::borrow::Cow::Borrowed(g),
                    name: app.screens.pipeline.grey_name(&app.cell),
                    letter: Some(l),
                },
                None => first(),
            }
        }
        GreySource::Combined => match cur.outputs.as_deref().and_then(combined) {
            Some(g) => GreyView {
                image: std::borrow::Cow::Owned(g),
                name: "combined response".into(),
                letter: None,
            },
            None => GreyView {
                name: "lighting a (no response yet: change a value to run)".into(),
                ..first()
            },
        },
    }
}

/// `sqrt(H² + V²)` of the combined responses as a grey image (its
/// percentile stretch maps it to the whole ramp).
fn combined(o: &crate::llv::pipeline::StageOutputs) -> Option<GreyImage> {
    let (h, v) = (&o.response_h, &o.response_v);
    if h.width == 0 || h.width != v.width || h.height != v.height {
        return None;
    }
    let mag: Vec<f32> = (0..h.width * h.height)
        .map(|i| {
            let (a, b) = (h.value(i), v.value(i));
            let (a, b) = (
                if a.is_finite() { a } else { 0.0 },
                if b.is_finite() { b } else { 0.0 },
            );
            (a * a + b * b).sqrt()
        })
        .collect();
    let max = mag.iter().copied().fold(0.0f32, f32::max).max(1e-6);
    let data = mag
        .iter()
        .map(|m| (m / max * 255.0).round() as u8)
        .collect();
    GreyImage::new(h.width, h.height, data).ok()
}

fn stage_view(
    app: &App,
    cur: &Loaded,
    grey: &GreyView,
    v: StageView,
    area: Rect,
    small: bool,
    buf: &mut Buffer,
) {
    let out = cur.outputs.as_deref();
    let img: &GreyImage = &grey.image;
    // The corrected image of the lighting shown (lit lightings only, in
    // the order the frame rule gives the pipeline its images).
    let corrected = |o: &'_ crate::llv::pipeline::StageOutputs| -> Option<usize> {
        let l = grey.letter?;
        let lit = app.cell.rule.lit_letters(cur.frames.iter().map(|f| f.0));
        lit.iter()
            .position(|c| *c == l)
            .filter(|&i| i < o.corrected.len())
    };
    let layer = match (v, out) {
        (StageView::Grey, _) => Some(Layer::Grey(img)),
        (StageView::Corrected, Some(o)) => {
            Some(Layer::Grey(corrected(o).map_or(img, |i| &o.corrected[i])))
        }
        (StageView::EdgesH, Some(o)) => Some(Layer::Edges(&o.edges_h)),
        (StageView::EdgesV, Some(o)) => Some(Layer::Edges(&o.edges_v)),
        (StageView::LinesRaw, Some(o)) => Some(Layer::Lines(&o.lines_raw)),
        (StageView::Lines, Some(o)) => Some(Layer::Lines(&o.lines)),
        (StageView::Overlay, Some(o)) => Some(Layer::LinesOver(
            corrected(o).map_or(img, |i| &o.corrected[i]),
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
    let shows_grey = matches!(
        v,
        StageView::Grey | StageView::Corrected | StageView::Overlay
    );
    let bottom = if shows_grey {
        let s = match &layer {
            Some(Layer::Grey(g) | Layer::LinesOver(g, _)) => stretch_of(g),
            _ => stretch_of(img),
        };
        let not_corrected =
            v == StageView::Corrected && out.is_some_and(|o| corrected(o).is_none());
        format!(
            "{}{} · grey {}–{} stretched",
            grey.name,
            if not_corrected {
                " (not corrected)"
            } else {
                ""
            },
            s.lo,
            s.hi
        )
    } else {
        String::new()
    };
    let stale = match (v, app.tracker.stale()) {
        (StageView::Grey, _) | (_, None) => String::new(),
        (_, Some(why)) => format!("{why} · "),
    };
    let letter = match (shows_grey, grey.letter) {
        (true, Some(l)) => l.to_string(),
        _ => String::new(),
    };
    let top = if small {
        // Side by side: what the view is, and whether it is stale.
        let stale = if stale.is_empty() { "" } else { "STALE " };
        format!("{stale}{}{count}", v.title())
    } else {
        format!("{stale}image {}{letter} · {}{count}", cur.k, v.title())
    };
    let b = if bottom.is_empty() || small {
        block(app, &top)
    } else {
        block2(app, &top, &bottom)
    };
    let inner = b.inner(area);
    b.render(area, buf);
    match layer {
        Some(layer) => {
            let mut p = Preview::new(layer, app.chrome.look.mode, app.chrome.look.colour);
            p.palette.c256 = app.chrome.look.c256;
            // Edge and line layers keep the grey image's frame, so the
            // cursor and zoom line up across views.
            let nav = &app.screens.pipeline.nav;
            p.view = nav.view;
            let size = cur.frames[0].1.size();
            p.frame = Some(size);
            p.cursor = Some(nav.cursor_or_centre(size));
            p.render(inner, buf);
        }
        // Why the run failed is said here, not only in the message row,
        // where the saves that finish after it soon take its place.
        None => Paragraph::new(match &cur.failed {
            Some(why) => format!("the last run failed: {}", crate::tui::text::clean(why)),
            // A capture cut short: nothing runs until every lighting is in.
            None => match cur.missing(&app.cell.letters) {
                m if m.is_empty() => "running…".to_string(),
                m => format!(
                    "not run: {} not captured yet (Survey: {})",
                    crate::tui::app::lightings(&m),
                    if cur.k == app.session.work.k {
                        "Enter captures the rest"
                    } else {
                        "R on its row captures again"
                    }
                ),
            },
        })
        .wrap(Wrap { trim: true })
        .render(inner, buf),
    }
}

fn params_panel(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let inner_h = area.height.saturating_sub(2) as usize;
    let inner_w = area.width.saturating_sub(2) as usize;
    let sel = app.screens.pipeline.param;
    let doc_rows = super::chrome::wrap(app.screens.pipeline.param_spec().doc, inner_w).len();
    let stats_rows = (5 + doc_rows).min(inner_h / 2);
    let room = inner_h.saturating_sub(stats_rows).max(1);
    let params = &app.tracker.params;
    let rows: Vec<Line> = PARAMS
        .iter()
        .enumerate()
        .map(|(i, sp)| {
            let v = params.get(sp.key).map(fmt_value).unwrap_or_default();
            let changed = params.get(sp.key) != app.tracker.profile_params.get(sp.key);
            let mark = if changed { '*' } else { ' ' };
            let w = inner_w.saturating_sub(2 + sp.key.len()).max(v.len());
            let text = format!("{} {v:>w$}{mark}", sp.key);
            if i == sel {
                Line::styled(text, t.selected())
            } else if changed {
                Line::styled(text, t.warn())
            } else {
                Line::raw(text)
            }
        })
        .collect();
    let mut lines = window(rows, sel, room, t);
    let cur = app.tracker.current.as_ref();
    // Lens correction asked for but impossible: said where the lens time
    // would show, with why (the log has it whole).
    if params.lens.enabled
        && let Some(c) = cur
        && let Some(why) = c.lens_problem(&app.cell)
    {
        lines.push(Line::styled(format!("lens OFF — {why}"), t.warn()));
    }
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
            if cur.is_some_and(|c| c.from_disk) {
                lines.push(Line::styled("(saved outputs, not run)", t.dim()));
            } else {
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
        }
        None => lines.push(Line::styled("no outputs yet", t.dim())),
    }
    let sp = app.screens.pipeline.param_spec();
    let default = app
        .tracker
        .profile_params
        .get(sp.key)
        .map(fmt_value)
        .unwrap_or_default();
    lines.push(Line::from(vec![Span::styled(
        format!("{} {} · profile {default}", sp.range_text(), sp.unit),
        t.dim(),
    )]));
    lines.push(Line::styled(sp.doc, t.dim()));
    let title = if app.tracker.busy() {
        "parameters (running)"
    } else {
        "parameters (* changed)"
    };
    Paragraph::new(lines)
        .wrap(Wrap { trim: true })
        .block(block(app, title))
        .render(area, buf);
}

fn cursor_line(app: &App, cur: &Loaded, area: Rect, buf: &mut Buffer) {
    let grey = &cur.frames[0].1;
    let size = grey.size();
    let nav = &app.screens.pipeline.nav;
    let (x, y) = nav.cursor_or_centre(size);
    let g = grey.get(x, y).map_or("-".into(), |v| v.to_string());
    let resp = |r: Option<&crate::llv::edges::Response>| -> String {
        r.and_then(|r| r.get(x, y))
            .filter(|v| v.is_finite())
            .map_or("-".into(), signed)
    };
    let out = cur.outputs.as_deref();
    let (h, v) = (
        resp(out.map(|o| &o.response_h)),
        resp(out.map(|o| &o.response_v)),
    );
    let (zoom, at) = (nav.view.zoom, nav.position(size));
    // The longest that fits: at 80 columns a zoomed view's place would
    // run past the edge, so the words shorten, then the responses go
    // (the zoom and the place stay: they say what the picture shows).
    let compact = at.replace("x ", "x").replace("y ", "y");
    let text = [
        format!("x{x} y{y} grey {g} H {h} V {v} · ×{zoom} {at}"),
        format!("x{x} y{y} g{g} H{h} V{v} ×{zoom} {compact}"),
        format!("x{x} y{y} g{g} ×{zoom} {compact}"),
    ]
    .into_iter()
    .find(|t| t.chars().count() <= area.width as usize)
    .unwrap_or_else(|| format!("×{zoom} {compact}"));
    Paragraph::new(text).render(area, buf);
}
