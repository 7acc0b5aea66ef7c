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
