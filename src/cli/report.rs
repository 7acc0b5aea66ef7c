//! `vss report`: PostScript and SVG of a session (the survey report) or of
//! single files (`--ldr test1.ldr` as `ldr2ps`, `--img cube1a.img` as
//! `img2ps`).

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context as _, bail};

use super::Global;
use crate::formats;
use crate::fsutil::write_atomic_with;
use crate::llv::GreyImage;
use crate::report::{ps, survey, svg};
use crate::session::Session;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Session folder to report on. A file of it the report cannot show (a
    /// damaged .ldr, a missing image) is marked on the page, said on stderr,
    /// and the exit status is 3.
    pub dir: Option<PathBuf>,
    /// Only this image number of the session.
    #[arg(long, value_name = "K")]
    pub image: Option<u32>,
    /// Write PostScript here (default: NAME.ps in the current folder for a
    /// session, the input file with .ps for --ldr/--img).
    #[arg(long, value_name = "FILE")]
    pub ps: Option<PathBuf>,
    /// Write SVG here (for a session of several images: one file per image,
    /// FILE with the image number before the extension).
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// A line file (.lex/.ldr) to print as ldr2ps did.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["dir", "img"])]
    pub ldr: Option<PathBuf>,
    /// Grey images (.img/.imc/.png/.pgm/.tif/.bmp) to print as img2ps did,
    /// six per page. Repeat for more.
    #[arg(long, value_name = "FILE", conflicts_with = "dir")]
    pub img: Vec<PathBuf>,
    /// Picture size of a line file, WxH pixels (default: a grey image of the
    /// same name beside it, else 512x512 grown to hold every line).
    #[arg(long, value_name = "WxH", requires = "ldr")]
    pub size: Option<String>,
}

pub fn run(_g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    if let Some(ldr) = &a.ldr {
        return lines_report(ldr, &a);
    }
    if !a.img.is_empty() {
        return grey_report(&a);
    }
    let Some(dir) = &a.dir else {
        bail!("name a session folder, or --ldr FILE, or --img FILE (see `vss report --help`)");
    };
    session_report(dir, &a)
}

/// Writes `path` atomically, streaming the document into the temporary
/// file: nothing at `path` changes unless all of it was written.
fn write(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<&mut File>) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    write_atomic_with(path, fill).with_context(|| {
        format!(
            "cannot write {} ({})",
            crate::text::path(path),
            survey::on_disk(path)
        )
    })?;
    outln!("wrote {}", crate::text::path(path));
    Ok(())
}

fn lines_report(ldr: &Path, a: &Args) -> anyhow::Result<ExitCode> {
    let lines = formats::lines::read_lines(ldr)?;
    let (w, h) = match &a.size {
        Some(s) => parse_size(s)?,
        None => guess_size(ldr, &lines)?,
    };
    let caption = ldr.file_name().map_or_else(
        || crate::text::path(ldr),
        |n| n.to_string_lossy().into_owned(),
    );
    let ps_path =
        a.ps.clone()
            .or_else(|| a.svg.is_none().then(|| ldr.with_extension("ps")));
    if let Some(p) = ps_path {
        write(&p, |o| {
            ps::write_lines_page(o, &caption, &lines, w, h).map(drop)
        })?;
    }
    if let Some(p) = &a.svg {
        write(p, |o| {
            svg::write_lines_svg(o, &caption, &lines, w, h).map(drop)
        })?;
    }
    Ok(ExitCode::SUCCESS)
}

fn parse_size(s: &str) -> anyhow::Result<(usize, usize)> {
    let parsed = s
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 && w <= 65535 && h <= 65535 => Ok((w, h)),
        _ => bail!("--size {s:?}: expected WxH in pixels, e.g. 512x512"),
    }
}

/// The picture size of a line file: a grey image of the same name beside it
/// in any format vss reads (`test1.ldr` → `test1.img`, `test1a.img`, …,
/// `test1.png`, `photo.ldr` → `photo.jpg`, as `vss llv` names its outputs;
/// a JPEG's size after its EXIF orientation, as `vss llv` drew the lines),
/// else 512 × 512 grown to the lines' extent. Says which.
fn guess_size(ldr: &Path, lines: &[crate::llv::Segment]) -> anyhow::Result<(usize, usize)> {
    const EXTENSIONS: [&str; 9] = [
        "img", "imc", "png", "pgm", "tif", "tiff", "bmp", "jpg", "jpeg",
    ];
    let stem = ldr
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = ldr.parent().unwrap_or(Path::new("."));
    let names = std::iter::once(stem.clone()).chain(('a'..='z').map(|l| format!("{stem}{l}")));
    for name in names {
        for ext in EXTENSIONS {
            let p = dir.join(format!("{name}.{ext}"));
            if !p.is_file() {
                continue;
            }
            if let Ok((f, _)) =
                formats::imageio::read_any_sized(&p, crate::report::check_picture_size)
            {
                let (w, h) = f.image.size();
                outln!("picture {w} × {h}, the size of {}", crate::text::path(&p));
                return Ok((w.max(1), h.max(1)));
            }
        }
    }
    let (mut w, mut h) = (512.0f64, 512.0f64);
    if let Some((_, max)) = formats::lines::bounding_box(lines) {
        w = w.max(max.x.ceil() + 1.0);
        h = h.max(max.y.ceil() + 1.0);
    }
    let (w, h) = (w.min(65535.0) as usize, h.min(65535.0) as usize);
    outln!(
        "picture {w} × {h}: no grey image named {stem}.* beside it, so 512 × 512 grown to hold \
         every line (--size WxH gives it)"
    );
    Ok((w, h))
}

fn grey_report(a: &Args) -> anyhow::Result<ExitCode> {
    let mut images: Vec<(String, GreyImage)> = Vec::new();
    // Each picture, and all of them together, within what a report draws:
    // checked from each header before its pixels are read (a 20000²
    // image cost 2 GB and a 774 MB PostScript file).
    let mut total = 0usize;
    for p in &a.img {
        let (f, _) = formats::imageio::read_any_sized(p, |w, h| {
            crate::report::check_picture_size(w, h)?;
            let all = total.saturating_add(w.saturating_mul(h));
            if all > crate::report::MAX_PICTURE_PIXELS {
                return Err(anyhow::anyhow!(
                    "with it the report would draw {all} pixels, more than the {} a report \
                     draws in all: report fewer or smaller images",
                    crate::report::MAX_PICTURE_PIXELS
                ));
            }
            Ok(())
        })?;
        total += f.image.width() * f.image.height();
        let name = p.file_name().map_or_else(
            || crate::text::path(p),
            |n| n.to_string_lossy().into_owned(),
        );
        images.push((name, f.image));
    }
    let first = a.img.first().cloned().unwrap_or_default();
    let ps_path =
        a.ps.clone()
            .or_else(|| a.svg.is_none().then(|| first.with_extension("ps")));
    if let Some(p) = ps_path {
        let refs: Vec<(&str, &GreyImage)> = images.iter().map(|(n, i)| (n.as_str(), i)).collect();
        let title = images.first().map_or("", |(n, _)| n.as_str());
        write(&p, |o| ps::write_grey_page(o, title, &refs).map(drop))?;
    }
    if let Some(p) = &a.svg {
        for (i, (name, img)) in images.iter().enumerate() {
            let path = if images.len() == 1 {
                p.clone()
            } else {
                survey::numbered(p, i as u32 + 1)
            };
            write(&path, |o| svg::write_grey_svg(o, name, img).map(drop))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn session_report(dir: &Path, a: &Args) -> anyhow::Result<ExitCode> {
    let s = Session::inspect(dir)?;
    if s.manifest().image.is_empty() {
        errln!("vss: note: session {} has no images yet", s.name());
    }
    let targets = survey::Targets {
        ps: a.ps.clone().or_else(|| {
            a.svg
                .is_none()
                .then(|| PathBuf::from(format!("{}.ps", s.name())))
        }),
        svg: a.svg.clone(),
    };
    let written = survey::write(&s, a.image, &targets).map_err(|e| match e.on_disk() {
        // Which file is still the old one.
        Some(old) => anyhow::anyhow!("{e} ({old})"),
        None => e.into(),
    })?;
    for p in &written.files {
        outln!("wrote {}", crate::text::path(p));
    }
    if written.problems.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    // Written whole, but not all the session's files are in it: said, and
    // an exit status of its own, so a script does not take it as complete.
    for p in &written.problems {
        errln!("vss: warning: {p}");
    }
    errln!(
        "vss: warning: the report is written, but {} file(s) of session {} are not in it \
         (marked on its pages); exit status {INCOMPLETE}",
        written.problems.len(),
        s.name()
    );
    Ok(ExitCode::from(INCOMPLETE))
}

/// The exit status of a session report written whole but marking files it
/// could not show (a damaged `.ldr`, a missing image): not 1, an error that
/// wrote nothing, nor 2, a mistake in the command line.
pub const INCOMPLETE: u8 = 3;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_or_explain() {
        assert_eq!(parse_size("640x480").unwrap(), (640, 480));
        assert!(parse_size("640").unwrap_err().to_string().contains("WxH"));
        assert!(parse_size("0x5").is_err());
    }
}
