//! The `genicam` grabber kind: GigE Vision and USB3 Vision cameras through
//! Aravis, behind the same [`FrameGrabber`] operations as the VSG/1 driver,
//! so the console, `vss grab`, calibration and sessions use them unchanged.
//! Built only with `--features genicam` (it links Debian's libaravis).
//!
//! How the basic operations map onto GenICam:
//! - camera select: camera N is the profile's `cameras[N-1]`, a device id as
//!   Aravis names it or an address; each camera is opened when first
//!   selected, set as its `[[grabber.camera]]` entry says (pixel format,
//!   region, exposure, gain), put in software-trigger mode and left
//!   acquiring, so a freeze costs one frame and no set-up;
//! - freeze: a software trigger and the one frame it makes. The pixels are
//!   copied out of Aravis's buffer at once and reduced to 8-bit grey
//!   ([`super::pixels`]); the frame is kept on the PC (the "grabber's
//!   memory"), and transfer hands it over. The camera's exposure and gain
//!   are read again as each frame comes (a camera on automatic changes
//!   them itself): the session records them with the frame;
//! - live: the console's live view repeats freezes, at most one every
//!   [`LIVE_INTERVAL`].
//!
//! Faults: a frame that comes incomplete (lost packets that Aravis's
//! resends did not recover) is thrown away and the camera triggered again,
//! up to the profile's `retries`; then the freeze fails and nothing is kept.
//! A camera that does not answer (unplugged, powered off, the fake camera
//! killed) or sends no frame within the timeout fails with an error that
//! names it and counts as vanished, so the console reconnects as it does
//! for the serial grabber. A pixel format vss cannot use (one the camera
//! does not offer, or one vss cannot reduce to 8 bits) is refused when the
//! camera is opened, before any frame, naming the camera and the formats it
//! offers that vss reads.
//!
//! The one `unsafe` block of vss's own code outside the allocator test is
//! here (`copy_frame`): Aravis hands a frame as a pointer and a length.

use std::time::Duration;

use aravis::prelude::*;
use aravis::{Buffer, BufferPayloadType, BufferStatus, Camera, Stream};

use super::grabber::{FrameGrabber, WireStats};
use super::protocol::{FrameInfo, GrabberInfo, GrabberStatus, crc32};
use super::{CameraState, RigError};
use crate::formats::pixels::{Mono, PIXEL_FORMATS, to_grey8};
use crate::llv::GreyImage;
use crate::profile::{CameraSettings, GrabberConfig};

/// Least time between two live frames.
pub const LIVE_INTERVAL: Duration = Duration::from_millis(50);

/// Buffers queued on each camera's stream.
const BUFFERS: usize = 3;

/// One opened camera.
struct Open {
    camera: Camera,
    stream: Stream,
    payload: usize,
    format: Mono,
    state: CameraState,
}

/// The GenICam grabber: the profile's cameras, the one selected, the frame
/// last frozen.
pub struct GenicamGrabber {
    ids: Vec<String>,
    settings: Vec<CameraSettings>,
    timeout: Duration,
    retries: u32,
    cams: Vec<Option<Open>>,
    /// 1-based.
    current: u32,
    live: bool,
    frame: Option<FrameInfo>,
    image: Option<GreyImage>,
    name: String,
    stats: WireStats,
}

/// Aravis's error as text (`glib::Error`'s message).
fn text(e: &aravis::glib::Error) -> String {
    e.message().to_string()
}

impl GenicamGrabber {
    /// The cameras a profile's `[grabber]` names; opens camera 1 at once, so
    /// a camera that is not there is said now.
    pub fn open(cfg: &GrabberConfig) -> Result<GenicamGrabber, RigError> {
        if cfg.cameras.is_empty() {
            return Err(RigError::Config(
                "the genicam grabber has no cameras: set `cameras` in the profile's [grabber]"
                    .into(),
            ));
        }
        let mut g = GenicamGrabber {
            ids: cfg.cameras.iter().map(|s| s.trim().to_string()).collect(),
            settings: cfg.camera.clone(),
            timeout: Duration::from_millis(cfg.timeout_ms.max(1)),
            retries: cfg.retries,
            cams: cfg.cameras.iter().map(|_| None).collect(),
            current: 1,
            live: false,
            frame: None,
            image: None,
            name: String::new(),
            stats: WireStats::default(),
        };
        g.name = g.label(1);
        g.opened(1)?;
        Ok(g)
    }

    /// "camera 1 (Aravis-Fake-GV01)", for messages.
    fn label(&self, cam: u32) -> String {
        let id = self
            .ids
            .get(cam.saturating_sub(1) as usize)
            .map_or("?", |s| s.as_str());
        format!("camera {cam} ({id})")
    }

    fn err(&self, cam: u32, detail: String, gone: bool) -> RigError {
        RigError::Camera {
            port: self.label(cam),
            detail,
            gone,
        }
    }

    /// Camera `cam`, opened (and set up) if it is not yet.
    fn opened(&mut self, cam: u32) -> Result<&mut Open, RigError> {
        let i = cam.checked_sub(1).map(|i| i as usize);
        let Some(i) = i.filter(|&i| i < self.ids.len()) else {
            return Err(RigError::Config(format!(
                "camera {cam} does not exist: the profile's [grabber] cameras are 1 to {}",
                self.ids.len()
            )));
        };
        if self.cams.get(i).is_some_and(|c| c.is_none()) {
            let open = self.open_camera(cam, i)?;
            if let Some(slot) = self.cams.get_mut(i) {
                *slot = Some(open);
            }
        }
        match self.cams.get_mut(i).and_then(|c| c.as_mut()) {
            Some(o) => Ok(o),
            None => Err(RigError::Config(format!("camera {cam} is not open"))),
        }
    }

    fn open_camera(&self, cam: u32, i: usize) -> Result<Open, RigError> {
        let id = self.ids.get(i).cloned().unwrap_or_default();
        let camera = Camera::new(Some(&id)).map_err(|e| {
            self.err(
                cam,
                format!(
                    "not found ({}) — is it powered and connected, and is `{id}` its device id \
                     or address? Check the profile's [grabber] cameras",
                    text(&e)
                ),
                true,
            )
        })?;
        let s = self.settings.get(i).cloned().unwrap_or_default();
        let set = |what: &str, r: Result<(), aravis::glib::Error>| {
            r.map_err(|e| {
                self.err(
                    cam,
                    format!(
                        "cannot set {what}: {} — check [[grabber.camera]] entry {cam}",
                        text(&e)
                    ),
                    false,
                )
            })
        };
        // The formats the camera offers, and of those the ones vss reads:
        // named whenever a format is refused.
        let formats = Formats::of(&camera);
        let refuse = |what: String| {
            self.err(
                cam,
                format!(
                    "{} {what}; {} (nothing was grabbed)",
                    identity(&camera),
                    formats.advice(cam)
                ),
                false,
            )
        };
        if let Some(f) = &s.pixel_format {
            if !formats.offered.is_empty() && !formats.offered.contains(f) {
                return Err(refuse(format!("has no pixel format {f}")));
            }
            camera
                .set_pixel_format_from_string(f)
                .map_err(|e| refuse(format!("refused the pixel format {f} ({})", text(&e))))?;
        }
        if let Some([x, y, w, h]) = s.roi {
            let n = |v: u32| i32::try_from(v).unwrap_or(i32::MAX);
            set(
                &format!("the region to x {x}, y {y}, {w} × {h}"),
                camera.set_region(n(x), n(y), n(w), n(h)),
            )?;
        }
        if let Some(us) = s.exposure_us {
            // A camera without auto exposure refuses this: not an error.
            let _ = camera.set_exposure_time_auto(aravis::Auto::Off);
            set(
                &format!("the exposure to {us} µs"),
                camera.set_exposure_time(us),
            )?;
        }
        if let Some(db) = s.gain_db {
            let _ = camera.set_gain_auto(aravis::Auto::Off);
            set(&format!("the gain to {db} dB"), camera.set_gain(db))?;
        }
        let gone = |e: aravis::glib::Error| {
            self.err(
                cam,
                format!("does not answer ({}) — is it still connected?", text(&e)),
                true,
            )
        };
        let pfnc = camera.pixel_format().map_err(gone)?.raw();
        let format = Mono::from_pfnc(pfnc).ok_or_else(|| {
            let name = camera
                .pixel_format_as_string()
                .map(|s| s.to_string())
                .unwrap_or_else(|_| format!("0x{pfnc:08X}"));
            refuse(format!(
                "is set to {name} pixels, which vss cannot reduce to 8-bit grey"
            ))
        })?;
        set(
            "software trigger (TriggerMode On, TriggerSource Software)",
            camera.set_trigger("Software"),
        )?;
        if camera.is_gv_device() {
            match s.packet_size {
                Some(b) => set(
                    &format!("the GigE Vision packet size to {b} bytes"),
                    camera.gv_set_packet_size(i32::try_from(b).unwrap_or(i32::MAX)),
                )?,
                // The largest packet the network carries, where the camera
                // can test it; otherwise its own size.
                None => {
                    let _ = camera.gv_auto_packet_size();
                }
            }
        }
        let payload = camera.payload().map_err(gone)? as usize;
        let stream = camera
            .create_stream()
            .map_err(|e| self.err(cam, format!("cannot open its stream: {}", text(&e)), true))?;
        for _ in 0..BUFFERS {
            stream.push_buffer(Buffer::new_allocate(payload));
        }
        camera.start_acquisition().map_err(gone)?;
        let state = read_state(&camera, format, &id);
        Ok(Open {
            camera,
            stream,
            payload,
            format,
            state,
        })
    }

    /// The frame of one software trigger, whole, as 8-bit grey.
    fn trigger_one(&mut self) -> Result<GreyImage, RigError> {
        let cam = self.current;
        let (timeout, retries) = (self.timeout, self.retries);
        let label = self.label(cam);
        let mut incomplete = Vec::new();
        for attempt in 0..=retries {
            if attempt > 0 {
                self.stats.retries += 1;
            }
            let o = self.opened(cam)?;
            // Frames of earlier triggers that came after their freeze gave
            // up belong to no one.
            while let Some(b) = o.stream.try_pop_buffer() {
                o.stream.push_buffer(b);
            }
            let exposure = Duration::from_secs_f64(o.state.exposure_us.max(0.0) / 1e6);
            let wait = timeout + exposure;
            let (payload, format) = (o.payload, o.format);
            if let Err(e) = o.camera.software_trigger() {
                return Err(RigError::Camera {
                    port: label,
                    detail: format!(
                        "does not answer the software trigger ({}) — is it still connected? \
                         Nothing was saved",
                        text(&e)
                    ),
                    gone: true,
                });
            }
            let Some(buf) = o
                .stream
                .timeout_pop_buffer(wait.as_micros().min(u64::MAX as u128) as u64)
            else {
                return Err(RigError::Camera {
                    port: label,
                    detail: format!(
                        "sent no frame within {} ms of the trigger — is it still connected, \
                         and is the profile's timeout_ms longer than a frame? Nothing was saved",
                        wait.as_millis()
                    ),
                    gone: true,
                });
            };
            let status = buf.status();
            let result = if status == BufferStatus::Success {
                copy_frame(&buf, payload, format)
            } else {
                Err(status_text(status))
            };
            o.stream.push_buffer(buf);
            if result.is_ok() {
                read_settings(o);
            }
            match result {
                Ok(img) => {
                    let n = img.data().len() as u64;
                    self.stats.rx += n;
                    self.stats.payload += n;
                    return Ok(img);
                }
                Err(why) => {
                    self.stats.bad_blocks += 1;
                    incomplete.push(why);
                }
            }
        }
        Err(RigError::Camera {
            port: label,
            detail: format!(
                "{} frames in a row came incomplete ({}); nothing was saved — check the \
                 network (cable, switch, packet size), then freeze again",
                incomplete.len(),
                incomplete.join(", ")
            ),
            gone: false,
        })
    }
}

/// The pixel formats a camera offers (its `PixelFormat` entries that are
/// available now) and, of those, the ones vss reads.
struct Formats {
    offered: Vec<String>,
    usable: Vec<String>,
}

impl Formats {
    /// Asks the camera; a camera that cannot say offers nothing known.
    fn of(camera: &Camera) -> Formats {
        let offered: Vec<String> = camera
            .dup_available_pixel_formats_as_strings()
            .map(|v| v.iter().map(|s| s.to_string()).collect())
            .unwrap_or_default();
        let usable = offered
            .iter()
            .filter(|f| Mono::from_name(f).is_some())
            .cloned()
            .collect();
        Formats { offered, usable }
    }

    /// What to set `pixel_format` to, for camera `cam`.
    fn advice(&self, cam: u32) -> String {
        let key = format!("pixel_format in [[grabber.camera]] entry {cam}");
        if !self.usable.is_empty() {
            format!(
                "of the formats vss can use it offers {}: set {key} to one of them",
                self.usable.join(", ")
            )
        } else if !self.offered.is_empty() {
            format!(
                "it offers none that vss can use ({}; vss reads {}): set the camera to one \
                 of those with its maker's tool, then {key}",
                self.offered.join(", "),
                PIXEL_FORMATS.join(", ")
            )
        } else {
            format!(
                "it does not say which formats it offers; vss reads {}: set {key} to one \
                 the camera has",
                PIXEL_FORMATS.join(", ")
            )
        }
    }
}

/// "the Aravis Fake #GV01": the camera's vendor, model and serial number,
/// as far as it says them.
fn identity(camera: &Camera) -> String {
    let serial = serial(camera);
    let parts: Vec<String> = [
        gtext(camera.vendor_name()),
        gtext(camera.model_name()),
        if serial.is_empty() {
            serial
        } else {
            format!("#{serial}")
        },
    ]
    .into_iter()
    .filter(|p| !p.trim().is_empty())
    .collect();
    if parts.is_empty() {
        "the camera".into()
    } else {
        format!("the {}", parts.join(" "))
    }
}

/// What an unsuccessful buffer's status means, for the operator.
fn status_text(status: BufferStatus) -> String {
    match status {
        BufferStatus::MissingPackets => "packets missing".into(),
        BufferStatus::Timeout => "packets still missing at the frame's timeout".into(),
        BufferStatus::WrongPacketId => "packets of another frame".into(),
        BufferStatus::SizeMismatch => "larger than the camera's payload".into(),
        BufferStatus::Aborted => "aborted".into(),
        other => format!("{other:?}"),
    }
}

/// Reads the camera's exposure and gain again, as a frame comes: they go
/// into the frame's record in the session, and a camera left on automatic
/// exposure or gain (the profile sets neither) changes them itself. A
/// value the camera does not give keeps the one read before.
fn read_settings(o: &mut Open) {
    if let Ok(us) = o.camera.exposure_time() {
        o.state.exposure_us = us;
    }
    if let Ok(db) = o.camera.gain() {
        o.state.gain_db = db;
    }
}

/// Aravis's text, or nothing when the camera does not give it.
fn gtext(r: Result<aravis::glib::GString, aravis::glib::Error>) -> String {
    r.map(|s| s.to_string()).unwrap_or_default()
}

/// The camera's serial number (older GenICam files call it DeviceID).
fn serial(camera: &Camera) -> String {
    gtext(
        camera
            .string("DeviceSerialNumber")
            .or_else(|_| camera.string("DeviceID")),
    )
}

/// The camera's identity and settings as it reports them now.
fn read_state(camera: &Camera, format: Mono, id: &str) -> CameraState {
    let s = gtext;
    let (x, y, w, h) = camera.region().unwrap_or((0, 0, 0, 0));
    CameraState {
        id: id.to_string(),
        vendor: s(camera.vendor_name()),
        model: s(camera.model_name()),
        serial: serial(camera),
        pixel_format: format.name().to_string(),
        exposure_us: camera.exposure_time().unwrap_or(f64::NAN),
        gain_db: camera.gain().unwrap_or(f64::NAN),
        roi: [x, y, w, h].map(|v| v.max(0) as u32),
        frame_rate_hz: camera.frame_rate().unwrap_or(f64::NAN),
    }
}

/// Copies a successful buffer's image out of Aravis's memory and reduces it
/// to 8-bit grey; `Err` says why the frame cannot be used.
fn copy_frame(buf: &Buffer, payload: usize, expected: Mono) -> Result<GreyImage, String> {
    if buf.payload_type() != BufferPayloadType::Image {
        return Err(format!("payload {:?}, not an image", buf.payload_type()));
    }
    let (w, h) = (buf.image_width(), buf.image_height());
    let (Ok(w), Ok(h)) = (usize::try_from(w), usize::try_from(h)) else {
        return Err(format!("a frame of {w} × {h} pixels"));
    };
    let format = buf.image_pixel_format().raw();
    if Mono::from_pfnc(format) != Some(expected) {
        return Err(format!(
            "pixel format 0x{format:08X}, not the {} the camera was set to",
            expected.name()
        ));
    }
    let (ptr, len) = buf.data();
    if ptr.is_null() || len > payload {
        return Err(format!("{len} bytes in a buffer of {payload}"));
    }
    #[allow(unsafe_code)]
    // SAFETY: `ptr` and `len` are Aravis's own description of this buffer's
    // memory (arv_buffer_get_data), non-null as checked; `buf` is borrowed
    // for this whole function, so the buffer is alive and has not been given
    // back to the stream (the caller pushes it back only after this returns),
    // so nothing writes it while the slice lives. The slice is read once,
    // by `to_grey8` below, which copies the pixels out; it does not outlive
    // this function.
    let raw: &[u8] = unsafe { std::slice::from_raw_parts(ptr.cast_const(), len) };
    let grey = to_grey8(expected, raw, w, h).ok_or_else(|| {
        format!(
            "{len} bytes for a {w} × {h} {} frame: rows missing",
            expected.name()
        )
    })?;
    GreyImage::new(w, h, grey).map_err(|e| e.to_string())
}

impl FrameGrabber for GenicamGrabber {
    fn hello(&mut self) -> Result<GrabberInfo, RigError> {
        let cameras = self.ids.len() as u32;
        let o = self.opened(self.current)?;
        let [_, _, w, h] = o.state.roi;
        Ok(GrabberInfo {
            model: "genicam".into(),
            width: w,
            height: h,
            depth: 8,
            cameras,
            maxblock: o.payload.min(u32::MAX as usize) as u32,
        })
    }

    fn init(&mut self) -> Result<(), RigError> {
        self.frame = None;
        self.image = None;
        Ok(())
    }

    fn live(&mut self, cam: u32) -> Result<(), RigError> {
        self.select_camera(cam)?;
        self.live = true;
        Ok(())
    }

    fn freeze(&mut self) -> Result<FrameInfo, RigError> {
        self.frame = None;
        self.image = None;
        self.live = false;
        let img = self.trigger_one()?;
        let (w, h) = img.size();
        let f = FrameInfo {
            width: w as u32,
            height: h as u32,
            crc: crc32(img.data()),
        };
        self.frame = Some(f);
        self.image = Some(img);
        Ok(f)
    }

    fn check_camera(&mut self, cam: u32) -> Result<(), RigError> {
        self.opened(cam).map(|_| ())
    }

    fn select_camera(&mut self, cam: u32) -> Result<(), RigError> {
        self.opened(cam)?;
        if cam != self.current {
            self.current = cam;
            self.name = self.label(cam);
        }
        Ok(())
    }

    fn load(&mut self, img: &GreyImage) -> Result<(), RigError> {
        let (w, h) = img.size();
        self.frame = Some(FrameInfo {
            width: w as u32,
            height: h as u32,
            crc: crc32(img.data()),
        });
        self.image = Some(img.clone());
        Ok(())
    }

    fn transfer(
        &mut self,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        let img = self.image.clone().ok_or_else(|| RigError::NoFrame {
            port: self.name.clone(),
        })?;
        let n = img.data().len();
        progress(n, n);
        Ok(img)
    }

    fn status(&mut self) -> Result<GrabberStatus, RigError> {
        Ok(GrabberStatus {
            camera: self.current,
            live: self.live,
            frame: self.frame.map(|f| f.crc),
        })
    }

    fn frame(&self) -> Option<FrameInfo> {
        self.frame
    }

    fn port_name(&self) -> &str {
        &self.name
    }

    fn reconnect(&mut self) -> Result<(), RigError> {
        for c in self.cams.iter_mut() {
            if let Some(o) = c.take() {
                let _ = o.camera.stop_acquisition();
            }
        }
        self.frame = None;
        self.image = None;
        self.opened(self.current).map(|_| ())
    }

    fn wire_stats(&self) -> WireStats {
        self.stats
    }

    fn camera_state(&self) -> Option<CameraState> {
        let i = self.current.checked_sub(1)? as usize;
        self.cams.get(i)?.as_ref().map(|o| o.state.clone())
    }

    fn set_exposure(&mut self, us: f64) -> Result<CameraState, RigError> {
        let cam = self.current;
        let label = self.label(cam);
        let id = self.ids.get(cam as usize - 1).cloned().unwrap_or_default();
        let o = self.opened(cam)?;
        let us = match o.camera.exposure_time_bounds() {
            Ok((lo, hi)) if lo <= hi && us.is_finite() => us.clamp(lo, hi),
            _ => us,
        };
        let _ = o.camera.set_exposure_time_auto(aravis::Auto::Off);
        o.camera
            .set_exposure_time(us)
            .map_err(|e| RigError::Camera {
                port: label,
                detail: format!("cannot set the exposure to {us} µs: {}", text(&e)),
                gone: false,
            })?;
        o.state = read_state(&o.camera, o.format, &id);
        Ok(o.state.clone())
    }

    fn set_gain(&mut self, db: f64) -> Result<CameraState, RigError> {
        let cam = self.current;
        let label = self.label(cam);
        let id = self.ids.get(cam as usize - 1).cloned().unwrap_or_default();
        let o = self.opened(cam)?;
        let db = match o.camera.gain_bounds() {
            Ok((lo, hi)) if lo <= hi && db.is_finite() => db.clamp(lo, hi),
            _ => db,
        };
        let _ = o.camera.set_gain_auto(aravis::Auto::Off);
        o.camera.set_gain(db).map_err(|e| RigError::Camera {
            port: label,
            detail: format!("cannot set the gain to {db} dB: {}", text(&e)),
            gone: false,
        })?;
        o.state = read_state(&o.camera, o.format, &id);
        Ok(o.state.clone())
    }

    fn live_interval(&self) -> Option<Duration> {
        Some(LIVE_INTERVAL)
    }
}

impl Drop for GenicamGrabber {
    fn drop(&mut self) {
        for o in self.cams.iter().flatten() {
            let _ = o.camera.stop_acquisition();
        }
    }
}
