//! The Capture screen: the live picture of the selected camera, camera
//! choice, the lights panel (each light on/off, each lighting configuration
//! one key) and what the grabber and relay board report.

use ratatui::buffer::Buffer;
use ratatui::crossterm::event::KeyEvent;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, gauge_text, split_panel};
use crate::tui::app::App;
use crate::tui::keymap::{self, Action, Scope, ScreenId};
use crate::tui::widgets::preview::{Layer, Preview};

/// The Capture screen's own state: the highlighted light and the camera.
#[derive(Clone, Debug)]
pub struct CaptureScreen {
    pub light: usize,
    pub camera: u32,
}

impl Default for CaptureScreen {
    fn default() -> Self {
        CaptureScreen {
            light: 0,
            camera: 1,
        }
    }
}

impl CaptureScreen {
    pub fn handle_key(&mut self, key: KeyEvent) -> Option<Action> {
        keymap::lookup(Scope::Screen(ScreenId::Capture), &key)
    }
}

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let (panel, right) = split_panel(area, 32);
    let d = &app.device;
    let mut lines = vec![
        Line::styled("grabber", t.title()),
        if let Some(e) = &d.lost {
            Line::styled(format!(" LOST: {e}"), t.error())
        } else if d.connected {
            Line::raw(format!(" {}", d.grabber))
        } else {
            Line::styled(" connecting…", t.warn())
        },
        Line::styled("relay board", t.title()),
        Line::raw(format!(" {} mask {:#06x}", d.relay, d.mask)),
        Line::raw(format!(
            "camera {} (c)  live {} (v)",
            app.capture.camera,
            if d.live { "ON" } else { "off" }
        )),
        Line::styled("lights (↑↓ Space, o off)", t.title()),
    ];
    for (i, (name, relay)) in app.lights.iter().enumerate() {
        let on = d.lights_on.contains(name);
        let st = if i == app.capture.light {
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
    for (l, on) in &app.lighting_on {
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
        lines.push(Line::raw(gauge_text(
            done,
            total,
            panel.width.saturating_sub(2) as usize,
        )));
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block(app, "devices"))
        .render(panel, buf);
    let title = match &app.live {
        Some((cam, img)) => format!("camera {cam} {}×{}", img.width(), img.height()),
        None => "no picture: v live, g grab".into(),
    };
    let b = block(app, &title);
    let inner = b.inner(right);
    b.render(right, buf);
    if let Some((_, img)) = &app.live {
        Preview::new(Layer::Grey(img), app.look.mode, app.look.colour).render(inner, buf);
    }
}
