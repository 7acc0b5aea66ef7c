//! The survey checklist, read from the manifest alone (cheap enough for the
//! console to ask every frame): per image which lightings are captured,
//! whether its outputs are done, missing or stale, how many manual edits;
//! and the resume point, the first thing left to do.

use super::MAX_IMAGE_NUMBER;
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

/// The checklist of `m`: a line for every number from 1 to the planned
/// images or the largest recorded number, whichever is more. A manifest that
/// did not pass [`Manifest::parse`] may hold numbers beyond
/// [`MAX_IMAGE_NUMBER`]: the lines without a record stop there and records
/// beyond it are listed as they are, so no number sizes the list.
pub fn progress(m: &Manifest) -> Progress {
    let letters: Vec<char> = m.lighting.iter().map(|l| l.letter).collect();
    let last = m
        .image
        .iter()
        .map(|r| r.number)
        .max()
        .unwrap_or(0)
        .max(m.session.planned_images)
        .min(MAX_IMAGE_NUMBER);
    let cams = m.session.cameras.max(1);
    // Walk the records in number order beside the numbers, rather than
    // search the records for every number. A stable sort keeps the first of
    // duplicate numbers first, the one `Manifest::image` finds.
    let mut records: Vec<&ImageRecord> = m.image.iter().filter(|r| r.number > 0).collect();
    records.sort_by_key(|r| r.number);
    records.dedup_by_key(|r| r.number);
    let mut recorded = records.into_iter().peekable();
    let mut images = Vec::new();
    for k in 1..=last {
        match recorded.next_if(|r| r.number == k) {
            Some(r) => images.push(from_record(r, &letters)),
            None => images.push(ImageProgress {
                number: k,
                camera: (k - 1) % cams + 1,
                location: (k - 1) / cams + 1,
                captured: Vec::new(),
                missing: letters.clone(),
                outputs: OutputState::Missing,
                edits: 0,
            }),
        }
    }
    images.extend(recorded.map(|r| from_record(r, &letters)));
    Progress { letters, images }
}

/// The checklist line of a recorded image.
fn from_record(r: &ImageRecord, letters: &[char]) -> ImageProgress {
    let captured: Vec<char> = r.grey.iter().map(|g| g.letter).collect();
    ImageProgress {
        number: r.number,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::manifest::{FORMAT, LightingInfo, SessionInfo};

    fn manifest(planned: u32, numbers: &[u32]) -> Manifest {
        Manifest {
            format: FORMAT,
            session: SessionInfo {
                name: "cube".into(),
                created: String::new(),
                modified: String::new(),
                version: String::new(),
                profile: String::new(),
                planned_images: planned,
                cameras: 2,
            },
            lighting: vec![LightingInfo {
                letter: 'a',
                on: Vec::new(),
                note: String::new(),
            }],
            image: numbers
                .iter()
                .map(|&number| ImageRecord {
                    number,
                    camera: 9,
                    location: 9,
                    cdf: None,
                    grey: Vec::new(),
                    outputs: None,
                    edit: Vec::new(),
                })
                .collect(),
            calibration: Vec::new(),
        }
    }

    #[test]
    fn a_line_for_every_number_up_to_the_largest() {
        let p = progress(&manifest(2, &[5, 3]));
        let numbers: Vec<u32> = p.images.iter().map(|i| i.number).collect();
        assert_eq!(numbers, [1, 2, 3, 4, 5]);
        // Recorded images keep their camera; the others go round the cameras.
        let cams: Vec<u32> = p.images.iter().map(|i| i.camera).collect();
        assert_eq!(cams, [1, 2, 9, 2, 9]);
        assert_eq!(
            p.next_step(),
            Some(Step::Capture {
                image: 1,
                letter: 'a'
            })
        );
    }

    #[test]
    fn numbers_beyond_the_limit_do_not_size_the_checklist() {
        // Not a manifest that loads (validate refuses it); one built in memory.
        let p = progress(&manifest(u32::MAX, &[u32::MAX, 2]));
        assert_eq!(p.images.len(), MAX_IMAGE_NUMBER as usize + 1);
        assert_eq!(p.images.last().map(|i| i.number), Some(u32::MAX));
        assert_eq!(p.images[1].camera, 9, "image 2 from its record");
    }
}
