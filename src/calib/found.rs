//! What grid detection gives for one view, and why it gives none: shared by
//! the squares plate's finder (`detect`) and the checkerboard's (`saddle`),
//! so that neither needs the other's module.

use super::plate::PlateCorner;

/// Edges wider than this (px, 10–90 % of the step) make a blurred board.
pub const MAX_EDGE_WIDTH: f64 = 6.0;

/// Why a view gave no grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DetectError {
    #[error(
        "the plate is not in view (found {quads} square outlines, the plate has {expected}): hold the whole plate in front of the camera, sharp and evenly lit"
    )]
    NotFound { quads: usize, expected: usize },
    #[error(
        "found {found} of the plate's {expected} squares in a grid of {columns} × {rows}: the whole plate must be in view, sharp and evenly lit"
    )]
    WrongCount {
        found: usize,
        expected: usize,
        columns: usize,
        rows: usize,
    },
    #[error(
        "no checkerboard of {columns} × {rows} inner corners found ({saddles} corner-like points, none in a grid of alternating squares): hold the whole board in front of the camera, sharp and evenly lit"
    )]
    NoGrid {
        saddles: usize,
        columns: usize,
        rows: usize,
    },
    #[error(
        "a grid of {columns} × {rows} inner corners; the plate file says {want_columns} × {want_rows} (a checkerboard of {} × {} squares): check the plate file's `columns` and `rows` (squares, one more than inner corners), or whether part of the board is hidden",
        want_columns + 1, want_rows + 1
    )]
    GridSize {
        columns: usize,
        rows: usize,
        want_columns: usize,
        want_rows: usize,
    },
    #[error(
        "the board is partly out of the frame: a grid of {columns} × {rows} inner corners reaches the image's edge, the plate has {want_columns} × {want_rows}: move the board (or the camera) so that the whole board is in view"
    )]
    PartlyOut {
        columns: usize,
        rows: usize,
        want_columns: usize,
        want_rows: usize,
    },
    #[error(
        "two boards in view (grids of {} × {} and {} × {} inner corners): show one board at a time",
        first.0, first.1, second.0, second.1
    )]
    TwoBoards {
        first: (usize, usize),
        second: (usize, usize),
    },
    #[error(
        "the board is in view ({corners} inner corners) but blurred: its edges are {:.1} px wide (at most {} px gives sharp corners): focus, hold the board still, or give more light for a shorter exposure",
        // Rounded up: 6.04 px is refused, so it must not read "6.0 px".
        (width * 10.0).ceil() / 10.0,
        MAX_EDGE_WIDTH
    )]
    Blurred { width: f64, corners: usize },
    #[error("the image cannot be processed: {0}")]
    Image(#[from] crate::llv::LlvError),
}

/// One corner found in an image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    pub corner: PlateCorner,
    /// Observed position (px).
    pub px: [f64; 2],
}

/// The grid found in one view.
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    /// Every corner of [`Plate::corners`](super::plate::Plate::corners), in that order.
    pub corners: Vec<Corner>,
    /// The plate's cells as found (image corners), for drawing.
    pub cells: Vec<[[f64; 2]; 4]>,
    /// Whether the origin corner was told apart (else one of the plate's
    /// symmetric turns was taken).
    pub oriented: bool,
    /// Segments the pipeline gave.
    pub segments: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_board_refused_as_blurred_never_reads_as_sharp_enough() {
        let e = DetectError::Blurred {
            width: 6.04,
            corners: 48,
        }
        .to_string();
        assert!(e.contains("6.1 px wide (at most 6 px"), "{e}");
    }
}
