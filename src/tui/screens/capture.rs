//! The Capture screen: the live picture of the selected camera, camera
//! choice, the lights panel (each light on/off and each lighting
//! configuration, chosen with ↑↓ and set with Space; the first six also by
//! Shift+letter) and what the grabber and relay board report.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget};

use super::chrome::wrap;
use super::{block, block2, gauge_text, split_panel, window};
use crate::tui::app::App;
use crate::tui::keymap::{self, Action, CaptureAction, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview, stretch_of};

const CAPTURE: Scope = Scope::Screen(ScreenId::Capture);

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 32);
    let d = &app.cell.device;
    let cap = &app.screens.capture;
    let outer = block(app, "devices");
    let inner = outer.inner(panel);
    outer.render(panel, buf);
    let width = usize::from(inner.width).max(1);
    // The devices' lines wrap (a port's path is long); the lights panel's
    // rows below them are a list cut to the room left, around the chosen row.
    let mut top: Vec<Line> = Vec::new();
    let mut wrapped = |text: String, style: Style| {
        top.extend(
            wrap(&text, width)
                .into_iter()
                .map(|r| Line::styled(r, style)),
        );
    };
    wrapped("grabber".into(), t.title());
    if let Some(e) = &d.lost {
        wrapped(format!(" {}: {e}", d.lost_word()), t.error());
    } else if d.connected {
        wrapped(format!(" {}", d.grabber), Style::default());
    } else {
        wrapped(" connecting…".into(), t.warn());
    }
    wrapped("relay board".into(), t.title());
    wrapped(
        format!(" {} mask {:#06x}", d.relay, d.mask),
        Style::default(),
    );
    wrapped(
        format!(
            "camera {} (c)  live {} (v)",
            cap.camera,
            if d.live { "ON" } else { "off" }
        ),
        Style::default(),
    );
    let chosen = |row: usize| {
        if row == cap.light {
            t.selected()
        } else {
            Style::default()
        }
    };
    let mut list = vec![Line::styled("lights (↑↓ Space, 0 all off)", t.title())];
    for (i, (name, relay)) in app.cell.lights.iter().enumerate() {
        let on = d.lights_on.contains(name);
        list.push(Line::styled(
            format!(" [{}] {name} (relay {relay})", if on { 'x' } else { ' ' }),
            chosen(i),
        ));
    }
    list.push(Line::styled("lightings (Space, Shift+key)", t.title()));
    let mut lit = d.lights_on.clone();
    lit.sort();
    for (i, (l, on)) in app.cell.lighting_on.iter().enumerate() {
        let row = app.cell.lights.len() + i;
        let now = {
            let mut a = on.clone();
            a.sort();
            a == lit
        };
        // A lighting with a key of its own shows it; the others (the key
        // table has six) are set by ↑↓ and Space.
        let action = u8::try_from(i).map(|i| Action::Capture(CaptureAction::Lighting(i)));
        let key = match action.ok().and_then(|a| keymap::key_label(CAPTURE, a)) {
            Some(k) => Span::styled(format!(" {k}"), t.key()),
            None => Span::styled(format!(" {l}"), t.dim()),
        };
        list.push(
            Line::from(vec![
                key,
                Span::raw(format!(
                    " {}{}",
                    if on.is_empty() {
                        "ambient".to_string()
                    } else {
                        on.join("+")
                    },
                    if now { "  <" } else { "" }
                )),
            ])
            .style(chosen(row)),
        );
    }
    let gauge = d.transfer.map(|(_, done, total)| {
        Line::raw(if d.settling && done == 0 {
            "lights settling…".to_string()
        } else {
            gauge_text(done, total, width)
        })
    });
    // The chosen row's place in the list: past the lights' title, and past
    // the lightings' one for a lighting.
    let focus = cap.light + 1 + usize::from(cap.light >= app.cell.lights.len());
    let room = usize::from(inner.height)
        .saturating_sub(top.len())
        .saturating_sub(usize::from(gauge.is_some()));
    let mut lines = top;
    lines.extend(window(list, focus, room, t));
    lines.extend(gauge);
    Paragraph::new(lines).render(inner, buf);
    let b = match &app.cell.live {
        Some((cam, img)) => {
            let s = stretch_of(img);
            block2(
                app,
                &format!("camera {cam} {}×{}", img.width(), img.height()),
                &format!(
                    "grey {}–{} stretched · {}",
                    s.lo,
                    s.hi,
                    cap.nav.position(img.size())
                ),
            )
        }
        None => block(app, "no picture: v live, g grab"),
    };
    let inner = b.inner(right);
    b.render(right, buf);
    if let Some((_, img)) = &app.cell.live {
        let mut p = Preview::new(
            Layer::Grey(img),
            app.chrome.look.mode,
            app.chrome.look.colour,
        );
        p.palette.c256 = app.chrome.look.c256;
        p.view = cap.nav.view;
        if cap.nav.cursor.is_some() {
            p.cursor = Some(cap.nav.cursor_or_centre(img.size()));
        }
        p.render(inner, buf);
    }
}
