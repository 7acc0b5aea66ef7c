//! Camera description files `.cdf` (formats.md §4): parameters written as a
//! line `NAME=STATUS` followed by their values, one number per line (for `T`,
//! one matrix row of four per line).
//!
//! The known parameters (`S`, `C`, `f`, `D`, `T`) are checked for their
//! number of values; unknown ones are kept, rows as they were, and written
//! back in their place, so a newer calibration program's additions survive
//! the console. A parameter with status `N` may carry its values or none.
//! Numbers are written with six decimals when that is exact, else with the
//! digits needed to read back the same value.

use std::path::Path;

use super::{
    FormatError, FormatErrorKind as K, fmt_exact, numbered_lines, parse_f64, read_text, shorten,
    write_bytes,
};
use crate::llv::lens::CameraModel;

/// How a parameter's value was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// `N`: not available.
    NotAvailable,
    /// `E`: estimated.
    Estimated,
    /// `A`: calibrated.
    Calibrated,
    /// `S`: stated (e.g. from the data sheet).
    Stated,
}

impl Status {
    pub fn letter(self) -> char {
        match self {
            Status::NotAvailable => 'N',
            Status::Estimated => 'E',
            Status::Calibrated => 'A',
            Status::Stated => 'S',
        }
    }
    pub fn from_letter(c: &str) -> Option<Status> {
        Some(match c {
            "N" => Status::NotAvailable,
            "E" => Status::Estimated,
            "A" => Status::Calibrated,
            "S" => Status::Stated,
            _ => return None,
        })
    }
    /// What the letter means, for `vss info`.
    pub fn describe(self) -> &'static str {
        match self {
            Status::NotAvailable => "not available",
            Status::Estimated => "estimated",
            Status::Calibrated => "calibrated",
            Status::Stated => "stated",
        }
    }
}

/// One parameter: name, status and value rows (one number per row, except
/// `T` with four).
#[derive(Clone, Debug, PartialEq)]
pub struct CdfParam {
    pub name: String,
    pub status: Status,
    pub rows: Vec<Vec<f64>>,
}

impl CdfParam {
    /// All values, row after row.
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.rows.iter().flatten().copied()
    }
    /// Whether the values are usable (status not `N`).
    pub fn available(&self) -> bool {
        self.status != Status::NotAvailable
    }
}

/// A camera description: its parameters in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cdf {
    pub params: Vec<CdfParam>,
}

/// `(rows, values per row)` of the parameters the spec defines.
pub fn known_shape(name: &str) -> Option<(usize, usize)> {
    Some(match name {
        "S" | "C" => (2, 1),
        "f" => (1, 1),
        "D" => (5, 1),
        "K" => (2, 1),
        "T" => (3, 4),
        _ => return None,
    })
}

impl Cdf {
    /// The parameter named `name`.
    pub fn get(&self, name: &str) -> Option<&CdfParam> {
        self.params.iter().find(|p| p.name == name)
    }

    /// The values of an available parameter.
    fn available(&self, name: &str) -> Option<Vec<f64>> {
        let p = self.get(name).filter(|p| p.available())?;
        let v: Vec<f64> = p.values().collect();
        let (r, c) = known_shape(name)?;
        (v.len() == r * c).then_some(v)
    }

    /// Replaces the parameter of that name, or appends it.
    pub fn set(&mut self, p: CdfParam) {
        match self.params.iter_mut().find(|q| q.name == p.name) {
            Some(q) => *q = p,
            None => self.params.push(p),
        }
    }

    /// The intrinsic camera model, or why there is none ([`Cdf::model`]).
    pub fn camera_model(&self) -> Option<CameraModel> {
        self.model().ok()
    }

    /// The intrinsic camera model, or why the description gives none, said
    /// as "lacks …" after its file's name: `S`, `C` or `f` missing or `N`,
    /// or no `D` line at all. `D=N` says the lens has no distortion; a
    /// description without the line is refused, because a file cut after
    /// `f` would otherwise read as a lens without distortion and lens
    /// correction would silently do nothing. `K` missing or `N` gives no
    /// higher radial terms.
    pub fn model(&self) -> Result<CameraModel, String> {
        let gone: Vec<&str> = ["S", "C", "f"]
            .into_iter()
            .filter(|n| self.available(n).is_none())
            .collect();
        if let [one] = gone.as_slice() {
            return Err(format!("lacks {one} (or marks it N)"));
        }
        if !gone.is_empty() {
            return Err(format!("lacks {} (or marks them N)", gone.join(", ")));
        }
        if self.get("D").is_none() {
            return Err("lacks its D line (D=N says the lens has no distortion)".into());
        }
        self.intrinsics()
            .ok_or_else(|| "lacks S, C or f (or marks them N)".into())
    }

    fn intrinsics(&self) -> Option<CameraModel> {
        let s = self.available("S")?;
        let c = self.available("C")?;
        let f = self.available("f")?;
        let d = self
            .available("D")
            .and_then(|d| <[f64; 5]>::try_from(d).ok());
        Some(CameraModel {
            cx: *c.first()?,
            cy: *c.get(1)?,
            sx: *s.first()?,
            sy: *s.get(1)?,
            f: *f.first()?,
            distortion: d,
            radial: self
                .available("K")
                .and_then(|k| <[f64; 2]>::try_from(k).ok())
                .unwrap_or([0.0; 2]),
        })
    }

    /// The extrinsic matrix `[R | t]` (world to camera, mm), if available.
    pub fn extrinsic(&self) -> Option<[[f64; 4]; 3]> {
        let v = self.available("T")?;
        let mut t = [[0.0; 4]; 3];
        for (i, x) in v.into_iter().enumerate() {
            *t.get_mut(i / 4)?.get_mut(i % 4)? = x;
        }
        Some(t)
    }

    /// A calibrated (`A`) description of a camera model, with `T` when given
    /// (else `T=N` with zeros). Distortion `None` is written `D=N`.
    pub fn from_camera(m: &CameraModel, t: Option<[[f64; 4]; 3]>) -> Cdf {
        let col = |v: &[f64]| v.iter().map(|&x| vec![x]).collect::<Vec<_>>();
        let a = Status::Calibrated;
        let (ds, d) = match m.distortion {
            Some(d) => (a, d),
            None => (Status::NotAvailable, [0.0; 5]),
        };
        let (ts, tm) = match t {
            Some(t) => (a, t),
            None => (Status::NotAvailable, [[0.0; 4]; 3]),
        };
        let mut cdf = Cdf {
            params: vec![
                CdfParam {
                    name: "S".into(),
                    status: a,
                    rows: col(&[m.sx, m.sy]),
                },
                CdfParam {
                    name: "C".into(),
                    status: a,
                    rows: col(&[m.cx, m.cy]),
                },
                CdfParam {
                    name: "f".into(),
                    status: a,
                    rows: col(&[m.f]),
                },
                CdfParam {
                    name: "D".into(),
                    status: ds,
                    rows: col(&d),
                },
                CdfParam {
                    name: "T".into(),
                    status: ts,
                    rows: tm.iter().map(|r| r.to_vec()).collect(),
                },
            ],
        };
        // `K` only where it says something: a camera of `k1` alone keeps
        // the 1994 file's five parameters.
        if m.distortion.is_some() && m.radial != [0.0; 2] {
            cdf.params.insert(
                4,
                CdfParam {
                    name: "K".into(),
                    status: a,
                    rows: col(&m.radial),
                },
            );
        }
        cdf
    }
}

fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '-')
}

/// Parses `.cdf` text; `path` names the file in errors.
pub fn parse_cdf(text: &str, path: &Path) -> Result<Cdf, FormatError> {
    let mut cdf = Cdf::default();
    // Line of each parameter's header, to name it when its values are short.
    let mut starts: Vec<usize> = Vec::new();
    let mut last_line = 0;
    for (n, line) in numbered_lines(text) {
        last_line = n;
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if let Some((name, status)) = t.split_once('=') {
            let (name, status) = (name.trim(), status.trim());
            if !valid_name(name) {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!(
                        "expected a parameter name (letters, digits, _ . -) before '=', found \"{}\"",
                        shorten(name)
                    ),
                ));
            }
            let Some(status) = Status::from_letter(status) else {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!(
                        "{name}: expected status N, E, A or S after '=', found \"{}\"",
                        shorten(status)
                    ),
                ));
            };
            if let Some(i) = cdf.params.iter().position(|p| p.name == name) {
                let first = starts.get(i).copied().unwrap_or(0);
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!("parameter {name} given twice (first at line {first})"),
                ));
            }
            if let Some(prev) = cdf.params.last() {
                check_shape(prev, starts.last().copied().unwrap_or(0), path)?;
            }
            cdf.params.push(CdfParam {
                name: name.to_string(),
                status,
                rows: Vec::new(),
            });
            starts.push(n);
            continue;
        }
        let Some(cur) = cdf.params.last_mut() else {
            return Err(FormatError::at_line(
                path,
                n,
                K::Syntax,
                format!(
                    "expected NAME=STATUS (e.g. \"S=A\"), found \"{}\"",
                    shorten(t)
                ),
            ));
        };
        let what = format!("a value of {}", cur.name);
        let row = t
            .split_whitespace()
            .map(|tok| parse_f64(tok, path, n, &what))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some((rows, cols)) = known_shape(&cur.name) {
            if row.len() != cols {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!(
                        "{}: expected {cols} number(s) on this line, found {}",
                        cur.name,
                        row.len()
                    ),
                ));
            }
            if cur.rows.len() >= rows {
                return Err(FormatError::at_line(
                    path,
                    n,
                    K::Syntax,
                    format!(
                        "{} has {rows} value line(s); expected NAME=STATUS here, found \"{}\"",
                        cur.name,
                        shorten(t)
                    ),
                ));
            }
        }
        check_value(&cur.name, cur.status, &row, path, n)?;
        cur.rows.push(row);
    }
    if let Some(prev) = cdf.params.last() {
        check_shape(prev, starts.last().copied().unwrap_or(0), path)?;
    }
    if cdf.params.is_empty() {
        return Err(FormatError::at_line(
            path,
            last_line.max(1),
            K::Missing,
            "no parameters: expected lines NAME=STATUS followed by values",
        ));
    }
    Ok(cdf)
}

/// The sense of a value line of a parameter the camera model uses: scale
/// factors and the focal length are positive (a zero scale puts every pixel
/// at infinity, which once made an all-black `.imc` and no lines, silently).
/// Values of a parameter marked `N` are placeholders and not checked.
fn check_value(
    name: &str,
    status: Status,
    row: &[f64],
    path: &Path,
    line: usize,
) -> Result<(), FormatError> {
    if status == Status::NotAvailable {
        return Ok(());
    }
    // Beyond these no camera is: a 1e-300 mm lens or a centre a billion
    // pixels off the 65535-pixel image is a damaged or hostile file, and
    // would make lens correction divide by nearly nothing.
    let (what, lo, hi) = match name {
        "S" => ("a scale factor (mm per pixel)", 1e-7, 1e3),
        "f" => ("the focal length (mm)", 1e-2, 1e5),
        "C" => ("the image centre (pixels)", -1e5, 1e5),
        _ => return Ok(()),
    };
    if name != "C"
        && let Some(v) = row.iter().find(|&&v| v <= 0.0)
    {
        return Err(FormatError::at_line(
            path,
            line,
            K::Range,
            format!("{name}: {what} must be greater than 0, found {v}"),
        ));
    }
    match row.iter().find(|&&v| !(lo..=hi).contains(&v)) {
        Some(v) => Err(FormatError::at_line(
            path,
            line,
            K::Range,
            format!("{name}: {what} must be from {lo} to {hi}, found {v}"),
        )),
        None => Ok(()),
    }
}

/// The share of a corrected image below which a camera model is refused.
const MIN_VALID_SHARE: f64 = 0.1;

/// Checks that lens correction with `m` leaves a picture: of a grid of
/// points over a `width` × `height` corrected image, at least a tenth must
/// come from inside the observed image. A model whose centre, scale or
/// distortion sends (nearly) everything outside would give a black image
/// and no lines; it is refused naming the file and the fields to check.
/// So is a distortion that folds the image (`CameraModel::fold_in`).
pub fn check_camera_area(
    m: &CameraModel,
    width: usize,
    height: usize,
    path: &Path,
) -> Result<(), FormatError> {
    const N: usize = 24;
    let (w, h) = (width.max(1) as f64, height.max(1) as f64);
    let mut inside = 0usize;
    for j in 0..N {
        for i in 0..N {
            let x = (i as f64 + 0.5) * w / N as f64 - 0.5;
            let y = (j as f64 + 0.5) * h / N as f64 - 0.5;
            let (xs, ys) = m.ideal_to_observed_converged(x, y);
            if xs.is_finite()
                && ys.is_finite()
                && (-0.5..=w - 0.5).contains(&xs)
                && (-0.5..=h - 0.5).contains(&ys)
            {
                inside += 1;
            }
        }
    }
    if let Some((x, y)) = m.fold_in(width, height) {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!(
                "D, K: the distortion folds a {width} × {height} image near pixel ({x:.0}, \
                 {y:.0}): two places of the scene would be seen at one pixel there, which no \
                 lens does, so lens correction would mirror part of the image; check the \
                 distortion coefficients (a digit or a sign mistyped?)"
            ),
        ));
    }
    let share = inside as f64 / (N * N) as f64;
    if share < MIN_VALID_SHARE {
        return Err(FormatError::new(
            path,
            super::Location::None,
            K::Range,
            format!(
                "C, S, D, K: lens correction of a {width} × {height} image with this camera model \
                 leaves {:.0} % of it with pixels (at least {:.0} % are needed): check the \
                 image centre, the scale factors and the distortion coefficients",
                share * 100.0,
                MIN_VALID_SHARE * 100.0
            ),
        ));
    }
    Ok(())
}

fn check_shape(p: &CdfParam, line: usize, path: &Path) -> Result<(), FormatError> {
    let Some((rows, _)) = known_shape(&p.name) else {
        return Ok(());
    };
    let ok = p.rows.len() == rows || (p.status == Status::NotAvailable && p.rows.is_empty());
    if ok {
        return Ok(());
    }
    Err(FormatError::at_line(
        path,
        line,
        K::Missing,
        format!(
            "{} needs {rows} value line(s), found {}",
            p.name,
            p.rows.len()
        ),
    ))
}

/// The `.cdf` text of a description, exactly as formats.md §4 lays it out.
pub fn format_cdf(c: &Cdf) -> String {
    let mut s = String::new();
    for p in &c.params {
        s.push_str(&format!("{}={}\n", p.name, p.status.letter()));
        for row in &p.rows {
            let cells: Vec<String> = row.iter().map(|&v| fmt_exact(v)).collect();
            s.push_str(&cells.join(" "));
            s.push('\n');
        }
    }
    s
}

/// Reads a `.cdf` file.
pub fn read_cdf(path: &Path) -> Result<Cdf, FormatError> {
    parse_cdf(&read_text(path)?, path)
}

/// Writes a `.cdf` file atomically. Refuses non-finite values, empty rows
/// and names the reader would not accept.
pub fn write_cdf(path: &Path, c: &Cdf) -> Result<(), FormatError> {
    for p in &c.params {
        let bad = |m: String| FormatError::new(path, super::Location::None, K::Range, m);
        if !valid_name(&p.name) {
            return Err(bad(format!(
                "parameter name \"{}\" cannot be written",
                shorten(&p.name)
            )));
        }
        if p.rows.iter().any(|r| r.is_empty()) || p.values().any(|v| !v.is_finite()) {
            return Err(bad(format!(
                "parameter {} has an empty row or a non-finite value",
                p.name
            )));
        }
    }
    write_bytes(path, format_cdf(c).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "S=A\n0.011250\n0.007800\nC=E\n256.000000\n256.000000\nf=A\n11.892729\n\
D=A\n-0.000527\n0.000379\n0.001330\n-0.000703\n-0.001406\nT=A\n\
0.999943 -0.009549 -0.004720 -88.393677\n-0.010480 -0.961660 -0.274044 45.803197\n\
-0.001920 0.274078 -0.961706 432.081189\n";

    #[test]
    fn spec_example_reads_and_writes_back_identically() {
        let c = parse_cdf(SPEC, Path::new("cam1.cdf")).unwrap();
        assert_eq!(format_cdf(&c), SPEC);
        let m = c.camera_model().unwrap();
        assert_eq!((m.sx, m.sy, m.cx, m.f), (0.01125, 0.0078, 256.0, 11.892729));
        assert_eq!(m.distortion.unwrap()[0], -0.000527);
        assert_eq!(c.extrinsic().unwrap()[2][3], 432.081189);
        assert_eq!(c.get("C").unwrap().status, Status::Estimated);
    }

    /// A description cut after `f` (at a line's end, so it parses) is not a
    /// lens without distortion: it gives no model, and says why.
    #[test]
    fn a_description_without_its_d_line_gives_no_model() {
        let cut = &SPEC[..SPEC.find("D=A").unwrap()];
        let c = parse_cdf(cut, Path::new("cam1.cdf")).unwrap();
        assert_eq!(c.camera_model(), None);
        assert_eq!(
            c.model().unwrap_err(),
            "lacks its D line (D=N says the lens has no distortion)"
        );
        let no_f = &SPEC[..SPEC.find("f=A").unwrap()];
        let c = parse_cdf(no_f, Path::new("cam1.cdf")).unwrap();
        assert_eq!(c.model().unwrap_err(), "lacks f (or marks it N)");
        let c = parse_cdf("C=N\n0\n0\nD=N\n", Path::new("cam1.cdf")).unwrap();
        assert_eq!(c.model().unwrap_err(), "lacks S, C, f (or marks them N)");
    }

    #[test]
    fn unknown_kept_and_d_n_means_no_distortion() {
        let t = "S=A\r\n1\r\n1\r\nX=S\r\n1 2 3\r\n\r\nC=A\n0\n0\nf=A\n8\nD=N\n";
        let c = parse_cdf(t, Path::new("a.cdf")).unwrap();
        assert_eq!(c.params[1].name, "X");
        assert_eq!(c.params[1].rows, vec![vec![1.0, 2.0, 3.0]]);
        assert_eq!(c.camera_model().unwrap().distortion, None);
        assert_eq!(c.extrinsic(), None);
        let again = parse_cdf(&format_cdf(&c), Path::new("b.cdf")).unwrap();
        assert_eq!(again, c);
    }

    #[test]
    fn from_camera_round_trips() {
        let c = parse_cdf(SPEC, Path::new("cam1.cdf")).unwrap();
        let m = c.camera_model().unwrap();
        let d = Cdf::from_camera(&m, c.extrinsic());
        assert_eq!(d.camera_model(), Some(m));
        assert_eq!(d.extrinsic(), c.extrinsic());
        // The spec's example has no `K`: no higher radial terms, and none
        // written back.
        assert_eq!(m.radial, [0.0; 2]);
        assert!(d.get("K").is_none());
    }

    #[test]
    fn k_holds_the_higher_radial_terms() {
        let c = parse_cdf(SPEC, Path::new("cam1.cdf")).unwrap();
        let m = CameraModel {
            radial: [2.5e-5, -1.0e-7],
            ..c.camera_model().unwrap()
        };
        let text = format_cdf(&Cdf::from_camera(&m, c.extrinsic()));
        assert!(text.contains("K=A\n0.000025"), "{text}");
        let back = parse_cdf(&text, Path::new("k.cdf")).unwrap();
        assert_eq!(back.camera_model(), Some(m));
        // `K=N` means none; a `K` of the wrong shape is refused.
        let n = text.replace("K=A", "K=N");
        let back = parse_cdf(&n, Path::new("n.cdf")).unwrap();
        assert_eq!(back.camera_model().unwrap().radial, [0.0; 2]);
        let short = text.replace("\n-0.0000001\n", "\n");
        assert_ne!(short, text);
        let e = parse_cdf(&short, Path::new("s.cdf"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.cdf") && e.contains('K'), "{e}");
    }

    #[test]
    fn a_distortion_that_folds_the_image_is_refused_naming_the_file() {
        let c = parse_cdf(SPEC, Path::new("cam1.cdf")).unwrap();
        let good = c.camera_model().unwrap();
        assert!(check_camera_area(&good, 512, 512, Path::new("cam1.cdf")).is_ok());
        // k1 typed as 0.05 for -0.0005: most of the image still has
        // pixels, but its outer part would be mirrored.
        let mut d = good.distortion.unwrap();
        d[0] = 0.05;
        let folds = CameraModel {
            distortion: Some(d),
            ..good
        };
        let e = check_camera_area(&folds, 512, 512, Path::new("cam1.cdf"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("cam1.cdf") && e.contains("folds a 512 × 512 image near pixel"),
            "{e}"
        );
    }
}
