//! Calibration plates (`profiles/plates/*.toml`): a grid of dark squares on a
//! light plate, or a checkerboard, with its size in millimetres, its rows and
//! columns, the corner its coordinates start from, and optionally where it
//! lies in the cell (for the extrinsic calibration).
//!
//! Plate coordinates: origin at the outer corner of the grid at the origin
//! corner, `x` along a row away from it (columns increase), `y` along a
//! column (rows increase), `z = x × y`, all in mm on the printed face
//! (`z = 0`). The origin label says how the plate looks from its printed
//! side: from `top-left` or `bottom-right`, `x` to `y` turns clockwise, as the
//! image's `x` to `y` does; from `top-right` or `bottom-left` it turns the
//! other way. That is all the detector needs to tell the plate from its
//! mirror image.
//!
//! Telling the origin corner from the others in an image needs something
//! that breaks the grid's symmetry: on a squares plate, `origin_mark = true`
//! leaves the origin square out; on a checkerboard, the origin square is
//! dark and, with rows + columns odd, no other corner square matches it. A
//! plate without either can still calibrate intrinsics (each view has its
//! own pose), not the extrinsic pose.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

/// Most squares a side: a plate is read whole, and the detector's search is
/// quadratic in its squares.
pub const MAX_SQUARES: u32 = 64;

/// Largest plate file read (bytes): a plate is a few lines.
pub const MAX_PLATE_BYTES: u64 = 64 * 1024;

/// The plates built into vss: name and text (`profiles/plates/`).
pub const BUILT_IN: [(&str, &str); 2] = [
    (
        "squares",
        include_str!("../../profiles/plates/squares.toml"),
    ),
    (
        "checkerboard",
        include_str!("../../profiles/plates/checkerboard.toml"),
    ),
];

/// Whether [`Plate::load`] takes `name_or_path` for a file (anything with
/// a `/` or ending in `.toml`) rather than a built-in plate's name.
fn names_a_file(name_or_path: &str) -> bool {
    name_or_path.ends_with(".toml") || Path::new(name_or_path).components().count() > 1
}

/// Which plate file `name_or_path` names, for people: a file's absolute
/// path, or `NAME (built in)`. The one owner of that answer, with [`Plate::load`]'s
/// rule; the Calibrate screen and `vss calibrate` show it.
pub fn in_use(name_or_path: &str) -> String {
    if names_a_file(name_or_path) {
        let p = Path::new(name_or_path);
        crate::text::path(std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
    } else {
        format!("{name_or_path} (built in)")
    }
}

/// A plate that could not be read, or contradicts itself.
#[derive(Debug, thiserror::Error)]
pub enum PlateError {
    #[error("cannot read plate file {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("plate `{name}` is not a built-in plate ({tried})")]
    NotFound { name: String, tried: String },
    #[error("{path}:{line}: {message}")]
    Invalid {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

/// Which kind of plate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlateKind {
    /// Dark squares on a light plate, apart from each other.
    Squares,
    /// A checkerboard: dark and light squares touching at their corners.
    Checkerboard,
}

/// The corner plate coordinates start from, seen from the printed side.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    TopLeft,
    TopRight,
    BottomLeft,
    BottomRight,
}

impl Origin {
    /// +1 when plate `x` → `y` turns like image `x` → `y` seen from the
    /// printed side (clockwise on the screen), −1 otherwise.
    pub fn handedness(self) -> f64 {
        match self {
            Origin::TopLeft | Origin::BottomRight => 1.0,
            Origin::TopRight | Origin::BottomLeft => -1.0,
        }
    }
}

/// The plate's pose in the cell: plate coordinates → world (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    /// Rotation: columns are the plate's `x`, `y`, `z` axes in the world.
    pub rotation: [[f64; 3]; 3],
    /// The plate's origin in the world (mm).
    pub origin: [f64; 3],
}

impl Place {
    /// World coordinates of a plate point.
    pub fn to_world(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        std::array::from_fn(|i| r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + self.origin[i])
    }
}

/// A checked calibration plate.
#[derive(Clone, Debug, PartialEq)]
pub struct Plate {
    pub name: String,
    pub kind: PlateKind,
    /// Squares from top to bottom (along `y`).
    pub rows: u32,
    /// Squares from left to right (along `x`).
    pub columns: u32,
    /// Side of a square (mm).
    pub square: f64,
    /// Centre-to-centre distance of neighbouring squares (mm); equals
    /// `square` on a checkerboard.
    pub pitch: f64,
    pub origin: Origin,
    /// The origin square is left out (squares plates).
    pub origin_mark: bool,
    /// Light margin around the grid (mm).
    pub border: f64,
    pub place: Option<Place>,
    /// The file it came from.
    pub source: Option<PathBuf>,
}

/// One lattice corner of the plate: its key (unique on the plate) and its
/// position in plate coordinates (mm, `z = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateCorner {
    pub key: (u32, u32),
    pub xy: [f64; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlateFile {
    #[serde(default)]
    name: String,
    kind: Spanned<PlateKind>,
    rows: Spanned<u32>,
    columns: Spanned<u32>,
    square: Spanned<f64>,
    #[serde(default)]
    pitch: Option<Spanned<f64>>,
    origin: Spanned<Origin>,
    #[serde(default)]
    origin_mark: Option<Spanned<bool>>,
    #[serde(default)]
    border: Option<Spanned<f64>>,
    #[serde(default)]
    place: Option<Spanned<PlaceFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaceFile {
    origin: Spanned<[f64; 3]>,
    x_axis: Spanned<[f64; 3]>,
    y_axis: Spanned<[f64; 3]>,
}

impl Plate {
    /// Loads a plate: a bare name is one of the plates built into vss
    /// ([`BUILT_IN`], the files of `profiles/plates/` as they were when vss
    /// was built), anything with a `/` or ending in `.toml` a file, read
    /// with the bounded, link-refusing reader ([`crate::fsutil::read_input_text`]).
    /// No folder is searched: a file planted in the current folder's
    /// `profiles/plates/` is never taken for a built-in plate.
    pub fn load(name_or_path: &str) -> Result<Plate, PlateError> {
        let p = Path::new(name_or_path);
        if names_a_file(name_or_path) {
            let text = crate::fsutil::read_input_text(p, MAX_PLATE_BYTES).map_err(|source| {
                PlateError::Io {
                    path: p.to_path_buf(),
                    source,
                }
            })?;
            return Plate::from_toml(&text, p);
        }
        match BUILT_IN.iter().find(|(n, _)| *n == name_or_path) {
            Some((n, text)) => Plate::from_toml(text, Path::new(&format!("(built in) {n}.toml"))),
            None => Err(PlateError::NotFound {
                name: name_or_path.to_string(),
                tried: format!(
                    "the built-in plates {}; a plate file is named by its path, e.g. ./{name_or_path}.toml",
                    BUILT_IN
                        .iter()
                        .map(|(n, _)| *n)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }),
        }
    }

    /// Parses and checks a plate file; `path` names it in errors.
    pub fn from_toml(text: &str, path: &Path) -> Result<Plate, PlateError> {
        let err = |span: Option<std::ops::Range<usize>>, message: String| PlateError::Invalid {
            path: path.to_path_buf(),
            line: span.map_or(0, |s| line_of(text, s.start)),
            message,
        };
        let f: PlateFile = toml::from_str(text).map_err(|e| {
            let in_place = e.span().is_some_and(|s| s.start > 0);
            err(e.span(), explain_missing(e.message(), in_place))
        })?;
        let kind = *f.kind.get_ref();
        for (what, v) in [("rows", &f.rows), ("columns", &f.columns)] {
            let min = if kind == PlateKind::Checkerboard {
                3
            } else {
                2
            };
            if !(min..=MAX_SQUARES).contains(v.get_ref()) {
                return Err(err(
                    Some(v.span()),
                    format!(
                        "{what} = {}: a {} needs {min} to {MAX_SQUARES} squares a side",
                        v.get_ref(),
                        kind_name(kind)
                    ),
                ));
            }
        }
        let square = *f.square.get_ref();
        if !(square.is_finite() && square > 0.0 && square <= 1000.0) {
            return Err(err(
                Some(f.square.span()),
                format!(
                    "square = {square}: the side of a square is more than 0 and at most 1000 mm"
                ),
            ));
        }
        let pitch = match (kind, &f.pitch) {
            (PlateKind::Squares, None) => {
                return Err(err(
                    Some(f.kind.span()),
                    "a squares plate needs `pitch`, the distance from one square to the next (mm)"
                        .into(),
                ));
            }
            (PlateKind::Squares, Some(p)) => {
                let v = *p.get_ref();
                if !(v.is_finite() && v > square && v <= 10.0 * square) {
                    return Err(err(
                        Some(p.span()),
                        format!(
                            "pitch = {v} with square = {square}: the squares would {}; the pitch is more than the square (and at most ten squares)",
                            if v <= square {
                                "touch or overlap"
                            } else {
                                "be too far apart"
                            }
                        ),
                    ));
                }
                v
            }
            (PlateKind::Checkerboard, Some(p)) if *p.get_ref() != square => {
                return Err(err(
                    Some(p.span()),
                    format!(
                        "pitch = {} on a checkerboard, whose squares touch: the pitch is the square ({square}); leave it out",
                        p.get_ref()
                    ),
                ));
            }
            (PlateKind::Checkerboard, _) => square,
        };
        let origin_mark = match (&f.origin_mark, kind) {
            (Some(m), PlateKind::Checkerboard) if *m.get_ref() => {
                return Err(err(
                    Some(m.span()),
                    "origin_mark = true on a checkerboard: its origin square is told by its colour (dark), not left out".into(),
                ));
            }
            (Some(m), _) => *m.get_ref(),
            (None, _) => false,
        };
        let border = match &f.border {
            Some(b) => {
                let v = *b.get_ref();
                if !(0.0..=1000.0).contains(&v) {
                    return Err(err(
                        Some(b.span()),
                        format!("border = {v}: the margin is 0 to 1000 mm"),
                    ));
                }
                v
            }
            None => square,
        };
        let place = f
            .place
            .as_ref()
            .map(|p| check_place(p.get_ref()).map_err(|(span, m)| err(Some(span), m)))
            .transpose()?;
        let name = if f.name.is_empty() {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        } else {
            f.name
        };
        Ok(Plate {
            name,
            kind,
            rows: *f.rows.get_ref(),
            columns: *f.columns.get_ref(),
            square,
            pitch,
            origin: *f.origin.get_ref(),
            origin_mark,
            border,
            place,
            source: Some(path.to_path_buf()),
        })
    }

    /// Whether cell `(i, j)` (column, row) is a dark square.
    pub fn is_dark(&self, i: u32, j: u32) -> bool {
        match self.kind {
            PlateKind::Squares => !(self.origin_mark && i == 0 && j == 0),
            PlateKind::Checkerboard => (i + j).is_multiple_of(2),
        }
    }

    /// The cells the detector sees as closed quadrilaterals: every dark
    /// square, and on a checkerboard the light squares off its border (a
    /// border square's outer side meets the light margin, so it has no
    /// edge there).
    pub fn quad_cells(&self) -> BTreeSet<(u32, u32)> {
        let mut s = BTreeSet::new();
        for j in 0..self.rows {
            for i in 0..self.columns {
                let inner = i > 0 && j > 0 && i + 1 < self.columns && j + 1 < self.rows;
                let light_ok = self.kind == PlateKind::Checkerboard && inner;
                if self.is_dark(i, j) || light_ok {
                    s.insert((i, j));
                }
            }
        }
        s
    }

    /// The four corners of cell `(i, j)` in plate mm, in the order
    /// `(0,0) (1,0) (1,1) (0,1)` of the cell, with their keys.
    pub fn cell_corners(&self, i: u32, j: u32) -> [PlateCorner; 4] {
        let (s, p) = (self.square, self.pitch);
        [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(a, b)| {
            let key = match self.kind {
                PlateKind::Squares => (2 * i + a, 2 * j + b),
                PlateKind::Checkerboard => (i + a, j + b),
            };
            PlateCorner {
                key,
                xy: [
                    f64::from(i) * p + f64::from(a) * s,
                    f64::from(j) * p + f64::from(b) * s,
                ],
            }
        })
    }

    /// Every corner the detector finds on a whole view, by key: on a
    /// checkerboard its inner corners (where four squares meet), on a
    /// squares plate the squares' corners.
    pub fn corners(&self) -> Vec<PlateCorner> {
        if self.kind == PlateKind::Checkerboard {
            let mut out = Vec::new();
            for j in 1..self.rows {
                for i in 1..self.columns {
                    out.push(PlateCorner {
                        key: (i, j),
                        xy: [f64::from(i) * self.square, f64::from(j) * self.square],
                    });
                }
            }
            return out;
        }
        let mut seen = BTreeSet::new();
        let mut out = Vec::new();
        for (i, j) in self.quad_cells() {
            for c in self.cell_corners(i, j) {
                if seen.insert(c.key) {
                    out.push(c);
                }
            }
        }
        out.sort_by_key(|c| (c.key.1, c.key.0));
        out
    }

    /// Width and height of the grid (mm), without the border.
    pub fn grid_size(&self) -> (f64, f64) {
        let g = self.pitch - self.square;
        (
            f64::from(self.columns) * self.pitch - g,
            f64::from(self.rows) * self.pitch - g,
        )
    }

    /// Whether the origin corner can be told apart in an image: the lattice
    /// looks the same turned by 180° (or 90° when square) otherwise.
    pub fn oriented(&self) -> bool {
        match self.kind {
            PlateKind::Squares => self.origin_mark,
            PlateKind::Checkerboard => (self.rows + self.columns) % 2 == 1,
        }
    }

    /// One line for people: "squares 8 × 6 of 25 mm at 40 mm".
    pub fn describe(&self) -> String {
        match self.kind {
            PlateKind::Squares => format!(
                "{} squares of {} mm at {} mm pitch ({} columns × {} rows{})",
                self.quad_cells().len(),
                self.square,
                self.pitch,
                self.columns,
                self.rows,
                if self.origin_mark {
                    ", origin square left out"
                } else {
                    ""
                }
            ),
            PlateKind::Checkerboard => format!(
                "checkerboard of {} columns × {} rows, {} mm squares",
                self.columns, self.rows, self.square
            ),
        }
    }
}

fn kind_name(k: PlateKind) -> &'static str {
    match k {
        PlateKind::Squares => "squares plate",
        PlateKind::Checkerboard => "checkerboard",
    }
}

type Span = std::ops::Range<usize>;

/// A parser's "missing field `x`" said as what the field is and the values
/// it takes (`in_place`: of the `[place]` table); other messages as they are.
fn explain_missing(message: &str, in_place: bool) -> String {
    let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.strip_suffix('`'))
    else {
        return message.to_string();
    };
    let what = match (field, in_place) {
        ("kind", _) => "\"squares\" (dark squares apart) or \"checkerboard\"",
        ("rows", _) => "the number of squares from top to bottom",
        ("columns", _) => "the number of squares from left to right",
        ("square", _) => "the side of a square in mm",
        ("origin", false) => {
            "the corner plate coordinates start from, seen from the printed side: \"top-left\", \"top-right\", \"bottom-left\" or \"bottom-right\""
        }
        ("origin", true) => "where the plate's origin is in the cell, [x, y, z] in mm",
        ("x_axis" | "y_axis", _) => "the plate's axis as a direction in the cell, [x, y, z]",
        _ => return message.to_string(),
    };
    let table = if in_place { "[place] " } else { "" };
    format!("{table}needs `{field}`: {what}")
}

/// 1-based line of a byte offset (the profile's loader has its own, private
/// to it).
fn line_of(text: &str, pos: usize) -> usize {
    text.get(..pos.min(text.len()))
        .map_or(0, |t| t.matches('\n').count())
        + 1
}

fn check_place(p: &PlaceFile) -> Result<Place, (Span, String)> {
    let o = *p.origin.get_ref();
    if o.iter().any(|v| !v.is_finite() || v.abs() > 1e6) {
        return Err((
            p.origin.span(),
            "place.origin: three finite numbers (mm)".into(),
        ));
    }
    let unit = |v: &Spanned<[f64; 3]>, what: &str| -> Result<[f64; 3], (Span, String)> {
        let a = *v.get_ref();
        let n = a.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(n.is_finite() && n > 1e-9) {
            return Err((v.span(), format!("place.{what}: a direction, not zero")));
        }
        Ok(a.map(|c| c / n))
    };
    let x = unit(&p.x_axis, "x_axis")?;
    let y = unit(&p.y_axis, "y_axis")?;
    let dot: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
    let angle = dot.clamp(-1.0, 1.0).acos().to_degrees();
    if (angle - 90.0).abs() > 0.05 {
        return Err((
            p.y_axis.span(),
            format!(
                "place.x_axis and place.y_axis are {angle:.2}° apart: a plate's axes are perpendicular"
            ),
        ));
    }
    // Make y exactly perpendicular (the check allows 0.05°).
    let y: [f64; 3] = std::array::from_fn(|i| y[i] - dot * x[i]);
    let n = y.iter().map(|c| c * c).sum::<f64>().sqrt();
    let y = y.map(|c| c / n);
    let z = [
        x[1] * y[2] - x[2] * y[1],
        x[2] * y[0] - x[0] * y[2],
        x[0] * y[1] - x[1] * y[0],
    ];
    Ok(Place {
        rotation: std::array::from_fn(|i| [x[i], y[i], z[i]]),
        origin: o,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARES: &str = r#"
kind = "squares"
rows = 3
columns = 4
square = 10.0
pitch = 25.0
origin = "top-left"
origin_mark = true
"#;

    fn parse(t: &str) -> Result<Plate, PlateError> {
        Plate::from_toml(t, Path::new("p.toml"))
    }

    #[test]
    fn a_squares_plate_has_its_corners_and_its_mark() {
        let p = parse(SQUARES).unwrap();
        assert_eq!(p.quad_cells().len(), 11);
        assert_eq!(p.corners().len(), 44);
        assert!(p.oriented());
        assert_eq!(p.grid_size(), (85.0, 60.0));
        let c = p.cell_corners(1, 2);
        assert_eq!(c[2].xy, [35.0, 60.0]);
    }

    #[test]
    fn a_checkerboard_shares_its_corners() {
        let t = "kind = \"checkerboard\"\nrows = 4\ncolumns = 5\nsquare = 30.0\norigin = \"bottom-left\"\n";
        let p = parse(t).unwrap();
        // Dark 10, inner light (3 × 2 inner cells, 3 of them light).
        assert_eq!(p.quad_cells().len(), 13);
        // The inner corners: 4 × 3.
        assert_eq!(p.corners().len(), 12);
        assert!(p.oriented());
        assert_eq!(p.origin.handedness(), -1.0);
    }

    #[test]
    fn contradictions_are_refused_with_their_line() {
        let cases = [
            (SQUARES.replace("pitch = 25.0", "pitch = 8.0"), 6, "overlap"),
            (SQUARES.replace("pitch = 25.0\n", ""), 2, "needs `pitch`"),
            (SQUARES.replace("rows = 3", "rows = 1"), 3, "2 to 64"),
            (
                SQUARES.replace("square = 10.0", "square = -1"),
                5,
                "more than 0",
            ),
            (
                SQUARES.replace("kind = \"squares\"", "kind = \"checkerboard\""),
                6,
                "leave it out",
            ),
            (
                SQUARES.replace("origin = \"top-left\"", "origin = \"middle\""),
                7,
                "top-left",
            ),
            (format!("{SQUARES}colour = 1\n"), 9, "colour"),
            (
                SQUARES.replace("origin = \"top-left\"\n", ""),
                1,
                "needs `origin`: the corner plate coordinates start from, seen from the printed side: \"top-left\"",
            ),
            (
                format!("{SQUARES}[place]\norigin = [0.0, 0.0, 0.0]\nx_axis = [1.0, 0.0, 0.0]\n"),
                9,
                "[place] needs `y_axis`: the plate's axis as a direction in the cell",
            ),
            (
                format!(
                    "{SQUARES}[place]\norigin = [0.0, 0.0, 0.0]\nx_axis = [1.0, 0.0, 0.0]\ny_axis = [0.1, 1.0, 0.0]\n"
                ),
                12,
                "perpendicular",
            ),
        ];
        for (text, line, want) in cases {
            let e = parse(&text).unwrap_err();
            let PlateError::Invalid {
                line: l, message, ..
            } = &e
            else {
                panic!("{e}")
            };
            assert!(message.contains(want), "{message}");
            assert_eq!(*l, line, "{message}");
        }
    }

    #[test]
    fn the_place_maps_plate_to_world() {
        let t = format!(
            "{SQUARES}[place]\norigin = [10.0, 20.0, 0.0]\nx_axis = [0.0, 2.0, 0.0]\ny_axis = [-1.0, 0.0, 0.0]\n"
        );
        let p = parse(&t).unwrap();
        let w = p.place.unwrap().to_world([1.0, 2.0, 3.0]);
        let want = [8.0, 21.0, 3.0];
        assert!(
            w.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
            "{w:?}"
        );
    }
}
