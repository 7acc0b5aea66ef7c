//! `vss convert IN OUT`: grey images between the grabber's `.img`/`.imc` and
//! PNG, PGM, TIFF, BMP, and from JPEG photographs (formats chosen by
//! extension; JPEG is read, not written). PNG keeps an `.img`'s
//! comment and upper-left corner, so `.img → .png → .img` is exact. Notes
//! (colour reduced to grey, comment dropped) go to stderr; on any error
//! nothing is written.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;

use super::Global;
use crate::formats::imageio::{ImageKind, read_any_noted, write_any};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input image: .img, .imc, .png, .pgm, .tif, .tiff, .bmp, .jpg or .jpeg.
    pub input: PathBuf,
    /// Output image; the extension picks the format.
    pub output: PathBuf,
    /// Comment (image name) for the output; default: the input's comment,
    /// or the output's file name when the input has none.
    #[arg(long, value_name = "TEXT")]
    pub comment: Option<String>,
}

pub fn run(_g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let out_kind = ImageKind::of(&a.output).with_context(|| {
        format!(
            "{}: unknown output format; use .img, .imc, .png, .pgm, .tif, .tiff or .bmp",
            crate::text::path(&a.output)
        )
    })?;
    if !out_kind.writable() {
        anyhow::bail!(
            "{}: vss reads JPEG but does not write it (lossy); use .png, .pgm, .tif or .bmp",
            crate::text::path(&a.output)
        );
    }
    let (mut f, notes) = read_any_noted(&a.input)?;
    let in_kind = ImageKind::of(&a.input);
    for n in notes {
        errln!("vss: note: {}: {n}", crate::text::path(&a.input));
    }
    if let Some(c) = a.comment {
        f.comment = c;
    } else if f.comment.is_empty() && !in_kind.is_some_and(ImageKind::keeps_header) {
        // A name for the image, as the grabber writes one.
        f.comment = a
            .output
            .file_name()
            .map(|n| {
                n.to_string_lossy()
                    .chars()
                    .filter(|c| u32::from(*c) < 0x100)
                    .take(199)
                    .collect()
            })
            .unwrap_or_default();
    }
    if !out_kind.keeps_header() && (!f.comment.is_empty() || f.x0 != 0 || f.y0 != 0) {
        errln!(
            "vss: note: {}: this format keeps only the pixels (comment and upper-left corner dropped)",
            crate::text::path(&a.output)
        );
    }
    write_any(&a.output, &f)?;
    let (w, h) = f.image.size();
    outln!(
        "{} → {} ({w} × {h})",
        crate::text::path(&a.input),
        crate::text::path(&a.output)
    );
    Ok(ExitCode::SUCCESS)
}
