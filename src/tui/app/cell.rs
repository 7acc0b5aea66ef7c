//! What the console knows of the cell: the profile's lightings, lights and
//! cameras, the camera models, and what the devices last reported (who
//! answers, the lights on, a transfer under way, the live picture).

use crate::llv::GreyImage;
use crate::llv::lens::CameraModel;
use crate::profile::Profile;
use crate::session::input::FrameRule;
use crate::tui::event::FramePurpose;
use crate::tui::text::clean;

/// What the devices last reported.
#[derive(Clone, Debug, Default)]
pub struct DeviceState {
    pub connected: bool,
    pub grabber: String,
    pub relay: String,
    pub lost: Option<String>,
    /// What `lost` says is another program holding a port, not a fault
    /// ([`DeviceState::lost_word`]).
    pub busy: bool,
    pub lights_on: Vec<String>,
    pub mask: u32,
    /// A frame coming in: what for, bytes done and total.
    pub transfer: Option<(FramePurpose, usize, usize)>,
    /// The lights are settling before a freeze (nothing transferred yet).
    pub settling: bool,
    pub live: bool,
    /// The operator stopped the transfer under way (Esc): its failure is
    /// that stop, not a fault.
    pub cancelled: bool,
}

#[derive(Debug)]
pub struct CellState {
    pub profile_name: String,
    /// Which profile file is in use ([`Profile::in_use`]): its absolute
    /// path, or `built-in`.
    pub profile_file: String,
    /// Lighting letters of the profile, and which one is ambient (no light on).
    pub letters: Vec<char>,
    pub ambient: Option<char>,
    /// Which frames are lit and which is ambient: the session code's rule.
    pub rule: FrameRule,
    /// Light names and relay channels, in profile order.
    pub lights: Vec<(String, u32)>,
    /// Lighting configuration letter → names of the lights on.
    pub lighting_on: Vec<(char, Vec<String>)>,
    pub cameras: u32,
    /// Each camera's model (index 0 is camera 1), or why it has none —
    /// as [`Profile::camera_cdf`] gives them (the store worker asks it).
    pub camera_models: Vec<Result<CameraModel, String>>,
    /// Where each camera's `.cdf` is written by Calibrate (index 0 is
    /// camera 1).
    pub cdf_paths: Vec<Option<std::path::PathBuf>>,
    pub device: DeviceState,
    /// The latest frame of the live view or a single grab (camera, image).
    pub live: Option<(u32, GreyImage)>,
}

impl DeviceState {
    /// What the screens call a device that does not answer: "BUSY" when
    /// another program holds its port, else "LOST".
    pub fn lost_word(&self) -> &'static str {
        if self.busy { "BUSY" } else { "LOST" }
    }
}

impl CellState {
    pub fn new(profile: &Profile) -> CellState {
        let rule = FrameRule::of_profile(profile);
        let ambient = rule.ambient();
        CellState {
            rule,
            profile_name: clean(&profile.name),
            profile_file: clean(&profile.in_use()),
            letters: profile.lighting.iter().map(|l| l.letter).collect(),
            ambient,
            lights: profile
                .lights
                .iter()
                .map(|l| (clean(&l.name), l.relay))
                .collect(),
            lighting_on: profile
                .lighting
                .iter()
                .map(|l| (l.letter, l.on.iter().map(|s| clean(s)).collect()))
                .collect(),
            cameras: profile.survey.cameras.max(1),
            camera_models: Vec::new(),
            cdf_paths: (1..=profile.survey.cameras.max(1))
                .map(|k| profile.cdf_path(k))
                .collect(),
            device: DeviceState::default(),
            live: None,
        }
    }

    /// The camera model of camera `cam` (1-based), if its `.cdf` has one.
    pub fn camera_model(&self, cam: u32) -> Option<CameraModel> {
        self.camera_models
            .get(cam.checked_sub(1)? as usize)?
            .as_ref()
            .ok()
            .copied()
    }

    /// Why camera `cam` (1-based) has no model for lens correction, once
    /// the store has said (`None` while it has not, or when it has one).
    /// A camera past the profile's (a session made with a profile of more
    /// cameras) has no `.cdf` here at all.
    pub fn camera_problem(&self, cam: u32) -> Option<String> {
        if self.camera_models.is_empty() {
            return None;
        }
        match self.camera_models.get(cam.checked_sub(1)? as usize) {
            Some(m) => m.as_ref().err().cloned(),
            None => Some(format!(
                "not one of this profile's {} cameras, so it has no camera description",
                self.cameras
            )),
        }
    }
}
