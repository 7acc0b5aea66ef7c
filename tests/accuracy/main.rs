//! The accuracy floors, apart from the other integration tests so that
//! `cargo test --test accuracy` runs them alone: `cubes::` on the family the
//! engine is tuned on, `yard::` on the one it is not. Each floor is within
//! 0.01 of what the engine measures, so that a regression fails.

mod cubes;
mod yard;
