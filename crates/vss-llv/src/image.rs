//! `GreyImage`: 8-bit grey pixels, row by row from the top, with an optional
//! validity mask (pixels that lens correction could not fill).

use super::LlvError;

/// The smallest image the stages accept (llv.md §0).
pub const MIN_SIZE: usize = 16;

/// The most pixels the stages accept: 2²⁶, 8192 × 8192. The cell's cameras
/// give 512 × 512; the stages' buffers take several bytes a pixel for one
/// image, more with a lens map or several lightings (docs/reliability.md,
/// "Peak memory at the bounds", has `vss llv`'s). A small file that decodes
/// to a huge image (a compressed PNG, a sparse `.img`) is refused up front
/// rather than exhausting memory half-way.
pub const MAX_PIXELS: usize = 1 << 26;

/// An 8-bit grey image. `data[y * width + x]` is `Img(x, y)`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GreyImage {
    width: usize,
    height: usize,
    data: Vec<u8>,
    /// `Some(mask)` where some pixels are invalid: `mask[i]` is true for a
    /// valid pixel. `None` means every pixel is valid.
    valid: Option<Vec<bool>>,
}

/// [`GreyImage::check_stage_size`] of an image of `width` × `height`
/// pixels, before it is read or a lens map is made for it.
pub fn check_stage_size(width: usize, height: usize) -> Result<(), LlvError> {
    if width < MIN_SIZE || height < MIN_SIZE {
        return Err(LlvError::TooSmall {
            width,
            height,
            min: MIN_SIZE,
        });
    }
    if width.saturating_mul(height) > MAX_PIXELS {
        return Err(LlvError::TooLarge {
            width,
            height,
            max: MAX_PIXELS,
        });
    }
    Ok(())
}

impl GreyImage {
    /// Wraps a pixel buffer; the buffer must hold exactly `width * height`
    /// bytes and neither side may be zero.
    pub fn new(width: usize, height: usize, data: Vec<u8>) -> Result<Self, LlvError> {
        let expected = width.saturating_mul(height);
        if width == 0 || height == 0 || data.len() != expected {
            return Err(LlvError::BufferSize {
                width,
                height,
                expected,
                actual: data.len(),
            });
        }
        Ok(GreyImage {
            width,
            height,
            data,
            valid: None,
        })
    }

    /// A `width × height` image filled with `value`.
    pub fn filled(width: usize, height: usize, value: u8) -> Result<Self, LlvError> {
        Self::new(width, height, vec![value; width.saturating_mul(height)])
    }

    /// Checks the size the LLV stages need (≥ 16 × 16, at most
    /// [`MAX_PIXELS`]).
    pub fn check_stage_size(&self) -> Result<(), LlvError> {
        check_stage_size(self.width, self.height)
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
    pub fn data(&self) -> &[u8] {
        &self.data
    }
    pub fn data_mut(&mut self) -> &mut [u8] {
        &mut self.data
    }
    pub fn into_data(self) -> Vec<u8> {
        self.data
    }
    /// `Img(x, y)`; `None` outside the image.
    pub fn get(&self, x: usize, y: usize) -> Option<u8> {
        (x < self.width && y < self.height).then(|| self.data[y * self.width + x])
    }
    /// One row of pixels.
    pub fn row(&self, y: usize) -> &[u8] {
        &self.data[y * self.width..(y + 1) * self.width]
    }
    /// The validity mask, if any pixel is invalid.
    pub fn valid_mask(&self) -> Option<&[bool]> {
        self.valid.as_deref()
    }
    /// Removes and returns the validity mask (every pixel is then valid),
    /// so a buffer can be reused without allocating.
    pub fn take_valid_mask(&mut self) -> Option<Vec<bool>> {
        self.valid.take()
    }
    /// Whether pixel `(x, y)` holds real data (false outside the image).
    pub fn is_valid(&self, x: usize, y: usize) -> bool {
        x < self.width
            && y < self.height
            && self.valid.as_ref().is_none_or(|m| m[y * self.width + x])
    }
    /// Sets the validity mask; `None` or a mask of the wrong length clears it
    /// only when every entry is true.
    pub fn set_valid_mask(&mut self, mask: Option<Vec<bool>>) -> Result<(), LlvError> {
        match mask {
            Some(m) if m.len() != self.data.len() => Err(LlvError::BufferSize {
                width: self.width,
                height: self.height,
                expected: self.data.len(),
                actual: m.len(),
            }),
            Some(m) if m.iter().all(|&v| v) => {
                self.valid = None;
                Ok(())
            }
            other => {
                self.valid = other;
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_mismatched_and_empty_buffers() {
        assert!(GreyImage::new(0, 0, vec![]).is_err());
        assert!(GreyImage::new(4, 4, vec![0; 15]).is_err());
        assert!(GreyImage::new(usize::MAX, 2, vec![]).is_err());
        let img = GreyImage::new(4, 2, (0..8).collect()).unwrap();
        assert_eq!(img.get(3, 1), Some(7));
        assert_eq!(img.get(4, 1), None);
        assert!(img.check_stage_size().is_err());
        // The largest size, one pixel more, and a product that overflows.
        assert!(check_stage_size(8192, 8192).is_ok());
        assert!(matches!(
            check_stage_size(8193, 8192),
            Err(LlvError::TooLarge { .. })
        ));
        assert!(check_stage_size(1 << 40, 1 << 40).is_err());
        assert!(check_stage_size(usize::MAX, 16).is_err());
    }
}
