//! The device worker: owns the [`Cell`] (grabber + relay board, or the
//! embedded simulated cell), runs captures with progress and a cancel flag,
//! keeps the live view going at a throttled rate, and when a device vanishes
//! says so and keeps trying to reconnect.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::send;
use crate::profile::Profile;
use crate::rig::{CameraState, Cell, FrameGrabber, RigError};
use crate::tui::event::{DeviceCmd, DeviceEvent, FramePurpose, Msg};

/// Least time between two live frames: the link and the terminal keep up.
pub const LIVE_INTERVAL: Duration = Duration::from_millis(500);
/// Time between reconnection attempts after a device vanished.
pub const RETRY_INTERVAL: Duration = Duration::from_secs(2);

/// The UI's handle on the device worker.
pub struct DeviceHandle {
    pub tx: Sender<DeviceCmd>,
    /// Set to stop the transfer under way (checked between blocks).
    pub cancel: Arc<AtomicBool>,
    pub join: JoinHandle<()>,
}

impl DeviceHandle {
    /// Forwards a command; `Cancel` also raises the flag the running
    /// transfer polls, since the worker is not reading commands then.
    pub fn send(&self, cmd: DeviceCmd) {
        if cmd == DeviceCmd::Cancel {
            self.cancel.store(true, Ordering::SeqCst);
        }
        let _ = self.tx.send(cmd);
    }
}

/// How the worker opens the cell (again, if it never answered).
pub type Opener = Box<dyn FnMut() -> Result<Cell, RigError> + Send>;

/// Starts the worker on the cell the profile describes.
pub fn spawn(profile: Profile, ui: Sender<Msg>) -> std::io::Result<DeviceHandle> {
    spawn_with(Box::new(move || Cell::open(&profile)), ui)
}

/// Starts the worker on a cell opened by `open` (tests inject faults here).
pub fn spawn_with(open: Opener, ui: Sender<Msg>) -> std::io::Result<DeviceHandle> {
    let (tx, rx) = mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    let join = std::thread::Builder::new()
        .name("vss-device".into())
        .spawn(move || Worker::new(open, ui, flag).run(rx))?;
    Ok(DeviceHandle { tx, cancel, join })
}

struct Worker {
    open: Opener,
    ui: Sender<Msg>,
    cancel: Arc<AtomicBool>,
    cell: Option<Cell>,
    /// False after a device vanished, until reconnected.
    healthy: bool,
    last_try: Option<Instant>,
    live: Option<u32>,
    last_live: Option<Instant>,
}

fn ev(ui: &Sender<Msg>, e: DeviceEvent) {
    send(ui, Msg::Device(e));
}

impl Worker {
    fn new(open: Opener, ui: Sender<Msg>, cancel: Arc<AtomicBool>) -> Worker {
        Worker {
            open,
            ui,
            cancel,
            cell: None,
            healthy: false,
            last_try: None,
            live: None,
            last_live: None,
        }
    }

    /// Least time between two live frames: the grabber's own (a GenICam
    /// camera's is short), or [`LIVE_INTERVAL`].
    fn live_interval(&self) -> Duration {
        self.cell
            .as_ref()
            .and_then(|c| c.grabber.live_interval())
            .unwrap_or(LIVE_INTERVAL)
    }

    fn run(mut self, rx: Receiver<DeviceCmd>) {
        loop {
            self.ensure_connected();
            let interval = self.live_interval();
            let wait = match (self.live, self.last_live) {
                (Some(_), Some(t)) => interval.saturating_sub(t.elapsed()),
                (Some(_), None) => Duration::ZERO,
                _ if !self.healthy => RETRY_INTERVAL,
                _ => Duration::from_secs(3600),
            };
            match rx.recv_timeout(wait) {
                Ok(cmd) => self.handle(cmd),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if let Some(cam) = self.live
                && self.healthy
                && self.last_live.is_none_or(|t| t.elapsed() >= interval)
            {
                self.last_live = Some(Instant::now());
                self.grab(FramePurpose::Live, cam, None);
            }
        }
        // Leave the cell dark.
        if let Some(c) = self.cell.as_mut() {
            let _ = c.set_lights(0);
        }
    }

    fn ensure_connected(&mut self) {
        if self.healthy || self.last_try.is_some_and(|t| t.elapsed() < RETRY_INTERVAL) {
            return;
        }
        self.last_try = Some(Instant::now());
        let result = match self.cell.as_mut() {
            Some(c) => c.reconnect_grabber(),
            None => (self.open)().map(|c| {
                self.cell = Some(c);
            }),
        };
        let hello = result.and_then(|_| match self.cell.as_mut() {
            Some(c) => c.grabber.hello().map(|h| {
                // A GenICam camera also says what it is and how it is set.
                let port = match c.grabber.camera_state() {
                    Some(st) => format!("{}: {}", c.grabber.port_name(), st.summary()),
                    None => c.grabber.port_name().to_string(),
                };
                (h, c.lights.port_name().to_string(), port)
            }),
            None => Err(RigError::Config("no cell".into())),
        });
        match hello {
            Ok((h, relay_port, grabber_port)) => {
                self.healthy = true;
                ev(
                    &self.ui,
                    DeviceEvent::Connected {
                        grabber: format!(
                            "{} {}×{} {} cameras on {grabber_port}",
                            h.model, h.width, h.height, h.cameras
                        ),
                        relay: relay_port,
                    },
                );
                self.report_lights();
            }
            Err(e) => {
                self.healthy = false;
                ev(
                    &self.ui,
                    DeviceEvent::Lost {
                        error: e.to_string(),
                        busy: e.is_busy(),
                    },
                );
            }
        }
    }

    fn report_lights(&mut self) {
        if let Some(c) = self.cell.as_ref() {
            ev(
                &self.ui,
                DeviceEvent::Lights {
                    on: c.lights_on(),
                    mask: c.mask(),
                },
            );
        }
    }

    fn failed(&mut self, e: &RigError) {
        if e.is_vanished() || matches!(e, RigError::Timeout { .. }) {
            self.healthy = false;
            self.last_try = Some(Instant::now());
            ev(
                &self.ui,
                DeviceEvent::Lost {
                    error: e.to_string(),
                    busy: false,
                },
            );
        }
    }

    fn handle(&mut self, cmd: DeviceCmd) {
        match cmd {
            DeviceCmd::Capture {
                purpose,
                camera,
                lighting,
            } => self.grab(purpose, camera, lighting),
            DeviceCmd::Live { on, camera } => {
                self.live = on.then_some(camera);
                self.last_live = None;
                ev(
                    &self.ui,
                    DeviceEvent::Note(format!("live view {}", if on { "on" } else { "off" })),
                );
            }
            DeviceCmd::Cancel => {
                self.live = None;
                self.cancel.store(false, Ordering::SeqCst);
            }
            DeviceCmd::SetLight { relay, on } => self.lights(|c| {
                let bit = 1u32 << relay.min(31);
                let mask = if on { c.mask() | bit } else { c.mask() & !bit };
                c.set_lights(mask)
            }),
            DeviceCmd::AllOff => self.lights(|c| c.set_lights(0)),
            DeviceCmd::Lighting(l) => self.lights(|c| c.switch_lighting(l)),
            DeviceCmd::Exposure { camera, factor } => self.camera_setting(camera, |g| {
                let now = g.camera_state().map_or(f64::NAN, |s| s.exposure_us);
                let st = g.set_exposure(now * factor)?;
                let note = format!("exposure {:.0} µs", st.exposure_us);
                Ok((st, note))
            }),
            DeviceCmd::Gain { camera, db } => self.camera_setting(camera, |g| {
                let now = g.camera_state().map_or(f64::NAN, |s| s.gain_db);
                let st = g.set_gain(now + db)?;
                let note = format!("gain {:.1} dB", st.gain_db);
                Ok((st, note))
            }),
            DeviceCmd::SimTarget(t) => {
                let note = match self.cell.as_ref().and_then(|c| c.sim()) {
                    Some(sim) => {
                        let on = t.is_some();
                        sim.scene().set_target(t);
                        format!("calibration plate {}", if on { "in view" } else { "away" })
                    }
                    None => "no simulated cell: hold the plate in front of the camera".into(),
                };
                ev(&self.ui, DeviceEvent::Note(note));
            }
        }
    }

    /// Sets camera `camera`'s exposure or gain through `f`; logs what it
    /// became (with the camera and its settings) or why not.
    fn camera_setting(
        &mut self,
        camera: u32,
        f: impl FnOnce(&mut dyn FrameGrabber) -> Result<(CameraState, String), RigError>,
    ) {
        let Some(c) = self.cell.as_mut().filter(|_| self.healthy) else {
            ev(
                &self.ui,
                DeviceEvent::Note("the grabber is not connected (see the log)".into()),
            );
            return;
        };
        let g = c.grabber.as_mut();
        match g.select_camera(camera).and_then(|_| f(g)) {
            Ok((st, what)) => {
                let port = g.port_name().to_string();
                let info = g.hello().ok();
                let grabber = match info {
                    Some(h) => format!(
                        "{} {}×{} {} cameras on {port}: {}",
                        h.model,
                        h.width,
                        h.height,
                        h.cameras,
                        st.summary()
                    ),
                    None => format!("{port}: {}", st.summary()),
                };
                ev(
                    &self.ui,
                    DeviceEvent::CameraSet {
                        grabber,
                        note: format!("{port}: {what} ({})", st.summary()),
                    },
                );
            }
            Err(e) => {
                ev(&self.ui, DeviceEvent::Note(e.to_string()));
                self.failed(&e);
            }
        }
    }

    fn lights(&mut self, f: impl FnOnce(&mut Cell) -> Result<(), RigError>) {
        let Some(c) = self.cell.as_mut() else {
            ev(
                &self.ui,
                DeviceEvent::Note("no relay board connected".into()),
            );
            return;
        };
        if let Err(e) = f(c) {
            ev(&self.ui, DeviceEvent::Note(format!("lights: {e}")));
            self.failed(&e);
        }
        self.report_lights();
    }

    fn grab(&mut self, purpose: FramePurpose, camera: u32, lighting: Option<char>) {
        let (ui, cancel) = (self.ui.clone(), self.cancel.clone());
        let Some(c) = self.cell.as_mut().filter(|_| self.healthy) else {
            ev(
                &self.ui,
                DeviceEvent::CaptureFailed {
                    purpose,
                    error: "the grabber is not connected (see the log); retrying".into(),
                },
            );
            return;
        };
        let mut last_sent = 0usize;
        let mut progress = move |done: usize, total: usize| -> bool {
            // A message per ~2 % keeps the channel light on slow links.
            if done == total || done >= last_sent + total / 50 {
                last_sent = done;
                ev(&ui, DeviceEvent::Progress { done, total });
            }
            !cancel.load(Ordering::SeqCst)
        };
        let result = match lighting {
            Some(l) => c
                .capture(camera, l, &mut progress)
                .map(|cap| (cap.image, cap.settings)),
            None => c
                .grabber
                .select_camera(camera)
                .and_then(|_| c.grabber.freeze())
                .and_then(|_| c.grabber.transfer(&mut progress))
                .map(|image| (image, c.frame_settings())),
        };
        self.cancel.store(false, Ordering::SeqCst);
        match result {
            Ok((image, settings)) => ev(
                &self.ui,
                DeviceEvent::Frame {
                    purpose,
                    camera,
                    image,
                    settings,
                },
            ),
            Err(e) => {
                if matches!(e, RigError::Cancelled { .. }) {
                    self.live = None;
                }
                ev(
                    &self.ui,
                    DeviceEvent::CaptureFailed {
                        purpose,
                        error: e.to_string(),
                    },
                );
                self.failed(&e);
            }
        }
        if lighting.is_some() {
            self.report_lights();
        }
    }
}
