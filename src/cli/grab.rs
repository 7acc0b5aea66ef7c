//! `vss grab`: headless capture of one image under several lightings. For
//! each lighting: switch, settle, freeze, transfer (progress on stderr),
//! verify the CRCs, save `NAMEKa.img` atomically. A failed capture saves
//! nothing of its frame and exits non-zero with the reason; the frames
//! already saved are kept.
//!
//! The images go through the session (`crate::session`): `DIR/NAME` is
//! opened, or created from the profile, and its lock taken, so a console
//! surveying the same session is not written under, and every frame lands
//! in the manifest with the camera and its `.cdf`. The image number, camera
//! and lightings are checked before a new session is made, so a refused
//! grab leaves nothing behind. A locked session is taken over with
//! `--take-over`, or when the person at the terminal says yes, by the rule
//! the console follows ([`crate::session::takeover`]): a live holder on
//! this host (a console, another grab) is asked through the session folder
//! and signalled only when it does not answer.
//!
//! A grab asked to leave its session (`NAME.lock.leave`, checked between
//! lightings, every 0.2 s of a transfer and at each reply a stalled
//! grabber does not send in time) stops the frame under way —
//! nothing of it is saved, the lightings saved before stay recorded —
//! releases the lock and exits non-zero, naming who took the session.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};

use super::{Global, StdoutError};
use crate::formats::img::ImgFile;
use crate::formats::names::{SessionName, VssFile};
use crate::rig::Cell;
use crate::rig::sim::Faults;
use crate::session::takeover::LEAVE_POLL;
use crate::session::{Session, SessionError};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Camera number (1-based).
    #[arg(long)]
    pub camera: u32,
    /// Lighting configurations to capture, e.g. `a,b,c,e`.
    #[arg(long, value_delimiter = ',', required = true)]
    pub lighting: Vec<char>,
    /// The session folder; its last component is the session name.
    #[arg(long, value_name = "DIR/NAME")]
    pub session: PathBuf,
    /// Image number within the session.
    #[arg(long)]
    pub image: u32,
    /// Overwrite images that exist already.
    #[arg(long)]
    pub yes: bool,
    /// Take the session over from the lock's holder: a holder that is gone
    /// (a killed grab, a crashed console) or on another host at once; a
    /// live vss on this host is asked to leave (a console saves and
    /// releases it), and signalled only if it does not within 5 s. Without
    /// it, a terminal is asked.
    #[arg(long)]
    pub take_over: bool,
    /// Faults injected into an embedded simulated grabber (testing).
    #[arg(long, value_name = "SPEC", hide = true)]
    pub sim_faults: Option<String>,
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    let profile = g.load_profile()?;
    let name = a
        .session
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| {
            format!(
                "{}: the session path ends in no name",
                crate::text::path(&a.session)
            )
        })?;
    let session = SessionName::new(name).with_context(|| {
        format!(
            "{}: not a valid session name",
            crate::text::path(&a.session)
        )
    })?;
    crate::session::check_image_number(a.image).context("--image")?;
    // A letter named twice would be captured twice, the second frame
    // replacing the first without --yes.
    if let Some((_, &letter)) = a
        .lighting
        .iter()
        .enumerate()
        .find(|&(i, l)| a.lighting[..i].contains(l))
    {
        bail!(
            "--lighting {}: lighting {letter} is named twice; name each lighting once",
            a.lighting
                .iter()
                .map(char::to_string)
                .collect::<Vec<_>>()
                .join(",")
        );
    }
    let files: Vec<(char, PathBuf)> = a
        .lighting
        .iter()
        .map(|&letter| {
            let f = VssFile {
                session: session.clone(),
                image: a.image,
                lighting: Some(letter),
                ext: "img".into(),
            };
            (letter, a.session.join(f.file_name()))
        })
        .collect();
    if !a.yes {
        let existing: Vec<String> = files
            .iter()
            .filter(|(_, p)| p.exists())
            .map(|(_, p)| crate::text::path(p))
            .collect();
        if !existing.is_empty() {
            bail!(
                "refusing to overwrite {} (add --yes to replace them)",
                existing.join(", ")
            );
        }
    }
    let parent = match a.session.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    // An existing session is locked before the grabber is touched; a new
    // one is made only once the camera and lightings are known good.
    let existing = open_existing(&parent, &session, &a)?;
    let faults = match &a.sim_faults {
        Some(s) => Faults::parse(s)?,
        None => Faults::default(),
    };
    let cancel = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // A second Ctrl-C ends at once; the first cancels the transfer.
        signal_hook::flag::register_conditional_shutdown(sig, 1, Arc::clone(&cancel))
            .context("cannot install the Ctrl-C handler")?;
        signal_hook::flag::register(sig, Arc::clone(&cancel))
            .context("cannot install the Ctrl-C handler")?;
    }
    let mut cell = Cell::open_with_faults(&profile, faults)?;
    // Check everything asked for before the first frame, so a typo does not
    // leave half an image set behind.
    let cameras = cell.info().cameras;
    if a.camera == 0 || a.camera > cameras {
        bail!(
            "camera {} does not exist: the grabber on {} has cameras 1 to {cameras}",
            a.camera,
            cell.grabber.port_name()
        );
    }
    for (letter, _) in &files {
        cell.mask_for(*letter)?;
    }
    cell.grabber.check_camera(a.camera)?;
    let mut sess = match existing {
        Some(s) => s,
        None => Session::create(&parent, session.as_str(), &profile).with_context(|| {
            format!(
                "cannot create the session {}",
                crate::text::path(&a.session)
            )
        })?,
    };
    // A session made with another profile may letter its lightings otherwise.
    let known = sess.letters();
    if let Some(letter) = a.lighting.iter().find(|l| !known.contains(l)) {
        bail!(
            "lighting {letter} is not one of the lightings of session {} ({}); nothing was captured",
            crate::text::path(&a.session),
            known.iter().collect::<String>()
        );
    }
    let cdf = profile.camera_cdf(a.camera).unwrap_or_else(|e| {
        errln!(
            "vss: warning: {e}; image {} has no camera description",
            a.image
        );
        None
    });
    sess.set_image_camera(a.image, a.camera, 1, cdf.as_ref())
        .context("cannot record the camera in the session")?;
    // A report line that cannot be written (its reader gone: `| head -1`)
    // does not stop the capture: the frames are the job, and a script
    // that stopped reading still gets every lighting it asked for. The
    // first such error ends the command once they are saved.
    let mut unreported: Option<std::io::Error> = None;
    for (letter, path) in &files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut asked = left_for(&sess);
        if asked.is_none() {
            let captured = capture_one(
                &mut cell, &mut sess, &a, *letter, &stem, &cancel, &mut asked,
            );
            if asked.is_none() {
                let line = captured.with_context(|| {
                    format!(
                        "capturing {stem} (camera {}, lighting {letter}) failed; nothing of it \
                         was saved",
                        a.camera
                    )
                })?;
                if unreported.is_none() {
                    let text = crate::text::sanitize_lines(&line);
                    unreported = writeln!(std::io::stdout(), "{text}").err();
                }
            }
        }
        if let Some(by) = asked {
            drop(sess);
            bail!(
                "session {} was taken over by {by}: {stem} was not captured (nothing of it \
                 saved), the lightings saved before are kept; the lock is released",
                crate::text::path(&a.session)
            );
        }
    }
    match unreported {
        Some(e) => Err(StdoutError(e))
            .context("every lighting was captured and saved; their report could not be written"),
        None => Ok(ExitCode::SUCCESS),
    }
}

/// Opens the session if it exists, taking over its lock with `--take-over`
/// or when a person at a terminal says so — the same function as the
/// console and `vss session redo`.
fn open_existing(
    parent: &Path,
    session: &SessionName,
    a: &Args,
) -> anyhow::Result<Option<Session>> {
    let context = || format!("cannot open the session {}", crate::text::path(&a.session));
    match Session::open_existing(parent, session.as_str()) {
        Err(e @ SessionError::Locked { .. }) => {
            if a.take_over || ask_take_over(&e)? {
                let dir = parent.join(session.as_str());
                let mut say = |text: String| errln!("{text}");
                let s = crate::session::takeover::open_taking_over(&dir, &mut say)
                    .with_context(context)?;
                errln!("took over the lock of {}", crate::text::path(&dir));
                Ok(Some(s))
            } else {
                Err(anyhow::Error::new(e).context(context()))
            }
        }
        r => r.with_context(context),
    }
}

/// Asks on the terminal whether to take a stale lock over; `false` without
/// a terminal (the error then says `--take-over`).
fn ask_take_over(e: &SessionError) -> anyhow::Result<bool> {
    use std::io::IsTerminal;
    if !std::io::stdin().is_terminal() || !std::io::stderr().is_terminal() {
        return Ok(false);
    }
    let mut err = std::io::stderr();
    write!(
        err,
        "{e}
take the session over? [y/N] "
    )?;
    err.flush()?;
    let mut answer = String::new();
    std::io::stdin().read_line(&mut answer)?;
    Ok(matches!(answer.trim(), "y" | "Y" | "yes" | "YES" | "Yes"))
}

/// Who asked this grab to leave its session, if anyone did and the
/// request checks out ([`Session::leave_requested`]); a request that does
/// not is said and ignored.
fn left_for(sess: &Session) -> Option<String> {
    match sess.leave_requested()? {
        Ok(asker) => Some(asker.to_string()),
        Err(why) => {
            errln!("vss: a request to leave the session was ignored: {why}");
            None
        }
    }
}

/// Captures lighting `letter` into the session and saves its frame;
/// returns the line that reports it (printed by the caller).
fn capture_one(
    cell: &mut Cell,
    sess: &mut Session,
    a: &Args,
    letter: char,
    stem: &str,
    cancel: &AtomicBool,
    asked: &mut Option<String>,
) -> anyhow::Result<String> {
    let camera = a.camera;
    let mut err = std::io::stderr();
    let mut last_pct = u64::MAX;
    let mut checked = std::time::Instant::now();
    let watched: &Session = sess;
    let mut progress = |done: usize, total: usize| {
        let pct = (done as u64 * 100) / (total.max(1) as u64);
        if pct != last_pct {
            last_pct = pct;
            let _ = write!(err, "\r{stem}: {done}/{total} bytes ({pct}%)");
            let _ = err.flush();
        }
        // A request to leave stops the transfer, as Ctrl-C does.
        if asked.is_none() && checked.elapsed() >= LEAVE_POLL {
            checked = std::time::Instant::now();
            *asked = left_for(watched);
        }
        !cancel.load(Ordering::SeqCst) && asked.is_none()
    };
    let result = cell.capture(camera, letter, &mut progress);
    errln!();
    let cap = result?;
    let img = ImgFile::new(cap.image).with_comment(stem);
    let path = sess.save_frame(a.image, letter, &img, cap.settings)?;
    let on = if cap.lights_on.is_empty() {
        "ambient only".to_string()
    } else {
        cap.lights_on.join(", ")
    };
    Ok(format!(
        "{}: camera {camera}, lighting {letter} ({on}), crc {:08X}, {} ms",
        crate::text::path(&path),
        cap.frame.crc,
        cap.elapsed.as_millis()
    ))
}
