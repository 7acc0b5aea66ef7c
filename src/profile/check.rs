//! Loading a profile with the checks a person needs: TOML syntax, unknown
//! keys and wrong types (from serde, with the key found from the error's
//! span), LLV parameters out of their [`PARAMS`] ranges, and the cell's
//! consistency (lights, relay channels, lighting letters, sizes). Every error
//! names the file, the line and the key, and says what is allowed.

use std::ops::Range;
use std::path::Path;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::{GrabberKind, Profile, ProfileError, RelayKind};
use crate::llv::params::{PARAMS, spec};

/// Highest relay channel of the boards the cell uses.
pub const MAX_RELAY: u32 = 15;

/// One step of a key path: a table key or an array index.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Seg<'a> {
    Key(&'a str),
    Index(usize),
}

/// 1-based line of a byte offset.
pub(crate) fn line_of(text: &str, pos: usize) -> usize {
    let end = pos.min(text.len());
    text.as_bytes()
        .get(..end)
        .map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count())
        + 1
}

/// The deepest dotted key whose key or value holds byte `pos`.
fn key_at(t: &DeTable<'_>, pos: usize) -> Option<String> {
    for (k, v) in t.iter() {
        let name = k.get_ref().to_string();
        if let Some(deeper) = key_in_value(v, pos) {
            return Some(format!("{name}{deeper}"));
        }
        if k.span().contains(&pos) || v.span().contains(&pos) {
            return Some(name);
        }
    }
    None
}

fn key_in_value(v: &Spanned<DeValue<'_>>, pos: usize) -> Option<String> {
    match v.get_ref() {
        DeValue::Table(t) => key_at(t, pos).map(|k| format!(".{k}")),
        DeValue::Array(a) => a.iter().enumerate().find_map(|(i, el)| {
            if let Some(d) = key_in_value(el, pos) {
                Some(format!("[{i}]{d}"))
            } else {
                el.span().contains(&pos).then(|| format!("[{i}]"))
            }
        }),
        _ => None,
    }
}

/// The span of the key (for a table entry) or element (for an index) at
/// `path`, as far down the path as the file goes.
pub(crate) fn span_of(doc: &DeTable<'_>, path: &[Seg<'_>]) -> Option<Range<usize>> {
    let mut table = doc;
    let mut array: Option<&[Spanned<DeValue<'_>>]> = None;
    let mut best = None;
    for seg in path {
        let v = match (*seg, array) {
            (Seg::Key(k), None) => {
                let (key, v) = table.iter().find(|(key, _)| key.get_ref().as_ref() == k)?;
                best = Some(key.span());
                v
            }
            (Seg::Index(i), Some(a)) => {
                let v = a.get(i)?;
                best = Some(v.span());
                v
            }
            _ => return best,
        };
        array = None;
        match v.get_ref() {
            DeValue::Table(t) => table = t,
            DeValue::Array(a) => array = Some(&a[..]),
            _ => {}
        }
    }
    best
}

/// Text of a path: `lights[2].relay`.
fn path_text(path: &[Seg<'_>]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

struct Ctx<'a, 'd> {
    text: &'a str,
    doc: &'a DeTable<'d>,
    path: &'a Path,
}

impl Ctx<'_, '_> {
    /// An error at the line of `key` (or its nearest ancestor in the file).
    fn at(&self, key: &[Seg<'_>], message: String) -> ProfileError {
        let line = span_of(self.doc, key).map_or(1, |s| line_of(self.text, s.start));
        ProfileError::Invalid {
            path: self.path.to_path_buf(),
            line,
            message: format!("key `{}`: {message}", path_text(key)),
        }
    }
}

/// Parses `text` as a profile and runs every check.
pub(crate) fn parse_checked(text: &str, path: &Path) -> Result<Profile, ProfileError> {
    let invalid = |line: usize, message: String| ProfileError::Invalid {
        path: path.to_path_buf(),
        line,
        message,
    };
    let doc = DeTable::parse(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of(text, s.start));
        invalid(line, format!("not valid TOML: {}", e.message().trim()))
    })?;
    let doc = doc.get_ref();
    let prof: Profile = toml::from_str(text).map_err(|e| {
        let pos = e.span().map(|s| s.start);
        let line = pos.map_or(1, |p| line_of(text, p));
        let key = pos.and_then(|p| key_at(doc, p));
        let mut msg = e.message().trim().to_string();
        if let Some(k) = &key {
            if let Some(sp) = k.strip_prefix("llv.").and_then(spec) {
                msg.push_str(&format!(
                    "; allowed {}{} ({})",
                    sp.range_text(),
                    unit(sp.unit),
                    sp.doc
                ));
            } else if let Some(h) = cell_hint(k) {
                msg.push_str(&format!("; allowed {h}"));
            }
            msg = format!("key `{k}`: {msg}");
        }
        invalid(line, msg)
    })?;
    let cx = Ctx { text, doc, path };
    check_params(&prof, &cx)?;
    check_cell(&prof, &cx)?;
    Ok(prof)
}

/// What a cell key allows, for type errors (the ranges [`check_cell`]
/// enforces).
fn cell_hint(key: &str) -> Option<&'static str> {
    // `lights[2].relay` → `lights.relay`
    let mut k = String::with_capacity(key.len());
    let mut skip = false;
    for c in key.chars() {
        match c {
            '[' => skip = true,
            ']' => skip = false,
            _ if !skip => k.push(c),
            _ => {}
        }
    }
    Some(match k.as_str() {
        "name" | "lights.name" | "lighting.note" | "grabber.port" | "relay.port" => "a string",
        "grabber.baud" | "relay.baud" => "a whole number, 50 to 4000000 (bits/s)",
        "grabber.timeout_ms" | "relay.timeout_ms" => "a whole number, 1 to 600000 (ms)",
        "grabber.retries" => "a whole number, 0 to 100",
        "grabber.block" => "a whole number, 1 to 65536 (bytes)",
        "grabber.cameras" => "a list of camera ids or addresses, camera 1 first",
        "grabber.camera.pixel_format" => "\"Mono8\", \"Mono10\", \"Mono12\" or \"Mono16\"",
        "grabber.camera.exposure_us" => "a number, 1 to 60000000 (µs)",
        "grabber.camera.gain_db" => "a number, -50 to 100 (dB)",
        "grabber.camera.roi" => "four whole numbers [x, y, width, height] (px)",
        "grabber.camera.packet_size" => "a whole number, 576 to 65500 (bytes)",
        "relay.settle_ms" => "a whole number, 0 to 60000 (ms)",
        "lights.relay" => "a whole number, 0 to 15",
        "lights.position" => "three numbers [x, y, z] (mm)",
        "lighting.letter" => "one letter: a, b, c… in order",
        "lighting.on" => "a list of light names, e.g. [\"left-front\"]",
        "survey.dir" => "a folder name",
        "survey.cameras" => "a whole number, 1 to 64",
        "survey.cdf" => "a list of .cdf file names, camera 1 first",
        "sim.seed" => "a whole number, 0 or more",
        "sim.noise" => "a number, 0 to 100 (grey levels)",
        "sim.width" | "sim.height" => "a whole number, 16 to 4096 (px)",
        _ => return None,
    })
}

fn unit(u: &str) -> String {
    if u.is_empty() {
        String::new()
    } else {
        format!(" {u}")
    }
}

fn check_params(p: &Profile, cx: &Ctx<'_, '_>) -> Result<(), ProfileError> {
    for sp in PARAMS {
        let v = p.llv.get(sp.key).unwrap_or(f64::NAN);
        let mut q = crate::llv::Params::default();
        if q.set(sp.key, v).is_err() {
            let mut segs = vec![Seg::Key("llv")];
            segs.extend(sp.key.split('.').map(Seg::Key));
            return Err(cx.at(
                &segs,
                format!(
                    "{v} is out of range: allowed {}{} ({})",
                    sp.range_text(),
                    unit(sp.unit),
                    sp.doc
                ),
            ));
        }
    }
    Ok(())
}

fn check_cell(p: &Profile, cx: &Ctx<'_, '_>) -> Result<(), ProfileError> {
    use Seg::{Index as I, Key as K};
    if let Some(c) = p.relay.channels
        && ![1, 2, 4, 8, 16, 32].contains(&c)
    {
        return Err(cx.at(
            &[K("relay"), K("channels")],
            format!("{c} relays: a board has 1, 2, 4, 8, 16 or 32"),
        ));
    }
    // Lights: named, unique, on distinct channels 0–15.
    for (i, l) in p.lights.iter().enumerate() {
        if l.name.trim().is_empty() || l.name.chars().any(char::is_control) {
            return Err(cx.at(
                &[K("lights"), I(i), K("name")],
                "a light needs a name without control characters".into(),
            ));
        }
        let max_relay = p.relay.channels.map_or(MAX_RELAY, |c| c.saturating_sub(1));
        if l.relay > max_relay {
            return Err(cx.at(
                &[K("lights"), I(i), K("relay")],
                format!(
                    "relay channel {} is out of range: allowed 0 to {max_relay}{}",
                    l.relay,
                    if p.relay.channels.is_some() {
                        " (the board's [relay] channels)"
                    } else {
                        " (set [relay] channels for a larger board)"
                    }
                ),
            ));
        }
        if let Some((j, _)) = p
            .lights
            .iter()
            .enumerate()
            .take(i)
            .find(|(_, o)| o.name == l.name)
        {
            return Err(cx.at(
                &[K("lights"), I(i), K("name")],
                format!("light \"{}\" is defined twice (also lights[{j}])", l.name),
            ));
        }
        if let Some((j, _)) = p
            .lights
            .iter()
            .enumerate()
            .take(i)
            .find(|(_, o)| o.relay == l.relay)
        {
            return Err(cx.at(
                &[K("lights"), I(i), K("relay")],
                format!("relay channel {} is used twice (also by lights[{j}]); each light needs its own channel", l.relay),
            ));
        }
        if l.position
            .is_some_and(|pos| pos.iter().any(|v| !v.is_finite()))
        {
            return Err(cx.at(
                &[K("lights"), I(i), K("position")],
                "position must be three finite numbers (mm)".into(),
            ));
        }
    }
    // Lightings: a, b, c… in order, each `on` a defined light.
    if p.lighting.is_empty() {
        return Err(cx.at(
            &[K("lighting")],
            "at least one [[lighting]] is needed (letter = \"a\", on = [...])".into(),
        ));
    }
    if p.lighting.len() > 26 {
        return Err(cx.at(
            &[K("lighting")],
            format!(
                "{} lightings: at most 26 (letters a to z)",
                p.lighting.len()
            ),
        ));
    }
    for (i, l) in p.lighting.iter().enumerate() {
        let want = char::from(b'a' + i as u8);
        if l.letter != want {
            return Err(cx.at(
                &[K("lighting"), I(i), K("letter")],
                format!("lighting {} has letter {:?}; letters run a, b, c… in order without gaps, so expected {want:?}", i + 1, l.letter),
            ));
        }
        for (j, name) in l.on.iter().enumerate() {
            if !p.lights.iter().any(|x| &x.name == name) {
                let known: Vec<&str> = p.lights.iter().map(|x| x.name.as_str()).collect();
                return Err(cx.at(
                    &[K("lighting"), I(i), K("on")],
                    format!(
                        "light \"{name}\" is not defined; defined lights: {}",
                        if known.is_empty() {
                            "none".into()
                        } else {
                            known.join(", ")
                        }
                    ),
                ));
            }
            if l.on.iter().take(j).any(|x| x == name) {
                return Err(cx.at(
                    &[K("lighting"), I(i), K("on")],
                    format!("light \"{name}\" listed twice"),
                ));
            }
        }
    }
    // Hardware.
    let g = &p.grabber;
    if g.kind == GrabberKind::Vsg && g.port.trim().is_empty() {
        return Err(cx.at(
            &[K("grabber"), K("port")],
            "a vsg grabber needs its serial port (e.g. \"/dev/ttyUSB0\")".into(),
        ));
    }
    range(cx, &[K("grabber"), K("baud")], g.baud.into(), 50, 4_000_000)?;
    range(
        cx,
        &[K("grabber"), K("timeout_ms")],
        g.timeout_ms,
        1,
        600_000,
    )?;
    range(cx, &[K("grabber"), K("retries")], g.retries.into(), 0, 100)?;
    range(cx, &[K("grabber"), K("block")], g.block.into(), 1, 65_536)?;
    check_genicam(g, cx)?;
    let r = &p.relay;
    if r.kind != RelayKind::Simulated && r.port.trim().is_empty() {
        return Err(cx.at(
            &[K("relay"), K("port")],
            "a relay board needs its serial port (e.g. \"/dev/ttyACM0\")".into(),
        ));
    }
    range(cx, &[K("relay"), K("baud")], r.baud.into(), 50, 4_000_000)?;
    range(cx, &[K("relay"), K("timeout_ms")], r.timeout_ms, 1, 600_000)?;
    range(cx, &[K("relay"), K("settle_ms")], r.settle_ms, 0, 60_000)?;
    // Survey and simulated cell.
    range(
        cx,
        &[K("survey"), K("cameras")],
        p.survey.cameras.into(),
        1,
        64,
    )?;
    // Fewer files than cameras is allowed (cameras not yet calibrated get no
    // lens correction); more cannot be meant.
    if p.survey.cdf.len() > p.survey.cameras as usize {
        return Err(cx.at(
            &[K("survey"), K("cdf")],
            format!(
                "{} .cdf files for {} cameras; give at most one per camera, camera 1 first",
                p.survey.cdf.len(),
                p.survey.cameras
            ),
        ));
    }
    range(cx, &[K("sim"), K("width")], p.sim.width.into(), 16, 4096)?;
    range(cx, &[K("sim"), K("height")], p.sim.height.into(), 16, 4096)?;
    if !(0.0..=100.0).contains(&p.sim.noise) {
        return Err(cx.at(
            &[K("sim"), K("noise")],
            format!(
                "{} is out of range: allowed 0 to 100 grey levels",
                p.sim.noise
            ),
        ));
    }
    Ok(())
}

fn range(cx: &Ctx<'_, '_>, key: &[Seg<'_>], v: u64, lo: u64, hi: u64) -> Result<(), ProfileError> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(cx.at(key, format!("{v} is out of range: allowed {lo} to {hi}")))
    }
}

/// The `genicam` grabber's cameras and their settings.
fn check_genicam(g: &super::GrabberConfig, cx: &Ctx<'_, '_>) -> Result<(), ProfileError> {
    use Seg::{Index as I, Key as K};
    if g.kind == GrabberKind::Genicam && g.cameras.is_empty() {
        return Err(cx.at(
            &[K("grabber"), K("kind")],
            "a genicam grabber needs its cameras, e.g. cameras = [\"Aravis-Fake-GV01\"] \
             (the device id as Aravis names it, or the camera's address)"
                .into(),
        ));
    }
    for (i, c) in g.cameras.iter().enumerate() {
        if c.trim().is_empty() {
            return Err(cx.at(
                &[K("grabber"), K("cameras"), I(i)],
                format!("camera {} has an empty id", i + 1),
            ));
        }
        if g.cameras.iter().take(i).any(|x| x.trim() == c.trim()) {
            return Err(cx.at(
                &[K("grabber"), K("cameras"), I(i)],
                format!("camera \"{c}\" is listed twice"),
            ));
        }
    }
    if g.camera.len() > g.cameras.len().max(1) {
        return Err(cx.at(
            &[K("grabber"), K("camera"), I(g.cameras.len())],
            format!(
                "{} [[grabber.camera]] settings for {} cameras: entry N is for camera N",
                g.camera.len(),
                g.cameras.len()
            ),
        ));
    }
    for (i, s) in g.camera.iter().enumerate() {
        if let Some(f) = &s.pixel_format
            && !crate::formats::pixels::PIXEL_FORMATS.contains(&f.as_str())
        {
            return Err(cx.at(
                &[K("grabber"), K("camera"), I(i), K("pixel_format")],
                format!(
                    "pixel format \"{f}\" cannot be used; vss reads {}",
                    crate::formats::pixels::PIXEL_FORMATS.join(", ")
                ),
            ));
        }
        if let Some(e) = s.exposure_us
            && !(e.is_finite() && (1.0..=60_000_000.0).contains(&e))
        {
            return Err(cx.at(
                &[K("grabber"), K("camera"), I(i), K("exposure_us")],
                format!("exposure {e} µs is out of range: 1 to 60000000 µs"),
            ));
        }
        if let Some(d) = s.gain_db
            && !(d.is_finite() && (-50.0..=100.0).contains(&d))
        {
            return Err(cx.at(
                &[K("grabber"), K("camera"), I(i), K("gain_db")],
                format!("gain {d} dB is out of range: -50 to 100 dB"),
            ));
        }
        if let Some(b) = s.packet_size {
            range(
                cx,
                &[K("grabber"), K("camera"), I(i), K("packet_size")],
                b.into(),
                576,
                65_500,
            )?;
        }
        if let Some([_, _, w, h]) = s.roi
            && (w == 0 || h == 0 || w > 65_535 || h > 65_535)
        {
            return Err(cx.at(
                &[K("grabber"), K("camera"), I(i), K("roi")],
                format!(
                    "a region of {w} × {h} px: width and height are 1 to 65535 \
                     (a .img holds at most 65535 × 65535)"
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_of_offsets() {
        assert_eq!(line_of("a\nb\nc", 0), 1);
        assert_eq!(line_of("a\nb\nc", 2), 2);
        assert_eq!(line_of("a\nb\nc", 4), 3);
    }

    #[test]
    fn spans_find_keys() {
        let text = "[llv.edges]\nfloor = 1\nhalf_width = 4\n[[lights]]\nname = \"x\"\nrelay = 1\n[[lights]]\nname = \"y\"\nrelay = 2\n";
        let doc = DeTable::parse(text).unwrap();
        let s = span_of(
            doc.get_ref(),
            &[Seg::Key("llv"), Seg::Key("edges"), Seg::Key("half_width")],
        )
        .unwrap();
        assert_eq!(line_of(text, s.start), 3);
        let s = span_of(
            doc.get_ref(),
            &[Seg::Key("lights"), Seg::Index(1), Seg::Key("relay")],
        )
        .unwrap();
        assert_eq!(line_of(text, s.start), 9);
        assert_eq!(
            key_at(doc.get_ref(), s.start + 1).as_deref(),
            Some("lights[1].relay")
        );
    }
}
