//! [`Cell`]: the grabber and the relay board a profile names, opened as real
//! serial ports or as the embedded simulated cell on pseudo-terminals (the
//! same drivers either way), plus the lighting configurations: switch to
//! configuration `b`, read the relays back, wait the settle time, and always
//! know which lights are on.

use std::time::{Duration, Instant};

use super::RigError;
use super::grabber::{ClientConfig, FrameGrabber, VsgClient};
use super::lights::{LcusBoard, LightSwitch, NumatoBoard};
use super::protocol::{FrameInfo, GrabberInfo};
use super::sim::{Faults, SimCell};
use crate::llv::GreyImage;
use crate::profile::{GrabberKind, Profile, RelayKind};
use crate::session::FrameSettings;

/// The cell's devices and what they are set to.
pub struct Cell {
    pub grabber: Box<dyn FrameGrabber>,
    pub lights: Box<dyn LightSwitch>,
    sim: Option<SimCell>,
    profile: Profile,
    info: GrabberInfo,
    /// The relays known to be on (read back from the board).
    mask: u32,
    lighting: Option<char>,
}

/// One captured frame and how it was taken.
#[derive(Clone, Debug)]
pub struct Capture {
    pub image: GreyImage,
    pub frame: FrameInfo,
    pub camera: u32,
    pub lighting: char,
    pub lights_on: Vec<String>,
    /// The camera's exposure and gain when it took the frame (none from
    /// the serial grabber).
    pub settings: FrameSettings,
    /// Switch + settle + freeze + transfer.
    pub elapsed: Duration,
}

/// Channels of an LCUS board when the profile's lights do not say more.
const LCUS_CHANNELS: u32 = 8;

/// Opens the relay board a profile names (`sim` is the embedded simulated
/// cell, needed when the board is `simulated`).
pub fn open_lights(
    profile: &Profile,
    sim: Option<&SimCell>,
) -> Result<Box<dyn LightSwitch>, RigError> {
    let r = &profile.relay;
    let timeout = Duration::from_millis(r.timeout_ms.max(1));
    Ok(match (r.kind, sim) {
        (RelayKind::Simulated, Some(s)) => Box::new(NumatoBoard::open(
            s.relay_path(),
            r.baud,
            timeout,
            Some(s.scene().opts.relays),
        )?),
        (RelayKind::Simulated, None) => {
            return Err(RigError::Config(
                "the relay board is `simulated` but no simulated cell runs".into(),
            ));
        }
        (RelayKind::Lcus, _) => {
            let channels = r.channels.unwrap_or_else(|| {
                profile
                    .lights
                    .iter()
                    .map(|l| l.relay + 1)
                    .max()
                    .unwrap_or(0)
                    .max(LCUS_CHANNELS)
            });
            Box::new(LcusBoard::open(&r.port, channels, timeout)?)
        }
        (RelayKind::Numato, _) => {
            Box::new(NumatoBoard::open(&r.port, r.baud, timeout, r.channels)?)
        }
    })
}

/// Opens the grabber a profile names and says hello: the VSG/1 client on
/// its serial port or on the simulated cell's pseudo-terminal, or the
/// GenICam cameras.
fn open_grabber(
    profile: &Profile,
    sim: Option<&SimCell>,
) -> Result<(Box<dyn FrameGrabber>, GrabberInfo), RigError> {
    let g = &profile.grabber;
    let path = match (g.kind, sim) {
        (GrabberKind::Genicam, _) => return open_genicam(g),
        (GrabberKind::Simulated, Some(s)) => s.grabber_path().to_string(),
        _ => g.port.clone(),
    };
    let mut grabber = VsgClient::open(&path, g.baud, ClientConfig::from_profile(g))?;
    let info = match grabber.info() {
        Some(i) => i.clone(),
        None => grabber.hello()?,
    };
    Ok((Box::new(grabber), info))
}

#[cfg(feature = "genicam")]
fn open_genicam(
    g: &crate::profile::GrabberConfig,
) -> Result<(Box<dyn FrameGrabber>, GrabberInfo), RigError> {
    let mut grabber = super::genicam::GenicamGrabber::open(g)?;
    let info = grabber.hello()?;
    Ok((Box::new(grabber), info))
}

#[cfg(not(feature = "genicam"))]
fn open_genicam(
    _g: &crate::profile::GrabberConfig,
) -> Result<(Box<dyn FrameGrabber>, GrabberInfo), RigError> {
    Err(RigError::Config(
        "the profile's grabber is `genicam`, but this vss was built without GenICam cameras: \
         install libaravis-dev and libusb-1.0-0-dev, then build with \
         `cargo build --release --features genicam`"
            .into(),
    ))
}

impl Cell {
    /// Opens the cell a profile describes. `simulated` devices start the
    /// embedded simulator on pseudo-terminals and the same drivers connect
    /// to it; `vsg`/`numato`/`lcus` open the profile's serial ports.
    pub fn open(profile: &Profile) -> Result<Cell, RigError> {
        Cell::open_with_faults(profile, Faults::default())
    }

    /// Like [`Cell::open`], with faults injected into a simulated grabber.
    pub fn open_with_faults(profile: &Profile, faults: Faults) -> Result<Cell, RigError> {
        let needs_sim = profile.grabber.kind == GrabberKind::Simulated
            || profile.relay.kind == RelayKind::Simulated;
        let sim = if needs_sim {
            Some(SimCell::from_profile(profile, faults)?)
        } else {
            None
        };
        let (grabber, info) = open_grabber(profile, sim.as_ref())?;
        let lights = open_lights(profile, sim.as_ref())?;
        let mut cell = Cell {
            grabber,
            lights,
            sim,
            profile: profile.clone(),
            info,
            mask: 0,
            lighting: None,
        };
        cell.mask = cell.lights.read_mask()?;
        Ok(cell)
    }

    /// The embedded simulator, if the profile asked for one.
    pub fn sim(&self) -> Option<&SimCell> {
        self.sim.as_ref()
    }

    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// The grabber as it introduced itself (model, frame size, cameras).
    pub fn info(&self) -> &GrabberInfo {
        &self.info
    }

    /// The relay mask lighting configuration `letter` asks for.
    pub fn mask_for(&self, letter: char) -> Result<u32, RigError> {
        let Some(cfg) = self.profile.lighting.iter().find(|l| l.letter == letter) else {
            let known: String = self.profile.lighting.iter().map(|l| l.letter).collect();
            return Err(RigError::Config(format!(
                "no lighting configuration `{letter}` in the profile (it has: {})",
                if known.is_empty() {
                    "none".into()
                } else {
                    known
                }
            )));
        };
        let mut mask = 0u32;
        for name in &cfg.on {
            let light = self
                .profile
                .lights
                .iter()
                .find(|l| &l.name == name)
                .ok_or_else(|| {
                    RigError::Config(format!(
                        "lighting `{letter}` names light `{name}`, which is not in the profile's [[lights]]"
                    ))
                })?;
            if light.relay >= 32 {
                return Err(RigError::Config(format!(
                    "light `{name}` is on relay {}; relays go from 0 to 31",
                    light.relay
                )));
            }
            mask |= 1 << light.relay;
        }
        Ok(mask)
    }

    /// Sets the relays to `mask`, reads them back, and remembers them.
    pub fn set_lights(&mut self, mask: u32) -> Result<(), RigError> {
        self.lighting = None;
        let r = self.lights.set_mask(mask);
        // Whatever happened, learn what is really on.
        self.mask = self.lights.read_mask().unwrap_or(self.mask);
        r?;
        if self.mask != mask {
            return Err(RigError::RelayMismatch {
                port: self.lights.port_name().to_string(),
                relay: "mask".into(),
                expected: format!("{mask:04x}"),
                got: format!("{:04x}", self.mask),
            });
        }
        Ok(())
    }

    /// Switches to lighting configuration `letter` and waits the settle
    /// time, so a freeze right after sees the new light.
    pub fn switch_lighting(&mut self, letter: char) -> Result<(), RigError> {
        let mask = self.mask_for(letter)?;
        self.set_lights(mask)?;
        self.lighting = Some(letter);
        std::thread::sleep(Duration::from_millis(self.profile.relay.settle_ms));
        Ok(())
    }

    /// The lighting configuration last switched to (`None` after a manual
    /// change).
    pub fn lighting(&self) -> Option<char> {
        self.lighting
    }

    /// The relays known to be on.
    pub fn mask(&self) -> u32 {
        self.mask
    }

    /// Names of the lights that are on (relays without a light show as
    /// `relay N`).
    pub fn lights_on(&self) -> Vec<String> {
        let mut names = Vec::new();
        for bit in 0..32 {
            if self.mask & (1 << bit) == 0 {
                continue;
            }
            match self.profile.lights.iter().find(|l| l.relay == bit) {
                Some(l) => names.push(l.name.clone()),
                None => names.push(format!("relay {bit}")),
            }
        }
        names
    }

    /// Selects `camera`, switches to `letter`, freezes and transfers. A
    /// grabber that loses its frame on the way (a reset) is asked for it
    /// again by its driver (`VsgClient`'s transfer says when); the frame
    /// returned has passed every CRC check, against the FREEZE that made it.
    pub fn capture(
        &mut self,
        camera: u32,
        letter: char,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<Capture, RigError> {
        let start = Instant::now();
        self.switch_lighting(letter)?;
        self.grabber.select_camera(camera)?;
        let frozen = self.grabber.freeze()?;
        let image = self.grabber.transfer(progress)?;
        Ok(Capture {
            image,
            frame: self.grabber.frame().unwrap_or(frozen),
            camera,
            lighting: letter,
            lights_on: self.lights_on(),
            settings: self.frame_settings(),
            elapsed: start.elapsed(),
        })
    }

    /// The selected camera's exposure and gain as the grabber last read
    /// them (a GenICam grabber reads them at every freeze); none from the
    /// serial grabber.
    pub fn frame_settings(&self) -> FrameSettings {
        self.grabber
            .camera_state()
            .map_or_else(FrameSettings::default, |s| s.frame_settings())
    }

    /// After the grabber vanished or stopped answering: plug the simulated
    /// one back in if it was pulled, and reopen the port (the old one is
    /// closed first: serial ports are opened exclusively).
    pub fn reconnect_grabber(&mut self) -> Result<(), RigError> {
        let simulated = self.profile.grabber.kind == GrabberKind::Simulated;
        let pulled = |c: &Cell| simulated && c.sim.as_ref().is_some_and(|s| !s.grabber_plugged());
        if !pulled(self) {
            match self.grabber.reconnect() {
                // It went away while we tried: plug it back in below.
                Err(_) if pulled(self) => {}
                r => return r,
            }
        }
        let Some(sim) = self.sim.as_mut() else {
            return Err(RigError::Sim("no simulated cell".into()));
        };
        let path = sim.replug_grabber()?.to_string();
        self.grabber = Box::new(Unplugged {
            port: self.grabber.port_name().to_string(),
        });
        let g = &self.profile.grabber;
        self.grabber = Box::new(VsgClient::open(
            &path,
            g.baud,
            ClientConfig::from_profile(g),
        )?);
        Ok(())
    }
}

/// Stands in for a grabber between closing its old port and opening the
/// new one; every call says the device is not there.
struct Unplugged {
    port: String,
}

impl Unplugged {
    fn err(&self) -> RigError {
        RigError::Vanished {
            port: self.port.clone(),
            source: std::io::Error::new(std::io::ErrorKind::NotConnected, "not connected"),
        }
    }
}

impl FrameGrabber for Unplugged {
    fn hello(&mut self) -> Result<GrabberInfo, RigError> {
        Err(self.err())
    }
    fn init(&mut self) -> Result<(), RigError> {
        Err(self.err())
    }
    fn live(&mut self, _cam: u32) -> Result<(), RigError> {
        Err(self.err())
    }
    fn freeze(&mut self) -> Result<FrameInfo, RigError> {
        Err(self.err())
    }
    fn select_camera(&mut self, _cam: u32) -> Result<(), RigError> {
        Err(self.err())
    }
    fn load(&mut self, _img: &GreyImage) -> Result<(), RigError> {
        Err(self.err())
    }
    fn transfer(
        &mut self,
        _progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        Err(self.err())
    }
    fn status(&mut self) -> Result<crate::rig::GrabberStatus, RigError> {
        Err(self.err())
    }
    fn frame(&self) -> Option<FrameInfo> {
        None
    }
    fn port_name(&self) -> &str {
        &self.port
    }
    fn reconnect(&mut self) -> Result<(), RigError> {
        Err(self.err())
    }
    fn wire_stats(&self) -> crate::rig::WireStats {
        crate::rig::WireStats::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The console runs the cell on a device worker thread.
    #[test]
    fn cell_can_move_to_a_worker_thread() {
        fn assert_send<T: Send>() {}
        assert_send::<Cell>();
    }

    #[test]
    fn lighting_masks_come_from_the_profile() {
        let mut p = crate::rig::sim::cell_profile(32, 32);
        p.relay.settle_ms = 0;
        let Ok(cell) = Cell::open(&p) else {
            panic!("the simulated cell opens")
        };
        assert_eq!(cell.info().cameras, 4);
        assert_eq!((cell.info().width, cell.info().height), (32, 32));
        assert_eq!(cell.mask_for('c').ok(), Some(0b100));
        assert_eq!(cell.mask_for('e').ok(), Some(0));
        p.lighting[0].on.push("nowhere".into());
        let cell = Cell { profile: p, ..cell };
        let e = cell
            .mask_for('a')
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("nowhere"), "{e}");
    }
}
