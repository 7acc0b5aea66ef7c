//! `vss params`: the LLV parameters between profiles and the cell's old
//! parameter files (formats.md §3).
//!
//! - `vss params list`: every parameter with its default, range, unit and doc.
//! - `vss params export PROFILE --set edges|lines|connect|lens|all [--out F.par]`
//! - `vss params import F.par [--out P.toml]`: applied to the `--profile`
//!   (default `default`); with `--out`, that profile's text with the values
//!   replaced in place (comments kept), else the `[llv.*]` tables on stdout.
//!
//! The mapping (set `vss edges`, entries named by key, types i/b/f) is
//! documented in [`crate::formats::par`].

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Subcommand;

use super::Global;
use crate::formats::par::{ParamSet, format_par, from_params, import_params, write_par};
use crate::llv::Params;
use crate::llv::params::{Kind, PARAMS};
use crate::profile::{Origin, Profile, edit};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Debug, Subcommand)]
pub enum Cmd {
    /// List every LLV parameter: key, default, range, unit and what it does.
    List,
    /// Write a profile's LLV parameters as a parameter file (.par).
    Export {
        /// Profile: a path to a .toml file or a name (as for --profile).
        profile: String,
        /// Which parameters.
        #[arg(long = "set", value_name = "SET", value_enum, default_value_t = SetArg::All)]
        set: SetArg,
        /// Output file (default: standard output).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Read a parameter file (.par) into a profile's LLV parameters.
    Import {
        /// The parameter file.
        file: PathBuf,
        #[arg(
            long,
            value_name = "FILE",
            help = "Write the changed profile here (default: print the [llv] tables)"
        )]
        out: Option<PathBuf>,
    },
}

/// The parameter set `vss params export --set` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SetArg {
    /// Lens correction (`vss lens`).
    Lens,
    /// Edge detection (`vss edges`).
    Edges,
    /// Line extraction (`vss lines`).
    Lines,
    /// CONNECT and corner closing (`vss connect`).
    Connect,
    /// Every parameter (`vss all`).
    All,
}

impl From<SetArg> for ParamSet {
    fn from(s: SetArg) -> ParamSet {
        match s {
            SetArg::Lens => ParamSet::Lens,
            SetArg::Edges => ParamSet::Edges,
            SetArg::Lines => ParamSet::Lines,
            SetArg::Connect => ParamSet::Connect,
            SetArg::All => ParamSet::All,
        }
    }
}

pub fn run(g: &Global, a: Args) -> anyhow::Result<ExitCode> {
    match a.cmd {
        Cmd::List => {
            out!("{}", list_text());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Export { profile, set, out } => {
            let p = Profile::load(&profile)?;
            let set = ParamSet::from(set);
            let f = from_params(&p.llv, set);
            match out {
                Some(o) => {
                    write_par(&o, &f)?;
                    errln!(
                        "vss: wrote {} ({} parameters, set \"{}\")",
                        crate::text::path(&o),
                        f.entries.len(),
                        f.name
                    );
                }
                None => out!("{}", format_par(&f)),
            }
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Import { file, out } => {
            let base_name = g.profile.as_deref().unwrap_or("default");
            let origin = crate::profile::locate(base_name)?;
            let (base_text, base_path) = crate::profile::text_of(&origin)?;
            let base = match origin {
                Origin::File(_) => Profile::from_toml(&base_text, &base_path)?,
                Origin::Builtin => Profile::builtin()?,
            };
            let text = crate::fsutil::read_input(&file, crate::formats::max_len(&file))
                .with_context(|| format!("cannot read {}", crate::text::path(&file)))?;
            let text = std::str::from_utf8(&text).map_err(|_| {
                anyhow::anyhow!(
                    "{}: not UTF-8 text; expected a parameter file",
                    crate::text::path(&file)
                )
            })?;
            let (params, notes) = import_params(text, &file, &base.llv)?;
            for n in notes {
                errln!("vss: note: {}: {n}", crate::text::path(&file));
            }
            match out {
                Some(o) => {
                    let new_text = edit::set_llv(&base_text, &base_path, &params)?;
                    crate::fsutil::write_atomic(&o, new_text.as_bytes())
                        .with_context(|| format!("cannot write {}", crate::text::path(&o)))?;
                    let moved = o.parent().map(|d| d.canonicalize().ok())
                        != base_path.parent().map(|d| d.canonicalize().ok());
                    let relative = base.survey.cdf.iter().any(|c| c.is_relative());
                    if base.builtin && relative {
                        errln!(
                            "vss: note: {} names the built-in cameras' .cdf files (sim/cam1.cdf, …), which are not files: put them beside it or change survey.cdf",
                            crate::text::path(&o)
                        );
                    } else if moved && relative {
                        errln!(
                            "vss: note: {} is in another folder than {}: its relative survey.cdf paths now point elsewhere",
                            crate::text::path(&o),
                            crate::text::path(&base_path)
                        );
                    }
                    errln!(
                        "vss: wrote {} ({} from {})",
                        crate::text::path(&o),
                        changed_text(&base.llv, &params),
                        crate::text::path(&file)
                    );
                }
                None => out!("{}", llv_toml(&params)),
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn changed_text(old: &Params, new: &Params) -> String {
    let n = PARAMS
        .iter()
        .filter(|sp| old.get(sp.key) != new.get(sp.key))
        .count();
    format!("{n} parameter(s) changed")
}

/// The `[llv.*]` tables of a parameter set, as they stand in a profile.
pub fn llv_toml(p: &Params) -> String {
    let mut s = String::new();
    let mut group = "";
    for sp in PARAMS {
        let (g, name) = sp.key.split_once('.').unwrap_or(("", sp.key));
        if g != group {
            if !s.is_empty() {
                s.push('\n');
            }
            s.push_str(&format!("[llv.{g}]\n"));
            group = g;
        }
        let v = edit::toml_value(sp.kind, p.get(sp.key).unwrap_or(0.0));
        s.push_str(&format!("{name} = {v}\n"));
    }
    s
}

/// The table of `vss params list`.
pub fn list_text() -> String {
    let d = Params::default();
    let mut s = format!(
        "{:<26} {:>8}  {:<15} {:<12} {}\n",
        "KEY", "DEFAULT", "RANGE", "UNIT", "WHAT IT DOES"
    );
    for sp in PARAMS {
        let v = d.get(sp.key).unwrap_or(f64::NAN);
        let def = match sp.kind {
            Kind::Bool => (v != 0.0).to_string(),
            _ => format!("{v}"),
        };
        s.push_str(&format!(
            "{:<26} {:>8}  {:<15} {:<12} {}\n",
            sp.key,
            def,
            sp.range_text(),
            sp.unit,
            sp.doc
        ));
    }
    s
}
