//! Capturing an image again, or making its outputs again from its saved
//! frames: the question `R` asks and what each answer does.

use super::*;

impl Ctx<'_> {
    /// Asks before capturing image `k` again: only its damaged lightings,
    /// or all of them.
    pub fn ask_retake(&mut self, k: u32) {
        if matches!(
            self.session.work.phase,
            Phase::Capturing | Phase::Processing | Phase::NoSession
        ) {
            self.warn("nothing to capture again now");
            return;
        }
        let mut damaged: Vec<(char, String)> = self
            .session
            .image(k)
            .map(|i| i.damaged.clone())
            .unwrap_or_default();
        let on_disk = damaged.len();
        // And the lightings of this run the session could not save.
        if let Some(c) = self.tracker.current.as_ref().filter(|c| c.k == k) {
            for (l, why) in &c.unsaved {
                if !damaged.iter().any(|d| d.0 == *l) {
                    damaged.push((*l, why.clone()));
                }
            }
        }
        let state = match (on_disk, damaged.len() - on_disk) {
            (_, 0) => "damaged",
            (0, _) => "not saved",
            _ => "damaged or not saved",
        };
        let all = Pending::Retake {
            k,
            letters: Vec::new(),
        };
        let outputs_damaged = self
            .session
            .image(k)
            .and_then(|i| i.outputs_damaged.clone());
        if damaged.is_empty()
            && let Some(why) = outputs_damaged
        {
            // The frames are good: making the outputs again from them is
            // the remedy; a new capture is the second choice.
            self.chrome.modal = Some(Modal::Confirm {
                question: format!(
                    "Image {k}: its outputs are damaged ({why}). y makes them again from its \
                     saved frames with its recorded values (its hand edits are lost), a \
                     captures every lighting again, n nothing."
                ),
                on_yes: Pending::Remake(k),
                on_all: Some(all),
                on_look: None,
            });
            return;
        }
        if damaged.is_empty() {
            self.ask(
                format!(
                    "Capture image {k} again under every lighting? Its saved grey images and \
                     outputs are replaced as the new captures come in."
                ),
                all,
            );
            return;
        }
        let letters: Vec<char> = damaged.iter().map(|d| d.0).collect();
        let list: String = letters.iter().collect();
        let words = crate::tui::app::tracker::lightings(&letters);
        let why: Vec<String> = damaged.iter().map(|(l, w)| format!("{l}: {w}")).collect();
        self.chrome.modal = Some(Modal::Confirm {
            question: format!(
                "Image {k}: {words} {state} ({}). y sets up the retake of only {list} \
                 (Enter then captures), a of every lighting, n nothing.",
                why.join("; ")
            ),
            on_yes: Pending::Retake { k, letters },
            on_all: Some(all),
            on_look: None,
        });
    }

    /// Captures image `k` again: every lighting (`letters` empty), or only
    /// the damaged ones.
    pub fn retake(&mut self, k: u32, letters: Vec<char>) -> Vec<Cmd> {
        self.session.work.k = k;
        self.session.work.phase = Phase::Setup;
        self.follow_plan();
        self.use_recorded_params(k);
        if letters.is_empty() {
            let mut l = Loaded::new(k, self.session.work.camera);
            l.accepted = self.session.accepted(k);
            l.version = self.tracker.next_version();
            self.tracker.current = Some(l);
            self.info(format!("image {k} will be captured again: Enter starts"));
            return vec![Cmd::Store(StoreCmd::Redo(k))];
        }
        self.info(format!(
            "image {k}: Enter captures {} again; the others are kept",
            crate::tui::app::tracker::lightings(&letters)
        ));
        match self.tracker.current.as_mut() {
            Some(c) if c.k == k => {
                c.frames.retain(|f| !letters.contains(&f.0));
                c.outputs = None;
                Vec::new()
            }
            _ => vec![Cmd::Store(StoreCmd::Load(k))],
        }
    }

    /// Makes image `k`'s outputs again from its saved frames with its
    /// recorded values (the session's redo, as `vss session redo`); the
    /// store reads the image back when done.
    pub fn remake(&mut self, k: u32) -> Vec<Cmd> {
        if !self.set_image_under_work(k) {
            return Vec::new();
        }
        self.use_recorded_params(k);
        self.tracker.current = None;
        self.info(format!(
            "image {k}: making its outputs again from its saved frames…"
        ));
        vec![Cmd::Store(StoreCmd::Remake(k))]
    }
}
