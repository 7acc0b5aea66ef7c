//! The crate's one way to write a file and its one way to open a file it
//! reads, because a session folder is a place others can write into too.
//!
//! Writing ([`write_atomic`]): a temporary file is *created* (never opened:
//! `O_CREAT | O_EXCL | O_NOFOLLOW`, so a file or link planted under its name
//! makes the creation fail instead of being written through) under a random
//! name in the target's folder, filled, fsynced and renamed over the target,
//! then the folder is fsynced. An interrupted save never corrupts the
//! previous good file, and a replaced file keeps its permission bits. The target name itself must be absent or a regular
//! file: a symbolic link (or a FIFO, a device, a folder) there is refused
//! with an error naming the path, so vss never writes through a link, even
//! one that points back into its own folder. Temporary names embed the pid
//! (and a hash of the host name), so the next write into a folder removes
//! the temporary files of writers on this host that died (SIGKILL, power).
//!
//! Reading ([`read_input`], [`open_input`]): `O_NOFOLLOW | O_NONBLOCK`, then
//! the opened file must be a regular file no larger than the caller's bound
//! (each format says how large it can be). A FIFO cannot block a reader, a
//! link to `/dev/zero` or to a file outside the folder is refused before a
//! byte is read, and no reader allocates more than its bound.

use std::ffi::OsStr;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// Marks a temporary file: `.NAME.tmp.PID.HHHHHHHHRRRRRRRR` (host hash,
/// random part).
const TMP_MARK: &str = ".tmp.";

/// Writes `bytes` to `path` atomically. On error nothing at `path` changes and
/// the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// Like [`write_atomic`], with the content produced by a closure writing into
/// the temporary file.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut io::BufWriter<&mut File>) -> io::Result<()>,
) -> io::Result<()> {
    let dir = parent_dir(path);
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"))?;
    check_target(path)?;
    sweep_stale_temps(dir);
    // A replaced file keeps its permissions (a 0600 `.cdf` stays 0600).
    let old_mode = fs::symlink_metadata(path)
        .ok()
        .filter(|m| m.file_type().is_file())
        .map(|m| m.permissions());
    let (mut file, tmp) = create_temp(dir, name)?;
    let result = (|| {
        if let Some(mode) = old_mode {
            file.set_permissions(mode)?;
        }
        {
            let mut w = io::BufWriter::new(&mut file);
            fill(&mut w)?;
            w.flush()?;
        }
        file.sync_all()?;
        fs::rename(&tmp, path)?;
        // Make the rename itself durable.
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Several files replaced as one: each is written to its temporary file
/// (created exclusively, filled, fsynced) by [`StagedWrites::stage`], and
/// only [`StagedWrites::commit`], once every file is on disk, renames them
/// into place. A failure while staging (a full disk) leaves every target as
/// it was: no mix of old and new outputs. Dropped uncommitted, the
/// temporary files are removed.
#[derive(Debug, Default)]
pub struct StagedWrites {
    /// (temporary file, target), in the order staged.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl StagedWrites {
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes `bytes` for `path` to a temporary file beside it.
    pub fn stage(&mut self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        let dir = parent_dir(path);
        let name = path
            .file_name()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"))?;
        check_target(path)?;
        sweep_stale_temps(dir);
        let mode = fs::symlink_metadata(path)
            .ok()
            .filter(|m| m.file_type().is_file())
            .map(|m| m.permissions());
        let (mut file, tmp) = create_temp(dir, name)?;
        let r = (|| {
            if let Some(mode) = mode {
                file.set_permissions(mode)?;
            }
            file.write_all(bytes)?;
            file.sync_all()
        })();
        if let Err(e) = r {
            let _ = fs::remove_file(&tmp);
            return Err(e);
        }
        self.staged.push((tmp, path.to_path_buf()));
        Ok(())
    }

    /// Renames every staged file into place, in order, then makes the
    /// renames durable. Returns the targets.
    pub fn commit(mut self) -> io::Result<Vec<PathBuf>> {
        let staged = std::mem::take(&mut self.staged);
        let mut done = Vec::with_capacity(staged.len());
        let mut iter = staged.into_iter();
        for (tmp, target) in iter.by_ref() {
            if let Err(e) = check_target(&target).and_then(|()| fs::rename(&tmp, &target)) {
                let _ = fs::remove_file(&tmp);
                for (t, _) in iter {
                    let _ = fs::remove_file(t);
                }
                return Err(e);
            }
            done.push(target);
        }
        let mut dirs: Vec<&Path> = done.iter().map(|t| parent_dir(t)).collect();
        dirs.dedup();
        for d in dirs {
            if let Ok(d) = File::open(d) {
                let _ = d.sync_all();
            }
        }
        Ok(done)
    }
}

impl Drop for StagedWrites {
    fn drop(&mut self) {
        for (tmp, _) in &self.staged {
            let _ = fs::remove_file(tmp);
        }
    }
}

/// The folder a path lives in (`.` for a bare name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// What a non-regular file is, for messages.
fn describe(t: fs::FileType) -> &'static str {
    if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Refuses a write target that is anything but absent or a regular file:
/// vss replaces files, it never writes through a link or into a device.
pub fn check_target(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_file() => Ok(()),
        Ok(m) if m.file_type().is_symlink() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is a symbolic link; vss writes no file through a link — \
                 remove the link or write to another name",
                crate::text::path(path)
            ),
        )),
        Ok(m) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a regular file; vss only replaces regular files",
                crate::text::path(path),
                describe(m.file_type())
            ),
        )),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// A hash of this host's name, so the temporary files of another host
/// sharing the folder (NFS) are never taken for a dead writer's.
fn host_tag() -> u32 {
    let host = fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| fs::read_to_string("/etc/hostname"))
        .unwrap_or_default();
    crc32fast::hash(host.trim().as_bytes())
}

/// 32 unpredictable bits: std's hasher keys come from the OS's randomness.
fn random_u32() -> u32 {
    use std::hash::BuildHasher;
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let h = std::hash::RandomState::new().hash_one((n, t));
    (h ^ (h >> 32)) as u32
}

/// The temporary name for a file called `name`.
fn temp_name(name: &OsStr) -> String {
    format!(
        ".{}{TMP_MARK}{}.{:08x}{:08x}",
        name.to_string_lossy(),
        std::process::id(),
        host_tag(),
        random_u32()
    )
}

/// Creates a new temporary file for `name` in `dir`, exclusively: a name
/// that exists (a file, a planted link) is never opened, another random
/// name is tried.
pub(crate) fn create_temp(dir: &Path, name: &OsStr) -> io::Result<(File, PathBuf)> {
    let mut last = None;
    for _ in 0..16 {
        let tmp = dir.join(temp_name(name));
        match create_exclusive(&tmp) {
            Ok(f) => return Ok((f, tmp)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("cannot create a temporary file")))
}

/// Creates `path`, failing if anything (a file, a link, even a dangling
/// one) is there already.
fn create_exclusive(path: &Path) -> io::Result<File> {
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)
}

/// Who left a temporary file: its pid, and whether it names this host
/// (files of the older `.NAME.tmp.PID` form had no host and were always
/// made here).
fn temp_owner(file_name: &str) -> Option<(u32, bool)> {
    let rest = file_name.strip_prefix('.')?;
    let at = rest.rfind(TMP_MARK)?;
    let tail = rest.get(at + TMP_MARK.len()..)?;
    let (pid, tag) = match tail.split_once('.') {
        Some((pid, tag)) => (pid, Some(tag)),
        None => (tail, None),
    };
    let pid: u32 = pid.parse().ok().filter(|&p| p > 0)?;
    let here = match tag {
        None => true,
        Some(t) if t.len() == 16 && t.bytes().all(|b| b.is_ascii_hexdigit()) => {
            u32::from_str_radix(t.get(..8)?, 16).ok()? == host_tag()
        }
        Some(_) => return None,
    };
    Some((pid, here))
}

/// The temporary files in `dir` whose writer ran on this host and is gone
/// (a live writer's, this process's included, are in use), sorted. Best
/// effort: a folder that cannot be listed has none, and without `/proc`
/// no writer can be proved gone.
pub fn stale_temps(dir: &Path) -> Vec<PathBuf> {
    if !Path::new("/proc/self").exists() {
        return Vec::new();
    }
    let Ok(rd) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let me = std::process::id();
    let mut stale: Vec<PathBuf> = rd
        .filter_map(Result::ok)
        .filter(|entry| {
            let name = entry.file_name();
            let Some((pid, here)) = name.to_str().and_then(temp_owner) else {
                return false;
            };
            // Only files and links (unlinking a link leaves its target alone).
            here && pid != me
                && !Path::new(&format!("/proc/{pid}")).exists()
                && entry
                    .file_type()
                    .is_ok_and(|t| t.is_file() || t.is_symlink())
        })
        .map(|entry| entry.path())
        .collect();
    stale.sort();
    stale
}

/// Removes [`stale_temps`] from `dir`. Returns how many went.
pub fn sweep_stale_temps(dir: &Path) -> usize {
    stale_temps(dir)
        .iter()
        .filter(|p| fs::remove_file(p).is_ok())
        .count()
}

/// Opens a file to read it: not through a symbolic link, without blocking
/// on a FIFO, and only if it is a regular file of at most `limit` bytes.
/// Returns the file and its size. Errors say what the path is instead.
pub fn open_input(path: &Path, limit: u64) -> io::Result<(File, u64)> {
    let file = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| {
            if e.raw_os_error() == Some(libc::ELOOP) {
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    "it is a symbolic link; vss reads no file through a link — name the file itself",
                )
            } else {
                e
            }
        })?;
    let meta = file.metadata()?;
    if !meta.file_type().is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("it is {}, not a regular file", describe(meta.file_type())),
        ));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len(), limit));
    }
    Ok((file, meta.len()))
}

fn too_large(len: u64, limit: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::FileTooLarge,
        format!("it has {len} bytes, more than the {limit} this kind of file may have"),
    )
}

/// Reads a whole file through [`open_input`]: at most `limit` bytes, even
/// if the file grows while it is read.
pub fn read_input(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let (file, len) = open_input(path, limit)?;
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64, limit));
    }
    Ok(bytes)
}

/// [`read_input`] of a UTF-8 text file.
pub fn read_input_text(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read_input(path, limit)?)
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e.utf8_error()))
}

#[cfg(test)]
mod tests;
