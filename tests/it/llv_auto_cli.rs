//! `vss llv --auto` and the line attributes as an operator sees them
//! (several lightings): four lightings plus an ambient image of a synthetic scene.

use std::path::Path;

use crate::support::vss;
use assert_cmd::assert::OutputAssertExt;
use vss::formats::img::{ImgFile, write_img};
use vss::formats::lines::read_lines;
use vss::synth::{self, PointLight, RenderOptions};

/// Writes `cube1a.img` … `cube1d.img` (four lights) and `cube1e.img`
/// (ambient only) of one synthetic view.
fn write_view(dir: &Path) {
    let (scene, cam, lights) = synth::test_scenes(1, 256, 256, 66).pop().unwrap();
    let key = &lights[0];
    let mut four: Vec<PointLight> = Vec::new();
    for k in 0..4 {
        let t = k as f64 * std::f64::consts::FRAC_PI_2;
        let (s, c) = t.sin_cos();
        let p = key.position;
        four.push(PointLight {
            position: [p[0] * c - p[1] * s, p[0] * s + p[1] * c, p[2]],
            intensity: 0.8,
        });
    }
    let o = |seed| RenderOptions {
        noise_sigma: 5.0,
        seed,
        ..RenderOptions::default()
    };
    for (k, l) in four.iter().enumerate() {
        let img = synth::render(&scene, &cam, std::slice::from_ref(l), &o(k as u64));
        let name = format!("cube1{}.img", (b'a' + k as u8) as char);
        write_img(&dir.join(name), &ImgFile::new(img)).unwrap();
    }
    let amb = synth::render(&scene, &cam, &[], &o(9));
    write_img(&dir.join("cube1e.img"), &ImgFile::new(amb)).unwrap();
}

#[test]
fn auto_prints_its_changes_and_uses_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_view(d);
    let run = |extra: &[&str]| {
        let mut c = vss();
        c.arg("llv").args(extra).arg("--out").arg(d.join("out"));
        for l in ["a", "b", "c", "d"] {
            c.arg(d.join(format!("cube1{l}.img")));
        }
        c.arg("--ambient").arg(d.join("cube1e.img"));
        c.assert().success().get_output().stdout.clone()
    };
    let plain = String::from_utf8(run(&[])).unwrap();
    let base = read_lines(&d.join("out/cube1.ldr")).unwrap().len();
    let want = base / 2;
    let text = String::from_utf8(run(&["--auto", &format!("lines={want}")])).unwrap();
    eprintln!("{plain}\n{text}");
    let head = format!("cube1: auto lines={want}: ");
    let line = text.lines().find(|l| l.starts_with(&head)).unwrap();
    assert!(line.contains(&format!("(was {base})")), "{line}");
    assert!(text.contains("  --set "), "{text}");
    // The written lines are the proposal's.
    let got = read_lines(&d.join("out/cube1.ldr")).unwrap().len();
    assert!(line.contains(&format!(": {got} lines")), "{line} vs {got}");
    assert!(
        got.abs_diff(want) < base.abs_diff(want),
        "{got} for {want} (base {base})"
    );

    // JSON: the same, as data, with the line attributes.
    let json = run(&["--json", "--auto", &format!("lines={want}")]);
    let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(v["auto"]["lines"], got);
    assert_eq!(v["auto"]["base_lines"], base);
    assert!(!v["auto"]["changes"].as_array().unwrap().is_empty());
    let attrs = v["line_attributes"].as_array().unwrap();
    assert_eq!(attrs.len(), got);
    // Mean signed responses of both signs and real fit residuals survive
    // CONNECT.
    let resp: Vec<f64> = attrs
        .iter()
        .map(|a| a["response"].as_f64().unwrap())
        .collect();
    assert!(
        resp.iter().any(|&r| r > 5.0) && resp.iter().any(|&r| r < -5.0),
        "{resp:?}"
    );
    let res: Vec<f64> = attrs
        .iter()
        .map(|a| a["residual"].as_f64().unwrap())
        .collect();
    assert!(res.iter().all(|&r| r.is_finite() && r >= 0.0), "{res:?}");
    assert!(
        res.iter().filter(|&&r| r > 0.0 && r < 1.0).count() * 2 > res.len(),
        "{res:?}"
    );
}

#[test]
fn a_bad_auto_target_is_refused_with_the_accepted_forms() {
    let dir = tempfile::tempdir().unwrap();
    write_view(dir.path());
    let out = vss()
        .args(["llv", "--auto", "lines=many"])
        .arg(dir.path().join("cube1a.img"))
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    assert!(err.contains("lines=N") && err.contains("clean"), "{err}");
}
