//! A session open only to look (its folder cannot be written: a
//! read-only mount, no write permission; or another console that still
//! runs holds it; opened so after the operator chose it): the images,
//! lines and files can be seen, and every action that would write into it
//! is refused here, before anything changes, with what was refused. The
//! hint line offers only the keys [`App::refused_here`] lets through. The
//! store refuses the same writes again.
//!
//! The same refusals hold while another session is being opened (a
//! take-over waits up to seconds for its holder): the store does its
//! commands in order, so a save asked meanwhile would land in the session
//! it opens, not in the one on screen.

use super::App;
use super::session::Opening;
use crate::tui::event::{Cmd, StoreCmd};
use crate::tui::keymap::{Action, EditAction, FilesAction, PipelineAction, SurveyAction};
use crate::tui::text::clean;

/// The status line's words for such a session.
pub const READ_ONLY: &str = "read-only: nothing will be saved";

impl App {
    /// Whether the open session is open only to look.
    pub fn read_only(&self) -> bool {
        self.session.read_only()
    }

    /// What `a` would do that a session open only to look refuses, when
    /// the open session is one (`None`: `a` goes on). The one rule of
    /// what works read-only: the refusal ([`App::act`]) and the hint line
    /// both follow it.
    pub fn refused_here(&self, a: Action) -> Option<&'static str> {
        if !self.read_only() && self.session.opening.is_empty() {
            return None;
        }
        match a {
            // Nothing is captured here: no capture to set up.
            Action::Survey(SurveyAction::Camera) => Some("choosing a capture's camera"),
            Action::Survey(SurveyAction::Location) => Some("choosing a capture's location"),
            a => self.would_write(a),
        }
    }

    /// Notes a session asked of the store in `cmds` ([`App::update`]'s),
    /// as said: writes wait until the store says it is done
    /// ([`crate::tui::event::StoreEvent::OpeningDone`]).
    pub(super) fn note_opening(&mut self, cmds: &[Cmd]) {
        for c in cmds {
            let asked = match c {
                Cmd::Store(StoreCmd::Create(name)) => format!("new session {name}"),
                Cmd::Store(
                    StoreCmd::Open(d) | StoreCmd::TakeOver(d) | StoreCmd::OpenReadOnly(d),
                ) => format!(
                    "session {}",
                    d.file_name().unwrap_or(d.as_os_str()).to_string_lossy()
                ),
                _ => continue,
            };
            let since = self.chrome.log.pushed();
            self.session.opening.push(Opening {
                what: clean(&asked),
                since,
            });
        }
    }

    /// What `a` would write into the open session, if it would.
    fn would_write(&self, a: Action) -> Option<&'static str> {
        let survey = &self.screens.survey;
        let w = &self.session.work;
        match a {
            // Enter on the image under work captures it, accepts it or
            // starts one beyond the plan; on another row it only shows
            // that image, and in the list it opens a session.
            Action::Survey(SurveyAction::Enter)
                if !survey.picking
                    && survey.row(w) == w.k
                    && matches!(
                        w.phase,
                        super::Phase::Setup | super::Phase::Review | super::Phase::Complete
                    ) =>
            {
                Some(match w.phase {
                    super::Phase::Setup => "capturing",
                    super::Phase::Review => "accepting",
                    _ => "a new image",
                })
            }
            Action::Survey(SurveyAction::Accept) => Some("accepting"),
            Action::Survey(SurveyAction::Redo) => Some("taking an image again"),
            Action::Pipeline(PipelineAction::Save) => Some("saving the outputs"),
            Action::Edit(
                EditAction::Connect
                | EditAction::Extend
                | EditAction::Delete
                | EditAction::Undo
                | EditAction::Redo,
            ) => Some("editing the lines"),
            Action::Files(FilesAction::Export) => Some("writing the reports"),
            _ => None,
        }
    }

    /// Refuses `a` when [`App::refused_here`] says so (said on the message
    /// line, with what was refused); whether it was.
    pub(super) fn refused_read_only(&mut self, a: Action) -> bool {
        let Some(what) = self.refused_here(a) else {
            return false;
        };
        if let Some(Opening { what: next, .. }) = self.session.opening.last() {
            let msg = format!(
                "{what} refused: {next} is being opened — wait until it is (the store would \
                 write it there, not into the session on screen)"
            );
            self.ctx().warn(msg);
            return true;
        }
        let name = self
            .session
            .view
            .as_ref()
            .map(|v| v.name.clone())
            .unwrap_or_default();
        self.ctx().error(format!(
            "{READ_ONLY} — {what} refused: session {name} is open only to look; o opens \
             another session"
        ));
        true
    }
}
