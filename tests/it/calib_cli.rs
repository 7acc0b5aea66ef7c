//! `vss calibrate` as a person runs it: `vss sim --target plate` in its own
//! process, twelve `vss grab`s through the profile's ports (the plate at a
//! new pose each freeze), `vss calibrate` on the saved images, then the
//! plate at its place and `vss calibrate --extrinsic`; and the refusals,
//! which write nothing.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::support::vss;
use vss::formats::cdf::{Status, read_cdf};
use vss::profile::{GrabberKind, Profile, RelayKind};
use vss::rig::sim::cell_profile;

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// The simulated cell at 512², its cameras' `.cdf` files from the repository.
fn base() -> Profile {
    let mut p = cell_profile(512, 512);
    p.relay.settle_ms = 5;
    p.survey.cdf = (1..=4)
        .map(|k| repo(&format!("profiles/sim/cam{k}.cdf")))
        .collect();
    p
}

fn write_profile(dir: &Path, name: &str, p: &Profile) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, toml::to_string(p).expect("profile to toml")).expect("write profile");
    path
}

/// `vss sim --target …` in the background, stopped (SIGTERM) when dropped.
struct Sim {
    child: Child,
    relay: String,
}

impl Sim {
    fn start(profile: &Path, target: &str, link: &Path) -> Sim {
        let mut child = vss()
            .arg("--profile")
            .arg(profile)
            .args(["sim", "--target", target, "--plate", "squares", "--link"])
            .arg(link)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start vss sim");
        let out = child.stdout.take().expect("stdout");
        let mut lines = BufReader::new(out).lines();
        let mut next = || lines.next().and_then(Result::ok).unwrap_or_default();
        let _grabber = next();
        let relay = next()
            .strip_prefix("relay: ")
            .map(str::to_string)
            .expect("relay path");
        assert!(next().starts_with("simulated cell:"));
        Sim { child, relay }
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let pid = self.child.id().to_string();
        let _ = Command::new("kill").args(["-TERM", &pid]).status();
        let _ = self.child.wait();
    }
}

/// Grabs `n` images (ambient lighting) of camera 1 into session `dir`.
fn grab(tmp: &Path, sim: &Sim, link: &Path, session: &Path, n: u32) -> Vec<PathBuf> {
    let mut p = base();
    p.grabber.kind = GrabberKind::Vsg;
    p.grabber.port = link.to_string_lossy().into_owned();
    p.relay.kind = RelayKind::Numato;
    p.relay.port = sim.relay.clone();
    let prof = write_profile(tmp, "cell.toml", &p);
    let name = session.file_name().unwrap().to_string_lossy().into_owned();
    (1..=n)
        .map(|k| {
            let out = vss()
                .arg("--profile")
                .arg(&prof)
                .args([
                    "grab",
                    "--camera",
                    "1",
                    "--lighting",
                    "e",
                    "--image",
                    &k.to_string(),
                    "--session",
                ])
                .arg(session)
                .output()
                .expect("vss grab");
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            session.join(format!("{name}{k}e.img"))
        })
        .collect()
}

fn calibrate(profile: &Path, args: &[&str], images: &[PathBuf]) -> (bool, String, String) {
    let out = vss()
        .arg("--profile")
        .arg(profile)
        .arg("calibrate")
        .args(args)
        .args(images)
        .output()
        .expect("vss calibrate");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_camera_calibrated_from_the_simulated_cell_by_commands() {
    let tmp = tempfile::tempdir().expect("tmp");
    let t = tmp.path();
    let prof = write_profile(t, "sim.toml", &base());
    let link = t.join("ttyVSG0");
    let cdf = t.join("cam1.cdf");
    let cdf_s = cdf.to_string_lossy().into_owned();
    let images = {
        let sim = Sim::start(&prof, "plate", &link);
        grab(t, &sim, &link, &t.join("s/cal"), 12)
    };
    let (ok, out, err) = calibrate(
        &prof,
        &[
            "--camera", "1", "--plate", "squares", "--centre", "image", "--out", &cdf_s,
        ],
        &images,
    );
    assert!(ok, "{out}\n{err}");
    let rms: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("overall: "))
        .and_then(|l| l.split("RMS ").nth(1))
        .and_then(|l| l.split(' ').next())
        .and_then(|v| v.parse().ok())
        .expect("overall RMS");
    assert!(rms <= 0.1, "{out}");
    assert!(out.contains("f          ") && out.contains("± "), "{out}");
    let c = read_cdf(&cdf).unwrap();
    let m = c.camera_model().unwrap();
    let truth = read_cdf(&repo("profiles/sim/cam1.cdf"))
        .unwrap()
        .camera_model()
        .unwrap();
    assert!((m.f - truth.f).abs() / truth.f < 0.002, "{m:?}");
    assert_eq!(c.get("S").unwrap().status, Status::Stated);
    assert_eq!(c.get("C").unwrap().status, Status::Stated);
    assert_eq!(c.get("D").unwrap().status, Status::Calibrated);
    assert_eq!(c.get("T").unwrap().status, Status::NotAvailable);
    // Again without --yes: refused, the file untouched.
    let before = std::fs::read(&cdf).unwrap();
    let (ok, _, err) = calibrate(
        &prof,
        &["--camera", "1", "--plate", "squares", "--out", &cdf_s],
        &images,
    );
    assert!(!ok && err.contains("--yes"), "{err}");
    assert_eq!(std::fs::read(&cdf).unwrap(), before);

    // The plate at its place: T into the same file, the old one kept.
    let placed = {
        let sim = Sim::start(&prof, "plate-placed", &link);
        grab(t, &sim, &link, &t.join("s/ext"), 1)
    };
    let (ok, out, err) = calibrate(
        &prof,
        &[
            "--extrinsic",
            "--camera",
            "1",
            "--plate",
            "squares",
            "--out",
            &cdf_s,
        ],
        &placed,
    );
    assert!(ok, "{out}\n{err}");
    let c = read_cdf(&cdf).unwrap();
    assert_eq!(c.get("T").unwrap().status, Status::Calibrated);
    assert_eq!(c.camera_model(), Some(m));
    let bak = read_cdf(&t.join("cam1.cdf.bak")).unwrap();
    assert_eq!(bak.get("T").unwrap().status, Status::NotAvailable);
    // The camera stands where it does in the cell (its position, mm).
    let pos = |t: [[f64; 4]; 3]| -> [f64; 3] {
        std::array::from_fn(|j| -(0..3).map(|i| t[i][j] * t[i][3]).sum::<f64>())
    };
    let (a, b) = (
        pos(c.extrinsic().unwrap()),
        pos(read_cdf(&repo("profiles/sim/cam1.cdf"))
            .unwrap()
            .extrinsic()
            .unwrap()),
    );
    let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    assert!(d < 2.0, "camera position {d} mm off: {a:?} {b:?}");

    // Refusals write nothing.
    let fresh = t.join("fresh.cdf");
    let fresh_s = fresh.to_string_lossy().into_owned();
    let (ok, _, err) = calibrate(
        &prof,
        &["--camera", "1", "--plate", "squares", "--out", &fresh_s],
        &images[..2],
    );
    assert!(
        !ok && err.contains("at least 3") && err.contains("nothing written"),
        "{err}"
    );
    let bad_plate = t.join("bad.toml");
    std::fs::write(
        &bad_plate,
        std::fs::read_to_string(repo("profiles/plates/squares.toml"))
            .unwrap()
            .replace("pitch = 40.0", "pitch = 20.0"),
    )
    .unwrap();
    let (ok, _, err) = calibrate(
        &prof,
        &[
            "--camera",
            "1",
            "--plate",
            &bad_plate.to_string_lossy(),
            "--out",
            &fresh_s,
        ],
        &images,
    );
    assert!(
        !ok && err.contains("bad.toml:") && err.contains("overlap"),
        "{err}"
    );
    assert!(!fresh.exists());
}
