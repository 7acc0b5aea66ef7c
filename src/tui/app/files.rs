//! The Session/Report screen's state and keys: the file list's scroll,
//! checking every file, and writing the reports.

use super::Ctx;
use crate::tui::event::{Cmd, StoreCmd};
use crate::tui::keymap::FilesAction;

/// The Session screen's own state: how far the file list is scrolled.
#[derive(Clone, Debug, Default)]
pub struct FilesScreen {
    pub scroll: usize,
}

impl FilesScreen {
    pub fn update(&mut self, a: FilesAction, ctx: &mut Ctx) -> Vec<Cmd> {
        match a {
            FilesAction::Up => {
                self.scroll = self.scroll.saturating_sub(1);
                Vec::new()
            }
            FilesAction::Down => {
                let n = ctx.session.view.as_ref().map_or(0, |v| v.files.len());
                self.scroll = (self.scroll + 1).min(n.saturating_sub(1));
                Vec::new()
            }
            FilesAction::Export | FilesAction::Check if ctx.session.view.is_none() => {
                ctx.warn("no session open: open or create one on the Survey screen (1)");
                Vec::new()
            }
            FilesAction::Export => {
                ctx.info("writing the reports…");
                vec![Cmd::Store(StoreCmd::Export)]
            }
            FilesAction::Check => {
                ctx.info("checking every file of the session…");
                vec![Cmd::Store(StoreCmd::Refresh)]
            }
        }
    }
}
