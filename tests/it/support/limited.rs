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
