//! The session folder as a writer takes it: the folder itself, never a
//! symbolic link to one. `sessions/cube -> /elsewhere/cube` would have
//! every save land outside the survey folder, where a link removed or
//! repointed later leaves the session without its files: such a folder is
//! refused for writing (the console and the command line alike, as both
//! take the lock through [`Lock::acquire`](super::lock::Lock::acquire)),
//! naming the link and where it leads. Looking at it (`vss session show`,
//! `check`, a report, the console's read-only open) still reads through it.

use std::fs;
use std::path::{Path, PathBuf};

use super::SessionError;
use crate::text;

/// A session folder that is a symbolic link, refused for writing.
#[derive(Debug, thiserror::Error)]
#[error(
    "{} is a symbolic link (to {}): vss writes no session through a link — open {} itself",
    text::path(link),
    text::path(target),
    text::path(real)
)]
pub struct Linked {
    /// The link, as it was named.
    pub link: PathBuf,
    /// What the link holds.
    pub target: PathBuf,
    /// The folder it leads to, all links resolved (as far as they go).
    pub real: PathBuf,
}

/// Folder `dir`'s device and inode, opened without following a link
/// (`O_NOFOLLOW`: a link put in its place at any moment before is seen,
/// not followed); [`Linked`] when it is a link.
pub fn unlinked(dir: &Path) -> Result<(u64, u64), SessionError> {
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    // "cube/" would follow the link: the last component itself is asked.
    let d: PathBuf = dir.components().collect();
    let opened = fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_DIRECTORY)
        .open(&d)
        .and_then(|f| f.metadata());
    let io = |source| SessionError::Io {
        path: d.clone(),
        source,
    };
    match opened {
        Ok(m) => Ok((m.dev(), m.ino())),
        Err(e) => match fs::symlink_metadata(&d) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = fs::read_link(&d).map_err(io)?;
                let real = d.canonicalize().unwrap_or_else(|_| match d.parent() {
                    Some(p) => p.join(&target),
                    None => target.clone(),
                });
                Err(SessionError::Linked(Linked {
                    link: d,
                    target,
                    real,
                }))
            }
            // Not readable (a folder of mode -wx): its identity still
            // tells it from a link swapped in later.
            Ok(m) if m.is_dir() => Ok((m.dev(), m.ino())),
            _ => Err(io(e)),
        },
    }
}
