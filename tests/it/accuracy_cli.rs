//! `vss selftest` as a user runs it: the tables of both families, the JSON
//! for scripts, and a clear refusal of bad arguments. Small scenes keep it
//! quick; the floors themselves are in `tests/accuracy/` (`cargo test --test accuracy`).

use crate::support::vss;

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
        (&["selftest", "--noise=-1"][..], 2, "not a noise level"),
        (&["selftest", "--noise", "-1"], 2, "unexpected argument"),
        (&["selftest", "--size", "8"], 1, "too small"),
        (&["selftest", "--scenes", "0"], 1, "at least 1"),
        (&["selftest", "--noise", "two"], 2, "two"),
        (&["selftest", "--family", "spheres"], 2, "spheres"),
        (
            &["selftest", "--export", "/tmp/x", "--score", "/tmp/y"],
            2,
            "cannot be used with",
        ),
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

#[test]
fn selftest_reports_the_yard_family_with_its_breakdowns_and_lens_check() {
    let out = vss()
        .args([
            "selftest", "--family", "yard", "--scenes", "2", "--size", "192", "--noise", "0,sd",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.starts_with("yard: 2 scenes of 192×192 px"),
        "{stdout}"
    );
    assert!(!stdout.contains("cubes:"), "{stdout}");
    assert!(stdout.contains("strong R close R off-angle"), "{stdout}");
    for noise in ["0", "sd"] {
        let row = stdout
            .lines()
            .find(|l| l.split_whitespace().next() == Some(noise))
            .unwrap_or_else(|| panic!("no row for noise {noise}:\n{stdout}"));
        // recall, precision and F are fractions.
        for v in row.split_whitespace().skip(1).take(3) {
            let x: f64 = v.parse().unwrap();
            assert!((0.0..=1.0).contains(&x), "{row}");
        }
    }
    assert_eq!(stdout.matches("lens (noise").count(), 2, "{stdout}");
}

#[test]
fn selftest_json_holds_both_families() {
    let out = vss()
        .args([
            "selftest", "--scenes", "1", "--size", "128", "--noise", "2,sd", "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The cube family keeps its keys at the top; sd is the yard's alone.
    assert_eq!(v["levels"].as_array().unwrap().len(), 1);
    assert_eq!(v["levels"][0]["noise"], 2.0);
    let yard = &v["yard"];
    assert_eq!(yard["config"]["size"], 128);
    assert_eq!(yard["levels"][0]["noise"], 2.0);
    assert_eq!(yard["levels"][1]["noise"], "sd");
    for key in [
        "recall",
        "precision",
        "recall_strong",
        "recall_close",
        "off_angle",
    ] {
        let x = yard["levels"][1]["metrics"][key].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&x), "{key} = {x}");
    }
    assert!(yard["lens"][0]["f_difference"].as_f64().is_some());
}
