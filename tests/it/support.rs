//! Helpers shared by the test modules: the `vss` binary (`bin`, also
//! included by `tests/accuracy`), profile fragments (`fixtures`), golden
//! files and `VSS_REGEN` (`golden`), Ghostscript rendering, `vss` under
//! memory limits, planted files and folders (`files`) and the seeded bench scene (also included by
//! `benches/llv.rs` and `examples/llv_count.rs`).

pub mod bin;
pub mod files;
pub mod fixtures;
pub mod golden;
pub mod gs;
pub mod limited;
pub mod llv_scene;
pub mod run;

pub use bin::vss;
