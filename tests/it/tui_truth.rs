//! One truth with the session code: the console's own engine and store,
//! driven through the App by messages as the real console drives them,
//! write the same `.ldr` for one captured image as `vss session redo`, and
//! its export (`e`) writes the same report pages as `vss report`.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::mpsc::{Receiver, channel};

use assert_cmd::Command;
use vss::llv::GreyImage;
use vss::profile::Profile;
use vss::synth::{self, RenderOptions};
use vss::tui::app::{App, Phase};
use vss::tui::event::{Cmd, DeviceCmd, DeviceEvent, Msg, PipelineResult, StoreCmd};
use vss::tui::keymap::{Action, Scope, ScreenId, SurveyAction};
use vss::tui::mode::Look;
use vss::tui::widgets::preview::PreviewMode;
use vss::tui::workers::pipeline::Engine;
use vss::tui::workers::store::Store;

use super::tui_harness::{five_lightings, write_cdfs};
use super::tui_screens::press;

/// The simulated cell's five lightings of camera 1 at 128 × 128.
fn frames() -> Vec<GreyImage> {
    let scene = synth::cell_scene();
    let cams = synth::cell_cameras(128, 128);
    let o = RenderOptions {
        ambient: 0.15,
        blur_sigma: 0.7,
        noise_sigma: 2.0,
        seed: 5,
        distort: true,
    };
    let mut out: Vec<GreyImage> = synth::cell_lights()
        .iter()
        .map(|l| synth::render(&scene, &cams[0], std::slice::from_ref(l), &o))
        .collect();
    out.push(synth::render(&scene, &cams[0], &[], &o));
    out
}

/// Runs commands as the console's workers would — the store and the
/// pipeline engine for real, the grabber answering from `frames` — until
/// nothing more is asked.
fn drive(
    app: &mut App,
    store: &mut Store,
    rx: &Receiver<Msg>,
    engine: &mut Engine,
    cmds: Vec<Cmd>,
) {
    let images = frames();
    let mut queue: VecDeque<Cmd> = cmds.into();
    loop {
        while let Some(c) = queue.pop_front() {
            let more = match c {
                Cmd::Store(s) => {
                    store.handle(s);
                    Vec::new()
                }
                Cmd::Pipeline(req) => {
                    let outcome = engine.process(&req);
                    app.update(Msg::Pipeline(PipelineResult {
                        generation: req.generation,
                        image_key: req.image_key,
                        params: req.params.clone(),
                        outcome,
                    }))
                }
                Cmd::Device(DeviceCmd::Capture {
                    purpose,
                    camera,
                    lighting: Some(l),
                }) => app.update(Msg::Device(DeviceEvent::Frame {
                    purpose,
                    camera,
                    image: images[(l as u8 - b'a') as usize].clone(),
                    settings: Default::default(),
                })),
                Cmd::Device(_) => Vec::new(),
            };
            queue.extend(more);
        }
        let mut any = false;
        while let Ok(m) = rx.try_recv() {
            any = true;
            queue.extend(app.update(m));
        }
        if !any && queue.is_empty() {
            return;
        }
    }
}

fn survey_key(app: &mut App, a: SurveyAction) -> Vec<Cmd> {
    press(app, Scope::Screen(ScreenId::Survey), Action::Survey(a))
}

/// A session `cube` with image 1 captured, run and accepted by the
/// console's own App, engine and store; returns the session folder.
fn console_survey(dir: &Path) -> std::path::PathBuf {
    console_survey_then(dir, |_| ()).0
}

/// [`console_survey`], with `before_export` done to the session folder
/// just before the console's export; also returns the report's message.
fn console_survey_then(
    dir: &Path,
    before_export: impl FnOnce(&Path),
) -> (std::path::PathBuf, String) {
    let text = five_lightings(true).replace(
        "dir = \"sessions\"",
        &format!("dir = {:?}", dir.join("sessions")),
    );
    std::fs::write(dir.join("cell.toml"), text).unwrap();
    write_cdfs(dir, 2);
    let profile = Profile::load(dir.join("cell.toml").to_str().unwrap()).unwrap();
    let (tx, rx) = channel();
    let mut store = Store::new(profile.clone(), tx);
    let look = Look {
        mode: PreviewMode::Ascii,
        colour: false,
        c256: false,
    };
    let mut app = App::new(&profile, look);
    let mut engine = Engine::default();
    store.cameras();
    drive(
        &mut app,
        &mut store,
        &rx,
        &mut engine,
        vec![Cmd::Store(StoreCmd::Create("cube".into()))],
    );
    assert_eq!(app.session.work.phase, Phase::Setup);
    let cmds = survey_key(&mut app, SurveyAction::Enter);
    drive(&mut app, &mut store, &rx, &mut engine, cmds);
    assert_eq!(
        app.session.work.phase,
        Phase::Review,
        "{:?}",
        app.chrome.log.last()
    );
    let cmds = survey_key(&mut app, SurveyAction::Accept);
    drive(&mut app, &mut store, &rx, &mut engine, cmds);
    let outputs = app
        .tracker
        .current
        .as_ref()
        .and_then(|c| c.outputs.clone())
        .unwrap();
    assert!(!outputs.corrected.is_empty(), "lens correction ran");
    assert!(!outputs.lines.is_empty());
    let d = dir.join("sessions/cube");
    before_export(&d);
    // The console's export, before the store lets the session go.
    drive(
        &mut app,
        &mut store,
        &rx,
        &mut engine,
        vec![Cmd::Store(StoreCmd::Export)],
    );
    let said = app
        .chrome
        .log
        .entries()
        .find(|e| e.text.contains("report written"))
        .map(|e| e.text.clone());
    let said = said.unwrap_or_else(|| panic!("{:?}", app.chrome.log.last()));
    drop(store);
    (d, said)
}

#[test]
fn the_console_and_session_redo_write_the_same_ldr() {
    let tmp = tempfile::tempdir().unwrap();
    let d = console_survey(tmp.path());
    let console = std::fs::read(d.join("cube1.ldr")).unwrap();
    let hpo = std::fs::read(d.join("cube1.hpo")).unwrap();
    Command::cargo_bin("vss")
        .unwrap()
        .current_dir(tmp.path())
        .args(["--profile", "cell.toml", "session", "redo"])
        .arg(&d)
        .args(["--image", "1", "--from", "lens"])
        .assert()
        .success();
    let redo = std::fs::read(d.join("cube1.ldr")).unwrap();
    assert!(
        console == redo,
        "the .ldr differs:\nconsole:\n{}\nredo:\n{}",
        String::from_utf8_lossy(&console),
        String::from_utf8_lossy(&redo)
    );
    assert_eq!(
        hpo,
        std::fs::read(d.join("cube1.hpo")).unwrap(),
        "same edge points"
    );
}

#[test]
fn the_console_export_and_vss_report_write_the_same_pages() {
    let tmp = tempfile::tempdir().unwrap();
    let d = console_survey(tmp.path());
    let out = tmp.path().join("cli");
    std::fs::create_dir(&out).unwrap();
    Command::cargo_bin("vss")
        .unwrap()
        .current_dir(tmp.path())
        .args(["--profile", "cell.toml", "report"])
        .arg(&d)
        .arg("--ps")
        .arg(out.join("cube.ps"))
        .arg("--svg")
        .arg(out.join("cube.svg"))
        .assert()
        .success();
    for (console, cli) in [("cube.ps", "cube.ps"), ("cube1.svg", "cube1.svg")] {
        let a = std::fs::read_to_string(d.join(console)).unwrap();
        let b = std::fs::read_to_string(out.join(cli)).unwrap();
        assert!(a == b, "{console} differs from vss report's {cli}");
        assert!(a.len() > 1000, "{console} has pages");
    }
}

/// A `.ldr` damaged under the console: its export and `vss report` both
/// write the report and say the file and where it is damaged, from the
/// same writer; the command's exit status says the report is not whole.
#[test]
fn a_damaged_ldr_is_said_by_the_console_s_export_and_by_vss_report() {
    let tmp = tempfile::tempdir().unwrap();
    let (d, said) = console_survey_then(tmp.path(), |d| {
        std::fs::write(d.join("cube1.ldr"), "1 2 3\nnot a line file\n").unwrap();
    });
    assert!(d.join("cube.ps").is_file(), "the console wrote the report");
    let out = Command::cargo_bin("vss")
        .unwrap()
        .current_dir(tmp.path())
        .args(["--profile", "cell.toml", "report"])
        .arg(&d)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(tmp.path().join("cube.ps").is_file(), "vss report wrote it");
    let problem = stderr
        .lines()
        .find_map(|l| l.strip_prefix("vss: warning: cannot show cube1.ldr: "))
        .unwrap_or_else(|| panic!("no warning naming cube1.ldr:\n{stderr}"));
    assert!(
        problem.contains("cube1.ldr:2: "),
        "where it is damaged: {problem}"
    );
    assert!(
        said.contains("1 problem(s) marked in it") && said.contains(problem),
        "the console's message: {said}\nvss report: {problem}"
    );
}
