//! Replacing the open session — creating one, opening one, taking one
//! over, opening one only to look — by one rule: the new session is
//! opened first (its lock taken, or its read-only view made), and only
//! then is the old one closed. When the new one cannot be opened (held by
//! a console that still runs, an unwritable folder, a damaged session,
//! a take-over that failed) the old one stays open, its lock held, and
//! the store says so: the console, which shows the old one until it hears
//! [`StoreEvent::Opened`], and the store agree, and no other console can
//! take the session this one still shows. One exception: while a take-over
//! waits, the old session is left to a console that asks for it (two
//! consoles taking over each other's at once); when the new one then fails,
//! no session is open, and that is said.

use std::path::{Path, PathBuf};

use super::{Store, session_err};
use crate::session::{Session, SessionError};
use crate::tui::event::{StoreError, StoreEvent};

/// What is to replace the open session.
pub(super) enum Opening {
    /// A new session of this name in the survey folder.
    Create(String),
    /// The session in this folder, to write (a stale lock taken over).
    Open(PathBuf),
    /// The session in this folder, to write, taken over from a live holder.
    TakeOver(PathBuf),
    /// The session in this folder, only to look: no lock.
    Look(PathBuf),
}

impl Opening {
    /// The folder asked for, when it is named.
    fn dir(&self) -> Option<&Path> {
        match self {
            Opening::Create(_) => None,
            Opening::Open(d) | Opening::TakeOver(d) | Opening::Look(d) => Some(d),
        }
    }

    /// The session asked for, as said.
    fn shown(&self) -> String {
        match self {
            Opening::Create(name) => format!("new session {name}"),
            Opening::Open(d) | Opening::TakeOver(d) | Opening::Look(d) => crate::text::path(d),
        }
    }
}

impl Store {
    /// Replaces the open session by `how` (the rule above), saying each
    /// outcome: [`StoreEvent::Opened`], or why not — a question for the
    /// operator ([`StoreEvent::Locked`], [`StoreEvent::Unwritable`]) or an
    /// error — followed by which session stays open, if one does; then
    /// [`StoreEvent::OpeningDone`], whatever the outcome.
    pub(super) fn replace(&mut self, how: Opening) {
        self.open_instead(how);
        self.reply(StoreEvent::OpeningDone);
    }

    fn open_instead(&mut self, how: Opening) {
        if let Some(name) = self.holding(&how) {
            // Its lock is ours: opening it again would find it held.
            self.reply(StoreEvent::Note(format!(
                "session {name} is already open here: nothing changed"
            )));
            return;
        }
        // The session held when asked: a take-over gives it up while it
        // waits when its holder asks for it meanwhile (a crossed take-over).
        let held = self
            .session
            .as_ref()
            .filter(|_| !self.read_only)
            .map(|s| s.name().to_string());
        match self.open_new(&how) {
            Ok(Some(s)) => {
                // None left to close when it was given up meanwhile.
                self.close();
                let look = matches!(how, Opening::Look(_));
                // Its lock is only read: a holder keeps it, unasked.
                let holder = look.then(|| s.lock_holder()).flatten();
                self.read_only = look;
                self.opened(s);
                if let Some(h) = holder {
                    self.reply(StoreEvent::Note(format!(
                        "session {} stays with {h}, undisturbed; what it saves shows here \
                         within 2 s",
                        how.shown()
                    )));
                }
            }
            Ok(None) => self.say_kept(&how, held),
            Err(e) => {
                self.reply(StoreEvent::Error(e));
                self.say_kept(&how, held);
            }
        }
    }

    /// The name of the open session when `how` names it and this console
    /// holds its lock (open to write).
    fn holding(&self, how: &Opening) -> Option<String> {
        let s = self.session.as_ref().filter(|_| !self.read_only)?;
        let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => a == b,
        };
        how.dir()
            .is_some_and(|d| same(d, s.dir()))
            .then(|| s.name().to_string())
    }

    /// Opens the session `how` asks for, leaving the open one alone;
    /// `None` when the operator is asked first (held, unwritable).
    fn open_new(&mut self, how: &Opening) -> Result<Option<Session>, StoreError> {
        let cannot = |d: &Path| session_err(format!("cannot open {}", crate::text::path(d)));
        let dir = match how {
            Opening::Create(name) => {
                return Session::create(&self.profile.survey.dir, name, &self.profile)
                    .map(Some)
                    .map_err(session_err(format!("cannot create session {name}")));
            }
            Opening::TakeOver(dir) => return self.take_over(dir).map(Some),
            Opening::Look(dir) => return Session::inspect(dir).map(Some).map_err(cannot(dir)),
            Opening::Open(dir) => dir.clone(),
        };
        match Session::open(&dir) {
            Ok(s) => Ok(Some(s)),
            Err(SessionError::Locked { stale: true, .. }) => {
                self.reply(StoreEvent::Note(format!(
                    "took over the lock of {}: its holder is gone",
                    crate::text::path(&dir)
                )));
                Session::open_take_over(&dir)
                    .map(Some)
                    .map_err(cannot(&dir))
            }
            Err(SessionError::Locked { holder, .. }) => {
                self.reply(StoreEvent::Locked { dir, holder });
                Ok(None)
            }
            // A link to a folder is never written through: looking is
            // offered, not done.
            Err(SessionError::Linked(l)) => {
                let why = l.to_string();
                self.reply(StoreEvent::Unwritable { dir, why });
                Ok(None)
            }
            // The lock cannot be written: the folder is read-only (a
            // mount, permissions). Looking is offered, not done.
            Err(SessionError::Unwritable { path, source }) => {
                let why = format!(
                    "its lock cannot be written ({}: {source})",
                    crate::text::path(&path)
                );
                self.reply(StoreEvent::Unwritable { dir, why });
                Ok(None)
            }
            Err(e) => Err(cannot(&dir)(e)),
        }
    }

    /// Says which session stays open after `how` did not replace it, or,
    /// when `held` (held when asked) was given up meanwhile, that none is.
    fn say_kept(&self, how: &Opening, held: Option<String>) {
        let text = match (&self.session, held) {
            (Some(s), _) => {
                let kept = if self.read_only {
                    "only to look"
                } else {
                    "its lock kept"
                };
                format!(
                    "session {} is still open here, {kept}: {} was not opened",
                    s.name(),
                    how.shown()
                )
            }
            (None, Some(name)) => format!(
                "no session is open here now: session {name} was left to the console that \
                 asked for it while this one waited, and {} was not opened; choose or create \
                 a session",
                how.shown()
            ),
            (None, None) => return,
        };
        self.reply(StoreEvent::Note(text));
    }

    /// Opens a session another vss holds, by the rule every take-over
    /// follows (`takeover::open_taking_over`: a live holder on this host
    /// is asked through the session folder, and signalled only when it
    /// does not answer); each step is said. While it waits, a request for
    /// the session this console holds is answered as between commands
    /// ([`Store::leave_if_asked`]).
    fn take_over(&mut self, dir: &Path) -> Result<Session, StoreError> {
        use crate::session::takeover::{self, TakeOverError};
        takeover::open_taking_over(dir, &mut Taking(self)).map_err(|e| match e {
            TakeOverError::Session(e) => {
                session_err(format!("cannot take over {}", crate::text::path(dir)))(e)
            }
            e => StoreError::TakeOver(e),
        })
    }
}

/// The store taking a session over: its steps are notes, while it waits it
/// answers a request to leave the session it still holds, and it gives up
/// (no signal) when the console quits.
struct Taking<'a>(&'a mut Store);

impl crate::session::takeover::Taker for Taking<'_> {
    fn say(&mut self, text: String) {
        self.0.reply(StoreEvent::Note(text));
    }

    fn meanwhile(&mut self) {
        self.0.leave_if_asked();
    }

    fn given_up(&self) -> bool {
        self.0.quitting.load(std::sync::atomic::Ordering::SeqCst)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::mpsc::{Receiver, channel};

    use super::*;
    use crate::profile::Profile;
    use crate::tui::event::{Msg, StoreCmd};

    /// A store on the built-in cell whose survey folder is `dir`.
    fn store(dir: &Path) -> (Store, Receiver<Msg>) {
        let mut profile = Profile::builtin().unwrap();
        profile.survey.dir = dir.to_path_buf();
        let (tx, rx) = channel();
        (Store::new(profile, tx), rx)
    }

    /// The notes said since the last call.
    fn notes(rx: &Receiver<Msg>) -> Vec<String> {
        rx.try_iter()
            .filter_map(|m| match m {
                Msg::Store(StoreEvent::Note(t)) => Some(t),
                _ => None,
            })
            .collect()
    }

    /// The open session's name, and its lock file.
    fn open_here(s: &Store) -> (String, String) {
        let s = s.session.as_ref().expect("a session open");
        let lock = std::fs::read_to_string(s.lock_path()).unwrap();
        (s.name().to_string(), lock)
    }

    /// Runs `cmd` on `st`, which must keep `held` open for writing; what
    /// it said, and `cmd` as said in the assertions.
    fn keeps(
        st: &mut Store,
        rx: &Receiver<Msg>,
        cmd: StoreCmd,
        held: &(String, String),
    ) -> (Vec<String>, String) {
        let what = format!("{cmd:?}");
        st.handle(cmd);
        assert_eq!(&open_here(st), held, "after {what}");
        assert!(!st.read_only, "after {what}");
        (notes(rx), what)
    }

    /// Every way a new session can fail to open — held by a live console
    /// (the operator asked), damaged, missing, a take-over of a damaged
    /// one, a name taken — leaves the open one open and its lock held,
    /// and says so.
    #[test]
    fn a_session_that_cannot_be_opened_leaves_the_open_one_held() {
        let d = tempfile::tempdir().unwrap();
        let (mut st, rx) = store(d.path());
        st.handle(StoreCmd::Create("one".into()));
        let held = open_here(&st);
        assert_eq!(held.0, "one");
        // two is held by a live vss (this process, another lock).
        let _two = Session::create(d.path(), "two", &st.profile).unwrap();
        let bad = d.path().join("bad");
        drop(Session::create(d.path(), "bad", &st.profile).unwrap());
        std::fs::write(bad.join("bad.toml"), "not a manifest [").unwrap();
        notes(&rx);
        let tries = [
            StoreCmd::Open(d.path().join("two")),
            StoreCmd::Open(bad.clone()),
            StoreCmd::Open(d.path().join("none")),
            StoreCmd::OpenReadOnly(bad.clone()),
            StoreCmd::TakeOver(bad.clone()),
            StoreCmd::Create("two".into()),
        ];
        for cmd in tries {
            let (said, what) = keeps(&mut st, &rx, cmd, &held);
            assert!(
                said.iter()
                    .any(|n| n.starts_with("session one is still open here, its lock kept")),
                "after {what}: {said:?}"
            );
            // Nobody else can take it.
            let one = d.path().join("one");
            assert!(
                matches!(
                    Session::open(&one),
                    Err(SessionError::Locked { stale: false, .. })
                ),
                "after {what}"
            );
        }
    }

    /// Opening the session this console holds again is no deadlock on its
    /// own lock and no re-take: nothing changes, and that is said.
    #[test]
    fn opening_the_session_held_here_changes_nothing() {
        let d = tempfile::tempdir().unwrap();
        let (mut st, rx) = store(d.path());
        st.handle(StoreCmd::Create("one".into()));
        let held = open_here(&st);
        notes(&rx);
        let one = d.path().join("one");
        for cmd in [
            StoreCmd::Open(one.clone()),
            StoreCmd::Open(d.path().join(".").join("one")),
            StoreCmd::TakeOver(one.clone()),
            StoreCmd::OpenReadOnly(one.clone()),
        ] {
            let (said, what) = keeps(&mut st, &rx, cmd, &held);
            assert_eq!(
                said,
                ["session one is already open here: nothing changed"],
                "after {what}"
            );
        }
    }

    /// A session open only to look stays so when the next one cannot be
    /// opened.
    #[test]
    fn a_session_open_to_look_stays_when_the_next_cannot_be_opened() {
        let d = tempfile::tempdir().unwrap();
        let (mut st, rx) = store(d.path());
        drop(Session::create(d.path(), "one", &st.profile).unwrap());
        st.handle(StoreCmd::OpenReadOnly(d.path().join("one")));
        assert!(st.read_only);
        notes(&rx);
        st.handle(StoreCmd::Open(d.path().join("none")));
        let s = st.session.as_ref().expect("one still open");
        assert_eq!(s.name().as_str(), "one");
        assert!(st.read_only);
        let said = notes(&rx);
        assert!(
            said.iter()
                .any(|n| n.starts_with("session one is still open here, only to look")),
            "{said:?}"
        );
    }
}
