//! The console on Aravis's fake GigE Vision camera (the `genicam` grabber
//! kind), lights on the simulated relay board: a survey of four images
//! under five lightings by keys alone in a real terminal at 80 × 24, with
//! the same files as with the serial grabber; the device worker's live view
//! rate; and the worker saying the camera is lost when it is killed, then
//! reconnecting when it comes back.

use std::path::Path;
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use super::genicam::{FakeCamera, whole};
use super::tui_harness::{Console, SURVEY, exists};
use vss::profile::Profile;
use vss::rig::Cell;
use vss::tui::event::{DeviceCmd, DeviceEvent, FramePurpose, Msg};
use vss::tui::keymap::{Action, SurveyAction};
use vss::tui::workers::device;

/// One fake camera (its frames cut to 256 × 256), four lights and five
/// lightings (the last ambient), one camera in the survey.
const PROFILE: &str = concat!(
    "name = \"fake GigE Vision camera\"\n",
    crate::support::fixtures::five_lightings!(),
    r#"
[grabber]
kind = "genicam"
cameras = ["127.0.0.1"]
timeout_ms = 2000

[[grabber.camera]]
pixel_format = "Mono8"
exposure_us = 10000.0
gain_db = 0.0
roi = [0, 0, 256, 256]
packet_size = 16000

[relay]
settle_ms = 5

[survey]
dir = "sessions"
cameras = 1
"#
);

/// Captures image `k` on the Survey screen (going beyond the plan of one
/// image when asked) and accepts it.
fn survey_image(c: &mut Console, k: u32) {
    if k > 1 {
        // One camera: one image planned; the next ones are asked for.
        let s = c.wait(&format!("image {k} or the end of the plan"), 20, |s| {
            s.contains(&format!("Image {k}: camera"))
                || s.to_lowercase().contains("survey complete")
        });
        if !s.contains(&format!("Image {k}: camera")) {
            c.press(SURVEY, Action::Survey(SurveyAction::Enter));
            c.wait_text("beyond the plan", 10);
            c.yes();
        }
    }
    c.capture_current(k);
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_words(&format!("image {k} accepted"), 30);
}

#[test]
fn survey_of_four_images_under_five_lightings_at_80x24() {
    let _cam = FakeCamera::start("CONSOLE1", None);
    let mut c = Console::start_with(PROFILE, 80, 24, &[], |_| {});
    c.create_session("cube");
    for k in 1..=4u32 {
        survey_image(&mut c, k);
    }
    // Capture screen: the camera's identity, live view on, and a key
    // answered while it runs.
    c.send("2");
    c.wait("the camera on the Capture screen", 10, |s| {
        ["Aravis", "#CONSOLE1", "Mono8", "exp 10000", "gain 0.0 dB"]
            .iter()
            .all(|p| s.contains(p))
    });
    c.send("v");
    c.wait_text("live ON (v)", 10);
    let t = Instant::now();
    c.send(" ");
    c.wait_text("[x] lf", 5);
    eprintln!(
        "light switched during live view in {} ms",
        t.elapsed().as_millis()
    );
    // Exposure and gain, changed by keys during live view: the grabber
    // line and the log say the new values.
    c.send("]");
    c.wait("exposure × 1.25", 10, |s| {
        s.contains("exp 12500") && s.contains("exposure 12500 µs")
    });
    c.send("+");
    c.wait("gain + 1 dB", 10, |s| s.contains("gain 1.0 dB"));
    c.send("[");
    c.wait("exposure ÷ 1.25", 10, |s| s.contains("exp 10000"));
    c.send("v");
    c.wait_text("live off (v)", 10);
    c.send("q");
    c.wait_exit(15);

    let d = c.session();
    for k in 1..=4 {
        for l in "abcde".chars() {
            let name = format!("cube{k}{l}.img");
            assert!(exists(&d, &name), "{name} missing in {}", d.display());
            let img = vss::formats::img::read_img(&d.join(&name)).expect("reads");
            assert_eq!(img.image.size(), (256, 256), "{name}");
            whole(&img.image).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        for ext in ["hpo", "vpo", "lex", "ldr"] {
            let name = format!("cube{k}.{ext}");
            assert!(exists(&d, &name), "{name} missing in {}", d.display());
        }
    }
    assert!(exists(&d, "cube.ses"));
    let sess = vss::session::Session::inspect(&d).expect("a session");
    for k in 1..=4 {
        assert_eq!(sess.manifest().image(k).map(|r| r.camera), Some(1), "{k}");
    }
}

/// Issue 36: exposure and gain are saved in the manifest with each frame.
/// Image 1 is taken at the profile's 10 000 µs; the exposure is then
/// raised by key on the Capture screen (× 1.25, and the gain by 1 dB), and
/// every frame of image 2 records the new values.
#[test]
fn exposure_changed_on_the_capture_screen_is_recorded_with_later_frames() {
    let _cam = FakeCamera::start("EXPO1", None);
    let mut c = Console::start_with(PROFILE, 80, 24, &[], |_| {});
    c.create_session("cube");
    survey_image(&mut c, 1);
    c.send("2");
    c.wait("the camera on the Capture screen", 10, |s| {
        s.contains("exp 10000") && s.contains("gain 0.0 dB")
    });
    c.send("]");
    c.wait("exposure × 1.25", 10, |s| s.contains("exp 12500"));
    c.send("+");
    c.wait("gain + 1 dB", 10, |s| s.contains("gain 1.0 dB"));
    c.send("1");
    survey_image(&mut c, 2);
    c.send("q");
    c.wait_exit(15);

    let sess = vss::session::Session::inspect(&c.session()).expect("a session");
    for (k, settings) in [(1, (10_000.0, 0.0)), (2, (12_500.0, 1.0))] {
        let rec = sess.manifest().image(k).expect("image recorded");
        assert_eq!(rec.grey.len(), 5, "image {k}");
        for g in &rec.grey {
            assert_eq!(
                (g.exposure_us, g.gain_db),
                (Some(settings.0), Some(settings.1)),
                "{}",
                g.file
            );
        }
    }
}

/// The next device event matching `f`, within `secs`.
fn next(
    rx: &Receiver<Msg>,
    secs: u64,
    what: &str,
    f: impl Fn(&DeviceEvent) -> bool,
) -> DeviceEvent {
    let end = Instant::now() + Duration::from_secs(secs);
    loop {
        let left = end.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(Msg::Device(e)) if f(&e) => return e,
            Ok(_) => {}
            Err(_) => panic!("no {what} within {secs} s"),
        }
    }
}

#[test]
fn live_view_rate_and_reconnecting_after_the_camera_is_killed() {
    let mut cam = FakeCamera::start("LIVE1", None);
    let profile = Profile::from_toml(PROFILE, Path::new("t.toml")).expect("the profile loads");
    let (tx, rx) = channel();
    let h = device::spawn_with(Box::new(move || Cell::open(&profile)), tx).expect("worker");
    let connected = next(&rx, 15, "connection", |e| {
        matches!(e, DeviceEvent::Connected { .. })
    });
    let DeviceEvent::Connected { grabber, .. } = connected else {
        unreachable!()
    };
    // The Capture screen's grabber line: the camera's vendor, model,
    // serial, pixel format, exposure and gain.
    for part in [
        "camera 1 (127.0.0.1)",
        "Aravis",
        "#LIVE1",
        "Mono8",
        "10000 µs",
        "0.0 dB",
    ] {
        assert!(grabber.contains(part), "{part} in {grabber}");
    }

    // Live view: frames for three seconds.
    h.send(DeviceCmd::Live {
        on: true,
        camera: 1,
    });
    let live = |e: &DeviceEvent| {
        matches!(
            e,
            DeviceEvent::Frame {
                purpose: FramePurpose::Live,
                ..
            }
        )
    };
    next(&rx, 10, "a first live frame", live);
    let t = Instant::now();
    let mut frames = 0u32;
    while t.elapsed() < Duration::from_secs(3) {
        if let DeviceEvent::Frame { image, .. } = next(&rx, 5, "a live frame", live) {
            whole(&image).expect("a whole live frame");
            frames += 1;
        }
    }
    let fps = f64::from(frames) / t.elapsed().as_secs_f64();
    eprintln!(
        "live view: {frames} frames in {:.2} s = {fps:.1} frames/s",
        t.elapsed().as_secs_f64()
    );
    assert!(fps >= 10.0, "{fps:.1} live frames a second");

    // The camera goes: the worker says so and keeps trying.
    cam.kill();
    let lost = next(&rx, 20, "the camera lost", |e| {
        matches!(e, DeviceEvent::Lost { .. })
    });
    let DeviceEvent::Lost { error, .. } = lost else {
        unreachable!()
    };
    assert!(error.contains("camera 1 (127.0.0.1)"), "{error}");
    h.send(DeviceCmd::Live {
        on: false,
        camera: 1,
    });
    // It comes back: the worker reconnects on its own and captures again.
    cam.restart();
    next(&rx, 30, "reconnection", |e| {
        matches!(e, DeviceEvent::Connected { .. })
    });
    h.send(DeviceCmd::Capture {
        purpose: FramePurpose::Snapshot,
        camera: 1,
        lighting: Some('a'),
    });
    let f = next(&rx, 15, "a frame after reconnecting", |e| {
        matches!(
            e,
            DeviceEvent::Frame { .. } | DeviceEvent::CaptureFailed { .. }
        )
    });
    match f {
        DeviceEvent::Frame { image, .. } => whole(&image).expect("whole"),
        other => panic!("{other:?}"),
    }
    drop(h);
}
