//! The undistortion map ([`LensMap`]), laid out for fast resampling.
//!
//! Lens distortion is smooth: along a row of the corrected image the source
//! of consecutive pixels usually moves by exactly one pixel, on the same
//! source row, for tens to hundreds of pixels. The map therefore stores
//! *runs* (output span → first source index, the k-th pixel's source being
//! `src + k`) plus one byte per pixel for each interpolation fraction. The
//! resampler then reads contiguous slices of two source rows and the weight
//! planes, a loop the compiler vectorises, instead of gathering four pixels
//! through a per-pixel index (8 bytes of map per pixel before, 2 now).
//!
//! A fraction can round to a whole pixel (256/256) when the source lies
//! within 1/512 px below the next pixel column or row (about 2 % of the
//! pixels of a typical camera: wherever the distortion is a hair negative).
//! Such a pixel samples the same value from the next column (row) with
//! fraction 0, so the runs do that and `shifted` keeps the exact entry for
//! the validity, which depends on the true 2 × 2 neighbourhood. Only at the
//! last column or row is there no next one to use: those few pixels are
//! recomputed afterwards from `fixups`, so the bulk loop needs no branch.

/// Fixed-point steps per pixel of the interpolation weights.
pub(super) const FRAC: u32 = 256;

/// `Run::src` of a run whose source lies outside the image.
pub(super) const OUTSIDE: usize = usize::MAX;

/// Consecutive output pixels of one row whose top-left source pixels are
/// consecutive too (or which are all outside the image).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Run {
    /// Output index (`y * width + x`) of the first pixel.
    pub start: usize,
    pub len: usize,
    /// Source index of the first pixel's top-left neighbour, or [`OUTSIDE`].
    /// For every `k < len`, source pixel `src + k` lies at most in the
    /// last-but-one column and row, so `src + k + 1 + width` is inside.
    pub src: usize,
}

/// The exact entry of a pixel whose fraction is a whole pixel (256): in
/// `fixups` its bytes in the fraction planes are placeholders and its run
/// may imply another (in-bounds) source; in `shifted` its run samples the
/// next column (row) with fraction 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Fixup {
    pub out: usize,
    pub src: usize,
    pub fx: u16,
    pub fy: u16,
}

/// Where each pixel of the corrected image was observed, ready for bilinear
/// sampling: for output pixel `i = y * width + x`, the top-left source pixel
/// of its 2 × 2 neighbourhood (or "outside the image") and the offsets from
/// it in 1/256 px. An identity map (no distortion) holds no arrays at all and
/// correction costs nothing.
///
/// Fixed-point weights keep the per-pixel work to integer multiply-adds (the
/// 1/256 px quantisation is far below the edge detector's accuracy). See the
/// module documentation for the layout (about 2 bytes per pixel).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LensMap {
    pub(super) width: usize,
    pub(super) height: usize,
    /// Every output pixel in order, split into runs; the runs of row `y` are
    /// `runs[row_runs[y]..row_runs[y + 1]]`.
    pub(super) runs: Vec<Run>,
    pub(super) row_runs: Vec<usize>,
    /// Per output pixel, the offsets from the top-left source pixel in
    /// 1/256 px (0 outside and for fixups).
    pub(super) fx: Vec<u8>,
    pub(super) fy: Vec<u8>,
    /// Pixels with an offset of 256/256 that the runs cannot sample (at
    /// the last column or row), sorted by output index.
    pub(super) fixups: Vec<Fixup>,
    /// Pixels with an offset of 256/256 that the runs sample from the next
    /// column (row) with offset 0: the same value, but a different 2 × 2
    /// neighbourhood for the validity. Sorted by output index.
    pub(super) shifted: Vec<Fixup>,
    /// Whether some pixel's source lies outside the image.
    pub(super) any_outside: bool,
}

impl LensMap {
    /// The map of camera `m` for images of `width × height` pixels.
    pub fn new(m: &super::CameraModel, width: usize, height: usize) -> LensMap {
        if m.is_identity() {
            return LensMap::identity(width, height);
        }
        // A pixel the lens cannot have observed is outside (invalid).
        LensMap::from_sources(width, height, |x, y| {
            m.ideal_to_observed_checked(x as f64, y as f64)
                .unwrap_or((f64::NAN, f64::NAN))
        })
    }

    /// A map from any source function `(x, y) → (xs, ys)`.
    pub fn from_sources(
        width: usize,
        height: usize,
        source: impl Fn(usize, usize) -> (f64, f64),
    ) -> LensMap {
        let n = width.saturating_mul(height);
        if n == 0 {
            return LensMap::identity(width, height);
        }
        let mut map = LensMap {
            width,
            height,
            runs: Vec::new(),
            row_runs: Vec::with_capacity(height + 1),
            fx: Vec::with_capacity(n),
            fy: Vec::with_capacity(n),
            fixups: Vec::new(),
            shifted: Vec::new(),
            any_outside: false,
        };
        let (xmax, ymax) = (
            width.saturating_sub(1) as f64,
            height.saturating_sub(1) as f64,
        );
        let too_big = width < 2 || height < 2 || n >= u32::MAX as usize;
        for y in 0..height {
            map.row_runs.push(map.runs.len());
            // The open run of this row: `None` for none or an outside run,
            // else its source row and column offset `x0 - x`.
            let mut key: Option<(usize, isize)> = None;
            for x in 0..width {
                let o = y * width + x;
                let (xs, ys) = source(x, y);
                // Inside the hull of the pixel centres, with a sliver of
                // tolerance for rounding at the exact border.
                let inside = xs >= -1e-3 && ys >= -1e-3 && xs <= xmax + 1e-3 && ys <= ymax + 1e-3;
                if !inside || too_big {
                    map.fx.push(0);
                    map.fy.push(0);
                    map.any_outside = true;
                    match map.runs.last_mut() {
                        Some(r) if r.src == OUTSIDE && r.start + r.len == o && x > 0 => r.len += 1,
                        _ => map.runs.push(Run {
                            start: o,
                            len: 1,
                            src: OUTSIDE,
                        }),
                    }
                    key = None;
                    continue;
                }
                let (xc, yc) = (xs.clamp(0.0, xmax), ys.clamp(0.0, ymax));
                let x0 = (xc as usize).min(width - 2);
                let y0 = (yc as usize).min(height - 2);
                let fx = ((xc - x0 as f64) * FRAC as f64).round() as u16;
                let fy = ((yc - y0 as f64) * FRAC as f64).round() as u16;
                let exact = Fixup {
                    out: o,
                    src: y0 * width + x0,
                    fx,
                    fy,
                };
                // A whole-pixel fraction samples the next column (row) with
                // weight 256, which is the same value as sampling from that
                // column with fraction 0 (only the 2 × 2 neighbourhood, and
                // so the validity, differs).
                let whole = FRAC as u16;
                let (x0, fx) = match fx == whole && x0 + 2 < width {
                    true => (x0 + 1, 0),
                    false => (x0, fx),
                };
                let (y0, fy) = match fy == whole && y0 + 2 < height {
                    true => (y0 + 1, 0),
                    false => (y0, fy),
                };
                let fits = fx < whole && fy < whole;
                map.fx.push(if fits { fx as u8 } else { 0 });
                map.fy.push(if fits { fy as u8 } else { 0 });
                if !fits {
                    map.fixups.push(exact);
                } else if y0 * width + x0 != exact.src {
                    map.shifted.push(exact);
                }
                let mine = (y0, x0 as isize - x as isize);
                // A fixup pixel takes whatever source its run implies, as
                // long as that keeps the 2 × 2 reads inside the image.
                let joins = key.is_some_and(|k| {
                    let x0k = x as isize + k.1;
                    if fits {
                        k == mine
                    } else {
                        x0k >= 0 && x0k <= width as isize - 2
                    }
                });
                match map.runs.last_mut() {
                    Some(r) if joins => r.len += 1,
                    _ => {
                        map.runs.push(Run {
                            start: o,
                            len: 1,
                            src: y0 * width + x0,
                        });
                        key = Some(mine);
                    }
                }
            }
        }
        map.row_runs.push(map.runs.len());
        map
    }

    /// The identity map of a size (what a `.cdf` without distortion gives).
    pub fn identity(width: usize, height: usize) -> LensMap {
        LensMap {
            width,
            height,
            ..LensMap::default()
        }
    }

    /// True when correction changes nothing (and the pipeline skips it).
    pub fn is_identity(&self) -> bool {
        self.runs.is_empty()
    }

    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The observed position of output pixel `(x, y)` (to 1/256 px);
    /// `None` outside the image or where the source is outside.
    pub fn source(&self, x: usize, y: usize) -> Option<(f32, f32)> {
        if x >= self.width || y >= self.height {
            return None;
        }
        if self.is_identity() {
            return Some((x as f32, y as f32));
        }
        let o = y * self.width + x;
        fn find(list: &[Fixup], o: usize) -> Option<&Fixup> {
            list.get(list.binary_search_by_key(&o, |f| f.out).ok()?)
        }
        let (i, fx, fy) = match find(&self.fixups, o).or_else(|| find(&self.shifted, o)) {
            Some(f) => (f.src, f.fx, f.fy),
            None => {
                let row = self
                    .runs
                    .get(*self.row_runs.get(y)?..*self.row_runs.get(y + 1)?)?;
                let r = row.get(row.partition_point(|r| r.start + r.len <= o))?;
                if r.src == OUTSIDE {
                    return None;
                }
                let fx = *self.fx.get(o)?;
                let fy = *self.fy.get(o)?;
                (r.src + (o - r.start), fx as u16, fy as u16)
            }
        };
        let (x0, y0) = (i % self.width, i / self.width);
        Some((
            x0 as f32 + fx as f32 / FRAC as f32,
            y0 as f32 + fy as f32 / FRAC as f32,
        ))
    }
}
