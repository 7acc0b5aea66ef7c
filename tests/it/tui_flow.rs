//! The console's flows through messages alone: following the survey's
//! plan, capturing again (only the damaged lighting, when one is), going
//! back to any image (its saved outputs shown, not re-run), edits and
//! their questions, the session picker, the end of the survey, quitting
//! during a capture, the lock of a live console, and the text field.

use std::path::PathBuf;

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use vss::llv::pipeline::StageOutputs;
use vss::llv::{Point, Segment};
use vss::tui::app::{App, Modal, Phase};
use vss::tui::event::{
    Cmd, DeviceCmd, FramePurpose, ImageState, LoadedImage, Msg, SavedOutputs, SessionEntry,
    StoreCmd, StoreEvent,
};
use vss::tui::keymap::{
    Action, EditAction, GlobalAction, ModalAction, Scope, ScreenId, SurveyAction,
};

use super::tui_harness::flat;
use super::tui_screens::{
    code, colour, draw, edit, go, grabber_connected, key, lines_shown, press, profile, reviewed,
    reviewed_in, run, square, survey, view,
};

fn yes(app: &mut App) -> Vec<Cmd> {
    press(app, Scope::Confirm, Action::Modal(ModalAction::Yes))
}

fn plan(k: u32, camera: u32, location: u32) -> ImageState {
    ImageState {
        k,
        camera,
        location,
        ..Default::default()
    }
}

fn done(k: u32) -> ImageState {
    ImageState {
        captured: vec!['a', 'b', 'c'],
        outputs: true,
        ..plan(k, 1, 1)
    }
}

#[test]
fn accept_moves_on_to_the_camera_and_location_the_survey_planned() {
    // The session has image 2 on record for camera 3 at location 2 (a new
    // survey plans one image per camera); image 1 is taken with camera 1.
    let mut v = view();
    v.images = vec![plan(1, 1, 1), plan(2, 3, 2)];
    let mut app = reviewed_in(v);
    survey(&mut app, SurveyAction::Accept);
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("Image 2: camera 3 (c), location 2 (p)"), "{s}");
    let cmds = survey(&mut app, SurveyAction::Enter);
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
fn capturing_again_asks_first() {
    let mut app = reviewed();
    assert!(survey(&mut app, SurveyAction::Redo).is_empty());
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("Capture image 1 again"), "{s}");
    assert!(press(&mut app, Scope::Confirm, Action::Modal(ModalAction::No)).is_empty());
    assert_eq!(app.session.work.phase, Phase::Review);
    survey(&mut app, SurveyAction::Redo);
    let cmds = yes(&mut app);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Redo(1))))
    );
    assert_eq!(app.session.work.phase, Phase::Setup);
    assert_eq!(app.missing_letters(), vec!['a', 'b', 'c']);
}

/// Image 2's lighting b is damaged: capturing it again offers only b.
#[test]
fn a_damaged_lighting_is_retaken_alone() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    let mut two = done(2);
    two.damaged = vec![('b', "cube2b.img: truncated at byte 4096".into())];
    v.images = vec![done(1), two];
    v.next = None;
    app.update(Msg::Store(StoreEvent::Opened(v)));
    let (s, _) = draw(&app, 80, 24);
    assert!(
        s.contains("a!c"),
        "the checklist marks the damaged lighting:\n{s}"
    );
    survey(&mut app, SurveyAction::Up);
    survey(&mut app, SurveyAction::Up);
    survey(&mut app, SurveyAction::Down);
    assert_eq!(app.screens.survey.row, Some(2));
    survey(&mut app, SurveyAction::Redo);
    let (s, _) = draw(&app, 80, 24);
    let words = s
        .replace('│', " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    assert!(words.contains("y sets up the retake of only b"), "{s}");
    let cmds = yes(&mut app);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Load(2))))
    );
    app.update(Msg::Store(StoreEvent::Loaded(Box::new(LoadedImage {
        k: 2,
        images: vec![('a', square(150)), ('c', square(90))],
        damaged: vec![('b', "cube2b.img: truncated".into())],
        ..Default::default()
    }))));
    assert_eq!(app.missing_letters(), vec!['b']);
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(
        cmds.iter().any(|c| matches!(
            c,
            Cmd::Device(DeviceCmd::Capture {
                purpose: FramePurpose::Survey { k: 2, letter: 'b' },
                ..
            })
        )),
        "{cmds:?}"
    );
}

#[test]
fn resuming_a_session_loads_the_partial_image() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    v.images = vec![
        ImageState {
            captured: vec!['a', 'b', 'c'],
            outputs: true,
            ..plan(1, 2, 1)
        },
        ImageState {
            captured: vec!['a'],
            ..plan(2, 3, 2)
        },
    ];
    v.next = Some((2, Some('b')));
    let cmds = app.update(Msg::Store(StoreEvent::Opened(v)));
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Load(2))))
    );
    app.update(Msg::Store(StoreEvent::Loaded(Box::new(LoadedImage {
        k: 2,
        images: vec![('a', square(200))],
        ..Default::default()
    }))));
    assert_eq!(app.session.work.k, 2);
    assert_eq!(app.session.work.camera, 3);
    assert_eq!(app.missing_letters(), vec!['b', 'c']);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("captures lightings bc"), "{s}");
}

fn saved_outputs(lines: usize) -> StageOutputs {
    StageOutputs {
        lines: (0..lines)
            .map(|i| {
                Segment::new(
                    Point::new(1.0, i as f64 * 5.0),
                    Point::new(60.0, i as f64 * 5.0),
                )
            })
            .collect(),
        ..StageOutputs::default()
    }
}

/// On resume the last worked image is shown; going back to an accepted
/// image shows its saved outputs and lines (nothing re-run) with the panel
/// at the values they were made with, titled with the image.
#[test]
fn any_image_can_be_gone_back_to() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    v.images = vec![done(1), done(2), plan(3, 3, 1)];
    v.next = Some((3, Some('a')));
    let cmds = app.update(Msg::Store(StoreEvent::Opened(v)));
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Load(2)))),
        "the last worked image loads: {cmds:?}"
    );
    let mut p = vss::llv::Params::default();
    p.edges.floor = 3.5;
    let cmds = app.update(Msg::Store(StoreEvent::Loaded(Box::new(LoadedImage {
        k: 2,
        images: vec![('a', square(150)), ('b', square(200)), ('c', square(90))],
        saved: Some(SavedOutputs {
            outputs: saved_outputs(3),
            params: p.clone(),
        }),
        lines: Some(saved_outputs(2).lines),
        accepted: true,
        ..Default::default()
    }))));
    assert!(
        cmds.is_empty(),
        "saved outputs are shown, not re-run: {cmds:?}"
    );
    assert_eq!(app.tracker.params, p, "the panel shows the saved values");
    assert_eq!(
        lines_shown(&app),
        2,
        "the .ldr's lines, hand edits included"
    );
    go(&mut app, ScreenId::Pipeline);
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("image 2a · lines over grey"), "{s}");
    assert!(!s.contains("stale"), "{s}");
    go(&mut app, ScreenId::Edit);
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("image 2a · lines over grey 2"), "{s}");
    // Image 1 from the checklist: Up twice from image 3, then Enter.
    go(&mut app, ScreenId::Survey);
    survey(&mut app, SurveyAction::Up);
    survey(&mut app, SurveyAction::Up);
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Load(1)))),
        "{cmds:?}"
    );
    assert_eq!(app.session.work.k, 1);
}

#[test]
fn editing_an_accepted_image_asks_and_undo_takes_the_edit_back() {
    let mut app = reviewed();
    let n = lines_shown(&app);
    survey(&mut app, SurveyAction::Accept);
    go(&mut app, ScreenId::Edit);
    edit(&mut app, EditAction::LineNext);
    assert_eq!(app.screens.edit.highlighted, Some(0));
    let cmds = edit(&mut app, EditAction::Delete);
    assert!(cmds.is_empty(), "asks first: {cmds:?}");
    assert!(matches!(app.chrome.modal, Some(Modal::Confirm { .. })));
    let cmds = yes(&mut app);
    assert!(
        cmds.iter().any(|c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { k: 1, what, lines }) if lines.len() == n - 1 && what.starts_with("deleted line 0 ("))),
        "{cmds:?}"
    );
    let (s, _) = draw(&app, 100, 30);
    assert!(s.contains("deleted line 0"), "the edit in words:\n{s}");
    let cmds = edit(&mut app, EditAction::Undo);
    assert!(
        cmds.iter().any(
            |c| matches!(c, Cmd::Store(StoreCmd::UndoEdit { k: 1, lines }) if lines.len() == n)
        ),
        "undo takes the edit back, not a new edit: {cmds:?}"
    );
    let cmds = edit(&mut app, EditAction::Redo);
    assert!(
        cmds.iter().any(|c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { what, .. }) if what.starts_with("deleted"))),
        "{cmds:?}"
    );
    // Space toggles the highlighted line; the corner key picks two lines.
    edit(&mut app, EditAction::LineNext);
    edit(&mut app, EditAction::Toggle);
    assert_eq!(app.screens.edit.selected.len(), 1);
    edit(&mut app, EditAction::Toggle);
    assert!(app.screens.edit.selected.is_empty());
    edit(&mut app, EditAction::Corner);
    assert_eq!(app.screens.edit.selected.len(), 2);
    assert_ne!(app.screens.edit.selected[0], app.screens.edit.selected[1]);
}

#[test]
fn accepting_after_hand_edits_keeps_the_edits_on_disk() {
    let mut app = reviewed();
    let n = lines_shown(&app);
    go(&mut app, ScreenId::Edit);
    edit(&mut app, EditAction::LineNext);
    edit(&mut app, EditAction::Delete);
    go(&mut app, ScreenId::Survey);
    let cmds = survey(&mut app, SurveyAction::Accept);
    let save = cmds
        .iter()
        .position(|c| matches!(c, Cmd::Store(StoreCmd::SaveOutputs { k: 1, .. })));
    let ed = cmds.iter().position(
        |c| matches!(c, Cmd::Store(StoreCmd::RecordEdit { k: 1, lines, .. }) if lines.len() == n - 1),
    );
    assert!(
        save.is_some() && ed.is_some() && save < ed,
        "outputs, then the edits on top: {cmds:?}"
    );
}

#[test]
fn resumed_hand_edited_lines_win_over_the_first_rerun() {
    let mut app = App::new(&profile(), colour());
    let mut v = view();
    v.images = vec![ImageState {
        captured: vec!['a', 'b', 'c'],
        edits: 1,
        ..plan(1, 1, 1)
    }];
    v.next = Some((1, None));
    app.update(Msg::Store(StoreEvent::Opened(v)));
    let edited = vec![Segment::new(Point::new(1.0, 1.0), Point::new(50.0, 1.0))];
    let cmds = app.update(Msg::Store(StoreEvent::Loaded(Box::new(LoadedImage {
        k: 1,
        images: vec![('a', square(150)), ('b', square(200)), ('c', square(90))],
        lines: Some(edited.clone()),
        ..Default::default()
    }))));
    run(&mut app, cmds);
    assert_eq!(app.session.work.phase, Phase::Review);
    assert_eq!(
        app.tracker.current.as_ref().unwrap().lines().unwrap(),
        &edited[..]
    );
}

#[test]
fn the_worker_engine_reruns_from_the_changed_stage() {
    use vss::tui::event::PipelineResult;
    use vss::tui::keymap::PipelineAction;
    use vss::tui::workers::pipeline::Engine;
    let mut app = reviewed();
    go(&mut app, ScreenId::Pipeline);
    let i = vss::llv::params::PARAMS
        .iter()
        .position(|p| p.key == "connect.min_line_length")
        .unwrap();
    for _ in 0..i {
        super::tui_screens::pipe(&mut app, PipelineAction::ParamNext);
    }
    let before = lines_shown(&app);
    let mut engine = Engine::default();
    for _ in 0..3 {
        for c in super::tui_screens::pipe(&mut app, PipelineAction::Inc10) {
            if let Cmd::Pipeline(req) = c {
                let outcome = engine.process(&req);
                app.update(Msg::Pipeline(PipelineResult {
                    generation: req.generation,
                    image_key: req.image_key,
                    params: req.params.clone(),
                    outcome,
                }));
            }
        }
    }
    assert_eq!(app.tracker.params.connect.min_line_length, 42.0);
    let after = lines_shown(&app);
    assert!(
        after < before,
        "longer minimum keeps fewer lines: {before} -> {after}"
    );
}

fn entry(name: &str, damaged: Option<&str>) -> SessionEntry {
    SessionEntry {
        name: name.into(),
        dir: PathBuf::from(format!("/tmp/sessions/{name}")),
        summary: "0/4 done".into(),
        damaged: damaged.map(str::to_string),
    }
}

/// `o` with a session open shows the list and asks before switching; a
/// damaged session is listed with why and cannot be opened by mistake
/// (Enter reads the list again, and it opens only if it now reads).
#[test]
fn the_session_picker_confirms_and_shows_damaged_sessions() {
    let mut app = reviewed();
    app.update(Msg::Store(StoreEvent::Sessions(vec![
        entry("bad", Some("bad.toml:11: planned_images: invalid type")),
        entry("cube", None),
        entry("other", None),
    ])));
    survey(&mut app, SurveyAction::OpenPicker);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("bad  DAMAGED: bad.toml"), "{s}");
    assert_eq!(app.screens.survey.selected, 1, "the open session is chosen");
    survey(&mut app, SurveyAction::Down);
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(cmds.is_empty(), "asks first: {cmds:?}");
    let (s, _) = draw(&app, 80, 24);
    assert!(
        s.contains("Leave session cube and open session other?"),
        "{s}"
    );
    let cmds = yes(&mut app);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Open(d)) if d.ends_with("other")))
    );
    survey(&mut app, SurveyAction::OpenPicker);
    survey(&mut app, SurveyAction::Up);
    survey(&mut app, SurveyAction::Up);
    // The listing is read again first (the folder may have been mended
    // since): still damaged, it is not opened.
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(
        matches!(cmds.as_slice(), [Cmd::Store(StoreCmd::List)]),
        "{cmds:?}"
    );
    let cmds = app.update(Msg::Store(StoreEvent::Sessions(vec![
        entry("bad", Some("bad.toml:11: planned_images: invalid type")),
        entry("cube", None),
        entry("other", None),
    ])));
    assert!(cmds.is_empty(), "not opened: {cmds:?}");
    let (s, _) = draw(&app, 80, 24);
    assert!(
        flat(&s.replace('│', " ")).contains("vss session check"),
        "the full error and the command:\n{s}"
    );
}

#[test]
fn the_end_of_the_survey_is_announced_and_more_is_a_choice() {
    let mut v = view();
    v.images = vec![plan(1, 1, 1)];
    let mut app = reviewed_in(v);
    survey(&mut app, SurveyAction::Accept);
    assert_eq!(app.session.work.phase, Phase::Complete);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("survey complete"), "{s}");
    assert!(s.contains("5 writes the report"), "{s}");
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(cmds.is_empty());
    assert!(matches!(app.chrome.modal, Some(Modal::Confirm { .. })));
    yes(&mut app);
    assert_eq!(
        (app.session.work.k, app.session.work.phase),
        (2, Phase::Setup)
    );
}

#[test]
fn quitting_during_a_capture_asks() {
    let mut app = App::new(&profile(), colour());
    app.update(Msg::Store(StoreEvent::Opened(view())));
    survey(&mut app, SurveyAction::Enter);
    assert_eq!(app.session.work.phase, Phase::Capturing);
    press(&mut app, Scope::Global, Action::Global(GlobalAction::Quit));
    assert!(!app.quit(), "asks first");
    press(&mut app, Scope::Confirm, Action::Modal(ModalAction::No));
    assert!(!app.quit());
    press(&mut app, Scope::Global, Action::Global(GlobalAction::Quit));
    let cmds = yes(&mut app);
    assert!(app.quit());
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Device(DeviceCmd::Cancel)))
    );
}

#[test]
fn a_live_lock_says_tmux_attach_and_offers_a_take_over() {
    let mut app = App::new(&profile(), colour());
    app.update(Msg::Store(StoreEvent::Locked {
        dir: PathBuf::from("/tmp/sessions/cube"),
        holder: "process 4242 of user op on host cell".into(),
    }));
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("tmux attach"), "{s}");
    let cmds = yes(&mut app);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::TakeOver(_))))
    );
}

fn ctrl(app: &mut App, c: char) {
    app.update(Msg::Key(KeyEvent::new(
        KeyCode::Char(c),
        KeyModifiers::CONTROL,
    )));
}

/// The text field: the rule before typing, readline keys, the limit while
/// typing, the text kept after an error, the digit warning.
#[test]
fn the_session_name_field_edits_like_a_shell() {
    let mut app = App::new(&profile(), colour());
    survey(&mut app, SurveyAction::NewSession);
    let (s, _) = draw(&app, 80, 24);
    assert!(s.contains("starting with a letter"), "the rule first:\n{s}");
    for c in "cube".chars() {
        key(&mut app, c);
    }
    // A space can never be in a name: refused as it is typed.
    key(&mut app, ' ');
    for c in "one".chars() {
        key(&mut app, c);
    }
    ctrl(&mut app, 'w');
    for c in "two".chars() {
        key(&mut app, c);
    }
    code(&mut app, KeyCode::Home);
    key(&mut app, 'x');
    code(&mut app, KeyCode::End);
    code(&mut app, KeyCode::Backspace);
    let Some(Modal::Prompt(p)) = &app.chrome.modal else {
        panic!("the field is open")
    };
    assert_eq!(p.text, "xtw");
    ctrl(&mut app, 'u');
    for c in "-tw".chars() {
        key(&mut app, c);
    }
    let cmds = code(&mut app, KeyCode::Enter);
    assert!(cmds.is_empty(), "a name starting with - is refused");
    let Some(Modal::Prompt(p)) = &app.chrome.modal else {
        panic!("the field stays open after an error")
    };
    assert_eq!(p.text, "-tw", "with the typed text");
    assert!(
        p.error
            .as_deref()
            .is_some_and(|e| e.contains("starts with '-'")),
        "{:?}",
        p.error
    );
    ctrl(&mut app, 'u');
    for _ in 0..40 {
        key(&mut app, 'q');
    }
    let Some(Modal::Prompt(p)) = &app.chrome.modal else {
        panic!()
    };
    assert_eq!(p.text.chars().count(), 32, "the limit holds while typing");
    ctrl(&mut app, 'u');
    key(&mut app, 'q');
    key(&mut app, '1');
    // A name ending in a digit is asked about; no goes back to the field.
    let cmds = code(&mut app, KeyCode::Enter);
    assert!(cmds.is_empty(), "not created before the question");
    let (s, _) = draw(&app, 80, 24);
    assert!(flat(&s).contains("q11a.img"), "the digit warning:\n{s}");
    assert!(flat(&s).contains("Create q1 anyway?"), "{s}");
    let cmds = key(&mut app, 'n');
    assert!(cmds.is_empty());
    let Some(Modal::Prompt(p)) = &app.chrome.modal else {
        panic!("back to the field")
    };
    assert_eq!(p.text, "q1", "with the name to change");
    code(&mut app, KeyCode::Enter);
    let cmds = key(&mut app, 'y');
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Create(n)) if n == "q1")),
        "yes creates it: {cmds:?}"
    );
}

/// Captures and runs image `k` (in Setup) through messages, as the device
/// and pipeline workers would answer.
fn capture_k(app: &mut App, k: u32) {
    let mut cmds = survey(app, SurveyAction::Enter);
    for (i, letter) in ['a', 'b', 'c'].into_iter().enumerate() {
        assert!(
            cmds.iter().any(|c| matches!(c, Cmd::Device(DeviceCmd::Capture {
                purpose: FramePurpose::Survey { k: kk, letter: l }, .. }) if *l == letter && *kk == k)),
            "capture of image {k} {letter} asked: {cmds:?}"
        );
        cmds = app.update(Msg::Device(vss::tui::event::DeviceEvent::Frame {
            purpose: FramePurpose::Survey { k, letter },
            camera: 1,
            image: square(120 + 40 * i as u8),
            settings: Default::default(),
        }));
    }
    run(app, cmds);
    assert_eq!(app.session.work.phase, Phase::Review);
    assert_eq!(app.session.work.k, k);
}

/// Accepting the last image while the store still saves the one before
/// (its outputs not yet in the session's view) ended the survey one image
/// back: the view said image 1 had no outputs, so the survey went to it.
/// And an acceptance the store then refuses stays said in the next-step
/// box, whatever messages come after it.
#[test]
fn accepting_the_last_image_while_the_one_before_saves_ends_the_survey() {
    let mut v = view();
    v.images = vec![plan(1, 1, 1), plan(2, 1, 1)];
    let mut app = reviewed_in(v.clone());
    survey(&mut app, SurveyAction::Accept);
    assert_eq!(
        (app.session.work.k, app.session.work.phase),
        (2, Phase::Setup)
    );
    // Image 1's save is still under way: the view has no outputs for it.
    capture_k(&mut app, 2);
    survey(&mut app, SurveyAction::Accept);
    assert_eq!(
        app.session.work.phase,
        Phase::Complete,
        "the survey ends, not back at image 1 (at image {})",
        app.session.work.k
    );
    // Image 1's save fails after all; later messages follow.
    app.update(Msg::Store(StoreEvent::OutputsNotSaved {
        k: 1,
        error: vss::tui::event::StoreError::NoSession,
    }));
    app.update(Msg::Store(StoreEvent::OutputsSaved(2)));
    app.update(Msg::Store(StoreEvent::Note("a later note".into())));
    let (s, _) = draw(&app, 80, 24);
    assert!(
        flat(&s.replace('│', " ")).contains("Image 1 NOT accepted"),
        "the refusal stays in sight:\n{s}"
    );
    // Once image 1 is saved, it is no longer said.
    app.update(Msg::Store(StoreEvent::OutputsSaved(1)));
    let (s, _) = draw(&app, 80, 24);
    assert!(!s.contains("NOT accepted"), "{s}");
}

/// What opening a session found (a damaged frame's warning) is the answer
/// to the Enter that opened it: a device note that arrives just after
/// (the cell connecting late, under load) goes to the log and does not
/// push the warning off the message line. Before, the warning was gone at
/// once and the line said "grabber … connected".
#[test]
fn a_session_s_warning_is_not_pushed_off_the_line_by_a_device_note() {
    let mut app = App::new(&profile(), colour());
    app.start();
    app.update(Msg::Store(StoreEvent::Sessions(vec![entry("cube", None)])));
    let cmds = survey(&mut app, SurveyAction::Enter);
    assert!(
        cmds.iter()
            .any(|c| matches!(c, Cmd::Store(StoreCmd::Open(d)) if d.ends_with("cube"))),
        "{cmds:?}"
    );
    app.update(Msg::Store(StoreEvent::Opened(view())));
    app.update(Msg::Store(StoreEvent::Warning(
        "cube1a.img: too large for this session".into(),
    )));
    app.update(Msg::Store(StoreEvent::OpeningDone));
    grabber_connected(&mut app);
    let (s, _) = draw(&app, 80, 24);
    let bottom = flat(&s.lines().rev().take(5).collect::<Vec<_>>().join(" "));
    assert!(bottom.contains("cube1a.img: too large"), "{s}");
    assert!(bottom.contains("(+1 newer in the log)"), "{s}");
}
