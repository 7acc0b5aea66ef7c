//! `vss session`: create, show, check and redo survey sessions from the
//! command line (the console does the same through [`crate::session`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context as _;

use super::Global;
use crate::llv::params::Stage;
use crate::session::{OutputState, Session};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Cmd,
}

#[derive(Debug, clap::Subcommand)]
pub enum Cmd {
    /// Make a new session folder DIR/NAME for the profile's survey.
    New {
        /// Session name: 1–32 letters, digits, _ or -, starting with a letter or _.
        name: String,
        /// Parent folder (default: the profile's survey.dir).
        #[arg(long, value_name = "D")]
        dir: Option<PathBuf>,
    },
    /// Show a session: lightings, checklist, outputs, edits, lock holder.
    Show { dir: PathBuf },
    /// Check that every file the manifest names exists and parses; list
    /// stale outputs. Exits non-zero on problems.
    Check {
        dir: PathBuf,
        /// Treat warnings (changed files, stale outputs) as problems too.
        #[arg(long)]
        strict: bool,
    },
    /// Re-run the stages of one image with the current profile's parameters.
    Redo {
        dir: PathBuf,
        #[arg(long, value_name = "K")]
        image: u32,
        /// First stage to re-run.
        #[arg(long, value_name = "STAGE", value_enum, default_value_t = FromStage::Edges)]
        from: FromStage,
        /// Take the session over: a lock whose holder is gone at once, a
        /// live vss on this host asked to leave (as the console asks) and
        /// signalled only if it does not within 5 s.
        #[arg(long)]
        take_over: bool,
    },
    /// Test helper: save into a session in an endless loop (the crash-safety
    /// test kills it at random moments).
    #[command(hide = true)]
    Torture {
        dir: PathBuf,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Stop after this many saves.
        #[arg(long, default_value_t = 1_000_000)]
        limit: u64,
    },
}

/// The stage `vss session redo --from` starts at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FromStage {
    /// Lens correction and everything after it, on the grey images.
    Lens,
    /// Edges and everything after them, on the grey images.
    Edges,
    /// Line extraction and CONNECT with the saved edges' parameters, on the
    /// grey images (on the saved .hpo and .vpo when there are none).
    Lines,
    /// CONNECT alone, on the saved .lex.
    Connect,
}

impl From<FromStage> for Stage {
    fn from(s: FromStage) -> Stage {
        match s {
            FromStage::Lens => Stage::Lens,
            FromStage::Edges => Stage::Edges,
            FromStage::Lines => Stage::Lines,
            FromStage::Connect => Stage::Connect,
        }
    }
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    match a.command {
        Cmd::New { name, dir } => new(g, &name, dir),
        Cmd::Show { dir } => show(&session_dir(g, dir)),
        Cmd::Check { dir, strict } => check(&session_dir(g, dir), strict),
        Cmd::Redo {
            dir,
            image,
            from,
            take_over,
        } => redo(g, &session_dir(g, dir), image, from.into(), take_over),
        Cmd::Torture { dir, seed, limit } => {
            use std::io::Write as _;
            let mut out = std::io::stdout().lock();
            crate::session::torture::run(&dir, seed, limit, &mut |n| {
                let _ = writeln!(
                    out,
                    "{}",
                    if n == 0 {
                        "ready".to_string()
                    } else {
                        format!("saved {n}")
                    }
                );
                let _ = out.flush();
            })?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// The session folder an argument names: the path itself when it is a
/// folder, else a bare session name under the profile's `survey.dir`
/// (where `vss session new NAME` and the console make them), so
/// `vss session check cube` works from the folder vss runs in. Anything
/// else is returned unchanged, for the session to report as missing.
fn session_dir(g: &Global, dir: PathBuf) -> PathBuf {
    let bare = dir.components().count() == 1
        && matches!(
            dir.components().next(),
            Some(std::path::Component::Normal(_))
        );
    if dir.is_dir() || !bare {
        return dir;
    }
    match g.load_profile() {
        Ok(p) if p.survey.dir.join(&dir).is_dir() => p.survey.dir.join(&dir),
        _ => dir,
    }
}

fn new(g: &Global, name: &str, dir: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let parent = dir.unwrap_or_else(|| profile.survey.dir.clone());
    // The camera descriptions the profile names go into the session as
    // NAMEk.cdf for every planned image of that camera; a failure in any
    // of it leaves no session behind.
    let s = Session::create_with(&parent, name, &profile, |s| {
        let cams = s.manifest().session.cameras.max(1);
        for k in 1..=s.manifest().session.planned_images {
            let cam = (k - 1) % cams + 1;
            let cdf = match profile.camera_cdf(cam) {
                Ok(c) => c,
                Err(e) => {
                    errln!("vss: warning: {e}; image {k} has no camera description");
                    continue;
                }
            };
            s.set_image_camera(k, cam, (k - 1) / cams + 1, cdf.as_ref())?;
        }
        Ok(())
    })?;
    if let Some(w) = s.name().dos_warning(s.manifest().session.planned_images) {
        errln!("vss: note: {w}");
    }
    outln!("created session {}", crate::text::path(s.dir()));
    print_checklist(&s)?;
    Ok(ExitCode::SUCCESS)
}

fn show(dir: &Path) -> anyhow::Result<ExitCode> {
    let s = Session::inspect(dir)?;
    let m = s.manifest();
    // Every text from the manifest is one line: a line break in a note must
    // not make a line of its own that looks like the checklist's.
    let t = crate::text::sanitize;
    outln!(
        "session {} in {}",
        t(&m.session.name),
        crate::text::path(s.dir())
    );
    outln!(
        "  created {}, modified {} by vss {}, profile \"{}\"",
        t(&m.session.created),
        t(&m.session.modified),
        t(&m.session.version),
        t(&m.session.profile)
    );
    match s.lock_holder() {
        Some(h) => outln!(
            "  in use by {h}{}",
            if h.is_stale() {
                " (gone: stale lock)"
            } else {
                ""
            }
        ),
        None => outln!("  not in use"),
    }
    outln!("lightings:");
    for l in &m.lighting {
        outln!(
            "  {}: {}{}",
            t(&l.letter.to_string()),
            if l.on.is_empty() {
                "no lights".to_string()
            } else {
                t(&l.on.join(", "))
            },
            if l.note.is_empty() {
                String::new()
            } else {
                format!(" -- {}", t(&l.note))
            }
        );
    }
    print_checklist(&s)?;
    for r in &m.image {
        if !r.grey.is_empty() {
            outln!("  {}", camera_note(&s, r));
        }
        if let Some(o) = &r.outputs {
            let c = &o.counts;
            outln!(
                "  image {}: {} + {} edge points, {} lines extracted, {} lines; made {}",
                r.number,
                c.edges_h,
                c.edges_v,
                c.lines_raw,
                c.lines,
                t(&o.made)
            );
        }
        for e in &r.edit {
            outln!(
                "  image {}: edit {} at {} -> {} lines",
                r.number,
                t(&e.op),
                t(&e.at),
                e.lines
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The camera description image `r` runs with, as [`Session::image_camera`]
/// decides for `vss session redo` and the console: its recorded file, or
/// why it runs without lens correction, or why it does not run at all.
fn camera_note(s: &Session, r: &crate::session::manifest::ImageRecord) -> String {
    use crate::session::camera::ImageCamera;
    let t = crate::text::sanitize;
    let (k, file) = (r.number, r.cdf.as_ref().map_or("", |c| c.file.as_str()));
    match s.image_camera(k) {
        Ok(ImageCamera::Model(_)) => {
            format!(
                "image {k}: camera description {} (recorded at capture)",
                t(file)
            )
        }
        Ok(ImageCamera::Unrecorded) => {
            format!("image {k}: no camera description recorded: it runs without lens correction")
        }
        Ok(ImageCamera::NoModel(why)) => format!(
            "image {k}: camera description {} gives no camera model ({}): it runs without \
             lens correction",
            t(file),
            t(&why)
        ),
        Err(e) => t(&e.to_string()),
    }
}

fn print_checklist(s: &Session) -> anyhow::Result<()> {
    let p = s.progress();
    let (done, all) = p.done();
    outln!("checklist ({done} of {all} images done):");
    outln!("  image camera location captured  outputs");
    for i in &p.images {
        let captured: String = p
            .letters
            .iter()
            .map(|l| {
                if i.captured.contains(l) && !l.is_control() {
                    *l
                } else {
                    '.'
                }
            })
            .collect();
        let out = match &i.outputs {
            OutputState::Missing => "-".to_string(),
            OutputState::Done => "done".to_string(),
            OutputState::Stale(why) => format!("STALE ({})", crate::text::sanitize(why)),
        };
        let edits = if i.edits > 0 {
            format!(", {} manual edits", i.edits)
        } else {
            String::new()
        };
        outln!(
            "  {:>5} {:>6} {:>8} {captured:<9} {out}{edits}",
            i.number,
            i.camera,
            i.location
        );
    }
    match p.next_step() {
        Some(step) => outln!("next: {step}"),
        None => outln!("next: nothing, the survey is complete"),
    }
    Ok(())
}

fn check(dir: &Path, strict: bool) -> anyhow::Result<ExitCode> {
    let s = Session::inspect(dir)?;
    let r = s.check();
    for p in &r.problems {
        outln!("problem: {p}");
    }
    for w in &r.warnings {
        outln!("warning: {w}");
    }
    for (k, why) in &r.stale {
        outln!("stale: image {k}: {why}");
    }
    let bad = !r.problems.is_empty() || (strict && (!r.warnings.is_empty() || !r.stale.is_empty()));
    outln!(
        "{}: {} files read, {} problems, {} warnings, {} stale",
        if bad { "FAILED" } else { "ok" },
        r.checked,
        r.problems.len(),
        r.warnings.len(),
        r.stale.len()
    );
    Ok(if bad {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn redo(g: &Global, dir: &Path, k: u32, stage: Stage, take_over: bool) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let mut s = if take_over {
        let mut say = |text: String| errln!("{text}");
        crate::session::takeover::open_taking_over(dir, &mut say)?
    } else {
        Session::open(dir)?
    };
    let summary = s
        .redo(k, stage, &profile.llv)
        .with_context(|| format!("redo image {k} of {}", crate::text::path(dir)))?;
    outln!("{summary}");
    Ok(ExitCode::SUCCESS)
}
