//! PostScript and SVG reports of a survey (spec/formats.md §7): the grey-image
//! page of the original `img2ps`, the line page of `ldr2ps`, and a multi-page
//! survey report per image (grey images, edge images, raw and connected
//! lines, parameters, counts, timings). The writers draw from plain data
//! ([`GreyImage`], [`Segment`], [`EdgePoints`]) straight into an
//! [`std::io::Write`], page by page: a report is streamed into the temporary
//! file of [`crate::fsutil::write_atomic_with`], never built whole in
//! memory, so its cost is one image's pictures, not the length of the
//! document. [`survey`] gathers that data from a session, one image at a
//! time, and is the one writer of a session's report, for the command line
//! and the console alike.

pub mod calibration;
pub mod clip;
pub mod encode;
pub mod ps;
pub mod survey;
pub mod svg;

use crate::formats::edgefile::MAX_SIDE;
use crate::llv::{EdgePoints, GreyImage, Segment};

/// Everything the report shows about one image number of a survey.
#[derive(Clone, Debug, Default)]
pub struct ImageReport {
    /// Heading, e.g. `cube1`.
    pub title: String,
    /// Image size in pixels (the lines' coordinate frame).
    pub width: usize,
    pub height: usize,
    /// Grey images with their captions (file names), one per lighting.
    pub greys: Vec<(String, GreyImage)>,
    pub edges_h: Option<EdgePoints>,
    pub edges_v: Option<EdgePoints>,
    /// Lines as extracted (`.lex`) and after post-processing (`.ldr`).
    pub lines_raw: Option<Vec<Segment>>,
    pub lines: Option<Vec<Segment>>,
    /// Free text lines: parameters used, counts, timings.
    pub notes: Vec<String>,
    /// The notes that say a file cannot be shown (also in `notes`): what
    /// the report's caller must pass on, not only print on the page.
    pub problems: Vec<String>,
}

/// Most pixels an edge image may have: 2^26, e.g. 8192 × 8192, 256 times a
/// 512 × 512 cell picture. An edge image is allocated from a size that a file
/// header or the manifest states, not from pixels read, so the size is
/// checked first; its PostScript is already 128 MiB of hex at this limit.
pub const MAX_PICTURE_PIXELS: usize = 1 << 26;

/// A picture size the report will not allocate an image for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "a picture of {width} x {height} pixels cannot be drawn: the report draws 1 to {MAX_SIDE} \
     pixels a side and at most {MAX_PICTURE_PIXELS} in all"
)]
pub struct PictureSizeError {
    pub width: usize,
    pub height: usize,
}

/// Checks a picture size before an image of that size is allocated: each
/// side 1 to [`MAX_SIDE`] (the `.img` and edge-file limit) and at most
/// [`MAX_PICTURE_PIXELS`] in all.
pub fn check_picture_size(width: usize, height: usize) -> Result<(), PictureSizeError> {
    let side = |v: usize| (1..=MAX_SIDE).contains(&v);
    if side(width) && side(height) && width.saturating_mul(height) <= MAX_PICTURE_PIXELS {
        Ok(())
    } else {
        Err(PictureSizeError { width, height })
    }
}

/// Renders edge points as a grey image the size of the picture: white paper,
/// each point a dark pixel (darker for a stronger response), so the edge
/// image prints with the same `image` operator as a grey image. The size is
/// the edge file's, or `width × height` when the file gives none; it is
/// checked with [`check_picture_size`] before anything is allocated.
pub fn edge_image(
    e: &EdgePoints,
    width: usize,
    height: usize,
) -> Result<GreyImage, PictureSizeError> {
    let (w, h) = edge_image_size(e, width, height)?;
    let mut img = GreyImage::filled(w, h, 255).map_err(|_| PictureSizeError {
        width: w,
        height: h,
    })?;
    let max = e
        .points
        .iter()
        .map(|p| p.response.abs())
        .filter(|r| r.is_finite())
        .fold(0.0f32, f32::max);
    let data = img.data_mut();
    for p in &e.points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let (x, y) = (p.x.round(), p.y.round());
        if x < 0.0 || y < 0.0 || x >= w as f32 || y >= h as f32 {
            continue;
        }
        // Even the weakest kept point must be clearly visible on paper.
        let strength = if max > 0.0 && p.response.is_finite() {
            (p.response.abs() / max).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let v = 160.0 - 160.0 * strength;
        if let Some(px) = data.get_mut(y as usize * w + x as usize) {
            *px = v as u8;
        }
    }
    Ok(img)
}

/// The size [`edge_image`] draws the points of `e` at, checked with
/// [`check_picture_size`]: the edge file's size, or `width × height` when
/// the file gives none. A report plans its pages with it before drawing.
pub fn edge_image_size(
    e: &EdgePoints,
    width: usize,
    height: usize,
) -> Result<(usize, usize), PictureSizeError> {
    let (w, h) = if e.width > 0 && e.height > 0 {
        (e.width, e.height)
    } else {
        (width, height)
    };
    check_picture_size(w, h)?;
    Ok((w, h))
}

/// Text safe for a PostScript string or an XML attribute: the crate's one
/// sanitiser ([`crate::text::sanitize`]) first, then printable ASCII only,
/// the standard fonts' characters (the comment of an `.img` may hold
/// anything).
pub(crate) fn printable(s: &str) -> String {
    crate::text::sanitize(s)
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '?'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::llv::{EdgePoint, ScanDir};

    #[test]
    fn edge_image_marks_points_and_ignores_outsiders() {
        let e = EdgePoints {
            dir: Some(ScanDir::Horizontal),
            width: 20,
            height: 10,
            points: vec![
                EdgePoint {
                    x: 3.2,
                    y: 4.0,
                    response: -40.0,
                },
                EdgePoint {
                    x: 30.0,
                    y: 4.0,
                    response: 10.0,
                },
                EdgePoint {
                    x: f32::NAN,
                    y: 1.0,
                    response: 10.0,
                },
            ],
        };
        let img = edge_image(&e, 0, 0).unwrap();
        assert_eq!(img.size(), (20, 10));
        assert_eq!(img.get(3, 4), Some(0));
        assert_eq!(img.data().iter().filter(|&&v| v < 255).count(), 1);
    }

    #[test]
    fn edge_image_refuses_sizes_it_cannot_allocate() {
        let e = |width, height| EdgePoints {
            width,
            height,
            ..Default::default()
        };
        // From the edge file's header, or the fallback size when it has none.
        for (edges, w, h) in [
            (e(100_000, 100_000), 10, 10),
            (e(usize::MAX, usize::MAX), 10, 10),
            (e(MAX_SIDE, MAX_SIDE), 10, 10),
            (e(0, 0), 4_000_000_000, 4_000_000_000),
            (e(0, 0), 0, 0),
        ] {
            let err = edge_image(&edges, w, h).unwrap_err();
            assert!(err.to_string().contains("cannot be drawn"), "{err}");
        }
        assert_eq!(edge_image(&e(0, 5), 8, 6).unwrap().size(), (8, 6));
        assert!(check_picture_size(8192, 8192).is_ok());
        assert!(check_picture_size(MAX_SIDE, 1024).is_ok());
        assert!(check_picture_size(MAX_SIDE + 1, 1).is_err());
    }

    #[test]
    fn printable_strips_control_and_unicode() {
        assert_eq!(printable("a\u{1b}[2Jb µ"), "a[2Jb ?");
    }
}
