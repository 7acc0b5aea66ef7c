//! The console on the built-in simulated cell as a new operator meets it:
//! the real binary started with no profile in an empty folder, with an
//! empty home and the XDG folders inside it, so nothing beside the binary
//! can stand in for what is compiled in. Lens correction must run there
//! (its time on the Pipeline screen, kept by a re-run from the edges; a
//! corrected view that is not the grey one), the Calibrate screen must compute with the built-in camera's
//! scale, and accepting writes the camera's `.cdf` where the profile names
//! it, keeping the built-in description's other entries.

use vss::formats::cdf::{Status, read_cdf};
use vss::tui::keymap::{
    Action, CalibrateAction as CA, GlobalAction, PipelineAction, Scope, ScreenId, SurveyAction,
};

use super::tui_harness::{Console, PIPELINE, SURVEY, flat, panel_value};

/// The console with the built-in profile in an empty folder, `HOME` and
/// the XDG folders in another empty one (kept alive by the caller).
fn start_bare(cols: u16, rows: u16, home: &std::path::Path) -> Console {
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    let h = |sub: &str| home.join(sub).to_string_lossy().into_owned();
    let env = [
        ("HOME", home.to_string_lossy().into_owned()),
        ("XDG_CONFIG_HOME", h(".config")),
        ("XDG_DATA_HOME", h(".local/share")),
        ("XDG_CACHE_HOME", h(".cache")),
        ("XDG_STATE_HOME", h(".local/state")),
    ];
    let env: Vec<(&str, &str)> = env.iter().map(|(k, v)| (*k, v.as_str())).collect();
    Console::start_in(dir, cols, rows, &env, &[])
}

/// The milliseconds of the lens stage on the Pipeline screen.
fn lens_ms(screen: &str) -> Option<f64> {
    let at = screen.find("ms lens ")? + "ms lens ".len();
    screen[at..].split_whitespace().next()?.parse().ok()
}

/// The cells of the preview box (inside its border, above the cursor
/// row) with their colours: what the operator sees of the picture.
fn picture(c: &Console, cols: u16, rows: u16) -> Vec<String> {
    c.with_screen(|s| {
        let mut out = Vec::new();
        for r in 3..rows.saturating_sub(5) {
            for col in 34..cols.saturating_sub(1) {
                if let Some(cell) = s.cell(r, col) {
                    out.push(format!(
                        "{}{:?}{:?}",
                        cell.contents(),
                        cell.fgcolor(),
                        cell.bgcolor()
                    ));
                }
            }
        }
        out
    })
}

#[test]
fn builtin_cell_from_an_empty_folder_corrects_lenses_and_calibrates() {
    let home = tempfile::tempdir().unwrap();
    let (cols, rows) = (80, 24);
    let mut c = start_bare(cols, rows, home.path());
    c.wait_text("simulated cell", 15);
    c.create_session("cube");
    c.capture_current(1);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
    );
    let s = c.wait("the lens time", 30, |s| lens_ms(s).is_some());
    let ms = lens_ms(&s).unwrap();
    assert!(
        ms > 0.0,
        "lens correction ran on the built-in cell (lens {ms} ms):\n{s}"
    );
    assert!(!s.contains("lens OFF"), "{s}");
    // A change to the edges re-runs from the edges: the lens stage keeps
    // the time of the run that made its output (it showed 0.0, as if lens
    // correction were off).
    c.choose_param("edges.noise_sigmas");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Inc));
    let s = c.wait("edges.noise_sigmas = 2.75 run", 30, |s| {
        panel_value(s, "edges.noise_sigmas").as_deref() == Some("2.75") && !s.contains("running")
    });
    assert_eq!(lens_ms(&s), Some(ms), "the lens time after a re-run:\n{s}");
    // The views in turn from the overlay: the grey one, then the corrected.
    c.press(PIPELINE, Action::Pipeline(PipelineAction::ViewNext));
    c.wait_text("· grey ─", 10);
    let grey = picture(&c, cols, rows);
    c.press(PIPELINE, Action::Pipeline(PipelineAction::ViewNext));
    let s = c.wait_text("· corrected ─", 10);
    assert!(!s.contains("not corrected"), "{s}");
    let corrected = picture(&c, cols, rows);
    assert_eq!(grey.len(), corrected.len());
    let differ = grey.iter().zip(&corrected).filter(|(a, b)| a != b).count();
    assert!(
        differ > 0,
        "the corrected view is the grey one cell for cell:\n{s}"
    );

    // Calibrate with the built-in camera 1's stated scale S.
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Calibrate)),
    );
    c.wait_text("views kept: 0", 10);
    let cb = Scope::Screen(ScreenId::Calibrate);
    c.press(cb, Action::Calibrate(CA::Plate));
    c.wait_text("plate shown (p)", 10);
    for n in 1..=6 {
        c.press(cb, Action::Calibrate(CA::Grab));
        c.wait("a grid in the new frame", 30, |s| {
            s.contains("corners found")
        });
        c.press(cb, Action::Calibrate(CA::Keep));
        c.wait_text(&format!("views kept: {n}"), 10);
    }
    // The centre stated at the image's middle, as for the cell's cameras.
    c.press(cb, Action::Calibrate(CA::Centre));
    c.wait_text("stated, image middle", 10);
    c.press(cb, Action::Calibrate(CA::Solve));
    let s = c.wait("the calibration or a refusal", 60, |s| {
        s.contains("RMS") || s.contains("no scale S")
    });
    assert!(!s.contains("no scale S"), "{s}");
    c.press(cb, Action::Calibrate(CA::Accept));
    c.wait_text("write S, C, f, D", 10);
    c.yes();
    let cdf = c.dir.path().join("sim/cam1.cdf");
    c.wait("the .cdf written", 15, |_| cdf.is_file());
    c.wait_text("wrote", 10);
    let got = read_cdf(&cdf).unwrap();
    assert_eq!(got.get("D").unwrap().status, Status::Calibrated);
    assert!(
        got.get("T").is_some(),
        "the built-in description's T is kept: {got:?}"
    );
    c.send("q");
    c.wait_exit(15);
}

/// Lens correction on, and camera 1's `.cdf` named but not there: the
/// Pipeline screen says lens correction is off for it and why, where the
/// lens time shows (before, the time read 0.0 and nothing said why).
#[test]
fn a_camera_without_its_cdf_is_said_on_the_pipeline_screen() {
    let mut c = Console::start_with(
        &super::tui_harness::five_lightings(true),
        80,
        24,
        &[],
        |_| {},
    );
    c.create_session("cube");
    c.capture_current(1);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
    );
    let s = c.wait_words("lens OFF — camera 1:", 30);
    assert!(super::tui_harness::flat(&s).contains("cam1.cdf"), "{s}");
    c.send("q");
    c.wait_exit(15);
}

/// A session surveyed with a profile of three cameras, opened with one of
/// two: image 3's camera has no description in this profile, but the
/// image has its own on record (`cube3.cdf`), which it runs with, as `vss
/// session redo` runs it: lens correction is not off for it. Before, the
/// Pipeline screen said "lens OFF — camera 3: not one of this profile's 2
/// cameras" while redo corrected the image with its record.
#[test]
fn an_image_of_a_camera_past_the_profile_s_runs_with_its_recorded_description() {
    let three = super::tui_harness::five_lightings(true)
        .replace("cameras = 2", "cameras = 3")
        .replace(
            r#"cdf = ["cam1.cdf", "cam2.cdf"]"#,
            r#"cdf = ["cam1.cdf", "cam2.cdf", "cam3.cdf"]"#,
        );
    let mut c = Console::start_with(&three, 80, 24, &[], |d| {
        super::tui_harness::write_cdfs(d, 3);
    });
    // Three images, one a camera (the last has no next image to wait for).
    c.survey(2);
    c.capture_current(3);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("image 3 accepted", 20);
    let mut c = c.restart_after(|d| {
        std::fs::write(
            d.join("cell.toml"),
            super::tui_harness::five_lightings(true),
        )
        .unwrap();
    });
    c.open_cube();
    c.press(SURVEY, Action::Survey(SurveyAction::Up));
    c.press(SURVEY, Action::Survey(SurveyAction::Enter));
    c.wait_text("image 3a", 20);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
    );
    let s = c.wait("the Pipeline screen on image 3", 30, |s| {
        s.contains("parameters") && s.contains("image 3")
    });
    assert!(!s.contains("lens OFF"), "{s}");
    c.send("q");
    c.wait_exit(15);
}

/// `vss llv --camera 1` in an empty folder on the built-in profile takes
/// camera 1's description from the same owner as the console (the
/// compiled-in one) and lens-corrects: the `.imc` is written and differs
/// from the input.
#[test]
fn llv_camera_uses_the_builtin_description_from_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    let home = tempfile::tempdir().unwrap();
    let img = super::support::llv_scene::scene(512, 512, 1.0, 5);
    let input = dir.path().join("view.img");
    vss::formats::img::write_img(&input, &vss::formats::img::ImgFile::new(img.clone())).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
        .current_dir(dir.path())
        .env("HOME", home.path())
        .env("XDG_CONFIG_HOME", home.path().join(".config"))
        .args(["llv", "--camera", "1", "view.img"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let imc = vss::formats::img::read_img(&dir.path().join("view.imc")).unwrap();
    assert_ne!(imc.image, img, "the .imc is lens-corrected");
}

/// Issue 34, N12: the console names the profile file in use where the
/// operator starts (the Survey screen's step box, the first message) and
/// in the help window, with the plate Calibrate uses: `built-in` for the
/// compiled-in profile, the file's absolute path otherwise.
#[test]
fn the_profile_file_in_use_is_named_on_screen() {
    let home = tempfile::tempdir().unwrap();
    let mut c = start_bare(80, 24, home.path());
    let s = c.wait_text("profile: built-in", 15);
    assert!(s.contains("choose a session"), "{s}");
    c.press(Scope::Global, Action::Global(GlobalAction::Help));
    let s = c.wait_text("Files in use", 10);
    assert!(flat(&s).contains("profile built-in"), "{s}");
    assert!(flat(&s).contains("plate squares (built in)"), "{s}");
    c.send("q");
    c.send("q");
    c.wait_exit(10);

    let mut c = Console::start(80, 24, &[]);
    let file = c.dir.path().join("cell.toml");
    let s = c.wait_text(&format!("profile: {}", file.display()), 15);
    assert!(!s.contains("built-in"), "{s}");
    c.create_session("cube");
    // Still said while the first image is set up.
    c.wait_text(&format!("profile: {}", file.display()), 10);
    c.send("q");
    c.wait_exit(10);
}
