//! Several images of one view under different lights → one edge response
//! (llv.md §2.6). MINIMAL PLACEHOLDER written by helper `llv` so the pipeline
//! compiles; helper `issue6` owns this file and replaces it.
//!
//! Here: each image's response `r_i` (minus the ambient image's, since the
//! kernel is linear), noise level `τ_i = noise_factor · median |r_i|`, and
//! `Sum = Σ_{|r_i| ≥ τ_i} |r_i|` with the sign of `Σ_{|r_i| ≥ τ_i} r_i`.

use super::edges::{Response, response};
use super::image::GreyImage;
use super::params::EdgeParams;
use super::{LlvError, ScanDir};

/// The combined signed response of `images` (all of one size).
pub fn combined_response(
    images: &[GreyImage],
    ambient: Option<&GreyImage>,
    dir: ScanDir,
    p: &EdgeParams,
) -> Result<Response, LlvError> {
    let first = images.first().ok_or(LlvError::TooSmall {
        width: 0,
        height: 0,
        min: super::image::MIN_SIZE,
    })?;
    let a = p.half_width as usize;
    let amb = ambient.map(|g| response(g, dir, a)).transpose()?;
    let mut out = response(first, dir, a)?;
    let mut abs_sum = vec![0.0f32; out.data.len()];
    let mut signed = vec![0.0f32; out.data.len()];
    for img in images {
        if img.size() != first.size() {
            return Err(LlvError::SizeMismatch {
                a: first.size(),
                b: img.size(),
            });
        }
        let mut r = response(img, dir, a)?;
        if let Some(am) = &amb {
            if am.data.len() != r.data.len() {
                return Err(LlvError::SizeMismatch {
                    a: first.size(),
                    b: (am.width, am.height),
                });
            }
            for (v, s) in r.data.iter_mut().zip(&am.data) {
                *v -= s;
            }
        }
        let mut mags: Vec<f32> = r
            .data
            .iter()
            .filter(|v| v.is_finite())
            .map(|v| v.abs())
            .collect();
        let tau = if mags.is_empty() {
            0.0
        } else {
            let mid = mags.len() / 2;
            *mags.select_nth_unstable_by(mid, f32::total_cmp).1 * p.noise_factor as f32
        };
        for ((v, s), q) in r.data.iter().zip(abs_sum.iter_mut()).zip(signed.iter_mut()) {
            if v.is_nan() {
                *s = f32::NAN;
            } else if v.abs() >= tau {
                *s += v.abs();
                *q += v;
            }
        }
    }
    for ((o, s), q) in out.data.iter_mut().zip(&abs_sum).zip(&signed) {
        *o = if *q < 0.0 { -s } else { *s };
    }
    Ok(out)
}
