//! Running the LLV stages on a session: save_outputs of a pipeline run,
//! redo from edges, lines and connect (only the later stages change), lens
//! correction from the image's .cdf, edits cleared by a new .ldr, the
//! `vss session redo` command, and one captured image giving the same lines
//! whether `vss session redo` or the console's way of running runs it.

use std::process::Command;

use vss::formats::img::ImgFile;
use vss::llv::edit::EditOp;
use vss::llv::params::Stage;
use vss::llv::pipeline::{self, Input};
use vss::llv::{GreyImage, Params};
use vss::profile::{Lighting, Profile};
use vss::session::{FrameRule, OutputState, Runner, Session};

/// A bright rectangle on a dark ground, anti-aliased edges by 4×4 sampling.
fn rectangle(level: f64) -> GreyImage {
    let (w, h) = (128, 96);
    let (x0, y0, x1, y1) = (30.3, 20.6, 97.7, 71.2);
    let mut img = GreyImage::filled(w, h, 40).unwrap();
    for y in 0..h {
        for x in 0..w {
            let mut inside = 0;
            for sy in 0..4 {
                for sx in 0..4 {
                    let (px, py) = (
                        x as f64 + (sx as f64 + 0.5) / 4.0 - 0.5,
                        y as f64 + (sy as f64 + 0.5) / 4.0 - 0.5,
                    );
                    if px > x0 && px < x1 && py > y0 && py < y1 {
                        inside += 1;
                    }
                }
            }
            let v = 40.0 + (level - 40.0) * f64::from(inside) / 16.0;
            img.data_mut()[y * w + x] = v.round() as u8;
        }
    }
    img
}

fn profile(letters: &[char]) -> Profile {
    let mut p = Profile::default();
    p.survey.cameras = 1;
    p.lighting = letters
        .iter()
        .map(|&letter| Lighting {
            letter,
            on: vec![],
            note: String::new(),
        })
        .collect();
    p
}

/// A session `box` in `dir` with one lighting and image 1 captured: the
/// rectangle at grey level 200.
fn box_with_one_image(dir: &std::path::Path) -> Session {
    let mut s = Session::create(dir, "box", &profile(&['a'])).unwrap();
    s.save_image(1, 'a', &ImgFile::new(rectangle(200.0)))
        .unwrap();
    s
}

fn hash_of(s: &Session, file: &str) -> String {
    let o = s.manifest().image(1).unwrap().outputs.as_ref().unwrap();
    o.files
        .iter()
        .find(|f| f.file == file)
        .unwrap()
        .hash
        .clone()
}

#[test]
fn redo_runs_only_the_stages_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = box_with_one_image(dir.path());
    let p = Params::default();
    let r = s.redo(1, Stage::Edges, &p).unwrap();
    assert!(r.counts.edges_h > 50 && r.counts.edges_v > 50, "{r}");
    assert!(r.counts.lines >= 4, "{r}");
    assert!(!r.lens_corrected);
    assert!(s.progress().is_complete());
    assert!(!s.path("box1a.imc").exists(), "no lens correction, no .imc");
    let hpo = hash_of(&s, "box1.hpo");
    let lex = hash_of(&s, "box1.lex");

    // From lines with a larger minimum length: edges untouched, fewer lines.
    let mut p2 = p.clone();
    p2.lines.min_length = 55.0;
    p2.edges.floor = 9.0; // an edge parameter: must NOT be applied from lines
    let r2 = s.redo(1, Stage::Lines, &p2).unwrap();
    assert!(r2.counts.lines_raw < r.counts.lines_raw, "{r2} vs {r}");
    assert_eq!(hash_of(&s, "box1.hpo"), hpo);
    assert_ne!(hash_of(&s, "box1.lex"), lex);
    let used = &s
        .manifest()
        .image(1)
        .unwrap()
        .outputs
        .as_ref()
        .unwrap()
        .params;
    assert_eq!(used.lines.min_length, 55.0);
    assert_eq!(
        used.edges.floor, p.edges.floor,
        "edges keep the parameters they were made with"
    );

    // A manual edit, then a redo from connect replaces the .ldr and the log.
    let lines = s.load_lines(1).unwrap();
    let edited = vss::llv::edit::apply(&lines, &EditOp::Delete(vec![0])).unwrap();
    s.record_edit_op(1, &EditOp::Delete(vec![0]), &edited)
        .unwrap();
    assert_eq!(s.manifest().image(1).unwrap().edit[0].op, "delete 0");
    assert_eq!(s.load_lines(1).unwrap().len(), lines.len() - 1);
    let lex_before = hash_of(&s, "box1.lex");
    s.redo(1, Stage::Connect, &p2).unwrap();
    assert!(s.manifest().image(1).unwrap().edit.is_empty());
    assert_eq!(s.load_lines(1).unwrap().len(), lines.len());
    assert_eq!(
        hash_of(&s, "box1.lex"),
        lex_before,
        "connect keeps the .lex"
    );
    assert!(
        s.check().is_ok() && s.check().warnings.is_empty(),
        "{:?}",
        s.check()
    );
}

#[test]
fn photometric_run_with_lens_correction_is_saved_per_lighting() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "box", &profile(&['a', 'b'])).unwrap();
    s.save_image(1, 'a', &ImgFile::new(rectangle(200.0)))
        .unwrap();
    s.save_image(1, 'b', &ImgFile::new(rectangle(150.0)))
        .unwrap();
    let cdf = dir.path().join("cam.cdf");
    std::fs::write(
        &cdf,
        "S=A\n0.01\n0.01\nC=E\n64\n48\nf=A\n8\nD=A\n-0.002\n0\n0\n0\n0\n",
    )
    .unwrap();
    s.set_image_info(1, 1, 1, Some(&cdf)).unwrap();
    let r = s.redo(1, Stage::Lens, &Params::default()).unwrap();
    assert!(r.lens_corrected, "{r}");
    for f in ["box1a.imc", "box1b.imc", "box1.cdf"] {
        assert!(s.path(f).is_file(), "{f}");
    }
    // The console's way: run the pipeline itself, then save the outputs.
    let imgs: Vec<GreyImage> = s
        .load_images(1)
        .unwrap()
        .into_iter()
        .map(|(_, f)| f.image)
        .collect();
    let out = pipeline::run(
        &Input {
            images: &imgs,
            ambient: None,
            lens: None,
        },
        &Params::default(),
    )
    .unwrap();
    s.save_outputs(1, &out, &Params::default()).unwrap();
    let o = s.manifest().image(1).unwrap().outputs.as_ref().unwrap();
    assert_eq!(o.counts.lines as usize, out.lines.len());
    assert_eq!(o.inputs.len(), 3, "two images and the cdf");
    // Re-capturing under b makes the outputs stale again.
    s.save_image(1, 'b', &ImgFile::new(rectangle(160.0)))
        .unwrap();
    assert!(matches!(
        s.progress().images[0].outputs,
        OutputState::Stale(_)
    ));
}

/// An image whose manifest lists no frames (dropped by hand, say) but
/// keeps its saved edges: `redo --from lines` runs on the `.hpo` / `.vpo`
/// alone, as `vss llv --from-edges` does, and gives those lines.
#[test]
fn redo_from_lines_without_frames_uses_the_edge_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = box_with_one_image(dir.path());
    let p = Params::default();
    s.redo(1, Stage::Edges, &p).unwrap();
    assert!(s.has_frames(1));
    let sdir = s.dir().to_path_buf();
    drop(s);

    // The manifest without the image's frames.
    let path = sdir.join("box.toml");
    let mut doc: toml_edit::DocumentMut = std::fs::read_to_string(&path).unwrap().parse().unwrap();
    let images = doc["image"].as_array_of_tables_mut().unwrap();
    images.get_mut(0).unwrap().remove("grey").unwrap();
    std::fs::write(&path, doc.to_string()).unwrap();

    let mut s = Session::open(&sdir).unwrap();
    assert!(!s.has_frames(1));
    let r = s.redo(1, Stage::Lines, &p).unwrap();
    assert!(r.counts.lines >= 4, "{r}");
    let h = vss::formats::edgefile::read_edges(&sdir.join("box1.hpo")).unwrap();
    let v = vss::formats::edgefile::read_edges(&sdir.join("box1.vpo")).unwrap();
    let by_edges = Runner::new()
        .run_saved(vss::llv::pipeline::Saved::Edges { h, v }, &p, None)
        .unwrap()
        .lines
        .clone();
    assert_eq!(s.load_lines(1).unwrap().len(), by_edges.len());
}

#[test]
fn redo_command_uses_the_profile_and_explains_missing_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let sdir = box_with_one_image(dir.path()).dir().to_path_buf();
    let vss = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_vss"))
            .args(args)
            .arg(&sdir)
            .output()
            .unwrap()
    };
    let o = vss(&["session", "redo", "--image", "1", "--from", "lines"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("redo from edges first"));
    let o = vss(&["session", "redo", "--image", "1", "--from", "edges"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("image 1 redone from Edges"));
    let o = vss(&["session", "check"]);
    assert!(o.status.success());
    let o = vss(&["session", "redo", "--image", "2", "--from", "edges"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no grey image captured yet"));
}

/// The default profile's simulated cell, smaller and quicker: 256², lights
/// settled in 5 ms, the cameras' `.cdf` files by absolute path.
fn quick_cell(dir: &std::path::Path) -> (Profile, std::path::PathBuf) {
    let mut p = Profile::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/profiles/default.toml"
    ))
    .unwrap();
    p.sim.width = 256;
    p.sim.height = 256;
    p.relay.settle_ms = 5;
    p.survey.cdf = (1..=p.survey.cameras)
        .map(|c| p.cdf_path(c).unwrap())
        .collect();
    let path = dir.join("cell.toml");
    std::fs::write(&path, p.to_toml().unwrap()).unwrap();
    (Profile::load(path.to_str().unwrap()).unwrap(), path)
}

#[test]
fn redo_and_the_console_s_way_write_the_same_ldr() {
    let dir = tempfile::tempdir().unwrap();
    let (profile, prof_path) = quick_cell(dir.path());
    let sdir = dir.path().join("cube");
    let vss = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_vss"))
            .arg("--profile")
            .arg(&prof_path)
            .args(args)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        o
    };
    let s = sdir.to_str().unwrap();
    vss(&[
        "grab",
        "--camera",
        "2",
        "--lighting",
        "a,b,c,d,e",
        "--image",
        "1",
        "--session",
        s,
    ]);
    vss(&["session", "redo", s, "--image", "1", "--from", "edges"]);
    let ldr = sdir.join("cube1.ldr");
    let by_redo = std::fs::read(&ldr).unwrap();

    // The console's way: the captured frames in memory, split by the
    // profile's rule, the camera's model from the profile's .cdf, run by a
    // runner as its pipeline worker does, saved through the session.
    let frames: Vec<(char, GreyImage)> = "abcde"
        .chars()
        .map(|l| {
            let f = vss::formats::img::read_img(&sdir.join(format!("cube1{l}.img"))).unwrap();
            (l, f.image)
        })
        .collect();
    let camera = vss::formats::cdf::read_cdf(&profile.cdf_path(2).unwrap())
        .unwrap()
        .camera_model();
    assert!(camera.is_some());
    let input = FrameRule::of_profile(&profile)
        .split(frames.clone())
        .with_camera(camera);
    assert_eq!(input.letters, vec!['a', 'b', 'c', 'd']);
    assert_eq!(input.ambient.as_ref().map(|a| a.0), Some('e'));
    let mut runner = Runner::new();
    let out = runner.run_changed(1, &input, &profile.llv).unwrap().clone();
    std::fs::remove_file(&ldr).unwrap();
    let mut sess = Session::open(&sdir).unwrap();
    sess.save_outputs(1, &out, &profile.llv).unwrap();
    assert!(
        std::fs::read(&ldr).unwrap() == by_redo,
        "the console's way wrote another .ldr than vss session redo"
    );
    assert_eq!(out.corrected.len(), 4, "the four lit frames lens-corrected");

    // `vss llv` on the five files and the camera's .cdf: the same rule, the
    // same runner, the same lines.
    let out_dir = dir.path().join("llv");
    let mut args: Vec<String> = vec!["llv".into(), "--out".into(), out_dir.display().to_string()];
    args.push("--cdf".into());
    args.push(profile.cdf_path(2).unwrap().display().to_string());
    args.extend(
        "abcde"
            .chars()
            .map(|l| sdir.join(format!("cube1{l}.img")).display().to_string()),
    );
    let o = vss(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("cube1e.img (subtracted"),
        "{o:?}"
    );
    assert!(
        std::fs::read(out_dir.join("cube1.ldr")).unwrap() == by_redo,
        "vss llv wrote another .ldr than vss session redo"
    );

    // The ambient frame is subtracted, not a fifth lighting: taken as lit
    // it gives other lines (the redo of old did that).
    let all_lit = FrameRule::default().split(frames).with_camera(camera);
    assert_eq!(all_lit.images.len(), 5);
    let other = Runner::new()
        .run(&all_lit, Stage::Lens, &profile.llv)
        .unwrap()
        .clone();
    assert_ne!(
        (other.edges_h.points.len(), other.lines.len()),
        (out.edges_h.points.len(), out.lines.len())
    );

    // From lines, with the same parameters, the same lines again: the
    // frames run again with the saved edges' parameters, as the console
    // re-runs lines (tracks follow peaks below the edge threshold, which the
    // edge files do not hold); from the saved .lex, whose six decimals round
    // the extracted lines, the same lines to within that rounding.
    drop(sess);
    vss(&["session", "redo", s, "--image", "1", "--from", "lines"]);
    assert!(
        std::fs::read(&ldr).unwrap() == by_redo,
        "--from lines: another .ldr"
    );
    vss(&["session", "redo", s, "--image", "1", "--from", "connect"]);
    let again = vss::formats::lines::read_lines(&ldr).unwrap();
    assert_eq!(again.len(), out.lines.len());
    for (a, b) in again.iter().zip(&out.lines) {
        let d = (a.a.x - b.a.x).abs()
            + (a.a.y - b.a.y).abs()
            + (a.b.x - b.b.x).abs()
            + (a.b.y - b.b.y).abs();
        assert!(d < 1e-4, "--from connect: {a:?} against {b:?}");
    }
    let o = vss(&["session", "check", s]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("ok"), "{o:?}");
}
