use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use super::*;

fn key(code: KeyCode, m: KeyModifiers) -> KeyEvent {
    KeyEvent::new(code, m)
}

fn swap_case(k: Key) -> Option<Key> {
    match k.code {
        KeyCode::Char(c) if c.is_ascii_alphabetic() && !k.ctrl => {
            let o = if c.is_ascii_lowercase() {
                c.to_ascii_uppercase()
            } else {
                c.to_ascii_lowercase()
            };
            Some(Key {
                code: KeyCode::Char(o),
                ..k
            })
        }
        _ => None,
    }
}

#[test]
fn screen_keys_win_then_picture_then_global() {
    let s = Scope::Screen(ScreenId::Pipeline);
    let inc = Some(Action::Pipeline(PipelineAction::Inc));
    assert_eq!(
        lookup(s, &key(KeyCode::Char('+'), KeyModifiers::SHIFT)),
        inc
    );
    assert_eq!(lookup(s, &key(KeyCode::Right, KeyModifiers::NONE)), inc);
    assert_eq!(
        lookup(s, &key(KeyCode::Right, KeyModifiers::SHIFT)),
        Some(Action::Pipeline(PipelineAction::Inc10))
    );
    assert_eq!(
        lookup(s, &key(KeyCode::Char('z'), KeyModifiers::NONE)),
        Some(Action::Nav(NavAction::ZoomIn))
    );
    assert_eq!(
        lookup(s, &key(KeyCode::Char('q'), KeyModifiers::NONE)),
        Some(Action::Global(GlobalAction::Quit))
    );
    assert_eq!(
        lookup(s, &key(KeyCode::Char('c'), KeyModifiers::CONTROL)),
        Some(Action::Global(GlobalAction::Quit))
    );
    assert_eq!(
        lookup(s, &key(KeyCode::Char('S'), KeyModifiers::CONTROL)),
        Some(Action::Pipeline(PipelineAction::Save)),
        "Ctrl+letter whatever the case"
    );
    assert_eq!(
        lookup(Scope::Confirm, &key(KeyCode::Char('q'), KeyModifiers::NONE)),
        None
    );
    assert_eq!(
        lookup(
            Scope::Screen(ScreenId::Session),
            &key(KeyCode::Char('z'), KeyModifiers::NONE)
        ),
        None,
        "no picture keys where there is no picture"
    );
    assert_eq!(
        lookup(
            Scope::Screen(ScreenId::Capture),
            &key(KeyCode::Char('B'), KeyModifiers::SHIFT)
        ),
        Some(Action::Capture(CaptureAction::Lighting(1)))
    );
}

#[test]
fn no_key_is_bound_twice_in_one_scope_and_none_shadows_another() {
    for (i, a) in KEYMAP.iter().enumerate() {
        for bnd in &KEYMAP[i + 1..] {
            assert!(
                !(a.scope == bnd.scope && a.key == bnd.key),
                "{:?} {} bound twice",
                a.scope,
                a.key.label()
            );
        }
    }
    // The picture keys and the global keys mean the same on every screen.
    for b in KEYMAP {
        let Scope::Screen(s) = b.scope else { continue };
        for other in KEYMAP.iter().filter(|o| o.key == b.key) {
            assert!(
                other.scope != Scope::Global,
                "{} on {s:?} hides the global key",
                b.key.label()
            );
            assert!(
                !(other.scope == Scope::Picture && has_picture(s)),
                "{} on {s:?} hides the picture key",
                b.key.label()
            );
        }
    }
}

/// With Caps Lock on (or Shift held by mistake) a navigation key never
/// becomes one that writes or throws away work.
#[test]
fn destructive_keys_share_no_letter_with_navigation_keys() {
    let scopes_of = |s: Scope| -> Vec<Scope> {
        match s {
            Scope::Screen(id) if has_picture(id) => vec![s, Scope::Picture, Scope::Global],
            Scope::Screen(_) => vec![s, Scope::Global],
            Scope::Picture => ScreenId::ALL
                .iter()
                .filter(|id| has_picture(**id))
                .map(|id| Scope::Screen(*id))
                .chain([Scope::Picture, Scope::Global])
                .collect(),
            other => vec![other],
        }
    };
    for d in KEYMAP.iter().filter(|b| b.action.is_destructive()) {
        let keys: Vec<Key> = std::iter::once(d.key).chain(swap_case(d.key)).collect();
        for n in KEYMAP.iter().filter(|b| b.action.is_navigation()) {
            if !scopes_of(d.scope).contains(&n.scope) && !scopes_of(n.scope).contains(&d.scope) {
                continue;
            }
            assert!(
                !keys.contains(&n.key),
                "{} ({:?}) sits on the letter of {} ({:?})",
                d.key.label(),
                d.action,
                n.key.label(),
                n.action
            );
        }
    }
}

#[test]
fn help_joins_keys_and_hints_are_short() {
    let rows = describe(Scope::Screen(ScreenId::Pipeline));
    assert!(
        rows.iter()
            .any(|(k, d)| k == "+ = →" && d.starts_with("increase"))
    );
    let h = hints(Scope::Global);
    assert!(h.iter().any(|(k, d)| k == "q" && *d == "quit"));
    for (_, scope) in scopes() {
        let h = hints(scope);
        assert!(h.iter().all(|(_, d)| d.len() <= 11), "{h:?}");
    }
    let pic = hints(Scope::Picture);
    assert!(
        pic.iter().any(|(k, d)| k == "zZ" && *d == "zoom"),
        "{pic:?}"
    );
    assert!(
        pic.iter().any(|(k, d)| k == "hjkl" && *d == "cursor"),
        "{pic:?}"
    );
}

/// `docs/keys.md` is the key table as it is.
#[test]
fn keys_md_is_the_key_table() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/keys.md");
    let want = markdown();
    if std::env::var_os("VSS_WRITE_KEYS").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    let have = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        have == want,
        "docs/keys.md is stale: rewrite it with `VSS_WRITE_KEYS=1 cargo test --lib keys_md`"
    );
    for (title, _) in scopes() {
        assert!(have.contains(&format!("## {title}")), "{title}");
    }
}
