//! Files and folders the robustness tests plant: a FIFO, a sparse image
//! of any size, a folder made read-only.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A FIFO (named pipe) at `p`.
pub fn mkfifo(p: &Path) {
    let ok = Command::new("mkfifo")
        .arg(p)
        .status()
        .expect("mkfifo")
        .success();
    assert!(ok, "mkfifo {}", p.display());
}

/// A sparse `.img` whose header and size agree on `w` × `h` pixels.
pub fn sparse_img(p: &Path, w: u16, h: u16) {
    let mut head = vec![0u8; 64];
    head[0] = b'I';
    head[1] = b'M';
    head[4..6].copy_from_slice(&w.to_le_bytes());
    head[6..8].copy_from_slice(&h.to_le_bytes());
    std::fs::write(p, &head).expect("header");
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(p)
        .expect("open");
    f.set_len(64 + u64::from(w) * u64::from(h)).expect("grow");
}

/// A folder made read-only until dropped: bind-mounted read-only over
/// itself (root), or its write permission taken away (anyone else).
pub enum ReadOnly {
    Mounted(PathBuf),
    Unwritable(PathBuf, std::fs::Permissions),
}

impl ReadOnly {
    /// `None` where neither works (root that cannot mount writes through
    /// permissions).
    pub fn make(dir: &Path) -> Option<ReadOnly> {
        use std::os::unix::fs::PermissionsExt;
        if let Some(ro) = ReadOnly::mount(dir) {
            return Some(ro);
        }
        let before = std::fs::metadata(dir).ok()?.permissions();
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o555)).ok()?;
        let ro = ReadOnly::Unwritable(dir.to_path_buf(), before);
        // Root writes through the permission: no way left to test here.
        std::fs::write(dir.join("probe"), "x")
            .is_err()
            .then_some(ro)
    }

    fn mount(dir: &Path) -> Option<ReadOnly> {
        let run = |args: &[&str]| {
            Command::new("mount")
                .stderr(std::process::Stdio::null())
                .args(args)
                .arg(dir)
                .arg(dir)
                .status()
                .is_ok_and(|s| s.success())
        };
        if !run(&["--bind"]) {
            return None;
        }
        let ro = ReadOnly::Mounted(dir.to_path_buf());
        run(&["-o", "remount,bind,ro"]).then_some(ro)
    }
}

impl Drop for ReadOnly {
    fn drop(&mut self) {
        match self {
            ReadOnly::Mounted(dir) => {
                let _ = Command::new("umount").arg(&*dir).status();
            }
            ReadOnly::Unwritable(dir, before) => {
                let _ = std::fs::set_permissions(&*dir, before.clone());
            }
        }
    }
}
