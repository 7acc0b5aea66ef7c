//! The Capture screen's state and keys: the camera, the highlighted light,
//! live view, single grabs, each light or lighting configuration switched.

use super::{Ctx, PreviewNav};
use crate::tui::event::{Cmd, DeviceCmd};
use crate::tui::keymap::CaptureAction;

/// The Capture screen's own state.
#[derive(Clone, Debug)]
pub struct CaptureScreen {
    /// The highlighted row of the lights panel: a light (`0..lights`), then
    /// a lighting configuration, so that every one of a profile's lightings
    /// can be set, not only the six with a Shift key.
    pub light: usize,
    pub camera: u32,
    pub nav: PreviewNav,
}

impl Default for CaptureScreen {
    fn default() -> Self {
        CaptureScreen {
            light: 0,
            camera: 1,
            nav: PreviewNav::default(),
        }
    }
}

impl CaptureScreen {
    pub fn update(&mut self, a: CaptureAction, ctx: &mut Ctx) -> Vec<Cmd> {
        match a {
            CaptureAction::Camera => ctx.next_camera(&mut self.camera),
            CaptureAction::ToggleLive => ctx.toggle_live(self.camera),
            CaptureAction::Grab => ctx.grab(self.camera),
            CaptureAction::LightPrev => {
                self.light = self.light.saturating_sub(1);
                Vec::new()
            }
            CaptureAction::LightNext => {
                if self.light + 1 < ctx.cell.lights.len() + ctx.cell.letters.len() {
                    self.light += 1;
                }
                Vec::new()
            }
            CaptureAction::LightToggle => {
                let Some((name, relay)) = ctx.cell.lights.get(self.light).cloned() else {
                    return lighting(ctx, self.light.saturating_sub(ctx.cell.lights.len()));
                };
                let on = !ctx.cell.device.lights_on.contains(&name);
                ctx.info(format!("light {name} {}", if on { "on" } else { "off" }));
                vec![Cmd::Device(DeviceCmd::SetLight { relay, on })]
            }
            CaptureAction::LightsOff => {
                ctx.info("all lights off");
                vec![Cmd::Device(DeviceCmd::AllOff)]
            }
            CaptureAction::Lighting(i) => lighting(ctx, usize::from(i)),
            CaptureAction::Cancel => super::App::cancel_transfer(ctx),
            CaptureAction::ExposureUp | CaptureAction::ExposureDown => {
                let factor = if a == CaptureAction::ExposureUp {
                    1.25
                } else {
                    0.8
                };
                vec![Cmd::Device(DeviceCmd::Exposure {
                    camera: self.camera,
                    factor,
                })]
            }
            CaptureAction::GainUp | CaptureAction::GainDown => {
                let db = if a == CaptureAction::GainUp {
                    1.0
                } else {
                    -1.0
                };
                vec![Cmd::Device(DeviceCmd::Gain {
                    camera: self.camera,
                    db,
                })]
            }
        }
    }
}

/// Sets the profile's `i`-th lighting configuration.
fn lighting(ctx: &mut Ctx, i: usize) -> Vec<Cmd> {
    match ctx.cell.letters.get(i) {
        Some(&l) => {
            ctx.info(format!("lighting {l}"));
            vec![Cmd::Device(DeviceCmd::Lighting(l))]
        }
        None => {
            ctx.warn(format!(
                "the profile has no lighting configuration {}",
                char::from_u32('a' as u32 + i as u32).unwrap_or('?')
            ));
            Vec::new()
        }
    }
}
