//! Taking over a session another console on this host holds (issue 34):
//! by request through the session folder (`NAME.lock.leave`), which the
//! holding console watches — it leaves the session cleanly, stays open and
//! says who took it — and only when no answer comes, by a signal to the
//! lock's own vss. Two real consoles on real ptys.

use std::path::Path;
use std::time::{Duration, Instant};

use vss::session::lock::{LockInfo, leave_path, read_holder};

use super::tui_harness::Console;

/// Field 22 of `/proc/PID/stat`: the process's start time.
fn proc_start(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let rest = &stat[stat.rfind(')').unwrap() + 1..];
    rest.split_whitespace().nth(19).unwrap().parse().unwrap()
}

#[test]
fn a_console_asked_through_the_folder_leaves_the_session_and_stays() {
    let mut a = Console::start(80, 24, &[]);
    a.create_session("cube");
    let lock = a.session().join("cube.lock");
    let a_pid = read_holder(&lock).expect("a holds the lock").pid;
    let mut b = a.another(80, 24);
    b.wait_text("in use by", 10);
    b.send("\r");
    let s = b.wait_text("over anyway?", 10);
    assert!(s.contains("tmux attach"), "{s}");
    let t0 = Instant::now();
    b.yes();
    b.wait_text("session cube open", 20);
    // Answered at once, not after the wait that precedes a signal.
    assert!(
        t0.elapsed() < Duration::from_secs(5),
        "took {:?}",
        t0.elapsed()
    );
    // The first console is still running, without the session, and says
    // who took it; the lock is the second's, the request gone.
    let s = a.wait_words("was taken over by process", 10);
    assert!(s.contains("choose a session"), "back to the list:\n{s}");
    assert_eq!(a.exit_code(), None, "the first console runs on");
    let holder = read_holder(&lock).expect("b holds the lock");
    assert_ne!(holder.pid, a_pid);
    assert!(!leave_path(&lock).exists(), "the request is removed");
    // The second writes the session; the first quits without a question.
    b.send("q");
    b.wait_exit(10);
    a.send("q");
    a.wait_exit(10);
    assert_eq!(a.exit_code(), Some(0));
}

/// A copy of `sleep` named `vss` in `dir`, running: a vss holder that
/// never answers a request.
fn silent_vss(dir: &Path) -> std::process::Child {
    let sleep = ["/bin/sleep", "/usr/bin/sleep"]
        .into_iter()
        .find(|p| Path::new(p).exists())
        .expect("sleep");
    let exe = dir.join("vss");
    std::fs::copy(sleep, &exe).unwrap();
    for _ in 0..50 {
        match std::process::Command::new(&exe).arg("60").spawn() {
            Ok(c) => return c,
            Err(e) if e.raw_os_error() == Some(libc::ETXTBSY) => {
                std::thread::sleep(Duration::from_millis(20))
            }
            Err(e) => panic!("{}: {e}", exe.display()),
        }
    }
    panic!("text file busy")
}

#[test]
fn a_holder_that_does_not_answer_is_signalled_after_the_wait() {
    use std::os::unix::process::ExitStatusExt;
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let bin = tempfile::tempdir().unwrap();
    let mut holder = silent_vss(bin.path());
    let pid = holder.id();
    let mut c = c.restart_after(|dir| {
        let lock = dir.join("sessions/cube/cube.lock");
        let info = LockInfo {
            pid,
            proc_start: proc_start(pid),
            ..LockInfo::current()
        };
        std::fs::write(&lock, toml::to_string(&info).unwrap()).unwrap();
    });
    c.wait_text("in use by", 10);
    c.send("\r");
    c.wait_text("over anyway?", 10);
    let t0 = Instant::now();
    c.yes();
    c.wait_text("session cube open", 30);
    // The request came first, and the signal only after its wait.
    assert!(
        t0.elapsed() >= Duration::from_secs(4),
        "signalled after {:?}",
        t0.elapsed()
    );
    let status = holder.wait().unwrap();
    assert_eq!(status.signal(), Some(libc::SIGTERM));
    assert!(!leave_path(&c.session().join("cube.lock")).exists());
    c.send("q");
    c.wait_exit(10);
}

/// The name `id -un` gives this test's user (from `/etc/passwd`).
fn user_name() -> String {
    let out = std::process::Command::new("id")
        .arg("-un")
        .output()
        .unwrap();
    assert!(out.status.success(), "id -un: {out:?}");
    String::from_utf8(out.stdout).unwrap().trim().to_string()
}

/// A console started without `USER` and `LOGNAME` (`env -u`, a service)
/// names its user in the lock from `/etc/passwd`, not "uid N", and a
/// second console says so.
#[test]
fn the_lock_names_the_user_without_user_in_the_environment() {
    let name = user_name();
    let mut a = Console::start(80, 24, &[("USER", ""), ("LOGNAME", "")]);
    a.create_session("cube");
    let holder = read_holder(&a.session().join("cube.lock")).expect("a holds the lock");
    assert_eq!(holder.user, name, "{holder:?}");
    let mut b = a.another(80, 24);
    let s = b.wait_words("in use by", 10);
    // "(in use by NAME)", wrapped in the session list's column.
    assert!(s.contains(&format!(" {name})")), "{s}");
    b.send("q");
    b.wait_exit(10);
    a.send("q");
    a.wait_exit(10);
}

/// `vss grab --take-over` on a session a live console holds takes it over
/// the way the console does (one function): the console is asked through
/// the folder, saves, leaves and says who took it; the grab captures; the
/// manifest records every image, the console's and the grab's.
#[test]
fn grab_take_over_asks_a_console_that_holds_the_session() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(2);
    let lock = c.session().join("cube.lock");
    let console_pid = read_holder(&lock).expect("the console holds the lock").pid;
    let grab = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
            .current_dir(c.dir.path())
            .env("XDG_STATE_HOME", c.dir.path().join("state"))
            .args(["--profile", "cell.toml", "grab", "--camera", "1"])
            .args([
                "--lighting",
                "a,b,c",
                "--image",
                "3",
                "--session",
                "sessions/cube",
            ])
            .args(extra)
            .stdin(std::process::Stdio::null())
            .output()
            .unwrap()
    };
    // Without --take-over (and no terminal): refused, nothing asked.
    let out = grab(&[]);
    assert!(!out.status.success(), "{out:?}");
    assert_eq!(read_holder(&lock).map(|h| h.pid), Some(console_pid));
    let t0 = Instant::now();
    let out = grab(&["--take-over"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(&format!("asking process {console_pid}")),
        "{err}"
    );
    // Answered by the request, not by the signal after 5 s.
    assert!(!err.contains("did not release"), "{err}");
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
    let s = c.wait_words("was taken over by process", 10);
    assert!(s.contains("choose a session"), "back to the list:\n{s}");
    assert_eq!(c.exit_code(), None, "the console runs on");
    assert!(!lock.exists(), "the grab released the lock");
    assert!(!leave_path(&lock).exists(), "the request is removed");
    let s = vss::session::Session::inspect(&c.session()).unwrap();
    let m = s.manifest();
    for k in 1..=2 {
        let r = m.image(k).unwrap_or_else(|| panic!("image {k} recorded"));
        assert_eq!(r.grey.len(), 3, "image {k}: {r:?}");
        assert!(r.outputs.is_some(), "image {k} accepted: {r:?}");
    }
    let r = m.image(3).expect("the grab's image recorded");
    let letters: String = r.grey.iter().map(|g| g.letter).collect();
    assert_eq!(letters, "abc", "{r:?}");
    c.send("q");
    c.wait_exit(10);
    assert_eq!(c.exit_code(), Some(0));
}
