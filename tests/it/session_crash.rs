//! Crash safety, for real: a child `vss` process saves into a session in a
//! loop and is SIGKILLed at random (seeded) moments, 30 times. After every
//! kill each file of the session must be a complete version (it parses and
//! is self-consistent), the manifest must load, and `vss session check`
//! must pass.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::Stdio;
use std::time::Duration;

use crate::support::vss;
use vss::formats::{edgefile, img, lines};
use vss::llv::rng::SplitMix64;
use vss::session::Session;
use vss::session::torture::{below, consistent_edges, consistent_image, consistent_lines};

const PROFILE: &str = r#"
name = "torture"
[[lights]]
name = "left"
relay = 0
[[lights]]
name = "right"
relay = 1
[survey]
cameras = 2
[[lighting]]
letter = "a"
on = ["left"]
[[lighting]]
letter = "b"
on = ["right"]
[[lighting]]
letter = "c"
on = ["left", "right"]
"#;

/// Every session file is whole; returns how many were verified.
fn verify_files(dir: &Path) -> usize {
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with('.') {
            continue; // temporary file of an interrupted save: never a session file
        }
        let ext = name.rsplit_once('.').map_or("", |(_, e)| e);
        match ext {
            "img" => {
                let f = img::read_img(&p).unwrap_or_else(|e| panic!("{e}"));
                assert!(consistent_image(&f), "{name} is a mixed or partial image");
            }
            "lex" | "ldr" => {
                let l = lines::read_lines(&p).unwrap_or_else(|e| panic!("{e}"));
                assert!(consistent_lines(&l), "{name} holds a mixed line set");
            }
            "hpo" | "vpo" => {
                let e = edgefile::read_edges(&p).unwrap_or_else(|e| panic!("{e}"));
                assert!(consistent_edges(&e), "{name} holds mixed edge points");
            }
            "ses" => {
                vss::formats::ses::read_ses(&p).unwrap_or_else(|e| panic!("{e}"));
            }
            "toml" | "lock" => {}
            other => panic!("unexpected file {name} (.{other})"),
        }
        n += 1;
    }
    n
}

#[test]
fn killed_saves_leave_complete_files_and_a_passing_check() {
    let tmp = tempfile::tempdir().unwrap();
    let profile = tmp.path().join("torture.toml");
    std::fs::write(&profile, PROFILE).unwrap();
    let st = vss()
        .args(["session", "new", "tort", "--dir"])
        .arg(tmp.path())
        .arg("--profile")
        .arg(&profile)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let dir = tmp.path().join("tort");
    let mut rng = SplitMix64::new(0x5eed);
    let mut saves = 0;
    for round in 0..30 {
        let mut child = vss()
            .args(["session", "torture"])
            .arg(&dir)
            .args(["--seed", &(round + 1).to_string()])
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        // Kill only once the child has the session open ...
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        out.read_line(&mut line).unwrap();
        assert_eq!(line.trim(), "ready", "round {round}");
        // ... and has completed a save, so every round kills real work.
        line.clear();
        out.read_line(&mut line).unwrap();
        assert_eq!(
            line.trim(),
            "saved 1",
            "round {round}: the child cannot save"
        );
        std::thread::sleep(Duration::from_millis(20 + below(&mut rng, 200)));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        let mut rest = String::new();
        out.read_to_string(&mut rest).unwrap();
        saves += 1 + rest.lines().filter(|l| l.starts_with("saved")).count();

        let files = verify_files(&dir);
        assert!(files >= 3, "round {round}: only {files} files");
        let s = Session::inspect(&dir).unwrap_or_else(|e| panic!("round {round}: {e}"));
        let report = s.check();
        assert!(report.is_ok(), "round {round}: {:?}", report.problems);
        if round % 10 == 9 {
            let out = vss().args(["session", "check"]).arg(&dir).output().unwrap();
            assert!(
                out.status.success(),
                "round {round}: vss session check failed:\n{}",
                String::from_utf8_lossy(&out.stdout)
            );
        }
    }
    // The children really worked between kills.
    eprintln!("{saves} saves completed across 30 SIGKILLed children");
    let s = Session::open_take_over(&dir).unwrap();
    let m = s.manifest();
    assert!(m.image.iter().any(|r| !r.grey.is_empty()));
    assert!(m.image.iter().any(|r| r.outputs.is_some()));
    assert!(
        s.leftovers().is_empty(),
        "opening for writing clears leftovers"
    );
}

/// Opening a session for writing removes the temporary files of saves
/// whose writer is gone, and only those: a temporary file of a live vss (a
/// second one asking for the lock has one in flight) stays. Removing it
/// made that vss fail with "NAME.lock: No such file or directory" when the
/// holder reopened the session at that moment.
#[test]
fn opening_removes_the_temporary_files_of_dead_writers_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("torture");
    std::fs::write(dir.path().join("p.toml"), PROFILE).unwrap();
    let o = vss()
        .args([
            "session",
            "new",
            "torture",
            "--dir",
            ".",
            "--profile",
            "p.toml",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut live = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .unwrap();
    let mut dead = std::process::Command::new("true").spawn().unwrap();
    let dead_pid = dead.id();
    dead.wait().unwrap();
    let in_flight = d.join(format!(".torture.lock.tmp.{}", live.id()));
    let left = d.join(format!(".torture1a.img.tmp.{dead_pid}"));
    std::fs::write(&in_flight, "pid = 1\n").unwrap();
    std::fs::write(&left, "half an image").unwrap();
    let s = Session::inspect(&d).unwrap();
    assert_eq!(s.leftovers(), vec![left.clone()], "only the dead writer's");
    drop(s);
    let s = Session::open(&d).unwrap();
    let _ = live.kill();
    let _ = live.wait();
    assert!(!left.exists(), "the dead writer's temporary file stays");
    assert!(
        in_flight.exists(),
        "a live writer's temporary file was removed"
    );
    drop(s);
}
