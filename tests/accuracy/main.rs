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
