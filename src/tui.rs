//! The operator console (issue 7): a keyboard-driven TUI over the survey,
//! the capture hardware, the LLV pipeline, the line editor and the reports.

use std::process::ExitCode;

use crate::cli::Global;

pub mod keymap;
pub mod mode;
pub mod text;
pub mod widgets;

/// Opens the console on the profile's cell.
pub fn run(_g: &Global, _preview: Option<&str>) -> anyhow::Result<ExitCode> {
    Ok(ExitCode::SUCCESS)
}
