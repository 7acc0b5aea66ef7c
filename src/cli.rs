//! The headless command line. `vss` with no subcommand opens the console;
//! each subcommand lives in its own file under `cli/` with its `Args` and `run`.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// `println!` that hands a failed write back (`?`, as a [`StdoutError`])
/// instead of panicking: a reader that goes away (`vss info FILE | head
/// -2`) ends the command quietly (see [`main`]). What it prints goes
/// through the one sanitiser ([`crate::text::sanitize_lines`]): text from
/// files (a note, a light name, a comment) never reaches the terminal with
/// an escape sequence in it.
macro_rules! outln {
    () => {{
        use std::io::Write as _;
        writeln!(std::io::stdout()).map_err($crate::cli::StdoutError)?
    }};
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = $crate::text::sanitize_lines(&format!($($arg)*));
        writeln!(std::io::stdout(), "{text}").map_err($crate::cli::StdoutError)?
    }};
}

/// `print!` as [`outln`] does it.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = $crate::text::sanitize_lines(&format!($($arg)*));
        write!(std::io::stdout(), "{text}").map_err($crate::cli::StdoutError)?
    }};
}

/// `eprintln!` through the one sanitiser: notes and errors name files and
/// quote what they hold. A standard error that cannot be written (closed,
/// `/dev/full`) loses the message, not the exit status: `eprintln!` would
/// panic (exit 101).
macro_rules! errln {
    () => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr());
    }};
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "{}",
            $crate::text::sanitize_lines(&format!($($arg)*))
        );
    }};
}

pub mod calibrate;
pub mod convert;
pub mod grab;
pub mod info;
pub mod lights;
pub mod llv;
pub mod params;
pub mod report;
pub mod selftest;
pub mod session;
pub mod sim;

/// Options every subcommand shares.
#[derive(Debug, Clone, clap::Args)]
pub struct Global {
    /// Profile: a path to a .toml file, or a NAME looked up as NAME.toml in
    /// ./profiles, then ~/.config/vss/profiles (default: "default", built in
    /// unless a default.toml is there).
    #[arg(long, global = true, value_name = "P")]
    pub profile: Option<String>,
}

impl Global {
    /// Loads the profile named on the command line, or `default`.
    /// A profile found by name in the working folder's `profiles/` is
    /// named on stderr: a file there changes what vss drives.
    pub fn load_profile(&self) -> anyhow::Result<crate::profile::Profile> {
        let name = self.profile.as_deref().unwrap_or("default");
        let p = crate::profile::Profile::load(name)?;
        if let Some(src) = &p.source
            && src.is_relative()
            && !std::path::Path::new(name).is_file()
        {
            errln!(
                "vss: note: profile `{name}` is {} (found in the working folder)",
                crate::text::path(src)
            );
        }
        Ok(p)
    }
}

#[derive(Debug, Parser)]
#[command(
    name = "vss",
    version,
    about = "Vision Survey System: the operator console of the robot welding cell",
    long_about = "Vision Survey System: the operator console of the robot welding cell.\n\n\
                  Without a subcommand, opens the console on the profile's cell \
                  (the built-in simulated cell by default)."
)]
pub struct Cli {
    #[command(flatten)]
    pub global: Global,
    /// Preview mode of the console (default: picked from TERM and NO_COLOR).
    #[arg(long, value_name = "MODE", value_enum)]
    pub preview: Option<Preview>,
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// How the console draws its previews (`--preview`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preview {
    /// Plain ASCII: a character ramp for grey, `- | / \\` strokes for lines.
    Ascii,
    /// Braille dots (2 × 4 a cell) for everything.
    Braille,
    /// Half-blocks in 256-colour greys for images, Braille for lines.
    Blocks,
}

impl Preview {
    /// The mode's name, as typed after `--preview`.
    pub fn name(self) -> &'static str {
        match self {
            Preview::Ascii => "ascii",
            Preview::Braille => "braille",
            Preview::Blocks => "blocks",
        }
    }
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Convert images between .img and PNG, PGM, TIFF, BMP.
    Convert(convert::Args),
    /// Describe any cell file in a few lines.
    Info(info::Args),
    /// Import and export parameter files, list the LLV parameters.
    Params(params::Args),
    /// Run the LLV stages on images (or on saved edge files).
    Llv(llv::Args),
    /// Run the pipeline on synthetic scenes with known edges and report accuracy.
    Selftest(selftest::Args),
    /// Start the simulated grabber and relay board on pseudo-terminals.
    Sim(sim::Args),
    /// Capture one image under several lightings, headless.
    Grab(grab::Args),
    /// Switch and read the lights.
    Lights(lights::Args),
    /// Calibrate a camera from images of a calibration plate (writes its .cdf).
    Calibrate(calibrate::Args),
    /// Create, show, check and redo survey sessions.
    Session(session::Args),
    /// Write PostScript and SVG reports.
    Report(report::Args),
}

/// Parses the command line and runs it; errors go to stderr as `vss: …`.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => cli.global.load_profile().and_then(|p| {
            crate::tui::run(
                p,
                crate::tui::mode::from_env(cli.preview.map(Preview::name)),
            )
        }),
        Some(cmd) => run(&cli.global, cmd),
    };
    match result {
        Ok(code) => code,
        // The reader of the output went away (`| head`): it has what it
        // wanted, so stop quietly, as a pipeline expects.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("vss: error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined with ": ", as `{:#}` does, but a cause
/// whose text the message already holds is not repeated (an I/O error
/// shown in its wrapper's message and kept as its source printed
/// "(os error 28)" twice).
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if c.is_empty() || text.contains(&c) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&c);
    }
    text
}

/// A failed write of a command's output to stdout: kept apart from other
/// I/O errors, so that only a closed stdout ends a command quietly (a
/// grabber link that breaks is an error).
#[derive(Debug, thiserror::Error)]
#[error("cannot write the output: {0}")]
pub struct StdoutError(pub std::io::Error);

/// Whether `e` comes from writing the output to a pipe whose reader has
/// gone.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<StdoutError>()
            .is_some_and(|o| o.0.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

fn run(g: &Global, cmd: Command) -> anyhow::Result<ExitCode> {
    match cmd {
        Command::Convert(a) => convert::run(g, a),
        Command::Info(a) => info::run(g, a),
        Command::Params(a) => params::run(g, a),
        Command::Llv(a) => llv::run(g, a),
        Command::Selftest(a) => selftest::run(g, a),
        Command::Sim(a) => sim::run(g, a),
        Command::Grab(a) => grab::run(g, a),
        Command::Lights(a) => lights::run(g, a),
        Command::Calibrate(a) => calibrate::run(g, a),
        Command::Session(a) => session::run(g, a),
        Command::Report(a) => report::run(g, a),
    }
}
