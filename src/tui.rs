//! The operator console: a keyboard-driven TUI over the survey, the
//! capture hardware, the LLV pipeline, the line editor and the reports.
//!
//! "Functional core, imperative shell": [`app::App`] holds the state and
//! turns messages into commands without any I/O; this file is the shell —
//! terminal set-up and restore (panic, SIGTERM, SIGHUP, Ctrl-C), the input
//! thread, the workers ([`workers`]), and a loop that draws only when
//! something changed, so an idle console writes nothing.

use std::io::{self, Write};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use anyhow::Context;
use ratatui::Terminal;
use ratatui::backend::CrosstermBackend;
use ratatui::crossterm::event as term_event;
use ratatui::crossterm::{cursor, execute, terminal};

pub mod app;
pub mod event;
pub mod keymap;
pub mod mode;
pub mod screens;
mod suspend;
pub mod text;
pub mod widgets;
pub mod workers;

use app::App;
use event::{Cmd, Msg};

/// Least time between two draws while messages pour in (progress, live).
const FRAME: Duration = Duration::from_millis(16);

/// Opens the console on `profile`'s cell, drawn as `look` says.
pub fn run(profile: crate::profile::Profile, look: mode::Look) -> anyhow::Result<ExitCode> {
    // A terminal without cursor addressing gets words, not escape sequences.
    // Said on standard error; a reader of it that has gone loses the
    // words, not the exit status (`eprintln!` would panic).
    if let Some(why) = mode::unusable(std::env::var("TERM").ok().as_deref()) {
        let _ = writeln!(io::stderr(), "{why}");
        return Ok(ExitCode::from(2));
    }
    if !io::IsTerminal::is_terminal(&io::stdout()) {
        let _ = writeln!(
            io::stderr(),
            "vss: the console needs a terminal on its output; use the vss subcommands \
             (`vss --help`) in scripts and pipes"
        );
        return Ok(ExitCode::from(2));
    }

    // Signals first: a hang-up during start-up must still restore the terminal.
    let stop = Arc::new(AtomicBool::new(false));
    // Which signal stopped the console, for the log's last line.
    let signal = Arc::new(AtomicUsize::new(0));
    for sig in [
        signal_hook::consts::SIGTERM,
        signal_hook::consts::SIGHUP,
        signal_hook::consts::SIGINT,
        signal_hook::consts::SIGQUIT,
    ] {
        signal_hook::flag::register_usize(sig, signal.clone(), sig as usize)
            .context("installing signal handlers")?;
        signal_hook::flag::register(sig, stop.clone()).context("installing signal handlers")?;
    }
    // Ctrl-Z from elsewhere (`kill -TSTP`) and `fg`: the loop leaves and
    // takes back the terminal ([`suspend`]).
    let job = JobSignals::default();
    signal_hook::flag::register(signal_hook::consts::SIGTSTP, job.stop.clone())
        .context("installing signal handlers")?;
    signal_hook::flag::register(signal_hook::consts::SIGCONT, job.cont.clone())
        .context("installing signal handlers")?;
    install_panic_hook();
    let mut terminal = enter().context("setting up the terminal")?;
    let result = run_loop(&mut terminal, profile, look, &stop, &signal, &job);
    // Drop the terminal first: its own clean-up writes to the screen, and
    // leaving the alternate screen must be the last thing written.
    drop(terminal);
    leave();
    // Ended by a signal: the shell's convention, 128 + its number, so that
    // a script or a supervisor sees the console did not end by `q`.
    let sig = signal.load(Ordering::SeqCst);
    result.map(|()| match u8::try_from(128 + sig) {
        Ok(code) if sig != 0 => ExitCode::from(code),
        _ => ExitCode::SUCCESS,
    })
}

type Term = Terminal<CrosstermBackend<io::Stdout>>;

/// SIGTSTP and SIGCONT as they come: the loop takes them.
#[derive(Default)]
struct JobSignals {
    stop: Arc<AtomicBool>,
    cont: Arc<AtomicBool>,
}

fn enter() -> io::Result<Term> {
    terminal::enable_raw_mode()?;
    let mut out = io::stdout();
    if let Err(e) = screen_modes(&mut out) {
        leave();
        return Err(e);
    }
    Terminal::new(CrosstermBackend::new(out))
}

/// The console's screen modes, after raw mode: the alternate screen, no
/// cursor, and mouse reports where the terminal sends them (others ignore
/// the request). At start and when taken back after a suspension
/// ([`suspend::take_back`]); [`leave`] undoes them.
fn screen_modes(out: &mut impl Write) -> io::Result<()> {
    execute!(
        out,
        terminal::EnterAlternateScreen,
        cursor::Hide,
        term_event::EnableMouseCapture
    )
}

/// Puts the terminal back as the shell had it: cooked mode, cursor shown,
/// main screen. Safe to call twice and from the panic hook.
pub fn leave() {
    let _ = terminal::disable_raw_mode();
    let mut out = io::stdout();
    let _ = execute!(
        out,
        // A frame cut short (a panic mid-draw) must not leave the terminal
        // holding back its output.
        terminal::EndSynchronizedUpdate,
        term_event::DisableMouseCapture,
        cursor::Show,
        terminal::LeaveAlternateScreen
    );
    let _ = out.flush();
}

fn install_panic_hook() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        leave();
        previous(info);
    }));
}

/// Reads keys and resizes on their own thread so the UI loop never blocks
/// on the terminal; ends when the UI is gone or input fails (hang-up).
fn spawn_input(tx: Sender<Msg>, stop: Arc<AtomicBool>) -> io::Result<()> {
    std::thread::Builder::new()
        .name("vss-input".into())
        .spawn(move || {
            while !stop.load(Ordering::SeqCst) {
                match term_event::poll(Duration::from_millis(100)) {
                    Ok(false) => continue,
                    Ok(true) => {}
                    Err(_) => break,
                }
                let msg = match term_event::read() {
                    Ok(term_event::Event::Key(k)) => Msg::Key(k),
                    Ok(term_event::Event::Resize(w, h)) => Msg::Resize(w, h),
                    Ok(term_event::Event::Mouse(m)) => Msg::Mouse(m),
                    Ok(_) => continue,
                    Err(_) => break,
                };
                if tx.send(msg).is_err() {
                    break;
                }
            }
            // Input is gone (terminal hung up): ask the loop to stop.
            stop.store(true, Ordering::SeqCst);
        })?;
    Ok(())
}

fn run_loop(
    terminal: &mut Term,
    profile: crate::profile::Profile,
    look: mode::Look,
    stop: &Arc<AtomicBool>,
    signal: &Arc<AtomicUsize>,
    job: &JobSignals,
) -> anyhow::Result<()> {
    let (tx, rx) = mpsc::channel::<Msg>();
    let mut app = App::new(&profile, look);
    if let Ok(size) = terminal.size() {
        app.update(Msg::Resize(size.width, size.height));
    }
    // Draw before anything slow starts: the operator sees the console at once.
    draw(terminal, &app)?;
    spawn_input(tx.clone(), stop.clone())?;
    let workers = Workers {
        device: workers::device::spawn(profile.clone(), tx.clone())?,
        pipeline: workers::pipeline::spawn(tx.clone())?,
        store: workers::store::spawn(profile, tx.clone())?,
    };
    drop(tx);
    let first = app.start();
    workers.dispatch(first);
    workers.dispatch(app.take_log_lines().into_iter().collect());
    let mut dirty = true;
    let mut last_draw = Instant::now();
    // A terminal that takes no more output (its window gone, no SIGHUP
    // seen yet) ends the loop like a hang-up: the workers still finish.
    let mut broken: Option<io::Error> = None;
    while !app.quit() && !stop.load(Ordering::SeqCst) {
        if dirty && last_draw.elapsed() >= FRAME {
            workers.dispatch(sync_size(terminal, &mut app));
            if let Err(e) = draw(terminal, &app) {
                broken = Some(e);
                break;
            }
            last_draw = Instant::now();
            dirty = false;
        }
        let wait = if dirty {
            FRAME.saturating_sub(last_draw.elapsed())
        } else {
            Duration::from_millis(100)
        };
        match rx.recv_timeout(wait) {
            Ok(msg) => {
                let msg = place(&app, msg);
                dirty |= !matches!(msg, Msg::Tick);
                let cmds = app.update(msg);
                workers.dispatch(cmds);
                // Take whatever else is waiting before drawing again (a key
                // queued behind a tick must still mark the screen dirty).
                while let Ok(msg) = rx.try_recv() {
                    let msg = place(&app, msg);
                    dirty |= !matches!(msg, Msg::Tick);
                    let cmds = app.update(msg);
                    workers.dispatch(cmds);
                    if app.quit() || app.chrome.suspend {
                        break;
                    }
                }
                // Every message of the run also goes to the log file.
                workers.dispatch(app.take_log_lines().into_iter().collect());
            }
            Err(RecvTimeoutError::Timeout) => dirty |= app.release_held(Instant::now()),
            Err(RecvTimeoutError::Disconnected) => break,
        }
        let asked = app.take_suspend();
        if (asked || job.stop.swap(false, Ordering::SeqCst)) && !stop.load(Ordering::SeqCst) {
            suspend_here(terminal, &mut app, asked, job, &workers, stop);
            dirty = true;
        } else if job.cont.swap(false, Ordering::SeqCst) {
            // Continued after a stop the console did not make (SIGSTOP):
            // the shell may have taken the terminal back meanwhile.
            take_back(terminal, &mut app, stop);
            dirty = true;
        }
        workers.dispatch(app.take_log_lines().into_iter().collect());
        workers.dispatch(app.due(Instant::now()));
    }
    // The log says why the console ended: the operator, a signal, or the
    // terminal gone.
    let why = match signal.load(Ordering::SeqCst) as i32 {
        0 if broken.is_some() => format!(
            "the terminal cannot be written ({})",
            broken.as_ref().map_or(String::new(), |e| e.to_string())
        ),
        0 if app.quit() => "quit by the operator".to_string(),
        0 if stop.load(Ordering::SeqCst) => "the terminal's input ended (hang-up)".to_string(),
        0 => "its workers stopped".to_string(),
        signal_hook::consts::SIGHUP => "SIGHUP: the terminal hung up".to_string(),
        signal_hook::consts::SIGTERM => "SIGTERM: asked to stop".to_string(),
        signal_hook::consts::SIGINT => "SIGINT".to_string(),
        signal_hook::consts::SIGQUIT => "SIGQUIT".to_string(),
        n => format!("signal {n}"),
    };
    app.ctx().info(format!("console ended: {why}"));
    workers.dispatch(app.take_log_lines().into_iter().collect());
    workers.finish();
    match broken {
        Some(e) => Err(anyhow::Error::from(e).context("drawing the console")),
        None => Ok(()),
    }
}

/// Suspends the console (Ctrl-Z, or `asked` false: SIGTSTP) if a shell can
/// continue it, saying so on the main screen and in the log, and takes the
/// terminal back when continued. A console continued to end (the shell
/// hung up sends SIGHUP, then SIGCONT) does not draw again: the loop ends
/// as for any hang-up, saves finished first.
fn suspend_here(
    terminal: &mut Term,
    app: &mut App,
    asked: bool,
    job: &JobSignals,
    workers: &Workers,
    stop: &AtomicBool,
) {
    let how = if asked { "Ctrl-Z" } else { "SIGTSTP" };
    if !suspend::can_suspend() {
        let before = app.chrome.log.pushed();
        app.ctx().warn(format!(
            "{how}: not suspended — no shell with job control started this console, \
             so nothing could bring it back; q quits"
        ));
        // The answer to the key, held as any key's is.
        if asked {
            app.chrome.hold_answer(before, Instant::now());
        }
        return;
    }
    let held = match &app.session.view {
        Some(v) if !v.read_only => format!("; session {} stays open here", v.name),
        _ => String::new(),
    };
    app.ctx().info(format!("suspended ({how}){held}"));
    workers.dispatch(app.take_log_lines().into_iter().collect());
    let note = format!("vss: suspended{held}; fg brings the console back");
    if let Err(e) = suspend::stop(&note) {
        app.ctx().error(format!("{how}: not suspended: {e}"));
    }
    // This stop's own SIGTSTP (sent to the group) and SIGCONT: the
    // terminal is taken back here.
    job.stop.store(false, Ordering::SeqCst);
    job.cont.store(false, Ordering::SeqCst);
    take_back(terminal, app, stop);
}

/// Takes the terminal again after a stop, unless the console is ending;
/// a terminal that cannot be taken (gone) ends it.
fn take_back(terminal: &mut Term, app: &mut App, stop: &AtomicBool) {
    if stop.load(Ordering::SeqCst) {
        return;
    }
    match suspend::take_back(terminal) {
        Ok(()) => {
            if let Ok(size) = terminal.size() {
                app.update(Msg::Resize(size.width, size.height));
            }
            app.ctx().info("back from suspension");
        }
        Err(e) => {
            app.ctx()
                .error(format!("the terminal cannot be taken back: {e}"));
            stop.store(true, Ordering::SeqCst);
        }
    }
}

/// The terminal's size now, given to the App before a frame is drawn
/// when its last resize event has not come yet: the frame (drawn at the
/// terminal's size) and the keys that follow it (read against the App's)
/// then agree on one size, so a key never acts on a screen that is not
/// drawn ("too small") or drawn otherwise.
fn sync_size(term: &Term, app: &mut App) -> Vec<Cmd> {
    match term.size() {
        Ok(size) if (size.width, size.height) != app.chrome.size => {
            app.update(Msg::Resize(size.width, size.height))
        }
        _ => Vec::new(),
    }
}

/// Draws one frame as a synchronized update (DEC mode 2026): a terminal
/// that knows the mode shows the frame whole, never half old and half new
/// (over a slow SSH link, or while the machine is loaded); others ignore
/// the two sequences.
fn draw(term: &mut Term, app: &App) -> io::Result<()> {
    ratatui::crossterm::queue!(term.backend_mut(), terminal::BeginSynchronizedUpdate)?;
    term.draw(|f| f.render_widget(app, f.area()))?;
    execute!(term.backend_mut(), terminal::EndSynchronizedUpdate)
}

/// A mouse event placed on what the screen shows there (nothing, where
/// it falls on nothing that takes the mouse).
fn place(app: &App, msg: Msg) -> Msg {
    match msg {
        Msg::Mouse(m) => {
            let (w, h) = app.chrome.size;
            let area = ratatui::layout::Rect::new(0, 0, w, h);
            screens::pointer(app, area, m).map_or(Msg::Tick, Msg::Pointer)
        }
        other => other,
    }
}

struct Workers {
    device: workers::device::DeviceHandle,
    pipeline: workers::pipeline::PipelineHandle,
    store: workers::store::StoreHandle,
}

impl Workers {
    fn dispatch(&self, cmds: Vec<Cmd>) {
        for c in cmds {
            match c {
                Cmd::Device(d) => self.device.send(d),
                Cmd::Pipeline(p) => self.pipeline.send(p),
                Cmd::Store(s) => self.store.send(s),
            }
        }
    }

    /// Lets the store finish the saves it has queued (nothing saved is lost),
    /// stops the rest without waiting on a device.
    fn finish(self) {
        self.device.cancel.store(true, Ordering::SeqCst);
        drop(self.device.tx);
        drop(self.pipeline);
        self.store.finish(Duration::from_secs(10));
    }
}
