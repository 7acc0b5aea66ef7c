//! The console's log file: every message of the run appended as it comes,
//! flushed to disk, so it outlives a crash or a dropped connection. It is
//! `NAME.log` in the open session's folder, or `vss/console.log` in the
//! XDG state folder (`$XDG_STATE_HOME`, else `~/.local/state`) while no
//! session is open. The file is opened once and written through that
//! handle; a path that is not a plain file (a symlink, a folder, a FIFO) is
//! refused.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

#[derive(Debug, Default)]
pub struct LogFile {
    file: Option<(PathBuf, File)>,
}

/// The log file while no session is open.
pub fn state_path() -> Option<PathBuf> {
    Some(crate::dirs::state_home()?.join("vss").join("console.log"))
}

impl LogFile {
    pub fn path(&self) -> Option<&Path> {
        self.file.as_ref().map(|(p, _)| p.as_path())
    }

    /// Starts writing to `path` (its folder made if missing).
    pub fn open(&mut self, path: &Path) -> io::Result<()> {
        if self.path() == Some(path) {
            return Ok(());
        }
        self.file = None;
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        // One open that neither follows a link nor waits on a FIFO, then
        // the opened file itself checked: a look at the path before the
        // open would leave a moment for a link to be put in its place.
        let not_plain = || {
            io::Error::other(
                "not a plain file (a symlink, a folder or a FIFO): not written through",
            )
        };
        let f = OpenOptions::new()
            .append(true)
            .create(true)
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
            .open(path)
            .map_err(|e| match e.raw_os_error() {
                Some(libc::ELOOP | libc::EISDIR | libc::ENXIO) => not_plain(),
                _ => e,
            })?;
        if !f.metadata()?.file_type().is_file() {
            return Err(not_plain());
        }
        let mut f = f;
        writeln!(
            f,
            "--- vss console {} (process {}) ---",
            crate::clock::now_rfc3339(),
            std::process::id()
        )?;
        f.sync_data()?;
        self.file = Some((path.to_path_buf(), f));
        Ok(())
    }

    /// Appends lines and flushes them to disk.
    pub fn append(&mut self, lines: &[String]) -> io::Result<()> {
        let Some((_, f)) = self.file.as_mut() else {
            return Ok(());
        };
        let mut text = String::new();
        for l in lines {
            text.push_str(l);
            text.push('\n');
        }
        f.write_all(text.as_bytes())?;
        f.sync_data()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn appends_and_refuses_symlinks() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a/console.log");
        let mut l = LogFile::default();
        l.open(&p).unwrap();
        l.append(&["one".into(), "two".into()]).unwrap();
        let mut again = LogFile::default();
        again.open(&p).unwrap();
        again.append(&["three".into()]).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(
            text.contains("one\ntwo\n") && text.ends_with("three\n"),
            "{text}"
        );
        let link = d.path().join("link.log");
        std::os::unix::fs::symlink(&p, &link).unwrap();
        assert!(LogFile::default().open(&link).is_err());
        assert!(LogFile::default().open(d.path()).is_err());
        let fifo = d.path().join("fifo.log");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        let e = LogFile::default().open(&fifo).unwrap_err();
        assert!(e.to_string().contains("not a plain file"), "{e}");
    }
}
