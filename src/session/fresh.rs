//! Undoing a session that could not be made whole: what `Session::create`
//! made (the session folder and any folders above it that were not there,
//! or, in a folder that was there, the files that were not) is removed, and
//! nothing else, so a failure (a full disk) leaves no empty or partial
//! session behind.

use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

use super::SessionError;
use crate::formats::names::SessionName;

/// What was in place before a session was made at `dir`.
#[derive(Debug)]
pub(super) struct Before {
    dir: PathBuf,
    /// The folders from `dir` up that did not exist, `dir` first.
    missing: Vec<PathBuf>,
    /// The entries of `dir` when it existed.
    entries: Vec<OsString>,
}

impl Before {
    /// Looks at `dir` and the folders above it before anything is made.
    pub(super) fn look(dir: &Path) -> Before {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .filter(|d| !d.as_os_str().is_empty())
            .take_while(|d| fs::symlink_metadata(d).is_err())
            .map(Path::to_path_buf)
            .collect();
        let entries = if missing.is_empty() {
            names(dir)
        } else {
            Vec::new()
        };
        Before {
            dir: dir.to_path_buf(),
            missing,
            entries,
        }
    }

    /// Removes what was made since [`Before::look`]: the folders that were
    /// not there (with what is in them, all of it made by this creation,
    /// which held the session's lock), else the new files of `dir`. `Ok`
    /// when nothing made is left; else the first thing that could not go.
    pub(super) fn undo(&self) -> Result<(), (PathBuf, std::io::Error)> {
        // Not there, or a file where a folder above it should be (a survey
        // folder that is a file): nothing was made.
        let gone = |p: &Path, r: std::io::Result<()>| match r {
            Err(e)
                if !matches!(
                    e.kind(),
                    std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
                ) =>
            {
                Err((p.to_path_buf(), e))
            }
            _ => Ok(()),
        };
        if self.missing.is_empty() {
            for n in names(&self.dir) {
                if !self.entries.contains(&n) {
                    let p = self.dir.join(&n);
                    gone(&p, fs::remove_file(&p))?;
                }
            }
            return Ok(());
        }
        gone(&self.dir, fs::remove_dir_all(&self.dir))?;
        for d in &self.missing[1..] {
            gone(d, fs::remove_dir(d))?;
        }
        Ok(())
    }
}

/// The names in folder `dir` (none when it cannot be read).
fn names(dir: &Path) -> Vec<OsString> {
    fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.file_name())).collect())
        .unwrap_or_default()
}

/// The longest path the system takes (`PATH_MAX`, with its final NUL).
pub(super) const PATH_MAX: usize = libc::PATH_MAX as usize;

/// Refuses a session folder whose files' paths would exceed `PATH_MAX`
/// (the longest: a temporary name of `NAME9999z.img`), before anything is
/// made: such a session was made, then not found.
pub(super) fn check_path_len(dir: &Path, name: &SessionName) -> Result<(), SessionError> {
    let abs = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    // "/.NAME9999z.img.tmp.PID.HHHHHHHHRRRRRRRR" and the final NUL.
    let longest = abs.as_os_str().len() + 2 + name.as_str().len() + 9 + 5 + 10 + 17 + 1;
    if longest > PATH_MAX {
        return Err(SessionError::PathTooLong {
            dir: dir.to_path_buf(),
            len: abs.as_os_str().len(),
        });
    }
    Ok(())
}

/// Why `dir` is not a session: there is no folder there at all (a name
/// mistyped), or a folder without the manifest `manifest`.
pub(super) fn not_a_session(dir: &Path, manifest: &str) -> String {
    if !super::present(dir) {
        format!(
            "{}: no such folder, so no session there (`vss session new NAME` makes one)",
            crate::text::path(dir)
        )
    } else {
        format!(
            "{} is not a session folder: no manifest {manifest} in it (make one with `vss session new NAME`)",
            crate::text::path(dir)
        )
    }
}
