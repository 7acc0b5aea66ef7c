//! The Edit screen through the real binary in a pty at 80 × 24 (issue 33,
//! annoyance 4): an extension of two nearly parallel lines, whose corner
//! lies far outside the image, asks before it is made; "no" leaves the
//! lines as they were, "yes" makes it; a sensible corner is made at once.

use vss::tui::keymap::{Action, EditAction, GlobalAction, Scope, ScreenId};

use super::tui_harness::{Console, EDIT};

/// The screen's words, box borders left out, so text wrapped inside a box
/// reads on.
fn flat(s: &str) -> String {
    s.replace(['│', '|'], " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// A line as the Edit panel prints it: `#i (ax,ay)-(bx,by) Lpx`.
#[derive(Clone, Copy, Debug)]
struct Shown {
    a: (f64, f64),
    b: (f64, f64),
}

fn parse_highlighted(screen: &str, i: usize) -> Option<Shown> {
    let tag = format!("#{i} (");
    let at = screen.find(&tag)?;
    let rest = &screen[at + tag.len()..];
    let end = rest.find("px")?;
    let nums: Vec<f64> = rest[..end]
        .split(|c: char| !(c.is_ascii_digit() || c == '-' || c == '.'))
        .filter(|t| !t.is_empty() && *t != "-")
        .filter_map(|t| t.parse().ok())
        .collect();
    match nums[..] {
        [ax, ay, bx, by, _len] => Some(Shown {
            a: (ax, ay),
            b: (bx, by),
        }),
        _ => None,
    }
}

/// Where the infinite lines through `p` and `q` cross (`None` if parallel).
fn cross(p: Shown, q: Shown) -> Option<(f64, f64)> {
    let (d1, d2) = (
        (p.b.0 - p.a.0, p.b.1 - p.a.1),
        (q.b.0 - q.a.0, q.b.1 - q.a.1),
    );
    let den = d1.0 * d2.1 - d1.1 * d2.0;
    if den.abs() < 1e-9 {
        return None;
    }
    let t = ((q.a.0 - p.a.0) * d2.1 - (q.a.1 - p.a.1) * d2.0) / den;
    Some((p.a.0 + t * d1.0, p.a.1 + t * d1.1))
}

fn dist_to(s: Shown, x: (f64, f64)) -> f64 {
    let (dx, dy) = (s.b.0 - s.a.0, s.b.1 - s.a.1);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((x.0 - s.a.0) * dx + (x.1 - s.a.1) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((s.a.0 + t * dx - x.0).powi(2) + (s.a.1 + t * dy - x.1).powi(2)).sqrt()
}

/// The words of the Edit screen's left panel (30 columns), read on over
/// its wrapped rows.
fn panel(s: &str) -> String {
    flat(
        &s.lines()
            .map(|l| l.chars().take(30).collect::<String>())
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

fn wait_words(c: &Console, text: &str, secs: u64) -> String {
    c.wait(text, secs, |s| flat(s).contains(text))
}

fn edit(c: &mut Console, a: EditAction) {
    c.press(EDIT, Action::Edit(a));
}

/// Highlights line `i` from no highlight and puts it in the selection.
fn select(c: &mut Console, i: usize) {
    for _ in 0..=i {
        edit(c, EditAction::LineNext);
    }
    c.wait_text(&format!("#{i} ("), 5);
    edit(c, EditAction::Toggle);
}

/// A console with session `cube`, image 1 captured, on the Edit screen;
/// and that screen.
fn image_1_on_the_edit_screen() -> (Console, String) {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    c.capture_current(1);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Edit)),
    );
    let s = c.wait_text("highlighted (n p", 10);
    (c, s)
}

#[test]
fn an_extension_far_outside_the_image_asks_first() {
    let (mut c, s) = image_1_on_the_edit_screen();
    let n: usize = flat(&s)
        .split("image 1: ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("the line count on the Edit panel:\n{s}"));
    assert!(n >= 4, "a cube shows several lines:\n{s}");
    // Every line's figures, as the panel shows them.
    let mut lines = Vec::new();
    for i in 0..n {
        edit(&mut c, EditAction::LineNext);
        let s = c.wait(&format!("line {i} highlighted"), 5, |s| {
            parse_highlighted(s, i).is_some()
        });
        lines.push(parse_highlighted(&s, i).unwrap());
    }
    // The pair whose corner lies farthest outside the 128 × 128 image, and
    // a pair that meets within 3 px of both lines, inside it.
    let outside = |x: (f64, f64)| (-x.0).max(x.0 - 128.0).max(-x.1).max(x.1 - 128.0).max(0.0);
    let mut far = None::<(usize, usize, f64)>;
    let mut near = None::<(usize, usize)>;
    for i in 0..n {
        for j in i + 1..n {
            let Some(x) = cross(lines[i], lines[j]) else {
                continue;
            };
            let o = outside(x);
            if far.is_none_or(|f| o > f.2) {
                far = Some((i, j, o));
            }
            if o == 0.0 && dist_to(lines[i], x) < 3.0 && dist_to(lines[j], x) < 3.0 {
                near.get_or_insert((i, j));
            }
        }
    }
    let (i, j, o) = far.unwrap();
    assert!(o > 128.0, "two lines that meet far outside: {lines:?}");
    edit(&mut c, EditAction::ClearSelection);
    select(&mut c, i);
    for _ in i..j {
        edit(&mut c, EditAction::LineNext);
    }
    c.wait_text(&format!("#{j} ("), 5);
    edit(&mut c, EditAction::Toggle);
    edit(&mut c, EditAction::Extend);
    let s = wait_words(&c, "Extend anyway?", 10);
    assert!(
        flat(&s).contains(&format!("lines {i} and {j} meet at")),
        "the question says where the corner would be:\n{s}"
    );
    c.send("n");
    let s = wait_words(&c, "nothing changed", 10);
    assert!(!flat(&s).contains("extended"), "{s}");
    let ldr = c.session().join("cube1.ldr");
    let before = std::fs::read(&ldr).ok();
    // Asked again, and yes makes it.
    edit(&mut c, EditAction::Extend);
    wait_words(&c, "Extend anyway?", 10);
    c.yes();
    // The panel's last edits (the message row moves on to "saved").
    let made = format!("extended lines {i} (");
    c.wait(&made, 10, |s| panel(s).contains(&made));
    c.wait("the edit written", 10, |_| {
        std::fs::read(&ldr).ok() != before
    });
    // A corner where the lines nearly meet is made without a question.
    if let Some((p, q)) = near {
        edit(&mut c, EditAction::Undo);
        // Said as the edit was: which lines, not only "the last edit".
        wait_words(&c, &format!("undone: extended lines {i} ("), 10);
        edit(&mut c, EditAction::ClearSelection);
        select(&mut c, p);
        for _ in p..q {
            edit(&mut c, EditAction::LineNext);
        }
        c.wait_text(&format!("#{q} ("), 5);
        edit(&mut c, EditAction::Toggle);
        edit(&mut c, EditAction::Extend);
        let made = format!("extended lines {p} (");
        let s = c.wait(&made, 10, |s| panel(s).contains(&made));
        assert!(!flat(&s).contains("anyway?"), "{s}");
    }
    c.send("q");
    c.wait_exit(15);
}

/// An edit whose `.ldr` cannot be written (here a folder stands in its
/// place) counts as outputs not saved: q asks before it quits, as it does
/// for outputs not saved.
#[test]
fn an_edit_not_written_makes_q_ask() {
    let (mut c, _) = image_1_on_the_edit_screen();
    let ldr = c.session().join("cube1.ldr");
    let _ = std::fs::remove_file(&ldr);
    std::fs::create_dir_all(ldr.join("in the way")).unwrap();
    select(&mut c, 0);
    edit(&mut c, EditAction::Delete);
    if flat(&c.screen()).contains("anyway?") || flat(&c.screen()).contains("accepted.") {
        c.yes();
    }
    wait_words(&c, "edit of image 1 NOT saved", 10);
    c.send("q");
    let s = wait_words(&c, "Quit anyway?", 10);
    assert!(flat(&s).contains("not saved"), "{s}");
    assert_eq!(c.exit_code(), None, "q quit without asking:\n{s}");
    c.yes();
    c.wait_exit(15);
}
