//! The sessions of the survey folder as the console lists them. The list
//! is read again every few seconds while it is on screen (another console
//! or a `vss grab` may open, capture into or close a session), so a folder
//! is read again only when it, its manifest or its lock changed, and the
//! console is told only of a list that differs from the one it has.

use std::collections::{HashMap, HashSet};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use crate::session::lock::LockInfo;
use crate::session::{Session, SessionError};
use crate::tui::event::SessionEntry;

/// What the list says of a session's lock. Whether its holder still runs
/// is looked at each time (a console killed changes nothing in the folder):
/// a lock a console left behind when it was killed is not "in use", and
/// the session opens (the lock is taken over).
fn in_use(h: &LockInfo) -> String {
    if h.is_stale() {
        " (stale lock: its console ended)".to_string()
    } else {
        format!(" (in use by {})", crate::formats::sanitize(&h.user))
    }
}

/// What a folder's entry rests on: the folder, `FOLDER.toml` and
/// `FOLDER.lock`, each by inode, change time (any write, rename or
/// permission change moves it) and length (`None`: absent).
pub(super) type Stamp = [Option<(u64, i64, i64, u64)>; 3];

pub(super) fn stamp(dir: &Path, folder: &str) -> Stamp {
    let of = |p: &Path| {
        std::fs::metadata(p)
            .ok()
            .map(|m| (m.ino(), m.ctime(), m.ctime_nsec(), m.len()))
    };
    [
        of(dir),
        of(&dir.join(format!("{folder}.toml"))),
        of(&dir.join(format!("{folder}.lock"))),
    ]
}

/// A folder as last read.
#[derive(Clone)]
enum Read {
    Session {
        name: String,
        done: usize,
        all: usize,
        /// Who the lock names, if anyone.
        holder: Option<LockInfo>,
        /// When its manifest was last written.
        when: SystemTime,
    },
    NotASession,
    Damaged(String),
}

fn read(dir: &Path) -> Read {
    match Session::inspect(dir) {
        Ok(s) => {
            let (done, all) = s.progress().done();
            let name = s.name().as_str().to_string();
            let when = std::fs::metadata(dir.join(format!("{name}.toml")))
                .and_then(|m| m.modified())
                .unwrap_or(UNIX_EPOCH);
            Read::Session {
                done,
                all,
                holder: s.lock_holder(),
                when,
                name,
            }
        }
        Err(SessionError::NotASession { .. }) => Read::NotASession,
        Err(e) => Read::Damaged(e.to_string()),
    }
}

/// The folders read so far, and the list last said to the console.
#[derive(Default)]
pub struct Lister {
    seen: HashMap<PathBuf, (Stamp, Read)>,
    said: Option<Vec<SessionEntry>>,
}

impl Lister {
    /// Sessions under `survey`: name, folder, checklist summary (and who
    /// holds it: `here` is the one this console has open); a folder whose
    /// manifest does not read is listed with why. Damaged sessions first
    /// (they need a look), then the most recently worked on: after a
    /// dropped connection the session just worked on is the one chosen.
    pub fn list(&mut self, survey: &Path, here: Option<&Path>) -> Vec<SessionEntry> {
        let Ok(rd) = std::fs::read_dir(survey) else {
            self.seen.clear();
            return Vec::new();
        };
        let mut present = HashSet::new();
        let mut out: Vec<(SystemTime, SessionEntry)> = Vec::new();
        for e in rd.flatten() {
            let dir = e.path();
            if !dir.is_dir() {
                continue;
            }
            let folder = e.file_name().to_string_lossy().into_owned();
            let now = stamp(&dir, &folder);
            let r = match self.seen.get(&dir) {
                Some((was, r)) if *was == now => r.clone(),
                _ => {
                    let r = read(&dir);
                    // A folder whose session is named otherwise (a link)
                    // is not stamped by its own files: read it each time.
                    if !matches!(&r, Read::Session { name, .. } if *name != folder) {
                        self.seen.insert(dir.clone(), (now, r.clone()));
                    }
                    r
                }
            };
            present.insert(dir.clone());
            match r {
                Read::Session {
                    name,
                    done,
                    all,
                    holder,
                    when,
                } => {
                    // The session this console has open is ours, not "in
                    // use by" someone.
                    let busy = if here == Some(dir.as_path()) {
                        " (open here)".to_string()
                    } else {
                        holder.map_or(String::new(), |h| in_use(&h))
                    };
                    // A link is opened only to look (no session is
                    // written through one): marked before Enter.
                    let link = if e.file_type().is_ok_and(|t| t.is_symlink()) {
                        " (a link)"
                    } else {
                        ""
                    };
                    let summary = format!("{done}/{all} done{busy}{link}");
                    let entry = SessionEntry {
                        name,
                        dir,
                        summary,
                        damaged: None,
                    };
                    out.push((when, entry));
                }
                Read::NotASession => {}
                Read::Damaged(why) => out.push((
                    UNIX_EPOCH,
                    SessionEntry {
                        name: folder,
                        dir,
                        summary: "DAMAGED".into(),
                        damaged: Some(why),
                    },
                )),
            }
        }
        self.seen.retain(|d, _| present.contains(d));
        out.sort_by(|a, b| {
            (b.1.damaged.is_some(), b.0)
                .cmp(&(a.1.damaged.is_some(), a.0))
                .then_with(|| a.1.name.cmp(&b.1.name))
        });
        out.into_iter().map(|(_, e)| e).collect()
    }

    /// Forgets the folders read: the next list reads each again (asked
    /// for by the operator, it trusts no stamp).
    pub fn forget(&mut self) {
        self.seen.clear();
    }

    /// Remembers `list` as said; whether it differs from the one said
    /// before.
    pub fn say(&mut self, list: &[SessionEntry]) -> bool {
        let new = self.said.as_deref() != Some(list);
        self.said = Some(list.to_vec());
        new
    }
}
