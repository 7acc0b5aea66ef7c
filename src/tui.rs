//! The operator console (to be written).

use std::process::ExitCode;

use crate::cli::Global;

/// Opens the console on the profile's cell.
pub fn run(_g: &Global, _preview: Option<&str>) -> anyhow::Result<ExitCode> {
    use clap::CommandFactory;
    crate::cli::Cli::command().print_help()?;
    Ok(ExitCode::SUCCESS)
}
