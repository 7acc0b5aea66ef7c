//! Ctrl-Z and `fg`: the console gives the terminal back to the shell,
//! stops, and takes the terminal again when it is continued.
//!
//! In raw mode the terminal sends Ctrl-Z as a key, not as SIGTSTP, so the
//! console does what the terminal's own suspend would: it leaves the
//! terminal as the shell had it (cooked mode, cursor shown, main screen,
//! no mouse reports), then stops itself. A shell with job control puts its
//! own modes back while the job is stopped and does not restore the job's
//! on `fg`: on SIGCONT the console sets raw mode and the alternate screen
//! again and draws the whole screen anew. SIGTSTP from elsewhere (`kill
//! -TSTP`) is taken the same way, so the terminal is never left raw under
//! a shell prompt.
//!
//! A console that no shell could continue (its process group is orphaned:
//! started by `ssh host vss`, or as a login command) is not stopped: it
//! would stay stopped for good, holding its session. It says so instead.

use std::io::{self, Write};
use std::path::Path;

use ratatui::crossterm::terminal;

use super::Term;

/// Whether a shell with job control could continue this process once it
/// stops: the process group is not orphaned, that is some ancestor in
/// another process group belongs to the same session (a shell that ran
/// `vss`, or `cargo run` under a shell).
pub fn can_suspend() -> bool {
    let (Ok(sid), pgrp) = (rustix::process::getsid(None), rustix::process::getpgrp()) else {
        return false;
    };
    let (sid, pgrp) = (sid.as_raw_nonzero().get(), pgrp.as_raw_nonzero().get());
    let mut pid = std::process::id();
    // A few levels at most; the bound only guards against a loop.
    for _ in 0..64 {
        let Some((ppid, _, _)) = stat_ids(Path::new(&format!("/proc/{pid}/stat"))) else {
            return false;
        };
        if ppid <= 1 {
            return false;
        }
        let Some((_, its_pgrp, its_sid)) = stat_ids(Path::new(&format!("/proc/{ppid}/stat")))
        else {
            return false;
        };
        if its_pgrp != pgrp {
            return its_sid == sid;
        }
        pid = ppid as u32;
    }
    false
}

/// A process's parent, process group and session from its `/proc/PID/stat`.
fn stat_ids(path: &Path) -> Option<(i32, i32, i32)> {
    let stat = std::fs::read_to_string(path).ok()?;
    // The command name (field 2) may hold spaces and parentheses.
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // f[0] is field 3 (state): ppid, pgrp, session follow.
    Some((
        f.get(1)?.parse().ok()?,
        f.get(2)?.parse().ok()?,
        f.get(3)?.parse().ok()?,
    ))
}

/// Gives the terminal back and stops the process until it is continued.
/// `note` is written on the main screen first, above the shell's "Stopped".
pub fn stop(note: &str) -> io::Result<()> {
    super::leave();
    let mut out = io::stdout();
    let _ = writeln!(out, "{note}");
    let _ = out.flush();
    // What the terminal's own Ctrl-Z does: SIGTSTP to the whole process
    // group, so that a parent in it (`cargo run`, `sh -c`) stops too and
    // the shell sees its job stopped (a console stopped alone left the
    // shell waiting on its parent, the terminal with nobody reading it).
    // The console's own handler of SIGTSTP only sets a flag (the caller
    // clears it): it stops itself with SIGSTOP, which returns once
    // continued.
    rustix::process::kill_current_process_group(rustix::process::Signal::TSTP)?;
    signal_hook::low_level::emulate_default_handler(signal_hook::consts::SIGTSTP)
}

/// Takes the terminal again after the process was stopped, whoever
/// stopped it: raw mode (the shell put its own modes back meanwhile), the
/// alternate screen, no cursor, mouse reports; the next draw is whole.
pub fn take_back(term: &mut Term) -> io::Result<()> {
    // crossterm keeps the modes it found at start: restore them, so that
    // raw mode is set again rather than taken as already on.
    let _ = terminal::disable_raw_mode();
    terminal::enable_raw_mode()?;
    super::screen_modes(term.backend_mut())?;
    // Cleared and drawn whole next time, at the size the terminal has now
    // (it may have changed meanwhile). Not `Terminal::clear`, which asks
    // the terminal where its cursor is and waits for the answer.
    let size = term.size()?;
    term.resize(ratatui::layout::Rect::new(0, 0, size.width, size.height))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ids_are_read_after_the_command_name() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("stat");
        std::fs::write(&p, "4242 (a (b) c) S 17 4242 17 34816 4242 4194304 1").unwrap();
        assert_eq!(stat_ids(&p), Some((17, 4242, 17)));
        std::fs::write(&p, "4242 (vss) S").unwrap();
        assert_eq!(stat_ids(&p), None);
    }
}
