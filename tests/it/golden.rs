//! Golden outputs: the files `vss llv` writes for two fixed inputs, compared
//! byte for byte with the copies committed in `tests/golden/`. The accuracy
//! floors catch a worse engine; these catch a *different* one, so that an
//! intended change shows up as a diff in review and an unintended one fails.
//! Regenerate deliberately with `VSS_REGEN=1 cargo test --test it golden::`
//! and read the diff before committing it.
//!
//! - `bench/`: the LLV bench scene (`support::llv_scene`, 512², σ 2), one
//!   image, no lens;
//! - `five/`: view 1 of the built-in simulated cell under its five
//!   lightings, rendered by the simulator's own code, through camera 1's
//!   lens (`--cdf`).

use std::path::Path;

use assert_cmd::Command;

use vss::formats::img::{ImgFile, write_img};
use vss::llv::GreyImage;
use vss::profile::Profile;
use vss::rig::sim::{Scene, SimOptions};

use crate::support::golden::{dir as golden_dir, regen};
use crate::support::llv_scene;

const OUTPUTS: [&str; 4] = ["hpo", "vpo", "lex", "ldr"];

/// Runs `vss llv ARGS --out DIR` in `dir` and compares (or, with
/// `VSS_REGEN=1`, rewrites) `STEM.{hpo,vpo,lex,ldr}` against `tests/golden/NAME/`.
fn check(name: &str, dir: &Path, stem: &str, args: &[&str]) {
    let out = dir.join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_vss"))
        .current_dir(dir)
        .arg("llv")
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "vss llv {args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let golden = golden_dir(name);
    let mut differ = Vec::new();
    for ext in OUTPUTS {
        let file = format!("{stem}.{ext}");
        let made = std::fs::read(out.join(&file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let want = golden.join(&file);
        if regen() {
            std::fs::create_dir_all(&golden).unwrap();
            std::fs::write(&want, &made).unwrap();
            continue;
        }
        let kept = std::fs::read(&want).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (write it with VSS_REGEN=1 cargo test --test it golden::)",
                want.display()
            )
        });
        if kept != made {
            let first = kept
                .iter()
                .zip(&made)
                .position(|(a, b)| a != b)
                .unwrap_or(kept.len().min(made.len()));
            differ.push(format!(
                "{file}: {} bytes against the golden {} bytes, first difference at byte {first}",
                made.len(),
                kept.len()
            ));
        }
    }
    assert!(
        differ.is_empty(),
        "vss llv's outputs differ from tests/golden/{name}/ (if the change is intended, \
         regenerate with VSS_REGEN=1 cargo test --test it golden:: and review the diff):\n{}",
        differ.join("\n")
    );
}

fn save(path: &Path, image: GreyImage) {
    write_img(path, &ImgFile::new(image)).unwrap();
}

#[test]
fn the_bench_scene_gives_the_golden_outputs() {
    let dir = tempfile::tempdir().unwrap();
    save(
        &dir.path().join("bench1a.img"),
        llv_scene::scene(512, 512, 2.0, 7),
    );
    check("bench", dir.path(), "bench1", &["bench1a.img"]);
}

#[test]
fn five_lightings_of_the_simulated_cell_give_the_golden_outputs() {
    let profile = Profile::builtin().unwrap();
    let scene = Scene::new(SimOptions::from_profile(&profile));
    let (w, h) = (profile.sim.width as usize, profile.sim.height as usize);
    let dir = tempfile::tempdir().unwrap();
    let mut args = Vec::new();
    for l in &profile.lighting {
        let mask = profile
            .lights
            .iter()
            .filter(|light| l.on.contains(&light.name))
            .fold(0u32, |m, light| m | 1 << light.relay);
        let name = format!("five1{}.img", l.letter);
        let frame = scene.frame(1, mask, u64::from(l.letter as u32));
        save(
            &dir.path().join(&name),
            GreyImage::new(w, h, frame).unwrap(),
        );
        args.push(name);
    }
    assert_eq!(args.len(), 5, "the built-in cell has five lightings");
    let cdf = profile.camera_cdf(1).unwrap().expect("camera 1 has a .cdf");
    vss::formats::cdf::write_cdf(&dir.path().join("cam1.cdf"), &cdf).unwrap();
    let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
    all.extend(["--cdf", "cam1.cdf"]);
    check("five", dir.path(), "five1", &all);
}
