//! The one key table: (scope, key, action, description). Dispatch, the help
//! overlay (`?`) and the status-bar hints all read it, so a key can never do
//! one thing and be documented as another.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// The screens of the console, in top-bar order.
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
}

/// Where a binding applies. Modal scopes (help, prompt, confirm) take every
/// key while they are open.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    Global,
    Screen(ScreenId),
    /// A yes/no question is open.
    Confirm,
    /// A text field is open (other printable keys type into it).
    Prompt,
}

/// Everything a key can ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Quit,
    Help,
    ToggleLog,
    GoTo(ScreenId),
    Cancel,
    // Survey
    NewSession,
    SelectUp,
    SelectDown,
    OpenSelected,
    NextStep,
    Accept,
    Redo,
    CameraNext,
    LocationNext,
    // Capture
    ToggleLive,
    Grab,
    LightPrev,
    LightNext,
    LightToggle,
    LightsOff,
    Lighting(u8),
    // Pipeline and Edit previews
    ParamPrev,
    ParamNext,
    ParamInc,
    ParamDec,
    ParamInc10,
    ParamDec10,
    ParamType,
    SaveOutputs,
    ViewNext,
    ViewPrev,
    SideBySide,
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
    // Edit
    LineNext,
    LinePrev,
    LineNearest,
    Corner,
    Mark,
    Connect,
    Extend,
    Delete,
    Undo,
    RedoEdit,
    // Session / report
    Export,
    Refresh,
    // Calibrate
    CalibPlate,
    CalibKeep,
    CalibDrop,
    CalibSolve,
    CalibCentre,
    CalibAccept,
    // Modal
    Yes,
    No,
    Submit,
}

/// A key: its code and whether Ctrl / Shift are held. For characters the
/// case already tells Shift, so Shift is ignored there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Key {
    pub code: KeyCode,
    pub ctrl: bool,
    pub shift: bool,
}

const fn ch(c: char) -> Key {
    Key {
        code: KeyCode::Char(c),
        ctrl: false,
        shift: false,
    }
}
const fn k(code: KeyCode) -> Key {
    Key {
        code,
        ctrl: false,
        shift: false,
    }
}
const fn shift(code: KeyCode) -> Key {
    Key {
        code,
        ctrl: false,
        shift: true,
    }
}
const fn ctrl(c: char) -> Key {
    Key {
        code: KeyCode::Char(c),
        ctrl: true,
        shift: false,
    }
}

impl Key {
    /// Whether a key event from the terminal is this key.
    pub fn matches(&self, ev: &KeyEvent) -> bool {
        let ctrl = ev.modifiers.contains(KeyModifiers::CONTROL);
        let shift = ev.modifiers.contains(KeyModifiers::SHIFT);
        match (self.code, ev.code) {
            (KeyCode::Char(a), KeyCode::Char(b)) => a == b && ctrl == self.ctrl,
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

const fn b(
    scope: Scope,
    key: Key,
    action: Action,
    desc: &'static str,
    hint: &'static str,
) -> Binding {
    Binding {
        scope,
        key,
        action,
        desc,
        hint,
    }
}

use Action as A;
use KeyCode as K;
use ScreenId as S;
const G: Scope = Scope::Global;
const SU: Scope = Scope::Screen(S::Survey);
const CA: Scope = Scope::Screen(S::Capture);
const PI: Scope = Scope::Screen(S::Pipeline);
const ED: Scope = Scope::Screen(S::Edit);
const SE: Scope = Scope::Screen(S::Session);
const CB: Scope = Scope::Screen(S::Calibrate);

/// The key table. Screen rows come before global rows so a screen may
/// reuse a key; the first match wins.
pub const KEYMAP: &[Binding] = &[
    // Modal scopes.
    b(Scope::Confirm, ch('y'), A::Yes, "yes, go ahead", "yes"),
    b(
        Scope::Confirm,
        ch('n'),
        A::No,
        "no, keep what is there",
        "no",
    ),
    b(Scope::Confirm, k(K::Esc), A::No, "no", ""),
    b(
        Scope::Prompt,
        k(K::Enter),
        A::Submit,
        "accept the typed text",
        "accept",
    ),
    b(
        Scope::Prompt,
        k(K::Esc),
        A::Cancel,
        "cancel typing",
        "cancel",
    ),
    // Survey.
    b(
        SU,
        ch('n'),
        A::NewSession,
        "new session (type its name)",
        "new",
    ),
    b(SU, k(K::Up), A::SelectUp, "choose a session above", ""),
    b(SU, k(K::Down), A::SelectDown, "choose a session below", ""),
    b(
        SU,
        ch('o'),
        A::OpenSelected,
        "open (resume) the chosen session",
        "open",
    ),
    b(
        SU,
        k(K::Enter),
        A::NextStep,
        "next step: capture all lightings / run",
        "next step",
    ),
    b(
        SU,
        ch('a'),
        A::Accept,
        "accept this image, go to the next",
        "accept",
    ),
    b(SU, ch('r'), A::Redo, "redo this image (asks first)", "redo"),
    b(SU, ch('c'), A::CameraNext, "next camera", "camera"),
    b(SU, ch('p'), A::LocationNext, "next camera location", ""),
    b(SU, k(K::Esc), A::Cancel, "cancel the transfer", ""),
    // Calibrate.
    b(
        CB,
        ch('p'),
        A::CalibPlate,
        "simulated cell: calibration plate in view / away",
        "plate",
    ),
    b(CB, ch('v'), A::ToggleLive, "live view on/off", "live"),
    b(CB, ch('g'), A::Grab, "grab one frame", "grab"),
    b(CB, ch('c'), A::CameraNext, "next camera", "camera"),
    b(
        CB,
        ch(' '),
        A::CalibKeep,
        "keep this view (its grid was found)",
        "keep",
    ),
    b(
        CB,
        k(K::Backspace),
        A::CalibDrop,
        "drop the last view kept",
        "",
    ),
    b(
        CB,
        ch('s'),
        A::CalibCentre,
        "centre C: solved / stated at the image's middle",
        "centre",
    ),
    b(
        CB,
        k(K::Enter),
        A::CalibSolve,
        "compute the calibration from the views kept",
        "compute",
    ),
    b(
        CB,
        ch('a'),
        A::CalibAccept,
        "accept: write camN.cdf (asks before replacing)",
        "accept",
    ),
    // Capture.
    b(CA, ch('v'), A::ToggleLive, "live view on/off", "live"),
    b(CA, ch('g'), A::Grab, "grab one frame", "grab"),
    b(CA, ch('c'), A::CameraNext, "next camera", "camera"),
    b(CA, k(K::Up), A::LightPrev, "previous light", ""),
    b(CA, k(K::Down), A::LightNext, "next light", ""),
    b(
        CA,
        ch(' '),
        A::LightToggle,
        "switch the chosen light",
        "light",
    ),
    b(CA, ch('o'), A::LightsOff, "all lights off", ""),
    b(CA, ch('A'), A::Lighting(0), "lighting configuration a", ""),
    b(CA, ch('B'), A::Lighting(1), "lighting configuration b", ""),
    b(CA, ch('C'), A::Lighting(2), "lighting configuration c", ""),
    b(CA, ch('D'), A::Lighting(3), "lighting configuration d", ""),
    b(CA, ch('E'), A::Lighting(4), "lighting configuration e", ""),
    b(CA, ch('F'), A::Lighting(5), "lighting configuration f", ""),
    b(CA, k(K::Esc), A::Cancel, "cancel the transfer", ""),
    // Pipeline.
    b(PI, k(K::Up), A::ParamPrev, "previous parameter", ""),
    b(PI, k(K::Down), A::ParamNext, "next parameter", ""),
    b(PI, ch('+'), A::ParamInc, "increase by one step", "more"),
    b(PI, ch('='), A::ParamInc, "increase by one step", ""),
    b(PI, k(K::Right), A::ParamInc, "increase by one step", ""),
    b(PI, ch('-'), A::ParamDec, "decrease by one step", "less"),
    b(PI, k(K::Left), A::ParamDec, "decrease by one step", ""),
    b(PI, ch('>'), A::ParamInc10, "increase by ten steps", ""),
    b(
        PI,
        shift(K::Right),
        A::ParamInc10,
        "increase by ten steps",
        "",
    ),
    b(PI, ch('<'), A::ParamDec10, "decrease by ten steps", ""),
    b(
        PI,
        shift(K::Left),
        A::ParamDec10,
        "decrease by ten steps",
        "",
    ),
    b(PI, k(K::Enter), A::ParamType, "type a value", "type"),
    b(PI, k(K::Tab), A::ViewNext, "next stage view", "view"),
    b(PI, k(K::BackTab), A::ViewPrev, "previous stage view", ""),
    b(PI, ch('b'), A::SideBySide, "side by side / one view", ""),
    b(
        PI,
        ch('S'),
        A::SaveOutputs,
        "save these outputs to the session",
        "",
    ),
    // Pipeline and Edit share the preview keys.
    b(PI, ch('z'), A::ZoomIn, "zoom in", ""),
    b(PI, ch('x'), A::ZoomOut, "zoom out", ""),
    b(PI, ch('a'), A::CursorLeft, "cursor left", ""),
    b(PI, ch('d'), A::CursorRight, "cursor right", ""),
    b(PI, ch('w'), A::CursorUp, "cursor up", ""),
    b(PI, ch('s'), A::CursorDown, "cursor down", ""),
    b(PI, ch('A'), A::PanLeft, "pan left", ""),
    b(PI, ch('D'), A::PanRight, "pan right", ""),
    b(PI, ch('W'), A::PanUp, "pan up", ""),
    b(PI, ch('X'), A::PanDown, "pan down", ""),
    // Edit.
    b(ED, ch('n'), A::LineNext, "select the next line", "next"),
    b(ED, k(K::Tab), A::LineNext, "select the next line", ""),
    b(ED, ch('p'), A::LinePrev, "select the previous line", ""),
    b(
        ED,
        k(K::BackTab),
        A::LinePrev,
        "select the previous line",
        "",
    ),
    b(
        ED,
        ch('.'),
        A::LineNearest,
        "select the line nearest the cursor",
        "nearest",
    ),
    b(
        ED,
        ch('k'),
        A::Corner,
        "select the two lines of the corner at the cursor",
        "corner",
    ),
    b(
        ED,
        ch(' '),
        A::Mark,
        "add the line to / drop it from the selection",
        "",
    ),
    b(
        ED,
        ch('c'),
        A::Connect,
        "connect the two selected lines",
        "connect",
    ),
    b(
        ED,
        ch('e'),
        A::Extend,
        "extend the first line to the second",
        "extend",
    ),
    b(
        ED,
        ch('x'),
        A::Delete,
        "delete the selected lines",
        "delete",
    ),
    b(ED, k(K::Delete), A::Delete, "delete the selected lines", ""),
    b(ED, ch('u'), A::Undo, "undo", "undo"),
    b(ED, ch('r'), A::RedoEdit, "redo", "redo"),
    b(ED, k(K::Esc), A::Cancel, "clear the selection", ""),
    b(ED, ch('z'), A::ZoomIn, "zoom in", ""),
    b(ED, ch('Z'), A::ZoomOut, "zoom out", ""),
    b(ED, ch('a'), A::CursorLeft, "cursor left", ""),
    b(ED, ch('d'), A::CursorRight, "cursor right", ""),
    b(ED, ch('w'), A::CursorUp, "cursor up", ""),
    b(ED, ch('s'), A::CursorDown, "cursor down", ""),
    b(ED, k(K::Left), A::PanLeft, "pan left", ""),
    b(ED, k(K::Right), A::PanRight, "pan right", ""),
    b(ED, k(K::Up), A::PanUp, "pan up", ""),
    b(ED, k(K::Down), A::PanDown, "pan down", ""),
    // Session / report.
    b(
        SE,
        ch('e'),
        A::Export,
        "export the PostScript and SVG reports",
        "export",
    ),
    b(
        SE,
        ch('r'),
        A::Refresh,
        "re-read the session's files",
        "refresh",
    ),
    b(SE, k(K::Up), A::SelectUp, "scroll the file list up", ""),
    b(
        SE,
        k(K::Down),
        A::SelectDown,
        "scroll the file list down",
        "",
    ),
    // Everywhere.
    b(G, ch('1'), A::GoTo(S::Survey), "Survey screen", ""),
    b(G, ch('2'), A::GoTo(S::Capture), "Capture screen", ""),
    b(G, ch('3'), A::GoTo(S::Pipeline), "Pipeline screen", ""),
    b(G, ch('4'), A::GoTo(S::Edit), "Edit screen", ""),
    b(G, ch('5'), A::GoTo(S::Session), "Session/Report screen", ""),
    b(G, ch('6'), A::GoTo(S::Calibrate), "Calibrate screen", ""),
    b(G, ch('?'), A::Help, "help: every key", "help"),
    b(
        G,
        ch('l'),
        A::ToggleLog,
        "log pane: hide / show / expand",
        "log",
    ),
    b(G, ch('q'), A::Quit, "quit", "quit"),
    b(G, ctrl('c'), A::Quit, "quit", ""),
];

/// The action of a key in a scope (global rows are tried after the scope's
/// own only for screen scopes; modal scopes take nothing else).
pub fn lookup(scope: Scope, ev: &KeyEvent) -> Option<Action> {
    let own = KEYMAP
        .iter()
        .find(|b| b.scope == scope && b.key.matches(ev))
        .map(|b| b.action);
    match scope {
        Scope::Screen(_) => own.or_else(|| {
            KEYMAP
                .iter()
                .find(|b| b.scope == Scope::Global && b.key.matches(ev))
                .map(|b| b.action)
        }),
        _ => own,
    }
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

/// The status-bar hints of a scope: (key, short label) pairs.
pub fn hints(scope: Scope) -> Vec<(String, &'static str)> {
    KEYMAP
        .iter()
        .filter(|b| !b.hint.is_empty() && b.scope == scope)
        .map(|b| (b.key.label(), b.hint))
        .collect()
}

/// The key table as Markdown (for the README): one line per screen.
pub fn markdown() -> String {
    let mut out = String::new();
    let mut scopes: Vec<(String, Scope)> = ScreenId::ALL
        .iter()
        .map(|s| (s.title().to_string(), Scope::Screen(*s)))
        .collect();
    scopes.push(("Everywhere".into(), Scope::Global));
    scopes.push(("Questions".into(), Scope::Confirm));
    scopes.push(("Typing".into(), Scope::Prompt));
    for (title, scope) in scopes {
        let rows: Vec<String> = describe(scope)
            .into_iter()
            .map(|(k, d)| format!("`{k}` {d}"))
            .collect();
        out.push_str(&format!("- **{title}**: {}\n", rows.join("; ")));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(code: KeyCode, m: KeyModifiers) -> KeyEvent {
        KeyEvent::new(code, m)
    }

    #[test]
    fn screen_keys_win_over_global_and_fall_back() {
        let s = Scope::Screen(ScreenId::Pipeline);
        assert_eq!(
            lookup(s, &key(K::Char('+'), KeyModifiers::SHIFT)),
            Some(A::ParamInc)
        );
        assert_eq!(
            lookup(s, &key(K::Right, KeyModifiers::SHIFT)),
            Some(A::ParamInc10)
        );
        assert_eq!(
            lookup(s, &key(K::Right, KeyModifiers::NONE)),
            Some(A::ParamInc)
        );
        assert_eq!(
            lookup(s, &key(K::Char('q'), KeyModifiers::NONE)),
            Some(A::Quit)
        );
        assert_eq!(
            lookup(s, &key(K::Char('c'), KeyModifiers::CONTROL)),
            Some(A::Quit)
        );
        assert_eq!(
            lookup(Scope::Confirm, &key(K::Char('q'), KeyModifiers::NONE)),
            None
        );
        assert_eq!(
            lookup(
                Scope::Screen(ScreenId::Capture),
                &key(K::Char('B'), KeyModifiers::SHIFT)
            ),
            Some(A::Lighting(1))
        );
    }

    #[test]
    fn no_key_is_bound_twice_in_one_scope() {
        for (i, a) in KEYMAP.iter().enumerate() {
            for bnd in &KEYMAP[i + 1..] {
                assert!(
                    !(a.scope == bnd.scope && a.key == bnd.key),
                    "{:?} {} bound twice",
                    a.scope,
                    a.key.label()
                );
            }
        }
    }

    #[test]
    fn markdown_lists_every_scope() {
        let md = markdown();
        // `cargo test markdown_lists -- --nocapture` prints it for the README.
        println!("{md}");
        assert_eq!(md.lines().count(), 9);
        assert!(md.contains("`?` help: every key"));
    }

    #[test]
    fn help_joins_keys_and_hints_are_short() {
        let rows = describe(Scope::Screen(ScreenId::Pipeline));
        assert!(
            rows.iter()
                .any(|(k, d)| k == "+ = →" && d.starts_with("increase"))
        );
        let h = hints(Scope::Global);
        assert!(h.iter().any(|(k, d)| k == "q" && *d == "quit"));
        assert!(h.iter().all(|(_, d)| d.len() <= 10), "{h:?}");
    }
}
