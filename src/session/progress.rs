//! The survey checklist, read from the manifest alone (cheap enough for the
//! console to ask every frame): per image which lightings are captured,
//! whether its outputs are done, missing or stale, how many manual edits;
//! and the resume point, the first thing left to do.

use super::manifest::{ImageRecord, Manifest};

/// State of the stage outputs of one image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutputState {
    Missing,
    Done,
    /// Made, but from inputs that have changed since: why.
    Stale(String),
}

/// One line of the checklist.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageProgress {
    pub number: u32,
    pub camera: u32,
    pub location: u32,
    pub captured: Vec<char>,
    pub missing: Vec<char>,
    pub outputs: OutputState,
    pub edits: usize,
}

impl ImageProgress {
    /// Captured under every lighting and processed from those images.
    pub fn is_done(&self) -> bool {
        self.missing.is_empty() && self.outputs == OutputState::Done
    }
}

/// The next thing the survey needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Grab image `image` under lighting `letter`.
    Capture { image: u32, letter: char },
    /// Run the stages on image `image` (outputs missing or stale).
    Process { image: u32 },
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Step::Capture { image, letter } => {
                write!(f, "capture image {image} under lighting {letter}")
            }
            Step::Process { image } => write!(f, "process image {image}"),
        }
    }
}

/// The whole checklist.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Progress {
    pub letters: Vec<char>,
    pub images: Vec<ImageProgress>,
}

impl Progress {
    /// Where an interrupted survey resumes: the first image missing a
    /// lighting, else the first image whose outputs are missing or stale.
    /// `None` when the survey is complete.
    pub fn next_step(&self) -> Option<Step> {
        for i in &self.images {
            if let Some(&letter) = i.missing.first() {
                return Some(Step::Capture {
                    image: i.number,
                    letter,
                });
            }
            if i.outputs != OutputState::Done {
                return Some(Step::Process { image: i.number });
            }
        }
        None
    }

    pub fn is_complete(&self) -> bool {
        self.next_step().is_none()
    }

    /// Images fully done, of all planned.
    pub fn done(&self) -> (usize, usize) {
        (
            self.images.iter().filter(|i| i.is_done()).count(),
            self.images.len(),
        )
    }
}

pub fn progress(m: &Manifest) -> Progress {
    let letters: Vec<char> = m.lighting.iter().map(|l| l.letter).collect();
    let last = m
        .image
        .iter()
        .map(|r| r.number)
        .max()
        .unwrap_or(0)
        .max(m.session.planned_images);
    let cams = m.session.cameras.max(1);
    let images = (1..=last)
        .map(|k| match m.image(k) {
            Some(r) => {
                let captured: Vec<char> = r.grey.iter().map(|g| g.letter).collect();
                ImageProgress {
                    number: k,
                    camera: r.camera,
                    location: r.location,
                    missing: letters
                        .iter()
                        .copied()
                        .filter(|l| !captured.contains(l))
                        .collect(),
                    captured,
                    outputs: output_state(r),
                    edits: r.edit.len(),
                }
            }
            None => ImageProgress {
                number: k,
                camera: (k - 1) % cams + 1,
                location: (k - 1) / cams + 1,
                captured: Vec::new(),
                missing: letters.clone(),
                outputs: OutputState::Missing,
                edits: 0,
            },
        })
        .collect();
    Progress { letters, images }
}

/// Whether the outputs of `r` were made from the inputs now recorded.
pub fn output_state(r: &ImageRecord) -> OutputState {
    let Some(o) = &r.outputs else {
        return OutputState::Missing;
    };
    let mut now: Vec<(&str, &str)> = r
        .grey
        .iter()
        .map(|g| (g.file.as_str(), g.hash.as_str()))
        .collect();
    if let Some(c) = &r.cdf {
        now.push((c.file.as_str(), c.hash.as_str()));
    }
    let mut why = Vec::new();
    for input in &o.inputs {
        match now.iter().find(|(f, _)| *f == input.file) {
            None => why.push(format!("{} is no longer recorded", input.file)),
            Some((_, h)) if *h != input.hash => {
                why.push(format!(
                    "{} changed after the outputs were made",
                    input.file
                ));
            }
            Some(_) => {}
        }
    }
    for (f, _) in &now {
        if !o.inputs.iter().any(|i| i.file == *f) {
            why.push(format!("{f} was added after the outputs were made"));
        }
    }
    if why.is_empty() {
        OutputState::Done
    } else {
        OutputState::Stale(why.join("; "))
    }
}
