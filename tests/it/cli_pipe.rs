//! Commands whose reader goes away (`vss info FILE | head -2`) stop quietly:
//! no panic, no error message, success. A standard error whose reader has
//! gone loses the notes, not the exit status.

use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `vss ARGS` with its output going to a pipe that is already closed,
/// so that its first write fails as it does after `head` has quit.
fn run_into_a_closed_pipe(args: &[&str]) -> std::process::Output {
    run_with_a_closed_pipe(args, false)
}

/// Runs `vss ARGS` with its standard error (`stderr`) or its output going
/// to a pipe that is already closed.
fn run_with_a_closed_pipe(args: &[&str], stderr: bool) -> std::process::Output {
    let mut vss = vss_in(Path::new(env!("CARGO_MANIFEST_DIR")));
    vss.args(args);
    closed(vss, stderr)
}

/// `vss` to be run in `dir`.
fn vss_in(dir: &Path) -> Command {
    let mut vss = Command::new(assert_cmd::cargo::cargo_bin("vss"));
    vss.current_dir(dir);
    vss
}

/// Runs `cmd` with its standard error (`stderr`) or its output going to a
/// pipe that is already closed.
fn closed(mut cmd: Command, stderr: bool) -> std::process::Output {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if stderr {
        drop(child.stderr.take());
    } else {
        drop(child.stdout.take());
    }
    child.wait_with_output().unwrap()
}

#[test]
fn a_closed_pipe_ends_a_command_quietly() {
    // A bright square on a dark ground, for `vss llv`.
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("square1.pgm");
    let mut pgm = b"P5\n48 48\n255\n".to_vec();
    pgm.extend((0..48 * 48).map(|i| {
        let (x, y) = (i % 48, i / 48);
        if (12..36).contains(&x) && (12..36).contains(&y) {
            200
        } else {
            40
        }
    }));
    std::fs::write(&image, pgm).unwrap();
    let image = image.to_str().unwrap();
    for args in [
        &["info", "profiles/sim/cam1.cdf"][..],
        &["params", "list"],
        &["llv", image],
    ] {
        let out = run_into_a_closed_pipe(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {:?} {err}", out.status);
        assert!(err.is_empty(), "{args:?}: {err}");
    }
    // What `vss llv` saves is saved before it reports.
    assert!(dir.path().join("square1.ldr").is_file());
}

/// `vss calibrate IMAGES 2>&1 | head -1`: its notes on the images it leaves
/// out go to a standard error whose reader has gone. It ends with its own
/// status (1 here: no image shows the plate), not a panic (101, "failed
/// printing to stderr").
#[test]
fn a_closed_standard_error_does_not_panic_calibrate() {
    let dir = tempfile::tempdir().unwrap();
    let cdf = dir.path().join("cam1.cdf");
    let mut args = vec!["calibrate", "--camera", "1", "--plate", "squares", "--out"];
    let mut paths = vec![cdf.to_str().unwrap().to_string()];
    for k in 1..=2 {
        // A flat grey image of the camera's size: no plate in view.
        let image = dir.path().join(format!("flat{k}.pgm"));
        let mut pgm = b"P5\n512 512\n255\n".to_vec();
        pgm.resize(pgm.len() + 512 * 512, 90);
        std::fs::write(&image, pgm).unwrap();
        paths.push(image.to_str().unwrap().to_string());
    }
    args.extend(paths.iter().map(String::as_str));
    let out = run_with_a_closed_pipe(&args, true);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{:?}\n{text}", out.status);
    assert!(text.starts_with("plate squares:"), "{text}");
    assert!(!cdf.exists(), "nothing written");
}

/// `vss` started where it cannot draw (its output not a terminal, or TERM
/// dumb) says why on standard error and ends with 2, also when that error
/// stream's reader has gone: not a panic (101).
#[test]
fn the_console_refusing_to_start_ends_with_2_when_its_error_stream_is_gone() {
    for term in ["xterm-256color", "dumb"] {
        let mut vss = vss_in(Path::new(env!("CARGO_MANIFEST_DIR")));
        vss.env("TERM", term).stdin(Stdio::null());
        let out = closed(vss, true);
        assert_eq!(out.status.code(), Some(2), "TERM={term}: {:?}", out.status);
    }
}

/// `vss grab … | head -1`: the reader of its report goes after the first
/// line. The capture goes on: every lighting asked for is saved and the
/// command ends quietly, as a pipeline expects. Before, it stopped after
/// the next lighting with success, one frame missing.
#[test]
fn a_grab_whose_report_reader_has_gone_still_captures_every_lighting() {
    let dir = tempfile::tempdir().unwrap();
    crate::support::fixtures::quick_sim_profile(dir.path(), "p.toml");
    let args = crate::support::fixtures::grab_args(Some("p.toml"), "1", "1", "a,b,c");
    let mut vss = vss_in(dir.path());
    vss.args(args);
    let out = closed(vss, false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?} {err}", out.status);
    assert!(!err.contains("vss: error"), "{err}");
    for l in ['a', 'b', 'c'] {
        let frame = dir.path().join(format!("s/g/g1{l}.img"));
        assert!(frame.is_file(), "{} missing: {err}", frame.display());
    }
}
