//! Questions and text fields over the current screen: a yes/no question
//! whose "yes" is a [`Pending`] action, and a one-line text field with the
//! readline keys (← → Home End, Ctrl-A/E/U/W, Backspace, Delete), its rule
//! shown before typing, its length limit enforced while typing, and the
//! typed text kept after an error.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use super::{App, Level};
use crate::tui::event::{Cmd, StoreCmd};
use crate::tui::keymap::{Action, ModalAction, Scope};

/// What a confirmed question does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pending {
    Quit,
    /// Capture image `k` again: only `letters`, or every lighting when empty.
    Retake {
        k: u32,
        letters: Vec<char>,
    },
    /// Make image `k`'s outputs again from its saved frames with its
    /// recorded values.
    Remake(u32),
    /// Accept the image under review (save its outputs, go on).
    Accept,
    /// Save the outputs on screen over an image's accepted ones.
    SaveOutputs,
    /// Leave the open session for the one in this folder.
    Switch(std::path::PathBuf),
    /// Take the lock of a session held by a console that still runs.
    TakeOver(std::path::PathBuf),
    /// Open, only to look, a session whose folder cannot be written or
    /// that another console holds: without its lock, nothing saved.
    OpenReadOnly(std::path::PathBuf),
    /// Start an image beyond the survey's plan.
    ExtraImage(u32),
    /// Go on with the edit of an accepted image's lines.
    Edit,
    /// Go on with an edit whose result looks like nonsense.
    EditDoubtful,
    /// Create a session whose name ends in a digit.
    CreateSession(String),
    /// Write the calibration shown into its camera's `.cdf`.
    CalibWrite,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PromptPurpose {
    SessionName,
    ParamValue(&'static str),
    /// The Calibrate screen's fields (images to load, plate, centre).
    Calibrate(super::calibrate::Field),
    /// The text `/` searches for.
    Search(super::SearchTarget),
}

/// A one-line text field.
#[derive(Clone, Debug, PartialEq)]
pub struct Prompt {
    pub title: String,
    /// What may be typed, shown before typing.
    pub rule: String,
    pub text: String,
    /// Cursor position, in characters.
    pub cursor: usize,
    /// The longest text accepted (characters).
    pub max: usize,
    pub purpose: PromptPurpose,
    /// Why the last Enter was refused (the text stays for correcting).
    pub error: Option<String>,
    /// The text offered when the field opened is selected: the first
    /// character typed replaces it (a value typed after `Enter` is that
    /// value, not the old one with it appended), a deleting key clears it,
    /// and a moving key keeps it for editing.
    pub selected: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Modal {
    Prompt(Prompt),
    Confirm {
        question: String,
        on_yes: Pending,
        /// What `a` ("all") does, where the question offers it.
        on_all: Option<Pending>,
        /// What `r` ("read-only", only look) does, where the question
        /// offers it.
        on_look: Option<Pending>,
    },
}

impl Modal {
    pub fn confirm(question: impl Into<String>, on_yes: Pending) -> Modal {
        Modal::Confirm {
            question: question.into(),
            on_yes,
            on_all: None,
            on_look: None,
        }
    }

    /// Whether the open question takes `a`: "all" and "read-only" only
    /// where it offers them.
    pub fn offers(&self, a: ModalAction) -> bool {
        match self {
            Modal::Confirm {
                on_all, on_look, ..
            } => match a {
                ModalAction::All => on_all.is_some(),
                ModalAction::Look => on_look.is_some(),
                _ => true,
            },
            Modal::Prompt(_) => true,
        }
    }

    /// The keys a question offers with their words, as the key table has
    /// them (`y yes`, `n no`, and `a all`, `r read-only` where offered; none
    /// for a text field): the question's box, the too-small window's line
    /// and the hint row say the same.
    pub fn choices(&self) -> Vec<(String, &'static str)> {
        if let Modal::Prompt(_) = self {
            return Vec::new();
        }
        crate::tui::keymap::hints_where(
            Scope::Confirm,
            |b| matches!(b.action, Action::Modal(m) if self.offers(m)),
        )
    }

    pub fn prompt(
        title: impl Into<String>,
        rule: impl Into<String>,
        text: String,
        max: usize,
        purpose: PromptPurpose,
    ) -> Modal {
        let cursor = text.chars().count();
        Modal::Prompt(Prompt {
            title: title.into(),
            rule: rule.into(),
            selected: false,
            text,
            cursor,
            max,
            purpose,
            error: None,
        })
    }

    /// The text field with its offered text selected ([`Prompt::selected`]),
    /// so that what is typed replaces it: for a value to replace (a
    /// parameter's). A text the operator typed and is to correct stays
    /// unselected.
    pub fn selected(mut self) -> Modal {
        if let Modal::Prompt(p) = &mut self {
            p.selected = !p.text.is_empty();
        }
        self
    }
}

impl Prompt {
    fn byte(&self, char_index: usize) -> usize {
        self.text
            .char_indices()
            .nth(char_index)
            .map_or(self.text.len(), |(i, _)| i)
    }

    /// Types one character at the cursor (refused past the limit); over
    /// the selected offered text, instead of it.
    pub fn insert(&mut self, c: char) -> bool {
        if c.is_control() {
            return false;
        }
        if std::mem::take(&mut self.selected) {
            self.text.clear();
            self.cursor = 0;
        }
        if self.text.chars().count() >= self.max {
            return false;
        }
        let at = self.byte(self.cursor);
        self.text.insert(at, c);
        self.cursor += 1;
        self.error = None;
        true
    }

    /// Why typing `c` makes the text a session name cannot be whatever
    /// follows ([`SessionName::new`]'s letters, separators and `..`
    /// errors), when the text so far has no such fault; a name too short
    /// or starting badly yet is left to Enter.
    ///
    /// [`SessionName::new`]: crate::formats::names::SessionName::new
    fn refused_letter(&self, c: char) -> Option<crate::formats::names::NameError> {
        use crate::formats::names::{NameError, SessionName};
        let letters = |text: &str| {
            SessionName::new(text).err().filter(|e| {
                matches!(
                    e,
                    NameError::BadChar { .. }
                        | NameError::PathSeparator { .. }
                        | NameError::DotDot { .. }
                )
            })
        };
        // Typing over a selection replaces it.
        if self.selected {
            return letters(&c.to_string());
        }
        if letters(&self.text).is_some() {
            return None;
        }
        let mut typed = self.text.clone();
        typed.insert(self.byte(self.cursor), c);
        letters(&typed)
    }

    /// A readline key.
    pub fn edit(&mut self, a: ModalAction) {
        if std::mem::take(&mut self.selected)
            && matches!(
                a,
                ModalAction::DeleteBack
                    | ModalAction::DeleteForward
                    | ModalAction::KillLine
                    | ModalAction::KillWord
            )
        {
            // A deleting key deletes the selection, as in any text field.
            self.text.clear();
            self.cursor = 0;
            self.error = None;
            return;
        }
        let n = self.text.chars().count();
        match a {
            ModalAction::Left => self.cursor = self.cursor.saturating_sub(1),
            ModalAction::Right => self.cursor = (self.cursor + 1).min(n),
            ModalAction::Home => self.cursor = 0,
            ModalAction::End => self.cursor = n,
            ModalAction::DeleteBack if self.cursor > 0 => {
                let (a, b) = (self.byte(self.cursor - 1), self.byte(self.cursor));
                self.text.replace_range(a..b, "");
                self.cursor -= 1;
            }
            ModalAction::DeleteForward if self.cursor < n => {
                let (a, b) = (self.byte(self.cursor), self.byte(self.cursor + 1));
                self.text.replace_range(a..b, "");
            }
            ModalAction::KillLine => {
                let b = self.byte(self.cursor);
                self.text.replace_range(..b, "");
                self.cursor = 0;
            }
            ModalAction::KillWord => {
                let chars: Vec<char> = self.text.chars().collect();
                let mut i = self.cursor;
                while i > 0 && chars[i - 1].is_whitespace() {
                    i -= 1;
                }
                while i > 0 && !chars[i - 1].is_whitespace() {
                    i -= 1;
                }
                let (a, b) = (self.byte(i), self.byte(self.cursor));
                self.text.replace_range(a..b, "");
                self.cursor = i;
            }
            ModalAction::DeleteBack
            | ModalAction::DeleteForward
            | ModalAction::All
            | ModalAction::Look
            | ModalAction::Yes
            | ModalAction::No
            | ModalAction::Submit
            | ModalAction::Cancel => {}
        }
        self.error = None;
    }
}

impl App {
    /// A printable key typed into the open text field. A session name's
    /// field refuses a character the name can never hold as it is typed,
    /// with the words Enter would say, the text left as it was; the
    /// refusal is also logged, so that a paste's last refusal stays said
    /// on the message line when its next letters are taken.
    pub(super) fn prompt_typed(&mut self, key: &KeyEvent) {
        let Some(Modal::Prompt(p)) = self.chrome.modal.as_mut() else {
            return;
        };
        let KeyCode::Char(c) = key.code else {
            return;
        };
        if key.modifiers.contains(KeyModifiers::CONTROL) || c.is_control() {
            return;
        }
        if p.purpose == PromptPurpose::SessionName
            && let Some(e) = p.refused_letter(c)
        {
            let why = format!("session name refused: {e}");
            p.error = Some(why.clone());
            self.chrome.log.push(Level::Error, why);
            return;
        }
        if !p.insert(c) {
            p.error = Some(format!("at most {} characters", p.max));
        }
    }

    pub(super) fn modal_action(&mut self, a: ModalAction) -> Vec<Cmd> {
        match a {
            ModalAction::Yes | ModalAction::No | ModalAction::All | ModalAction::Look => {
                self.answer(a)
            }
            ModalAction::Submit => self.submit(),
            ModalAction::Cancel => {
                self.chrome.modal = None;
                Vec::new()
            }
            ModalAction::Left
            | ModalAction::Right
            | ModalAction::Home
            | ModalAction::End
            | ModalAction::DeleteBack
            | ModalAction::DeleteForward
            | ModalAction::KillLine
            | ModalAction::KillWord => {
                if let Some(Modal::Prompt(p)) = self.chrome.modal.as_mut() {
                    p.edit(a);
                }
                Vec::new()
            }
        }
    }

    /// The answer to the open question: yes, no, "all" or "read-only"; a
    /// choice the question does not offer leaves it open.
    pub(super) fn answer(&mut self, a: ModalAction) -> Vec<Cmd> {
        if !self.chrome.modal.as_ref().is_some_and(|m| m.offers(a)) {
            return Vec::new();
        }
        let Some(Modal::Confirm {
            on_yes,
            on_all,
            on_look,
            ..
        }) = self.chrome.modal.take()
        else {
            return Vec::new();
        };
        let pending = match a {
            ModalAction::No => {
                if let Pending::CreateSession(name) = on_yes {
                    // Back to the field, the name there to change.
                    self.chrome.modal = Some(Modal::prompt(
                        "new session name:",
                        super::survey::NAME_RULE,
                        name,
                        crate::formats::names::MAX_SESSION_LEN,
                        PromptPurpose::SessionName,
                    ));
                    return Vec::new();
                }
                self.chrome.log.push(Level::Info, "nothing changed");
                return Vec::new();
            }
            ModalAction::All => on_all,
            ModalAction::Look => on_look,
            _ => Some(on_yes),
        };
        pending.map_or_else(Vec::new, |p| self.run_pending(p))
    }

    fn run_pending(&mut self, p: Pending) -> Vec<Cmd> {
        match p {
            Pending::Quit => {
                self.chrome.quit = true;
                vec![Cmd::Device(crate::tui::event::DeviceCmd::Cancel)]
            }
            Pending::Retake { k, letters } => self.ctx().retake(k, letters),
            Pending::Remake(k) => self.ctx().remake(k),
            Pending::Accept => self.ctx().accept(true),
            Pending::SaveOutputs => self.ctx().save_outputs(true).unwrap_or_default(),
            Pending::Switch(dir) => vec![Cmd::Store(StoreCmd::Open(dir))],
            Pending::TakeOver(dir) => vec![Cmd::Store(StoreCmd::TakeOver(dir))],
            Pending::OpenReadOnly(dir) => vec![Cmd::Store(StoreCmd::OpenReadOnly(dir))],
            Pending::ExtraImage(k) => self.ctx().extra_image(k),
            Pending::CreateSession(name) => vec![Cmd::Store(StoreCmd::Create(name))],
            Pending::Edit => {
                let (s, mut ctx) = self.parts();
                s.edit.confirmed(&mut ctx)
            }
            Pending::EditDoubtful => {
                let (s, mut ctx) = self.parts();
                s.edit.doubt_confirmed(&mut ctx)
            }
            Pending::CalibWrite => self.screens.calibrate.confirmed(),
        }
    }

    fn submit(&mut self) -> Vec<Cmd> {
        let Some(Modal::Prompt(mut p)) = self.chrome.modal.take() else {
            return Vec::new();
        };
        let result = match p.purpose {
            PromptPurpose::Search(target) => {
                // Not logged: a search is no event of the survey (and its
                // text in the log would be a match of the next search).
                if let Err(e) = self.search_submitted(target, &p.text) {
                    p.error = Some(e);
                    self.chrome.modal = Some(Modal::Prompt(p));
                }
                return Vec::new();
            }
            PromptPurpose::SessionName => {
                match crate::formats::names::SessionName::new(p.text.trim()) {
                    Ok(n) => {
                        let name = n.as_str();
                        let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
                        if stem.len() < name.len() {
                            // Asked, not only logged: the messages of the
                            // opening would push a warning off the row.
                            let digits = &name[stem.len()..];
                            let why = format!(
                                "session name {name} ends in a digit: its image 1 is \
                                 {name}1a.img, which also reads as session {stem} image \
                                 {digits}1 — a letter at the end avoids that"
                            );
                            self.chrome.log.push(Level::Warn, why.clone());
                            self.chrome.modal = Some(Modal::confirm(
                                format!("{why}. Create {name} anyway? (n: change the name)"),
                                Pending::CreateSession(name.to_string()),
                            ));
                            return Vec::new();
                        }
                        Ok(vec![Cmd::Store(StoreCmd::Create(n.as_str().to_string()))])
                    }
                    Err(e) => Err(format!("session name refused: {e}")),
                }
            }
            PromptPurpose::ParamValue(key) => {
                let mut params = self.tracker.params.clone();
                let spec = crate::llv::params::PARAMS.iter().find(|sp| sp.key == key);
                let typed = p.text.trim();
                // A fraction for a whole-number parameter is the wrong kind
                // of value, whatever its size ("6.7 is out of range: 1 to
                // 4096" sent the operator looking at the range).
                let fraction = spec.is_some_and(|sp| sp.kind == crate::llv::params::Kind::Int)
                    && typed.parse::<f64>().is_ok_and(|v| v.fract() != 0.0);
                if fraction {
                    Err(format!(
                        "{key} takes a whole number ({}): {typed} is not one",
                        spec.map(|sp| sp.range_text()).unwrap_or_default()
                    ))
                } else {
                    match params.set_str(&format!("{key}={typed}")) {
                        Ok(()) => {
                            let v = params.get(key).unwrap_or_default();
                            self.chrome.log.push(
                                Level::Info,
                                format!("{key} = {}", crate::llv::params::fmt_value(v)),
                            );
                            Ok(self.ctx().set_params(params))
                        }
                        Err(e) => Err(e.to_string()),
                    }
                }
            }
            PromptPurpose::Calibrate(field) => {
                let (s, mut ctx) = self.parts();
                s.calibrate.submitted(field, p.text.trim(), &mut ctx)
            }
        };
        match result {
            Ok(cmds) => cmds,
            Err(e) => {
                // The field stays open with the text, to correct it.
                self.chrome.log.push(Level::Error, e.clone());
                p.error = Some(e);
                self.chrome.modal = Some(Modal::Prompt(p));
                Vec::new()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn offered(text: &str) -> Prompt {
        match Modal::prompt("v =", "", text.to_string(), 24, PromptPurpose::SessionName).selected()
        {
            Modal::Prompt(p) => p,
            Modal::Confirm { .. } => unreachable!(),
        }
    }

    #[test]
    fn an_offered_value_is_replaced_cleared_or_kept_for_editing() {
        let mut p = offered("16");
        assert!(p.insert('1') && p.insert('2'));
        assert_eq!(p.text, "12");
        let mut p = offered("16");
        p.edit(ModalAction::DeleteBack);
        assert_eq!((p.text.as_str(), p.cursor), ("", 0));
        let mut p = offered("16");
        p.edit(ModalAction::Home);
        assert!(p.insert('2'));
        assert_eq!(p.text, "216");
        // A text to correct is offered unselected: typing appends.
        let Modal::Prompt(mut p) =
            Modal::prompt("name:", "", "q1".into(), 24, PromptPurpose::SessionName)
        else {
            unreachable!()
        };
        assert!(p.insert('x'));
        assert_eq!(p.text, "q1x");
    }
}
