//! The crash-safety helper behind the hidden `vss session torture DIR`: it
//! saves into a session in an endless loop — grey images, stage outputs,
//! manual edits, now and then closing and reopening the session — so a test
//! can SIGKILL it at random moments and then check that every file is a
//! complete version and the manifest still describes the folder.
//!
//! Every file it writes is self-consistent in a way a checker can verify
//! ([`consistent_image`], [`consistent_lines`], [`consistent_edges`]): a
//! half-written or mixed file fails those checks.

use std::path::Path;

use super::{OutputSet, Session, SessionError};
use crate::formats::img::ImgFile;
use crate::llv::rng::SplitMix64;
use crate::llv::{EdgePoint, EdgePoints, GreyImage, Params, Point, ScanDir, Segment};

/// Image size of the torture survey: big enough that a write takes a while.
pub const SIZE: (usize, usize) = (160, 120);

/// Uniform in `0..n` (`n > 0`) as the torture runs draw it: the generator's
/// next value modulo `n`.
pub fn below(rng: &mut SplitMix64, n: u64) -> u64 {
    rng.next_u64() % n.max(1)
}

/// Grey image of iteration `v`: every pixel `v % 256`, comment `v=<v>`.
pub fn image_for(v: u64) -> ImgFile {
    let (w, h) = SIZE;
    let img = GreyImage::filled(w, h, (v % 256) as u8).unwrap_or_default();
    ImgFile::new(img).with_comment(format!("v={v}"))
}

/// `n` parallel lines, all of length `n + 10`.
pub fn lines_for(n: usize) -> Vec<Segment> {
    (0..n)
        .map(|i| {
            let y = i as f64 + 0.5;
            Segment::new(Point::new(1.0, y), Point::new(11.0 + n as f64, y))
        })
        .collect()
}

/// `n` edge points, all at x = n.
pub fn edges_for(n: usize, dir: ScanDir) -> EdgePoints {
    EdgePoints {
        dir: Some(dir),
        width: SIZE.0,
        height: SIZE.1,
        points: (0..n)
            .map(|i| EdgePoint {
                x: n as f32,
                y: (i % SIZE.1) as f32,
                response: 10.0,
            })
            .collect(),
    }
}

/// Whether a grey image is one [`image_for`] wrote, whole.
pub fn consistent_image(f: &ImgFile) -> bool {
    let Some(v) = f
        .comment
        .strip_prefix("v=")
        .and_then(|v| v.parse::<u64>().ok())
    else {
        return false;
    };
    f.image.size() == SIZE && f.image.data().iter().all(|&p| u64::from(p) == v % 256)
}

/// Whether lines are one [`lines_for`] set, whole.
pub fn consistent_lines(l: &[Segment]) -> bool {
    lines_for(l.len())
        .iter()
        .zip(l)
        .all(|(a, b)| (a.a.dist(b.a) < 1e-3) && (a.b.dist(b.b) < 1e-3))
}

/// Whether edge points are one [`edges_for`] set, whole.
pub fn consistent_edges(e: &EdgePoints) -> bool {
    let n = e.points.len();
    e.points.iter().all(|p| p.x == n as f32)
}

/// Saves in a loop until killed (or after `limit` saves, so a forgotten
/// child cannot run forever). `progress(n)` is called with 0 once the session
/// is open, then after every completed save.
pub fn run(
    dir: &Path,
    seed: u64,
    limit: u64,
    progress: &mut dyn FnMut(u64),
) -> Result<(), SessionError> {
    let mut rng = SplitMix64::new(seed);
    let mut s = Session::open_take_over(dir)?;
    let letters = s.letters();
    let images = s.manifest().session.planned_images.max(1);
    progress(0);
    for i in 1..=limit {
        let k = 1 + below(&mut rng, u64::from(images)) as u32;
        match below(&mut rng, 10) {
            0..=3 => {
                let letter = letters
                    .get(below(&mut rng, letters.len() as u64) as usize)
                    .copied()
                    .unwrap_or('a');
                s.save_image(k, letter, &image_for(rng.next_u64()))?;
            }
            4..=6 => {
                let n = 1 + below(&mut rng, 400) as usize;
                let eh = edges_for(n, ScanDir::Horizontal);
                let ev = edges_for(n + 1, ScanDir::Vertical);
                let raw = lines_for(1 + below(&mut rng, 60) as usize);
                let lines = lines_for(1 + below(&mut rng, 30) as usize);
                let set = OutputSet {
                    edges_h: Some(&eh),
                    edges_v: Some(&ev),
                    lines_raw: Some(&raw),
                    lines: Some(&lines),
                    ..Default::default()
                };
                s.save_output_set(k, &set, &Params::default())?;
            }
            7 | 8 => {
                let n = 1 + below(&mut rng, 30) as usize;
                s.record_edit(k, &format!("delete {n}"), &lines_for(n))?;
            }
            _ => {
                // Close and reopen: the lock is released and taken again.
                drop(s);
                s = Session::open(dir)?;
            }
        }
        progress(i);
    }
    Ok(())
}
