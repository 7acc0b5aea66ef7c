//! Console benchmarks.
//!
//! Timed by divan: a parameter key press on a 512 × 512 survey image (five
//! lightings of the simulated cell) → `App::update` → the pipeline re-run
//! from the affected stage → drawing the Pipeline screen into a 120 × 40
//! buffer. Target ≤ 16 ms.
//!
//! Printed once before the timings (figures, not loops): bytes written to
//! the terminal for one parameter tweak at 120 × 40 (≤ 16 KiB), the real
//! binary's start to first drawn screen in a pseudo-terminal (≤ 200 ms), and
//! its peak resident memory (VmHWM) after a five-image survey and again
//! after its report (≤ 64 MiB), so what the report costs shows.
//! `VSS_BENCH_BIN=path` measures another build of the binary (an older
//! one, for a before and after) in the pty.
//!
//! `cargo bench --bench tui` (`cargo bench --bench tui -- none` for the
//! figures alone)

use std::io::{Read, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use divan::Bencher;
use ratatui::backend::{CrosstermBackend, TestBackend};
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::layout::Rect;
use ratatui::{Terminal, TerminalOptions, Viewport};
use vss::llv::{GreyImage, params::PARAMS};
use vss::profile::Profile;
use vss::synth::{self, RenderOptions};
use vss::tui::app::App;
use vss::tui::event::{
    Cmd, DeviceEvent, FramePurpose, Msg, PipelineResult, SessionView, StoreEvent,
};
use vss::tui::mode::Look;
use vss::tui::widgets::preview::PreviewMode;
use vss::tui::workers::pipeline::Engine;

fn main() {
    figures();
    divan::main();
}

const LETTERS: [char; 5] = ['a', 'b', 'c', 'd', 'e'];

/// The five lightings of camera 1 of the simulated cell at 512 × 512:
/// each light alone, then ambient only.
fn cell_images() -> Vec<GreyImage> {
    let scene = synth::cell_scene();
    let cams = synth::cell_cameras(512, 512);
    let lights = synth::cell_lights();
    let o = RenderOptions {
        ambient: 0.15,
        blur_sigma: 0.7,
        noise_sigma: 2.0,
        seed: 1,
        distort: true,
    };
    let mut out: Vec<GreyImage> = lights
        .iter()
        .map(|l| synth::render(&scene, &cams[0], std::slice::from_ref(l), &o))
        .collect();
    out.push(synth::render(&scene, &cams[0], &[], &o));
    out
}

fn profile() -> Profile {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("profiles/default.toml");
    Profile::load(path.to_str().unwrap_or("default")).expect("profiles/default.toml")
}

/// An App on the Pipeline screen with image 1 captured and processed, and
/// the engine that processed it.
fn ready() -> (App, Engine) {
    let mut app = App::new(
        &profile(),
        Look {
            mode: PreviewMode::Blocks,
            colour: true,
            c256: true,
        },
    );
    app.update(Msg::Store(StoreEvent::Opened(SessionView {
        name: "bench".into(),
        letters: LETTERS.to_vec(),
        next: Some((1, Some('a'))),
        ..Default::default()
    })));
    app.update(key(KeyCode::Enter));
    let mut cmds = Vec::new();
    for (letter, image) in LETTERS.into_iter().zip(cell_images()) {
        cmds = app.update(Msg::Device(DeviceEvent::Frame {
            purpose: FramePurpose::Survey { k: 1, letter },
            camera: 1,
            image,
            settings: Default::default(),
        }));
    }
    let mut engine = Engine::default();
    run_pipeline(&mut app, &mut engine, cmds);
    app.update(key(KeyCode::Char('3')));
    (app, engine)
}

fn key(code: KeyCode) -> Msg {
    Msg::Key(KeyEvent::new(code, KeyModifiers::NONE))
}

fn run_pipeline(app: &mut App, engine: &mut Engine, cmds: Vec<Cmd>) {
    for c in cmds {
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

fn select(app: &mut App, param: &str) {
    let i = PARAMS.iter().position(|p| p.key == param).unwrap_or(0);
    for _ in 0..PARAMS.len() {
        app.update(key(KeyCode::Up));
    }
    for _ in 0..i {
        app.update(key(KeyCode::Down));
    }
}

/// One key press (alternately up and down, so the state stays put) through
/// to the drawn preview.
fn tweak(app: &mut App, engine: &mut Engine, up: bool) {
    let cmds = app.update(key(KeyCode::Char(if up { '+' } else { '-' })));
    run_pipeline(app, engine, cmds);
}

/// One measured key press: update, pipeline re-run, draw (a function of
/// its own so `valgrind --toggle-collect='*press_and_draw*'` counts it).
#[inline(never)]
fn press_and_draw(app: &mut App, engine: &mut Engine, term: &mut Terminal<TestBackend>, up: bool) {
    tweak(app, engine, up);
    term.draw(|f| f.render_widget(&*app, f.area()))
        .expect("draw");
}

#[divan::bench(args = ["lines.min_length", "connect.wl", "edges.per_region"])]
fn param_key_to_preview_512(bencher: Bencher, param: &str) {
    let (mut app, mut engine) = ready();
    select(&mut app, param);
    let mut term = Terminal::new(TestBackend::new(120, 40)).expect("test backend");
    let mut up = true;
    bencher.bench_local(|| {
        press_and_draw(&mut app, &mut engine, &mut term, up);
        up = !up;
    });
}

/// Bytes the real backend writes for the redraw after each of `presses`
/// presses of `key_char` on `param`: (bytes, lines before, lines after).
fn tweak_bytes(param: &str, key_char: char, presses: usize) -> Vec<(usize, usize, usize)> {
    let (mut app, mut engine) = ready();
    select(&mut app, param);
    let opts = TerminalOptions {
        viewport: Viewport::Fixed(Rect::new(0, 0, 120, 40)),
    };
    let count = Arc::new(AtomicUsize::new(0));
    let writer = Counter(count.clone());
    let mut term = Terminal::with_options(CrosstermBackend::new(writer), opts).expect("backend");
    term.draw(|f| f.render_widget(&app, f.area()))
        .expect("draw");
    let lines = |app: &App| {
        app.tracker
            .current
            .as_ref()
            .and_then(|c| c.outputs.as_ref())
            .map_or(0, |o| o.lines.len())
    };
    let mut out = Vec::new();
    for _ in 0..presses {
        let before = lines(&app);
        count.store(0, Ordering::SeqCst);
        let cmds = app.update(key(KeyCode::Char(key_char)));
        run_pipeline(&mut app, &mut engine, cmds);
        term.draw(|f| f.render_widget(&app, f.area()))
            .expect("draw");
        out.push((count.load(Ordering::SeqCst), before, lines(&app)));
    }
    out
}

/// A terminal that only counts the bytes written to it.
struct Counter(Arc<AtomicUsize>);

impl Write for Counter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.fetch_add(buf.len(), Ordering::SeqCst);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

const SIM_PROFILE: &str = r#"
name = "bench cell"
[[lights]]
name = "l0"
relay = 0
[[lights]]
name = "l1"
relay = 1
[[lights]]
name = "l2"
relay = 2
[[lights]]
name = "l3"
relay = 3
[[lighting]]
letter = "a"
on = ["l0"]
[[lighting]]
letter = "b"
on = ["l1"]
[[lighting]]
letter = "c"
on = ["l2"]
[[lighting]]
letter = "d"
on = ["l3"]
[[lighting]]
letter = "e"
on = []
[sim]
width = 512
height = 512
"#;

/// The peak resident memory (VmHWM) of process `pid`, KiB.
fn vm_hwm_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

/// Runs the real binary in a pty: time to the first drawn screen, and peak
/// memory (KiB) after surveying five 512 × 512 images of five lightings
/// each, then after writing their report.
fn binary_figures() -> Option<(Duration, u64, u64)> {
    use portable_pty::{CommandBuilder, PtySize, native_pty_system};
    let dir = tempfile::tempdir().ok()?;
    std::fs::write(dir.path().join("cell.toml"), SIM_PROFILE).ok()?;
    let pair = native_pty_system()
        .openpty(PtySize {
            rows: 40,
            cols: 120,
            pixel_width: 0,
            pixel_height: 0,
        })
        .ok()?;
    let bin = std::env::var_os("VSS_BENCH_BIN")
        .unwrap_or_else(|| std::ffi::OsString::from(env!("CARGO_BIN_EXE_vss")));
    let mut cmd = CommandBuilder::new(bin);
    cmd.args(["--profile", "cell.toml"]);
    cmd.cwd(dir.path());
    cmd.env("TERM", "xterm-256color");
    let t0 = Instant::now();
    let mut child = pair.slave.spawn_command(cmd).ok()?;
    let mut reader = pair.master.try_clone_reader().ok()?;
    let mut writer = pair.master.take_writer().ok()?;
    let parser = Arc::new(Mutex::new(vt100::Parser::new(40, 120, 0)));
    let first = Arc::new(Mutex::new(None::<Duration>));
    let (p, f) = (parser.clone(), first.clone());
    std::thread::spawn(move || {
        let mut buf = [0u8; 16384];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            let mut p = p.lock().expect("parser");
            p.process(&buf[..n]);
            let mut f = f.lock().expect("first");
            if f.is_none() && p.screen().contents().contains("1 Survey") {
                *f = Some(t0.elapsed());
            }
        }
    });
    // Looks at least once, then until `secs` have passed.
    let wait = |text: &str, secs: u64| -> bool {
        let end = Instant::now() + Duration::from_secs(secs);
        loop {
            if parser
                .lock()
                .map(|p| p.screen().contents().contains(text))
                .unwrap_or(false)
            {
                return true;
            }
            if Instant::now() >= end {
                return false;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    let mut send = |s: &str| {
        let _ = writer.write_all(s.as_bytes());
        let _ = writer.flush();
        std::thread::sleep(Duration::from_millis(50));
    };
    wait("choose a session", 10).then_some(())?;
    let start = (*first.lock().ok()?)?;
    send("n");
    send("bench\r");
    for k in 1..=5 {
        // Past the plan (one image per camera), another image is asked for.
        if wait("Survey complete", 1) {
            send("\r");
            wait("beyond the plan?", 10).then_some(())?;
            send("y");
        }
        wait(&format!("Image {k}: camera"), 30).then_some(())?;
        send("\r");
        wait("before CONNECT", 120).then_some(())?;
        send("a");
        let next = format!("Image {}: camera", k + 1);
        let end = Instant::now() + Duration::from_secs(30);
        while !(wait(&next, 0) || wait("Survey complete", 0)) {
            (Instant::now() < end).then_some(())?;
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    let pid = child.process_id()?;
    let survey_kib = vm_hwm_kib(pid)?;
    // And its report (PostScript and SVG pages of every image).
    send("5");
    send("e");
    wait("report written", 120).then_some(())?;
    let report_kib = vm_hwm_kib(pid)?;
    send("q");
    let _ = child.wait();
    Some((start, survey_kib, report_kib))
}

fn figures() {
    for p in ["connect.min_line_length", "edges.per_region", "edges.floor"] {
        let runs = tweak_bytes(p, '>', 8);
        let max = runs.iter().map(|r| r.0).max().unwrap_or(0);
        let changed: Vec<String> = runs
            .iter()
            .filter(|r| r.1 != r.2)
            .map(|r| format!("{} B for lines {} -> {}", r.0, r.1, r.2))
            .collect();
        println!(
            "tui: bytes written per `{p}` key press (ten steps) at 120x40: at most {max} B \
             over 8 presses; presses that changed the lines: [{}] (target <= 16384)",
            changed.join(", ")
        );
    }
    match binary_figures() {
        Some((start, survey, report)) => {
            println!(
                "tui: start to first drawn screen: {:.0} ms (target <= 200)",
                start.as_secs_f64() * 1e3
            );
            println!(
                "tui: peak resident memory after a five-image survey: {:.1} MiB, and after its \
                 report: {:.1} MiB (target <= 64)",
                survey as f64 / 1024.0,
                report as f64 / 1024.0
            );
        }
        None => println!("tui: the pty figures could not be measured (no pty?)"),
    }
}
