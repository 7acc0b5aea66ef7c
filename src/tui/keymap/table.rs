//! The rows of the key table, one binding a line: scope, key, action, what
//! it does (help and `docs/keys.md`), its label in the status bar ("" when
//! it has none). A screen's own rows are tried first, so a screen may reuse
//! a key of the picture or global rows.
//!
//! The scheme: arrows choose in lists and panels; `h j k l` move the
//! picture's cursor and `H J K L` pan it, `z`/`Z` zoom, on every screen
//! with a picture; keys that write or replace the operator's work are
//! letters no navigation key shares in either case (Caps Lock can never
//! turn moving into saving), and the ones that replace accepted work ask.

use ratatui::crossterm::event::KeyCode;

use super::{
    Action, Binding, CalibrateAction, CaptureAction, EditAction, FilesAction, GlobalAction, Key,
    ModalAction, NavAction, PipelineAction, Scope, ScreenId, SearchAction, SurveyAction,
    ViewerAction,
};

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

const G: Scope = Scope::Global;
const PIC: Scope = Scope::Picture;
const SU: Scope = Scope::Screen(ScreenId::Survey);
const CA: Scope = Scope::Screen(ScreenId::Capture);
const PI: Scope = Scope::Screen(ScreenId::Pipeline);
const ED: Scope = Scope::Screen(ScreenId::Edit);
const SE: Scope = Scope::Screen(ScreenId::Session);
const CB: Scope = Scope::Screen(ScreenId::Calibrate);
const CO: Scope = Scope::Confirm;
const PR: Scope = Scope::Prompt;
const VI: Scope = Scope::Viewer;
const SR: Scope = Scope::Search;

use KeyCode as K;

macro_rules! rows {
    ($($scope:ident, $key:expr, $group:ident($($act:tt)+), $desc:literal, $hint:literal;)*) => {
        &[$(Binding {
            scope: $scope,
            key: $key,
            action: rows!(@act $group($($act)+)),
            desc: $desc,
            hint: $hint,
        }),*]
    };
    (@act Global($($a:tt)+)) => { Action::Global(GlobalAction::$($a)+) };
    (@act Nav($($a:tt)+)) => { Action::Nav(NavAction::$($a)+) };
    (@act Survey($($a:tt)+)) => { Action::Survey(SurveyAction::$($a)+) };
    (@act Capture($($a:tt)+)) => { Action::Capture(CaptureAction::$($a)+) };
    (@act Pipeline($($a:tt)+)) => { Action::Pipeline(PipelineAction::$($a)+) };
    (@act Edit($($a:tt)+)) => { Action::Edit(EditAction::$($a)+) };
    (@act Files($($a:tt)+)) => { Action::Files(FilesAction::$($a)+) };
    (@act Calibrate($($a:tt)+)) => { Action::Calibrate(CalibrateAction::$($a)+) };
    (@act Modal($($a:tt)+)) => { Action::Modal(ModalAction::$($a)+) };
    (@act Viewer($($a:tt)+)) => { Action::Viewer(ViewerAction::$($a)+) };
    (@act Search($($a:tt)+)) => { Action::Search(SearchAction::$($a)+) };
}

/// The key table.
pub const KEYMAP: &[Binding] = rows! {
    // Questions.
    CO, ch('y'), Modal(Yes), "yes, go ahead", "yes";
    CO, ch('n'), Modal(No), "no, keep what is there", "no";
    CO, k(K::Esc), Modal(No), "no", "";
    CO, ctrl('c'), Modal(No), "no; at \"Quit anyway?\" yes: a second C-c quits", "";
    CO, ch('a'), Modal(All), "all (where the question offers it)", "all";
    CO, ch('r'), Modal(Look), "read-only: only look, nothing saved (where the question offers it)", "read-only";
    // Typing.
    PR, k(K::Enter), Modal(Submit), "accept the typed text", "accept";
    PR, k(K::Esc), Modal(Cancel), "cancel typing", "cancel";
    PR, ctrl('c'), Modal(Cancel), "cancel typing", "";
    PR, k(K::Left), Modal(Left), "cursor left", "";
    PR, k(K::Right), Modal(Right), "cursor right", "";
    PR, k(K::Home), Modal(Home), "to the start", "";
    PR, ctrl('a'), Modal(Home), "to the start", "";
    PR, k(K::End), Modal(End), "to the end", "";
    PR, ctrl('e'), Modal(End), "to the end", "";
    PR, k(K::Backspace), Modal(DeleteBack), "delete the character before the cursor", "";
    PR, k(K::Delete), Modal(DeleteForward), "delete the character under the cursor", "";
    PR, ctrl('u'), Modal(KillLine), "delete everything before the cursor", "";
    PR, ctrl('w'), Modal(KillWord), "delete the word before the cursor", "";
    // Help and message windows.
    VI, k(K::Up), Viewer(Up), "scroll up", "";
    VI, k(K::Down), Viewer(Down), "scroll down", "";
    VI, k(K::PageUp), Viewer(PageUp), "a page up", "scroll";
    VI, k(K::PageDown), Viewer(PageDown), "a page down", "scroll";
    VI, k(K::Home), Viewer(Top), "the first row", "";
    VI, k(K::End), Viewer(Bottom), "the last row", "";
    VI, ch('/'), Search(Start), "search the window for a text", "search";
    VI, k(K::Esc), Viewer(Close), "close", "close";
    VI, ch('q'), Viewer(Close), "close", "";
    VI, k(K::Enter), Viewer(Close), "close", "";
    // Survey.
    SU, k(K::Up), Survey(Up), "choose the session / image above", "";
    SU, k(K::Down), Survey(Down), "choose the session / image below", "";
    SU, k(K::Enter), Survey(Enter), "open the chosen session; on an image: capture, run, or go to it", "next step";
    SU, ch('n'), Survey(NewSession), "new session (type its name)", "new";
    SU, ch('o'), Survey(OpenPicker), "open another session (pick one, asks first)", "open";
    SU, ch('a'), Survey(Accept), "accept the image under review, go to the next", "accept";
    SU, ch('R'), Survey(Redo), "capture the chosen image again (asks first)", "redo";
    SU, ch('c'), Survey(Camera), "next camera for the image to capture", "camera";
    SU, ch('p'), Survey(Location), "next camera location for the image to capture", "place";
    SU, k(K::Esc), Survey(CancelCapture), "stop the capture under way", "";
    SU, ch('D'), Survey(ResetParams), "every parameter back to the profile's value (the next capture uses them)", "";
    // Calibrate.
    CB, ch('p'), Calibrate(Plate), "simulated cell: the calibration plate in view / away", "plate";
    CB, ch('v'), Calibrate(ToggleLive), "live view on/off", "live";
    CB, ch('g'), Calibrate(Grab), "grab one frame", "grab";
    CB, ch('c'), Calibrate(Camera), "next camera", "camera";
    CB, ch(' '), Calibrate(Keep), "keep this view (its grid was found)", "keep";
    CB, k(K::Backspace), Calibrate(Drop), "drop the photograph shown, or the last view kept", "";
    CB, ch('s'), Calibrate(Centre), "centre C: solved / stated at the image's middle", "centre";
    CB, k(K::Enter), Calibrate(Solve), "compute the calibration from the views kept", "compute";
    CB, ch('a'), Calibrate(Accept), "accept: write the camera's .cdf (asks first)", "accept";
    CB, ch('o'), Calibrate(Open), "load photographs: a folder or files (typed); the grid found in each is kept", "open";
    CB, ch('n'), Calibrate(Next), "show the next photograph loaded, with its corners", "next";
    CB, ch('f'), Calibrate(PlateFile), "choose the plate: a built-in name or a plate file (typed)", "";
    CB, ch('S'), Calibrate(CentreAt), "centre C stated at X,Y (typed)", "";
    CB, ch('e'), Calibrate(Scale), "scale S: sy as the camera's .cdf states it / estimated", "";
    // Capture.
    CA, ch('v'), Capture(ToggleLive), "live view on/off", "live";
    CA, ch('g'), Capture(Grab), "grab one frame", "grab";
    CA, ch('c'), Capture(Camera), "next camera", "camera";
    CA, k(K::Up), Capture(LightPrev), "choose the light or lighting above", "";
    CA, k(K::Down), Capture(LightNext), "choose the light or lighting below", "";
    CA, ch(' '), Capture(LightToggle), "switch the chosen light, or to the chosen lighting", "switch";
    CA, ch('0'), Capture(LightsOff), "all lights off", "off";
    CA, ch('A'), Capture(Lighting(0)), "lighting configuration a", "";
    CA, ch('B'), Capture(Lighting(1)), "lighting configuration b", "";
    CA, ch('C'), Capture(Lighting(2)), "lighting configuration c", "";
    CA, ch('D'), Capture(Lighting(3)), "lighting configuration d", "";
    CA, ch('E'), Capture(Lighting(4)), "lighting configuration e", "";
    CA, ch('F'), Capture(Lighting(5)), "lighting configuration f", "";
    CA, k(K::Esc), Capture(Cancel), "stop the transfer and the live view", "";
    CA, ch(']'), Capture(ExposureUp), "exposure × 1.25 (GenICam cameras)", "";
    CA, ch('['), Capture(ExposureDown), "exposure ÷ 1.25 (GenICam cameras)", "";
    CA, ch('+'), Capture(GainUp), "gain + 1 dB (GenICam cameras)", "";
    CA, ch('='), Capture(GainUp), "gain + 1 dB (GenICam cameras)", "";
    CA, ch('-'), Capture(GainDown), "gain − 1 dB (GenICam cameras)", "";
    // Pipeline.
    PI, k(K::Up), Pipeline(ParamPrev), "choose the parameter above", "";
    PI, k(K::Down), Pipeline(ParamNext), "choose the parameter below", "";
    PI, ch('+'), Pipeline(Inc), "increase by one step", "value";
    PI, ch('='), Pipeline(Inc), "increase by one step", "";
    PI, k(K::Right), Pipeline(Inc), "increase by one step", "";
    PI, ch('-'), Pipeline(Dec), "decrease by one step", "value";
    PI, k(K::Left), Pipeline(Dec), "decrease by one step", "";
    PI, ch('>'), Pipeline(Inc10), "increase by ten steps", "";
    PI, shift(K::Right), Pipeline(Inc10), "increase by ten steps", "";
    PI, ch('<'), Pipeline(Dec10), "decrease by ten steps", "";
    PI, shift(K::Left), Pipeline(Dec10), "decrease by ten steps", "";
    PI, k(K::Enter), Pipeline(Type), "type a value", "type";
    PI, k(K::Tab), Pipeline(ViewNext), "next stage view", "view";
    PI, k(K::BackTab), Pipeline(ViewPrev), "previous stage view", "";
    PI, ch('b'), Pipeline(SideBySide), "all views side by side / one view", "both";
    PI, ch('i'), Pipeline(GreySource), "grey view: next lighting, combined response, ambient", "image";
    PI, ctrl('s'), Pipeline(Save), "save these outputs to the session (asks if accepted)", "save";
    PI, ch('d'), Pipeline(ResetParam), "the chosen parameter back to the profile's value", "profile";
    PI, ch('D'), Pipeline(ResetAll), "every parameter back to the profile's value", "";
    // Edit.
    ED, ch('n'), Edit(LineNext), "highlight the next line", "next";
    ED, k(K::Tab), Edit(LineNext), "highlight the next line", "";
    ED, ch('p'), Edit(LinePrev), "highlight the previous line", "";
    ED, k(K::BackTab), Edit(LinePrev), "highlight the previous line", "";
    ED, ch('.'), Edit(LineNearest), "highlight the line nearest the cursor", "nearest";
    ED, ch('v'), Edit(Corner), "select the two lines of the corner (vertex) at the cursor", "corner";
    ED, ch(' '), Edit(Toggle), "add the highlighted line to / drop it from the selection", "select";
    ED, ch('c'), Edit(Connect), "connect the two selected lines", "connect";
    ED, ch('e'), Edit(Extend), "extend the first selected line to the second", "extend";
    ED, ch('x'), Edit(Delete), "delete the selected lines", "delete";
    ED, k(K::Delete), Edit(Delete), "delete the selected lines", "";
    ED, ch('u'), Edit(Undo), "undo the last edit", "undo";
    ED, ch('U'), Edit(Redo), "redo the edit undone", "redo";
    ED, k(K::Esc), Edit(ClearSelection), "clear the selection", "";
    // Session / report.
    SE, ch('e'), Files(Export), "write the PostScript and SVG reports", "export";
    SE, ch('c'), Files(Check), "read and check every file of the session", "check";
    SE, k(K::Up), Files(Up), "scroll the file list up", "";
    SE, k(K::Down), Files(Down), "scroll the file list down", "";
    // Every picture.
    PIC, ch('z'), Nav(ZoomIn), "zoom in (at the cursor)", "zoom";
    PIC, ch('Z'), Nav(ZoomOut), "zoom out", "zoom";
    PIC, ch('h'), Nav(CursorLeft), "cursor left (the view follows)", "cursor";
    PIC, ch('j'), Nav(CursorDown), "cursor down", "cursor";
    PIC, ch('k'), Nav(CursorUp), "cursor up", "cursor";
    PIC, ch('l'), Nav(CursorRight), "cursor right", "cursor";
    PIC, ch('H'), Nav(PanLeft), "pan left", "pan";
    PIC, ch('J'), Nav(PanDown), "pan down", "pan";
    PIC, ch('K'), Nav(PanUp), "pan up", "pan";
    PIC, ch('L'), Nav(PanRight), "pan right", "pan";
    // Everywhere.
    G, ch('1'), Global(GoTo(ScreenId::Survey)), "Survey screen", "";
    G, ch('2'), Global(GoTo(ScreenId::Capture)), "Capture screen", "";
    G, ch('3'), Global(GoTo(ScreenId::Pipeline)), "Pipeline screen", "";
    G, ch('4'), Global(GoTo(ScreenId::Edit)), "Edit screen", "";
    G, ch('5'), Global(GoTo(ScreenId::Session)), "Session/Report screen", "";
    G, ch('6'), Global(GoTo(ScreenId::Calibrate)), "Calibrate screen", "";
    G, ch('?'), Global(Help), "help: every key, the checklist's marks", "help";
    G, k(K::F(1)), Global(Help), "help", "";
    G, ch('m'), Global(ToggleLog), "message log: one line / expanded / notes hidden", "log";
    G, ch('!'), Global(LastMessage), "the last message in full", "";
    G, k(K::PageUp), Global(LogUp), "scroll the message log up", "";
    G, k(K::PageDown), Global(LogDown), "scroll the message log down", "";
    G, k(K::Home), Global(LogTop), "the log's first message", "";
    G, k(K::End), Global(LogEnd), "the log's newest message", "";
    G, ch('/'), Search(Start), "search the message log (on the Session screen: its file list)", "";
    G, ch('q'), Global(Quit), "quit (asks while a capture runs)", "quit";
    // While a search is on.
    SR, ch('n'), Search(Next), "the next match", "next";
    SR, ch('N'), Search(Prev), "the previous match", "previous";
    SR, k(K::Esc), Search(Clear), "end the search", "end search";
    G, ctrl('c'), Global(Quit), "quit", "";
    G, ctrl('z'), Global(Suspend), "suspend to the shell, anywhere (fg brings the console back)", "";
};
