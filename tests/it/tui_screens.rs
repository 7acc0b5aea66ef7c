//! Every screen of the console drawn through ratatui's `TestBackend`
//! (80 × 24 and larger), driven by messages alone — the same messages the
//! workers send — so the survey flow, the generation rule, the questions,
//! the messages and the no-colour mode are checked without a terminal.
//! Keys are pressed by what they do, through the console's key table.
//! The helpers here are shared with `tui_flow`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::style::Color;

use vss::llv::pipeline;
use vss::llv::{GreyImage, Params};
use vss::profile::Profile;
use vss::tui::app::{App, Phase};
use vss::tui::event::{
    Cmd, DeviceCmd, DeviceEvent, FramePurpose, Msg, PipelineResult, SessionView, StoreCmd,
    StoreError, StoreEvent,
};
use vss::tui::keymap::{
    Action, EditAction, GlobalAction, KEYMAP, Key, PipelineAction, Scope, ScreenId, SurveyAction,
};
use vss::tui::mode::Look;
use vss::tui::widgets::preview::PreviewMode;

const PROFILE: &str = concat!(
    "name = \"screen test cell\"\n",
    crate::support::fixtures::two_lights!()
);

/// The profile, named by a fixed absolute path that is never made (the
/// console shows it; a relative one would show the checkout's folder).
pub fn profile() -> Profile {
    Profile::from_toml(PROFILE, Path::new("/srv/vss/profiles/screen-test.toml")).unwrap()
}

pub fn colour() -> Look {
    Look {
        mode: PreviewMode::Blocks,
        colour: true,
        c256: true,
    }
}

pub fn draw(app: &App, w: u16, h: u16) -> (String, ratatui::buffer::Buffer) {
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(|f| f.render_widget(app, f.area())).unwrap();
    let buf = t.backend().buffer().clone();
    let mut s = String::new();
    for y in 0..h {
        for x in 0..w {
            s.push_str(buf[(x, y)].symbol());
        }
        s.push('\n');
    }
    (s, buf)
}

pub fn event(k: Key) -> KeyEvent {
    let mut m = KeyModifiers::NONE;
    if k.ctrl {
        m |= KeyModifiers::CONTROL;
    }
    if k.shift {
        m |= KeyModifiers::SHIFT;
    }
    KeyEvent::new(k.code, m)
}

/// Presses the key the table binds to `action` in `scope` (or globally).
pub fn press(app: &mut App, scope: Scope, action: Action) -> Vec<Cmd> {
    let k = KEYMAP
        .iter()
        .find(|b| b.action == action && (b.scope == scope || b.scope == Scope::Global))
        .or_else(|| KEYMAP.iter().find(|b| b.action == action))
        .unwrap_or_else(|| panic!("no key for {action:?}"))
        .key;
    app.update(Msg::Key(event(k)))
}

pub fn survey(app: &mut App, a: SurveyAction) -> Vec<Cmd> {
    press(app, Scope::Screen(ScreenId::Survey), Action::Survey(a))
}
pub fn pipe(app: &mut App, a: PipelineAction) -> Vec<Cmd> {
    press(app, Scope::Screen(ScreenId::Pipeline), Action::Pipeline(a))
}
pub fn edit(app: &mut App, a: EditAction) -> Vec<Cmd> {
    press(app, Scope::Screen(ScreenId::Edit), Action::Edit(a))
}
pub fn go(app: &mut App, s: ScreenId) {
    press(app, Scope::Global, Action::Global(GlobalAction::GoTo(s)));
}

pub fn key(app: &mut App, c: char) -> Vec<Cmd> {
    app.update(Msg::Key(KeyEvent::new(
        KeyCode::Char(c),
        KeyModifiers::NONE,
    )))
}

pub fn code(app: &mut App, k: KeyCode) -> Vec<Cmd> {
    app.update(Msg::Key(KeyEvent::new(k, KeyModifiers::NONE)))
}

/// A dark image with a bright square: a few clear lines.
pub fn square(level: u8) -> GreyImage {
    let (w, h) = (96, 96);
    let mut d = vec![30u8; w * h];
    for y in 30..66 {
        for x in 25..70 {
            d[y * w + x] = level;
        }
    }
    GreyImage::new(w, h, d).unwrap()
}

pub fn view() -> SessionView {
    SessionView {
        name: "cube".into(),
        dir: PathBuf::from("/tmp/sessions/cube"),
        letters: vec!['a', 'b', 'c'],
        images: Vec::new(),
        next: Some((1, Some('a'))),
        files: Vec::new(),
        checked: true,
        read_only: false,
    }
}

/// Runs a pipeline request in the test, as the worker would, with the
/// stage times pinned (lens 1.0 ms, edges 2.0, lines 3.0, connect 0.4) so
/// that a drawing does not depend on the machine (`tui_golden`).
pub fn run(app: &mut App, cmds: Vec<Cmd>) {
    for c in cmds {
        if let Cmd::Pipeline(req) = c {
            let mut out = pipeline::run(&req.input.input(None), &req.params).unwrap();
            out.timings = pipeline::Timings {
                lens_us: 1000,
                edges_us: 2000,
                lines_us: 3000,
                connect_us: 400,
            };
            app.update(Msg::Pipeline(PipelineResult {
                generation: req.generation,
                image_key: req.image_key,
                params: req.params.clone(),
                outcome: Ok(Arc::new(out)),
            }));
        }
    }
}

/// The simulated cell's grabber and relay board answering: the device
/// worker's note, as it comes after start-up.
pub fn grabber_connected(app: &mut App) {
    app.update(Msg::Device(DeviceEvent::Connected {
        grabber: "VSS-SIM".into(),
        relay: "sim relays".into(),
    }));
}

/// Runs the survey for image 1 through messages; returns the app in Review.
pub fn reviewed() -> App {
    reviewed_in(view())
}

/// [`reviewed`] in the session `v`.
pub fn reviewed_in(v: SessionView) -> App {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Opened(v)));
    let mut cmds = survey(&mut app, SurveyAction::Enter);
    for (i, letter) in ['a', 'b', 'c'].into_iter().enumerate() {
        assert!(
            cmds.iter().any(|c| matches!(c, Cmd::Device(DeviceCmd::Capture {
                purpose: FramePurpose::Survey { k: 1, letter: l }, lighting: Some(_), .. }) if *l == letter)),
            "capture of {letter} asked: {cmds:?}"
        );
        cmds = app.update(Msg::Device(DeviceEvent::Frame {
            purpose: FramePurpose::Survey { k: 1, letter },
            camera: 1,
            image: square(120 + 40 * i as u8),
            settings: Default::default(),
        }));
        assert!(
            cmds.iter()
                .any(|c| matches!(c, Cmd::Store(StoreCmd::SaveImage { k: 1, .. })))
        );
    }
    let req = cmds
        .iter()
        .find_map(|c| match c {
            Cmd::Pipeline(r) => Some(r),
            _ => None,
        })
        .expect("pipeline asked once all lightings are in");
    assert_eq!(req.input.letters, vec!['a', 'b'], "lit images");
    assert!(
        req.input.ambient.as_ref().is_some_and(|a| a.0 == 'c'),
        "lighting c is ambient"
    );
    run(&mut app, cmds);
    assert_eq!(app.session.work.phase, Phase::Review);
    app
}

pub fn lines_shown(app: &App) -> usize {
    app.tracker
        .current
        .as_ref()
        .and_then(|c| c.lines())
        .map_or(0, <[_]>::len)
}

#[test]
fn every_screen_is_usable_at_80x24() {
    let mut app = reviewed();
    let wants: [(ScreenId, &[&str]); 5] = [
        (ScreenId::Survey, &["1 Survey", "session cube", "accepts"]),
        (ScreenId::Capture, &["lights", "left", "grabber"]),
        (
            ScreenId::Pipeline,
            &[
                "parameters",
                "edges.half_width",
                "lines over grey",
                "stretched",
            ],
        ),
        (ScreenId::Edit, &["lines over", "highlighted"]),
        (ScreenId::Session, &["session", "e writes"]),
    ];
    for (s, texts) in wants {
        go(&mut app, s);
        let (text, _) = draw(&app, 80, 24);
        for t in texts {
            assert!(text.contains(t), "{s:?} lacks {t:?}:\n{text}");
        }
        let last = text.lines().nth(23).unwrap();
        assert!(
            text.lines().skip(21).any(|l| l.contains("quit")),
            "hints on {s:?}: {last}"
        );
        assert!(
            text.lines().next().unwrap().contains("screen test cell"),
            "the profile's name in the top bar:\n{text}"
        );
    }
}

#[test]
fn survey_review_shows_the_line_count_and_accept_moves_on() {
    let mut app = reviewed();
    let (s, _) = draw(&app, 100, 30);
    let n = lines_shown(&app);
    assert!(n >= 4, "the square gives lines: {n}");
    assert!(s.contains(&format!("Image 1: {n} lines")), "{s}");
    let cmds = survey(&mut app, SurveyAction::Accept);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::SaveOutputs { k: 1, .. })))
    );
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("Image 2: camera"), "{s}");
}

/// Enter in review never accepts on its own: it asks.
#[test]
fn enter_in_review_asks_before_accepting() {
    let mut app = reviewed();
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(cmds.is_empty(), "{cmds:?}");
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("Accept image 1"), "{s}");
    press(
        &mut app,
        Scope::Confirm,
        Action::Modal(vss::tui::keymap::ModalAction::No),
    );
    assert_eq!(app.session.work.phase, Phase::Review);
    survey(&mut app, SurveyAction::Enter);
    let cmds = press(
        &mut app,
        Scope::Confirm,
        Action::Modal(vss::tui::keymap::ModalAction::Yes),
    );
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::SaveOutputs { k: 1, .. })))
    );
    assert_eq!(app.session.work.k, 2);
}

#[test]
fn a_parameter_change_reruns_and_older_results_never_win() {
    let mut app = reviewed();
    go(&mut app, ScreenId::Pipeline);
    pipe(&mut app, PipelineAction::ParamNext); // edges.half_width
    let before = app.tracker.generation;
    let cmds = pipe(&mut app, PipelineAction::Inc);
    let Some(Cmd::Pipeline(req)) = cmds.first() else {
        panic!("a parameter step asks for a run");
    };
    assert_eq!(req.generation, before + 1);
    assert_ne!(req.params, Params::default());
    assert!(
        app.chrome
            .log
            .last()
            .unwrap()
            .text
            .contains("edges.half_width 3 → 4"),
        "the change is logged"
    );
    let req = req.clone();
    run(&mut app, cmds);
    let shown = lines_shown(&app);
    // A result of an older generation arriving late is ignored.
    let mut stale = (*app
        .tracker
        .current
        .as_ref()
        .unwrap()
        .outputs
        .clone()
        .unwrap())
    .clone();
    stale.lines.clear();
    app.update(Msg::Pipeline(PipelineResult {
        generation: before,
        image_key: req.image_key,
        params: Params::default(),
        outcome: Ok(Arc::new(stale)),
    }));
    assert_eq!(lines_shown(&app), shown);
    let (s, _) = draw(&app, 80, 24);
    assert!(
        s.lines()
            .any(|l| l.contains("edges.half_width") && l.contains(" 4*")),
        "changed values are marked:\n{s}"
    );
}

/// A run that fails leaves the older outputs on screen: the views say so,
/// and neither the save key nor accept writes them as if they were the
/// panel's values.
#[test]
fn a_failed_run_is_stale_and_is_never_saved() {
    let mut app = reviewed();
    go(&mut app, ScreenId::Pipeline);
    pipe(&mut app, PipelineAction::ParamNext);
    let cmds = pipe(&mut app, PipelineAction::Inc);
    let Some(Cmd::Pipeline(req)) = cmds.into_iter().next() else {
        panic!("a parameter step asks for a run");
    };
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("stale: running"), "{s}");
    app.update(Msg::Pipeline(PipelineResult {
        generation: req.generation,
        image_key: req.image_key,
        params: req.params.clone(),
        outcome: Err(vss::llv::LlvError::SizeMismatch {
            a: (96, 96),
            b: (0, 0),
        }),
    }));
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("stale: last run failed"), "{s}");
    let cmds = pipe(&mut app, PipelineAction::Save);
    assert!(
        !cmds.iter().any(|c| matches!(c, Cmd::Store(_))),
        "nothing saved: {cmds:?}"
    );
    assert!(app.chrome.log.last().unwrap().text.contains("not saved"));
    go(&mut app, ScreenId::Survey);
    let cmds = survey(&mut app, SurveyAction::Accept);
    assert!(
        !cmds.iter().any(|c| matches!(c, Cmd::Store(_))),
        "accept saves nothing: {cmds:?}"
    );
    assert_eq!(
        app.session.work.phase,
        Phase::Review,
        "still reviewing image 1"
    );
}

#[test]
fn help_fits_80x24_scrolls_and_lists_every_key_and_the_marks() {
    let mut app = App::new(&profile(), colour());
    go(&mut app, ScreenId::Pipeline);
    press(&mut app, Scope::Global, Action::Global(GlobalAction::Help));
    let mut seen = String::new();
    for _ in 0..40 {
        let (s, _) = draw(&app, 80, 24);
        for l in s.lines() {
            assert!(l.chars().count() <= 80);
        }
        seen.push_str(&s);
        code(&mut app, KeyCode::PageDown);
    }
    assert!(seen.contains("+ = →"), "{seen}");
    assert!(seen.contains("type a value"));
    assert!(seen.contains("The checklist's marks"));
    assert!(seen.contains("DAMAGED"));
    assert!(seen.contains("Every picture"));
    for b in KEYMAP.iter().filter(|b| {
        matches!(b.scope, Scope::Global | Scope::Picture)
            || b.scope == Scope::Screen(ScreenId::Pipeline)
    }) {
        assert!(seen.contains(b.desc), "help lacks {:?}", b.desc);
    }
    code(&mut app, KeyCode::Esc);
    assert!(app.chrome.overlay.is_none());
}

#[test]
fn no_colour_mode_draws_without_colour_attributes() {
    let mut app = reviewed();
    app.chrome.look = Look {
        mode: PreviewMode::Ascii,
        colour: false,
        c256: false,
    };
    for s in ScreenId::ALL {
        go(&mut app, s);
        let (_, buf) = draw(&app, 80, 24);
        for c in buf.content() {
            assert_eq!((c.fg, c.bg), (Color::Reset, Color::Reset), "{s:?}");
            assert!(c.symbol().is_ascii(), "{s:?}: {:?}", c.symbol());
        }
    }
}

/// The Linux console: sixteen colours, no 256-colour index anywhere.
#[test]
fn the_linux_console_gets_its_sixteen_colours() {
    let mut app = reviewed();
    app.chrome.look = vss::tui::mode::pick(None, Some("linux"), None);
    let mut coloured = 0;
    for s in ScreenId::ALL {
        go(&mut app, s);
        let (_, buf) = draw(&app, 80, 24);
        for c in buf.content() {
            assert!(
                !matches!(c.fg, Color::Indexed(_) | Color::Rgb(..))
                    && !matches!(c.bg, Color::Indexed(_) | Color::Rgb(..)),
                "{s:?}: {c:?}"
            );
            assert!(c.symbol().is_ascii());
            coloured += usize::from(c.fg != Color::Reset);
        }
    }
    assert!(coloured > 0, "some colour is used");
}

#[test]
fn device_trouble_and_hostile_text_are_shown_cleanly() {
    let mut app = App::new(&profile(), colour());
    app.update(Msg::Device(DeviceEvent::Lost {
        error: "/dev/pts/9: gone\x1b[2J".into(),
        busy: false,
    }));
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("DEVICE LOST"), "{s}");
    assert!(!s.contains('\x1b'));
    app.update(Msg::Device(DeviceEvent::Connected {
        grabber: "VSG sim".into(),
        relay: "pts".into(),
    }));
    let (s, _) = draw(&app, 80, 24);
    assert!(!s.contains("DEVICE LOST"));
    assert!(s.contains("devices back"), "{s}");
}

/// A long message wraps over up to three rows; past that `!` shows it
/// all, and the expanded log keeps and scrolls the whole run.
#[test]
fn every_message_is_readable_at_80x24() {
    let mut app = App::new(&profile(), colour());
    let long = format!(
        "capture failed: {}",
        "transfer cancelled at byte 16384 of 262144; ".repeat(3)
    );
    app.update(Msg::Device(DeviceEvent::CaptureFailed {
        purpose: FramePurpose::Snapshot,
        error: long.clone(),
    }));
    let (s, _) = draw(&app, 80, 24);
    let rows: Vec<&str> = s.lines().collect();
    let shown: String = rows[..].join(" ");
    assert!(
        shown.contains("transfer cancelled at byte 16384 of 262144"),
        "{s}"
    );
    assert!(
        rows.iter().filter(|r| r.contains("262144")).count() >= 2,
        "wrapped:\n{s}"
    );
    let very = "x ".repeat(200);
    app.update(Msg::Device(DeviceEvent::Note(very.clone())));
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("! shows all"), "{s}");
    press(
        &mut app,
        Scope::Global,
        Action::Global(GlobalAction::LastMessage),
    );
    let (s, _) = draw(&app, 80, 24);
    assert!(s.matches('x').count() >= 200, "the whole message:\n{s}");
    code(&mut app, KeyCode::Esc);
    for i in 0..60 {
        app.update(Msg::Device(DeviceEvent::Note(format!("note {i}"))));
    }
    press(
        &mut app,
        Scope::Global,
        Action::Global(GlobalAction::ToggleLog),
    );
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("note 59") && !s.contains("note 0 "), "{s}");
    press(
        &mut app,
        Scope::Global,
        Action::Global(GlobalAction::LogTop),
    );
    let (s, _) = draw(&app, 80, 24);
    assert!(
        s.contains("profile screen test cell") || s.contains("capture failed"),
        "{s}"
    );
    assert!(!s.contains("note 59"), "{s}");
}

#[test]
fn too_small_a_terminal_says_so() {
    let app = App::new(&profile(), colour());
    let (s, _) = draw(&app, 40, 10);
    assert!(s.contains("terminal too small"), "{s}");
    assert!(s.contains("40 × 10"), "{s}");
}

/// The answer to a key is not replaced on the message line by a background
/// message that comes right after it: the background message goes to the
/// log (the line says how many newer ones wait there), and shows on the
/// line after the operator's next key.
#[test]
fn the_answer_to_a_key_is_not_replaced_by_a_background_message() {
    let mut app = App::new(&profile(), colour());
    // No session open: Accept is refused, and says why.
    survey(&mut app, SurveyAction::Accept);
    let answer = app.chrome.log.last().unwrap().text.clone();
    let (s, _) = draw(&app, 80, 24);
    let message: String = s.lines().skip(20).collect::<Vec<_>>().join(" ");
    assert!(message.contains(&answer[..answer.len().min(30)]), "{s}");
    app.update(Msg::Device(DeviceEvent::Note("the lights answered".into())));
    let (s, _) = draw(&app, 80, 24);
    assert!(
        s.contains(&answer[..answer.len().min(30)]),
        "the answer stays:\n{s}"
    );
    assert!(!s.contains("the lights answered"), "{s}");
    let words = s.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains("(+1 newer in the log)"), "{s}");
    assert_eq!(app.chrome.log.last().unwrap().text, "the lights answered");
    // A key that answers nothing (the cursor down): the newest shows.
    survey(&mut app, SurveyAction::Down);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("the lights answered"), "{s}");
    assert!(!s.contains("newer in the log"), "{s}");
}

/// An error that comes after the held answer to a key is not kept off the
/// message line: a failed save said after "saving its outputs…" or after
/// an edit's words showed only in the log for the hold's 3 s, the line
/// reading as if all went well.
#[test]
fn an_error_after_the_answer_to_a_key_takes_the_message_line() {
    let mut app = App::new(&profile(), colour());
    survey(&mut app, SurveyAction::Accept);
    let answer = app.chrome.log.last().unwrap().text.clone();
    app.update(Msg::Store(StoreEvent::Error(StoreError::Report {
        why: "the disk is full".into(),
        old: String::new(),
    })));
    app.update(Msg::Device(DeviceEvent::Note("the lights answered".into())));
    let (s, _) = draw(&app, 80, 24);
    let message: String = s.lines().skip(20).collect::<Vec<_>>().join(" ");
    assert!(
        message.contains("report NOT written: the disk is full"),
        "the error shows:\n{s}"
    );
    assert!(!message.contains(&answer[..answer.len().min(30)]), "{s}");
    let words = message.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains("(+1 newer in the log)"), "{s}");
}

/// A session open only to look says so on the top bar, in a word where
/// the words do not fit, and the profile's name stays whole at 80 columns
/// (a simulated and a real cell cannot be confused).
#[test]
fn the_top_bar_keeps_the_profile_name_beside_a_read_only_session() {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Opened(SessionView {
        name: "hull_port_aft".into(),
        read_only: true,
        ..view()
    })));
    let (s, _) = draw(&app, 80, 24);
    let top = s.lines().next().unwrap();
    assert!(top.contains("hull_port_aft"), "{top}");
    assert!(top.contains("read-only"), "{top}");
    assert!(top.trim_end().ends_with("screen test cell"), "{top}");
    let (s, _) = draw(&app, 120, 24);
    assert!(
        s.lines()
            .next()
            .unwrap()
            .contains("read-only: nothing will be saved"),
        "{s}"
    );
}
