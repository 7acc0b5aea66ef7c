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

/// The least address space (KiB, to within 256) in which `vss ARGS`, run
/// in `cwd`, succeeds, found by bisection up to 1 GiB.
pub fn least_kib<I, S>(cwd: &Path, args: I) -> u64
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let args: Vec<S> = args.into_iter().collect();
    let runs = |kib: u64| {
        vss_under(cwd, &format!("ulimit -v {kib}"), &args)
            .status
            .success()
    };
    let (mut lo, mut hi) = (1024u64, 1 << 20);
    assert!(runs(hi), "vss fails even in 1 GiB of address space");
    while hi - lo > 256 {
        let mid = (lo + hi) / 2;
        if runs(mid) { hi = mid } else { lo = mid }
    }
    hi
}

/// The address space (KiB) `vss` needs to start and exit (`vss --version`),
/// once per test run. A memory bound is this plus what the work may take:
/// the binary's libraries (more with the `genicam` feature: Aravis, GLib,
/// libusb) are not the work's.
pub fn baseline_kib() -> u64 {
    static BASE: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *BASE.get_or_init(|| least_kib(Path::new("."), ["--version"]))
}
