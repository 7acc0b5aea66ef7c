//! `vss sim`: starts the simulated grabber and relay board on
//! pseudo-terminals, prints their paths and a one-line summary, and serves
//! until Ctrl-C or SIGTERM, so that any tool (or a second console) can talk
//! to them as to real devices.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Context;

use super::Global;
use crate::rig::sim::{Faults, SimCell};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Faults injected into the grabber, e.g.
    /// `drop=1e-4,corrupt=1e-4,stall=2s,unplug-after=100000,reset,garbage=64`.
    #[arg(long, value_name = "SPEC")]
    pub faults: Option<String>,
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let faults = match &a.faults {
        Some(spec) => Faults::parse(spec)?,
        None => Faults::default(),
    };
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))
            .context("cannot install the Ctrl-C handler")?;
    }
    let sim = SimCell::from_profile(&profile, faults)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "grabber: {}", sim.grabber_path())?;
    writeln!(out, "relay: {}", sim.relay_path())?;
    writeln!(out, "{}", sim.summary())?;
    out.flush()?;
    drop(out);
    let mut told = false;
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(50));
        if !told && !sim.grabber_plugged() {
            eprintln!("vss sim: the grabber was unplugged (fault injection); Ctrl-C to end");
            told = true;
        }
    }
    sim.stop();
    eprintln!("vss sim: stopped");
    Ok(ExitCode::SUCCESS)
}
