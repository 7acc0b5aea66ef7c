//! Tuning through the real console (a pty, 80 × 24): every LLV parameter
//! is changed and changed back on a captured image of five lightings (an
//! ambient one among them), with lens correction on and off. After each
//! change the screen shows the new value with outputs made from it (no
//! "stale", no pipeline error), and the save key writes outputs whose
//! recorded parameters and line count are those on screen.
//!
//! With lens correction on, a new `edges.half_width` or `edges.noise_factor`
//! once failed on every other key press ("image sizes differ: (512, 512)
//! and (0, 0)": the corrected ambient image was missing from the re-run)
//! while the panel showed the new value, and the save key wrote the old
//! value's outputs.
//!
//! A tuned value survives the console: a capture cut short and resumed in
//! a new console goes on with the values the survey's images were made
//! with, not the profile's.

use std::time::{Duration, Instant};

use vss::llv::params::{Kind, PARAMS};
use vss::session::Session;
use vss::tui::keymap::{Action, PipelineAction, SurveyAction};

use super::tui_harness::{
    Console, PIPELINE, SURVEY, five_lightings, line_count, panel_value, write_cdfs,
};

/// The parameter values and line count of image 1's saved outputs.
fn saved(c: &Console) -> Option<(vss::llv::Params, usize)> {
    let s = Session::inspect(&c.session()).ok()?;
    let o = s.manifest().image(1)?.outputs.clone()?;
    Some((o.params, o.counts.lines as usize))
}

/// Waits for the saved outputs to carry `key = value`.
fn wait_saved(c: &Console, key: &str, value: f64) -> (vss::llv::Params, usize) {
    let end = Instant::now() + Duration::from_secs(20);
    loop {
        if let Some((p, n)) = saved(c)
            && p.get(key) == Some(value)
        {
            return (p, n);
        }
        assert!(
            Instant::now() < end,
            "outputs with {key} = {value} never saved; screen:\n{}",
            c.screen()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn every_parameter(lens: bool) {
    let mut c = Console::start_with(&five_lightings(lens), 80, 24, &[], |d| write_cdfs(d, 2));
    c.create_session("cube");
    c.capture_current(1);
    c.send("3");
    c.wait_text("parameters", 10);
    let mut values = vss::llv::Params::default();
    values.lens.enabled = lens;
    for (i, sp) in PARAMS.iter().enumerate() {
        if i > 0 {
            c.press(PIPELINE, Action::Pipeline(PipelineAction::ParamNext));
        }
        // Keys are taken in order: the change below goes to this parameter.
        let now = values.get(sp.key).unwrap();
        let up = match sp.kind {
            Kind::Bool => now == 0.0,
            _ => now + sp.step <= sp.max,
        };
        let changed = if up { now + sp.step } else { now - sp.step };
        let changed = if sp.kind == Kind::Bool {
            changed.clamp(0.0, 1.0)
        } else {
            changed
        };
        for (target, action) in [
            (
                changed,
                if up {
                    PipelineAction::Inc
                } else {
                    PipelineAction::Dec
                },
            ),
            (
                now,
                if up {
                    PipelineAction::Dec
                } else {
                    PipelineAction::Inc
                },
            ),
        ] {
            c.press(PIPELINE, Action::Pipeline(action));
            let s = c.wait(&format!("{} = {target} run", sp.key), 20, |s| {
                panel_value(s, sp.key).and_then(|v| v.parse::<f64>().ok()) == Some(target)
                    && !s.contains("running")
            });
            assert!(
                !s.contains("stale") && !s.contains("pipeline:"),
                "{} = {target} (lens {lens}): the outputs on screen are not the panel's:\n{s}",
                sp.key
            );
            let shown = line_count(&s).expect("a line count on the Pipeline screen");
            c.press(PIPELINE, Action::Pipeline(PipelineAction::Save));
            // Once saved, image 1 is accepted: saving over it asks.
            let q = c.wait("saved, or the question", 10, |s| {
                s.contains("Replace its saved outputs")
                    || saved(&c).is_some_and(|(p, _)| p.get(sp.key) == Some(target))
            });
            if q.contains("Replace its saved outputs") {
                c.yes();
            }
            let (p, n) = wait_saved(&c, sp.key, target);
            values.set(sp.key, target).unwrap();
            assert_eq!(
                p, values,
                "saved with the panel's values ({} = {target})",
                sp.key
            );
            assert_eq!(
                n,
                shown,
                "saved the line count on screen ({} = {target}); the screen read:\n{s}\nnow:\n{}",
                sp.key,
                c.screen()
            );
        }
    }
    if lens {
        let m = Session::inspect(&c.session()).unwrap();
        let files = &m
            .manifest()
            .image(1)
            .unwrap()
            .outputs
            .as_ref()
            .unwrap()
            .files;
        assert!(
            files.iter().any(|f| f.file == "cube1a.imc"),
            "lens-corrected images among the outputs: {files:?}"
        );
    }
    let s = c.screen();
    assert!(!s.contains("pipeline:"), "{s}");
    c.send("q");
}

#[test]
fn every_parameter_with_lens_correction() {
    every_parameter(true);
}

#[test]
fn every_parameter_without_lens_correction() {
    every_parameter(false);
}

/// A value typed after `Enter` replaces the parameter's value: `Enter`, `12`,
/// `Enter` on `edges.per_region` (16) gives 12. The field offered the old
/// value with the cursor after it, so the keys made 1612, a value in range
/// that was taken without a word.
#[test]
fn a_typed_value_replaces_the_old_one() {
    let mut c = Console::start_with(&five_lightings(false), 80, 24, &[], |_| {});
    c.create_session("cube");
    c.capture_current(1);
    c.send("3");
    c.wait_text("parameters", 10);
    c.choose_param("edges.per_region");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Type));
    c.wait_text("typing replaces it", 10);
    c.send("12\r");
    c.wait("edges.per_region = 12", 20, |s| {
        panel_value(s, "edges.per_region").as_deref() == Some("12") && !s.contains("running")
    });
    // ← keeps the offered value to edit: `Enter`, ←, `5`, `Enter` gives 152.
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Type));
    c.wait_text("typing replaces it", 10);
    c.send("\x1b[D5\r");
    c.wait("edges.per_region = 152", 20, |s| {
        panel_value(s, "edges.per_region").as_deref() == Some("152")
    });
    c.send("q");
}

/// The operator tunes a parameter, captures and accepts image 1; image 2's
/// capture is cut short (here only lighting a is on disk, as `vss grab`
/// leaves it) and the console is started again, as after a dropped SSH
/// connection. Resuming at image 2, the panel holds the tuned value image 1
/// was made with, and says so: before, it went back to the profile's value,
/// and the rest of the survey was made with other values than its start
/// without a word. The Pipeline screen says why nothing runs yet.
#[test]
fn a_tuned_value_survives_a_capture_cut_short() {
    let mut c = Console::start_with(&five_lightings(false), 80, 24, &[], |_| {});
    c.create_session("cube");
    c.send("3");
    c.wait_text("parameters", 10);
    c.choose_param("edges.noise_sigmas");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Inc));
    c.wait("edges.noise_sigmas = 2.75", 20, |s| {
        panel_value(s, "edges.noise_sigmas").as_deref() == Some("2.75")
    });
    c.send("1");
    c.capture_current(1);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("Image 2: camera", 20);
    let c = c.restart_after(|dir| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
            .current_dir(dir)
            .env("XDG_STATE_HOME", dir.join("state"))
            .args(["--profile", "cell.toml", "grab", "--camera", "2"])
            .args([
                "--lighting",
                "a",
                "--image",
                "2",
                "--session",
                "sessions/cube",
            ])
            .stdin(std::process::Stdio::null())
            .output()
            .unwrap();
        assert!(out.status.success(), "{out:?}");
    });
    let mut c = c;
    c.open_cube();
    c.wait_text("Enter captures lightings bcde", 20);
    let s = c.wait("the panel's values", 20, |s| {
        s.contains("not the profile's")
    });
    assert!(
        s.contains("edges.noise_sigmas 2.75"),
        "the tuned value, in the next-step box:\n{s}"
    );
    c.send("3");
    let s = c.wait_text("parameters", 10);
    assert_eq!(
        panel_value(&s, "edges.noise_sigmas").as_deref(),
        Some("2.75"),
        "{s}"
    );
    // Nothing runs on four missing lightings, and the view says so (it
    // said "running…" for ever).
    assert!(s.contains("not run: lightings b, c, d and e"), "{s}");
    assert!(!s.contains("running…"), "{s}");
    c.send("q");
    c.wait_exit(15);
}
