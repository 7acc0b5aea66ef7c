//! The open session as the store worker last described it, the sessions
//! of the survey folder (damaged ones included, with why), and where the
//! guided survey stands.

use super::survey::Work;
pub use crate::tui::event::SessionEntry;
use crate::tui::event::{ImageState, SessionView};

#[derive(Debug, Default)]
pub struct SessionState {
    pub view: Option<SessionView>,
    pub list: Vec<SessionEntry>,
    pub work: Work,
    /// Images accepted whose outputs the store is saving: done for the
    /// survey's next step (the view says so only once they are saved).
    pub saving: Vec<u32>,
    /// Images whose acceptance failed (their outputs not saved), with why:
    /// said in the next-step box until they are accepted, so that no later
    /// message hides it.
    pub refused: Vec<Refused>,
    /// When the session list was last asked for ([`App::due`]).
    ///
    /// [`App::due`]: super::App::due
    pub listed: Option<std::time::Instant>,
    /// When the session open only to look was last asked to be read again
    /// ([`App::due`]).
    ///
    /// [`App::due`]: super::App::due
    pub looked: Option<std::time::Instant>,
    /// Sessions asked of the store and not opened or refused yet (what was
    /// asked, as said; oldest first, one [`StoreEvent::OpeningDone`] each):
    /// until none is left, writes are refused ([`App::refused_here`]).
    ///
    /// [`StoreEvent::OpeningDone`]: crate::tui::event::StoreEvent::OpeningDone
    /// [`App::refused_here`]: super::App::refused_here
    pub opening: Vec<Opening>,
}

/// A session asked of the store and not opened yet.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Opening {
    /// What was asked, as said ("session cube", "new session hull").
    pub what: String,
    /// The log's [`Log::pushed`] when it was asked: the opening's messages
    /// are those pushed since.
    ///
    /// [`Log::pushed`]: super::log::Log::pushed
    pub since: usize,
}

/// An image whose outputs are not saved, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refused {
    pub k: u32,
    pub why: String,
    /// A hand edit (or its undo) that was not written: the next edit
    /// written puts it right, as a save does.
    pub edit: bool,
}

impl SessionState {
    /// Whether the open session is open only to look.
    pub fn read_only(&self) -> bool {
        self.view.as_ref().is_some_and(|v| v.read_only)
    }

    /// Image `k`'s outputs are not saved, for `why` (`edit`: a hand edit
    /// not written); said once, the newest reason.
    pub fn refuse(&mut self, k: u32, why: String, edit: bool) {
        self.refused.retain(|r| r.k != k);
        self.refused.push(Refused { k, why, edit });
    }

    /// Image `k`'s outputs are saved: no refusal of it stands.
    pub fn saved(&mut self, k: u32) {
        self.refused.retain(|r| r.k != k);
    }
    /// The checklist row of image `k`.
    pub fn image(&self, k: u32) -> Option<&ImageState> {
        self.view.as_ref()?.images.iter().find(|i| i.k == k)
    }

    /// The image numbers the checklist shows: the session's, and the one
    /// under work.
    pub fn numbers(&self) -> Vec<u32> {
        let mut ks: Vec<u32> = self
            .view
            .as_ref()
            .map(|v| v.images.iter().map(|i| i.k).collect())
            .unwrap_or_default();
        let beyond = self.work.phase == super::Phase::Complete;
        if self.view.is_some() && self.work.k > 0 && !beyond && !ks.contains(&self.work.k) {
            ks.push(self.work.k);
        }
        ks.sort_unstable();
        ks
    }

    /// Whether image `k` has accepted, current outputs.
    pub fn accepted(&self, k: u32) -> bool {
        self.image(k).is_some_and(|i| i.outputs && !i.stale)
    }
}
