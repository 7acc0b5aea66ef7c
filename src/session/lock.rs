//! The session lock: `NAME.lock` in the session folder, holding who writes
//! the session (pid, host, user, start time). It keeps a second console — or
//! a second SSH login — from writing the same survey.
//!
//! The lock file appears with its content complete: it is written to a
//! temporary file and hard-linked into place, which fails if a lock exists.
//! A lock is stale when its holder ran on this host and that process is gone
//! (checked through `/proc`, including the process start time so a reused
//! pid is not mistaken for the holder). A stale lock, or one held on another
//! host, can be taken over on request; a live holder on this host never.

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
        }
    }

    /// Whether the holder is certainly gone: it ran on this host and its
    /// process no longer exists (or is a zombie, or is another process that
    /// reused the pid).
    pub fn is_stale(&self) -> bool {
        if self.host != hostname() || !Path::new("/proc/self/stat").exists() {
            return false;
        }
        match proc_start(self.pid) {
            None => true,
            Some(start) => self.proc_start != 0 && start != self.proc_start,
        }
    }
}

/// A held lock; released (the file removed) on drop if it is still ours.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    info: LockInfo,
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
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let name = path.file_name().unwrap_or_default();
        // Created exclusively under a random name: a link planted in the
        // folder is never written through. (No sweep of stale temporary
        // files here: the session's first write does it, and a lock is
        // taken again quickly when a console closes and reopens.)
        let (mut file, tmp) = crate::fsutil::create_temp(dir, name).map_err(io_err)?;
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
            Some(h) if h == info => Ok(Lock {
                path: path.to_path_buf(),
                info,
            }),
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

fn username() -> String {
    for var in ["USER", "LOGNAME"] {
        if let Ok(u) = std::env::var(var)
            && !u.is_empty()
        {
            return u;
        }
    }
    fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Uid:"))
                .and_then(|rest| {
                    rest.split_whitespace()
                        .next()
                        .map(|uid| format!("uid {uid}"))
                })
        })
        .unwrap_or_else(|| "unknown-user".to_string())
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

    #[test]
    fn own_process_is_alive() {
        assert!(!LockInfo::current().is_stale());
    }
}
