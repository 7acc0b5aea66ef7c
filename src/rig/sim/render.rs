//! What a simulated camera sees: the cell scene of the synthetic generator
//! (`synth::cell_scene`, a cube, a box and an L-bracket on a floor
//! plate) through one of the four cell cameras with its own lens distortion,
//! under the point lights whose relays are on. Noise is added per frame by
//! the caller, so this noise-free render can be cached.

use super::SimOptions;
use crate::synth::{self, PointLight, RenderOptions};

/// Where lights stand when the profile does not say (mm, world frame): the
/// synthetic cell's four lights, in the order of `synth::CELL_LIGHT_NAMES`.
pub fn default_light_positions() -> Vec<[f64; 3]> {
    synth::cell_lights()
        .into_iter()
        .map(|l| l.position)
        .collect()
}

/// Irradiance of one light (synth units: 1 ≈ a surface facing it from 1 m
/// shows its albedo); the synthetic cell's own value.
pub fn light_intensity() -> f64 {
    synth::cell_lights().first().map_or(0.5, |l| l.intensity)
}

/// Ambient irradiance: with every light off the image is dim and flat.
pub const AMBIENT: f64 = 0.2;
/// Optical blur of the simulated lenses (px).
pub const BLUR: f64 = 0.8;

/// The cameras of the simulated cell at this image size (index 0 is camera 1).
pub fn cameras(o: &SimOptions) -> Vec<synth::Camera> {
    synth::cell_cameras(o.width as usize, o.height as usize)
}

/// Renders camera `cam` (1-based) under relay `mask`; row-major grey levels
/// (0–255, not yet noisy).
pub fn render_clean(o: &SimOptions, cam: u32, mask: u32) -> Vec<f32> {
    let cams = cameras(o);
    let (w, h) = (o.width as usize, o.height as usize);
    let Some(camera) = cams.get(cam.saturating_sub(1) as usize) else {
        return vec![0.0; w * h];
    };
    let intensity = light_intensity();
    let lights: Vec<PointLight> = o
        .lights
        .iter()
        .filter(|l| l.relay < 32 && mask & (1 << l.relay) != 0)
        .map(|l| PointLight {
            position: l.position,
            intensity,
        })
        .collect();
    let opts = RenderOptions {
        ambient: AMBIENT,
        blur_sigma: BLUR,
        noise_sigma: 0.0,
        seed: o.seed,
        distort: true,
    };
    let img = synth::render(&synth::cell_scene(), camera, &lights, &opts);
    img.data().iter().map(|&v| f32::from(v)).collect()
}
