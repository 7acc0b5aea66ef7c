//! `vss selftest` as a user runs it: the table, the JSON for scripts, and a
//! clear refusal of bad arguments. Small scenes keep it quick; the floors
//! themselves are in `accuracy.rs`.

use assert_cmd::Command;

fn vss() -> Command {
    Command::new(env!("CARGO_BIN_EXE_vss"))
}

#[test]
fn selftest_prints_both_position_kinds_and_the_lens_check() {
    let out = vss()
        .args([
            "selftest", "--scenes", "1", "--size", "160", "--noise", "3,8",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("1 scenes of 160×160 px"), "{stdout}");
    for noise in ["3", "8"] {
        for kind in ["subpixel", "whole-pixel"] {
            assert!(
                stdout
                    .lines()
                    .any(|l| l.split_whitespace().take(2).eq([noise, kind])),
                "no {kind} row for noise {noise}:\n{stdout}"
            );
        }
    }
    assert!(stdout.contains("lens (noise"), "{stdout}");
}

#[test]
fn selftest_json_has_stable_keys_and_sane_values() {
    let out = vss()
        .args([
            "selftest", "--scenes", "1", "--size", "160", "--noise", "4", "--seed", "7", "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["config"]["seed"], 7);
    assert_eq!(v["config"]["size"], 160);
    let level = &v["levels"][0];
    assert_eq!(level["noise"], 4.0);
    for kind in ["subpixel", "whole_pixel"] {
        for key in ["recall", "precision"] {
            let x = level[kind][key].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&x), "{kind}.{key} = {x}");
        }
        assert!(level[kind]["endpoint_mean"].as_f64().unwrap() >= 0.0);
        assert!(level[kind]["angle_mean_deg"].as_f64().unwrap() >= 0.0);
    }
    for key in [
        "residual_undistorted",
        "residual_corrected",
        "straightness_corrected",
    ] {
        assert!(v["lens"][key].as_f64().unwrap() >= 0.0, "{key}");
    }
    // Same seed, same figures.
    let again = vss()
        .args([
            "selftest", "--scenes", "1", "--size", "160", "--noise", "4", "--seed", "7", "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.stdout, again.stdout);
}

#[test]
fn selftest_refuses_bad_arguments() {
    // 2: refused by the argument parser; 1: refused by the command with
    // its reason. A panic (101) or a signal is not a refusal.
    for (args, code, reason) in [
        (&["selftest", "--noise=-1"][..], 1, "not a noise level"),
        (&["selftest", "--noise", "-1"], 2, "unexpected argument"),
        (&["selftest", "--size", "8"], 1, "too small"),
        (&["selftest", "--scenes", "0"], 1, "at least 1"),
        (&["selftest", "--noise", "two"], 2, "two"),
    ] {
        let out = vss().args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            stderr.contains(reason),
            "{args:?}: no reason given: {stderr}"
        );
        assert!(out.stdout.is_empty(), "{args:?}: printed results anyway");
    }
}
