//! `vss` — the Vision Survey System operator console, as a library.
//!
//! The pieces, from the bottom up:
//! - [`llv`]: the low-level vision core (lens correction, Lee edges, line
//!   extraction, CONNECT, manual edits). Pure: no I/O.
//! - [`synth`]: synthetic scenes with their true edges, and the scorers
//!   (synthetic truth, labelled photographs) `vss selftest` and the tests use.
//! - [`formats`]: the cell's file formats (`.img`, `.cdf`, `.lex`/`.ldr`,
//!   `.hpo`/`.vpo`, parameter files, `.ses`) and the VSS file-name scheme.
//! - [`profile`]: TOML profiles (LLV parameters, hardware, lights).
//! - [`rig`]: the frame grabber and relay-board drivers, and the simulated cell.
//! - [`session`]: a survey on disk; [`report`]: PostScript and SVG.
//! - [`cli`]: headless subcommands; [`tui`]: the operator console.
//! - [`text`]: the one sanitiser of text shown to a person; [`dirs`]: the
//!   XDG config and state folders; [`clock`]: UTC time stamps.

pub mod calib;
pub mod cli;
pub mod clock;
pub mod dirs;
pub mod formats;
pub mod fsutil;
/// The low-level vision core: the `vss-llv` crate of the workspace
/// (crates/vss-llv), which depends on no other crate of it.
pub use vss_llv as llv;
pub mod profile;
pub mod report;
pub mod rig;
pub mod session;
pub mod synth;
pub mod text;
pub mod tui;
