//! `vss sim`: starts the simulated grabber and relay board on
//! pseudo-terminals, prints their paths and a one-line summary, and serves
//! until Ctrl-C or SIGTERM, so that any tool (or a second console) can talk
//! to them as to real devices.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;

use super::Global;
use crate::rig::sim::{Faults, SimCell};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Faults injected into the grabber, e.g.
    /// `drop=1e-4,corrupt=1e-4,stall=2s,slow-freeze=1s,unplug-after=100000,reset,garbage=64`.
    #[arg(long, value_name = "SPEC")]
    pub faults: Option<String>,
    /// Keep a symlink here pointing at the grabber's pseudo-terminal (a
    /// stable port name for profiles, kept across replugs).
    #[arg(long, value_name = "PATH")]
    pub link: Option<std::path::PathBuf>,
    /// After an unplug fault, plug the grabber back in after this many
    /// seconds (on a new pseudo-terminal; `--link` follows it).
    #[arg(long, value_name = "SECONDS")]
    pub replug_after: Option<f64>,
    /// What the cameras see: the cell (`scene`), a calibration plate held at
    /// a new pose for every freeze (`plate`), or lying at its place in the
    /// cell (`plate-placed`).
    #[arg(long, value_name = "TARGET", default_value = "scene", value_parser = ["scene", "plate", "plate-placed"])]
    pub target: String,
    /// The calibration plate for --target (a name from profiles/plates/ or a file).
    #[arg(long, value_name = "PLATE", default_value = "squares")]
    pub plate: String,
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
    let mut sim = SimCell::from_profile(&profile, faults)?;
    let mode = match a.target.as_str() {
        "plate" => Some(crate::rig::sim::plate::Mode::Held),
        "plate-placed" => Some(crate::rig::sim::plate::Mode::Placed),
        _ => None,
    };
    if let Some(mode) = mode {
        let plate = crate::calib::Plate::load(&a.plate)?;
        if mode == crate::rig::sim::plate::Mode::Placed && plate.place.is_none() {
            anyhow::bail!(
                "plate {}: no [place] in its file, so it cannot lie at its place",
                plate.name
            );
        }
        sim.scene()
            .set_target(Some(crate::rig::sim::plate::PlateTarget { plate, mode }));
    }
    if let Some(link) = &a.link {
        sim.link_grabber(link)?;
    }
    let replug = match a.replug_after {
        Some(s) => Some(
            Duration::try_from_secs_f64(s)
                .map_err(|_| anyhow::anyhow!("--replug-after {s}: not a number of seconds"))?,
        ),
        None => None,
    };
    // Whoever starts the simulator may read only the paths, or nothing
    // (`--link` names the grabber): a closed stdout must not end it.
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "grabber: {}", sim.grabber_path())
        .and_then(|()| writeln!(out, "relay: {}", sim.relay_path()))
        .and_then(|()| writeln!(out, "{}", sim.summary()))
        .and_then(|()| out.flush());
    drop(out);
    let mut unplugged: Option<Instant> = None;
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(50));
        match unplugged {
            None if !sim.grabber_plugged() => {
                errln!("vss sim: the grabber was unplugged (fault injection)");
                unplugged = Some(Instant::now());
            }
            Some(t) if replug.is_some_and(|d| t.elapsed() >= d) => {
                let path = sim.replug_grabber()?.to_string();
                let mut out = std::io::stdout().lock();
                let _ = writeln!(out, "grabber: {path}").and_then(|()| out.flush());
                errln!("vss sim: the grabber is back on {path}");
                unplugged = None;
            }
            _ => {}
        }
    }
    sim.stop();
    errln!("vss sim: stopped");
    Ok(ExitCode::SUCCESS)
}
