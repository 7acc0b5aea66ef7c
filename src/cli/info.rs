//! `vss info FILE...`: a few lines on any cell file — grey images (header,
//! size, comment with control characters removed, grey levels: all rows of
//! an image up to 16 Mi pixels, else rows spread over it, so the largest
//! `.img` costs one row of memory), `.cdf`
//! parameters with their status letters, line files (count, bounding box),
//! edge files, `.par` entries, `.ses` files with their session, and
//! profiles. A file that cannot be read is reported on stderr and the others
//! are still described; the exit code is 1 if any failed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::Global;
use crate::formats::names::{SessionName, VssFile};
use crate::formats::{cdf, edgefile, imageio, img, lines, par, sanitize, ses};
use crate::profile::Profile;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Files to describe (.img .imc .png .pgm .tif .bmp .cdf .lex .ldr .hpo
    /// .vpo .par .ses .toml).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

pub fn run(_g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let mut failed = 0;
    for (i, f) in a.files.iter().enumerate() {
        match describe(f) {
            Ok(text) => {
                if i > 0 {
                    outln!();
                }
                out!("{text}");
            }
            Err(e) => {
                errln!("vss: error: {e}");
                failed += 1;
            }
        }
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The description of one file (several lines, each ending in a newline).
pub fn describe(path: &Path) -> anyhow::Result<String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let shown = crate::text::path(path);
    let mut s = String::new();
    match ext.as_str() {
        "img" | "imc" => {
            // Header and samples: a 65535² image costs one row of memory.
            let (h, comment, stats) = img::read_summary(path)?;
            let kind = if ext == "imc" {
                "lens-corrected grey image"
            } else {
                "grey image"
            };
            writeln!(
                s,
                "{shown}: {kind} (ITEX .img), {} × {} pixels",
                h.width, h.height
            )?;
            writeln!(
                s,
                "  header: upper-left ({}, {}), file type {}, comment {} bytes, pixels at byte {}, {} bytes",
                h.x0,
                h.y0,
                h.file_type,
                h.comment_len,
                h.pixel_offset(),
                h.file_len()
            )?;
            writeln!(s, "  comment: \"{}\"", sanitize(&comment))?;
            let sampled = if stats.rows_read < stats.rows {
                format!(" (sampled from {} of {} rows)", stats.rows_read, stats.rows)
            } else {
                String::new()
            };
            writeln!(
                s,
                "  grey levels {} to {}, mean {:.1}{sampled}",
                stats.lo, stats.hi, stats.mean
            )?;
        }
        "png" | "pgm" | "pnm" | "tif" | "tiff" | "bmp" => {
            let (f, notes) = imageio::read_any_noted(path)?;
            let (w, h) = f.image.size();
            writeln!(s, "{shown}: {} image, {w} × {h} pixels", ext.to_uppercase())?;
            if f.x0 != 0 || f.y0 != 0 {
                writeln!(s, "  upper-left ({}, {})", f.x0, f.y0)?;
            }
            image_lines(&mut s, &f)?;
            for n in notes {
                writeln!(s, "  note: {n}")?;
            }
        }
        "cdf" => {
            let c = cdf::read_cdf(path)?;
            writeln!(
                s,
                "{shown}: camera description, {} parameters",
                c.params.len()
            )?;
            for p in &c.params {
                let vals: Vec<String> = p
                    .rows
                    .iter()
                    .map(|r| {
                        r.iter()
                            .map(|v| format!("{v}"))
                            .collect::<Vec<_>>()
                            .join(" ")
                    })
                    .collect();
                let known = if cdf::known_shape(&p.name).is_some() {
                    ""
                } else {
                    " (unknown to vss, kept)"
                };
                writeln!(
                    s,
                    "  {}={} {:<13} {}{known}",
                    sanitize(&p.name),
                    p.status.letter(),
                    format!("({})", p.status.describe()),
                    vals.join(" | ")
                )?;
            }
            match c.model() {
                Ok(m) => writeln!(
                    s,
                    "  camera model: f {} mm, centre ({}, {}) px, {}",
                    m.f,
                    m.cx,
                    m.cy,
                    if m.is_identity() {
                        "no lens distortion"
                    } else {
                        "with lens distortion"
                    }
                )?,
                Err(why) => writeln!(s, "  camera model: none, the description {why}")?,
            }
        }
        "lex" | "ldr" => {
            let segs = lines::read_lines(path)?;
            let what = if ext == "lex" {
                "extracted lines"
            } else {
                "post-processed lines"
            };
            writeln!(s, "{shown}: {what}, {} segments", segs.len())?;
            if let Some((lo, hi)) = lines::bounding_box(&segs) {
                let total: f64 = segs.iter().map(|g| g.length()).sum();
                writeln!(
                    s,
                    "  bounding box ({:.2}, {:.2}) to ({:.2}, {:.2}), total length {:.1} px",
                    lo.x, lo.y, hi.x, hi.y, total
                )?;
            }
        }
        "hpo" | "vpo" => {
            let e = edgefile::read_edges(path)?;
            let dir = match e.dir {
                Some(crate::llv::ScanDir::Horizontal) => "horizontal scan",
                Some(crate::llv::ScanDir::Vertical) => "vertical scan",
                None => "no direction",
            };
            writeln!(
                s,
                "{shown}: edge points ({dir}), {} points, image {} × {}",
                e.points.len(),
                e.width,
                e.height
            )?;
            if !e.points.is_empty() {
                let (lo, hi) = e
                    .points
                    .iter()
                    .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(p.response), hi.max(p.response))
                    });
                writeln!(s, "  response {lo:.1} to {hi:.1} grey levels")?;
            }
        }
        "par" => {
            let f = par::read_par(path)?;
            writeln!(
                s,
                "{shown}: parameter set \"{}\", {} entries",
                sanitize(&f.name),
                f.entries.len()
            )?;
            for (i, e) in f.entries.iter().enumerate() {
                writeln!(
                    s,
                    "  {i:>3} {} ({}) = {}",
                    sanitize(&e.name),
                    e.kind.letter(),
                    sanitize(&e.value)
                )?;
            }
        }
        "ses" => {
            let x = ses::read_ses(path)?;
            let stem = path
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default();
            writeln!(
                s,
                "{shown}: session \"{}\": {} images, {} cameras, {} lighting configurations",
                sanitize(&stem),
                x.images,
                x.cameras,
                x.lightings
            )?;
            if let Ok(name) = SessionName::new(&stem) {
                session_files(&mut s, path, &name, &x)?;
            }
        }
        "toml" => {
            // A profile or a manifest: the larger bound of the two.
            let text =
                crate::fsutil::read_input_text(path, crate::session::manifest::MAX_LEN as u64)
                    .map_err(|e| anyhow::anyhow!("{shown}: cannot read: {e}"))?;
            match Profile::from_toml(&text, path) {
                Ok(p) => profile_lines(&mut s, &shown, &p)?,
                // A session's manifest is TOML too; describe its shape.
                Err(e) => match toml::from_str::<toml::Table>(&text) {
                    Ok(t) if t.contains_key("session") && !t.contains_key("llv") => {
                        let parts: Vec<String> = t
                            .iter()
                            .map(|(k, v)| match v {
                                toml::Value::Array(a) => format!("{k} ({})", a.len()),
                                _ => k.clone(),
                            })
                            .collect();
                        writeln!(s, "{shown}: session manifest (TOML): {}", parts.join(", "))?;
                    }
                    _ => return Err(e.into()),
                },
            }
        }
        _ => anyhow::bail!(
            "{shown}: unknown kind of file; vss describes .img .imc .png .pgm .tif .bmp .cdf .lex .ldr .hpo .vpo .par .ses .toml"
        ),
    }
    let vss_name = path
        .file_name()
        .and_then(|n| n.to_str())
        .map(VssFile::parse);
    if let Some(Ok(v)) = vss_name {
        let light = v
            .lighting
            .map(|l| format!(", lighting {l}"))
            .unwrap_or_default();
        writeln!(
            s,
            "  VSS name: session \"{}\", image {}{light}",
            v.session, v.image
        )?;
        if let Some(w) = v.session.dos_warning(v.image) {
            writeln!(s, "  note: {w}")?;
        }
    }
    Ok(s)
}

fn image_lines(s: &mut String, f: &img::ImgFile) -> std::fmt::Result {
    let c = sanitize(&f.comment);
    writeln!(s, "  comment: \"{c}\"")?;
    let d = f.image.data();
    let (lo, hi) = d
        .iter()
        .fold((255u8, 0u8), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let mean = d.iter().map(|&v| f64::from(v)).sum::<f64>() / d.len().max(1) as f64;
    writeln!(s, "  grey levels {lo} to {hi}, mean {mean:.1}")
}

/// Which image files of a session stand beside its `.ses`.
fn session_files(
    s: &mut String,
    ses_path: &Path,
    name: &SessionName,
    x: &ses::Ses,
) -> std::fmt::Result {
    let dir = match ses_path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let Ok(rd) = std::fs::read_dir(&dir) else {
        return Ok(());
    };
    let mut grey = 0;
    let mut images = std::collections::BTreeSet::new();
    let mut lines = 0;
    for e in rd.flatten() {
        let n = e.file_name();
        let Some(n) = n.to_str() else { continue };
        let Ok(v) = VssFile::parse_in(n, name) else {
            continue;
        };
        match v.ext.as_str() {
            "img" => {
                grey += 1;
                images.insert(v.image);
            }
            "ldr" => lines += 1,
            _ => {}
        }
    }
    let expected = u64::from(x.images) * u64::from(x.lightings);
    writeln!(
        s,
        "  in {}: {grey} of {expected} grey images (for {} of {} image numbers), {lines} .ldr line files",
        crate::text::path(&dir),
        images.len(),
        x.images
    )
}

fn profile_lines(s: &mut String, shown: &str, p: &Profile) -> std::fmt::Result {
    writeln!(s, "{shown}: profile \"{}\"", sanitize(&p.name))?;
    let port = |k: &str, port: &str| {
        if port.is_empty() {
            k.to_string()
        } else {
            format!("{k} on {port}")
        }
    };
    writeln!(
        s,
        "  grabber {}, relay board {}",
        port(
            &format!("{:?}", p.grabber.kind).to_lowercase(),
            &p.grabber.port
        ),
        port(&format!("{:?}", p.relay.kind).to_lowercase(), &p.relay.port)
    )?;
    let lights: Vec<String> = p
        .lights
        .iter()
        .map(|l| format!("{} (relay {})", l.name, l.relay))
        .collect();
    writeln!(s, "  lights: {}", lights.join(", "))?;
    for l in &p.lighting {
        let on = if l.on.is_empty() {
            "all off".to_string()
        } else {
            l.on.join(" + ")
        };
        writeln!(s, "  lighting {}: {on}", l.letter)?;
    }
    writeln!(
        s,
        "  survey: {} cameras, {} .cdf files",
        p.survey.cameras,
        p.survey.cdf.len()
    )?;
    let def = crate::llv::Params::default();
    let changed: Vec<String> = crate::llv::params::PARAMS
        .iter()
        .filter(|sp| p.llv.get(sp.key) != def.get(sp.key))
        .map(|sp| format!("{} = {}", sp.key, p.llv.get(sp.key).unwrap_or(f64::NAN)))
        .collect();
    if changed.is_empty() {
        writeln!(s, "  llv: all parameters at their defaults")
    } else {
        writeln!(
            s,
            "  llv (changed from the defaults): {}",
            changed.join(", ")
        )
    }
}
