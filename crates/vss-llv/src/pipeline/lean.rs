//! A scan direction of one image in a lean run (`Workspace::lean`, `vss
//! llv`) without its response held whole: made a strip of rows at a time
//! for the edge pass and read at the peaks for the tracks
//! (`edges/band.rs`). The same results, in a fraction of the memory on
//! images of pure texture (docs/reliability.md has the figures).

use std::time::Instant;

use super::{DirOut, DirScratch, Job, micros};
use crate::edges::Response;
use crate::edges::peaks::strips::detect_strips;
use crate::lines::track_pixels;
use crate::{GreyImage, LlvError, ScanDir};

impl Job<'_> {
    /// [`Job::run`] of one image, from the edges on, without the response:
    /// the microseconds of its edge stage and of its line extraction.
    pub(super) fn run_lean(&self, img: &GreyImage, o: DirOut) -> Result<(u64, u64), LlvError> {
        let p = self.params;
        let a = p.edges.half_width as usize;
        let t = Instant::now();
        *o.response = Response::default();
        let sums = detect_strips(
            img,
            o.dir,
            a,
            &p.edges,
            p.lines.track_sigmas,
            o.noise,
            &mut o.s.map,
            o.edges,
            &mut o.s.starts,
            &mut o.s.peaks,
        )?;
        self.check_edge_count(&o)?;
        let edges_us = micros(t);
        let t = Instant::now();
        track_pixels(
            sums,
            o.noise,
            std::mem::take(&mut o.s.map),
            o.edges,
            &mut o.s.starts,
            a,
            &p.lines,
            &mut o.s.segs,
            &mut o.s.lines,
        );
        let segs = std::mem::take(&mut o.s.segs);
        (*o.s, o.s.segs) = (DirScratch::default(), segs);
        Ok((edges_us, micros(t)))
    }
}

impl Job<'_> {
    /// [`Workspace::limit_edge_points`] on a direction's edge points.
    pub(super) fn check_edge_count(&self, o: &DirOut) -> Result<(), LlvError> {
        match self.edge_limit {
            Some(max) if o.edges.points.len() > max => Err(LlvError::TooManyEdgePoints {
                dir: match o.dir {
                    ScanDir::Horizontal => "horizontal",
                    ScanDir::Vertical => "vertical",
                },
                points: o.edges.points.len(),
                max,
            }),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Input, Workspace};
    use crate::lens::{CameraModel, LensMap};
    use crate::params::Params;
    use crate::rng::SplitMix64;
    use crate::{GreyImage, LlvError};

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> u8) -> GreyImage {
        let d = (0..w * h).map(|i| f(i % w, i / w)).collect();
        GreyImage::new(w, h, d).unwrap()
    }

    /// A lean run gives what a full one does (edge points, noise maps,
    /// lines), without a response: on pure texture, a pattern of edges
    /// everywhere, a noisy scene (a wider kernel), with lens correction (a
    /// validity mask), and at every half-width.
    #[test]
    fn a_lean_run_equals_a_full_run() {
        let mut rng = SplitMix64::new(7);
        let random: Vec<u8> = (0..300 * 200).map(|_| rng.next_u64() as u8).collect();
        let texture = GreyImage::new(300, 200, random).unwrap();
        let pattern = image(257, 190, |x, y| ((y * 257 + x) % 251) as u8);
        let scene = image(240, 180, |x, y| {
            let n = (SplitMix64::new((y * 240 + x) as u64).next_u64() % 13) as i32 - 6;
            let inside = x > 60 && x < 170 && y + x / 3 > 50 && y < 140;
            ((if inside { 170 } else { 60 }) + n) as u8
        });
        let model = CameraModel {
            cx: 120.0,
            cy: 90.0,
            sx: 0.01,
            sy: 0.01,
            f: 8.0,
            distortion: Some([-0.02, 0.0, 0.0, 0.0, 0.0]),
            radial: [0.0; 2],
        };
        let map = LensMap::new(&model, 240, 180);
        let mut lines = 0;
        for (name, img, lens) in [
            ("texture", &texture, None),
            ("pattern", &pattern, None),
            ("scene", &scene, None),
            ("lens", &scene, Some(&map)),
        ] {
            // (A 0: the default, widened where the image is noisy; 1: at
            // most 5 edge points in every 3 scan lines, ties kept.)
            for a in [0, 1, 3, 4, 5, 6, 7] {
                let mut p = Params::default();
                if a == 1 {
                    p.edges.per_region = 5;
                    p.edges.region_lines = 3;
                } else if a > 0 {
                    p.edges.half_width = a;
                    p.edges.noisy_sigma = 0.0;
                }
                let input = Input {
                    lens,
                    ..Input::single(img)
                };
                let full = Workspace::new().run(&input, &p).unwrap().clone();
                let mut ws = Workspace::lean();
                let lean = ws.run(&input, &p).unwrap();
                let at = format!("{name}, A {a}");
                assert!(lean.response_h.sums().is_empty(), "{at}");
                assert_eq!(lean.corrected, full.corrected, "{at}");
                assert_eq!(lean.noise_h, full.noise_h, "{at}");
                assert_eq!(lean.noise_v, full.noise_v, "{at}");
                assert_eq!(lean.edges_h, full.edges_h, "{at}");
                assert_eq!(lean.edges_v, full.edges_v, "{at}");
                assert_eq!(lean.lines_raw, full.lines_raw, "{at}");
                assert_eq!(lean.lines, full.lines, "{at}");
                assert!(!full.edges_h.points.is_empty(), "{at}");
                lines += full.lines_raw.len();
            }
        }
        assert!(lines > 20, "{lines}");
        // Its errors are a full run's.
        let mut p = Params::default();
        p.edges.half_width = 9;
        let mut ws = Workspace::lean();
        let err = ws.run(&Input::single(&scene), &p);
        assert!(matches!(err, Err(LlvError::Param { .. })), "{err:?}");
    }
}
