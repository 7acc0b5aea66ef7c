//! What a simulated camera sees: the noise-free image of the scene under the
//! lights that are on. (Placeholder scene until the synthetic generator is
//! merged: a floor plate and a box seen in flat-shaded projection, lit by
//! Lambert's law from the light positions.)

use super::SimOptions;

/// Where lights stand when the profile does not say (mm, world frame): the
/// four corners above the workpiece.
pub fn default_light_positions() -> Vec<[f64; 3]> {
    vec![
        [-600.0, -600.0, 900.0],
        [600.0, -600.0, 900.0],
        [600.0, 600.0, 900.0],
        [-600.0, 600.0, 900.0],
    ]
}

/// Grey level of the ambient light alone.
const AMBIENT: f64 = 25.0;
/// Grey level a face gets from one light head-on at 1 m.
const LIGHT: f64 = 90.0;

fn lambert(normal: [f64; 3], at: [f64; 3], light: [f64; 3]) -> f64 {
    let d = [light[0] - at[0], light[1] - at[1], light[2] - at[2]];
    let r2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).max(1.0);
    let cos = (normal[0] * d[0] + normal[1] * d[1] + normal[2] * d[2]) / r2.sqrt();
    cos.max(0.0) * 1.0e6 / r2
}

/// Renders camera `cam` (1-based) under relay `mask`; row-major grey levels.
pub fn render_clean(o: &SimOptions, cam: u32, mask: u32) -> Vec<f32> {
    let (w, h) = (o.width as usize, o.height as usize);
    // Each camera looks from another side: rotate the world about z.
    let angle = f64::from(cam.saturating_sub(1)) * std::f64::consts::FRAC_PI_2 + 0.4;
    let (s, c) = angle.sin_cos();
    let rot = |v: [f64; 3]| [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]];
    let on: Vec<[f64; 3]> = o
        .lights
        .iter()
        .filter(|l| l.relay < 32 && mask & (1 << l.relay) != 0)
        .map(|l| l.position)
        .collect();
    let shade = |normal: [f64; 3], at: [f64; 3], albedo: f64| {
        let n = rot(normal);
        let lit: f64 = on.iter().map(|&p| lambert(n, at, p)).sum();
        (AMBIENT + LIGHT * lit) * albedo
    };
    let floor = shade([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], 0.6);
    let top = shade([0.0, 0.0, 1.0], [0.0, 0.0, 100.0], 1.0);
    let left = shade([-1.0, 0.0, 0.0], [-50.0, 0.0, 50.0], 1.0);
    let right = shade([0.0, -1.0, 0.0], [0.0, -50.0, 50.0], 1.0);
    // The box's outline in the image: a hexagon made of three faces.
    let (fw, fh) = (w as f64, h as f64);
    let cx = fw * (0.45 + 0.05 * f64::from(cam % 2));
    let cy = fh * (0.5 + 0.04 * f64::from(cam / 2));
    let a = fw.min(fh) * 0.22;
    let mut img = vec![0f32; w * h];
    for (i, px) in img.iter_mut().enumerate() {
        let x = (i % w) as f64 - cx;
        let y = (i / w) as f64 - cy;
        // Isometric-like axes: top face is a rhombus above the centre.
        let u = x / a;
        let v = y / a;
        let in_top = v < 0.0 && v > -1.0 + u.abs() * 0.5 - 0.5 && u.abs() < 1.0 && v > -1.0;
        let in_left = (-1.0..0.0).contains(&u) && v >= 0.5 * u && v < 0.5 * u + 1.0;
        let in_right = (0.0..1.0).contains(&u) && v >= -0.5 * u && v < -0.5 * u + 1.0;
        let g = if in_left {
            left
        } else if in_right {
            right
        } else if in_top {
            top
        } else {
            floor
        };
        *px = g.clamp(0.0, 255.0) as f32;
    }
    img
}
