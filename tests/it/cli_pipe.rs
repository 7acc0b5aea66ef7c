//! Commands whose reader goes away (`vss info FILE | head -2`) stop quietly:
//! no panic, no error message, success.

use std::process::{Command, Stdio};

/// Runs `vss ARGS` with its output going to a pipe that is already closed,
/// so that its first write fails as it does after `head` has quit.
fn run_into_a_closed_pipe(args: &[&str]) -> std::process::Output {
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("vss"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
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
