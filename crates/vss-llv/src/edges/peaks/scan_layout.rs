//! The tracker's working copy of a [`PeakMap`] in scan layout: a scan
//! line is a row, so a search window is one word along either scan.

use super::PeakMap;
use crate::ScanDir;

impl PeakMap {
    /// Copies `o` into `self` in scan layout, reusing the buffers: a scan
    /// line is a row, so a search window is a word. A vertical scan's map
    /// is transposed: the copy is then that of the transposed response
    /// scanned horizontally, and takes the same scan coordinates `(u, v)`.
    pub(crate) fn scan_copy_from(&mut self, o: &PeakMap) {
        if o.dir != Some(ScanDir::Vertical) {
            self.copy_from(o);
            return;
        }
        let (w, h) = (o.width, o.height);
        self.width = h;
        self.height = w;
        self.dir = Some(ScanDir::Horizontal);
        self.floor = o.floor;
        self.sigmas = o.sigmas;
        self.wpr = h.div_ceil(64);
        let wpr = self.wpr;
        for (dst, src) in [(&mut self.pos, &o.pos), (&mut self.neg, &o.neg)] {
            dst.clear();
            dst.resize(wpr * w, 0);
            if o.wpr == 0 {
                continue;
            }
            // Bit `x` of image row `y` is bit `y` of row `x`.
            for (y, row) in src.chunks_exact(o.wpr).enumerate().take(h) {
                let (at, bit) = (y / 64, 1u64 << (y % 64));
                for (k, &word) in row.iter().enumerate() {
                    let mut m = word;
                    while m != 0 {
                        let x = k * 64 + m.trailing_zeros() as usize;
                        m &= m - 1;
                        if let Some(d) = dst.get_mut(x * wpr + at) {
                            *d |= bit;
                        }
                    }
                }
            }
        }
    }
}
