//! The drawing front end's place in a run (`lines.draw`, `lines/draw.rs`):
//! after both scan directions' edges, in place of their trackers.

use std::time::Instant;

use super::{Workspace, micros};
use crate::lines::draw::{DrawDir, draw_into};
use crate::params::Params;

impl Workspace {
    /// Draws the raw lines from both responses (their trackers did not
    /// run), adding its time to the lines stage's.
    pub(super) fn draw_lines(&mut self, p: &Params) {
        let t = Instant::now();
        let o = &mut self.out;
        let h = DrawDir {
            resp: &o.response_h,
            noise: &o.noise_h,
            starts: &self.dir_h.starts,
        };
        let v = DrawDir {
            resp: &o.response_v,
            noise: &o.noise_v,
            starts: &self.dir_v.starts,
        };
        let a = p.edges.half_width as usize;
        let (floor, lines) = (p.edges.floor, &p.lines);
        let shape = (a, self.noisy);
        draw_into(h, v, floor, shape, lines, &mut o.lines_raw, &mut self.draw);
        o.timings.lines_us += micros(t);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Input, Stage, Workspace};
    use crate::GreyImage;
    use crate::lines::draw::tests::square;
    use crate::params::Params;

    /// A drawn run makes no peak map, and leaves none that a tracker
    /// could take for its image's: the trackers rerun on its edges give
    /// what a full tracked run does, after a tracked run of another image
    /// of the same size.
    #[test]
    fn a_tracker_after_a_drawn_run_makes_its_own_peak_map() {
        let a = square(96, 80);
        let shifted = (0..96 * 80).map(|i| a.data()[i - i % 96 + (i % 96 + 11) % 96]);
        let b = GreyImage::new(96, 80, shifted.collect()).unwrap();
        let tracked = Params::default();
        let mut drawn = tracked.clone();
        drawn.lines.draw = true;
        let mut ws = Workspace::new();
        ws.run(&Input::single(&a), &tracked).unwrap();
        let drawn_edges_us = ws.run(&Input::single(&b), &drawn).unwrap().timings.edges_us;
        let again = ws
            .rerun(Stage::Lines, &Input::single(&b), &tracked)
            .unwrap();
        let full = Workspace::new()
            .run(&Input::single(&b), &tracked)
            .unwrap()
            .clone();
        // The edges were not run again: they keep the drawn run's time.
        assert_eq!(again.timings.edges_us, drawn_edges_us);
        assert_eq!(again.lines_raw, full.lines_raw);
        assert_eq!(full.lines_raw.len(), 4, "{:#?}", full.lines_raw);
    }
}
