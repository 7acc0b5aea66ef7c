//! Two consoles on one cell (the 3 a.m. case: a console left running on
//! the cell PC, a second started over SSH): the second cannot have the
//! serial ports, and says who holds them (not "check the cable"); once the
//! first quits, it takes them. Real consoles on real ptys, the cell a
//! `vss sim` process on pseudo-terminals of its own.

use std::io::{BufRead, BufReader};
use std::process::{Child, Stdio};

use vss::profile::{GrabberKind, RelayKind};
use vss::rig::sim::cell_profile;

use super::support::vss;
use super::tui_harness::{Console, flat};

/// `vss sim` on its own ptys, and the pipe it reports on, kept open (a
/// line written to a closed pipe would end it).
struct Sim {
    child: Child,
    _report: std::io::Lines<BufReader<std::process::ChildStdout>>,
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn sim(dir: &std::path::Path) -> (Sim, String, String) {
    let mut p = cell_profile(128, 128);
    p.relay.settle_ms = 5;
    let prof = dir.join("sim.toml");
    std::fs::write(&prof, toml::to_string(&p).unwrap()).unwrap();
    let mut child = vss()
        .arg("--profile")
        .arg(&prof)
        .arg("sim")
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start vss sim");
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut next = || lines.next().and_then(Result::ok).unwrap_or_default();
    let grabber = next()
        .strip_prefix("grabber: ")
        .expect("grabber")
        .to_string();
    let relay = next().strip_prefix("relay: ").expect("relay").to_string();
    assert!(next().starts_with("simulated cell:"));
    (
        Sim {
            child,
            _report: lines,
        },
        grabber,
        relay,
    )
}

#[test]
fn a_second_console_says_who_holds_the_ports_and_takes_them_when_free() {
    let cell = tempfile::tempdir().unwrap();
    let (_sim, grabber, relay) = sim(cell.path());
    let mut p = cell_profile(128, 128);
    p.name = "cell on ptys".into();
    p.grabber.kind = GrabberKind::Vsg;
    p.grabber.port = grabber.clone();
    p.relay.kind = RelayKind::Numato;
    p.relay.port = relay;
    p.relay.settle_ms = 5;
    let profile = toml::to_string(&p).unwrap();
    let mut a = Console::start_with(&profile, 80, 24, &[], |_| {});
    a.wait_devices(20);
    let holder = a.child.process_id().expect("the first console's pid");
    let mut b = a.another(80, 24);
    let s = b.wait("the second console says the port is busy", 20, |s| {
        flat(s).contains("DEVICE BUSY")
    });
    let said = flat(&s);
    assert!(
        said.contains(&format!("in use by vss (process {holder})")),
        "names the console that holds it:\n{s}"
    );
    assert!(!said.contains("check the cable"), "{s}");
    assert!(!said.contains("DEVICE LOST"), "{s}");
    // The first console is not disturbed, and quits; the second takes the
    // ports.
    assert!(a.exit_code().is_none(), "the first console runs on");
    a.send("q");
    assert_eq!(a.wait_exit(10), 0, "{}", a.screen());
    let s = b.wait("the second console takes the ports", 30, |s| {
        flat(s).contains("devices back")
    });
    assert!(!flat(&s).contains("DEVICE BUSY"), "{s}");
    b.send("q");
    assert_eq!(b.wait_exit(10), 0, "{}", b.screen());
}
