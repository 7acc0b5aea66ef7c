//! Helpers shared by the test modules: Ghostscript rendering and the seeded
//! bench scene (also included by `benches/llv.rs` and `examples/llv_count.rs`).

pub mod gs;
pub mod llv_scene;
