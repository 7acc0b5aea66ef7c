//! TOML profiles: which cell the console talks to (grabber, relay board,
//! lights, lighting configurations, the simulated cell's settings) and every
//! LLV parameter. A profile is given by path or by name: `NAME.toml` in
//! `./profiles`, then in the user's `~/.config/vss/profiles` (the XDG config
//! folder). The default profile — the simulated cell — and its cameras'
//! `.cdf` files are compiled into the binary, so `vss` copied alone to the
//! cell PC (or installed with `cargo install`) still starts; a `default.toml`
//! in either folder takes its place.
//!
//! The structure is the serde schema below; loading adds the checks a person
//! needs: unknown keys, wrong types and out-of-range values are errors naming
//! the file, the line and the key, with the allowed range.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::llv::Params;

mod check;
pub mod edit;

/// A whole profile.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Profile {
    /// A name for people: shown in the console's top bar.
    pub name: String,
    pub grabber: GrabberConfig,
    pub relay: RelayConfig,
    /// The lights: relay channel → name.
    pub lights: Vec<Light>,
    /// The lighting configurations a survey steps through, lettered a, b, …
    pub lighting: Vec<Lighting>,
    pub survey: SurveyConfig,
    pub sim: SimConfig,
    pub llv: Params,
    /// The file this profile was loaded from (`None` when built in code);
    /// relative paths in it (`survey.cdf`, `survey.dir`) are relative to its
    /// folder.
    #[serde(skip)]
    pub source: Option<PathBuf>,
    /// Whether this is the built-in default profile ([`Profile::builtin`]),
    /// whose `survey.cdf` names the compiled-in camera descriptions.
    #[serde(skip)]
    pub builtin: bool,
}

/// The built-in default profile: `profiles/default.toml`, compiled in.
pub const BUILTIN_TOML: &str = include_str!("../profiles/default.toml");

/// What the built-in profile is called in messages and where its relative
/// paths point (the folder vss runs in).
pub const BUILTIN_NAME: &str = "default (built in)";

/// What [`Profile::in_use`] says of the built-in profile.
pub const BUILTIN_IN_USE: &str = "built-in";

/// The simulated cameras' descriptions the built-in profile names in
/// `survey.cdf`, compiled in: (path as the profile gives it, text).
pub const BUILTIN_CDF: [(&str, &str); 4] = [
    ("sim/cam1.cdf", include_str!("../profiles/sim/cam1.cdf")),
    ("sim/cam2.cdf", include_str!("../profiles/sim/cam2.cdf")),
    ("sim/cam3.cdf", include_str!("../profiles/sim/cam3.cdf")),
    ("sim/cam4.cdf", include_str!("../profiles/sim/cam4.cdf")),
];

/// Where a profile was found ([`locate`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A profile file.
    File(PathBuf),
    /// The built-in default profile ([`BUILTIN_TOML`]).
    Builtin,
}

/// Which frame grabber, and how to reach it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GrabberConfig {
    pub kind: GrabberKind,
    /// Serial device (ignored for the simulated grabber).
    pub port: String,
    pub baud: u32,
    /// Timeout for every reply (ms).
    pub timeout_ms: u64,
    /// Retries of an idempotent command (READ, STATUS, HELLO, CAMERA).
    pub retries: u32,
    /// Bytes per READ block (at most the grabber's maxblock).
    pub block: u32,
    /// `genicam`: camera N is entry N, each the device id as Aravis names
    /// it (`Aravis-Fake-GV01`) or its address (`192.168.1.20`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cameras: Vec<String>,
    /// `genicam`: settings of camera N (`[[grabber.camera]]`, entry N); a
    /// camera without an entry, or a setting left out, keeps the camera's
    /// own (its pixel format must then be one vss reads).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub camera: Vec<CameraSettings>,
}

/// What a GenICam camera is set to before it grabs (each `None` leaves the
/// camera's own value).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSettings {
    /// `Mono8`, `Mono10`, `Mono12` or `Mono16` (reduced to 8 bits:
    /// docs/hardware.md says how).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pixel_format: Option<String>,
    /// Exposure time (µs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exposure_us: Option<f64>,
    /// Analogue gain (dB).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gain_db: Option<f64>,
    /// Region of interest `[x, y, width, height]` (px).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roi: Option<[u32; 4]>,
    /// GigE Vision stream packet size (bytes): fewer, larger packets where
    /// the network carries jumbo frames. Unset: the largest the camera's
    /// test packets get through, or the camera's own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub packet_size: Option<u32>,
}

impl Default for GrabberConfig {
    fn default() -> Self {
        GrabberConfig {
            kind: GrabberKind::Simulated,
            port: String::new(),
            baud: 921_600,
            timeout_ms: 1000,
            retries: 3,
            block: 16384,
            cameras: Vec::new(),
            camera: Vec::new(),
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GrabberKind {
    /// The embedded simulated grabber, reached over a real pseudo-terminal.
    #[default]
    Simulated,
    /// A VSG/1 grabber on a serial port.
    Vsg,
    /// GigE Vision / USB3 Vision cameras through Aravis (`cameras`); needs
    /// a vss built with `--features genicam`.
    Genicam,
}

/// Which relay board switches the lights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RelayConfig {
    pub kind: RelayKind,
    pub port: String,
    pub baud: u32,
    pub timeout_ms: u64,
    /// Wait after switching before a freeze (ms).
    pub settle_ms: u64,
    /// Relays on the board: 1, 2, 4, 8, 16 or 32. A Numato board's mask
    /// width follows it (learned from the board when not given); an LCUS
    /// board cannot be asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channels: Option<u32>,
}

impl Default for RelayConfig {
    fn default() -> Self {
        RelayConfig {
            kind: RelayKind::Simulated,
            port: String::new(),
            baud: 19200,
            timeout_ms: 500,
            settle_ms: 200,
            channels: None,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RelayKind {
    /// The embedded simulated board (Numato protocol over a pseudo-terminal).
    #[default]
    Simulated,
    /// A Numato Lab USB relay module.
    Numato,
    /// An LCUS / CH340 board (binary frames, no replies).
    Lcus,
}

/// One light on a relay channel.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub name: String,
    pub relay: u32,
    /// Where the light stands in the cell (mm, world frame); the simulated
    /// cell lights its scene from here.
    #[serde(default)]
    pub position: Option<[f64; 3]>,
}

/// One lighting configuration: a letter and the lights that are on.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lighting {
    pub letter: char,
    pub on: Vec<String>,
    /// What it is for, shown to the operator.
    #[serde(default)]
    pub note: String,
}

/// The survey the console guides by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SurveyConfig {
    /// Folder where new sessions are made; a relative path is relative to
    /// the working folder (unlike `cdf`, which is relative to the profile).
    pub dir: PathBuf,
    pub cameras: u32,
    /// `.cdf` file per camera (index 0 is camera 1); relative to the profile.
    pub cdf: Vec<PathBuf>,
}

impl Default for SurveyConfig {
    fn default() -> Self {
        SurveyConfig {
            dir: PathBuf::from("sessions"),
            cameras: 4,
            cdf: Vec::new(),
        }
    }
}

/// The simulated cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Seed of the sensor noise and the scene.
    pub seed: u64,
    /// Sensor noise σ (grey levels).
    pub noise: f64,
    /// Image size of the simulated cameras.
    pub width: u32,
    pub height: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            noise: 2.0,
            width: 512,
            height: 512,
        }
    }
}

/// The largest profile read: 1 MiB (a fully commented profile is about
/// 10 KiB; TOML parsing costs 25–50 times the text in memory, so a 12 MB
/// file once took 576 MB). Larger files are refused unread.
pub const MAX_LEN: usize = 1 << 20;

/// A profile that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    #[error("cannot read profile {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("profile `{name}` not found (looked for {tried})")]
    NotFound { name: String, tried: String },
    #[error("camera {camera}: {source}")]
    Camera {
        camera: u32,
        source: crate::formats::FormatError,
    },
    #[error("{path}:{line}: {message}")]
    Invalid {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

impl Profile {
    /// Parses and checks a profile from text; `path` is used in error
    /// messages (and becomes [`Profile::source`]). Every error names the
    /// file, the line and the key, and says what is allowed.
    pub fn from_toml(text: &str, path: &Path) -> Result<Profile, ProfileError> {
        if text.len() > MAX_LEN {
            return Err(ProfileError::Invalid {
                path: path.to_path_buf(),
                line: 1,
                message: format!(
                    "the profile has {} bytes, more than the {MAX_LEN} a profile may have",
                    text.len()
                ),
            });
        }
        let mut p = check::parse_checked(text, path)?;
        p.source = Some(path.to_path_buf());
        Ok(p)
    }

    /// Loads a profile by path or by name ([`locate`]).
    pub fn load(name_or_path: &str) -> Result<Profile, ProfileError> {
        match locate(name_or_path)? {
            Origin::File(path) => {
                let (text, path) = text_of(&Origin::File(path))?;
                Profile::from_toml(&text, &path)
            }
            Origin::Builtin => Profile::builtin(),
        }
    }

    /// The built-in default profile: the simulated cell, every parameter at
    /// its default. Its relative paths are taken from the folder vss runs
    /// in, but its `.cdf` files are the compiled-in ones.
    pub fn builtin() -> Result<Profile, ProfileError> {
        let mut p = check::parse_checked(BUILTIN_TOML, Path::new(BUILTIN_NAME))?;
        p.builtin = true;
        Ok(p)
    }

    /// The camera description of camera `cam` (1-based) that `survey.cdf`
    /// names: `None` when it names none. A file named but missing or
    /// malformed is an error naming the file.
    ///
    /// This is the one owner of "which camera model does camera N have":
    /// the console's pipeline, Calibrate, the session's recorded `NAMEk.cdf`,
    /// `vss llv --camera`, `vss calibrate`, `vss grab` and `vss session new`
    /// all ask it. For the built-in profile a file at the named path (one
    /// the Calibrate screen or `vss calibrate` wrote there) wins over the
    /// compiled-in description, which is served when there is none, so the
    /// built-in cell corrects its lenses from any folder.
    pub fn camera_cdf(&self, cam: u32) -> Result<Option<crate::formats::cdf::Cdf>, ProfileError> {
        let Some(named) = usize::try_from(cam)
            .ok()
            .and_then(|c| c.checked_sub(1))
            .and_then(|i| self.survey.cdf.get(i))
        else {
            return Ok(None);
        };
        let fail = |source| ProfileError::Camera {
            camera: cam,
            source,
        };
        if self.builtin
            && !self.resolve_path(named).exists()
            && let Some((_, text)) = BUILTIN_CDF.iter().find(|(n, _)| Path::new(n) == named)
        {
            let shown = Path::new(BUILTIN_NAME).join(named);
            return crate::formats::cdf::parse_cdf(text, &shown)
                .map(Some)
                .map_err(fail);
        }
        crate::formats::cdf::read_cdf(&self.resolve_path(named))
            .map(Some)
            .map_err(fail)
    }

    /// The camera model of camera `cam` for lens correction: none when the
    /// profile names no `.cdf` for it, it cannot be read, or it lacks the
    /// intrinsic parameters.
    pub fn camera_model(&self, cam: u32) -> Option<crate::llv::lens::CameraModel> {
        self.camera_cdf(cam).ok().flatten()?.camera_model()
    }

    /// The folder relative paths of this profile are relative to (the
    /// profile file's folder; the current folder for a built-in profile).
    pub fn dir(&self) -> PathBuf {
        match self.source.as_deref().and_then(Path::parent) {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }

    /// A path from the profile, made relative to [`Profile::dir`] unless it
    /// is absolute.
    pub fn resolve_path(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.dir().join(p)
        }
    }

    /// Where [`Profile::camera_cdf`] takes camera `cam`'s description
    /// from, for messages: the resolved file, or the compiled-in one
    /// ("sim/cam1.cdf (built in)"); `None` when the profile names none.
    pub fn cdf_shown(&self, cam: u32) -> Option<String> {
        let i = usize::try_from(cam).ok()?.checked_sub(1)?;
        let named = self.survey.cdf.get(i)?;
        let path = self.resolve_path(named);
        if self.builtin && !path.exists() && BUILTIN_CDF.iter().any(|(n, _)| Path::new(n) == named)
        {
            return Some(format!("{} (built in)", crate::text::path(named)));
        }
        Some(crate::text::path(&path))
    }

    /// The `.cdf` file of camera `cam` (1-based), resolved: where a new
    /// calibration is written (read it through [`Profile::camera_cdf`]).
    pub fn cdf_path(&self, cam: u32) -> Option<PathBuf> {
        let i = usize::try_from(cam).ok()?.checked_sub(1)?;
        self.survey.cdf.get(i).map(|p| self.resolve_path(p))
    }

    /// Which profile file is in use, for people and for `--json`: the
    /// file's absolute path, or `built-in` for the compiled-in default.
    /// The one owner of that answer: the console (its first message, the
    /// Survey screen's step box, the help window) and every `--json`
    /// output that depends on the profile call it.
    pub fn in_use(&self) -> String {
        match &self.source {
            Some(p) if !self.builtin => std::path::absolute(p)
                .unwrap_or_else(|_| p.clone())
                .display()
                .to_string(),
            _ => BUILTIN_IN_USE.to_string(),
        }
    }

    /// The lighting configuration of a letter.
    pub fn lighting(&self, letter: char) -> Option<&Lighting> {
        self.lighting.iter().find(|l| l.letter == letter)
    }

    /// The profile as TOML (comments of the original file are not kept; see
    /// [`edit::set_llv`] to change values in place).
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(self)
    }
}

/// The folders a profile name is looked up in, in order: `./profiles`,
/// then `vss/profiles` in the XDG config folder ([`crate::dirs::config_home`]:
/// `$XDG_CONFIG_HOME`, else `~/.config`). The name `default` is not looked up in `./profiles`
/// ([`locate`]).
pub fn search_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![PathBuf::from("profiles")];
    if let Some(c) = crate::dirs::config_home() {
        dirs.push(c.join("vss").join("profiles"));
    }
    dirs
}

/// Finds a profile: an existing path as given, else `NAME.toml` in each of
/// [`search_dirs`], else for `default` the built-in profile.
pub fn locate(name_or_path: &str) -> Result<Origin, ProfileError> {
    let p = Path::new(name_or_path);
    if p.is_file() {
        return Ok(Origin::File(p.to_path_buf()));
    }
    let file = if name_or_path.ends_with(".toml") {
        name_or_path.to_string()
    } else {
        format!("{name_or_path}.toml")
    };
    // The default is never taken from the working folder: a
    // `profiles/default.toml` anyone left there must not silently change
    // what a bare `vss` drives (and where it writes).
    let dirs: Vec<PathBuf> = if name_or_path == "default" || name_or_path == "default.toml" {
        search_dirs()
            .into_iter()
            .filter(|d| d.is_absolute())
            .collect()
    } else {
        search_dirs()
    };
    let candidates: Vec<PathBuf> = dirs.into_iter().map(|d| d.join(&file)).collect();
    if let Some(c) = candidates.iter().find(|c| c.is_file()) {
        return Ok(Origin::File(c.clone()));
    }
    if name_or_path == "default" {
        return Ok(Origin::Builtin);
    }
    let mut tried: Vec<String> = vec![crate::text::path(p)];
    tried.extend(candidates.iter().map(crate::text::path));
    tried.dedup();
    Err(ProfileError::NotFound {
        name: crate::text::sanitize(name_or_path),
        tried: tried.join(", "),
    })
}

/// A profile's text and the name its errors use, wherever it was found:
/// what `vss params import` edits.
pub fn text_of(origin: &Origin) -> Result<(String, PathBuf), ProfileError> {
    match origin {
        Origin::File(path) => {
            // A profile is configuration, which dotfile managers install as
            // symbolic links: the link is resolved and its target read
            // (bounded, regular file only, so a huge file or a FIFO is
            // refused unread).
            let io = |source| ProfileError::Io {
                path: path.clone(),
                source,
            };
            let real = std::fs::canonicalize(path).map_err(io)?;
            let text = crate::fsutil::read_input_text(&real, MAX_LEN as u64).map_err(io)?;
            Ok((text, path.clone()))
        }
        Origin::Builtin => Ok((BUILTIN_TOML.to_string(), PathBuf::from(BUILTIN_NAME))),
    }
}
