//! `vss llv IMAGE...`: runs lens correction, edges, line extraction and
//! CONNECT on grey images and writes `.imc` (with `--cdf`), `.hpo`, `.vpo`,
//! `.lex` and `.ldr`; `vss llv --from-edges STEM.hpo STEM.vpo` re-runs the
//! line stages from saved edge files alone.
//!
//! Images of one view under several lightings (`cube1a.img cube1b.img`: the
//! same stem but for the lighting letter, formats.md §1) are ONE input to the
//! photometric pipeline and give `cube1.hpo` etc.; other images are
//! processed one by one. Which of them is the ambient frame is the profile's
//! rule (`session::FrameRule`, as for the console and `vss session redo`),
//! unless `--ambient IMG` names one; the stages run through the same
//! `session::Runner`. A failing input is reported on stderr and the
//! others still run; the exit code is 1 if any failed.
//!
//! `--auto lines=200` (or `--auto clean`) first searches the parameters for
//! that target on each input (`llv::auto`), prints what it changed, and then
//! runs with the proposal.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use serde_json::json;

use super::Global;
use crate::formats::names::VssFile;
use crate::formats::{cdf, edgefile, imageio, img::ImgFile, lines as linefile};
use crate::llv::auto::{self, AutoResult, Target};
use crate::llv::lens::CameraModel;
use crate::llv::params::Stage;
use crate::llv::pipeline::{Saved, StageOutputs};
use crate::llv::{GreyImage, Params};
use crate::profile::Profile;
use crate::session::{FrameRule, Runner};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Grey images (.img .imc .png .pgm .tif .bmp .jpg); lightings of one view
    /// (cube1a.img cube1b.img) are combined.
    #[arg(required_unless_present = "from_edges", conflicts_with = "from_edges")]
    pub images: Vec<PathBuf>,
    /// Camera description: lens-correct the images and write .imc files.
    #[arg(long, value_name = "CAMERA.cdf")]
    pub cdf: Option<PathBuf>,
    /// Lens-correct with camera N's description as the profile gives it
    /// (its `.cdf` file, or the built-in cell's own), and write .imc files.
    #[arg(long, value_name = "N", conflicts_with = "cdf")]
    pub camera: Option<u32>,
    /// Change a parameter for this run: --set edges.per_region=12 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Directory for the outputs (default: beside each input).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print one JSON object per image instead of text.
    #[arg(long)]
    pub json: bool,
    /// An image taken with only ambient light, subtracted from every lit image.
    #[arg(long, value_name = "IMG")]
    pub ambient: Option<PathBuf>,
    /// Re-run line extraction and CONNECT from STEM.hpo STEM.vpo.
    #[arg(long, num_args = 2, value_names = ["STEM.hpo", "STEM.vpo"])]
    pub from_edges: Option<Vec<PathBuf>>,
    /// Search the edge, line and CONNECT parameters for a target first and
    /// run with the result: `lines=200` (about that many lines) or `clean`
    /// (the fewest lines that keep the long edges). Prints what it changed.
    #[arg(long, value_name = "TARGET", conflicts_with = "from_edges")]
    pub auto: Option<Target>,
}

/// One input of the pipeline: the images of one view and the output stem.
#[derive(Debug)]
struct Group {
    stem: String,
    dir: PathBuf,
    files: Vec<PathBuf>,
    /// The lighting letter of each file (VSS names), or none (one file).
    letters: Vec<Option<char>>,
}

/// Groups image paths into views, in order of first appearance.
fn group(paths: &[PathBuf]) -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    let mut index: HashMap<(PathBuf, String), usize> = HashMap::new();
    for p in paths {
        let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let parsed = VssFile::parse(&name).ok().filter(|f| f.lighting.is_some());
        let stem = match &parsed {
            Some(f) => format!("{}{}", f.session, f.image),
            None => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "image".to_string()),
        };
        let letter = parsed.as_ref().and_then(|f| f.lighting);
        match (parsed.is_some(), index.get(&(dir.clone(), stem.clone()))) {
            (true, Some(&k)) => {
                groups[k].files.push(p.clone());
                groups[k].letters.push(letter);
            }
            _ => {
                if parsed.is_some() {
                    index.insert((dir.clone(), stem.clone()), groups.len());
                }
                groups.push(Group {
                    stem,
                    dir,
                    files: vec![p.clone()],
                    letters: vec![letter],
                });
            }
        }
    }
    for g in &mut groups {
        let mut both: Vec<(PathBuf, Option<char>)> =
            g.files.drain(..).zip(g.letters.drain(..)).collect();
        both.sort_by_key(|(f, _)| f.file_name().map(|n| n.to_os_string()));
        (g.files, g.letters) = both.into_iter().unzip();
    }
    groups
}

fn params(profile: &Profile, a: &Args) -> anyhow::Result<Params> {
    let mut p = profile.llv.clone();
    for s in &a.set {
        p.set_str(s).with_context(|| format!("--set {s}"))?;
    }
    p.validate()?;
    Ok(p)
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let p = params(&profile, &a)?;
    if let Some(out) = &a.out {
        std::fs::create_dir_all(out).with_context(|| {
            format!(
                "{}: cannot create the output directory",
                crate::text::path(out)
            )
        })?;
    }
    if let Some(files) = &a.from_edges {
        let [hpo, vpo] = files.as_slice() else {
            bail!("--from-edges needs two files: STEM.hpo STEM.vpo");
        };
        let r = from_edges(hpo, vpo, &profile, &a, &p);
        return finish(r.map(|()| 0));
    }
    let lacks = |shown: &dyn std::fmt::Display, why: String| {
        anyhow::anyhow!("{shown}: the camera description {why}: cannot correct the lens")
    };
    let camera = match (&a.cdf, a.camera) {
        (Some(path), _) => Some((
            cdf::read_cdf(path)?
                .model()
                .map_err(|why| lacks(&crate::text::path(path), why))?,
            path.clone(),
        )),
        // The one owner of a camera's description (as the console uses).
        (None, Some(cam)) => {
            let shown = profile.cdf_shown(cam).unwrap_or_default();
            let c = profile.camera_cdf(cam)?.with_context(|| {
                format!("the profile names no .cdf for camera {cam} ([survey] cdf)")
            })?;
            Some((
                c.model().map_err(|why| lacks(&shown, why))?,
                PathBuf::from(shown),
            ))
        }
        (None, None) => None,
    };
    // An ambient image given by name is subtracted from every image given;
    // else the profile's rule picks it among the lightings of one view.
    let (rule, ambient) = match &a.ambient {
        Some(path) => (
            FrameRule::default(),
            Some((path.clone(), imageio::read_any(path)?.image)),
        ),
        None => (FrameRule::of_profile(&profile), None),
    };
    // One-shot runs: one scan direction's buffers at a time.
    let mut runner = Runner::lean();
    let mut failed = 0;
    for grp in group(&a.images) {
        if let Err(e) = run_group(
            &grp,
            &profile,
            &a,
            &p,
            camera.as_ref(),
            &rule,
            ambient.as_ref(),
            &mut runner,
        ) {
            if super::is_broken_pipe(&e) {
                return Err(e);
            }
            errln!("vss: error: {}: {e:#}", crate::text::path(&grp.stem));
            failed += 1;
        }
    }
    finish(Ok(failed))
}

fn finish(r: anyhow::Result<usize>) -> anyhow::Result<ExitCode> {
    Ok(if r? == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn out_path(a: &Args, dir: &Path, name: &str) -> PathBuf {
    a.out.as_deref().unwrap_or(dir).join(name)
}

#[allow(clippy::too_many_arguments)]
fn run_group(
    grp: &Group,
    profile: &Profile,
    a: &Args,
    p: &Params,
    camera: Option<&(CameraModel, PathBuf)>,
    rule: &FrameRule,
    ambient: Option<&(PathBuf, GreyImage)>,
    runner: &mut Runner,
) -> anyhow::Result<()> {
    let files: Vec<ImgFile> = grp
        .files
        .iter()
        .map(|f| {
            // The size from the header, before the pixels are read.
            let (img, notes) = imageio::read_any_sized(f, crate::llv::image::check_stage_size)?;
            for n in notes {
                errln!("vss: note: {}: {n}", crate::text::path(f));
            }
            Ok::<_, crate::formats::FormatError>(img)
        })
        .collect::<Result<_, _>>()?;
    // Sizes first: a lens map is made for the size before the stages run.
    for (path, f) in grp.files.iter().zip(&files) {
        f.image
            .check_stage_size()
            .with_context(|| crate::text::path(path))?;
    }
    // The lightings of one view and the ambient image are one picture each:
    // a file of another size is named (the stages said only "image sizes
    // differ", without the files).
    let ambient_size = ambient.map(|(path, img)| (path.as_path(), img));
    let sized = grp
        .files
        .iter()
        .map(PathBuf::as_path)
        .zip(files.iter().map(|f| &f.image));
    let mut sized = sized.chain(ambient_size);
    if let Some((first, img)) = sized.next() {
        let size = (img.width(), img.height());
        if let Some((other, o)) = sized.find(|(_, o)| (o.width(), o.height()) != size) {
            bail!(
                "{} is {} × {} pixels but {} is {} × {}: the lightings of one view and \
                 the ambient image must be the same size",
                crate::text::path(other),
                o.width(),
                o.height(),
                crate::text::path(first),
                size.0,
                size.1
            );
        }
    }
    // Files without a lighting letter come one to a group: any key will do.
    let keys: Vec<char> = grp.letters.iter().map(|l| l.unwrap_or('a')).collect();
    // The pixels move into the input (no second copy); each file's header
    // stays for the `.imc` written from it.
    let (images, headers): (Vec<_>, Vec<_>) = files
        .into_iter()
        .map(|f| (f.image, (f.comment, f.x0, f.y0)))
        .unzip();
    let mut input = rule
        .split(keys.iter().copied().zip(images))
        .with_camera(camera.map(|c| c.0));
    if let Some((_, img)) = ambient {
        input.ambient = Some(('-', img.clone()));
    }
    // Which file each lit image came from, and the ambient one's.
    let file_of = |key: char| keys.iter().position(|k| *k == key);
    let lit: Vec<usize> = input.letters.iter().filter_map(|l| file_of(*l)).collect();
    let ambient_file = match ambient {
        Some((path, _)) => Some(path.clone()),
        None => input
            .ambient
            .as_ref()
            .and_then(|(l, _)| file_of(*l))
            .map(|i| grp.files[i].clone()),
    };
    let size = input.size();
    if let Some((m, shown)) = camera {
        cdf::check_camera_area(m, size.0, size.1, shown)?;
    }
    let proposal = match &a.auto {
        Some(t) => {
            let map = runner.lens_map(&input, p)?;
            Some(auto::search(&input.input(map.as_deref()), p, t)?)
        }
        None => None,
    };
    let out = runner.run(
        &input,
        Stage::Lens,
        proposal.as_ref().map_or(p, |r| &r.params),
    )?;
    // Every output is staged first and renamed into place only when all
    // are on disk: a full disk leaves the previous run's set, not a mix.
    let mut set = crate::fsutil::StagedWrites::new();
    if camera.is_some() {
        // The corrected images of the lit frames (the inputs themselves when
        // the map is the identity or correction is switched off).
        for (k, &i) in lit.iter().enumerate() {
            let (path, (comment, x0, y0)) = (&grp.files[i], &headers[i]);
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
            let target = out_path(a, &grp.dir, &format!("{}.imc", stem.unwrap_or_default()));
            // The input's lit images are in the order of `lit`.
            let image = out.corrected.get(k).or(input.images.get(k));
            let imc = ImgFile {
                image: image.cloned().context("no image for the .imc")?,
                comment: comment.clone(),
                x0: *x0,
                y0: *y0,
            };
            let bytes = crate::formats::img::encode_img(&imc)?;
            stage(a, &mut set, &target, &bytes)?;
        }
    }
    write_outputs(a, &grp.dir, &grp.stem, out, true, &mut set)?;
    let written = commit(set)?;
    if let (Some(t), Some(r)) = (&a.auto, &proposal)
        && !a.json
    {
        print_auto(&grp.stem, t, r)?;
    }
    report(
        a,
        &profile.in_use(),
        &grp.stem,
        &grp.files,
        ambient_file.as_deref(),
        size,
        out,
        &written,
        proposal.as_ref(),
    )?;
    Ok(())
}

/// Stages `.hpo`/`.vpo` (when `edges`), `.lex` and `.ldr` into `set`.
fn write_outputs(
    a: &Args,
    dir: &Path,
    stem: &str,
    out: &StageOutputs,
    edges: bool,
    set: &mut crate::fsutil::StagedWrites,
) -> anyhow::Result<()> {
    if edges {
        for (ext, e) in [("hpo", &out.edges_h), ("vpo", &out.edges_v)] {
            let t = out_path(a, dir, &format!("{stem}.{ext}"));
            stage(a, set, &t, &edgefile::encode_checked(&t, e)?)?;
        }
    }
    for (ext, l) in [("lex", &out.lines_raw), ("ldr", &out.lines)] {
        let t = out_path(a, dir, &format!("{stem}.{ext}"));
        stage(a, set, &t, linefile::encode_checked(&t, l)?.as_bytes())?;
    }
    Ok(())
}

/// Stages one output; an error says that no output was replaced, and
/// where the outputs went beside the input, how to put them elsewhere.
fn stage(
    a: &Args,
    set: &mut crate::fsutil::StagedWrites,
    path: &Path,
    bytes: &[u8],
) -> anyhow::Result<()> {
    crate::formats::stage(set, path, bytes).map_err(|e| {
        let elsewhere = if a.out.is_none() {
            "; --out DIR writes the outputs to another folder"
        } else {
            ""
        };
        anyhow::anyhow!(
            "{e}; no output was replaced (those of an earlier run, if any, are as they \
             were){elsewhere}"
        )
    })
}

/// Renames the staged outputs into place.
fn commit(set: crate::fsutil::StagedWrites) -> anyhow::Result<Vec<PathBuf>> {
    set.commit().map_err(|e| {
        anyhow::anyhow!(
            "cannot put the outputs in place: {e}; outputs renamed before it are new, the rest \
             as they were (an earlier run's, if any)"
        )
    })
}

fn from_edges(
    hpo: &Path,
    vpo: &Path,
    profile: &Profile,
    a: &Args,
    p: &Params,
) -> anyhow::Result<()> {
    let (h, v) = (edgefile::read_edges(hpo)?, edgefile::read_edges(vpo)?);
    check_edge_pair(hpo, &h, vpo, &v)?;
    let saved = Saved::Edges { h, v };
    let mut runner = Runner::lean();
    let out = runner.run_saved(saved, p, None)?;
    let stem = hpo
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "edges".to_string());
    let dir = hpo.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut set = crate::fsutil::StagedWrites::new();
    write_outputs(a, &dir, &stem, out, false, &mut set)?;
    let written = commit(set)?;
    let size = (out.edges_h.width, out.edges_h.height);
    report(
        a,
        &profile.in_use(),
        &stem,
        &[hpo.to_path_buf(), vpo.to_path_buf()],
        None,
        size,
        out,
        &written,
        None,
    )?;
    Ok(())
}

/// `--from-edges` takes the horizontal scan's file, then the vertical
/// one's, of one image: a file whose header names the other direction (the
/// two swapped, or one file twice) or two files of different image sizes
/// are refused by name; the lines would mix two scans of one direction, or
/// two images. A direction `-` or a size 0 (not known) is taken as it is.
fn check_edge_pair(
    hpo: &Path,
    h: &crate::llv::EdgePoints,
    vpo: &Path,
    v: &crate::llv::EdgePoints,
) -> anyhow::Result<()> {
    use crate::llv::ScanDir::{Horizontal, Vertical};
    let named = |d| if d == Horizontal { "H" } else { "V" };
    for (path, e, want, which) in [(hpo, h, Horizontal, "first"), (vpo, v, Vertical, "second")] {
        if let Some(d) = e.dir
            && d != want
        {
            bail!(
                "{}: byte {}: the header says direction {}, but the {which} file of \
                 --from-edges must be the {} scan's (STEM.hpo STEM.vpo, in that order)",
                crate::text::path(path),
                edgefile::MAGIC.len() + 3,
                named(d),
                named(want)
            );
        }
    }
    let known = |e: &crate::llv::EdgePoints| e.width > 0 && e.height > 0;
    if known(h) && known(v) && (h.width, h.height) != (v.width, v.height) {
        bail!(
            "{} holds the edges of a {} × {} image, {} of a {} × {} one: the two edge \
             files must come from the same image",
            crate::text::path(hpo),
            h.width,
            h.height,
            crate::text::path(vpo),
            v.width,
            v.height
        );
    }
    Ok(())
}

/// What `--auto` changed, in text.
fn print_auto(stem: &str, t: &Target, r: &AutoResult) -> anyhow::Result<()> {
    outln!(
        "{}: auto {t}: {} lines (was {}) after {} pipeline runs",
        crate::text::path(stem),
        r.lines.len(),
        r.base_lines,
        r.runs
    );
    if r.changes.is_empty() {
        outln!("  no change: the current parameters are the best found");
    }
    for (key, old, new) in &r.changes {
        outln!("  --set {key}={new}   (was {old})");
    }
    Ok(())
}

/// What `--auto` changed, as JSON.
fn auto_json(r: &AutoResult) -> serde_json::Value {
    json!({
        "lines": r.lines.len(),
        "base_lines": r.base_lines,
        "runs": r.runs,
        "coverage": r.coverage,
        "changes": r.changes.iter().map(|(k, old, new)| json!({"key": k, "old": old, "new": new})).collect::<Vec<_>>(),
    })
}

/// Prints what one input gave: text, or one JSON object per line.
#[allow(clippy::too_many_arguments)]
fn report(
    a: &Args,
    profile: &str,
    stem: &str,
    files: &[PathBuf],
    ambient: Option<&Path>,
    size: (usize, usize),
    out: &StageOutputs,
    written: &[PathBuf],
    proposal: Option<&AutoResult>,
) -> anyhow::Result<()> {
    let t = &out.timings;
    let shown = |p: &PathBuf| crate::text::path(p);
    if a.json {
        let attrs: Vec<_> = out
            .lines
            .iter()
            .map(|l| json!({"response": l.response, "residual": l.residual, "shadow": l.shadow}))
            .collect();
        let mut v = json!({
            "image": crate::text::path(stem),
            "profile": crate::formats::sanitize(profile),
            "files": files.iter().map(shown).collect::<Vec<_>>(),
            "width": size.0,
            "height": size.1,
            "edges_h": out.edges_h.points.len(),
            "edges_v": out.edges_v.points.len(),
            "lines_raw": out.lines_raw.len(),
            "lines": out.lines.len(),
            "timings_us": {"lens": t.lens_us, "edges": t.edges_us, "lines": t.lines_us, "connect": t.connect_us},
            "line_attributes": attrs,
            "written": written.iter().map(shown).collect::<Vec<_>>(),
            "ambient": ambient.map(|p| shown(&p.to_path_buf())),
        });
        if let (Some(r), Some(obj)) = (proposal, v.as_object_mut()) {
            obj.insert("auto".to_string(), auto_json(r));
        }
        outln!("{v}");
        return Ok(());
    }
    let ms = |us: u64| us as f64 / 1000.0;
    outln!(
        "{} ({}): {} × {}",
        crate::text::path(stem),
        files.iter().map(shown).collect::<Vec<_>>().join(" "),
        size.0,
        size.1
    );
    if let Some(amb) = ambient {
        outln!(
            "  ambient      {} (subtracted from the others)",
            shown(&amb.to_path_buf())
        );
    }
    outln!(
        "  edge points  H {:>6}   V {:>6}",
        out.edges_h.points.len(),
        out.edges_v.points.len()
    );
    outln!(
        "  lines        {:>6} extracted, {} after CONNECT",
        out.lines_raw.len(),
        out.lines.len()
    );
    outln!(
        "  time (ms)    lens {:.2}  edges {:.2}  lines {:.2}  connect {:.2}",
        ms(t.lens_us),
        ms(t.edges_us),
        ms(t.lines_us),
        ms(t.connect_us)
    );
    outln!(
        "  wrote        {}",
        written.iter().map(shown).collect::<Vec<_>>().join(" ")
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lightings_of_one_view_form_one_group() {
        let paths: Vec<PathBuf> = [
            "d/cube1b.img",
            "d/cube1a.img",
            "d/photo.png",
            "d/cube2a.img",
            "e/cube1a.img",
        ]
        .iter()
        .map(PathBuf::from)
        .collect();
        let g = group(&paths);
        assert_eq!(g.len(), 4);
        assert_eq!(g[0].stem, "cube1");
        assert_eq!(
            g[0].files,
            vec![PathBuf::from("d/cube1a.img"), PathBuf::from("d/cube1b.img")]
        );
        assert_eq!(g[1].stem, "photo");
        assert_eq!(g[2].stem, "cube2");
        assert_eq!(g[3].dir, PathBuf::from("e"));
    }
}
