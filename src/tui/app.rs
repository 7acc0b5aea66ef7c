//! The console's state and its one update function: `App::update(Msg) ->
//! Vec<Cmd>`. No I/O here — workers do the serial link, the LLV and the
//! disk, and report back as messages — so every behaviour of the console can
//! be driven by a test through messages alone.
//!
//! The state is grouped: what is known of the cell ([`CellState`]), the
//! open session and the survey's position ([`SessionState`]), the image
//! under work and its pipeline runs ([`Tracker`]), the frame around the
//! screens ([`Chrome`]), and each screen's own state ([`Screens`]). A key
//! becomes an [`Action`] through the key table; each action has one owner —
//! the frame, the picture, or a screen's `update(action, ctx)` — that
//! matches its own actions exhaustively. Drawing (`screens/`) only reads.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

use super::event::{Cmd, DeviceCmd, Msg, StoreCmd, StoreEvent};
use super::keymap::{self, Action, GlobalAction, ModalAction, NavAction, Scope, ScreenId};
use super::mode::Look;
use crate::profile::Profile;

mod calibrate;
mod capture;
mod cell;
mod chrome;
mod edit;
mod files;
mod log;
mod modal;
mod mouse;
mod nav;
mod pipeline;
mod readonly;
mod results;
mod search;
mod session;
mod survey;
mod tracker;

pub use calibrate::{CalibrateScreen, Centre, Field, PLATE, short_name};
pub use capture::CaptureScreen;
pub use cell::{CellState, DeviceState};
pub use chrome::{Chrome, LogView, MIN_SIZE, Overlay, Search, SearchTarget};
pub use edit::{EditScreen, describe_op};
pub use files::FilesScreen;
pub use log::{Level, Log, LogEntry};
pub use modal::{Modal, Pending, Prompt, PromptPurpose};
pub use nav::PreviewNav;
pub use pipeline::{GreySource, PipelineScreen, StageView};
pub use readonly::READ_ONLY;
pub use session::{Opening, Refused, SessionEntry, SessionState};
pub use survey::{Phase, SurveyScreen, Work};
pub use tracker::{Loaded, Tracker, lightings};

/// How often the session list is read again while it is shown.
pub const RELIST: std::time::Duration = std::time::Duration::from_secs(2);

/// Whether [`RELIST`] has passed since `last` (or nothing was asked yet);
/// if so, `last` becomes `now`.
fn due_again(last: &mut Option<std::time::Instant>, now: std::time::Instant) -> bool {
    if last.is_some_and(|t| now.saturating_duration_since(t) < RELIST) {
        return false;
    }
    *last = Some(now);
    true
}

/// Each screen's own state.
#[derive(Debug, Default)]
pub struct Screens {
    pub survey: SurveyScreen,
    pub capture: CaptureScreen,
    pub pipeline: PipelineScreen,
    pub edit: EditScreen,
    pub files: FilesScreen,
    pub calibrate: CalibrateScreen,
}

impl Screens {
    /// The zoom, pan and cursor of a screen's picture.
    pub fn nav(&self, s: ScreenId) -> Option<&PreviewNav> {
        match s {
            ScreenId::Survey => Some(&self.survey.nav),
            ScreenId::Capture => Some(&self.capture.nav),
            ScreenId::Pipeline => Some(&self.pipeline.nav),
            ScreenId::Edit => Some(&self.edit.nav),
            ScreenId::Session | ScreenId::Calibrate => None,
        }
    }

    fn nav_mut(&mut self, s: ScreenId) -> Option<&mut PreviewNav> {
        match s {
            ScreenId::Survey => Some(&mut self.survey.nav),
            ScreenId::Capture => Some(&mut self.capture.nav),
            ScreenId::Pipeline => Some(&mut self.pipeline.nav),
            ScreenId::Edit => Some(&mut self.edit.nav),
            ScreenId::Session | ScreenId::Calibrate => None,
        }
    }
}

/// The whole console state.
pub struct App {
    pub cell: CellState,
    pub session: SessionState,
    pub tracker: Tracker,
    pub chrome: Chrome,
    pub screens: Screens,
}

/// What a screen's `update` may use besides its own state.
pub struct Ctx<'a> {
    pub cell: &'a mut CellState,
    pub session: &'a mut SessionState,
    pub tracker: &'a mut Tracker,
    pub chrome: &'a mut Chrome,
}

impl Ctx<'_> {
    pub fn info(&mut self, text: impl Into<String>) {
        self.chrome.log.push(Level::Info, text);
    }
    pub fn warn(&mut self, text: impl Into<String>) {
        self.chrome.log.push(Level::Warn, text);
    }
    pub fn error(&mut self, text: impl Into<String>) {
        self.chrome.log.push(Level::Error, text);
    }
    /// Opens a yes/no question.
    pub fn ask(&mut self, question: impl Into<String>, on_yes: Pending) {
        self.chrome.modal = Some(Modal::confirm(question, on_yes));
    }
}

impl App {
    pub fn new(profile: &Profile, look: Look) -> App {
        App {
            cell: CellState::new(profile),
            session: SessionState::default(),
            tracker: Tracker::new(profile.llv.clone()),
            chrome: Chrome::new(look),
            screens: Screens::default(),
        }
    }

    /// The screens and, apart from them, the rest of the state.
    pub fn parts(&mut self) -> (&mut Screens, Ctx<'_>) {
        (
            &mut self.screens,
            Ctx {
                cell: &mut self.cell,
                session: &mut self.session,
                tracker: &mut self.tracker,
                chrome: &mut self.chrome,
            },
        )
    }

    /// The rest of the state, for work that is no screen's.
    pub fn ctx(&mut self) -> Ctx<'_> {
        self.parts().1
    }

    /// The commands to send when the console starts.
    pub fn start(&mut self) -> Vec<Cmd> {
        let (name, file) = (&self.cell.profile_name, &self.cell.profile_file);
        let text = format!("profile {name}: {file}");
        self.chrome.starting = Some(self.chrome.log.pushed());
        self.ctx().info(text);
        self.session.listed = Some(std::time::Instant::now());
        vec![Cmd::Store(StoreCmd::List)]
    }

    /// Work the clock makes due (the shell calls it as it goes, keys or
    /// none): while the session list is on screen it is read again every
    /// [`RELIST`], so a session another console or a `vss grab` opened,
    /// captured into or closed shows as it is without a key pressed. The
    /// store says the list only when it changed; nothing is written.
    pub fn due(&mut self, now: std::time::Instant) -> Vec<Cmd> {
        let shown = self.chrome.screen == ScreenId::Survey
            && !self.chrome.too_small()
            && (self.session.view.is_none() || self.screens.survey.picking);
        if shown && due_again(&mut self.session.listed, now) {
            return vec![Cmd::Store(StoreCmd::Relist)];
        }
        // A session open only to look is read again as often, on any
        // screen (another console may be surveying it); the store says it
        // only when it changed.
        let looking = self.session.read_only();
        if looking && due_again(&mut self.session.looked, now) {
            return vec![Cmd::Store(StoreCmd::Relook)];
        }
        Vec::new()
    }

    pub fn quit(&self) -> bool {
        self.chrome.quit
    }

    /// Whether the operator asked to suspend the console (Ctrl-Z), once:
    /// the shell leaves the terminal and stops the process.
    pub fn take_suspend(&mut self) -> bool {
        std::mem::take(&mut self.chrome.suspend)
    }

    /// Applies one message; returns the work it asks of the workers.
    pub fn update(&mut self, msg: Msg) -> Vec<Cmd> {
        let by_operator = match &msg {
            Msg::Key(k) => k.kind == KeyEventKind::Press,
            Msg::Pointer(_) => true,
            _ => false,
        };
        // A session the operator asked for, opened or refused now: its
        // outcome is the answer to that key.
        let opened = match &msg {
            Msg::Store(StoreEvent::OpeningDone) => self.session.opening.first().map(|o| o.since),
            _ => None,
        };
        // The first list of sessions ends the start-up.
        let started = matches!(msg, Msg::Store(StoreEvent::Sessions(_)));
        let before = self.chrome.log.pushed();
        let cmds = self.apply(msg);
        self.note_opening(&cmds);
        self.close_stale_question();
        let now = std::time::Instant::now();
        if by_operator {
            self.chrome.hold_answer(before, now);
        } else if let Some(since) = opened {
            self.chrome.hold_outcome(since, now);
        } else if started && self.chrome.starting.is_some() {
            self.chrome.started(now);
        } else {
            self.chrome.release_held(now);
        }
        cmds
    }

    /// Lets the answer held on the message line go once its time is over
    /// (the shell calls it while idle); whether the screen changes.
    pub fn release_held(&mut self, now: std::time::Instant) -> bool {
        self.chrome.release_held(now)
    }

    /// Closes a question that no longer applies, saying so: "quit anyway?"
    /// asked because a capture was under way or a lighting or an image's
    /// outputs not saved, once
    /// neither holds (quitting is then safe, and `q` quits at once).
    fn close_stale_question(&mut self) {
        let quit_asked = matches!(
            &self.chrome.modal,
            Some(Modal::Confirm {
                on_yes: Pending::Quit,
                ..
            })
        );
        let still = self.session.work.phase == Phase::Capturing
            || self.cell.device.transfer.is_some()
            || self
                .tracker
                .current
                .as_ref()
                .is_some_and(|c| !c.unsaved.is_empty())
            || !self.session.refused.is_empty();
        if quit_asked && !still {
            self.chrome.modal = None;
            self.ctx()
                .info("the question to quit closed: nothing is under way now — q quits");
        }
    }

    fn apply(&mut self, msg: Msg) -> Vec<Cmd> {
        match msg {
            Msg::Key(k) => self.on_key(k),
            Msg::Pointer(p) => self.on_pointer(p),
            // Placed by the shell, which knows the layout (`screens::pointer`).
            Msg::Mouse(_) => Vec::new(),
            Msg::Resize(w, h) => {
                self.chrome.size = (w, h);
                Vec::new()
            }
            Msg::Tick => Vec::new(),
            Msg::Device(ev) => self.on_device(ev),
            Msg::Pipeline(r) => self.on_pipeline(r),
            Msg::Store(ev) => self.on_store(ev),
        }
    }

    /// The keymap scope keys go to right now.
    pub fn scope(&self) -> Scope {
        match (&self.chrome.modal, &self.chrome.overlay) {
            (Some(Modal::Prompt(_)), _) => Scope::Prompt,
            (Some(Modal::Confirm { .. }), _) => Scope::Confirm,
            (None, Some(_)) => Scope::Viewer,
            (None, None) => Scope::Screen(self.chrome.screen),
        }
    }

    fn on_key(&mut self, key: KeyEvent) -> Vec<Cmd> {
        if key.kind != KeyEventKind::Press {
            return Vec::new();
        }
        // Ctrl-Z suspends from anywhere, as in any terminal program: a
        // question or a field open stays as it is for the return.
        let suspend = Action::Global(GlobalAction::Suspend);
        if keymap::lookup(Scope::Global, &key) == Some(suspend) {
            return self.act(suspend);
        }
        let scope = self.scope();
        // Too small a terminal shows no screen, only what goes on and the
        // question asked: keys act on nothing unseen. q quits, Esc stops a
        // capture, and a question or a field on screen takes its keys.
        if self.chrome.too_small() && !matches!(scope, Scope::Prompt | Scope::Confirm) {
            let quit = keymap::lookup(scope, &key) == Some(Action::Global(GlobalAction::Quit));
            if !quit && key.code != KeyCode::Esc {
                return Vec::new();
            }
        }
        // A search on takes n, N and Esc while what it searches is in
        // front; once that is gone, so is the search.
        if self.chrome.search.is_some() && !matches!(scope, Scope::Prompt | Scope::Confirm) {
            if !self.search_in_front() {
                self.chrome.search = None;
            } else if let Some(a) = keymap::lookup(Scope::Search, &key) {
                return self.act(a);
            }
        }
        // Ctrl-C gets out: of a field or a question as Esc does, and a
        // second Ctrl-C at "Quit anyway?" quits, as pressing it twice means.
        let quit_asked = matches!(
            &self.chrome.modal,
            Some(Modal::Confirm {
                on_yes: Pending::Quit,
                ..
            })
        );
        if quit_asked
            && key.modifiers.contains(KeyModifiers::CONTROL)
            && keymap::lookup(Scope::Global, &key) == Some(Action::Global(GlobalAction::Quit))
        {
            return self.act(Action::Modal(ModalAction::Yes));
        }
        match keymap::lookup(scope, &key) {
            Some(a) => self.act(a),
            None if scope == Scope::Prompt => {
                self.prompt_typed(&key);
                Vec::new()
            }
            None => {
                if scope == Scope::Viewer {
                    // Any other key closes the window, as help always did.
                    self.chrome.overlay = None;
                } else {
                    self.unbound(&key, scope);
                }
                Vec::new()
            }
        }
    }

    /// A key with no binding where it was pressed says so, by its name,
    /// and where the keys that work are listed; keys that are no key of
    /// their own (a modifier or a lock alone) say nothing.
    fn unbound(&mut self, key: &KeyEvent, scope: Scope) {
        if matches!(
            key.code,
            KeyCode::Modifier(_)
                | KeyCode::CapsLock
                | KeyCode::NumLock
                | KeyCode::ScrollLock
                | KeyCode::Null
        ) {
            return;
        }
        let name = keymap::key_name(key);
        let where_ = match (scope, &self.chrome.modal) {
            // No screen is drawn, so ? lists nothing: what helps is room.
            (Scope::Screen(_), _) if self.chrome.too_small() => format!(
                "the terminal is too small: enlarge it to at least {} × {}; q quits",
                MIN_SIZE.0, MIN_SIZE.1
            ),
            (Scope::Screen(_), _) => "? lists this screen's keys".to_string(),
            (Scope::Confirm, Some(m)) => m
                .choices()
                .iter()
                .map(|(k, w)| format!("{k} {w}"))
                .collect::<Vec<_>>()
                .join(", "),
            _ => return,
        };
        self.ctx()
            .info(format!("{name} does nothing here — {where_}"));
    }

    /// Carries out one action through its owner.
    pub fn act(&mut self, a: Action) -> Vec<Cmd> {
        if self.refused_read_only(a) {
            return Vec::new();
        }
        let screen = self.chrome.screen;
        match a {
            Action::Global(g) => self.global(g),
            Action::Nav(n) => self.nav(screen, n),
            Action::Modal(m) => self.modal_action(m),
            Action::Viewer(v) => {
                self.chrome.viewer(v);
                Vec::new()
            }
            Action::Search(a) => {
                self.search(a);
                Vec::new()
            }
            Action::Survey(a) => {
                let (s, mut ctx) = self.parts();
                s.survey.update(a, &mut ctx)
            }
            Action::Capture(a) => {
                let (s, mut ctx) = self.parts();
                s.capture.update(a, &mut ctx)
            }
            Action::Pipeline(a) => {
                let (s, mut ctx) = self.parts();
                s.pipeline.update(a, &mut ctx)
            }
            Action::Edit(a) => {
                let (s, mut ctx) = self.parts();
                s.edit.update(a, &mut ctx)
            }
            Action::Files(a) => {
                let (s, mut ctx) = self.parts();
                s.files.update(a, &mut ctx)
            }
            Action::Calibrate(a) => {
                let (s, mut ctx) = self.parts();
                s.calibrate.update(a, &mut ctx)
            }
        }
    }

    fn nav(&mut self, screen: ScreenId, n: NavAction) -> Vec<Cmd> {
        let size = self.picture_size(screen);
        if let Some(nav) = self.screens.nav_mut(screen) {
            nav.apply(n, size);
        }
        Vec::new()
    }

    /// The size of the picture a screen shows.
    pub fn picture_size(&self, screen: ScreenId) -> Option<(usize, usize)> {
        match screen {
            ScreenId::Capture => self.cell.live.as_ref().map(|(_, g)| g.size()),
            _ => self.tracker.preview_size(),
        }
    }

    fn global(&mut self, g: GlobalAction) -> Vec<Cmd> {
        match g {
            GlobalAction::Quit => {
                if self.session.work.phase == Phase::Capturing
                    || self.cell.device.transfer.is_some()
                {
                    self.ctx().ask(
                        "A capture is under way. Quit anyway? The frames saved so far are kept.",
                        Pending::Quit,
                    );
                } else if let Some(c) = self
                    .tracker
                    .current
                    .as_ref()
                    .filter(|c| !c.unsaved.is_empty())
                {
                    let (letters, k) = (c.unsaved_letters(), c.k);
                    let letters = format!("L{}", &letters[1..]);
                    self.ctx().ask(
                        format!(
                            "{letters} of image {k} is not saved (! on the checklist): \
                             quitting loses it. Quit anyway?"
                        ),
                        Pending::Quit,
                    );
                } else if let Some(Refused { k, why, .. }) = self.session.refused.first() {
                    let q = format!(
                        "The outputs of image {k} are not saved ({why}): quitting loses them \
                         (its frames are kept). Quit anyway?"
                    );
                    self.ctx().ask(q, Pending::Quit);
                } else {
                    self.chrome.quit = true;
                }
                Vec::new()
            }
            GlobalAction::Suspend => {
                self.chrome.suspend = true;
                Vec::new()
            }
            GlobalAction::Help => {
                self.chrome.overlay = Some(Overlay::Help { scroll: 0 });
                Vec::new()
            }
            GlobalAction::LastMessage => {
                if self.chrome.log.is_empty() {
                    self.ctx().info("no message yet");
                } else {
                    self.chrome.overlay = Some(Overlay::Message { scroll: 0 });
                }
                Vec::new()
            }
            GlobalAction::ToggleLog => {
                self.chrome.cycle_log();
                Vec::new()
            }
            GlobalAction::LogUp
            | GlobalAction::LogDown
            | GlobalAction::LogTop
            | GlobalAction::LogEnd => {
                self.chrome.scroll_log(g);
                Vec::new()
            }
            GlobalAction::GoTo(s) => {
                self.chrome.screen = s;
                if s == ScreenId::Session && self.session.view.is_some() {
                    return vec![Cmd::Store(StoreCmd::Refresh)];
                }
                Vec::new()
            }
        }
    }

    /// Lighting letters of the image under work not captured yet.
    pub fn missing_letters(&self) -> Vec<char> {
        survey::missing_letters(&self.cell, &self.session.work, &self.tracker)
    }

    /// Stops a transfer (and the live view) under way.
    pub fn cancel_transfer(ctx: &mut Ctx) -> Vec<Cmd> {
        ctx.cell.device.live = false;
        ctx.cell.device.cancelled = ctx.cell.device.transfer.is_some();
        vec![Cmd::Device(DeviceCmd::Cancel)]
    }
}
