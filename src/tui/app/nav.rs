//! Zoom, pan and a cursor over a picture: the same keys on every screen
//! that shows one. Moving the cursor out of the visible part pans the view
//! after it, so the cursor is always on screen.

use crate::tui::keymap::NavAction;
use crate::tui::widgets::preview::Viewport;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviewNav {
    pub view: Viewport,
    /// Pixel under the cursor (`None` = image centre).
    pub cursor: Option<(usize, usize)>,
}

impl PreviewNav {
    /// Applies a navigation action to a picture of `size` (nothing without one).
    pub fn apply(&mut self, a: NavAction, size: Option<(usize, usize)>) {
        let Some((w, h)) = size else { return };
        let (cx, cy) = self.cursor_or_centre((w, h));
        // One press moves about a sixty-fourth of the visible width.
        let step = ((w as f64 / 64.0 / self.view.zoom).round() as usize).max(1);
        let mv = |c: usize, d: isize, max: usize| -> usize {
            (c as isize + d * step as isize).clamp(0, max as isize - 1) as usize
        };
        match a {
            NavAction::ZoomIn => {
                self.view.zoom_in();
                self.view.centre = Some((cx as f64 + 0.5, cy as f64 + 0.5));
            }
            NavAction::ZoomOut => self.view.zoom_out(),
            NavAction::CursorLeft => self.cursor = Some((mv(cx, -1, w), cy)),
            NavAction::CursorRight => self.cursor = Some((mv(cx, 1, w), cy)),
            NavAction::CursorUp => self.cursor = Some((cx, mv(cy, -1, h))),
            NavAction::CursorDown => self.cursor = Some((cx, mv(cy, 1, h))),
            NavAction::PanLeft => self.view.pan(-0.25, 0.0, (w, h)),
            NavAction::PanRight => self.view.pan(0.25, 0.0, (w, h)),
            NavAction::PanUp => self.view.pan(0.0, -0.25, (w, h)),
            NavAction::PanDown => self.view.pan(0.0, 0.25, (w, h)),
        }
        if matches!(
            a,
            NavAction::CursorLeft
                | NavAction::CursorRight
                | NavAction::CursorUp
                | NavAction::CursorDown
        ) {
            self.follow((w, h));
        }
    }

    /// Pans so that the cursor is inside the middle of the visible part.
    fn follow(&mut self, (w, h): (usize, usize)) {
        if self.view.zoom <= 1.0 {
            return;
        }
        let (x, y) = self.cursor_or_centre((w, h));
        let (vw, vh) = (w as f64 / self.view.zoom, h as f64 / self.view.zoom);
        let (mut cx, mut cy) = self.view.centre.unwrap_or((w as f64 / 2.0, h as f64 / 2.0));
        // Keep a margin of a tenth of the view on each side.
        let (mx, my) = (vw * 0.4, vh * 0.4);
        let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
        if px < cx - mx {
            cx = px + mx;
        } else if px > cx + mx {
            cx = px - mx;
        }
        if py < cy - my {
            cy = py + my;
        } else if py > cy + my {
            cy = py - my;
        }
        self.view.centre = Some((cx.clamp(0.0, w as f64), cy.clamp(0.0, h as f64)));
    }

    pub fn cursor_or_centre(&self, (w, h): (usize, usize)) -> (usize, usize) {
        let (x, y) = self.cursor.unwrap_or((w / 2, h / 2));
        (x.min(w.saturating_sub(1)), y.min(h.saturating_sub(1)))
    }

    /// Where the view is: `whole` or `x0–x1, y0–y1` in image pixels.
    pub fn position(&self, (w, h): (usize, usize)) -> String {
        if self.view.zoom <= 1.0 {
            return "whole image".into();
        }
        let (vw, vh) = (w as f64 / self.view.zoom, h as f64 / self.view.zoom);
        let (cx, cy) = self.view.centre.unwrap_or((w as f64 / 2.0, h as f64 / 2.0));
        let x0 = (cx - vw / 2.0).max(0.0).round();
        let y0 = (cy - vh / 2.0).max(0.0).round();
        let x1 = (cx + vw / 2.0).min(w as f64).round();
        let y1 = (cy + vh / 2.0).min(h as f64).round();
        format!("x {x0}–{x1} y {y0}–{y1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_view_follows_the_cursor() {
        let mut n = PreviewNav::default();
        let size = Some((512, 512));
        n.apply(NavAction::ZoomIn, size);
        n.apply(NavAction::ZoomIn, size);
        assert_eq!(n.view.zoom, 4.0);
        for _ in 0..60 {
            n.apply(NavAction::CursorRight, size);
        }
        let (x, _) = n.cursor.unwrap();
        let (cx, _) = n.view.centre.unwrap();
        let half = 512.0 / 4.0 / 2.0;
        assert!(
            (x as f64) < cx + half && (x as f64) > cx - half,
            "cursor {x} inside the view around {cx}"
        );
        assert!(n.position((512, 512)).starts_with("x "));
        n.apply(NavAction::ZoomOut, size);
        n.apply(NavAction::ZoomOut, size);
        assert_eq!(n.position((512, 512)), "whole image");
    }
}
