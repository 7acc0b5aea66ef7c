//! The Capture screen: the live picture of the selected camera, camera
//! choice, the lights panel (each light on/off, each lighting configuration
//! one key) and what the grabber and relay board report.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, block2, gauge_text, split_panel};
use crate::tui::app::App;
use crate::tui::widgets::preview::{Layer, Preview, stretch_of};

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 32);
    let d = &app.cell.device;
    let cap = &app.screens.capture;
    let mut lines = vec![
        Line::styled("grabber", t.title()),
        if let Some(e) = &d.lost {
            Line::styled(format!(" {}: {e}", d.lost_word()), t.error())
        } else if d.connected {
            Line::raw(format!(" {}", d.grabber))
        } else {
            Line::styled(" connecting…", t.warn())
        },
        Line::styled("relay board", t.title()),
        Line::raw(format!(" {} mask {:#06x}", d.relay, d.mask)),
        Line::raw(format!(
            "camera {} (c)  live {} (v)",
            cap.camera,
            if d.live { "ON" } else { "off" }
        )),
        Line::styled("lights (↑↓ Space, 0 all off)", t.title()),
    ];
    for (i, (name, relay)) in app.cell.lights.iter().enumerate() {
        let on = d.lights_on.contains(name);
        let st = if i == cap.light {
            t.selected()
        } else {
            Default::default()
        };
        lines.push(Line::styled(
            format!(" [{}] {name} (relay {relay})", if on { 'x' } else { ' ' }),
            st,
        ));
    }
    lines.push(Line::styled("lightings (Shift+letter)", t.title()));
    for (l, on) in &app.cell.lighting_on {
        let now = {
            let mut a = on.clone();
            let mut b = d.lights_on.clone();
            a.sort();
            b.sort();
            a == b
        };
        lines.push(Line::from(vec![
            Span::styled(format!(" {}", l.to_ascii_uppercase()), t.key()),
            Span::raw(format!(
                " {}{}",
                if on.is_empty() {
                    "ambient".to_string()
                } else {
                    on.join("+")
                },
                if now { "  <" } else { "" }
            )),
        ]));
    }
    if let Some((_, done, total)) = d.transfer {
        lines.push(Line::raw(if d.settling && done == 0 {
            "lights settling…".to_string()
        } else {
            gauge_text(done, total, panel.width.saturating_sub(2) as usize)
        }));
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block(app, "devices"))
        .render(panel, buf);
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
