//! Profiles as a person meets them: the shipped profiles load, and every
//! mistake is reported with the file, the line, the key and what is allowed.

use std::path::{Path, PathBuf};

use vss::llv::Params;
use vss::llv::params::PARAMS;
use vss::profile::{GrabberKind, Profile, ProfileError, RelayKind};

fn profiles_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles")
}

fn default_text() -> String {
    std::fs::read_to_string(profiles_dir().join("default.toml")).unwrap()
}

#[test]
fn default_profile_is_the_simulated_cell_with_default_parameters() {
    let p = Profile::load(profiles_dir().join("default.toml").to_str().unwrap()).unwrap();
    assert_eq!(p.llv, Params::default());
    assert_eq!(p.grabber.kind, GrabberKind::Simulated);
    assert_eq!(p.relay.kind, RelayKind::Simulated);
    assert_eq!(p.lights.len(), 4);
    let letters: String = p.lighting.iter().map(|l| l.letter).collect();
    assert_eq!(letters, "abcde");
    assert!(p.lighting[4].on.is_empty(), "e is ambient");
    assert_eq!(p.survey.cdf.len(), 4);
    assert_eq!(p.cdf_path(1).unwrap(), profiles_dir().join("sim/cam1.cdf"));
    assert_eq!(p.cdf_path(5), None);
}

#[test]
fn default_profile_writes_out_every_parameter_with_a_comment() {
    let text = default_text();
    for sp in PARAMS {
        let (group, name) = sp.key.split_once('.').unwrap();
        let header = format!("[llv.{group}]");
        let start = text.find(&header).unwrap_or_else(|| panic!("no {header}"));
        let section = &text[start + header.len()..];
        let section = &section[..section.find("\n[").unwrap_or(section.len())];
        let line = section
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("{} missing from default.toml", sp.key));
        let comment = line.split_once('#').map(|(_, c)| c).unwrap_or("");
        assert!(comment.trim().len() > 10, "{} has no comment", sp.key);
        if !sp.unit.is_empty() {
            assert!(
                comment.contains(sp.unit),
                "{}: unit {} not in comment",
                sp.key,
                sp.unit
            );
        }
    }
}

#[test]
fn real_cell_example_loads() {
    let p = Profile::load(profiles_dir().join("real-cell.toml").to_str().unwrap()).unwrap();
    assert_eq!(p.grabber.kind, GrabberKind::Vsg);
    assert_eq!(p.grabber.port, "/dev/ttyUSB0");
    assert_eq!(p.relay.kind, RelayKind::Numato);
    assert_eq!(p.relay.port, "/dev/ttyACM0");
    assert_eq!(p.lights.len(), 4);
    assert_eq!(p.lighting.len(), 5);
}

#[test]
fn profile_by_name() {
    let p = Profile::load("default").unwrap();
    assert_eq!(p.name, "simulated cell");
    assert!(matches!(
        Profile::load("no-such-profile"),
        Err(ProfileError::NotFound { .. })
    ));
}

/// Replaces the first occurrence of `from` in the default profile and loads it.
fn broken(from: &str, to: &str) -> (String, ProfileError) {
    let text = default_text();
    assert!(text.contains(from), "{from}");
    let text = text.replacen(from, to, 1);
    let err = Profile::from_toml(&text, Path::new("cell.toml")).unwrap_err();
    (text, err)
}

fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap();
    text[..at].matches('\n').count() + 1
}

#[track_caller]
fn assert_names(from: &str, to: &str, key: &str, also: &[&str]) {
    let (_, err) = broken(from, to);
    let msg = err.to_string();
    let line = line_of(&default_text(), from);
    assert!(
        msg.starts_with(&format!("cell.toml:{line}: ")),
        "line {line}: {msg}"
    );
    assert!(msg.contains(key), "key {key}: {msg}");
    for a in also {
        assert!(msg.contains(a), "{a}: {msg}");
    }
}

#[test]
fn out_of_range_parameters_name_line_key_and_range() {
    assert_names(
        "half_width = 3 ",
        "half_width = 9 ",
        "llv.edges.half_width",
        &["3 to 7"],
    );
    assert_names(
        "floor = 2.0 ",
        "floor = -1.0 ",
        "llv.edges.floor",
        &["0 to 255"],
    );
    assert_names("wd = 1.0 ", "wd = 21.0 ", "llv.connect.wd", &["0 to 20"]);
    assert_names(
        "max_gap = 3 ",
        "max_gap = 0 ",
        "llv.lines.max_gap",
        &["1 to 20"],
    );
}

#[test]
fn wrong_types_name_line_key_and_range() {
    assert_names(
        "half_width = 3 ",
        "half_width = \"four\" ",
        "llv.edges.half_width",
        &["3 to 7"],
    );
    assert_names(
        "half_width = 3 ",
        "half_width = 4.5 ",
        "llv.edges.half_width",
        &["3 to 7"],
    );
    assert_names(
        "enabled = true ",
        "enabled = 1 ",
        "llv.lens.enabled",
        &["true or false"],
    );
    assert_names(
        "baud = 921600",
        "baud = \"fast\"",
        "grabber.baud",
        &["50 to 4000000"],
    );
    assert_names(
        "relay = 2\n",
        "relay = \"two\"\n",
        "lights[2].relay",
        &["0 to 15"],
    );
    assert_names(
        "kind = \"simulated\"    # \"simulated\", \"numato\"",
        "kind = \"usb\"    # \"simulated\", \"numato\"",
        "relay.kind",
        &["`numato`, `lcus`"],
    );
}

#[test]
fn unknown_keys_name_line_and_key() {
    assert_names(
        "per_region = 4096 ",
        "per_regoin = 16 ",
        "per_regoin",
        &["llv.edges"],
    );
    assert_names("seed = 1 ", "sede = 1 ", "sede", &[]);
}

#[test]
fn cell_consistency() {
    assert_names(
        "relay = 3\n",
        "relay = 16\n",
        "lights[3].relay",
        &["0 to 15"],
    );
    assert_names("relay = 3\n", "relay = 1\n", "lights[3].relay", &["twice"]);
    assert_names(
        "letter = \"c\"",
        "letter = \"d\"",
        "lighting[2].letter",
        &["expected 'c'"],
    );
    assert_names(
        "on = [\"left-back\"]",
        "on = [\"left-bak\"]",
        "lighting[2].on",
        &["left-bak", "not defined"],
    );
    assert_names("width = 512 ", "width = 8 ", "sim.width", &["16 to 4096"]);
}

#[test]
fn no_lighting_is_refused() {
    let text = "name = \"x\"\n[[lights]]\nname = \"a\"\nrelay = 0\n";
    let e = Profile::from_toml(text, Path::new("x.toml")).unwrap_err();
    assert!(e.to_string().contains("at least one [[lighting]]"), "{e}");
}

#[test]
fn toml_syntax_error_names_line() {
    let (text, e) = broken("[sim]", "[sim");
    let line = line_of(&text, "[sim\n");
    assert!(
        e.to_string().starts_with(&format!("cell.toml:{line}: ")),
        "{e}"
    );
}

#[test]
fn more_cdf_files_than_cameras_is_refused_fewer_is_allowed() {
    let text = default_text();
    let three = text.replacen("cameras = 4 ", "cameras = 3 ", 1);
    let e = Profile::from_toml(&three, Path::new("cell.toml"))
        .unwrap_err()
        .to_string();
    let line = line_of(&text, "cdf = [");
    assert!(
        e.starts_with(&format!("cell.toml:{line}: key `survey.cdf`")),
        "{e}"
    );
    assert!(e.contains("4 .cdf files for 3 cameras"), "{e}");
    let five = text.replacen("cameras = 4 ", "cameras = 5 ", 1);
    let p = Profile::from_toml(&five, Path::new("cell.toml")).unwrap();
    assert_eq!(p.cdf_path(5), None, "camera 5 has no calibration yet");
}

#[test]
fn profiles_survive_to_toml_and_back() {
    for name in ["default.toml", "real-cell.toml"] {
        let mut p = Profile::load(profiles_dir().join(name).to_str().unwrap()).unwrap();
        p.lights[0].position = None;
        let text = p.to_toml().unwrap();
        let mut q = Profile::from_toml(&text, Path::new("x.toml")).unwrap();
        q.source = p.source.clone();
        assert_eq!(q, p, "{name}");
    }
}

/// The compiled-in default is the shipped `profiles/default.toml`, and its
/// cameras' descriptions are the shipped `profiles/sim/*.cdf`.
#[test]
fn the_built_in_profile_is_the_shipped_default() {
    let file = Profile::load(profiles_dir().join("default.toml").to_str().unwrap()).unwrap();
    let mut built = Profile::builtin().unwrap();
    assert!(built.builtin && built.source.is_none());
    built.builtin = false;
    built.source = file.source.clone();
    assert_eq!(built, file);
    let built = Profile::builtin().unwrap();
    for cam in 1..=4 {
        let want = vss::formats::cdf::read_cdf(&file.cdf_path(cam).unwrap()).unwrap();
        assert_eq!(
            built.camera_cdf(cam).unwrap(),
            Some(want.clone()),
            "camera {cam}"
        );
        assert_eq!(file.camera_cdf(cam).unwrap(), Some(want));
        assert!(built.camera_model(cam).is_some());
    }
    assert_eq!(built.camera_cdf(5).unwrap(), None);
}

/// The default profile with its `[grabber]` kind line replaced by `kind`
/// and `camera` (`[[grabber.camera]]` tables) after the section's keys.
fn genicam_text(kind: &str, camera: &str) -> String {
    let block = "block = 16384";
    let t = default_text();
    assert!(t.contains(block), "{block}");
    t.replacen("kind = \"simulated\"", kind, 1)
        .replacen(block, &format!("{block}\n{camera}"), 1)
}

/// The `genicam` grabber's keys load without the feature (the profile does
/// not depend on how vss was built), and bad ones name line and key.
#[test]
fn genicam_cameras_and_their_settings() {
    let text = genicam_text(
        "kind = \"genicam\"\ncameras = [\"Aravis-Fake-GV01\", \"192.168.1.21\"]",
        "[[grabber.camera]]\npixel_format = \"Mono12\"\nexposure_us = 8000.0\n\
         gain_db = 3.5\nroi = [0, 0, 640, 480]\npacket_size = 8192",
    );
    let p = Profile::from_toml(&text, Path::new("cell.toml")).expect("a genicam profile loads");
    assert_eq!(p.grabber.kind, GrabberKind::Genicam);
    assert_eq!(p.grabber.cameras, ["Aravis-Fake-GV01", "192.168.1.21"]);
    let c = &p.grabber.camera[0];
    assert_eq!(c.pixel_format.as_deref(), Some("Mono12"));
    assert_eq!((c.exposure_us, c.gain_db), (Some(8000.0), Some(3.5)));
    assert_eq!((c.roi, c.packet_size), (Some([0, 0, 640, 480]), Some(8192)));
    // Round trip, and a simulated profile writes none of the new keys.
    let back = Profile::from_toml(&toml::to_string(&p).unwrap(), Path::new("b.toml")).unwrap();
    assert_eq!(back.grabber, p.grabber);
    let sim = toml::to_string(&Profile::builtin().unwrap()).unwrap();
    assert!(
        !sim.contains("cameras = [") && !sim.contains("pixel_format"),
        "{sim}"
    );

    let bad = |kind: &str, camera: &str, key: &str, also: &str| {
        let text = genicam_text(kind, camera);
        let e = Profile::from_toml(&text, Path::new("cell.toml")).unwrap_err();
        let m = e.to_string();
        let last = key.rsplit('.').next().unwrap_or(key);
        let base = last.split('[').next().unwrap_or(last);
        let line = line_of(&text, &format!("{base} ="));
        assert!(
            m.starts_with(&format!("cell.toml:{line}: ")),
            "line {line}: {m}"
        );
        assert!(m.contains(key) && m.contains(also), "{key}, {also}: {m}");
    };
    let one = "kind = \"genicam\"\ncameras = [\"a\"]";
    bad(
        "kind = \"genicam\"",
        "",
        "grabber.kind",
        "needs its cameras",
    );
    bad(
        "kind = \"genicam\"\ncameras = [\"a\", \"a\"]",
        "",
        "grabber.cameras[1]",
        "listed twice",
    );
    let cam = |kv: &str| format!("[[grabber.camera]]\n{kv}");
    bad(
        one,
        &cam("pixel_format = \"RGB8\""),
        "grabber.camera[0].pixel_format",
        "Mono8, Mono10, Mono12, Mono16",
    );
    bad(
        one,
        &cam("exposure_us = 0.0"),
        "grabber.camera[0].exposure_us",
        "1 to 60000000",
    );
    bad(
        one,
        &cam("roi = [0, 0, 0, 480]"),
        "grabber.camera[0].roi",
        "1 to 65535",
    );
    bad(
        one,
        &cam("packet_size = 100"),
        "grabber.camera[0].packet_size",
        "576",
    );
}
