//! Every parameter an operator can tune in the LLV stages (spec/llv.md), with
//! its default, unit, allowed range and a one-line description — one table
//! ([`PARAMS`]) that the profile loader, `--set key=value`, the parameter-file
//! import/export, the console's parameter panel and the automatic search all
//! read.

use serde::{Deserialize, Serialize};

use super::LlvError;

/// Lens correction (llv.md §1, lens.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LensParams {
    /// Apply lens correction when a `.cdf` with distortion is given.
    pub enabled: bool,
}

impl Default for LensParams {
    fn default() -> Self {
        LensParams { enabled: true }
    }
}

/// Lee's edge detector and the adaptive threshold (llv.md §2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EdgeParams {
    /// Kernel half-width `A` (pixels), 3–7.
    pub half_width: u32,
    /// Floor threshold `T` (grey levels): no peak at or below it is kept.
    pub floor: f64,
    /// `M`: edge pixels kept per region by the adaptive threshold.
    pub per_region: u32,
    /// Scan lines per region of the adaptive threshold (1 = one scan line).
    pub region_lines: u32,
    /// Photometric combination (llv.md §2.6): an image's noise level `τ` is
    /// this multiple of its median absolute kernel response.
    pub noise_factor: f64,
}

impl Default for EdgeParams {
    fn default() -> Self {
        EdgeParams {
            half_width: 4,
            floor: 2.0,
            per_region: 8,
            region_lines: 1,
            noise_factor: 5.0,
        }
    }
}

/// The line extractor (llv.md §3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LineParams {
    /// Rows (columns) a line may skip without an edge point.
    pub max_gap: u32,
    /// Half-width of the search window around the predicted point (px).
    pub search_width: f64,
    /// Segments not longer than this are dropped (px).
    pub min_length: f64,
    /// Minimum angle between a line and the scan direction (degrees; π/8 = 22.5°).
    pub min_scan_angle_deg: f64,
    /// Line significance (grey levels): a segment whose points' mean
    /// |response| is below this is dropped as noise. Not in the original VSS:
    /// with the floor `T` at its default 2 grey levels, `M` points per scan
    /// line promote noise peaks in rows with few edges, and their chains make
    /// short lines of mean |response| 3–4 at noise σ = 2. 0 switches it off.
    pub min_response: f64,
}

impl Default for LineParams {
    fn default() -> Self {
        LineParams {
            max_gap: 3,
            search_width: 2.0,
            min_length: 8.0,
            min_scan_angle_deg: 22.5,
            min_response: 6.0,
        }
    }
}

/// CONNECT, the automatic post-processing (llv.md §4), and the corner closing
/// of §6.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConnectParams {
    /// Run CONNECT at all.
    pub enabled: bool,
    /// Environment length beyond each endpoint, along the segment (px).
    pub wl: f64,
    /// Environment half-width to each side of the segment (px).
    pub wd: f64,
    /// Largest direction difference of two segments that merge (degrees).
    pub max_angle_deg: f64,
    /// Segments shorter than this are dropped after merging (px).
    pub min_line_length: f64,
    /// Corner closing radius (px): endpoints of different lines within it move
    /// to the lines' intersection. 0 switches corner closing off.
    pub corner_radius: f64,
}

impl Default for ConnectParams {
    fn default() -> Self {
        ConnectParams {
            enabled: true,
            wl: 6.0,
            wd: 1.5,
            max_angle_deg: 3.0,
            min_line_length: 12.0,
            corner_radius: 5.0,
        }
    }
}

/// All LLV parameters, grouped as in the profile's `[llv.*]` tables.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    pub lens: LensParams,
    pub edges: EdgeParams,
    pub lines: LineParams,
    pub connect: ConnectParams,
}

/// The stage a parameter belongs to: changing it re-runs that stage and
/// everything after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Stage {
    Lens,
    Edges,
    Lines,
    Connect,
}

/// What kind of value a parameter holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Bool,
    Int,
    Float,
}

/// The description of one parameter.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// Dotted key, as in the profile and `--set`: `edges.per_region`.
    pub key: &'static str,
    pub kind: Kind,
    pub stage: Stage,
    pub unit: &'static str,
    pub min: f64,
    pub max: f64,
    /// The step of one `+`/`-` in the console (shift: ten steps).
    pub step: f64,
    pub doc: &'static str,
}

impl ParamSpec {
    /// The allowed range as a person reads it: `3 to 7`.
    pub fn range_text(&self) -> String {
        match self.kind {
            Kind::Bool => "true or false".to_string(),
            _ => format!("{} to {}", fmt_num(self.min), fmt_num(self.max)),
        }
    }
}

fn fmt_num(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

macro_rules! spec {
    ($key:literal, $kind:ident, $stage:ident, $unit:literal, $min:expr, $max:expr, $step:expr, $doc:literal) => {
        ParamSpec {
            key: $key,
            kind: Kind::$kind,
            stage: Stage::$stage,
            unit: $unit,
            min: $min,
            max: $max,
            step: $step,
            doc: $doc,
        }
    };
}

/// Every tunable LLV parameter, in the order the console shows them.
pub const PARAMS: &[ParamSpec] = &[
    spec!(
        "lens.enabled",
        Bool,
        Lens,
        "",
        0.0,
        1.0,
        1.0,
        "apply lens correction when the camera's .cdf has distortion"
    ),
    spec!(
        "edges.half_width",
        Int,
        Edges,
        "px",
        3.0,
        7.0,
        1.0,
        "Lee kernel half-width A; wider smooths more"
    ),
    spec!(
        "edges.floor",
        Float,
        Edges,
        "grey levels",
        0.0,
        255.0,
        0.5,
        "floor threshold T: weaker peaks are never edges"
    ),
    spec!(
        "edges.per_region",
        Int,
        Edges,
        "points",
        1.0,
        4096.0,
        1.0,
        "adaptive threshold M: strongest edge points kept per region"
    ),
    spec!(
        "edges.region_lines",
        Int,
        Edges,
        "lines",
        1.0,
        4096.0,
        1.0,
        "scan lines per adaptive-threshold region"
    ),
    spec!(
        "edges.noise_factor",
        Float,
        Edges,
        "× median",
        0.5,
        20.0,
        0.25,
        "several lightings: noise level tau as a multiple of the median |response|"
    ),
    spec!(
        "lines.max_gap",
        Int,
        Lines,
        "rows",
        1.0,
        20.0,
        1.0,
        "rows a line may bridge without an edge point"
    ),
    spec!(
        "lines.search_width",
        Float,
        Lines,
        "px",
        0.5,
        10.0,
        0.25,
        "half-width of the search window around the predicted point"
    ),
    spec!(
        "lines.min_length",
        Float,
        Lines,
        "px",
        0.0,
        1000.0,
        1.0,
        "extracted segments must be longer than this"
    ),
    spec!(
        "lines.min_scan_angle_deg",
        Float,
        Lines,
        "deg",
        0.0,
        45.0,
        0.5,
        "least angle between a line and the scan direction"
    ),
    spec!(
        "lines.min_response",
        Float,
        Lines,
        "grey levels",
        0.0,
        255.0,
        0.5,
        "lines whose mean |edge response| is below this are noise; 0 is off"
    ),
    spec!(
        "connect.enabled",
        Bool,
        Connect,
        "",
        0.0,
        1.0,
        1.0,
        "run CONNECT post-processing"
    ),
    spec!(
        "connect.wl",
        Float,
        Connect,
        "px",
        0.0,
        100.0,
        0.5,
        "environment length beyond each endpoint"
    ),
    spec!(
        "connect.wd",
        Float,
        Connect,
        "px",
        0.0,
        20.0,
        0.25,
        "environment half-width to each side"
    ),
    spec!(
        "connect.max_angle_deg",
        Float,
        Connect,
        "deg",
        0.0,
        45.0,
        0.25,
        "largest direction difference that still merges"
    ),
    spec!(
        "connect.min_line_length",
        Float,
        Connect,
        "px",
        0.0,
        1000.0,
        1.0,
        "merged segments shorter than this are dropped"
    ),
    spec!(
        "connect.corner_radius",
        Float,
        Connect,
        "px",
        0.0,
        50.0,
        0.5,
        "corner closing radius; 0 is off"
    ),
];

/// The spec of a dotted key, if it names a parameter.
pub fn spec(key: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.key == key)
}

impl Params {
    /// The value of a parameter as a number (bools are 0 and 1).
    pub fn get(&self, key: &str) -> Option<f64> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        Some(match key {
            "lens.enabled" => b(self.lens.enabled),
            "edges.half_width" => self.edges.half_width as f64,
            "edges.floor" => self.edges.floor,
            "edges.per_region" => self.edges.per_region as f64,
            "edges.region_lines" => self.edges.region_lines as f64,
            "edges.noise_factor" => self.edges.noise_factor,
            "lines.max_gap" => self.lines.max_gap as f64,
            "lines.search_width" => self.lines.search_width,
            "lines.min_length" => self.lines.min_length,
            "lines.min_scan_angle_deg" => self.lines.min_scan_angle_deg,
            "lines.min_response" => self.lines.min_response,
            "connect.enabled" => b(self.connect.enabled),
            "connect.wl" => self.connect.wl,
            "connect.wd" => self.connect.wd,
            "connect.max_angle_deg" => self.connect.max_angle_deg,
            "connect.min_line_length" => self.connect.min_line_length,
            "connect.corner_radius" => self.connect.corner_radius,
            _ => return None,
        })
    }

    /// Sets a parameter from a number, checking its range (and, for integer
    /// and boolean parameters, that the number is whole / 0 or 1).
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        let sp = spec(key).ok_or_else(|| ParamError::UnknownKey(key.to_string()))?;
        let whole = value == value.trunc();
        let bad = !value.is_finite()
            || value < sp.min
            || value > sp.max
            || (sp.kind != Kind::Float && !whole);
        if bad {
            return Err(ParamError::OutOfRange {
                key: sp.key,
                value,
                range: sp.range_text(),
            });
        }
        let u = value as u32;
        let on = value != 0.0;
        match key {
            "lens.enabled" => self.lens.enabled = on,
            "edges.half_width" => self.edges.half_width = u,
            "edges.floor" => self.edges.floor = value,
            "edges.per_region" => self.edges.per_region = u,
            "edges.region_lines" => self.edges.region_lines = u,
            "edges.noise_factor" => self.edges.noise_factor = value,
            "lines.max_gap" => self.lines.max_gap = u,
            "lines.search_width" => self.lines.search_width = value,
            "lines.min_length" => self.lines.min_length = value,
            "lines.min_scan_angle_deg" => self.lines.min_scan_angle_deg = value,
            "lines.min_response" => self.lines.min_response = value,
            "connect.enabled" => self.connect.enabled = on,
            "connect.wl" => self.connect.wl = value,
            "connect.wd" => self.connect.wd = value,
            "connect.max_angle_deg" => self.connect.max_angle_deg = value,
            "connect.min_line_length" => self.connect.min_line_length = value,
            "connect.corner_radius" => self.connect.corner_radius = value,
            _ => return Err(ParamError::UnknownKey(key.to_string())),
        }
        Ok(())
    }

    /// Parses `key=value` (as given to `--set`); `true`/`false` work for bools.
    pub fn set_str(&mut self, assignment: &str) -> Result<(), ParamError> {
        let (key, value) = assignment
            .split_once('=')
            .ok_or_else(|| ParamError::Syntax(assignment.to_string()))?;
        let (key, value) = (key.trim(), value.trim());
        let v = match value {
            "true" => 1.0,
            "false" => 0.0,
            _ => value.parse::<f64>().map_err(|_| ParamError::NotANumber {
                key: key.to_string(),
                value: value.to_string(),
            })?,
        };
        self.set(key, v)
    }

    /// Checks every parameter against its range; the first offender is named.
    pub fn validate(&self) -> Result<(), ParamError> {
        let mut copy = self.clone();
        for sp in PARAMS {
            let v = self.get(sp.key).unwrap_or(f64::NAN);
            copy.set(sp.key, v)?;
        }
        Ok(())
    }

    /// The earliest stage whose output differs between `self` and `other`
    /// (`None` when they are equal): re-run from there.
    pub fn first_changed_stage(&self, other: &Params) -> Option<Stage> {
        PARAMS
            .iter()
            .filter(|sp| self.get(sp.key) != other.get(sp.key))
            .map(|sp| sp.stage)
            .min()
    }

    /// The kernel half-width as the edge stage uses it, checked.
    pub fn half_width(&self) -> Result<usize, LlvError> {
        let a = self.edges.half_width;
        if !(3..=7).contains(&a) {
            return Err(LlvError::Param {
                name: "edges.half_width",
                value: a as f64,
                range: "3 to 7",
            });
        }
        Ok(a as usize)
    }
}

/// A parameter that cannot be set as asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error(
        "unknown parameter `{0}` (known: edges.per_region, lines.max_gap, … — see `vss params list`)"
    )]
    UnknownKey(String),
    #[error("parameter {key} = {value} is out of range: allowed {range}")]
    OutOfRange {
        key: &'static str,
        value: f64,
        range: String,
    },
    #[error("parameter {key}: `{value}` is not a number")]
    NotANumber { key: String, value: String },
    #[error("expected key=value, found `{0}`")]
    Syntax(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_and_accessors_agree() {
        let p = Params::default();
        p.validate().unwrap();
        for sp in PARAMS {
            let v = p.get(sp.key).expect(sp.key);
            let mut q = p.clone();
            q.set(sp.key, v).unwrap();
            assert_eq!(q, p, "{}", sp.key);
            assert!(q.set(sp.key, sp.max + 1.0).is_err(), "{}", sp.key);
        }
    }

    #[test]
    fn set_str_and_stages() {
        let mut p = Params::default();
        p.set_str("edges.per_region=12").unwrap();
        assert_eq!(p.edges.per_region, 12);
        assert!(p.set_str("edges.per_region=1.5").is_err());
        assert!(p.set_str("edges.half_width=9").is_err());
        assert!(p.set_str("nope=1").is_err());
        assert_eq!(
            Params::default().first_changed_stage(&p),
            Some(Stage::Edges)
        );
    }
}
