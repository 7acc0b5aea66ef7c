//! The mouse, where the terminal sends it: the shell places each event on
//! what is drawn there ([`Pointer`]), and here it becomes the same action
//! a key would be — a click chooses a checklist row, a session, a
//! parameter, or a point of the picture (the Edit screen highlights the
//! line nearest it); the wheel scrolls lists, the log and the help, and
//! zooms pictures.

use super::{App, Overlay};
use crate::tui::event::{Cmd, Pointer};
use crate::tui::keymap::{
    Action, EditAction, FilesAction, GlobalAction, NavAction, PipelineAction, ScreenId,
    SurveyAction, ViewerAction,
};

impl App {
    pub(super) fn on_pointer(&mut self, p: Pointer) -> Vec<Cmd> {
        if self.chrome.modal.is_some() {
            return Vec::new();
        }
        let screen = self.chrome.screen;
        match p {
            Pointer::ScrollLog { up } => {
                if self.chrome.overlay.is_some() {
                    self.chrome.viewer(if up {
                        ViewerAction::Up
                    } else {
                        ViewerAction::Down
                    });
                    return Vec::new();
                }
                self.act(Action::Global(if up {
                    GlobalAction::LogUp
                } else {
                    GlobalAction::LogDown
                }))
            }
            _ if matches!(
                self.chrome.overlay,
                Some(Overlay::Help { .. } | Overlay::Message { .. })
            ) =>
            {
                Vec::new()
            }
            Pointer::ScrollList { up } => match screen {
                ScreenId::Survey => self.act(Action::Survey(if up {
                    SurveyAction::Up
                } else {
                    SurveyAction::Down
                })),
                ScreenId::Pipeline => self.act(Action::Pipeline(if up {
                    PipelineAction::ParamPrev
                } else {
                    PipelineAction::ParamNext
                })),
                ScreenId::Session => self.act(Action::Files(if up {
                    FilesAction::Up
                } else {
                    FilesAction::Down
                })),
                ScreenId::Capture | ScreenId::Edit | ScreenId::Calibrate => Vec::new(),
            },
            Pointer::Zoom { zoom_in } => self.act(Action::Nav(if zoom_in {
                NavAction::ZoomIn
            } else {
                NavAction::ZoomOut
            })),
            Pointer::Checklist(k) => {
                self.screens.survey.picking = false;
                self.screens.survey.row = Some(k);
                Vec::new()
            }
            Pointer::SessionRow(i) => {
                if i < self.session.list.len() {
                    self.screens.survey.selected = i;
                }
                Vec::new()
            }
            Pointer::Param(i) => {
                if i < crate::llv::params::PARAMS.len() {
                    self.screens.pipeline.param = i;
                }
                Vec::new()
            }
            Pointer::Pixel(x, y) => {
                let size = self.picture_size(screen);
                let Some(nav) = self.screens.nav_mut(screen) else {
                    return Vec::new();
                };
                if let Some((w, h)) = size {
                    nav.cursor = Some((x.min(w.saturating_sub(1)), y.min(h.saturating_sub(1))));
                }
                if screen == ScreenId::Edit {
                    return self.act(Action::Edit(EditAction::LineNearest));
                }
                Vec::new()
            }
        }
    }
}
