//! The low-level vision core (spec/llv.md, spec/lens.md): pure functions over
//! plain data. No I/O, no terminal, no serial port; never panics on any image
//! size — bad sizes are [`LlvError`]s.
//!
//! ```text
//! grey image(s) ─► lens ─► edges ─► lines ─► connect ─► (edit)
//! ```

pub mod auto;
pub mod connect;
pub mod corners;
pub mod edges;
pub mod edit;
pub mod fit;
pub mod image;
pub mod lens;
pub mod lines;
pub mod params;
pub mod photometric;
pub mod pipeline;
pub mod refine;
pub mod rng;
pub mod shadow;

pub use image::GreyImage;
pub use params::Params;

use serde::{Deserialize, Serialize};

/// Errors of the vision core: only shapes and sizes can be wrong here.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LlvError {
    /// Width × height does not match the pixel buffer, or is zero.
    #[error("image of {width} × {height} pixels needs {expected} bytes, got {actual}")]
    BufferSize {
        width: usize,
        height: usize,
        expected: usize,
        actual: usize,
    },
    /// Below the smallest size the stages support.
    #[error(
        "image of {width} × {height} pixels is too small: the stages need at least {min} × {min}"
    )]
    TooSmall {
        width: usize,
        height: usize,
        min: usize,
    },
    /// Beyond the largest size the stages support.
    #[error(
        "image of {width} × {height} pixels is too large: the stages take at most {max} pixels (8192 × 8192)"
    )]
    TooLarge {
        width: usize,
        height: usize,
        max: usize,
    },
    /// Images that must share a size (lightings of one view, a lens map) do not.
    #[error("image sizes differ: {a:?} and {b:?}")]
    SizeMismatch {
        a: (usize, usize),
        b: (usize, usize),
    },
    /// A scan direction found more edge points than the run was told to
    /// keep ([`pipeline::Workspace::limit_edge_points`]).
    #[error(
        "{points} edge points in the {dir} scan are more than the {max} an edge file holds: \
         the image is texture, not a scene"
    )]
    TooManyEdgePoints {
        dir: &'static str,
        points: usize,
        max: usize,
    },
    /// The camera's distortion folds the image (`CameraModel::fold_in`):
    /// lens correction would mirror part of it onto itself.
    #[error(
        "the camera's distortion folds the image near pixel ({x:.0}, {y:.0}): two places of \
         the scene would be seen at one pixel there, which no lens does; check D and K in \
         its .cdf (a digit or a sign mistyped?)"
    )]
    LensFolds { x: f64, y: f64 },
    /// A parameter is outside its allowed range.
    #[error("parameter {name} = {value} is out of range ({range})")]
    Param {
        name: &'static str,
        value: f64,
        range: &'static str,
    },
}

/// A point in image coordinates: pixels, `x` right, `y` down, origin at the
/// centre of the top-left pixel (llv.md §0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    pub x: f64,
    pub y: f64,
}

impl Point {
    pub const fn new(x: f64, y: f64) -> Self {
        Point { x, y }
    }
    pub fn dist(self, o: Point) -> f64 {
        (self.x - o.x).hypot(self.y - o.y)
    }
}

/// The scan direction of an edge image. `Horizontal` scans along `x` and
/// finds edges of vertically oriented structures (`EdgeH`, `.hpo`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ScanDir {
    Horizontal,
    Vertical,
}

/// One edge point: subpixel position (pixels) and the signed response of the
/// Lee kernel at the peak (grey levels; the sign tells dark→light from
/// light→dark along the scan).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EdgePoint {
    pub x: f32,
    pub y: f32,
    pub response: f32,
}

/// All edge points of one scan direction of one image, in lexical order
/// (row by row, left to right, for either direction).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EdgePoints {
    pub dir: Option<ScanDir>,
    pub width: usize,
    pub height: usize,
    pub points: Vec<EdgePoint>,
}

/// A straight line segment between two endpoints, in pixels, with the
/// attributes the later stages and the operator use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    pub a: Point,
    pub b: Point,
    /// Mean signed edge response of the points behind the segment (grey
    /// levels); 0 where unknown (e.g. read from a `.lex` file).
    #[serde(default)]
    pub response: f64,
    /// RMS perpendicular distance of those points from the fitted line (px);
    /// 0 where unknown.
    #[serde(default)]
    pub residual: f64,
    /// Flagged as a shadow line (llv.md §6), not an object edge.
    #[serde(default)]
    pub shadow: bool,
}

impl Segment {
    pub fn new(a: Point, b: Point) -> Self {
        Segment {
            a,
            b,
            ..Default::default()
        }
    }
    pub fn length(&self) -> f64 {
        self.a.dist(self.b)
    }
    /// Direction angle in radians, from +x, counter-clockwise as a person sees
    /// the screen (so with `y` down: `atan2(-(by-ay), bx-ax)`), in (-π, π].
    pub fn angle(&self) -> f64 {
        (-(self.b.y - self.a.y)).atan2(self.b.x - self.a.x)
    }
}
