//! The session manifest `NAME.toml`: everything about a survey that the
//! three-number `.ses` file cannot hold — the lighting configurations, the
//! camera, location and `.cdf` of every image number, and for every saved
//! file its content hash; for the stage outputs the parameters, counts and
//! timings, when and by which version they were made and from which inputs;
//! the log of manual line edits.
//!
//! It is plain serde + TOML, readable and editable by a person. Loading is
//! strict (unknown keys are errors) and then checked for sense (unique image
//! numbers and letters, image numbers and `planned_images` within
//! [`MAX_IMAGE_NUMBER`], every record's camera one of the session's, file
//! names that stay inside the session folder), so
//! a manifest edited into nonsense is reported with its file and line and
//! never silently rewritten. It is read record by record (`records`): each
//! `[[image]]` is parsed on its own, never the whole file into one TOML
//! document, which cost 21 to 76 times the text.
//!
//! A grey image's record keeps the camera's exposure and gain when the
//! frame was taken (`exposure_us`, `gain_db`: GenICam cameras); the serial
//! grabber's frames, and manifests written before, have neither.

use std::path::Path;

use serde::{Deserialize, Serialize};

mod records;

pub use records::MAX_RECORD_LEN;
pub(crate) use records::check_record_sizes;

use super::{MAX_IMAGE_NUMBER, SessionError};
use crate::llv::{Params, Segment};

/// Version of the manifest schema this console writes.
pub const FORMAT: u32 = 1;

/// The largest manifest read: 4 MiB. Parsing a TOML record costs 21 to 76
/// times its text in memory (76 for nothing but one-digit array values: a
/// 16 MiB file of them took 1.27 GB). Records are parsed one at a time, so
/// a manifest of many images costs about 2.5 times its text; but one record
/// may be the whole file, and this bound keeps even that under about
/// 330 MB. A real manifest takes about 4 KiB a fully processed image (see
/// docs/reliability.md), so it holds about a thousand. Larger files are
/// refused unread.
pub const MAX_LEN: usize = 4 << 20;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Schema version ([`FORMAT`]).
    pub format: u32,
    pub session: SessionInfo,
    /// Lighting configurations, lettered a, b, …
    #[serde(default)]
    pub lighting: Vec<LightingInfo>,
    /// Image numbers with anything recorded, in ascending order.
    #[serde(default)]
    pub image: Vec<ImageRecord>,
    /// Camera calibrations made while the session was open, oldest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub calibration: Vec<CalibrationRecord>,
}

/// A camera's calibration accepted in the console: which `.cdf` it wrote,
/// when, from how many views, and how well it fits them. Images captured
/// after it copy the new `.cdf` into the session (their `cdf` record).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationRecord {
    pub camera: u32,
    /// UTC, RFC 3339.
    pub made: String,
    /// The `.cdf` written (the profile's path for the camera).
    pub cdf: String,
    pub views: u32,
    /// Reprojection error over all views: RMS and 95th percentile, px.
    pub rms_px: f64,
    pub p95_px: f64,
    /// `C` was stated rather than solved for.
    #[serde(default)]
    pub centre_stated: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SessionInfo {
    pub name: String,
    /// UTC, RFC 3339.
    pub created: String,
    pub modified: String,
    /// Version of `vss` that last wrote the manifest.
    pub version: String,
    /// Name of the profile the session was made with.
    #[serde(default)]
    pub profile: String,
    /// Images the survey plans (the checklist's length), at most
    /// [`MAX_IMAGE_NUMBER`].
    pub planned_images: u32,
    pub cameras: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingInfo {
    pub letter: char,
    /// Names of the lights that are on.
    #[serde(default)]
    pub on: Vec<String>,
    #[serde(default)]
    pub note: String,
}

/// A file of the session and the hash of its content when it was written.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileRecord {
    pub file: String,
    pub hash: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageRecord {
    pub number: u32,
    pub camera: u32,
    pub location: u32,
    /// The camera description copied into the session (`cube7.cdf`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cdf: Option<FileRecord>,
    /// Grey images, one per lighting letter captured.
    #[serde(default)]
    pub grey: Vec<GreyRecord>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outputs: Option<OutputRecord>,
    /// Manual line edits since the outputs were made, oldest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub edit: Vec<EditRecord>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GreyRecord {
    pub letter: char,
    pub file: String,
    pub hash: String,
    pub width: u32,
    pub height: u32,
    /// The camera's exposure time when the frame was taken (µs): written
    /// for GenICam cameras, absent for the serial grabber (which has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exposure_us: Option<f64>,
    /// The camera's gain when the frame was taken (dB); absent likewise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain_db: Option<f64>,
    pub saved: String,
    pub version: String,
}

/// What a camera was set to when it took a frame, as the grey image's
/// record keeps it ([`GreyRecord::exposure_us`], [`GreyRecord::gain_db`]):
/// `None` where the camera has no such setting or says nothing of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameSettings {
    /// Exposure time (µs).
    pub exposure_us: Option<f64>,
    /// Gain (dB).
    pub gain_db: Option<f64>,
}

impl FrameSettings {
    /// From the values a camera reports (NaN or infinite: none).
    pub fn new(exposure_us: f64, gain_db: f64) -> FrameSettings {
        let finite = |v: f64| v.is_finite().then_some(v);
        FrameSettings {
            exposure_us: finite(exposure_us),
            gain_db: finite(gain_db),
        }
    }
}

/// The stage outputs of one image number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputRecord {
    pub made: String,
    pub version: String,
    /// The inputs the outputs were made from, with their hashes then: the
    /// grey images (and the `.cdf`). Differences make the outputs stale.
    pub inputs: Vec<FileRecord>,
    /// The files written: `.imc`, `.hpo`, `.vpo`, `.lex`, `.ldr`.
    pub files: Vec<FileRecord>,
    pub counts: Counts,
    pub timings: TimingsRecord,
    /// Attributes of the extracted and of the post-processed lines, which
    /// the line files cannot carry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lex_attributes: Option<LineAttributes>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ldr_attributes: Option<LineAttributes>,
    /// The parameters used (last: TOML wants tables after plain values).
    pub params: Params,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Counts {
    pub edges_h: u64,
    pub edges_v: u64,
    pub lines_raw: u64,
    pub lines: u64,
}

/// Stage timings (µs), as the pipeline measured them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimingsRecord {
    pub lens_us: u64,
    pub edges_us: u64,
    pub lines_us: u64,
    pub connect_us: u64,
}

impl From<&crate::llv::pipeline::Timings> for TimingsRecord {
    fn from(t: &crate::llv::pipeline::Timings) -> Self {
        TimingsRecord {
            lens_us: t.lens_us,
            edges_us: t.edges_us,
            lines_us: t.lines_us,
            connect_us: t.connect_us,
        }
    }
}

/// Per-line attributes in file order: mean response, RMS residual, and the
/// indices (0-based) of the lines flagged as shadows.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineAttributes {
    pub response: Vec<f64>,
    pub residual: Vec<f64>,
    #[serde(default)]
    pub shadow: Vec<u32>,
}

/// Lines an image may have for their attributes to be recorded. About 50
/// bytes of manifest a line: 2 048 lines keep an image's record well under
/// [`MAX_RECORD_LEN`], which the reader refuses to go beyond. An image with
/// more lines keeps them all in its `.ldr`; only their response, residual
/// and shadow marks are not carried over to a reopened session.
pub const MAX_ATTRIBUTED_LINES: usize = 2048;

impl LineAttributes {
    /// `None` when no line carries an attribute (e.g. lines read from a
    /// `.lex`), nothing worth recording, or when there are more than
    /// [`MAX_ATTRIBUTED_LINES`].
    pub fn of(lines: &[Segment]) -> Option<LineAttributes> {
        if lines.len() > MAX_ATTRIBUTED_LINES {
            return None;
        }
        let any = lines
            .iter()
            .any(|s| s.response != 0.0 || s.residual != 0.0 || s.shadow);
        any.then(|| LineAttributes {
            // TOML has no way to say "no value" in an array: write 0.
            response: lines.iter().map(|s| finite(s.response)).collect(),
            residual: lines.iter().map(|s| finite(s.residual)).collect(),
            shadow: lines
                .iter()
                .enumerate()
                .filter(|(_, s)| s.shadow)
                .filter_map(|(i, _)| u32::try_from(i).ok())
                .collect(),
        })
    }

    /// Puts the attributes back on lines read from a line file (when the
    /// counts agree).
    pub fn apply(&self, lines: &mut [Segment]) {
        if self.response.len() != lines.len() || self.residual.len() != lines.len() {
            return;
        }
        for (i, s) in lines.iter_mut().enumerate() {
            s.response = self.response.get(i).copied().unwrap_or(0.0);
            s.residual = self.residual.get(i).copied().unwrap_or(0.0);
        }
        for &i in &self.shadow {
            if let Some(s) = lines.get_mut(i as usize) {
                s.shadow = true;
            }
        }
    }
}

fn finite(v: f64) -> f64 {
    if v.is_finite() { v } else { 0.0 }
}

/// One manual edit of the lines of an image.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditRecord {
    pub at: String,
    pub version: String,
    /// What was done, as the editor describes it: `connect 3 7`.
    pub op: String,
    /// Lines after the edit.
    pub lines: u64,
    /// Hash of the `.ldr` written after the edit.
    pub hash: String,
}

impl Manifest {
    pub fn image(&self, k: u32) -> Option<&ImageRecord> {
        self.image.iter().find(|r| r.number == k)
    }

    /// Every file the manifest names: (image number, file, recorded hash).
    pub fn files(&self) -> Vec<(u32, &str, &str)> {
        let mut out = Vec::new();
        for r in &self.image {
            let k = r.number;
            out.extend(r.cdf.iter().map(|f| (k, f.file.as_str(), f.hash.as_str())));
            out.extend(r.grey.iter().map(|g| (k, g.file.as_str(), g.hash.as_str())));
            if let Some(o) = &r.outputs {
                out.extend(
                    o.files
                        .iter()
                        .map(|f| (k, f.file.as_str(), f.hash.as_str())),
                );
            }
        }
        out
    }

    /// Parses manifest text; errors name `path` and the line.
    pub fn parse(text: &str, path: &Path) -> Result<Manifest, SessionError> {
        if text.len() > MAX_LEN {
            return Err(SessionError::Manifest {
                path: path.to_path_buf(),
                line: 0,
                message: format!(
                    "the manifest has {} bytes, more than the {MAX_LEN} a manifest may have",
                    text.len()
                ),
            });
        }
        // Said as what it is, not as the first field missing ("missing
        // field `format`"): a save cut short, a copy that failed.
        if text.trim().is_empty() {
            return Err(SessionError::Manifest {
                path: path.to_path_buf(),
                line: 0,
                message: match text.len() {
                    0 => "the manifest is empty (0 bytes)".to_string(),
                    n => format!("the manifest is empty ({n} bytes, all white space)"),
                },
            });
        }
        let m = records::parse(text, path)?;
        m.validate()
            .map_err(|(needle, message)| SessionError::Manifest {
                path: path.to_path_buf(),
                line: needle.map_or(0, |n| find_line(text, &n)),
                message,
            })?;
        Ok(m)
    }

    /// The manifest as TOML text.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        let body = toml::to_string(self)?;
        Ok(format!(
            "# Session manifest written by vss {}. The console owns this file: edit with care;\n\
             # `vss session check DIR` tells whether it still makes sense.\n{body}",
            env!("CARGO_PKG_VERSION")
        ))
    }

    /// Sense checks after parsing. On failure: text to look for (to find
    /// the line) and the message.
    fn validate(&self) -> Result<(), (Option<String>, String)> {
        if self.format != FORMAT {
            return Err((
                Some("format".into()),
                format!(
                    "manifest format {} is not one this console reads (it reads {FORMAT})",
                    self.format
                ),
            ));
        }
        if let Err(e) = crate::formats::names::SessionName::new(&self.session.name) {
            return Err((Some("name".into()), e.to_string()));
        }
        if self.session.cameras == 0 {
            return Err((Some("cameras".into()), "cameras must be at least 1".into()));
        }
        if self.session.planned_images > MAX_IMAGE_NUMBER {
            return Err((
                Some("planned_images".into()),
                format!(
                    "planned_images {} is more than a session holds: image numbers run from 1 to {MAX_IMAGE_NUMBER}",
                    self.session.planned_images
                ),
            ));
        }
        let mut letters = Vec::new();
        for l in &self.lighting {
            if !l.letter.is_ascii_lowercase() {
                return Err((
                    Some(format!("{:?}", l.letter.to_string())),
                    format!("lighting letter {:?} is not one of a–z", l.letter),
                ));
            }
            if letters.contains(&l.letter) {
                return Err((
                    Some(format!("letter = \"{}\"", l.letter)),
                    format!("lighting letter {:?} appears twice", l.letter),
                ));
            }
            letters.push(l.letter);
        }
        let mut numbers = std::collections::BTreeSet::new();
        for r in &self.image {
            let at = Some(format!("number = {}", r.number));
            if r.number == 0 || r.number > MAX_IMAGE_NUMBER {
                return Err((
                    at,
                    format!(
                        "image number {} is out of range: image numbers run from 1 to {MAX_IMAGE_NUMBER}",
                        r.number
                    ),
                ));
            }
            if !numbers.insert(r.number) {
                return Err((at, format!("image number {} appears twice", r.number)));
            }
            self.check_camera(r.camera)
                .map_err(|e| camera_at(r.camera, format!("[[image]] number {}: {e}", r.number)))?;
            for g in &r.grey {
                if !letters.contains(&g.letter) {
                    return Err((
                        Some(g.file.clone()),
                        format!(
                            "grey image {} has lighting {:?}, which the [[lighting]] list does not define",
                            g.file, g.letter
                        ),
                    ));
                }
            }
            let names = r
                .cdf
                .iter()
                .map(|f| f.file.as_str())
                .chain(r.grey.iter().map(|g| g.file.as_str()))
                .chain(
                    r.outputs
                        .iter()
                        .flat_map(|o| o.files.iter().chain(&o.inputs))
                        .map(|f| f.file.as_str()),
                );
            for name in names {
                if !plain_file_name(name) {
                    return Err((
                        Some(name.to_string()),
                        format!(
                            "file name {name:?} is not a plain file name inside the session folder"
                        ),
                    ));
                }
            }
        }
        for c in &self.calibration {
            self.check_camera(c.camera).map_err(|e| {
                camera_at(c.camera, format!("[[calibration]] made {}: {e}", c.made))
            })?;
        }
        Ok(())
    }

    /// Whether `camera` is one of the session's cameras (1 to
    /// `session.cameras`): what every image and calibration record must
    /// name, and what a session records; if not, why not.
    pub fn check_camera(&self, camera: u32) -> Result<(), String> {
        let n = self.session.cameras;
        if (1..=n).contains(&camera) {
            return Ok(());
        }
        Err(format!(
            "camera {camera} is not one of the session's cameras, which run from 1 to {n} \
             ([session] cameras = {n})"
        ))
    }
}

/// A camera check's failure at the record's `camera` key.
fn camera_at(camera: u32, message: String) -> (Option<String>, String) {
    (Some(format!("camera = {camera}")), message)
}

/// A name with no path in it: what a session may name.
pub fn plain_file_name(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\'])
        && !name.chars().any(char::is_control)
}

/// The 1-based line of the first occurrence of `needle` (0 if absent).
fn find_line(text: &str, needle: &str) -> usize {
    text.find(needle)
        .map_or(0, |i| text[..i].matches('\n').count() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::Point;

    fn full() -> Manifest {
        let file = |f: &str| FileRecord {
            file: f.into(),
            hash: "crc32:01234567:89".into(),
        };
        let mut seg = Segment::new(Point::new(1.5, 2.0), Point::new(3.0, 4.25));
        seg.response = -12.5;
        seg.residual = 0.125;
        seg.shadow = true;
        Manifest {
            format: FORMAT,
            session: SessionInfo {
                name: "cube".into(),
                created: "2026-11-22T02:00:00Z".into(),
                modified: "2026-11-22T03:00:00Z".into(),
                version: "0.1.0".into(),
                profile: "cell \"A\"".into(),
                planned_images: 8,
                cameras: 4,
            },
            lighting: vec![LightingInfo {
                letter: 'a',
                on: vec!["left".into(), "right".into()],
                note: "both".into(),
            }],
            image: vec![ImageRecord {
                number: 7,
                camera: 3,
                location: 2,
                cdf: Some(file("cube7.cdf")),
                grey: vec![GreyRecord {
                    letter: 'a',
                    file: "cube7a.img".into(),
                    hash: "crc32:1:2".into(),
                    width: 512,
                    height: 480,
                    exposure_us: Some(12_500.0),
                    gain_db: Some(-1.5),
                    saved: "2026-11-22T02:30:00Z".into(),
                    version: "0.1.0".into(),
                }],
                outputs: Some(OutputRecord {
                    made: "2026-11-22T02:31:00Z".into(),
                    version: "0.1.0".into(),
                    inputs: vec![file("cube7a.img"), file("cube7.cdf")],
                    files: vec![file("cube7.hpo"), file("cube7.ldr")],
                    counts: Counts {
                        edges_h: 1,
                        edges_v: 2,
                        lines_raw: 3,
                        lines: 1,
                    },
                    timings: TimingsRecord {
                        lens_us: 5,
                        edges_us: 6,
                        lines_us: 7,
                        connect_us: 8,
                    },
                    lex_attributes: LineAttributes::of(&[seg, Segment::default()]),
                    ldr_attributes: None,
                    params: Params::default(),
                }),
                edit: vec![EditRecord {
                    at: "2026-11-22T02:32:00Z".into(),
                    version: "0.1.0".into(),
                    op: "delete 0".into(),
                    lines: 0,
                    hash: "crc32:0:0".into(),
                }],
            }],
            calibration: vec![CalibrationRecord {
                camera: 2,
                made: "2026-01-01T00:00:00Z".into(),
                cdf: "profiles/sim/cam2.cdf".into(),
                views: 12,
                rms_px: 0.051,
                p95_px: 0.102,
                centre_stated: false,
            }],
        }
    }

    #[test]
    fn every_field_survives_toml_and_back() {
        let m = full();
        let text = m.to_toml().unwrap();
        assert_eq!(Manifest::parse(&text, Path::new("cube.toml")).unwrap(), m);
    }

    #[test]
    fn grey_records_without_camera_settings_are_written_and_read_without_them() {
        // The serial grabber's frames, and every manifest written before
        // exposure and gain were recorded.
        let mut m = full();
        m.image[0].grey[0].exposure_us = None;
        m.image[0].grey[0].gain_db = None;
        let text = m.to_toml().unwrap();
        assert!(
            !text.contains("exposure_us") && !text.contains("gain_db"),
            "{text}"
        );
        assert_eq!(Manifest::parse(&text, Path::new("cube.toml")).unwrap(), m);
    }

    #[test]
    fn attributes_round_trip_onto_lines() {
        let mut s = Segment::new(Point::new(0.0, 0.0), Point::new(1.0, 0.0));
        s.response = f64::NAN;
        s.residual = 0.5;
        s.shadow = true;
        let a = LineAttributes::of(&[Segment::default(), s]).unwrap();
        assert_eq!(a.response, vec![0.0, 0.0], "NaN is stored as 0");
        assert_eq!(a.shadow, vec![1]);
        let mut back = vec![Segment::default(); 2];
        a.apply(&mut back);
        assert!(back[1].shadow && back[1].residual == 0.5 && !back[0].shadow);
        assert!(LineAttributes::of(&[Segment::default()]).is_none());
    }

    #[test]
    fn sense_errors_point_at_their_line() {
        let mut m = full();
        m.lighting.push(m.lighting[0].clone());
        let text = m.to_toml().unwrap();
        let err = Manifest::parse(&text, Path::new("cube.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("appears twice"), "{err}");
        let line = text.lines().position(|l| l == "letter = \"a\"").unwrap() + 1;
        assert!(err.starts_with(&format!("cube.toml:{line}:")), "{err}");

        let mut m = full();
        m.image[0].number = MAX_IMAGE_NUMBER + 1;
        let err = refused_at(&m, &format!("number = {}", MAX_IMAGE_NUMBER + 1));
        assert!(err.contains(&format!("1 to {MAX_IMAGE_NUMBER}")), "{err}");

        let mut m = full();
        m.session.planned_images = u32::MAX;
        let err = Manifest::parse(&m.to_toml().unwrap(), Path::new("c.toml")).unwrap_err();
        assert!(
            err.to_string().contains("planned_images 4294967295"),
            "{err}"
        );

        let mut m = full();
        m.format = 9;
        let err = Manifest::parse(&m.to_toml().unwrap(), Path::new("c.toml")).unwrap_err();
        assert!(err.to_string().contains("format 9"), "{err}");
    }

    /// The error of `m` written and read back as `cube.toml`, which must
    /// name the line of the first `key_line` (the record's key and value).
    fn refused_at(m: &Manifest, key_line: &str) -> String {
        let text = m.to_toml().unwrap();
        let err = Manifest::parse(&text, Path::new("cube.toml"))
            .unwrap_err()
            .to_string();
        let line = text.lines().position(|l| l == key_line).unwrap() + 1;
        assert!(err.starts_with(&format!("cube.toml:{line}:")), "{err}");
        err
    }

    #[test]
    fn records_naming_a_camera_the_session_lacks_are_refused_at_their_line() {
        // The session has cameras 1 to 4; `full` names 3 (image 7) and 2
        // (its calibration).
        let refused = |m: Manifest, record: &str, camera: u32| {
            let err = refused_at(&m, &format!("camera = {camera}"));
            assert!(
                err.contains(&format!(
                    "{record}: camera {camera} is not one of the session's cameras, which run \
                     from 1 to 4"
                )),
                "{err}"
            );
        };
        for camera in [0, 5, 9, u32::MAX] {
            let mut m = full();
            m.image[0].camera = camera;
            refused(m, "[[image]] number 7", camera);
            let mut m = full();
            m.calibration[0].camera = camera;
            refused(m, "[[calibration]] made 2026-01-01T00:00:00Z", camera);
        }
        // The last camera is one of them.
        let mut m = full();
        m.image[0].camera = 4;
        m.calibration[0].camera = 4;
        assert_eq!(
            Manifest::parse(&m.to_toml().unwrap(), Path::new("c.toml")).unwrap(),
            m
        );
    }
}
