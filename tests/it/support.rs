//! Helpers shared by the test modules: Ghostscript rendering, `vss` under
//! memory limits and the seeded
//! bench scene (also included by `benches/llv.rs` and `examples/llv_count.rs`).

pub mod gs;
pub mod limited;
pub mod llv_scene;
