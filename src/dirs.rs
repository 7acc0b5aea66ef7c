//! The XDG base directories, owned here: where vss looks for the user's
//! profiles (`$XDG_CONFIG_HOME`, else `~/.config`) and where it keeps its
//! state — the console's log while no session is open, the LCUS relay
//! boards' last settings (`$XDG_STATE_HOME`, else `~/.local/state`). The
//! base directory rule is all a Linux cell PC needs; an empty or relative
//! value is invalid and ignored, as the specification says, because a
//! relative path would put the files in whatever folder vss runs in. The
//! same holds for `HOME`: without an absolute one there is no folder.

use std::ffi::OsString;
use std::path::PathBuf;

/// The XDG config folder: `$XDG_CONFIG_HOME`, else `~/.config`; `None`
/// when neither is absolute.
pub fn config_home() -> Option<PathBuf> {
    base(
        std::env::var_os("XDG_CONFIG_HOME"),
        std::env::var_os("HOME"),
        ".config",
    )
}

/// The XDG state folder: `$XDG_STATE_HOME`, else `~/.local/state`; `None`
/// when neither is absolute.
pub fn state_home() -> Option<PathBuf> {
    base(
        std::env::var_os("XDG_STATE_HOME"),
        std::env::var_os("HOME"),
        ".local/state",
    )
}

/// The rule itself, on the variables' values: `xdg` if absolute, else
/// `home/fallback` if `home` is absolute.
fn base(xdg: Option<OsString>, home: Option<OsString>, fallback: &str) -> Option<PathBuf> {
    xdg.map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| {
            home.map(PathBuf::from)
                .filter(|p| p.is_absolute())
                .map(|h| h.join(fallback))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(xdg: Option<&str>, home: Option<&str>) -> Option<PathBuf> {
        base(
            xdg.map(OsString::from),
            home.map(OsString::from),
            ".local/state",
        )
    }

    #[test]
    fn an_absolute_xdg_value_wins() {
        assert_eq!(
            b(Some("/x/state"), Some("/home/op")),
            Some("/x/state".into())
        );
    }

    #[test]
    fn empty_or_relative_values_are_ignored() {
        let home = Some(PathBuf::from("/home/op/.local/state"));
        assert_eq!(b(Some("rel/state"), Some("/home/op")), home);
        assert_eq!(b(Some(""), Some("/home/op")), home);
        assert_eq!(b(None, Some("/home/op")), home);
        assert_eq!(b(Some("rel"), Some("op")), None);
        assert_eq!(b(None, Some("")), None);
        assert_eq!(b(None, None), None);
    }
}
