//! Runs the `vss` binary under shell limits (`ulimit -v …`, `trap …`), so
//! a test can bound its memory: an allocation over the limit fails fast
//! instead of filling the machine.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

/// Runs `vss ARGS` in `cwd` after the shell commands `limits`; returns its
/// output.
pub fn vss_under<I, S>(cwd: &Path, limits: &str, args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new("sh")
        .arg("-c")
        .arg(format!("{limits} && exec \"$@\""))
        .arg("sh")
        .arg(assert_cmd::cargo::cargo_bin("vss"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run vss")
}

/// The address space (KiB) `vss` needs to start and exit (`vss --version`),
/// found by bisection, once per test run. A memory bound is this plus what
/// the work may take: the binary's libraries (more with the `genicam`
/// feature: Aravis, GLib, libusb) are not the work's.
pub fn baseline_kib() -> u64 {
    static BASE: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *BASE.get_or_init(|| {
        let runs = |kib: u64| {
            vss_under(Path::new("."), &format!("ulimit -v {kib}"), ["--version"])
                .status
                .success()
        };
        let (mut lo, mut hi) = (1024u64, 1 << 20);
        assert!(
            runs(hi),
            "vss --version fails even in 1 GiB of address space"
        );
        while hi - lo > 256 {
            let mid = (lo + hi) / 2;
            if runs(mid) { hi = mid } else { lo = mid }
        }
        hi
    })
}
