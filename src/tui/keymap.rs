//! The one key table: (scope, key, action, description, hint). Dispatch,
//! the help overlay (`?`), the status-bar hints and `docs/keys.md` all read
//! it, so a key can never do one thing and be documented as another.
//!
//! Actions are grouped by who carries them out — the frame around every
//! screen ([`GlobalAction`]), the picture of any screen that shows one
//! ([`NavAction`]: zoom, pan and cursor are the same keys everywhere), each
//! screen, and the questions and text fields — so each owner matches its
//! own actions exhaustively. The rows themselves are in `keymap/table.rs`.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

mod table;

pub use table::KEYMAP;

/// The screens of the console, in top-bar order. Adding one: a variant
/// here (its title and key), its state and `update` under `app/`, its
/// drawing under `screens/`, its action enum and rows in the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScreenId {
    Survey,
    Capture,
    Pipeline,
    Edit,
    Session,
    Calibrate,
}

impl ScreenId {
    pub const ALL: [ScreenId; 6] = [
        ScreenId::Survey,
        ScreenId::Capture,
        ScreenId::Pipeline,
        ScreenId::Edit,
        ScreenId::Session,
        ScreenId::Calibrate,
    ];
    pub fn title(self) -> &'static str {
        match self {
            ScreenId::Survey => "Survey",
            ScreenId::Capture => "Capture",
            ScreenId::Pipeline => "Pipeline",
            ScreenId::Edit => "Edit",
            ScreenId::Session => "Session/Report",
            ScreenId::Calibrate => "Calibrate",
        }
    }
    /// The short title of the top bar at 80 columns.
    pub fn short(self) -> &'static str {
        match self {
            ScreenId::Session => "Session",
            s => s.title(),
        }
    }
}

/// Where a binding applies. Modal scopes (prompt, confirm) take every key
/// while they are open.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    Global,
    Screen(ScreenId),
    /// The picture of every screen that shows one (tried after the
    /// screen's own rows, before the global ones).
    Picture,
    /// A yes/no question is open.
    Confirm,
    /// A text field is open (other printable keys type into it).
    Prompt,
    /// The help overlay or the message viewer is open.
    Viewer,
    /// A search is on (after `/` and Enter): tried before the scope in
    /// front, so `n` goes to the next match rather than to the screen.
    Search,
}

/// Everything a key can ask for, grouped by its owner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Global(GlobalAction),
    Nav(NavAction),
    Survey(SurveyAction),
    Capture(CaptureAction),
    Pipeline(PipelineAction),
    Edit(EditAction),
    Files(FilesAction),
    Calibrate(CalibrateAction),
    Modal(ModalAction),
    Viewer(ViewerAction),
    Search(SearchAction),
}

/// Keys of the frame around every screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlobalAction {
    Quit,
    /// Back to the shell that started the console (Ctrl-Z); `fg` returns.
    Suspend,
    Help,
    ToggleLog,
    /// The last message in full, in a window of its own.
    LastMessage,
    LogUp,
    LogDown,
    LogTop,
    LogEnd,
    GoTo(ScreenId),
}

/// Zoom, pan and cursor over a picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NavAction {
    ZoomIn,
    ZoomOut,
    CursorLeft,
    CursorRight,
    CursorUp,
    CursorDown,
    PanLeft,
    PanRight,
    PanUp,
    PanDown,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurveyAction {
    NewSession,
    /// The session picker (asks before leaving an open session).
    OpenPicker,
    Up,
    Down,
    /// Next step of the selected image: capture, run, or the accept question.
    Enter,
    Accept,
    Redo,
    Camera,
    Location,
    CancelCapture,
    /// Every parameter back to the profile's value (the next capture and
    /// run use them).
    ResetParams,
}

impl SurveyAction {
    /// Whether the key acts on an image of the checklist (accept, capture
    /// again, its camera, its location): it has nothing to act on where no
    /// checklist is shown.
    pub fn on_the_image(self) -> bool {
        matches!(
            self,
            SurveyAction::Accept
                | SurveyAction::Redo
                | SurveyAction::Camera
                | SurveyAction::Location
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaptureAction {
    ToggleLive,
    Grab,
    Camera,
    /// The row above / below in the lights panel: the lights, then the
    /// lighting configurations.
    LightPrev,
    LightNext,
    /// The chosen light switched, or the chosen lighting configuration set.
    LightToggle,
    LightsOff,
    /// The profile's `i`-th lighting configuration (Shift+A to F).
    Lighting(u8),
    Cancel,
    /// A GenICam camera's exposure time × 1.25 / ÷ 1.25.
    ExposureUp,
    ExposureDown,
    /// A GenICam camera's gain ± 1 dB.
    GainUp,
    GainDown,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PipelineAction {
    ParamPrev,
    ParamNext,
    Inc,
    Dec,
    Inc10,
    Dec10,
    Type,
    Save,
    ViewNext,
    ViewPrev,
    SideBySide,
    /// Which image the grey view shows: each lighting, the combined
    /// response, the ambient image.
    GreySource,
    /// The chosen parameter back to the profile's value.
    ResetParam,
    /// Every parameter back to the profile's value.
    ResetAll,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EditAction {
    LineNext,
    LinePrev,
    LineNearest,
    Corner,
    Toggle,
    Connect,
    Extend,
    Delete,
    Undo,
    Redo,
    ClearSelection,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilesAction {
    Export,
    Check,
    Up,
    Down,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalibrateAction {
    ToggleLive,
    Grab,
    Camera,
    /// The simulated cell's plate in view / away.
    Plate,
    Keep,
    Drop,
    /// The centre `C` solved or stated at the image's middle.
    Centre,
    /// The centre `C` stated at coordinates typed.
    CentreAt,
    /// The scale's `sy` as stated in the camera's `.cdf`, or estimated.
    Scale,
    Solve,
    Accept,
    /// Load images from files (a folder or a list, typed).
    Open,
    /// Show the next image loaded from files.
    Next,
    /// Choose the plate file (typed).
    PlateFile,
}

/// Questions and text fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModalAction {
    Yes,
    No,
    /// "All", where a question offers it (retake every lighting).
    All,
    /// Only look, read-only, where a question offers it (a session another
    /// console holds).
    Look,
    Submit,
    Cancel,
    Left,
    Right,
    Home,
    End,
    DeleteBack,
    DeleteForward,
    /// Ctrl-U: the text before the cursor.
    KillLine,
    /// Ctrl-W: the word before the cursor.
    KillWord,
}

/// The help overlay and the message viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewerAction {
    Up,
    Down,
    PageUp,
    PageDown,
    Top,
    Bottom,
    Close,
}

/// `/`: search the help window, the message log or the Session screen's
/// file list for a text; then the next and previous match, and the end of
/// the search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchAction {
    Start,
    Next,
    Prev,
    Clear,
}

impl Action {
    /// Whether the action writes, replaces or throws away something of the
    /// operator's (these keys never sit on a navigation key's letter).
    pub fn is_destructive(self) -> bool {
        match self {
            Action::Survey(a) => matches!(
                a,
                SurveyAction::Accept
                    | SurveyAction::Redo
                    | SurveyAction::NewSession
                    | SurveyAction::ResetParams
            ),
            Action::Pipeline(a) => matches!(a, PipelineAction::Save | PipelineAction::ResetAll),
            Action::Edit(a) => matches!(
                a,
                EditAction::Connect
                    | EditAction::Extend
                    | EditAction::Delete
                    | EditAction::Undo
                    | EditAction::Redo
            ),
            Action::Files(a) => a == FilesAction::Export,
            Action::Calibrate(a) => matches!(a, CalibrateAction::Drop | CalibrateAction::Accept),
            Action::Global(a) => a == GlobalAction::Quit,
            Action::Capture(_)
            | Action::Nav(_)
            | Action::Modal(_)
            | Action::Viewer(_)
            | Action::Search(_) => false,
        }
    }

    /// Whether the action only moves something on screen.
    pub fn is_navigation(self) -> bool {
        match self {
            Action::Nav(_) => true,
            Action::Global(g) => matches!(
                g,
                GlobalAction::LogUp
                    | GlobalAction::LogDown
                    | GlobalAction::LogTop
                    | GlobalAction::LogEnd
                    | GlobalAction::GoTo(_)
            ),
            Action::Survey(a) => matches!(a, SurveyAction::Up | SurveyAction::Down),
            Action::Pipeline(a) => matches!(
                a,
                PipelineAction::ParamPrev
                    | PipelineAction::ParamNext
                    | PipelineAction::ViewNext
                    | PipelineAction::ViewPrev
            ),
            Action::Edit(a) => matches!(a, EditAction::LineNext | EditAction::LinePrev),
            Action::Files(a) => matches!(a, FilesAction::Up | FilesAction::Down),
            Action::Capture(a) => matches!(a, CaptureAction::LightPrev | CaptureAction::LightNext),
            Action::Search(a) => matches!(a, SearchAction::Next | SearchAction::Prev),
            Action::Calibrate(_) | Action::Modal(_) | Action::Viewer(_) => false,
        }
    }
}

/// A key: its code and whether Ctrl / Shift are held. For characters the
/// case already tells Shift, so Shift is ignored there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Key {
    pub code: KeyCode,
    pub ctrl: bool,
    pub shift: bool,
}

impl Key {
    /// Whether a key event from the terminal is this key.
    pub fn matches(&self, ev: &KeyEvent) -> bool {
        let ctrl = ev.modifiers.contains(KeyModifiers::CONTROL);
        let shift = ev.modifiers.contains(KeyModifiers::SHIFT);
        match (self.code, ev.code) {
            (KeyCode::Char(a), KeyCode::Char(b)) => {
                // Terminals send Ctrl+letter without case.
                let same = if self.ctrl {
                    a.eq_ignore_ascii_case(&b)
                } else {
                    a == b
                };
                same && ctrl == self.ctrl
            }
            (a, b) => a == b && ctrl == self.ctrl && shift == self.shift,
        }
    }

    /// How the key is written in help and hints.
    pub fn label(&self) -> String {
        let base = match self.code {
            KeyCode::Char(' ') => "Space".to_string(),
            KeyCode::Char(c) => c.to_string(),
            KeyCode::Up => "↑".into(),
            KeyCode::Down => "↓".into(),
            KeyCode::Left => "←".into(),
            KeyCode::Right => "→".into(),
            KeyCode::Enter => "Enter".into(),
            KeyCode::Esc => "Esc".into(),
            KeyCode::Tab => "Tab".into(),
            KeyCode::BackTab => "S-Tab".into(),
            KeyCode::Backspace => "Bksp".into(),
            KeyCode::Delete => "Del".into(),
            KeyCode::Home => "Home".into(),
            KeyCode::End => "End".into(),
            KeyCode::PageUp => "PgUp".into(),
            KeyCode::PageDown => "PgDn".into(),
            KeyCode::F(n) => format!("F{n}"),
            other => format!("{other:?}"),
        };
        match (self.ctrl, self.shift) {
            (true, _) => format!("C-{base}"),
            (false, true) => format!("S-{base}"),
            _ => base,
        }
    }
}

/// How a key the terminal sent is written, as help writes the table's
/// keys (`F5`, `C-x`, `S-Tab`, `Space`); Alt is `Alt-`.
pub fn key_name(ev: &KeyEvent) -> String {
    let char_key = matches!(ev.code, KeyCode::Char(_));
    let key = Key {
        code: ev.code,
        ctrl: ev.modifiers.contains(KeyModifiers::CONTROL),
        // A character's case already says Shift.
        shift: !char_key && ev.modifiers.contains(KeyModifiers::SHIFT),
    };
    let alt = if ev.modifiers.contains(KeyModifiers::ALT) {
        "Alt-"
    } else {
        ""
    };
    format!("{alt}{}", key.label())
}

/// One row of the key table.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    pub scope: Scope,
    pub key: Key,
    pub action: Action,
    pub desc: &'static str,
    /// Its label in the status bar of its screen ("" = not shown there).
    pub hint: &'static str,
}

/// Whether a screen shows a picture (and so takes the [`Scope::Picture`] keys).
pub fn has_picture(s: ScreenId) -> bool {
    match s {
        ScreenId::Survey | ScreenId::Capture | ScreenId::Pipeline | ScreenId::Edit => true,
        ScreenId::Session | ScreenId::Calibrate => false,
    }
}

fn find(scope: Scope, ev: &KeyEvent) -> Option<Action> {
    KEYMAP
        .iter()
        .find(|b| b.scope == scope && b.key.matches(ev))
        .map(|b| b.action)
}

/// The action of a key in a scope: a screen's own rows first, then the
/// picture keys (on screens with a picture), then the global ones; modal
/// scopes take nothing else.
pub fn lookup(scope: Scope, ev: &KeyEvent) -> Option<Action> {
    match scope {
        Scope::Screen(s) => find(scope, ev)
            .or_else(|| has_picture(s).then(|| find(Scope::Picture, ev)).flatten())
            .or_else(|| find(Scope::Global, ev)),
        _ => find(scope, ev),
    }
}

/// The label of the first key bound to `action` in `scope`, if any.
pub fn key_label(scope: Scope, action: Action) -> Option<String> {
    KEYMAP
        .iter()
        .find(|b| b.scope == scope && b.action == action)
        .map(|b| b.key.label())
}

/// The rows of a scope, with the keys of one action joined: `+ = →`.
pub fn describe(scope: Scope) -> Vec<(String, &'static str)> {
    let mut out: Vec<(String, Action, &'static str)> = Vec::new();
    for bnd in KEYMAP.iter().filter(|b| b.scope == scope) {
        if let Some(row) = out.iter_mut().find(|r| r.1 == bnd.action) {
            row.0.push(' ');
            row.0.push_str(&bnd.key.label());
        } else {
            out.push((bnd.key.label(), bnd.action, bnd.desc));
        }
    }
    out.into_iter().map(|(k, _, d)| (k, d)).collect()
}

/// The status-bar hints of a scope: (keys, short label) pairs, the keys of
/// one hint joined (`zZ zoom`, `PgUp/PgDn scroll`).
pub fn hints(scope: Scope) -> Vec<(String, &'static str)> {
    hints_where(scope, |_| true)
}

/// The hints of a scope for the bindings `keep` keeps (what does nothing
/// now, or what another scope takes, is not offered).
pub fn hints_where(scope: Scope, keep: impl Fn(&Binding) -> bool) -> Vec<(String, &'static str)> {
    let mut out: Vec<(Vec<String>, &'static str)> = Vec::new();
    for b in KEYMAP
        .iter()
        .filter(|b| !b.hint.is_empty() && b.scope == scope && keep(b))
    {
        match out.iter_mut().find(|(_, h)| *h == b.hint) {
            Some((keys, _)) => keys.push(b.key.label()),
            None => out.push((vec![b.key.label()], b.hint)),
        }
    }
    out.into_iter()
        .map(|(keys, h)| {
            let sep = if keys.iter().all(|k| k.chars().count() == 1) {
                ""
            } else {
                "/"
            };
            (keys.join(sep), h)
        })
        .collect()
}

/// The scopes in the order help and `docs/keys.md` list them, with titles.
pub fn scopes() -> Vec<(String, Scope)> {
    let mut out: Vec<(String, Scope)> = ScreenId::ALL
        .iter()
        .map(|s| (format!("{} screen", s.title()), Scope::Screen(*s)))
        .collect();
    out.push((
        "Every picture (Survey, Capture, Pipeline, Edit)".into(),
        Scope::Picture,
    ));
    out.push(("Everywhere".into(), Scope::Global));
    out.push(("Questions".into(), Scope::Confirm));
    out.push(("Typing".into(), Scope::Prompt));
    out.push(("Help and message windows".into(), Scope::Viewer));
    out.push((
        "While a search is on (after / and Enter)".into(),
        Scope::Search,
    ));
    out
}

/// The key table as Markdown: `docs/keys.md` is this text (a test keeps
/// them the same).
pub fn markdown() -> String {
    let mut out = String::from(
        "# The console's keys\n\n\
         Generated from the console's key table (`src/tui/keymap/table.rs`), the one \
         the console dispatches with and draws its help (`?`) and hints from. \
         `cargo test --lib keys_md` fails when this file is stale; \
         `VSS_WRITE_KEYS=1 cargo test --lib keys_md` rewrites it.\n\n\
         `S-` is Shift, `C-` is Ctrl. A screen's own keys win over the picture \
         keys, which win over the keys that work everywhere. A key bound to nothing \
         where it is pressed says so on the message line (\"F5 does nothing here — ? \
         lists this screen's keys\"; in a question, its keys); in a text field it \
         types, or does nothing.\n",
    );
    for (title, scope) in scopes() {
        out.push_str(&format!("\n## {title}\n\n| key | does |\n|---|---|\n"));
        for (k, d) in describe(scope) {
            let k = k.replace('|', "\\|");
            out.push_str(&format!("| `{k}` | {d} |\n"));
        }
    }
    out
}

#[cfg(test)]
mod tests;
