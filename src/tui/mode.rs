//! Picking the preview mode and colours once at start, from the command
//! line and the environment only — never by querying the terminal, which
//! can hang over a slow SSH link.

use super::widgets::preview::PreviewMode;

/// How the console draws: preview mode and whether colour attributes may be
/// written at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Look {
    pub mode: PreviewMode,
    pub colour: bool,
    /// The 256-colour palette may be used (not on a Linux console).
    pub c256: bool,
}

/// Why the console cannot run on this `TERM` (a terminal without cursor
/// addressing), or `None`.
pub fn unusable(term: Option<&str>) -> Option<String> {
    match term {
        Some("dumb") | Some("") | None => Some(
            "vss: the console needs a terminal with cursor addressing (TERM is dumb or \
             unset); use the vss subcommands instead (`vss --help`), or set TERM (for \
             example TERM=xterm-256color)"
                .into(),
        ),
        _ => None,
    }
}

/// The look for an optional `--preview` override and the values of `TERM`
/// and `NO_COLOR`. `NO_COLOR` (any value, per no-color.org) removes every
/// colour attribute and, without an override, picks ASCII. The Linux console
/// gets its sixteen colours with ASCII previews (its font has no Braille);
/// VT100-like terminals get ASCII without colour.
pub fn pick(preview: Option<&str>, term: Option<&str>, no_color: Option<&str>) -> Look {
    let no_colour = no_color.is_some();
    let term = term.unwrap_or("");
    let linux = term == "linux";
    let plain_term = term.is_empty()
        || matches!(term, "dumb" | "vt100" | "vt102" | "vt220" | "ansi")
        || term.starts_with("vt1");
    let colour = !no_colour && !plain_term;
    let c256 = colour && !linux;
    let mode = match preview {
        Some("ascii") => PreviewMode::Ascii,
        Some("braille") => PreviewMode::Braille,
        Some("blocks") => PreviewMode::Blocks,
        _ if no_colour || plain_term || linux => PreviewMode::Ascii,
        _ => PreviewMode::Blocks,
    };
    Look { mode, colour, c256 }
}

/// The look for this process's environment.
pub fn from_env(preview: Option<&str>) -> Look {
    let term = std::env::var("TERM").ok();
    let no_color = std::env::var("NO_COLOR").ok();
    pick(preview, term.as_deref(), no_color.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environment_and_override() {
        let l = pick(None, Some("xterm-256color"), None);
        assert_eq!(
            l,
            Look {
                mode: PreviewMode::Blocks,
                colour: true,
                c256: true
            }
        );
        let l = pick(None, Some("xterm-256color"), Some("1"));
        assert_eq!((l.mode, l.colour), (PreviewMode::Ascii, false));
        for t in ["dumb", "vt100"] {
            assert_eq!(pick(None, Some(t), None).mode, PreviewMode::Ascii, "{t}");
            assert!(!pick(None, Some(t), None).colour);
        }
        let linux = pick(None, Some("linux"), None);
        assert_eq!(
            linux,
            Look {
                mode: PreviewMode::Ascii,
                colour: true,
                c256: false
            },
            "the Linux console's sixteen colours"
        );
        let l = pick(Some("braille"), Some("xterm"), Some(""));
        assert_eq!((l.mode, l.colour), (PreviewMode::Braille, false));
        assert_eq!(
            pick(Some("blocks"), Some("dumb"), None).mode,
            PreviewMode::Blocks
        );
        assert!(
            unusable(Some("dumb"))
                .unwrap()
                .contains("cursor addressing")
        );
        assert!(unusable(None).is_some());
        assert!(unusable(Some("linux")).is_none());
    }
}
