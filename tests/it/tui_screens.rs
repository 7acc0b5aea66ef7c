//! Every screen of the console drawn through ratatui's `TestBackend`
//! (80 × 24 and larger), driven by messages alone — the same messages the
//! workers send — so the survey flow, the generation rule, the modal
//! questions and the no-colour mode are checked without a terminal.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::style::Color;

use vss::llv::pipeline::{self, Input};
use vss::llv::{GreyImage, Params};
use vss::profile::Profile;
use vss::tui::app::{App, Phase};
use vss::tui::event::{
    Cmd, DeviceCmd, DeviceEvent, FramePurpose, ImageState, Msg, PipelineResult, SessionView,
    StoreCmd, StoreEvent,
};
use vss::tui::mode::Look;
use vss::tui::widgets::preview::PreviewMode;

const PROFILE: &str = r#"
name = "screen test cell"
[[lights]]
name = "left"
relay = 0
[[lights]]
name = "right"
relay = 1
[[lighting]]
letter = "a"
on = ["left"]
[[lighting]]
letter = "b"
on = ["right"]
[[lighting]]
letter = "c"
on = []
"#;

fn profile() -> Profile {
    Profile::from_toml(PROFILE, Path::new("test.toml")).unwrap()
}

fn colour() -> Look {
    Look {
        mode: PreviewMode::Blocks,
        colour: true,
    }
}

fn draw(app: &App, w: u16, h: u16) -> (String, ratatui::buffer::Buffer) {
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

fn key(app: &mut App, c: char) -> Vec<Cmd> {
    app.update(Msg::Key(KeyEvent::new(
        KeyCode::Char(c),
        KeyModifiers::NONE,
    )))
}

fn code(app: &mut App, k: KeyCode) -> Vec<Cmd> {
    app.update(Msg::Key(KeyEvent::new(k, KeyModifiers::NONE)))
}

/// A dark image with a bright square: a few clear lines.
fn square(level: u8) -> GreyImage {
    let (w, h) = (96, 96);
    let mut d = vec![30u8; w * h];
    for y in 30..66 {
        for x in 25..70 {
            d[y * w + x] = level;
        }
    }
    GreyImage::new(w, h, d).unwrap()
}

fn view() -> SessionView {
    SessionView {
        name: "cube".into(),
        dir: PathBuf::from("/tmp/sessions/cube"),
        letters: vec!['a', 'b', 'c'],
        images: Vec::new(),
        next: Some((1, Some('a'))),
        files: Vec::new(),
    }
}

/// Runs the survey for image 1 through messages; returns the app in Review.
fn reviewed() -> App {
    reviewed_in(view())
}

/// [`reviewed`] in the session `v`.
fn reviewed_in(v: SessionView) -> App {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Opened(v)));
    let mut cmds = code(&mut app, KeyCode::Enter);
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
        }));
        assert!(
            cmds.iter()
                .any(|c| matches!(c, Cmd::Store(StoreCmd::SaveImage { k: 1, .. })))
        );
    }
    let req = cmds
        .into_iter()
        .find_map(|c| match c {
            Cmd::Pipeline(r) => Some(r),
            _ => None,
        })
        .expect("pipeline asked once all lightings are in");
    assert_eq!(req.images.len(), 2, "lit images");
    assert!(req.ambient.is_some(), "lighting c is ambient");
    let out = pipeline::run(
        &Input {
            images: &req.images,
            ambient: req.ambient.as_deref(),
            lens: None,
        },
        &req.params,
    )
    .unwrap();
    app.update(Msg::Pipeline(PipelineResult {
        generation: req.generation,
        image_key: req.image_key,
        params: req.params.clone(),
        outcome: Ok(Arc::new(out)),
    }));
    assert_eq!(app.work.phase, Phase::Review);
    app
}

#[test]
fn every_screen_is_usable_at_80x24() {
    let mut app = reviewed();
    let wants: [(char, &[&str]); 5] = [
        ('1', &["1 Survey", "checklist", "a accept"]),
        ('2', &["lights", "left", "grabber"]),
        (
            '3',
            &["parameters", "edges.half_width", "lines over grey", "grey "],
        ),
        ('4', &["lines over grey", "selected"]),
        ('5', &["session", "e exports"]),
    ];
    for (k, texts) in wants {
        key(&mut app, k);
        let (s, _) = draw(&app, 80, 24);
        for t in texts {
            assert!(s.contains(t), "screen {k} lacks {t:?}:\n{s}");
        }
        let last = s.lines().nth(23).unwrap();
        assert!(last.contains("quit"), "status bar on screen {k}: {last}");
    }
}

#[test]
fn survey_review_shows_the_line_count_and_accept_moves_on() {
    let mut app = reviewed();
    let (s, _) = draw(&app, 100, 30);
    let n = app
        .current
        .as_ref()
        .unwrap()
        .outputs
        .as_ref()
        .unwrap()
        .lines
        .len();
    assert!(n >= 4, "the square gives lines: {n}");
    assert!(s.contains(&format!("Image 1: {n} lines")), "{s}");
    let cmds = key(&mut app, 'a');
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::SaveOutputs { k: 1, .. })))
    );
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("Image 2: camera"), "{s}");
}

#[test]
fn accept_moves_on_to_the_camera_and_location_the_survey_planned() {
    // The session has image 2 on record for camera 3 at location 2 (a new
    // survey plans one image per camera); image 1 is taken with camera 1.
    let plan = |k, camera, location| ImageState {
        k,
        camera,
        location,
        captured: Vec::new(),
        outputs: false,
        stale: false,
        edits: 0,
    };
    let mut v = view();
    v.images = vec![plan(1, 1, 1), plan(2, 3, 2)];
    let mut app = reviewed_in(v);
    key(&mut app, 'a');
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("Image 2: camera 3 (c), location 2 (p)"), "{s}");
    // Enter captures image 2 with that camera.
    let cmds = code(&mut app, KeyCode::Enter);
    assert!(
        cmds.iter().any(|c| matches!(
            c,
            Cmd::Device(DeviceCmd::Capture {
                purpose: FramePurpose::Survey { k: 2, .. },
                camera: 3,
                ..
            })
        )),
        "capture with camera 3 asked: {cmds:?}"
    );
}

#[test]
fn a_parameter_change_reruns_and_older_results_never_win() {
    let mut app = reviewed();
    key(&mut app, '3');
    code(&mut app, KeyCode::Down); // edges.half_width
    let before = app.generation;
    let cmds = key(&mut app, '+');
    let Some(Cmd::Pipeline(req)) = cmds.into_iter().next() else {
        panic!("a parameter step asks for a run");
    };
    assert_eq!(req.generation, before + 1);
    assert_ne!(req.params, Params::default());
    let out = pipeline::run(
        &Input {
            images: &req.images,
            ambient: req.ambient.as_deref(),
            lens: None,
        },
        &req.params,
    )
    .unwrap();
    let mut stale = out.clone();
    stale.lines.clear();
    app.update(Msg::Pipeline(PipelineResult {
        generation: req.generation,
        image_key: req.image_key,
        params: req.params.clone(),
        outcome: Ok(Arc::new(out)),
    }));
    let shown = app
        .current
        .as_ref()
        .unwrap()
        .outputs
        .as_ref()
        .unwrap()
        .lines
        .len();
    // A result of an older generation arriving late is ignored.
    app.update(Msg::Pipeline(PipelineResult {
        generation: before,
        image_key: req.image_key,
        params: Params::default(),
        outcome: Ok(Arc::new(stale)),
    }));
    assert_eq!(
        app.current
            .as_ref()
            .unwrap()
            .outputs
            .as_ref()
            .unwrap()
            .lines
            .len(),
        shown
    );
}

#[test]
fn redo_asks_before_overwriting() {
    let mut app = reviewed();
    key(&mut app, '1');
    assert!(key(&mut app, 'r').is_empty());
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("Redo image 1?"), "{s}");
    assert!(key(&mut app, 'n').is_empty());
    assert_eq!(app.work.phase, Phase::Review);
    key(&mut app, 'r');
    let cmds = key(&mut app, 'y');
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Redo(1))))
    );
    assert_eq!(app.work.phase, Phase::Setup);
}

#[test]
fn help_lists_the_key_table_of_the_screen() {
    let mut app = App::new(&profile(), colour());
    key(&mut app, '3');
    key(&mut app, '?');
    let (s, _) = draw(&app, 100, 40);
    assert!(s.contains("help"));
    assert!(s.contains("+ = →"), "{s}");
    assert!(s.contains("type a value"));
    key(&mut app, 'x');
    assert!(!app.help);
}

#[test]
fn no_colour_mode_draws_without_colour_attributes() {
    let mut app = reviewed();
    app.look = Look {
        mode: PreviewMode::Ascii,
        colour: false,
    };
    for k in ['1', '2', '3', '4', '5'] {
        key(&mut app, k);
        let (_, buf) = draw(&app, 80, 24);
        for c in buf.content() {
            assert_eq!((c.fg, c.bg), (Color::Reset, Color::Reset), "screen {k}");
            assert!(c.symbol().is_ascii(), "screen {k}: {:?}", c.symbol());
        }
    }
}

#[test]
fn device_trouble_and_hostile_text_are_shown_cleanly() {
    let mut app = App::new(&profile(), colour());
    app.update(Msg::Device(DeviceEvent::Lost {
        error: "/dev/pts/9: gone\x1b[2J".into(),
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

#[test]
fn resuming_a_session_loads_the_partial_image() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    v.images = vec![
        ImageState {
            k: 1,
            camera: 2,
            location: 1,
            captured: vec!['a', 'b', 'c'],
            outputs: true,
            ..Default::default()
        },
        ImageState {
            k: 2,
            camera: 3,
            location: 2,
            captured: vec!['a'],
            ..Default::default()
        },
    ];
    v.next = Some((2, Some('b')));
    let cmds = app.update(Msg::Store(StoreEvent::Opened(v)));
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Load(2))))
    );
    app.update(Msg::Store(StoreEvent::Images {
        k: 2,
        images: vec![('a', square(200))],
    }));
    assert_eq!(app.work.k, 2);
    assert_eq!(app.work.camera, 3);
    assert_eq!(app.missing_letters(), vec!['b', 'c']);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("captures lightings bc"), "{s}");
}

#[test]
fn edits_select_delete_undo_and_go_to_the_session_log() {
    let mut app = reviewed();
    key(&mut app, '4');
    let n = app
        .current
        .as_ref()
        .unwrap()
        .editor
        .as_ref()
        .unwrap()
        .lines()
        .len();
    assert!(
        key(&mut app, 'x').is_empty(),
        "nothing selected: nothing deleted"
    );
    key(&mut app, 'n');
    assert_eq!(app.edit.selected, vec![0]);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("#0 ("), "selected line listed:\n{s}");
    let cmds = key(&mut app, 'x');
    assert!(
        cmds.iter().any(|c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { k: 1, lines, .. }) if lines.len() == n - 1)),
        "{cmds:?}"
    );
    let cmds = key(&mut app, 'u');
    assert!(cmds.iter().any(|c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { what, lines, .. }) if what == "undo" && lines.len() == n)));
    // The corner key picks two different lines near the cursor.
    key(&mut app, 'k');
    assert_eq!(app.edit.selected.len(), 2);
    assert_ne!(app.edit.selected[0], app.edit.selected[1]);
}

#[test]
fn the_worker_engine_reruns_from_the_changed_stage() {
    use vss::tui::workers::pipeline::Engine;
    let mut app = reviewed();
    key(&mut app, '3');
    let i = vss::llv::params::PARAMS
        .iter()
        .position(|p| p.key == "connect.min_line_length")
        .unwrap();
    for _ in 0..i {
        code(&mut app, KeyCode::Down);
    }
    let lines = |app: &App| {
        app.current
            .as_ref()
            .unwrap()
            .outputs
            .as_ref()
            .unwrap()
            .lines
            .len()
    };
    let before = lines(&app);
    let mut engine = Engine::default();
    for _ in 0..3 {
        for c in key(&mut app, '>') {
            if let Cmd::Pipeline(req) = c {
                let outcome = engine.process(&req).map_err(|e| e.to_string());
                app.update(Msg::Pipeline(PipelineResult {
                    generation: req.generation,
                    image_key: req.image_key,
                    params: req.params.clone(),
                    outcome,
                }));
            }
        }
    }
    assert_eq!(app.params.connect.min_line_length, 42.0);
    let after = lines(&app);
    assert!(
        after < before,
        "longer minimum keeps fewer lines: {before} -> {after}"
    );
}

#[test]
fn accepting_after_hand_edits_keeps_the_edits_on_disk() {
    let mut app = reviewed();
    let n = app
        .current
        .as_ref()
        .unwrap()
        .editor
        .as_ref()
        .unwrap()
        .lines()
        .len();
    key(&mut app, '4');
    key(&mut app, 'n');
    key(&mut app, 'x');
    key(&mut app, '1');
    let cmds = key(&mut app, 'a');
    let save = cmds
        .iter()
        .position(|c| matches!(c, Cmd::Store(StoreCmd::SaveOutputs { k: 1, .. })));
    let edit = cmds.iter().position(
        |c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { k: 1, lines, .. }) if lines.len() == n - 1),
    );
    assert!(
        save.is_some() && edit.is_some() && save < edit,
        "outputs, then the edits on top: {cmds:?}"
    );
}

#[test]
fn resumed_hand_edited_lines_win_over_the_first_rerun() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    v.images = vec![ImageState {
        k: 1,
        camera: 1,
        location: 1,
        captured: vec!['a', 'b', 'c'],
        edits: 1,
        ..Default::default()
    }];
    v.next = Some((1, None));
    app.update(Msg::Store(StoreEvent::Opened(v)));
    let cmds = app.update(Msg::Store(StoreEvent::Images {
        k: 1,
        images: vec![('a', square(150)), ('b', square(200)), ('c', square(90))],
    }));
    let edited = vec![vss::llv::Segment::new(
        vss::llv::Point::new(1.0, 1.0),
        vss::llv::Point::new(50.0, 1.0),
    )];
    app.update(Msg::Store(StoreEvent::Lines {
        k: 1,
        lines: edited.clone(),
    }));
    let Some(Cmd::Pipeline(req)) = cmds.into_iter().next() else {
        panic!("resume runs the stages")
    };
    let out = pipeline::run(
        &Input {
            images: &req.images,
            ambient: req.ambient.as_deref(),
            lens: None,
        },
        &req.params,
    )
    .unwrap();
    app.update(Msg::Pipeline(PipelineResult {
        generation: req.generation,
        image_key: req.image_key,
        params: req.params.clone(),
        outcome: Ok(Arc::new(out)),
    }));
    assert_eq!(app.work.phase, Phase::Review);
    assert_eq!(
        app.current
            .as_ref()
            .unwrap()
            .editor
            .as_ref()
            .unwrap()
            .lines(),
        &edited[..]
    );
}

/// A run that fails leaves the older outputs on screen: the views say so,
/// and neither the save key nor accept writes them as if they were the
/// panel's values.
#[test]
fn a_failed_run_is_stale_and_is_never_saved() {
    let mut app = reviewed();
    key(&mut app, '3');
    code(&mut app, KeyCode::Down); // edges.half_width
    let cmds = key(&mut app, '+');
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
        }
        .to_string()),
    }));
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("stale: last run failed"), "{s}");
    let save = vss::tui::keymap::KEYMAP
        .iter()
        .find(|b| b.action == vss::tui::keymap::Action::SaveOutputs)
        .unwrap()
        .key;
    let KeyCode::Char(c) = save.code else {
        panic!("a letter saves")
    };
    let cmds = app.update(Msg::Key(KeyEvent::new(
        KeyCode::Char(c),
        if save.ctrl {
            KeyModifiers::CONTROL
        } else {
            KeyModifiers::NONE
        },
    )));
    assert!(
        !cmds.iter().any(|c| matches!(c, Cmd::Store(_))),
        "nothing saved: {cmds:?}"
    );
    assert!(app.log.last().unwrap().text.contains("not saved"));
    key(&mut app, '1');
    let cmds = key(&mut app, 'a');
    assert!(
        !cmds.iter().any(|c| matches!(c, Cmd::Store(_))),
        "accept saves nothing: {cmds:?}"
    );
    assert_eq!(app.work.phase, Phase::Review, "still reviewing image 1");
}
