//! The console in a real terminal, for the `tui_pty*` tests: the real `vss`
//! binary started in a pseudo-terminal (portable-pty), its output read
//! through a terminal emulator (vt100), keys written as a terminal sends
//! them. Tests wait for screen states, never for fixed times, and name keys
//! by what they do ([`Console::press`] reads the console's own key table).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use portable_pty::{Child, CommandBuilder, MasterPty, PtySize, native_pty_system};
use ratatui::crossterm::event::KeyCode;
use vss::tui::keymap::{Action, KEYMAP, Key, ModalAction, Scope, ScreenId, SurveyAction};

/// A small, quick simulated cell: 128 × 128 images, short settle, three
/// lightings (c ambient), four cameras, and lens correction off, as it is
/// without a camera's `.cdf` (on, the console began every test holding
/// "lens correction OFF … names no .cdf" on the message line for 3 s).
pub const PROFILE: &str = concat!(
    "name = \"pty test cell\"\n",
    crate::support::fixtures::two_lights!(),
    r#"
[relay]
settle_ms = 5

[survey]
dir = "sessions"
cameras = 4

[sim]
width = 128
height = 128
seed = 7
noise = 1.0

[llv.lens]
enabled = false
"#
);

/// The default cell's five lightings (four lights, then ambient) at 128 ×
/// 128, with each camera's `.cdf` beside the profile so lens correction
/// runs; `lens` sets `lens.enabled`.
pub fn five_lightings(lens: bool) -> String {
    format!(
        concat!(
            "name = \"five lightings\"\n",
            crate::support::fixtures::five_lightings!(),
            r#"
[relay]
settle_ms = 5

[survey]
dir = "sessions"
cameras = 2
cdf = ["cam1.cdf", "cam2.cdf"]

[sim]
width = 128
height = 128
seed = 3
noise = 1.0

[llv.lens]
enabled = {lens}
"#
        ),
        lens = lens
    )
}

/// Writes the simulated cameras' `.cdf` files for 128 × 128 images.
pub fn write_cdfs(dir: &Path, cameras: u32) {
    for cam in 1..=cameras {
        let cdf = vss::rig::sim::camera_cdf(cam, 128, 128).expect("a simulated camera");
        vss::formats::cdf::write_cdf(&dir.join(format!("cam{cam}.cdf")), &cdf).unwrap();
    }
}

#[allow(dead_code)] // each test module uses some of it
pub struct Console {
    pub master: Box<dyn MasterPty + Send>,
    writer: Box<dyn Write + Send>,
    pub child: Box<dyn Child + Send + Sync>,
    parser: Arc<Mutex<vt100::Parser>>,
    pub raw: Arc<Mutex<Vec<u8>>>,
    pub dir: tempfile::TempDir,
    /// Started in another console's folder.
    pub twin: bool,
}

#[allow(dead_code)]
impl Console {
    /// The console on [`PROFILE`].
    pub fn start(cols: u16, rows: u16, env: &[(&str, &str)]) -> Console {
        Console::start_with(PROFILE, cols, rows, env, |_| {})
    }

    /// The console on `profile` (written as `cell.toml` in a fresh folder,
    /// after `setup` has put whatever else it needs there).
    pub fn start_with(
        profile: &str,
        cols: u16,
        rows: u16,
        env: &[(&str, &str)],
        setup: impl FnOnce(&Path),
    ) -> Console {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("cell.toml"), profile).unwrap();
        setup(dir.path());
        Console::start_in(dir, cols, rows, env, &["--profile", "cell.toml"])
    }

    /// The console started in `dir` with `args`.
    pub fn start_in(
        dir: tempfile::TempDir,
        cols: u16,
        rows: u16,
        env: &[(&str, &str)],
        args: &[&str],
    ) -> Console {
        let cwd = dir.path().to_path_buf();
        Console::spawn(&cwd, dir, cols, rows, env, args)
    }

    /// An interactive shell with job control (bash) in the terminal, in a
    /// fresh folder holding [`PROFILE`] as `cell.toml`, which starts the
    /// console as an operator would; `child` is the shell. When the
    /// console ends the shell says `vss ended N` (its exit code).
    pub fn start_under_shell(cols: u16, rows: u16) -> Console {
        Console::start_under_shell_as(cols, rows, |vss| {
            format!("{vss} --profile cell.toml; echo vss ended $?")
        })
    }

    /// As [`Console::start_under_shell`], the shell given the command line
    /// `line` makes of the console's command (`vss --profile cell.toml`
    /// with the binary's path).
    pub fn start_under_shell_as(
        cols: u16,
        rows: u16,
        line: impl FnOnce(&str) -> String,
    ) -> Console {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("cell.toml"), PROFILE).unwrap();
        let cwd = dir.path().to_path_buf();
        let mut c = Console::spawn_program(
            "bash",
            &cwd,
            dir,
            cols,
            rows,
            &[("PS1", "$ "), ("HISTFILE", "/dev/null")],
            &["--norc", "--noprofile", "-i"],
        );
        // Typed at once: the shell reads it once it is ready.
        c.send(&format!("{}\r", line(env!("CARGO_BIN_EXE_vss"))));
        c
    }

    fn spawn(
        cwd: &Path,
        dir: tempfile::TempDir,
        cols: u16,
        rows: u16,
        env: &[(&str, &str)],
        args: &[&str],
    ) -> Console {
        let vss = env!("CARGO_BIN_EXE_vss");
        Console::spawn_program(vss, cwd, dir, cols, rows, env, args)
    }

    pub fn spawn_program(
        program: &str,
        cwd: &Path,
        dir: tempfile::TempDir,
        cols: u16,
        rows: u16,
        env: &[(&str, &str)],
        args: &[&str],
    ) -> Console {
        let pty = native_pty_system();
        let size = PtySize {
            rows,
            cols,
            pixel_width: 0,
            pixel_height: 0,
        };
        let pair = pty.openpty(size).unwrap();
        let mut cmd = CommandBuilder::new(program);
        cmd.args(args);
        cmd.cwd(cwd);
        cmd.env("TERM", "xterm-256color");
        // The log file goes to the session folder or here, never to the
        // tester's own state folder.
        cmd.env("XDG_STATE_HOME", cwd.join("state"));
        cmd.env_remove("NO_COLOR");
        // An empty value unsets the variable, as `env -u` does.
        for (k, v) in env {
            if v.is_empty() {
                cmd.env_remove(k);
            } else {
                cmd.env(k, v);
            }
        }
        let child = pair.slave.spawn_command(cmd).unwrap();
        drop(pair.slave);
        let mut reader = pair.master.try_clone_reader().unwrap();
        let writer = pair.master.take_writer().unwrap();
        let parser = Arc::new(Mutex::new(vt100::Parser::new(rows, cols, 0)));
        let raw = Arc::new(Mutex::new(Vec::new()));
        let (p, r) = (parser.clone(), raw.clone());
        std::thread::spawn(move || {
            let mut buf = [0u8; 8192];
            let mut frames = Frames::default();
            loop {
                match reader.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => {
                        r.lock().unwrap().extend_from_slice(&buf[..n]);
                        frames.take(&buf[..n], |bytes| p.lock().unwrap().process(bytes));
                    }
                }
            }
            let rest = std::mem::take(&mut frames.pending);
            p.lock().unwrap().process(&rest);
        });
        Console {
            master: pair.master,
            writer,
            child,
            parser,
            raw,
            dir,
            twin: false,
        }
    }

    /// Resizes the terminal: the parser first, under its lock, then the pty.
    /// The console answers SIGWINCH with a clear and a full redraw; bytes it
    /// wrote for the old size can only reach the parser before that clear,
    /// so the screen read afterwards is the new size's (resizing the pty
    /// first let a redraw be parsed at the old size).
    pub fn resize(&mut self, rows: u16, cols: u16) {
        let mut parser = self.parser.lock().unwrap();
        parser.screen_mut().set_size(rows, cols);
        self.master
            .resize(PtySize {
                rows,
                cols,
                pixel_width: 0,
                pixel_height: 0,
            })
            .unwrap();
        drop(parser);
    }

    pub fn screen(&self) -> String {
        self.parser.lock().unwrap().screen().contents()
    }

    /// Runs `f` on the emulated screen (colours, attributes of cells).
    pub fn with_screen<T>(&self, f: impl FnOnce(&vt100::Screen) -> T) -> T {
        f(self.parser.lock().unwrap().screen())
    }

    /// Writes bytes as typed.
    pub fn send(&mut self, keys: &str) {
        self.writer.write_all(keys.as_bytes()).unwrap();
        self.writer.flush().unwrap();
    }

    /// Presses the key the console's key table binds to `action` in
    /// `scope` (its first binding).
    pub fn press(&mut self, scope: Scope, action: Action) {
        let k = key_of(scope, action);
        self.send(&bytes(&k));
    }

    /// Answers the open question with yes.
    pub fn yes(&mut self) {
        self.press(Scope::Confirm, Action::Modal(ModalAction::Yes));
    }

    /// Waits until the screen satisfies `f`, or fails showing the screen.
    pub fn wait(&self, what: &str, secs: u64, f: impl Fn(&str) -> bool) -> String {
        let end = Instant::now() + Duration::from_secs(secs);
        loop {
            let s = self.screen();
            if f(&s) {
                return s;
            }
            if Instant::now() > end {
                panic!("timed out waiting for {what}; screen:\n{s}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    pub fn wait_text(&self, text: &str, secs: u64) -> String {
        self.wait(text, secs, |s| s.contains(text))
    }

    /// Waits for `text`, which may be wrapped over rows.
    pub fn wait_words(&self, text: &str, secs: u64) -> String {
        self.wait(text, secs, |s| flat(s).contains(text))
    }

    /// Waits for vss to exit and gives its exit code.
    pub fn wait_exit(&mut self, secs: u64) -> u32 {
        let end = Instant::now() + Duration::from_secs(secs);
        while Instant::now() < end {
            if let Some(st) = self.child.try_wait().unwrap() {
                // Let the reader drain the last bytes.
                std::thread::sleep(Duration::from_millis(200));
                return st.exit_code();
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        panic!("vss did not exit; screen:\n{}", self.screen());
    }

    /// Quits (answering yes if asked) and starts the console again in the
    /// same folder, with the same profile.
    pub fn restart(mut self, cols: u16, rows: u16, env: &[(&str, &str)]) -> Console {
        self.send("q");
        self.wait_exit(15);
        let dir = std::mem::replace(&mut self.dir, tempfile::tempdir().unwrap());
        Console::start_in(dir, cols, rows, env, &["--profile", "cell.toml"])
    }

    /// Quits, lets `setup` change the folder, and starts again there at
    /// the same size.
    pub fn restart_after(mut self, setup: impl FnOnce(&Path)) -> Console {
        let (rows, cols) = self.parser.lock().unwrap().screen().size();
        self.send("q");
        self.wait_exit(15);
        let dir = std::mem::replace(&mut self.dir, tempfile::tempdir().unwrap());
        setup(dir.path());
        Console::start_in(dir, cols, rows, &[], &["--profile", "cell.toml"])
    }

    /// A second console started in the same folder (its own `dir` is an
    /// empty one, for its drop).
    pub fn another(&self, cols: u16, rows: u16) -> Console {
        let mut c = Console::spawn(
            self.dir.path(),
            tempfile::tempdir().unwrap(),
            cols,
            rows,
            &[],
            &["--profile", "cell.toml"],
        );
        c.twin = true;
        c
    }

    /// Sends the console `sig` (SIGHUP: its SSH connection dropped;
    /// SIGKILL: a power cut) and waits until it has ended.
    pub fn end_by(&mut self, sig: rustix::process::Signal) {
        let pid = self.child.process_id().expect("pid") as i32;
        let rc = rustix::process::kill_process(rustix::process::Pid::from_raw(pid).unwrap(), sig);
        assert_eq!(rc, Ok(()));
        self.wait_exit(10);
    }

    /// The child's exit status, once it has ended.
    pub fn exit_code(&mut self) -> Option<u32> {
        self.child.try_wait().ok().flatten().map(|s| s.exit_code())
    }

    pub fn sessions(&self) -> PathBuf {
        self.dir.path().join("sessions")
    }

    pub fn session(&self) -> PathBuf {
        self.sessions().join("cube")
    }

    /// Creates session `name` by keys.
    pub fn create_session(&mut self, name: &str) {
        self.wait_text("choose a session", 10);
        self.press(SURVEY, Action::Survey(SurveyAction::NewSession));
        self.wait_text("new session name", 5);
        self.send(name);
        self.send("\r");
        self.wait_text(&format!("session {name}"), 10);
    }

    /// On the session list at start: opens session `cube` once its row is
    /// listed (an Enter before the list is read opens nothing).
    pub fn open_cube(&mut self) {
        self.wait_text("choose a session", 10);
        self.wait_text(" cube ", 10);
        self.press(SURVEY, Action::Survey(SurveyAction::Enter));
        self.wait_text("session cube", 10);
    }

    /// Captures and runs the survey's current image (Survey screen) and
    /// waits for its review.
    pub fn capture_current(&mut self, k: u32) {
        self.wait_text(&format!("Image {k}: camera"), 20);
        self.press(SURVEY, Action::Survey(SurveyAction::Enter));
        self.wait(&format!("image {k} reviewed"), 60, |s| {
            s.contains(&format!("Image {k}: ")) && s.contains("before CONNECT")
        });
        // Its lines can come before the store has written every frame
        // (under load): wait until no lighting of its row is still pending
        // ('.'), so that what a test does to the folder next meets the
        // frames on disk.
        self.wait(&format!("image {k}'s frames saved"), 30, |s| {
            s.lines().any(|l| {
                let f: Vec<&str> = l
                    .trim_start_matches(['│', '|', '>', ' '])
                    .split_whitespace()
                    .collect();
                l.contains('>') && f.len() >= 4 && f[0] == k.to_string() && !f[3].contains('.')
            })
        });
    }

    /// Waits until the console's devices have answered: the grabber's
    /// note read in the log pane, as the message line shows the newest
    /// message only and the note can come before another start-up line
    /// ("log file: …"). `m` cycles the log: one line, expanded, hidden;
    /// it is left as one line again.
    pub fn wait_devices(&mut self, secs: u64) {
        use vss::tui::keymap::GlobalAction;
        let m = Action::Global(GlobalAction::ToggleLog);
        self.press(Scope::Global, m);
        self.wait("the grabber's note in the log pane", secs, |s| {
            s.contains("┌ log:") && s.contains("grabber")
        });
        self.press(Scope::Global, m);
        self.press(Scope::Global, m);
        self.wait("the log pane closed", 5, |s| !s.contains("┌ log:"));
    }

    /// Creates session `cube` and surveys `n` images by keys alone.
    pub fn survey(&mut self, n: u32) {
        self.create_session("cube");
        for k in 1..=n {
            self.capture_current(k);
            self.press(SURVEY, Action::Survey(SurveyAction::Accept));
            self.wait_text(&format!("Image {}: camera", k + 1), 20);
            // Accepted once the store has its files (said then, not before).
            self.wait_text(&format!("image {k} accepted"), 20);
        }
    }

    /// Goes to the Pipeline screen and waits for its parameter panel.
    pub fn open_pipeline(&mut self) {
        use vss::tui::keymap::GlobalAction;
        self.press(
            Scope::Global,
            Action::Global(GlobalAction::GoTo(ScreenId::Pipeline)),
        );
        self.wait_text("parameters", 10);
    }

    /// On the Pipeline screen with the first parameter chosen, chooses
    /// parameter `key` (by the panel's key, as an operator steps down).
    pub fn choose_param(&mut self, key: &str) {
        let at = vss::llv::params::PARAMS
            .iter()
            .position(|sp| sp.key == key)
            .unwrap_or_else(|| panic!("no parameter {key}"));
        for _ in 0..at {
            self.press(
                PIPELINE,
                Action::Pipeline(vss::tui::keymap::PipelineAction::ParamNext),
            );
        }
    }
}

/// Begin and end of a synchronized update (DEC mode 2026), which the
/// console puts around every frame.
const SYNC_BEGIN: &[u8] = b"\x1b[?2026h";
const SYNC_END: &[u8] = b"\x1b[?2026l";

/// What a terminal that knows synchronized updates does: a frame reaches
/// the screen whole, at its end, so a test never reads a screen half old
/// and half new (the console writes a frame in pieces, and under load the
/// reader gets them one by one). Bytes outside a frame go through at once.
#[derive(Default)]
struct Frames {
    pending: Vec<u8>,
    in_frame: bool,
}

impl Frames {
    fn take(&mut self, bytes: &[u8], mut show: impl FnMut(&[u8])) {
        self.pending.extend_from_slice(bytes);
        loop {
            let mark = if self.in_frame { SYNC_END } else { SYNC_BEGIN };
            if let Some(at) = find(&self.pending, mark) {
                let end = at + mark.len();
                // Bytes before a frame begins show at once; a frame's whole
                // bytes show together at its end.
                show(&self.pending[..end]);
                self.pending.drain(..end);
                self.in_frame = !self.in_frame;
            } else {
                if !self.in_frame {
                    // All but what could be the start of a mark cut in two.
                    let keep = (mark.len() - 1).min(self.pending.len());
                    let upto = self.pending.len() - keep;
                    show(&self.pending[..upto]);
                    self.pending.drain(..upto);
                }
                return;
            }
        }
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

impl Drop for Console {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
        }
    }
}

pub const SURVEY: Scope = Scope::Screen(ScreenId::Survey);
pub const PIPELINE: Scope = Scope::Screen(ScreenId::Pipeline);
#[allow(dead_code)]
pub const EDIT: Scope = Scope::Screen(ScreenId::Edit);
#[allow(dead_code)]
pub const SESSION: Scope = Scope::Screen(ScreenId::Session);

/// The first key the table binds to `action` in `scope`, else among the
/// picture keys (a screen with a picture), else globally.
pub fn key_of(scope: Scope, action: Action) -> Key {
    [scope, Scope::Picture, Scope::Global]
        .iter()
        .find_map(|sc| KEYMAP.iter().find(|b| b.scope == *sc && b.action == action))
        .map(|b| b.key)
        .unwrap_or_else(|| panic!("no key for {action:?} in {scope:?}"))
}

/// The bytes an xterm sends for a key.
pub fn bytes(k: &Key) -> String {
    let mods = 1 + u8::from(k.shift) + 4 * u8::from(k.ctrl);
    let csi = |c: char| {
        if mods > 1 {
            format!("\x1b[1;{mods}{c}")
        } else {
            format!("\x1b[{c}")
        }
    };
    match k.code {
        KeyCode::Char(c) if k.ctrl => ((c as u8 & 0x1f) as char).to_string(),
        KeyCode::Char(c) => c.to_string(),
        KeyCode::Enter => "\r".into(),
        KeyCode::Esc => "\x1b".into(),
        KeyCode::Tab => "\t".into(),
        KeyCode::BackTab => "\x1b[Z".into(),
        KeyCode::Backspace => "\x7f".into(),
        KeyCode::Up => csi('A'),
        KeyCode::Down => csi('B'),
        KeyCode::Right => csi('C'),
        KeyCode::Left => csi('D'),
        KeyCode::Home => csi('H'),
        KeyCode::End => csi('F'),
        KeyCode::PageUp => "\x1b[5~".into(),
        KeyCode::PageDown => "\x1b[6~".into(),
        KeyCode::Delete => "\x1b[3~".into(),
        other => panic!("no bytes known for {other:?}"),
    }
}

/// The value the parameter panel shows for `key` (`None` when the row is
/// not on screen).
pub fn panel_value(screen: &str, key: &str) -> Option<String> {
    // Rows of the panel start at its border; the log also names keys.
    screen.lines().find_map(|l| {
        let at = ["│", "|"]
            .iter()
            .find_map(|b| l.starts_with(&format!("{b}{key} ")).then_some(b.len()))?;
        let rest = l[at + key.len()..].trim_start();
        let v: String = rest
            .chars()
            .take_while(|c| !c.is_whitespace() && !matches!(c, '│' | '|' | '*'))
            .collect();
        (!v.is_empty()).then_some(v)
    })
}

/// The line count the Pipeline screen shows as `lines N raw M`.
pub fn line_count(screen: &str) -> Option<usize> {
    screen.match_indices("lines ").find_map(|(i, l)| {
        let rest = &screen[i + l.len()..];
        let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        let after = &rest[digits.len()..];
        if digits.is_empty() || !after.starts_with(" raw") {
            return None;
        }
        digits.parse().ok()
    })
}

/// The screen's text with every run of blanks and line ends made one
/// space, so wrapped words read on.
pub fn flat(screen: &str) -> String {
    screen.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Whether `dir` holds a file `name`.
pub fn exists(dir: &Path, name: &str) -> bool {
    dir.join(name).is_file()
}

/// A frame cut anywhere, its marks included, reaches the screen only whole.
#[test]
fn frames_reach_the_screen_whole() {
    let stream = b"ab\x1b[?2026hFRAME ONE\x1b[?2026lcd\x1b[?2026hTWO\x1b[?2026l".to_vec();
    for cut in 0..=stream.len() {
        for cut2 in cut..=stream.len() {
            let mut f = Frames::default();
            let mut seen: Vec<Vec<u8>> = Vec::new();
            let mut shown = Vec::new();
            for part in [&stream[..cut], &stream[cut..cut2], &stream[cut2..]] {
                f.take(part, |b| shown.extend_from_slice(b));
                seen.push(shown.clone());
            }
            assert_eq!(shown, stream, "cut at {cut} and {cut2}");
            for s in &seen {
                let text = String::from_utf8_lossy(s);
                let frame_one = text.contains("FRAME");
                assert_eq!(frame_one, text.contains("ONE\x1b[?2026l"), "{text:?}");
                assert_eq!(
                    text.contains('T'),
                    text.contains("TWO\x1b[?2026l"),
                    "{text:?}"
                );
            }
        }
    }
}

/// The console on [`PROFILE`] starts with nothing worrying to say (the
/// log file has no warning), so no start-up warning is held on the
/// message line over what a test waits for. It held "lens correction OFF
/// … names no .cdf" for 3 s at the start of every test.
#[test]
fn the_test_cell_starts_without_a_warning() {
    let mut c = Console::start(80, 24, &[]);
    c.wait_devices(10);
    let file = c.dir.path().join("state/vss/console.log");
    c.wait("the grabber's note in the log file", 10, |_| {
        std::fs::read_to_string(&file).is_ok_and(|l| l.contains("relay board"))
    });
    let log = std::fs::read_to_string(&file).unwrap();
    assert!(
        !log.contains(" warning ") && !log.contains(" ERROR "),
        "{log}"
    );
    c.send("q");
    assert_eq!(c.wait_exit(10), 0);
}
