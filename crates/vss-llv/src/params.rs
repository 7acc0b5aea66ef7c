//! Every parameter an operator can tune in the LLV stages (spec/llv.md), with
//! its default, unit, allowed range and a one-line description — one table
//! ([`PARAMS`]) that the profile loader, `--set key=value`, the parameter-file
//! import/export, the console's parameter panel and the automatic search all
//! read.

use serde::{Deserialize, Serialize};

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

/// A parameter value as an operator types it: integers without a
/// fraction, others with at most four decimals, never `-0`.
pub fn fmt_value(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    if v == v.trunc() && v.abs() < 1e12 {
        format!("{}", v as i64)
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.to_string() }
    }
}

fn fmt_num(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

/// How a field's Rust type maps to a parameter's number (bools are 0 and 1).
trait Value: Copy {
    const KIND: Kind;
    fn to_f64(self) -> f64;
    /// From a number already checked against the range and kind.
    fn from_f64(v: f64) -> Self;
}

impl Value for bool {
    const KIND: Kind = Kind::Bool;
    fn to_f64(self) -> f64 {
        if self { 1.0 } else { 0.0 }
    }
    fn from_f64(v: f64) -> Self {
        v != 0.0
    }
}

impl Value for u32 {
    const KIND: Kind = Kind::Int;
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn from_f64(v: f64) -> Self {
        v as u32
    }
}

impl Value for f64 {
    const KIND: Kind = Kind::Float;
    fn to_f64(self) -> f64 {
        self
    }
    fn from_f64(v: f64) -> Self {
        v
    }
}

/// Declares every parameter once: its group's struct and field (with the
/// field's doc), its default, and its row of [`PARAMS`] (unit, range, step
/// of a console key press, the one-line description). The key is
/// `group.field`, the kind follows from the field's type, the stage from the
/// group. [`Params::get`] and [`Params::set`] are generated from the same
/// rows, so a parameter cannot be in the struct and missing from the table.
macro_rules! params {
    ($(
        $(#[$sdoc:meta])*
        $group:ident: $Struct:ident, $Stage:ident {
            $(
                $(#[$fdoc:meta])*
                $field:ident: $ty:ty = $default:expr,
                    $unit:literal, $min:literal ..= $max:literal, step $step:literal, $doc:literal;
            )*
        }
    )*) => {
        $(
            $(#[$sdoc])*
            #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
            #[serde(deny_unknown_fields, default)]
            pub struct $Struct {
                $( $(#[$fdoc])* pub $field: $ty, )*
            }

            impl Default for $Struct {
                fn default() -> Self {
                    $Struct { $( $field: $default, )* }
                }
            }
        )*

        /// All LLV parameters, grouped as in the profile's `[llv.*]` tables.
        #[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields, default)]
        pub struct Params {
            $( pub $group: $Struct, )*
        }

        /// Every tunable LLV parameter, in the order the console shows them.
        pub const PARAMS: &[ParamSpec] = &[
            $($(
                ParamSpec {
                    key: concat!(stringify!($group), ".", stringify!($field)),
                    kind: <$ty as Value>::KIND,
                    stage: Stage::$Stage,
                    unit: $unit,
                    min: $min,
                    max: $max,
                    step: $step,
                    doc: $doc,
                },
            )*)*
        ];

        impl Params {
            /// The value of a parameter as a number (bools are 0 and 1).
            pub fn get(&self, key: &str) -> Option<f64> {
                $($(
                    if key == concat!(stringify!($group), ".", stringify!($field)) {
                        return Some(Value::to_f64(self.$group.$field));
                    }
                )*)*
                None
            }

            /// Stores an already checked value.
            fn store(&mut self, key: &str, value: f64) {
                $($(
                    if key == concat!(stringify!($group), ".", stringify!($field)) {
                        self.$group.$field = <$ty as Value>::from_f64(value);
                        return;
                    }
                )*)*
            }
        }
    };
}

params! {
    /// Lens correction (llv.md §1, lens.md).
    lens: LensParams, Lens {
        /// Apply lens correction when a `.cdf` with distortion is given.
        enabled: bool = true,
            "", 0.0..=1.0, step 1.0,
            "apply lens correction when the camera's .cdf has distortion";
    }

    /// Lee's edge detector and the adaptive threshold (llv.md §2).
    edges: EdgeParams, Edges {
        /// Kernel half-width `A` (pixels), 3–7.
        half_width: u32 = 3,
            "px", 3.0..=7.0, step 1.0,
            "Lee kernel half-width A; wider smooths more";
        /// Floor threshold `T` (grey levels): no peak at or below it is kept.
        floor: f64 = 2.0,
            "grey levels", 0.0..=255.0, step 0.5,
            "floor threshold T: weaker peaks are never edges";
        /// `M`: edge pixels kept per region by the adaptive threshold.
        per_region: u32 = 4096,
            "points", 1.0..=4096.0, step 1.0,
            "adaptive threshold M: strongest edge points kept per region";
        /// Scan lines per region of the adaptive threshold (1 = one scan line).
        region_lines: u32 = 1,
            "lines", 1.0..=4096.0, step 1.0,
            "scan lines per adaptive-threshold region";
        /// Edge points must exceed this many times the noise scale of the
        /// response in their tile (its robust standard deviation, estimated
        /// from the image; `edges/noise.rs`). 0 switches the test off.
        /// Several lightings: sigmas of the noise model of their combined
        /// response (`photometric.rs`), which means the same.
        noise_sigmas: f64 = 2.5,
            "σ", 0.0..=20.0, step 0.25,
            "edge points must beat this many noise sigmas of their tile";
        /// The sensor's noise, from the image's least textured tiles: every
        /// tile's noise scale is raised to this percentile of the tiles'
        /// scales (a flat sky or a JPEG's smooth gradient does not set a
        /// threshold below the camera's noise) and capped at `noise_cap`
        /// times it (gravel does not hide the edges in it;
        /// `edges/noise.rs`). 0 keeps each tile's own scale.
        noise_percentile: f64 = 25.0,
            "%", 0.0..=100.0, step 5.0,
            "tiles' noise raised to this percentile of the image's; 0 is off";
        /// Images whose noise (Immerkær's estimate, `pipeline::noise_level`)
        /// is at least this many grey levels take `half_width + 1`, and
        /// those twice as noisy no orientation test (`lines.min_aligned`): a narrow
        /// kernel keeps close parallel edges apart in a clean photograph, a
        /// wider one averages more noise. 0 is off.
        noisy_sigma: f64 = 4.0,
            "grey levels", 0.0..=255.0, step 0.5,
            "images at least this noisy take half_width + 1; 0 is off";
        /// With `noise_percentile`: no tile's noise scale above this many
        /// times that percentile. 0: no cap.
        noise_cap: f64 = 2.0,
            "×", 0.0..=100.0, step 0.25,
            "tiles' noise capped at this multiple of the percentile; 0 is off";
        /// Threads for the two scan directions (edges and lines; 1 or 2).
        /// The results are the same.
        threads: u32 = 1,
            "threads", 1.0..=2.0, step 1.0,
            "threads for the two scan directions; the results are the same";
        /// Retired: the photometric combination (llv.md §2.6) once took
        /// this multiple of each image's median |response| off its term;
        /// it now takes nothing off (`photometric.rs`). Kept so that older
        /// profiles, sessions and `.par` files read; it has no effect.
        noise_factor: f64 = 5.0,
            "× median", 0.5..=20.0, step 0.25,
            "retired (no effect): several lightings take no noise level off";
    }

    /// The line extractor (llv.md §3).
    lines: LineParams, Lines {
        /// Rows (columns) a line may skip without an edge point.
        max_gap: u32 = 3,
            "rows", 1.0..=20.0, step 1.0,
            "rows a line may bridge without an edge point";
        /// Half-width of the search window around the predicted point (px).
        search_width: f64 = 2.0,
            "px", 0.5..=10.0, step 0.25,
            "half-width of the search window around the predicted point";
        /// Segments not longer than this are dropped (px).
        min_length: f64 = 8.0,
            "px", 0.0..=1000.0, step 1.0,
            "extracted segments must be longer than this";
        /// Minimum angle between a line and the scan direction (degrees; π/8 = 22.5°).
        min_scan_angle_deg: f64 = 22.5,
            "deg", 0.0..=45.0, step 0.5,
            "least angle between a line and the scan direction";
        /// Line significance (grey levels): a segment whose points' mean
        /// |response| is below this is dropped. Off by default: the
        /// a-contrario test (`log_nfa`) measures significance against the
        /// image's own noise instead. 0 switches it off.
        min_response: f64 = 0.0,
            "grey levels", 0.0..=255.0, step 0.5,
            "lines whose mean |edge response| is below this are noise; 0 is off";
        /// Points a line takes after its start must exceed this many noise
        /// sigmas of their tile (fewer than an edge point needs: a weak
        /// stretch of an edge is followed once the edge is found).
        track_sigmas: f64 = 1.5,
            "σ", 0.0..=20.0, step 0.25,
            "points a line follows must beat this many noise sigmas";
        /// A-contrario significance: a segment is kept when noise alone
        /// would give fewer than `10^log_nfa` segments as good in the image
        /// (`lines/nfa.rs`). 0: one false segment per image at most.
        log_nfa: f64 = 0.0,
            "log10", -20.0..=20.0, step 1.0,
            "keep segments whose log10 number of false alarms is below this";
        /// Gradient-orientation agreement: a line is kept when the image's
        /// gradient is within 22.5° of its normal at this fraction of its
        /// pixels (`lines/align.rs`: texture is not noise). 0 is off.
        min_aligned: f64 = 0.9,
            "fraction", 0.0..=1.0, step 0.1,
            "lines need the gradient across them at this fraction of their pixels; 0 is off";
        /// Experimental: draw edge chains from anchors on both responses
        /// (`lines/draw.rs`) instead of tracking each scan direction.
        draw: bool = false,
            "", 0.0..=1.0, step 1.0,
            "draw edge chains from anchors instead of the two trackers (experimental)";
    }

    /// CONNECT, the automatic post-processing (llv.md §4), and the corner closing
    /// of §6.
    connect: ConnectParams, Connect {
        /// Run CONNECT at all.
        enabled: bool = true,
            "", 0.0..=1.0, step 1.0,
            "run CONNECT post-processing";
        /// Environment length beyond each endpoint, along the segment (px).
        wl: f64 = 6.0,
            "px", 0.0..=100.0, step 0.5,
            "environment length beyond each endpoint";
        /// Environment half-width to each side of the segment (px). 1 px
        /// keeps close parallel edges (window mullions, plate pairs 2–3 px
        /// apart) from merging; 1.5 merged them (docs/accuracy.md).
        wd: f64 = 1.0,
            "px", 0.0..=20.0, step 0.25,
            "environment half-width to each side";
        /// Largest direction difference of two segments that merge (degrees).
        max_angle_deg: f64 = 3.0,
            "deg", 0.0..=45.0, step 0.25,
            "largest direction difference that still merges";
        /// Segments shorter than this are dropped after merging (px).
        min_line_length: f64 = 12.0,
            "px", 0.0..=1000.0, step 1.0,
            "merged segments shorter than this are dropped";
        /// A line shorter than `min_line_length` is kept when its points
        /// fix its direction within this many degrees (`connect.rs`,
        /// `long_enough`): a short edge the image shows clearly (a brick, a
        /// window's corner) stays, a short noise track does not
        /// (docs/accuracy.md). Not in a noisy image (`edges.noisy_sigma`),
        /// where a dozen points' scatter says too little. 0 is off: the
        /// spec's rule alone.
        short_line_deg: f64 = 2.0,
            "deg", 0.0..=10.0, step 0.25,
            "shorter lines kept when their points fix their direction within this; 0 is off";
        /// Corner closing radius (px): endpoints of different lines within it move
        /// to the lines' intersection. 0 switches corner closing off.
        corner_radius: f64 = 5.0,
            "px", 0.0..=50.0, step 0.5,
            "corner closing radius; 0 is off";
        /// Refit each line on the image along its normal after CONNECT
        /// (`refine.rs`); lines from edge files alone are not refitted.
        refine: bool = true,
            "", 0.0..=1.0, step 1.0,
            "refit each line on the image across it after CONNECT";
    }
}

/// The spec of a dotted key, if it names a parameter.
pub fn spec(key: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.key == key)
}

impl Params {
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
        self.store(sp.key, value);
        Ok(())
    }

    /// Parses `key=value` (as given to `--set`); `true`/`false` work for bools.
    pub fn set_str(&mut self, assignment: &str) -> Result<(), ParamError> {
        let (key, value) = assignment
            .split_once('=')
            .ok_or_else(|| ParamError::Syntax(assignment.to_string()))?;
        let (key, value) = (key.trim(), value.trim());
        // The key first: a typo in it is named as such, whatever the value.
        let sp = spec(key).ok_or_else(|| ParamError::UnknownKey(key.to_string()))?;
        let v = match value {
            "true" => 1.0,
            "false" => 0.0,
            _ => value.parse::<f64>().map_err(|_| ParamError::NotANumber {
                key: key.to_string(),
                value: value.to_string(),
                expected: match sp.kind {
                    Kind::Bool => "true or false",
                    _ => "a number",
                },
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
    #[error("parameter {key}: `{value}` is not {expected}")]
    NotANumber {
        key: String,
        value: String,
        expected: &'static str,
    },
    #[error("expected key=value, found `{0}`")]
    Syntax(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_as_typed() {
        assert_eq!(fmt_value(4.0), "4");
        assert_eq!(fmt_value(2.25), "2.25");
        assert_eq!(fmt_value(1.0 / 3.0), "0.3333");
        assert_eq!(fmt_value(-0.0), "0");
        assert_eq!(fmt_value(-0.00001), "0");
        assert_eq!(fmt_value(-1.5), "-1.5");
    }

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

    /// Every field the profile can hold (serde's view of the structs) is a
    /// row of the table, and every row a field.
    #[test]
    fn every_field_is_a_row() {
        let v = serde_json::to_value(Params::default()).unwrap();
        let mut fields: Vec<String> = v
            .as_object()
            .unwrap()
            .iter()
            .flat_map(|(g, t)| {
                t.as_object()
                    .unwrap()
                    .keys()
                    .map(move |f| format!("{g}.{f}"))
            })
            .collect();
        let mut keys: Vec<String> = PARAMS.iter().map(|p| p.key.to_string()).collect();
        fields.sort();
        keys.sort();
        assert_eq!(fields, keys);
        assert_eq!(spec("edges.half_width").unwrap().kind, Kind::Int);
        assert_eq!(spec("lens.enabled").unwrap().kind, Kind::Bool);
        assert_eq!(spec("connect.wd").unwrap().stage, Stage::Connect);
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
