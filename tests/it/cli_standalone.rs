//! The `vss` binary on its own, as on a cell PC it was copied to: in an
//! empty folder, with an empty home, no `profiles/` anywhere, it starts the
//! console on the built-in simulated cell (first screen drawn, in a real
//! terminal), runs `vss llv` on an image, and makes a session with the
//! built-in cameras' `.cdf` files. And the profile lookup order: a path,
//! `./profiles`, then `~/.config/vss/profiles` (`XDG_CONFIG_HOME`), then the
//! built-in default.

use std::io::{Read, Write as _};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use portable_pty::{CommandBuilder, PtySize, native_pty_system};
use vss::formats::img::ImgFile;
use vss::llv::GreyImage;

/// A folder with only the binary in `bin/`, an empty `work/` to run in and
/// an empty `home/`.
struct Alone {
    _dir: tempfile::TempDir,
    bin: PathBuf,
    work: PathBuf,
    home: PathBuf,
}

fn alone() -> Alone {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin/vss");
    std::fs::create_dir_all(bin.parent().unwrap()).unwrap();
    std::fs::copy(env!("CARGO_BIN_EXE_vss"), &bin).unwrap();
    // A child another test thread forked while the copy was open for
    // writing holds it until that child execs, and until then running the
    // copy fails with "Text file busy" (ETXTBSY). Once one run starts,
    // nobody can hold it any more.
    let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
    loop {
        match Command::new(&bin).arg("--version").output() {
            Err(e)
                if e.raw_os_error() == Some(libc::ETXTBSY) && std::time::Instant::now() < end =>
            {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            r => {
                r.unwrap();
                break;
            }
        }
    }
    let work = dir.path().join("work");
    let home = dir.path().join("home");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&home).unwrap();
    Alone {
        bin,
        work,
        home,
        _dir: dir,
    }
}

impl Alone {
    fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new(&self.bin);
        c.args(args)
            .current_dir(&self.work)
            .env("HOME", &self.home)
            .env_remove("XDG_CONFIG_HOME")
            .env("XDG_STATE_HOME", self.home.join("state"));
        c
    }

    fn run(&self, args: &[&str]) -> (bool, String) {
        let o = self.command(args).output().unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        (o.status.success(), text)
    }
}

/// A bright square on a dark ground, 64².
fn square() -> ImgFile {
    let mut g = GreyImage::filled(64, 64, 40).unwrap();
    for y in 16..48 {
        for x in 18..46 {
            g.data_mut()[y * 64 + x] = 200;
        }
    }
    ImgFile::new(g)
}

#[test]
fn the_binary_alone_starts_the_console_and_runs_llv() {
    let a = alone();
    let pty = native_pty_system();
    let size = PtySize {
        rows: 24,
        cols: 80,
        pixel_width: 0,
        pixel_height: 0,
    };
    let pair = pty.openpty(size).unwrap();
    let mut cmd = CommandBuilder::new(&a.bin);
    cmd.cwd(&a.work);
    cmd.env("TERM", "xterm-256color");
    cmd.env("HOME", &a.home);
    cmd.env_remove("XDG_CONFIG_HOME");
    cmd.env("XDG_STATE_HOME", a.home.join("state"));
    let mut child = pair.slave.spawn_command(cmd).unwrap();
    drop(pair.slave);
    let mut reader = pair.master.try_clone_reader().unwrap();
    let mut writer = pair.master.take_writer().unwrap();
    let parser = Arc::new(Mutex::new(vt100::Parser::new(24, 80, 0)));
    let p = parser.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 8192];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            p.lock().unwrap().process(&buf[..n]);
        }
    });
    let screen = || parser.lock().unwrap().screen().contents();
    let end = Instant::now() + Duration::from_secs(60);
    while !(screen().contains("simulated cell") && screen().contains("Survey")) {
        if Instant::now() > end || child.try_wait().unwrap().is_some() {
            let _ = child.kill();
            panic!("no first screen from the binary alone:\n{}", screen());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    writer.write_all(b"q").unwrap();
    writer.flush().unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > end {
            let _ = child.kill();
            panic!("the console did not quit:\n{}", screen());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status:?}");

    // `vss llv` on an image in the folder, with the built-in parameters.
    vss::formats::img::write_img(&a.work.join("box1a.img"), &square()).unwrap();
    let (ok, text) = a.run(&["llv", "box1a.img"]);
    assert!(ok, "{text}");
    let lines = vss::formats::lines::read_lines(&a.work.join("box1.ldr")).unwrap();
    assert!(lines.len() >= 4, "{text}");

    // A session with the built-in cameras' descriptions.
    let (ok, text) = a.run(&["session", "new", "cube", "--dir", "."]);
    assert!(ok && !text.contains("warning"), "{text}");
    let cdf = std::fs::read_to_string(a.work.join("cube/cube2.cdf")).unwrap();
    let want = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/profiles/sim/cam2.cdf"
    ))
    .unwrap();
    assert_eq!(cdf, want, "camera 2's built-in .cdf");
}

/// A profile that differs from the default in its name alone.
fn named(name: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/profiles/default.toml"
    ))
    .unwrap();
    text.replacen(
        "name = \"simulated cell\"",
        &format!("name = \"{name}\""),
        1,
    )
}

fn put(dir: &Path, file: &str, text: &str) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join(file), text).unwrap();
}

/// The profile name a new session records.
fn profile_of(a: &Alone, args: &[&str], session: &str) -> String {
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["session", "new", session, "--dir", "."]);
    let (ok, text) = a.run(&all);
    assert!(ok, "{args:?}: {text}");
    let m = std::fs::read_to_string(a.work.join(format!("{session}/{session}.toml"))).unwrap();
    let line = m.lines().find(|l| l.starts_with("profile = ")).unwrap();
    line.trim_start_matches("profile = ")
        .trim_matches('"')
        .to_string()
}

#[test]
fn profiles_are_found_here_then_in_the_config_folder_then_built_in() {
    let a = alone();
    let user = a.home.join(".config/vss/profiles");
    // Nothing anywhere: the built-in default.
    assert_eq!(profile_of(&a, &[], "s1"), "simulated cell");
    put(&user, "cell.toml", &named("user cell"));
    put(&user, "default.toml", &named("user default"));
    assert_eq!(profile_of(&a, &["--profile", "cell"], "s2"), "user cell");
    assert_eq!(
        profile_of(&a, &[], "s3"),
        "user default",
        "a user default.toml wins"
    );
    put(&a.work.join("profiles"), "cell.toml", &named("local cell"));
    assert_eq!(profile_of(&a, &["--profile", "cell"], "s4"), "local cell");
    put(&a.work, "mine.toml", &named("by path"));
    assert_eq!(profile_of(&a, &["--profile", "mine.toml"], "s5"), "by path");
    // XDG_CONFIG_HOME, when set, is the config folder.
    let xdg = a.home.join("xdg");
    put(&xdg.join("vss/profiles"), "other.toml", &named("xdg other"));
    let o = a
        .command(&["--profile", "other", "session", "new", "s6", "--dir", "."])
        .env("XDG_CONFIG_HOME", &xdg)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    assert!(
        std::fs::read_to_string(a.work.join("s6/s6.toml"))
            .unwrap()
            .contains("xdg other")
    );
    // A name found nowhere says where it looked.
    let (ok, text) = a.run(&["--profile", "nowhere", "session", "new", "s7"]);
    assert!(!ok);
    assert!(
        text.contains("profile `nowhere` not found")
            && text.contains("profiles/nowhere.toml")
            && text.contains(".config/vss/profiles/nowhere.toml"),
        "{text}"
    );
}
