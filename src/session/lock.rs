//! The session lock: `NAME.lock` in the session folder, holding who writes
//! the session (pid, host, user, start time). It keeps a second console — or
//! a second SSH login — from writing the same survey.
//!
//! The lock file appears with its content complete: it is written to a
//! temporary file and hard-linked into place, which fails if a lock exists.
//! A lock is stale when its holder ran on this host and that process is gone
//! (checked through `/proc`, including the process start time so a reused
//! pid is not mistaken for the holder), or when the process it names is not
//! a vss at all (a lock file anyone could have planted). A stale lock, or one
//! held on another host, can be taken over on request; a live holder on this
//! host never — it can only be asked to leave ([`ask_holder_to_leave`]), and
//! only when the process is provably the lock's vss: same start time, same
//! user, a vss executable.
//!
//! Each lock carries a random token, so a writer can tell that the lock is
//! still its own ([`Lock::check_held`]) even against a holder with the same
//! pid and host: after a take-over, the displaced writer's saves fail.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{SessionError, stamp};

/// The largest lock file read (a real one is about 150 bytes).
const MAX_LOCK_LEN: u64 = 64 << 10;

/// Who holds a lock.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LockInfo {
    pub pid: u32,
    pub host: String,
    pub user: String,
    /// When the holder took the lock (UTC, RFC 3339).
    pub started: String,
    /// The holder's process start time (clock ticks since boot, from
    /// `/proc/PID/stat`); 0 when unknown.
    #[serde(default)]
    pub proc_start: u64,
    /// Random, different for every lock taken: tells this lock from any
    /// other with the same holder fields. Empty in older lock files.
    #[serde(default)]
    pub token: String,
}

impl std::fmt::Display for LockInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // The lock file may have been tampered with: no control characters
        // reach the terminal.
        let clean = crate::formats::sanitize;
        write!(
            f,
            "process {} of user {} on host {}, since {}",
            self.pid,
            clean(&self.user),
            clean(&self.host),
            clean(&self.started)
        )
    }
}

impl LockInfo {
    /// This process.
    pub fn current() -> LockInfo {
        let pid = std::process::id();
        LockInfo {
            pid,
            host: hostname(),
            user: username(),
            started: stamp::now_rfc3339(),
            proc_start: proc_start(pid).unwrap_or(0),
            token: random_token(),
        }
    }

    /// Whether the holder is certainly gone: it ran on this host and its
    /// process no longer exists (or is a zombie, or is another process that
    /// reused the pid).
    ///
    /// A process that is certainly not a vss (its executable is readable
    /// and is something else) is not the holder either: the lock was left
    /// by a vss whose pid was reused, or planted.
    pub fn is_stale(&self) -> bool {
        if self.host != hostname() || !Path::new("/proc/self/stat").exists() {
            return false;
        }
        match proc_start(self.pid) {
            None => true,
            Some(start) if self.proc_start != 0 && start != self.proc_start => true,
            Some(_) => exe_is_vss(self.pid) == Some(false),
        }
    }
}

/// Asks the live holder of a lock on this host to end (SIGTERM: a vss
/// console finishes its saves and releases the lock, as on a hang-up) —
/// only when the process is provably that holder: its start time is the
/// lock's `proc_start`, it runs as this user, and its executable is vss.
/// The signal goes through the `kill` system call, not a program found on
/// `PATH`. `Err` says why nothing was signalled.
///
/// SIGCONT follows: a console suspended with Ctrl-Z in a shell still
/// running (a detached tmux) can only act on SIGTERM once continued; it
/// then ends without taking the terminal again. Before, the take-over of
/// a suspended console failed ("still held … after asking it to end") and
/// the console ended the moment its operator brought it back with `fg`.
pub fn ask_holder_to_leave(holder: &LockInfo) -> Result<(), String> {
    let pid = holder.pid;
    provably_vss(holder, "the lock's holder")?;
    let pid_t = i32::try_from(pid)
        .ok()
        .and_then(rustix::process::Pid::from_raw)
        .ok_or_else(|| format!("process {pid}: not a pid"))?;
    rustix::process::kill_process(pid_t, rustix::process::Signal::TERM)
        .map_err(|e| format!("cannot signal process {pid}: {e}"))?;
    rustix::process::kill_process(pid_t, rustix::process::Signal::CONT)
        .map_err(|e| format!("cannot continue process {pid}: {e}"))
}

/// Whether `who` names a live vss of this user on this host, provably:
/// its pid runs with the start time `who` records, as this user, from a
/// vss executable. `Err` says which check failed; `role` names `who` in it.
fn provably_vss(who: &LockInfo, role: &str) -> Result<(), String> {
    let pid = who.pid;
    if who.host != hostname() {
        return Err(format!(
            "{role} runs on host {}, not this one",
            crate::formats::sanitize(&who.host)
        ));
    }
    if pid <= 1 || pid == std::process::id() {
        return Err(format!("process {pid} cannot be {role}"));
    }
    let Some(start) = proc_start(pid) else {
        return Err(format!("process {pid} no longer runs"));
    };
    if who.proc_start == 0 {
        return Err(format!(
            "{role} records no start time, so process {pid} cannot be told from another"
        ));
    }
    if start != who.proc_start {
        return Err(format!(
            "process {pid} started at another time than {role}: it is another process"
        ));
    }
    if proc_uid(pid) != proc_uid(std::process::id()) {
        return Err(format!("process {pid} belongs to another user"));
    }
    if exe_is_vss(pid) != Some(true) {
        return Err(format!("process {pid} is not a vss"));
    }
    Ok(())
}

/// A request to the holder of a lock to release it, in `NAME.lock.leave`
/// beside the lock ([`request_leave`]): the holding console watches for it
/// and leaves the session cleanly. It is only a request: the holder
/// checks it ([`Lock::leave_requested`]) and acts on nothing it names
/// without that.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LeaveRequest {
    /// The token of the lock asked for: a request for another lock (an
    /// earlier holder's) is void.
    pub token: String,
    /// Who asks: a vss on this host, shown to the holder once checked.
    pub from: LockInfo,
}

/// The request file of the lock at `lock`: `NAME.lock.leave`.
pub fn leave_path(lock: &Path) -> PathBuf {
    let mut name = lock.file_name().unwrap_or_default().to_os_string();
    name.push(".leave");
    lock.with_file_name(name)
}

/// Asks the holder of the lock at `lock` (`holder`, as read from it) to
/// release it: writes [`leave_path`] atomically (never through a link),
/// naming the lock's token and this process. The taker then waits for the
/// lock to go, and signals only if it does not ([`ask_holder_to_leave`]).
pub fn request_leave(lock: &Path, holder: &LockInfo) -> io::Result<()> {
    let req = LeaveRequest {
        token: holder.token.clone(),
        from: LockInfo::current(),
    };
    let text = toml::to_string(&req).map_err(io::Error::other)?;
    crate::fsutil::write_atomic(&leave_path(lock), text.as_bytes())
}

/// The owner of `/proc/PID` (the process's effective user).
fn proc_uid(pid: u32) -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    fs::metadata(format!("/proc/{pid}")).ok().map(|m| m.uid())
}

/// Whether process `pid` runs vss: its executable is named `vss` or is this
/// program. `None` when that cannot be read (another user's process).
fn exe_is_vss(pid: u32) -> Option<bool> {
    let exe = fs::read_link(format!("/proc/{pid}/exe")).ok()?;
    // A binary replaced since it started reads as "PATH (deleted)".
    let text = exe.to_string_lossy();
    let exe = PathBuf::from(text.strip_suffix(" (deleted)").unwrap_or(&text));
    let named_vss = exe.file_name().is_some_and(|n| n == "vss");
    let this = std::env::current_exe().is_ok_and(|me| me == exe);
    Some(named_vss || this)
}

/// 16 hex digits from the standard library's randomly seeded hasher.
fn random_token() -> String {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    h.write_u32(std::process::id());
    format!("{:016x}", h.finish())
}

/// A held lock; released (the file removed) on drop if it is still ours.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    info: LockInfo,
    /// The session folder as it was when the lock was taken (device and
    /// inode), to tell a lock taken over from a folder moved away.
    folder: Option<(u64, u64)>,
}

/// The folder of the lock file at `path`.
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The device and inode of folder `dir`, not followed if it is a link.
fn identity(dir: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    fs::symlink_metadata(dir)
        .ok()
        .filter(fs::Metadata::is_dir)
        .map(|m| (m.dev(), m.ino()))
}

/// The session folder a lock was taken in is no longer at its path: moved,
/// renamed or deleted while the session was open (and maybe another folder
/// made in its place). Nothing is written then: not at the path, which is
/// not the session's, and not where the folder went, which is not known.
#[derive(Debug, thiserror::Error)]
#[error(
    "the session folder {} {}: this change was NOT saved, and nothing was written anywhere \
     else; put the folder back where it was and try again, or open the session where it now is",
    crate::text::path(dir),
    if *replaced {
        "is not the one opened (it was moved or deleted and another folder made in its place)"
    } else {
        "is gone (moved, renamed or deleted since it was opened)"
    }
)]
pub struct FolderGone {
    pub dir: PathBuf,
    pub replaced: bool,
}

impl Lock {
    /// Takes the lock at `path`, or reports who holds it.
    /// With `take_over`, replaces a stale lock or one held on another host.
    pub fn acquire(path: &Path, take_over: bool) -> Result<Lock, SessionError> {
        let info = LockInfo::current();
        let text = toml::to_string(&info).map_err(|e| SessionError::Io {
            path: path.to_path_buf(),
            source: io::Error::other(e),
        })?;
        let io_err = |source| SessionError::Io {
            path: path.to_path_buf(),
            source,
        };
        let dir = folder_of(path);
        // The folder itself, never through a link to one.
        let folder = super::folder::unlinked(dir)?;
        let name = path.file_name().unwrap_or_default();
        // Created exclusively under a random name: a link planted in the
        // folder is never written through. (No sweep of stale temporary
        // files here: the session's first write does it, and a lock is
        // taken again quickly when a console closes and reopens.)
        let (mut file, tmp) =
            crate::fsutil::create_temp(dir, name).map_err(|source| match source.kind() {
                io::ErrorKind::PermissionDenied | io::ErrorKind::ReadOnlyFilesystem => {
                    SessionError::Unwritable {
                        path: path.to_path_buf(),
                        source,
                    }
                }
                _ => io_err(source),
            })?;
        // No fsync: a lock torn by a crash reads as an unknown holder, which
        // can be taken over.
        if let Err(e) = file.write_all(text.as_bytes()) {
            let _ = fs::remove_file(&tmp);
            return Err(io_err(e));
        }
        drop(file);
        let linked = fs::hard_link(&tmp, path);
        let result = match linked {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                let holder = read_holder(path);
                let stale = holder.as_ref().is_none_or(LockInfo::is_stale);
                let foreign = holder.as_ref().is_some_and(|h| h.host != info.host);
                if take_over && (stale || foreign) {
                    // rename replaces atomically: whoever reads the lock sees
                    // the old or the new holder, never nothing.
                    fs::rename(&tmp, path).map_err(io_err)
                } else {
                    Err(SessionError::Locked {
                        path: path.to_path_buf(),
                        holder: holder.map_or_else(
                            || "an unknown holder (the lock file is unreadable)".to_string(),
                            |h| h.to_string(),
                        ),
                        stale,
                        foreign,
                    })
                }
            }
            Err(e) => Err(io_err(e)),
        };
        let _ = fs::remove_file(&tmp);
        result?;
        // Two take-overs may race: the last rename wins, the loser learns it here.
        match read_holder(path) {
            Some(h) if h == info => {
                let lock = Lock {
                    path: path.to_path_buf(),
                    info,
                    folder: Some(folder),
                };
                // Taken in the folder looked at, not in a link put in its
                // place meanwhile (dropped, the lock is removed again).
                lock.check_held()?;
                Ok(lock)
            }
            h => Err(SessionError::Locked {
                path: path.to_path_buf(),
                holder: h.map_or_else(|| "an unknown holder".to_string(), |h| h.to_string()),
                stale: false,
                foreign: false,
            }),
        }
    }

    pub fn info(&self) -> &LockInfo {
        &self.info
    }

    /// The lock file at `path()`.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A request to release this lock ([`request_leave`]), checked: `None`
    /// without one; `Some(Ok(asker))` when it names this lock's token and
    /// its asker is provably a live vss of this user on this host (the
    /// checks [`ask_holder_to_leave`] makes before a signal); `Some(Err)`
    /// saying why a request file there is not one to act on (unreadable,
    /// for another lock, from a process that is not a vss). Either way the
    /// request file is then removed: it is read once.
    pub fn leave_requested(&self) -> Option<Result<LockInfo, String>> {
        let path = leave_path(&self.path);
        if fs::symlink_metadata(&path).is_err() {
            return None;
        }
        let read = crate::fsutil::read_input_text(&path, MAX_LOCK_LEN)
            .map_err(|e| format!("{}: {e}", crate::text::path(&path)))
            .and_then(|text| {
                toml::from_str::<LeaveRequest>(&text).map_err(|e| {
                    format!(
                        "{}: not a request: {}",
                        crate::text::path(&path),
                        e.message()
                    )
                })
            });
        // Removed whatever it holds (a link is removed, not its target).
        let _ = fs::remove_file(&path);
        let req = match read {
            Ok(r) => r,
            Err(why) => return Some(Err(why)),
        };
        if req.token != self.info.token {
            return Some(Err(format!(
                "{}: the request is for another lock than this console's",
                crate::text::path(&path)
            )));
        }
        Some(provably_vss(&req.from, "the asker").map(|()| req.from))
    }

    /// Checks that the lock file still names this lock: after a take-over
    /// (or a removed lock) this writer no longer owns the session, and its
    /// saves must fail rather than overwrite the new holder's.
    /// A lock file that is gone because its folder is (moved, renamed or
    /// deleted) is said as that ([`FolderGone`]), not as a take-over.
    pub fn check_held(&self) -> Result<(), SessionError> {
        // The folder first: one moved away, or replaced (by another
        // folder, or by a link to one), is not written whatever it holds.
        let dir = folder_of(&self.path);
        if self.folder.is_some() && identity(dir) != self.folder {
            return Err(SessionError::FolderGone(FolderGone {
                dir: dir.to_path_buf(),
                replaced: fs::symlink_metadata(dir).is_ok(),
            }));
        }
        match read_holder(&self.path) {
            Some(h) if h == self.info => Ok(()),
            h => Err(SessionError::LockLost {
                path: self.path.clone(),
                holder: h.map_or_else(
                    || "nobody (the lock file is gone or unreadable)".to_string(),
                    |h| h.to_string(),
                ),
            }),
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        if read_holder(&self.path).is_some_and(|h| h == self.info) {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// The holder named in a lock file, if it can be read.
pub fn read_holder(path: &Path) -> Option<LockInfo> {
    let text = crate::fsutil::read_input_text(path, MAX_LOCK_LEN).ok()?;
    toml::from_str(&text).ok()
}

fn hostname() -> String {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|p| {
            let s = fs::read_to_string(p).ok()?;
            let s = s.trim();
            (!s.is_empty()).then(|| s.to_string())
        })
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_else(|| "unknown-host".to_string())
}

/// The largest `/etc/passwd` read for the user's name.
const MAX_PASSWD_LEN: u64 = 16 << 20;

/// Who runs this process: `USER` or `LOGNAME`, else the name
/// `/etc/passwd` gives the uid (a console started by a service or `env -u
/// USER` has neither variable), else "uid N".
fn username() -> String {
    for var in ["USER", "LOGNAME"] {
        if let Ok(u) = std::env::var(var)
            && !u.is_empty()
        {
            return u;
        }
    }
    let uid = rustix::process::getuid().as_raw();
    passwd_name(Path::new("/etc/passwd"), uid).unwrap_or_else(|| format!("uid {uid}"))
}

/// The name the passwd file at `path` gives `uid` (its first entry for
/// it), read through the bounded reader; none when the file does not read
/// or has no entry.
fn passwd_name(path: &Path, uid: u32) -> Option<String> {
    let bytes = crate::fsutil::read_input(path, MAX_PASSWD_LEN).ok()?;
    String::from_utf8_lossy(&bytes).lines().find_map(|l| {
        let mut f = l.split(':');
        let name = f.next()?;
        let _password = f.next()?;
        let id: u32 = f.next()?.trim().parse().ok()?;
        (id == uid && !name.is_empty()).then(|| name.to_string())
    })
}

/// Start time (field 22 of `/proc/PID/stat`) of a live, non-zombie process.
fn proc_start(pid: u32) -> Option<u64> {
    let stat = fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) may hold spaces and parentheses: split
    // after the last ')'.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // fields[0] is field 3 (state); field 22 is fields[19].
    if matches!(fields.first(), Some(&"Z") | Some(&"X")) {
        return None;
    }
    fields.get(19)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_user_is_named_from_the_passwd_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("passwd");
        fs::write(
            &p,
            "root:x:0:0:root:/root:/bin/sh\n# note\n\nbad line\nop:x:1000:1000::/home/op:/bin/sh\nop2:x:1000:1000::/:/bin/sh\n",
        )
        .unwrap();
        assert_eq!(passwd_name(&p, 0).as_deref(), Some("root"));
        assert_eq!(
            passwd_name(&p, 1000).as_deref(),
            Some("op"),
            "the first entry"
        );
        assert_eq!(passwd_name(&p, 7), None, "no entry: the caller says uid 7");
        assert_eq!(passwd_name(&dir.path().join("none"), 0), None);
    }

    #[test]
    fn second_holder_is_refused_and_release_frees() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.lock");
        let a = Lock::acquire(&p, false).unwrap();
        let err = Lock::acquire(&p, false).unwrap_err().to_string();
        assert!(
            err.contains(&format!("process {}", std::process::id())),
            "{err}"
        );
        // Our own live process: not stale, no take-over.
        assert!(Lock::acquire(&p, true).is_err());
        drop(a);
        assert!(!p.exists());
        let _b = Lock::acquire(&p, false).unwrap();
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "no temp left");
    }

    #[test]
    fn dead_holder_is_stale_and_can_be_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.lock");
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let ghost = LockInfo {
            pid: dead,
            proc_start: 12345,
            ..LockInfo::current()
        };
        fs::write(&p, toml::to_string(&ghost).unwrap()).unwrap();
        assert!(ghost.is_stale());
        let err = Lock::acquire(&p, false).unwrap_err().to_string();
        assert!(err.contains("take-over"), "{err}");
        let l = Lock::acquire(&p, true).unwrap();
        assert_eq!(read_holder(&p).unwrap(), *l.info());
    }

    /// A child running `sleep`, copied to `dir/name` first when given.
    fn sleeper(dir: &Path, name: Option<&str>) -> std::process::Child {
        let sleep = ["/bin/sleep", "/usr/bin/sleep"]
            .into_iter()
            .find(|p| Path::new(p).exists())
            .expect("sleep");
        let exe = match name {
            Some(n) => {
                let to = dir.join(n);
                fs::copy(sleep, &to).unwrap();
                to
            }
            None => PathBuf::from(sleep),
        };
        // A copy just written may be "text file busy" while another test
        // thread forks: try again.
        for _ in 0..50 {
            match std::process::Command::new(&exe).arg("30").spawn() {
                Ok(c) => return c,
                Err(e) if e.raw_os_error() == Some(libc::ETXTBSY) => {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                Err(e) => panic!("{}: {e}", exe.display()),
            }
        }
        panic!("{}: text file busy", exe.display())
    }

    /// Issue 34, N2: a planted lock naming a live process that is not a
    /// vss console gets it no signal, with or without its start time, and
    /// the lock is stale; a process that is the lock's vss is asked.
    #[test]
    fn only_the_locks_own_vss_is_signalled() {
        use std::os::unix::process::ExitStatusExt;
        let dir = tempfile::tempdir().unwrap();
        let mut victim = sleeper(dir.path(), None);
        let pid = victim.id();
        let start = proc_start(pid).expect("running");
        for proc_start in [start, 0] {
            let planted = LockInfo {
                pid,
                proc_start,
                ..LockInfo::current()
            };
            let why = ask_holder_to_leave(&planted).expect_err("sleep is not a vss");
            assert!(why.contains(&pid.to_string()), "{why}");
            assert!(planted.is_stale(), "a lock naming `sleep` is not held");
        }
        // Through the session's lock: taken over, nobody signalled.
        let p = dir.path().join("s.lock");
        let planted = LockInfo {
            pid,
            proc_start: start,
            ..LockInfo::current()
        };
        fs::write(&p, toml::to_string(&planted).unwrap()).unwrap();
        assert!(Lock::acquire(&p, true).is_ok());
        std::thread::sleep(std::time::Duration::from_millis(100));
        assert!(victim.try_wait().unwrap().is_none(), "sleep was signalled");
        victim.kill().unwrap();
        victim.wait().unwrap();

        // A vss with the lock's start time: asked to end (SIGTERM)…
        let mut vss = sleeper(dir.path(), Some("vss"));
        let pid = vss.id();
        let start = proc_start(pid).expect("running");
        let wrong = LockInfo {
            pid,
            proc_start: start + 1,
            ..LockInfo::current()
        };
        // …but not when the start time differs (a reused pid) or is unknown.
        assert!(ask_holder_to_leave(&wrong).is_err());
        let unknown = LockInfo {
            proc_start: 0,
            ..wrong.clone()
        };
        assert!(ask_holder_to_leave(&unknown).is_err());
        assert!(!unknown.is_stale(), "a live vss without a start time");
        assert!(vss.try_wait().unwrap().is_none());
        let holder = LockInfo {
            proc_start: start,
            ..wrong
        };
        assert!(!holder.is_stale());
        assert_eq!(ask_holder_to_leave(&holder), Ok(()));
        assert_eq!(vss.wait().unwrap().signal(), Some(libc::SIGTERM));
    }

    /// Issue 34: a request to leave is acted on only when it names this
    /// lock and comes from a live vss of this user (trust no file); read
    /// once, whatever it holds.
    #[test]
    fn a_request_to_leave_is_checked_before_it_counts() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.lock");
        let lock = Lock::acquire(&p, false).unwrap();
        let req = leave_path(&p);
        assert_eq!(req, dir.path().join("s.lock.leave"));
        assert!(lock.leave_requested().is_none(), "no request");
        let plant = |token: &str, from: &LockInfo| {
            let r = LeaveRequest {
                token: token.into(),
                from: from.clone(),
            };
            fs::write(&req, toml::to_string(&r).unwrap()).unwrap();
        };
        let mut victim = sleeper(dir.path(), None);
        let mut asker = sleeper(dir.path(), Some("vss"));
        let as_proc = |c: &std::process::Child| LockInfo {
            pid: c.id(),
            proc_start: proc_start(c.id()).unwrap(),
            ..LockInfo::current()
        };
        let token = lock.info().token.clone();
        for (t, from, why) in [
            ("0123", as_proc(&asker), "another lock"),
            (token.as_str(), as_proc(&victim), "not a vss"),
            (
                token.as_str(),
                LockInfo {
                    proc_start: 1,
                    ..as_proc(&asker)
                },
                "another process",
            ),
            (token.as_str(), LockInfo::current(), "cannot be"),
        ] {
            plant(t, &from);
            let e = lock.leave_requested().expect("a request").unwrap_err();
            assert!(e.contains(why), "{why}: {e}");
            assert!(!req.exists(), "read once");
        }
        fs::write(&req, "garbage").unwrap();
        assert!(lock.leave_requested().unwrap().is_err());
        std::os::unix::fs::symlink("/dev/zero", &req).unwrap();
        assert!(lock.leave_requested().unwrap().is_err());
        assert!(!req.exists() && Path::new("/dev/zero").exists());
        // Through request_leave, from a vss: it counts, and says who asked.
        let from = as_proc(&asker);
        plant(&token, &from);
        assert_eq!(lock.leave_requested(), Some(Ok(from)));
        request_leave(&p, lock.info()).unwrap();
        let e = lock.leave_requested().unwrap().unwrap_err();
        assert!(e.contains("cannot be"), "this process asks itself: {e}");
        for c in [&mut victim, &mut asker] {
            c.kill().unwrap();
            c.wait().unwrap();
        }
    }

    #[test]
    fn a_taken_over_lock_is_no_longer_held() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.lock");
        let a = Lock::acquire(&p, false).unwrap();
        assert!(a.check_held().is_ok());
        // The holder seen from another host: taken over from there.
        let mut other = a.info().clone();
        other.host = "cell-pc-2".into();
        other.token = random_token();
        fs::write(&p, toml::to_string(&other).unwrap()).unwrap();
        let e = a.check_held().expect_err("taken over").to_string();
        assert!(e.contains("cell-pc-2") && e.contains("NOT saved"), "{e}");
        // Same pid, host and second, another lock: told apart by the token.
        fs::remove_file(&p).unwrap();
        let b = Lock::acquire(&p, false).unwrap();
        assert!(b.check_held().is_ok() && a.check_held().is_err());
    }

    #[test]
    fn a_folder_moved_away_is_said_as_gone_not_as_a_take_over() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("s");
        fs::create_dir(&dir).unwrap();
        let a = Lock::acquire(&dir.join("s.lock"), false).unwrap();
        // Renamed while open: gone, not taken over.
        fs::rename(&dir, root.path().join("t")).unwrap();
        let e = a.check_held().expect_err("moved").to_string();
        assert!(
            e.contains("is gone (moved") && e.contains("NOT saved"),
            "{e}"
        );
        assert!(!e.contains("taken over"), "{e}");
        // Another folder made in its place.
        fs::create_dir(&dir).unwrap();
        let e = a.check_held().expect_err("replaced").to_string();
        assert!(e.contains("is not the one opened"), "{e}");
        // Put back: held again.
        fs::remove_dir(&dir).unwrap();
        fs::rename(root.path().join("t"), &dir).unwrap();
        assert!(a.check_held().is_ok());
        // Its lock removed in its own folder is still a lost lock.
        fs::remove_file(dir.join("s.lock")).unwrap();
        let e = a.check_held().expect_err("lock gone").to_string();
        assert!(e.contains("held by nobody"), "{e}");
    }

    #[test]
    fn own_process_is_alive() {
        assert!(!LockInfo::current().is_stale());
    }
}
