//! The frame around every screen: the top bar (screen keys, session,
//! profile), the newest message wrapped over up to three rows or the
//! expanded log pane (wrapped, scrollable, the whole run), the hints row(s)
//! with what the devices and the pipeline are doing, questions and text
//! fields, the help window (every key, the checklist's marks) and the
//! message window. Nothing is cut at the terminal width without a way to
//! read the rest.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph, Widget, Wrap};

use super::{block, gauge_text};
use crate::tui::app::{App, Modal, Overlay, SearchTarget};
use crate::tui::keymap::{self, Action, Scope, ScreenId, SurveyAction, has_picture};

/// Most rows the newest message takes at the bottom.
pub const MESSAGE_ROWS: usize = 3;

/// `text` wrapped to `width` columns.
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    textwrap::wrap(text, width.max(1))
        .into_iter()
        .map(|c| c.into_owned())
        .collect()
}

/// The message line's text: the message shown ([`Chrome::shown_message`]),
/// with how many newer ones wait in the log while it is held.
///
/// [`Chrome::shown_message`]: crate::tui::app::Chrome::shown_message
fn newest(app: &App) -> Option<(String, crate::tui::app::Level)> {
    app.chrome.shown_message().map(|(e, newer)| {
        let more = if newer > 0 {
            format!(" (+{newer} newer in the log)")
        } else {
            String::new()
        };
        (format!("{}{more}", e.dated()), e.level)
    })
}

/// Rows the newest message needs (1 to [`MESSAGE_ROWS`]).
pub fn message_rows(app: &App, width: u16) -> u16 {
    newest(app).map_or(1, |(m, _)| {
        wrap(&m, width as usize).len().clamp(1, MESSAGE_ROWS)
    }) as u16
}

pub fn top_bar(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let bar = if app.ascii() { '|' } else { '│' };
    let right = format!(" {bar} {} ", app.cell.profile_name);
    // A session open only to look says so in full where there is room,
    // else in a word: the profile's name on the right is never cut for it.
    let session_text = |short: bool| {
        app.session
            .view
            .as_ref()
            .map(|s| match (s.read_only, short) {
                (true, false) => format!(" {bar} {} {bar} {}", s.name, crate::tui::app::READ_ONLY),
                (true, true) => format!(" {bar} {} {bar} read-only", s.name),
                (false, _) => format!(" {bar} {}", s.name),
            })
            .unwrap_or_default()
    };
    let tabs = |short: bool| -> Vec<Span<'static>> {
        let mut spans = vec![Span::styled("vss", t.title())];
        for (i, s) in ScreenId::ALL.iter().enumerate() {
            let current = *s == app.chrome.screen;
            let label = if short && !current {
                format!(" {}", i + 1)
            } else {
                format!(" {} {}", i + 1, s.short())
            };
            let st = if current { t.selected() } else { Style::new() };
            spans.push(Span::styled(label, st));
        }
        spans
    };
    let width = |spans: &[Span]| spans.iter().map(|s| s.width()).sum::<usize>();
    let mut spans = tabs(false);
    let mut session = session_text(false);
    let fits = |spans: &[Span], session: &str| {
        // (The right part's last space may go.)
        width(spans) + session.chars().count() + right.trim_end().chars().count()
            <= area.width as usize
    };
    if !fits(&spans, &session) {
        spans = tabs(true);
    }
    if !fits(&spans, &session) {
        session = session_text(true);
    }
    spans.push(Span::styled(session, t.title()));
    let used = width(&spans);
    let room = (area.width as usize).saturating_sub(used);
    let right: String = if right.chars().count() > room {
        right.chars().take(room).collect()
    } else {
        format!("{right:>room$}")
    };
    spans.push(Span::styled(right, t.dim()));
    Line::from(spans).render(area, buf);
}

/// The newest message, wrapped; a longer one ends with how to read it all.
pub fn message(app: &App, area: Rect, buf: &mut Buffer) {
    if area.height == 0 {
        return;
    }
    let t = app.theme();
    let Some((text, level)) = newest(app) else {
        return;
    };
    let mut rows = wrap(&text, area.width as usize);
    let max = area.height as usize;
    if rows.len() > max {
        rows.truncate(max);
        let more = " … ! shows all";
        let w = area.width as usize;
        if let Some(last) = rows.last_mut() {
            let keep = w.saturating_sub(more.chars().count());
            *last = last.chars().take(keep).collect::<String>() + more;
        }
    }
    let lines: Vec<Line> = rows
        .into_iter()
        .map(|r| Line::styled(r, t.level(level)))
        .collect();
    Paragraph::new(lines).render(area, buf);
}

/// The whole run's messages, wrapped, newest at the bottom, scrolled by
/// PgUp/PgDn/Home/End.
pub fn log_pane(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let n = app.chrome.log.len();
    let file = app
        .chrome
        .log
        .file()
        .map(|p| format!(" · {}", crate::text::path(p)))
        .unwrap_or_default();
    let b = block(app, &format!("log: {n} messages{file}"));
    let inner = b.inner(area);
    b.render(area, buf);
    let h = inner.height as usize;
    let w = inner.width as usize;
    let want = app.chrome.log_scroll.saturating_add(h);
    let rows = marked(app, SearchTarget::Log, newest_items(app, w, want));
    let total = rows.len();
    let scroll = app.chrome.log_scroll.min(total.saturating_sub(h));
    let end = total - scroll;
    let start = end.saturating_sub(h);
    let mut shown: Vec<Line> = rows[start..end].to_vec();
    if scroll > 0
        && let Some(last) = shown.last_mut()
    {
        *last = Line::styled(format!("  ↓ {scroll} more rows (End: newest)"), t.dim());
    }
    Paragraph::new(shown).render(inner, buf);
}

/// A unit `/` searches: its whole text (neither wrapped nor cut) and the
/// rows it is drawn as, so that a text split over two rows, or cut at the
/// terminal's width, is found and its rows shown.
pub struct Item {
    pub text: String,
    pub rows: Vec<Line<'static>>,
}

impl Item {
    /// `text` wrapped at `width`, every row in `style`.
    fn wrapped(text: String, width: usize, style: Style) -> Item {
        let rows = wrap(&text, width)
            .into_iter()
            .map(|r| Line::styled(r, style))
            .collect();
        Item { text, rows }
    }

    /// One row, searched as drawn.
    fn row(row: Line<'static>) -> Item {
        let text = row.spans.iter().map(|s| s.content.as_ref()).collect();
        Item {
            text,
            rows: vec![row],
        }
    }
}

/// The log's messages at `width`, oldest first: at least the newest
/// `want` rows (all of them for `usize::MAX`).
fn newest_items(app: &App, width: usize, want: usize) -> Vec<Item> {
    let t = app.theme();
    let mut items: Vec<Item> = Vec::new();
    let mut rows = 0;
    for e in app.chrome.log.entries().rev() {
        let item = Item::wrapped(e.dated(), width, t.level(e.level));
        rows += item.rows.len();
        items.push(item);
        if rows >= want {
            break;
        }
    }
    items.reverse();
    items
}

/// Every message of the expanded log at `width`, oldest first (what `/`
/// searches).
pub fn log_items(app: &App, width: usize) -> Vec<Item> {
    newest_items(app, width, usize::MAX)
}

/// The rows of `items`, those of the items that match the search on
/// `target` marked.
pub fn marked(app: &App, target: SearchTarget, items: Vec<Item>) -> Vec<Line<'static>> {
    let search = app
        .chrome
        .search
        .as_ref()
        .filter(|s| s.target == target && app.search_in_front());
    let t = app.theme();
    items
        .into_iter()
        .flat_map(|item| {
            let hit = search.is_some_and(|s| s.matches(&item.text));
            item.rows
                .into_iter()
                .map(move |l| if hit { l.patch_style(t.selected()) } else { l })
        })
        .collect()
}

/// What the devices and the pipeline are doing, then the hints.
fn hint_spans(app: &App) -> Vec<Span<'static>> {
    let t = app.theme();
    let d = &app.cell.device;
    let mut spans = Vec::new();
    if let Some(lost) = &d.lost {
        // Word by word, so that the hint rows wrap it whole.
        spans.push(Span::styled(
            format!("DEVICE {}: ", d.lost_word()),
            t.error(),
        ));
        for w in lost.split_whitespace() {
            spans.push(Span::styled(format!("{w} "), t.error()));
        }
    } else if !d.connected {
        spans.push(Span::styled("connecting… ", t.warn()));
    }
    if let Some((_, done, total)) = d.transfer {
        let what = if d.settling && done == 0 {
            "lights settling".to_string()
        } else {
            format!("transfer {}", gauge_text(done, total, 16))
        };
        spans.push(Span::styled(format!("{what} "), t.warn()));
    }
    if app.tracker.busy() {
        spans.push(Span::styled("running… ", t.warn()));
    }
    if let Some(s) = app.chrome.search.as_ref().filter(|_| app.search_in_front()) {
        spans.push(Span::styled(
            format!("/{} match {} of {} ", s.query, s.current + 1, s.count),
            t.selected(),
        ));
    }
    spans.extend(key_hints(app));
    spans
}

/// The keys of the screen in front, then the picture's and the global ones.
fn key_hints(app: &App) -> Vec<Span<'static>> {
    key_hints_of(app, app.scope())
}

/// The hints of `scope` (with the picture's and the global ones on a
/// screen).
fn key_hints_of(app: &App, scope: Scope) -> Vec<Span<'static>> {
    let t = app.theme();
    let mut spans = Vec::new();
    let searching = app.search_in_front() && !matches!(scope, Scope::Prompt | Scope::Confirm);
    let mut hints = if searching {
        keymap::hints(Scope::Search)
    } else {
        Vec::new()
    };
    // Not offered: keys a search on takes, the image keys where no
    // checklist is shown (before a session is open there is no image, and
    // while the session list hides it they are refused), `D` before a
    // session is open, and what a session open only to look refuses
    // (`App::refused_here`).
    let keep = |b: &keymap::Binding| {
        let taken = searching
            && keymap::KEYMAP
                .iter()
                .any(|s| s.scope == Scope::Search && s.key == b.key);
        let no_session = app.session.view.is_none();
        let no_image = match b.action {
            Action::Survey(s) => {
                (s.on_the_image() && (no_session || app.screens.survey.picking))
                    || (s == SurveyAction::ResetParams && no_session)
            }
            _ => false,
        };
        // A question's "all" and "read-only" where it offers them.
        let unoffered = match (b.action, &app.chrome.modal) {
            (Action::Modal(m), Some(modal)) => !modal.offers(m),
            _ => false,
        };
        !taken && !no_image && !unoffered && app.refused_here(b.action).is_none()
    };
    hints.extend(keymap::hints_where(scope, keep));
    if let Scope::Screen(s) = scope {
        // The picture's keys once there is a picture to move over.
        if has_picture(s) && app.picture_size(s).is_some() {
            hints.extend(keymap::hints_where(Scope::Picture, keep));
        }
        hints.extend(keymap::hints_where(Scope::Global, keep));
    }
    for (k, d) in hints {
        spans.push(Span::styled(k, t.key()));
        spans.push(Span::raw(format!(" {d}  ")));
    }
    spans
}

/// The room kept on the hint rows for what comes and goes while the
/// operator tunes ("running…"), so that its coming does not take a row
/// from the screen above: a picture that lost a row would be drawn one
/// column narrower and sent again whole (issue 33). A transfer's gauge is
/// not kept room for: it comes with a capture, when the picture changes
/// anyway, and its room would cost a row at 80 × 24 for good.
/// `running… ` is 9 columns.
const STATUS_ROOM: usize = 9;

/// The hints laid out in rows of `width`: a key and its label stay
/// together.
fn hint_layout(app: &App, width: usize) -> Vec<Vec<Span<'static>>> {
    layout_spans(hint_spans(app), width, 0)
}

/// `spans` in rows of `width`, the first row starting after `used`
/// columns.
fn layout_spans(spans: Vec<Span<'static>>, width: usize, used: usize) -> Vec<Vec<Span<'static>>> {
    let mut rows: Vec<Vec<Span>> = vec![Vec::new()];
    let mut used = used;
    let mut it = spans.into_iter().peekable();
    while let Some(s) = it.next() {
        let mut group = vec![s];
        if group[0].style.add_modifier.contains(Modifier::BOLD)
            && let Some(next) = it.next_if(|n| n.style == Style::new())
        {
            group.push(next);
        }
        let w: usize = group.iter().map(|s| s.width()).sum();
        if used + w > width && used > 0 {
            rows.push(Vec::new());
            used = 0;
        }
        used += w;
        if let Some(r) = rows.last_mut() {
            r.extend(group);
        }
    }
    rows
}

/// Rows the hints need at `width` (at most three), with room kept for the
/// passing status (`STATUS_ROOM`) and for the screen's own hints while a
/// question or a field shows shorter ones: the same while a run comes and
/// goes, or a value is typed.
pub fn hint_rows(app: &App, width: u16) -> u16 {
    let now = hint_layout(app, width as usize).len();
    // Kept once there is a picture a key can re-run.
    let kept = if app.tracker.current.is_some() {
        let screen = key_hints_of(app, Scope::Screen(app.chrome.screen));
        layout_spans(screen, width as usize, STATUS_ROOM.min(width as usize)).len()
    } else {
        0
    };
    now.max(kept).clamp(1, 3) as u16
}

pub fn hints(app: &App, area: Rect, buf: &mut Buffer) {
    let lines: Vec<Line> = hint_layout(app, area.width as usize)
        .into_iter()
        .map(Line::from)
        .collect();
    // At the bottom of their rows: a row kept free is the upper one.
    let free = area.height.saturating_sub(lines.len() as u16);
    let area = Rect {
        y: area.y + free,
        height: area.height - free,
        ..area
    };
    Paragraph::new(lines).render(area, buf);
}

pub fn modal_box(app: &App, m: &Modal, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let w = area.width.min(70);
    let inner_w = w.saturating_sub(2) as usize;
    let (title, lines): (&str, Vec<Line>) = match m {
        Modal::Prompt(p) => {
            let mut lines: Vec<Line> = wrap(&p.rule, inner_w)
                .into_iter()
                .map(|r| Line::styled(r, t.dim()))
                .collect();
            let chars: Vec<char> = p.text.chars().collect();
            let reversed = Style::new().add_modifier(Modifier::REVERSED);
            let mut field = vec![Span::styled(format!("{} ", p.title), t.title())];
            if p.selected {
                // The whole offered text marked, the cursor after it.
                field.push(Span::styled(p.text.clone(), reversed));
                field.push(Span::raw(" "));
            } else {
                let before: String = chars[..p.cursor.min(chars.len())].iter().collect();
                let at: String = chars.get(p.cursor).map_or(" ".into(), |c| c.to_string());
                let after: String = chars.iter().skip(p.cursor + 1).collect();
                field.push(Span::raw(before));
                field.push(Span::styled(at, reversed));
                field.push(Span::raw(after));
            }
            lines.push(Line::from(field));
            let count = format!("{}/{} characters", chars.len(), p.max);
            lines.push(Line::styled(
                if p.selected {
                    format!("{count} · typing replaces it, ← → edit it")
                } else {
                    count
                },
                t.dim(),
            ));
            if let Some(e) = &p.error {
                lines.extend(
                    wrap(e, inner_w)
                        .into_iter()
                        .map(|r| Line::styled(r, t.error())),
                );
            }
            ("Enter accepts · Esc cancels · ←→ Home End C-u C-w", lines)
        }
        Modal::Confirm { question, .. } => {
            let mut lines: Vec<Line> = wrap(question, inner_w)
                .into_iter()
                .map(|r| Line::styled(r, t.warn()))
                .collect();
            let mut keys = Vec::new();
            for (key, word) in m.choices() {
                if !keys.is_empty() {
                    keys.push(Span::raw("   "));
                }
                keys.push(Span::styled(key, t.key()));
                keys.push(Span::raw(format!(" {word}")));
            }
            lines.push(Line::from(keys));
            ("question", lines)
        }
    };
    let h = (lines.len() as u16 + 2).min(area.height);
    let r = Rect::new(
        area.x + (area.width - w) / 2,
        area.y + area.height.saturating_sub(h) / 2,
        w,
        h,
    );
    Clear.render(r, buf);
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block(app, title))
        .render(r, buf);
}

/// The marks of the checklist, for the help window.
pub const LEGEND: &[(&str, &str)] = &[
    (">", "the image the survey is at"),
    ("abcde", "lightings captured (one letter each)"),
    (".", "a lighting not captured yet"),
    (
        "!",
        "a lighting whose saved image is damaged (R retakes it)",
    ),
    ("-", "no outputs yet"),
    ("done", "outputs saved and current"),
    ("stale", "outputs made from images changed since"),
    ("DAMAGED", "an output file does not read"),
    ("eN", "N hand edits in effect"),
];

/// The help window's entries at `width` (the drawing and `/` both use
/// them): a key with its description is one entry, however many rows it
/// wraps to.
pub fn help_items(app: &App, width: usize) -> Vec<Item> {
    let t = app.theme();
    let screen = app.chrome.screen;
    let mut sections: Vec<(String, Scope)> =
        vec![(format!("{} screen", screen.title()), Scope::Screen(screen))];
    for (title, scope) in keymap::scopes() {
        let own = matches!(scope, Scope::Screen(_));
        let pic = scope == Scope::Picture && !has_picture(screen);
        if !own && !pic {
            sections.push((title, scope));
        }
    }
    let key_w = 11;
    let desc_w = width.saturating_sub(key_w + 1).max(10);
    // A key (or a name) right-aligned, its text wrapped beside it.
    let keyed = |key: &str, text: &str| -> Item {
        let rows = wrap(text, desc_w)
            .into_iter()
            .enumerate()
            .map(|(i, part)| {
                let key = if i == 0 { key } else { "" };
                Line::from(vec![
                    Span::styled(format!("{key:>key_w$} "), t.key()),
                    Span::raw(part),
                ])
            })
            .collect();
        Item {
            text: format!("{key} {text}"),
            rows,
        }
    };
    let mut items = vec![Item::row(Line::styled("Files in use", t.title()))];
    let plate = &app.screens.calibrate.plate_name;
    for (what, file) in [
        ("profile", app.cell.profile_file.clone()),
        (
            "plate",
            crate::tui::text::clean(&crate::calib::plate::in_use(plate)),
        ),
    ] {
        items.push(keyed(what, &file));
    }
    for (title, scope) in sections {
        items.push(Item::row(Line::styled(title, t.title())));
        for (k, d) in keymap::describe(scope) {
            items.push(keyed(&k, d));
        }
    }
    items.push(Item::row(Line::styled("The checklist's marks", t.title())));
    for (m, d) in LEGEND {
        items.push(Item::row(Line::from(vec![
            Span::styled(format!("{m:>key_w$} "), t.key()),
            Span::raw(*d),
        ])));
    }
    let mouse = "The mouse, where the terminal sends it: a click chooses a checklist row or a \
                 line, the wheel scrolls lists and zooms pictures; Shift+drag selects text.";
    items.push(Item::wrapped(mouse.to_string(), width.max(10), t.dim()));
    items
}

pub fn overlay(app: &App, o: Overlay, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    // The whole screen: a window one column inside it let the borders of
    // the screen under it show at its edges.
    let r = area;
    Clear.render(r, buf);
    let inner_w = r.width.saturating_sub(2) as usize;
    let (name, lines, scroll) = match o {
        Overlay::Help { scroll } => (
            "help",
            marked(app, SearchTarget::Help, help_items(app, inner_w)),
            scroll,
        ),
        Overlay::Message { scroll } => {
            let mut lines: Vec<Line> = Vec::new();
            let mut entry = |e: &crate::tui::app::LogEntry, what: &str| {
                if !lines.is_empty() {
                    lines.push(Line::raw(""));
                }
                lines.push(Line::styled(
                    format!("{what} {} {}", e.when(), e.level.word()),
                    t.title(),
                ));
                lines.extend(
                    wrap(&e.shown(), inner_w)
                        .into_iter()
                        .map(|r| Line::styled(r, t.level(e.level))),
                );
            };
            let shown = app.chrome.shown_message().map(|(e, _)| e);
            if let Some(e) = shown {
                entry(e, "on the message line,");
            }
            let last = app.chrome.log.last();
            if let Some(e) = last.filter(|e| Some(*e) != shown) {
                entry(e, "newest,");
            }
            // An error that a later note pushed off the message row.
            let trouble = app
                .chrome
                .log
                .entries()
                .rev()
                .find(|e| e.level != crate::tui::app::Level::Info);
            if let Some(e) = trouble.filter(|e| Some(*e) != last && Some(*e) != shown) {
                entry(e, "last problem,");
            }
            if let Some(f) = app.chrome.log.file() {
                lines.push(Line::raw(""));
                lines.extend(
                    wrap(
                        &format!("Every message of this run is in {}", crate::text::path(f)),
                        inner_w,
                    )
                    .into_iter()
                    .map(|r| Line::styled(r, t.dim())),
                );
            }
            lines.push(Line::styled("m shows the whole log", t.dim()));
            ("last message", lines, scroll)
        }
    };
    let h = r.height.saturating_sub(2) as usize;
    let total = lines.len();
    let scroll = scroll.min(total.saturating_sub(h));
    let title = if total > h {
        format!(
            "{name}: rows {}–{} of {total} · ↑↓ PgUp/PgDn scroll · Esc closes",
            scroll + 1,
            (scroll + h).min(total)
        )
    } else {
        format!("{name} · Esc closes")
    };
    let shown: Vec<Line> = lines.into_iter().skip(scroll).take(h).collect();
    Paragraph::new(shown)
        .block(block(app, &title))
        .render(r, buf);
}

/// Replaces every non-ASCII symbol with an ASCII look-alike, for terminals
/// without Unicode (the ASCII preview mode promises plain ASCII output).
pub fn asciify(area: Rect, buf: &mut Buffer) {
    for y in area.top()..area.bottom() {
        for x in area.left()..area.right() {
            let Some(cell) = buf.cell_mut((x, y)) else {
                continue;
            };
            if cell.symbol().is_ascii() {
                continue;
            }
            let c = match cell.symbol().chars().next().unwrap_or(' ') {
                '—' | '–' | '─' | '━' => '-',
                '│' | '┃' => '|',
                '…' | '·' => '.',
                '×' => 'x',
                '←' => '<',
                '→' => '>',
                '↑' => '^',
                '↓' => 'v',
                '°' => 'o',
                '┌' | '┐' | '└' | '┘' | '├' | '┤' | '┬' | '┴' | '┼' => '+',
                _ => '?',
            };
            cell.set_char(c);
        }
    }
}
