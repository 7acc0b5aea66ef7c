//! The response of one image without holding it whole, for runs that do
//! not keep it (`Workspace::lean`, `vss llv`): a strip of rows at a time
//! ([`Strips`], for the noise estimate and the peak pass) and a sum at a
//! pixel ([`PixelSums`], for the edge points and the tracks, which read it
//! only at peaks). Both compute exactly what [`super::response_into`]
//! stores, so the results are the same; an 8192² image then needs its
//! pixels and a strip instead of 128 MiB of sums (docs/reliability.md).

use super::{LlvError, MaskBufs, NONE, checked_input, mask_invalid, row, rows_into};
use crate::{GreyImage, ScanDir};

/// Rows of a response, read a range at a time.
pub(crate) trait Rows {
    /// Makes rows `y0..y1` readable (the previous ones may go).
    fn load(&mut self, y0: usize, y1: usize);
    /// From the start of loaded row `y` to the end of the loaded rows.
    fn row(&self, y: usize) -> &[i16];
}

/// A whole response's sums, `w` a row.
pub(crate) struct Whole<'a>(pub &'a [i16], pub usize);

impl Rows for Whole<'_> {
    fn load(&mut self, _: usize, _: usize) {}

    #[inline]
    fn row(&self, y: usize) -> &[i16] {
        self.0.get(y * self.1..).unwrap_or(&[])
    }
}

/// The response of one image along one direction, computed where it is
/// read.
#[derive(Clone, Copy, Debug)]
pub struct PixelSums<'a> {
    px: &'a [u8],
    mask: Option<&'a [bool]>,
    pub(crate) w: usize,
    pub(crate) h: usize,
    pub(crate) dir: ScanDir,
    a: usize,
    shift: u32,
}

impl<'a> PixelSums<'a> {
    /// The response of `img` along `dir` with half-width `a` (3–7): the
    /// errors of [`super::response_into`].
    pub fn new(img: &'a GreyImage, dir: ScanDir, a: usize) -> Result<Self, LlvError> {
        let (w, h, px) = checked_input(img, a)?;
        Ok(PixelSums {
            px,
            mask: img.valid_mask(),
            w,
            h,
            dir,
            a,
            shift: row::shift(a, 1),
        })
    }

    /// Grey levels of one unit.
    pub fn scale(&self) -> f32 {
        row::scale(self.a) * (1u32 << self.shift) as f32
    }

    /// The sum at image index `i` ([`NONE`] where the response has none).
    #[inline]
    pub fn at(&self, i: usize) -> i16 {
        let (w, a) = (self.w, self.a);
        let (x, y) = (i % w.max(1), i / w.max(1));
        let (step, inside) = match self.dir {
            ScanDir::Horizontal => (1, x >= a && x + a < w),
            ScanDir::Vertical => (w, y >= a && y + a < self.h),
        };
        if !inside || i >= self.px.len() {
            return NONE;
        }
        let lo = i - a * step;
        if let Some(m) = self.mask
            && (0..=2 * a).any(|k| !m.get(lo + k * step).copied().unwrap_or(false))
        {
            return NONE;
        }
        let px = |j: usize| i32::from(self.px[j]);
        let sum: i32 = (1..a)
            .map(|s| row::coef(a, s) * (px(i + s * step) - px(i - s * step)))
            .sum();
        row::narrow_one(sum, self.shift)
    }
}

/// A [`PixelSums`]' rows, computed a range at a time into one buffer.
pub(crate) struct Strips<'a> {
    src: PixelSums<'a>,
    /// The first row held.
    y0: usize,
    buf: Vec<i16>,
    wide: Vec<i32>,
    mask: MaskBufs,
}

impl<'a> Strips<'a> {
    pub fn new(src: PixelSums<'a>) -> Self {
        Strips {
            src,
            y0: 0,
            buf: Vec::new(),
            wide: Vec::new(),
            mask: MaskBufs::default(),
        }
    }
}

impl Rows for Strips<'_> {
    fn load(&mut self, y0: usize, y1: usize) {
        let PixelSums {
            px,
            mask,
            w,
            h,
            dir,
            a,
            shift,
        } = self.src;
        let y1 = y1.min(h);
        let y0 = y0.min(y1);
        self.y0 = y0;
        // With a mask, the rows under a vertical window's reach too.
        let (e0, e1) = match (mask, dir) {
            (Some(_), ScanDir::Vertical) => (y0.saturating_sub(a), (y1 + a).min(h)),
            _ => (y0, y1),
        };
        self.buf.clear();
        self.buf.resize((e1 - e0) * w, NONE);
        rows_into(px, w, h, dir, a, shift, e0, &mut self.buf, &mut self.wide);
        if let Some(m) = mask {
            let rows = e1 - e0;
            mask_invalid(
                m.get(e0 * w..e1 * w).unwrap_or(&[]),
                w,
                rows,
                dir,
                a,
                &mut self.buf,
                &mut self.mask,
            );
            self.buf.drain(..(y0 - e0) * w);
            self.buf.truncate((y1 - y0) * w);
        }
    }

    #[inline]
    fn row(&self, y: usize) -> &[i16] {
        let w = self.src.w;
        self.buf.get(y.saturating_sub(self.y0) * w..).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::random_image;
    use super::*;
    use crate::edges::{ResponseScratch, response_into};
    use crate::rng::SplitMix64;

    /// Every sum a pixel at a time, and every strip (at the image's ends
    /// too), equals the whole response's, for each half-width, direction,
    /// and with and without a validity mask.
    #[test]
    fn pixels_and_strips_equal_the_whole_response() {
        let mut rng = SplitMix64::new(34);
        for (w, h, masked) in [
            (40, 37, false),
            (53, 70, true),
            (16, 16, true),
            (90, 20, true),
        ] {
            let img = random_image(&mut rng, w, h, masked);
            for a in 3..=7 {
                for dir in [ScanDir::Horizontal, ScanDir::Vertical] {
                    let mut r = crate::edges::Response::default();
                    response_into(&img, dir, a, &mut r, &mut ResponseScratch::default()).unwrap();
                    let src = PixelSums::new(&img, dir, a).unwrap();
                    assert_eq!(src.scale(), r.scale(), "{w}x{h} A {a} {dir:?}");
                    for (i, &want) in r.sums().iter().enumerate() {
                        assert_eq!(src.at(i), want, "{w}x{h} A {a} {dir:?} pixel {i}");
                    }
                    let mut strips = Strips::new(src);
                    for (y0, y1) in [(0, h), (0, 3), (5, 12), (h - 4, h), (h - 1, h + 5)] {
                        strips.load(y0, y1);
                        for y in y0..y1.min(h) {
                            assert_eq!(
                                &strips.row(y)[..w],
                                &r.sums()[y * w..(y + 1) * w],
                                "{w}x{h} A {a} {dir:?} strip {y0}..{y1} row {y}"
                            );
                        }
                    }
                }
            }
        }
        let mut bad = random_image(&mut rng, 20, 20, false);
        assert!(PixelSums::new(&bad, ScanDir::Vertical, 8).is_err());
        bad.set_valid_mask(Some(vec![false; 400])).unwrap();
        let src = PixelSums::new(&bad, ScanDir::Vertical, 4).unwrap();
        assert!((0..400).all(|i| src.at(i) == NONE) && src.at(400) == NONE);
    }
}
