//! Who holds a serial port that would not open, so that an operator reads
//! "in use by vss (process 4242)" (another console on this cell) rather
//! than a lock error that sends them to check the cable: the process that
//! holds the device's lock (`/proc/locks`: vss and serialport lock a port
//! with `flock`), else the first with it open (`/proc/*/fd`, as `fuser`
//! finds it; a pseudo-terminal's own end is open in the program that made
//! it, which is why the lock comes first).
//!
//! What is read is only shown, never acted on: a process can end or a
//! number be reused between the reading and the operator's reading. Its
//! name is shown without control characters (a process names itself).

use std::path::Path;

/// "vss (process 4242)", or "another program" when no process with the
/// port open can be seen (another user's processes are not readable
/// without root; on other systems there is no `/proc`).
pub fn describe(port: &Path) -> String {
    match holder(port) {
        Some((pid, name)) => format!("{name} (process {pid})"),
        None => "another program".to_string(),
    }
}

/// The process holding `port`'s lock (this one too: a port opened twice),
/// else the first other process with it
/// (links resolved) open; and its name.
fn holder(port: &Path) -> Option<(u32, String)> {
    let target = std::fs::canonicalize(port).ok()?;
    let me = std::process::id();
    let locks = std::fs::read_to_string("/proc/locks").unwrap_or_default();
    if let Some(pid) = lock_holder(&locks, &target) {
        let name = if pid == me {
            "this program itself".to_string()
        } else {
            name_of(pid)
        };
        return Some((pid, name));
    }
    let mut pids: Vec<u32> = std::fs::read_dir("/proc")
        .ok()?
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse().ok())
        .filter(|&pid| pid != me)
        .collect();
    pids.sort_unstable();
    pids.into_iter().find_map(|pid| {
        let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).ok()?;
        fds.flatten()
            .any(|fd| std::fs::read_link(fd.path()).is_ok_and(|l| l == target))
            .then(|| (pid, name_of(pid)))
    })
}

/// The process that holds a lock on `file` in `locks` (`/proc/locks`:
/// `1: FLOCK  ADVISORY  WRITE 4242 00:1a:16 0 EOF`, the device's major and
/// minor in hex, then the inode; waiters' lines have `->` and are skipped).
fn lock_holder(locks: &str, file: &Path) -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(file).ok()?;
    let dev = m.dev();
    let (major, minor) = (
        ((dev >> 8) & 0xfff) | ((dev >> 32) & !0xfff),
        (dev & 0xff) | ((dev >> 12) & !0xff),
    );
    let want = format!("{major:02x}:{minor:02x}:{}", m.ino());
    locks.lines().find_map(|l| {
        let f: Vec<&str> = l.split_whitespace().collect();
        match f.as_slice() {
            [_, _kind, _, _, pid, at, ..] if *at == want => pid.parse().ok(),
            _ => None,
        }
    })
}

/// A process's name (`comm`), printable characters only.
fn name_of(pid: u32) -> String {
    let raw = std::fs::read_to_string(format!("/proc/{pid}/comm")).unwrap_or_default();
    let name: String = raw
        .trim_end_matches('\n')
        .chars()
        .filter(|c| !c.is_control())
        .take(32)
        .collect();
    if name.is_empty() {
        "a process".to_string()
    } else {
        name
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What [`describe`] says of `asked` while `sh -c script FILE` runs
    /// (it says "ready" once it holds what it holds), and the shell's
    /// process number.
    fn while_held(script: &str, file: &Path, asked: &Path) -> (String, u32) {
        let mut child = std::process::Command::new("sh")
            .arg("-c")
            .arg(script)
            .arg("sh")
            .arg(file)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut out = child.stdout.take().unwrap();
        let mut buf = [0u8; 6];
        std::io::Read::read_exact(&mut out, &mut buf).unwrap();
        let said = describe(asked);
        drop(child.stdin.take());
        child.wait().unwrap();
        (said, child.id())
    }

    #[test]
    fn finds_the_process_that_holds_a_file_open_through_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("port");
        std::fs::write(&file, b"").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        assert_eq!(describe(&link), "another program", "nobody holds it yet");
        // A child holds it open (this process's own files do not count).
        let (said, sh) = while_held("exec 3<\"$1\"; echo ready; read _", &file, &link);
        assert_eq!(said, format!("sh (process {sh})"));
    }

    #[test]
    fn the_process_holding_the_lock_comes_before_others_with_it_open() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("port");
        std::fs::write(&file, b"").unwrap();
        // `sh` opens the file, then `flock`, its child, locks it (its own
        // open file) while `sh` still has it open.
        let (said, sh) = while_held(
            "exec 3<\"$1\"; flock \"$1\" sh -c 'echo ready; read _'",
            &file,
            &file,
        );
        // The first `sh` (the lowest process number with the file open)
        // does not hold the lock; `flock` does.
        assert!(said.starts_with("flock (process "), "{said}");
        assert_ne!(said, format!("flock (process {sh})"));
    }
}
