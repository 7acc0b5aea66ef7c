//! The simulated cell: a VSG/1 grabber and a Numato relay board served on
//! real pseudo-terminals by device threads, sharing one scene. What the
//! simulated camera digitises depends on the relays the simulated board has
//! switched on, on the selected camera, and on seeded sensor noise.
//!
//! The device side of each pty pair stays here; clients open the other side
//! by its path, exactly as they would open `/dev/ttyUSB0`. The sim also keeps
//! that other side open itself, so a client may come and go without the
//! device seeing a hang-up.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

use serialport::TTYPort;

use super::RigError;
use crate::llv::rng::SplitMix64;
use crate::profile::Profile;

mod board;
pub mod faults;
pub mod plate;
pub mod render;
mod vsg;

pub use faults::{Faults, FaultsError};

/// Standard normal by Box–Muller, one value per two uniforms (the
/// simulator's noise; its frames must repeat bit for bit for a seed).
fn gauss(rng: &mut SplitMix64) -> f64 {
    let u1 = rng.uniform().max(1e-300);
    let u2 = rng.uniform();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// One light of the simulated cell.
#[derive(Clone, Debug, PartialEq)]
pub struct SimLight {
    pub relay: u32,
    /// Position in the world frame (mm).
    pub position: [f64; 3],
}

/// Everything the simulated cell needs to know.
#[derive(Clone, Debug, PartialEq)]
pub struct SimOptions {
    pub width: u32,
    pub height: u32,
    pub seed: u64,
    /// Sensor noise σ in grey levels.
    pub noise: f64,
    pub cameras: u32,
    pub lights: Vec<SimLight>,
    /// Relays on the simulated board.
    pub relays: u32,
    /// Largest READ block the grabber serves.
    pub maxblock: u32,
    pub faults: Faults,
    /// How long the relay board takes between a command's echo and its
    /// answer and `>` prompt (real boards take up to tens of ms).
    pub prompt_delay: std::time::Duration,
}

impl SimOptions {
    /// The standard simulated cell at this image size, without faults.
    pub fn new(width: u32, height: u32) -> SimOptions {
        SimOptions::from_profile(&cell_profile(width, height))
    }

    /// The simulated cell a profile describes: its image size, noise, seed
    /// and lights (a light without a position gets one of the default
    /// positions, so every profile has a lit scene).
    pub fn from_profile(p: &Profile) -> SimOptions {
        let defaults = render::default_light_positions();
        let lights = p
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| SimLight {
                relay: l.relay,
                position: l.position.unwrap_or_else(|| {
                    defaults
                        .get(i % defaults.len().max(1))
                        .copied()
                        .unwrap_or([0.0, 0.0, 1000.0])
                }),
            })
            .collect();
        SimOptions {
            width: p.sim.width.clamp(16, 8192),
            height: p.sim.height.clamp(16, 8192),
            seed: p.sim.seed,
            noise: p.sim.noise.max(0.0),
            cameras: 4,
            lights,
            relays: p.relay.channels.unwrap_or(16),
            maxblock: 65536,
            faults: Faults::default(),
            prompt_delay: std::time::Duration::ZERO,
        }
    }
}

/// Noise-free frames by (camera, relay mask).
type FrameCache = HashMap<(u32, u32), Arc<Vec<f32>>>;

/// The state both simulated devices share.
pub struct Scene {
    pub opts: SimOptions,
    relays: Mutex<u32>,
    /// Noise-free frames per (camera, relay mask): rendering is costly,
    /// noise is cheap and drawn anew at every FREEZE.
    cache: Mutex<FrameCache>,
    /// A calibration plate shown instead of the bare cell (`None`: the cell).
    target: Mutex<Option<Arc<plate::PlateTarget>>>,
}

impl Scene {
    pub fn new(opts: SimOptions) -> Scene {
        Scene {
            opts,
            relays: Mutex::new(0),
            cache: Mutex::new(HashMap::new()),
            target: Mutex::new(None),
        }
    }

    pub fn relays(&self) -> u32 {
        *self.relays.lock().unwrap_or_else(PoisonError::into_inner)
    }

    pub fn set_relays(&self, mask: u32) {
        *self.relays.lock().unwrap_or_else(PoisonError::into_inner) = mask;
    }

    /// The noise-free image camera `cam` (1-based) sees under `mask`.
    pub fn clean(&self, cam: u32, mask: u32) -> Arc<Vec<f32>> {
        let key = (cam, mask & self.lit_mask());
        if let Some(img) = self
            .cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&key)
        {
            return Arc::clone(img);
        }
        let img = Arc::new(render::render_clean(&self.opts, cam, key.1));
        self.cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .insert(key, Arc::clone(&img));
        img
    }

    /// Relays that have a light on them (others do not change the image).
    fn lit_mask(&self) -> u32 {
        self.opts
            .lights
            .iter()
            .filter(|l| l.relay < 32)
            .fold(0, |m, l| m | (1 << l.relay))
    }

    /// Shows a calibration plate from the next freeze on (`None`: the cell).
    pub fn set_target(&self, target: Option<plate::PlateTarget>) {
        *self.target.lock().unwrap_or_else(PoisonError::into_inner) = target.map(Arc::new);
    }

    /// The calibration plate being shown, if any.
    pub fn target(&self) -> Option<Arc<plate::PlateTarget>> {
        self.target
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// A digitised frame: the clean image plus seeded noise, as 8 bits.
    pub fn frame(&self, cam: u32, mask: u32, shot: u64) -> Vec<u8> {
        let mut clean = self.clean(cam, mask);
        if let Some(t) = self.target() {
            clean = Arc::new(t.render(&self.opts, cam, shot, &clean));
        }
        let mut rng = SplitMix64::new(
            self.opts.seed ^ shot.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ u64::from(cam) << 56,
        );
        let sigma = self.opts.noise;
        clean
            .iter()
            .map(|&v| {
                let n = if sigma > 0.0 {
                    gauss(&mut rng) * sigma
                } else {
                    0.0
                };
                (f64::from(v) + n).round().clamp(0.0, 255.0) as u8
            })
            .collect()
    }
}

/// A device thread serving one pty.
struct Device {
    path: String,
    stop: Arc<AtomicBool>,
    alive: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Device {
    fn start(
        name: &str,
        serve: impl FnOnce(TTYPort, Arc<AtomicBool>, String) + Send + 'static,
    ) -> Result<Device, RigError> {
        let (master, slave) = TTYPort::pair().map_err(|e| {
            RigError::Sim(format!("cannot make a pseudo-terminal for the {name}: {e}"))
        })?;
        let path = serialport::SerialPort::name(&slave)
            .ok_or_else(|| RigError::Sim(format!("the {name}'s pseudo-terminal has no name")))?;
        let stop = Arc::new(AtomicBool::new(false));
        let alive = Arc::new(AtomicBool::new(true));
        let (s, a, p) = (Arc::clone(&stop), Arc::clone(&alive), path.clone());
        let thread = std::thread::Builder::new()
            .name(format!("sim-{name}"))
            .spawn(move || {
                // The slave side lives as long as the device: a client that
                // closes its end must not hang the line up.
                let _keep = slave;
                serve(master, s, p);
                a.store(false, Ordering::SeqCst);
            })
            .map_err(|e| RigError::Sim(format!("cannot start the {name} thread: {e}")))?;
        Ok(Device {
            path,
            stop,
            alive,
            thread: Some(thread),
        })
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// The simulated cell: both devices and their scene.
pub struct SimCell {
    scene: Arc<Scene>,
    grabber: Device,
    board: Device,
    /// A symlink kept pointing at the grabber's pty, so a client can reopen
    /// "the same port" after a replug, as with a real `/dev/ttyUSB0`.
    grabber_link: Arc<Mutex<Option<PathBuf>>>,
}

impl SimCell {
    /// Starts the simulated grabber and relay board on fresh ptys.
    pub fn start(opts: SimOptions) -> Result<SimCell, RigError> {
        let scene = Arc::new(Scene::new(opts));
        let grabber_link = Arc::new(Mutex::new(None));
        let grabber = Self::start_grabber(&scene, scene.opts.faults.clone(), &grabber_link)?;
        let sc = Arc::clone(&scene);
        let board = Device::start("relay board", move |port, stop, _path| {
            board::serve(port, &sc, &stop)
        })?;
        Ok(SimCell {
            scene,
            grabber,
            board,
            grabber_link,
        })
    }

    /// The simulated cell of a profile, with `faults` on the grabber.
    pub fn from_profile(p: &Profile, faults: Faults) -> Result<SimCell, RigError> {
        let mut o = SimOptions::from_profile(p);
        o.faults = faults;
        SimCell::start(o)
    }

    fn start_grabber(
        scene: &Arc<Scene>,
        faults: Faults,
        link: &Arc<Mutex<Option<PathBuf>>>,
    ) -> Result<Device, RigError> {
        let sc = Arc::clone(scene);
        let link = Arc::clone(link);
        Device::start("grabber", move |port, stop, path| {
            vsg::serve(port, &sc, faults, &stop);
            // Unplugged: the device name goes away, as /dev/ttyUSB0 does.
            if !stop.load(Ordering::SeqCst) {
                let l = link.lock().unwrap_or_else(PoisonError::into_inner).clone();
                if let Some(l) = l
                    && std::fs::read_link(&l).is_ok_and(|t| t == Path::new(&path))
                {
                    let _ = std::fs::remove_file(&l);
                }
            }
        })
    }

    pub fn grabber_path(&self) -> &str {
        &self.grabber.path
    }

    pub fn relay_path(&self) -> &str {
        &self.board.path
    }

    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// Whether the grabber is still plugged in (an `unplug-after` fault
    /// pulls it).
    pub fn grabber_plugged(&self) -> bool {
        self.grabber.alive.load(Ordering::SeqCst)
    }

    /// Plugs the grabber back in, power-cycled (no frame, camera 1) and
    /// without faults, on a new pseudo-terminal; returns its path.
    pub fn replug_grabber(&mut self) -> Result<&str, RigError> {
        self.grabber.shutdown();
        self.grabber = Self::start_grabber(&self.scene, Faults::default(), &self.grabber_link)?;
        let link = self
            .grabber_link
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone();
        if let Some(link) = link {
            self.link_grabber(&link)?;
        }
        Ok(&self.grabber.path)
    }

    /// Keeps a symlink at `link` pointing at the grabber's pseudo-terminal,
    /// also across [`SimCell::replug_grabber`]: a stable device name. Only
    /// a symbolic link (one an earlier `vss sim --link` left) is replaced:
    /// a file or folder at `link` is refused, never replaced or deleted.
    #[cfg(unix)]
    pub fn link_grabber(&mut self, link: &Path) -> Result<(), RigError> {
        let fail = |e: String| {
            RigError::Sim(format!(
                "cannot link {} to the grabber: {e}",
                crate::text::path(link)
            ))
        };
        match std::fs::symlink_metadata(link) {
            Ok(m) if !m.file_type().is_symlink() => {
                return Err(fail(format!(
                    "{} exists and is not a symbolic link; vss replaces only a link \
                     (remove it or choose another name)",
                    crate::text::path(link)
                )));
            }
            _ => {}
        }
        if let Some(target) = held_elsewhere(link, &self.grabber.path) {
            return Err(fail(format!(
                "it points at {}, a terminal that was open before the link was made and \
                 still is (another `vss sim --link` serving it?); stop that one, or remove \
                 the link if nothing uses it, or choose another name",
                crate::text::path(&target)
            )));
        }
        let name = link.file_name().map(|n| n.to_string_lossy().into_owned());
        // A name of this process's own, made by symlink(2), which never
        // replaces anything: whatever else is there stays.
        let tmp = link.with_file_name(format!(
            ".{}.new.{}",
            name.unwrap_or_default(),
            std::process::id()
        ));
        if std::fs::symlink_metadata(&tmp).is_ok_and(|m| m.file_type().is_symlink()) {
            let _ = std::fs::remove_file(&tmp);
        }
        std::os::unix::fs::symlink(&self.grabber.path, &tmp).map_err(|e| fail(e.to_string()))?;
        // Checked again right before the rename, which replaces what is there.
        if std::fs::symlink_metadata(link).is_ok_and(|m| !m.file_type().is_symlink()) {
            let _ = std::fs::remove_file(&tmp);
            return Err(fail(format!(
                "{} appeared and is not a link",
                crate::text::path(link)
            )));
        }
        if let Err(e) = std::fs::rename(&tmp, link) {
            let _ = std::fs::remove_file(&tmp);
            return Err(fail(e.to_string()));
        }
        *self
            .grabber_link
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Some(link.to_path_buf());
        Ok(())
    }

    /// The stable name of the grabber, if one was made.
    pub fn grabber_link(&self) -> Option<PathBuf> {
        self.grabber_link
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// One line for people.
    pub fn summary(&self) -> String {
        let o = &self.scene.opts;
        format!(
            "simulated cell: grabber {} ({}x{}, {} cameras, {}), relay board {} (Numato, {} relays, {} lights), seed {}, noise {}",
            self.grabber.path,
            o.width,
            o.height,
            o.cameras,
            o.faults.summary(),
            self.board.path,
            o.relays,
            o.lights.len(),
            o.seed,
            o.noise
        )
    }

    pub fn stop(mut self) {
        self.grabber.shutdown();
        self.board.shutdown();
        let link = self
            .grabber_link
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        // Only the link this cell made, still pointing at its grabber.
        if let Some(link) = link
            && std::fs::read_link(&link).is_ok_and(|t| t == Path::new(&self.grabber.path))
        {
            let _ = std::fs::remove_file(link);
        }
    }
}

/// Where `link` points, when it is a symbolic link another simulator keeps:
/// to a terminal other than `own` that is open and was made before the link
/// (a pseudo-terminal's name exists only while it is open; one made after
/// the link only reuses the number of a terminal that is gone, as after a
/// simulator killed with SIGKILL).
#[cfg(unix)]
fn held_elsewhere(link: &Path, own: &str) -> Option<PathBuf> {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let target = std::fs::read_link(link).ok()?;
    if target == Path::new(own) {
        return None;
    }
    let linked = std::fs::symlink_metadata(link).ok()?;
    let at = match link.parent() {
        Some(dir) if target.is_relative() => dir.join(&target),
        _ => target.clone(),
    };
    let tty = std::fs::metadata(at).ok()?;
    let made = (tty.ctime(), tty.ctime_nsec());
    (tty.file_type().is_char_device() && made <= (linked.mtime(), linked.mtime_nsec()))
        .then_some(target)
}

/// The standard simulated cell as a profile: the embedded grabber and relay
/// board, the synthetic cell's four lights on relays 0–3 at their positions,
/// lightings `a`–`d` (one light each) and `e` (ambient only), and the
/// cameras' `.cdf` files from `profiles/sim/`. `profiles/default.toml` is
/// this profile at 512 × 512; tests use it smaller.
pub fn cell_profile(width: u32, height: u32) -> Profile {
    use crate::profile::{Light, Lighting};
    let positions = render::default_light_positions();
    let names = crate::synth::CELL_LIGHT_NAMES;
    let mut p = Profile {
        name: "simulated cell".into(),
        ..Profile::default()
    };
    p.sim.width = width;
    p.sim.height = height;
    p.lights = names
        .iter()
        .zip(&positions)
        .enumerate()
        .map(|(i, (n, pos))| Light {
            name: (*n).to_string(),
            relay: i as u32,
            position: Some(*pos),
        })
        .collect();
    p.lighting = names
        .iter()
        .zip(['a', 'b', 'c', 'd'])
        .map(|(n, letter)| Lighting {
            letter,
            on: vec![(*n).to_string()],
            note: format!("{n} light only"),
        })
        .chain(std::iter::once(Lighting {
            letter: 'e',
            on: Vec::new(),
            note: "ambient only".into(),
        }))
        .collect();
    p.survey.cameras = 4;
    p.survey.cdf = (1..=4)
        .map(|k| std::path::PathBuf::from(format!("sim/cam{k}.cdf")))
        .collect();
    p
}

/// The `.cdf` of simulated camera `cam` (1-based) at this image size:
/// intrinsics, lens distortion and pose as the simulator renders them.
pub fn camera_cdf(cam: u32, width: u32, height: u32) -> Option<crate::formats::cdf::Cdf> {
    let cams = crate::synth::cell_cameras(width as usize, height as usize);
    let c = cams.get(cam.checked_sub(1)? as usize)?;
    Some(crate::formats::cdf::Cdf::from_camera(
        &c.model,
        Some(c.pose),
    ))
}
