//! `vss lights on|off|set CONFIG|status`: quick checks at the cell. Switches
//! the profile's relay board and reads it back. An LCUS board cannot be
//! read: `on`, `off` and `set` send its whole mask (it may have lost power
//! since vss last switched it), and `status` says what vss last set on it
//! (kept in its state file) and switches nothing.

use std::process::ExitCode;

use super::Global;
use crate::rig::cell::open_lights;
use crate::rig::sim::{Faults, SimCell};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Switch every light of the profile on.
    On,
    /// Switch every relay off.
    Off,
    // (The help is an attribute, not a doc comment, so that rustdoc does
    // not read `[[lighting]]` as a link.)
    #[command(
        about = "Switch to a lighting configuration (a letter of the profile's [[lighting]])"
    )]
    Set { config: char },
    /// Show which lights are on.
    Status,
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let sim = if profile.relay.kind == crate::profile::RelayKind::Simulated {
        Some(SimCell::from_profile(&profile, Faults::default())?)
    } else {
        None
    };
    let mut board = open_lights(&profile, sim.as_ref())?;
    if let Some(n) = board.note() {
        errln!("vss: note: {n}");
    }
    let mask_of = |names: &[String]| -> anyhow::Result<u32> {
        let mut m = 0u32;
        for n in names {
            let l = profile
                .lights
                .iter()
                .find(|l| &l.name == n)
                .ok_or_else(|| anyhow::anyhow!("light `{n}` is not in the profile's [[lights]]"))?;
            m |= 1u32
                .checked_shl(l.relay)
                .ok_or_else(|| anyhow::anyhow!("light `{n}`: relay {} is beyond 31", l.relay))?;
        }
        Ok(m)
    };
    match a.action {
        Action::On => {
            let all: Vec<String> = profile.lights.iter().map(|l| l.name.clone()).collect();
            board.set_mask(mask_of(&all)?)?;
        }
        Action::Off => board.set_mask(0)?,
        Action::Set { config } => {
            let Some(cfg) = profile.lighting.iter().find(|l| l.letter == config) else {
                let known: String = profile.lighting.iter().map(|l| l.letter).collect();
                anyhow::bail!(
                    "no lighting configuration `{config}` in the profile (it has: {known})"
                );
            };
            board.set_mask(mask_of(&cfg.on)?)?;
        }
        Action::Status => {}
    }
    let name_of = |mask: u32| -> String {
        let on: Vec<String> = (0..32)
            .filter(|b| mask & (1 << b) != 0)
            .map(|b| {
                profile
                    .lights
                    .iter()
                    .find(|l| l.relay == b)
                    .map_or_else(|| format!("relay {b}"), |l| l.name.clone())
            })
            .collect();
        if on.is_empty() {
            "none".to_string()
        } else {
            on.join(", ")
        }
    };
    if !board.reads_back() {
        // An LCUS board: nothing to ask, only what vss remembers.
        let last = match board.last_set() {
            Some(l) => format!(
                "relays {:04x} at {}; on: {}",
                l.mask,
                crate::formats::sanitize(&l.when),
                name_of(l.mask)
            ),
            None => "nothing recorded (vss has not switched this board yet)".to_string(),
        };
        outln!(
            "{}: LCUS boards cannot be read; last set by vss: {last}",
            board.port_name()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let mask = board.read_mask()?;
    outln!(
        "{}: relays {mask:04x}; on: {}",
        board.port_name(),
        name_of(mask)
    );
    Ok(ExitCode::SUCCESS)
}
