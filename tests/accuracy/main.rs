//! The accuracy floors, apart from the other integration tests so that
//! `cargo test --test accuracy` runs them alone: `cubes::` on the family the
//! engine is tuned on, `yard::` on the one it is not, `real::` on the real
//! photographs it is tuned on (`../shared/data/yud-tune`). Each floor is within
//! 0.01 of what the engine measures, so that a regression fails.

#[path = "../it/support/bin.rs"]
mod bin;
mod cubes;
mod lightings;
mod real;
mod yard;

/// The default profile's LLV parameters (the built-in profile, or
/// `profiles/default.toml` where it is there): what both families are
/// scored with.
fn default_params() -> vss::llv::Params {
    match vss::profile::Profile::load("default") {
        Ok(p) => p.llv,
        Err(e) => panic!("the default profile does not load: {e}"),
    }
}

/// The gain at column `x` of an image `w` px wide under lighting `l` of
/// the lightings tests (`real::three_…`, `lightings::`): 0 dimmed to 70 %;
/// 1 a shadow to 35 % over the left half through a ramp a fifth of the
/// width wide; 2 the same from the right.
fn lighting_gain(l: usize, w: usize, x: usize) -> f64 {
    let wf = w as f64;
    let ramp = |x: f64| 0.35 + 0.65 * ((x / wf - 0.4) / 0.2).clamp(0.0, 1.0);
    match l {
        0 => 0.7,
        1 => ramp(x as f64),
        _ => ramp(wf - 1.0 - x as f64),
    }
}
