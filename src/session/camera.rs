//! The camera description every image of a session records (`NAMEk.cdf`)
//! and the one answer to "which camera model does image k run with, or why
//! none" ([`Session::image_camera`]), which `vss session redo`, the
//! console's load path and every re-run ask, so they cannot disagree
//! (docs/calibration.md, "After a recalibration").

use std::path::Path;

use super::manifest::FileRecord;
use super::{Session, SessionError, check_image_number, stamp};
use crate::formats;
use crate::llv::lens::CameraModel;

/// What image `k` of a session runs with when it is run again
/// ([`Session::image_camera`]).
#[derive(Clone, Debug, PartialEq)]
pub enum ImageCamera {
    /// No camera description is recorded with it (captured without one):
    /// it runs without lens correction, as it was captured.
    Unrecorded,
    /// Its recorded description, the one it was captured with, gives no
    /// camera model (why, as [`formats::cdf::Cdf::model`] says it): it runs
    /// without lens correction, as it was captured.
    NoModel(String),
    /// The camera model of its recorded description.
    Model(CameraModel),
}

impl ImageCamera {
    /// The camera model lens correction uses, if any.
    pub fn model(&self) -> Option<CameraModel> {
        match self {
            ImageCamera::Model(m) => Some(*m),
            _ => None,
        }
    }

    /// Why image `k` has no camera model, in words (`None` with one).
    pub fn problem(&self, k: u32) -> Option<String> {
        match self {
            ImageCamera::Model(_) => None,
            ImageCamera::Unrecorded => Some(format!(
                "image {k}: captured with no camera description, it is run without one"
            )),
            ImageCamera::NoModel(why) => Some(format!(
                "image {k}: the camera description recorded with it gives no camera model \
                 ({why})"
            )),
        }
    }
}

impl Session {
    /// Which camera model image `k` runs with, or why it cannot run: the
    /// one decision `vss session redo` ([`Session::pipeline_input`]) and
    /// the console (`store::load`) both take. An image runs with the
    /// description recorded with it, never another one: with none when it
    /// records none or its description gives no model (as it was
    /// captured). A recorded description that does not read, or that reads
    /// but gives no model and is not the file recorded (cut short at a
    /// line's end), is damaged: [`SessionError::CameraDamaged`] says what
    /// and where, and nothing runs, so no output is made without the lens
    /// correction the image was surveyed with. A description edited by
    /// hand that still gives a model is used (`vss session check` warns
    /// that it changed).
    pub fn image_camera(&self, k: u32) -> Result<ImageCamera, SessionError> {
        let Some(rec) = self.manifest.image(k).and_then(|r| r.cdf.as_ref()) else {
            return Ok(ImageCamera::Unrecorded);
        };
        let path = self.path(&rec.file);
        let damaged = |why: String| SessionError::CameraDamaged {
            image: k,
            path: path.clone(),
            why,
        };
        let at = |e: formats::FormatError| damaged(e.located());
        // Read as `read_cdf` reads it, keeping the bytes for the record's hash.
        let bytes = formats::read_bytes(&path).map_err(at)?;
        let text = formats::text_of(&bytes, &path).map_err(at)?;
        let cdf = formats::cdf::parse_cdf(text, &path).map_err(at)?;
        match cdf.model() {
            Ok(m) => Ok(ImageCamera::Model(m)),
            Err(why) if stamp::hash(&bytes) == rec.hash => Ok(ImageCamera::NoModel(why)),
            Err(why) => Err(damaged(format!(
                "it {why}, and it is not the file recorded with the image ({} bytes, {} \
                 recorded): cut short",
                bytes.len(),
                rec.hash.rsplit(':').next().unwrap_or("?")
            ))),
        }
    }

    /// Whether image `k` is recorded with the camera description `cdf`,
    /// byte for byte as [`Session::set_image_camera`] writes it, and its
    /// `NAMEk.cdf` still holds it (`None`: with none).
    pub fn recorded_with(&self, k: u32, cdf: Option<&formats::cdf::Cdf>) -> bool {
        let recorded = self.manifest.image(k).and_then(|r| r.cdf.as_ref());
        match (recorded, cdf) {
            (None, None) => true,
            (Some(r), Some(c)) => {
                let want = stamp::hash(formats::cdf::format_cdf(c).as_bytes());
                r.hash == want
                    && formats::read_bytes(&self.path(&r.file))
                        .is_ok_and(|b| stamp::hash(&b) == want)
            }
            _ => false,
        }
    }

    /// Records which camera at which location took image `k`, and copies
    /// its camera description into the session as `NAMEk.cdf` (checked by
    /// parsing it first).
    pub fn set_image_info(
        &mut self,
        k: u32,
        camera: u32,
        location: u32,
        cdf: Option<&Path>,
    ) -> Result<(), SessionError> {
        let parsed = cdf.map(formats::cdf::read_cdf).transpose()?;
        self.set_image_camera(k, camera, location, parsed.as_ref())
    }

    /// Records which camera at which location took image `k`, and writes
    /// its camera description (as [`crate::profile::Profile::camera_cdf`]
    /// gives it, from a file or built in) into the session as `NAMEk.cdf`.
    /// With none (the profile names no `.cdf` for the camera now), the
    /// image records none: an older record is dropped from the manifest
    /// and its `NAMEk.cdf` removed after the manifest is written (a crash
    /// in between leaves a file the manifest does not name, which `vss
    /// session check` lists, never a record of a missing file), so the
    /// image runs again as it was captured, without lens correction.
    pub fn set_image_camera(
        &mut self,
        k: u32,
        camera: u32,
        location: u32,
        cdf: Option<&formats::cdf::Cdf>,
    ) -> Result<(), SessionError> {
        self.writable()?;
        check_image_number(k)?;
        self.known_camera(camera)?;
        let cdf_record = match cdf {
            Some(parsed) => {
                let file = self.file_name(k, None, "cdf");
                let bytes = formats::cdf::format_cdf(parsed).into_bytes();
                self.write_file(&file, &bytes)?;
                Some(FileRecord {
                    hash: stamp::hash(&bytes),
                    file,
                })
            }
            None => None,
        };
        let rec = self.record_mut(k)?;
        rec.camera = camera;
        rec.location = location.max(1);
        let old = std::mem::replace(&mut rec.cdf, cdf_record);
        self.commit()?;
        if cdf.is_none()
            && let Some(old) = old
        {
            // The name itself is removed (a link, never what it points to);
            // one that will not go stays, unrecorded, for `check` to list.
            let _ = std::fs::remove_file(self.path(&old.file));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn session(dir: &Path) -> Session {
        let p = crate::profile::Profile::builtin().unwrap();
        let mut s = Session::create(dir, "cube", &p).unwrap();
        let cdf = crate::rig::sim::camera_cdf(1, 128, 128).unwrap();
        s.set_image_camera(1, 1, 1, Some(&cdf)).unwrap();
        s
    }

    #[test]
    fn a_recorded_description_runs_and_a_damaged_one_says_where() {
        let dir = tempfile::tempdir().unwrap();
        let s = session(dir.path());
        assert!(matches!(s.image_camera(1), Ok(ImageCamera::Model(_))));
        assert_eq!(s.image_camera(2).unwrap(), ImageCamera::Unrecorded);
        let path = s.path("cube1.cdf");
        let text = std::fs::read_to_string(&path).unwrap();
        // Cut inside D's values: does not parse.
        let d = text.find("D=").unwrap();
        std::fs::write(&path, &text[..d + 12]).unwrap();
        let e = s.image_camera(1).unwrap_err().to_string();
        assert!(e.contains("cube1.cdf is damaged (line "), "{e}");
        // Cut at a line's end before D: parses, gives no model, not the
        // recorded file.
        std::fs::write(&path, &text[..d]).unwrap();
        let e = s.image_camera(1).unwrap_err().to_string();
        assert!(
            e.contains("lacks its D line") && e.contains("cut short"),
            "{e}"
        );
        std::fs::remove_file(&path).unwrap();
        let e = s.image_camera(1).unwrap_err().to_string();
        assert!(e.contains("cube1.cdf is damaged (cannot read"), "{e}");
    }

    #[test]
    fn a_capture_without_a_description_drops_the_record_and_its_file() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = session(dir.path());
        assert!(s.path("cube1.cdf").is_file());
        s.set_image_camera(1, 1, 1, None).unwrap();
        assert_eq!(s.manifest().image(1).unwrap().cdf, None);
        assert!(!s.path("cube1.cdf").exists());
        assert_eq!(s.image_camera(1).unwrap(), ImageCamera::Unrecorded);
        assert!(s.recorded_with(1, None));
    }
}
