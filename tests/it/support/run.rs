//! `vss` run to its end in a folder, as the CLI tests run it.

use std::path::Path;
use std::time::Duration;

use assert_cmd::Command;

/// `vss ARGS` run in `cwd`: whether it succeeded, and its stdout then its
/// stderr. The timeout turns a regression that hangs into a failure.
pub fn run_in(cwd: &Path, args: &[&str], timeout: Duration) -> (bool, String) {
    let o = Command::cargo_bin("vss")
        .expect("the vss binary")
        .args(args)
        .current_dir(cwd)
        .timeout(timeout)
        .output()
        .expect("run vss");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

/// `vss ARGS` run in `cwd`, its whole output (status, stdout, stderr).
pub fn output_in(cwd: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_vss"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run vss")
}
