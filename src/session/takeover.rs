//! Taking over a session another vss holds — one function for the console
//! (`y` to "Take it over anyway?") and every CLI `--take-over` (`vss grab`,
//! `vss session redo`), so they follow one rule (issue 34):
//!
//! - a stale lock, or one held on another host, is taken over as the lock
//!   allows, nobody asked;
//! - a live holder on this host is asked first through the session folder
//!   (`NAME.lock.leave`, [`lock::request_leave`]): a console saves what it
//!   has, releases the lock and says who took it; a `vss grab` stops the
//!   frame under way (the lightings saved stay) and ends;
//! - only when the lock is still held after [`LEAVE_WAIT`] is the holder
//!   signalled (SIGTERM), and only the lock's own vss
//!   ([`lock::ask_holder_to_leave`]).
//!
//! While it waits, the taker answers requests for what it holds itself
//! ([`Taker::meanwhile`]): two consoles that each take over the other's
//! session at once both get it, neither signalled.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::lock::{self, LockInfo};
use super::{Session, SessionError};

/// How long the taker waits for a holder to answer a request before it
/// signals it.
pub const LEAVE_WAIT: Duration = Duration::from_secs(5);

/// How often a holder (the console's store, a `vss grab` in a transfer)
/// looks for a request to leave its session: well inside [`LEAVE_WAIT`].
pub const LEAVE_POLL: Duration = Duration::from_millis(200);

/// How long the taker waits for a signalled holder to end.
const SIGNAL_WAIT: Duration = Duration::from_secs(15);

#[derive(Debug, thiserror::Error)]
pub enum TakeOverError {
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error(
        "session {} is still held by {holder} after asking it to end; nothing changed",
        crate::text::path(dir)
    )]
    NoAnswer { dir: PathBuf, holder: String },
    #[error(
        "the take-over of session {} was given up before {holder} was signalled; nothing changed",
        crate::text::path(dir)
    )]
    GivenUp { dir: PathBuf, holder: String },
    #[error(
        "session {} is held by {holder}, which was not asked to end: {why}; nothing changed",
        crate::text::path(dir)
    )]
    Refused {
        dir: PathBuf,
        holder: String,
        why: String,
    },
}

/// Who takes a session over: it hears each step, and while it waits for
/// the lock it may answer requests for a session it holds itself.
pub trait Taker {
    /// One step said ("asking process N to release…").
    fn say(&mut self, text: String);

    /// Run at every poll while the taker waits for the lock (at least
    /// every 50 ms). A console that holds another session answers a
    /// request to leave it here, as between commands: two consoles that
    /// each take over the other's session at once would otherwise each
    /// wait for an answer that never comes, and signal each other. A
    /// taker that holds nothing else (the CLI) does nothing.
    fn meanwhile(&mut self) {}

    /// Whether the taker gave up meanwhile (a console that quits): the
    /// request is withdrawn and the holder not signalled.
    fn given_up(&self) -> bool {
        false
    }
}

/// A taker that holds nothing else: its `say` alone (`vss grab`, `vss
/// session redo`).
impl<F: FnMut(String)> Taker for F {
    fn say(&mut self, text: String) {
        self(text)
    }
}

/// Opens the session at `dir` for writing, taking it over from whoever
/// holds it by the rule above; `taker` hears each step and answers, while
/// it waits, requests for what it holds ([`Taker::meanwhile`]).
pub fn open_taking_over(dir: &Path, taker: &mut dyn Taker) -> Result<Session, TakeOverError> {
    let mut looks = 0;
    let (s, h) = loop {
        looks += 1;
        let Ok(s) = Session::inspect(dir) else {
            return Ok(Session::open_take_over(dir)?);
        };
        match s.lock_holder() {
            Some(h) if h.host == LockInfo::current().host && !h.is_stale() => break (s, h),
            Some(_) => return Ok(Session::open_take_over(dir)?),
            None => {}
        }
        // No lock when looked at: opened as it is. A holder that let the
        // lock go between two saves (a `vss grab` between frames) may have
        // taken it again meanwhile: it is then asked like any other, not
        // refused as "in use".
        match Session::open(dir) {
            Err(SessionError::Locked { stale: false, .. }) if looks < 3 => continue,
            Err(SessionError::Locked { stale: true, .. }) => {
                return Ok(Session::open_take_over(dir)?);
            }
            opened => return Ok(opened?),
        }
    };
    let h = &h;
    let lock_path = s.lock_path();
    let leave = lock::leave_path(&lock_path);
    match lock::request_leave(&lock_path, h) {
        Err(e) => taker.say(format!(
            "cannot ask process {} through {} ({e}): signalling it instead",
            h.pid,
            crate::text::path(&leave)
        )),
        Ok(()) => {
            taker.say(format!(
                "asking process {} to release session {}…",
                h.pid,
                crate::text::path(dir)
            ));
            if let Some(s) = wait_for_lock(dir, LEAVE_WAIT, taker)? {
                let _ = std::fs::remove_file(&leave);
                return Ok(s);
            }
        }
    }
    // No answer: the request goes, and the holder is signalled — only the
    // lock's own vss — unless the taker gave up meanwhile.
    let _ = std::fs::remove_file(&leave);
    if taker.given_up() {
        return Err(TakeOverError::GivenUp {
            dir: dir.to_path_buf(),
            holder: h.to_string(),
        });
    }
    taker.say(format!(
        "process {} did not release session {}: asking it to end…",
        h.pid,
        crate::text::path(dir)
    ));
    if let Err(why) = lock::ask_holder_to_leave(h)
        && !h.is_stale()
    {
        return Err(TakeOverError::Refused {
            dir: dir.to_path_buf(),
            holder: h.to_string(),
            why,
        });
    }
    wait_for_lock(dir, SIGNAL_WAIT, taker)?.ok_or_else(|| TakeOverError::NoAnswer {
        dir: dir.to_path_buf(),
        holder: h.to_string(),
    })
}

/// Opens `dir` once its lock is free (or stale), waiting at most `limit`
/// and running `taker.meanwhile()` at every poll; `None` if it is still
/// held then, or at once when the taker gives up.
fn wait_for_lock(
    dir: &Path,
    limit: Duration,
    taker: &mut dyn Taker,
) -> Result<Option<Session>, SessionError> {
    let end = Instant::now() + limit;
    loop {
        taker.meanwhile();
        if taker.given_up() {
            return Ok(None);
        }
        match Session::open(dir) {
            Ok(s) => return Ok(Some(s)),
            Err(SessionError::Locked { stale: true, .. }) => {
                return Session::open_take_over(dir).map(Some);
            }
            Err(SessionError::Locked { .. }) if Instant::now() > end => return Ok(None),
            Err(SessionError::Locked { .. }) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A taker holding the session it asks for under another lock: its
    /// `meanwhile` runs while it waits and releases that lock after a few
    /// polls, as a console answering a request does.
    struct Holding {
        held: Option<Session>,
        polls: u32,
        said: Vec<String>,
    }

    impl Taker for Holding {
        fn say(&mut self, text: String) {
            self.said.push(text);
        }

        fn meanwhile(&mut self) {
            self.polls += 1;
            if self.polls == 3 {
                self.held = None;
            }
        }
    }

    /// The wait for the lock runs the taker's `meanwhile` at each poll, so
    /// a lock it releases there is taken at once: no signal, no 5 s wait
    /// (the holder here is this process, which would be refused a signal).
    #[test]
    fn the_taker_answers_while_it_waits() {
        let d = tempfile::tempdir().unwrap();
        let profile = crate::profile::Profile::builtin().unwrap();
        let held = Session::create(d.path(), "one", &profile).unwrap();
        let dir = held.dir().to_path_buf();
        let mut taker = Holding {
            held: Some(held),
            polls: 0,
            said: Vec::new(),
        };
        let t0 = Instant::now();
        let s = open_taking_over(&dir, &mut taker).expect("taken once released");
        assert!(t0.elapsed() < LEAVE_WAIT, "{:?}", t0.elapsed());
        assert!(taker.held.is_none() && taker.polls >= 3, "{}", taker.polls);
        assert!(
            taker.said[0].starts_with("asking process"),
            "{:?}",
            taker.said
        );
        assert_eq!(taker.said.len(), 1, "{:?}", taker.said);
        // Taken: another open finds it held.
        assert!(matches!(
            Session::open(&dir),
            Err(SessionError::Locked { stale: false, .. })
        ));
        assert!(!lock::leave_path(&s.lock_path()).exists());
    }
}
