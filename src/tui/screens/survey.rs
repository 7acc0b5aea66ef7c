//! The Survey screen: the session list (no session yet, or `o`), damaged
//! sessions among them; then the checklist of image numbers and lightings
//! (any row can be chosen and gone to), the step the survey is at, and a
//! preview of the image under work.

use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};

use super::{block, block2, gauge_text, split_panel, window};
use crate::tui::app::{App, Phase};
use crate::tui::event::FramePurpose;
use crate::tui::widgets::preview::{Layer, Preview, stretch_of};

/// Where the checklist's first image row is, inside the panel (rows).
pub const CHECKLIST_HEAD: u16 = 3;

pub fn render(app: &App, area: Rect, buf: &mut Buffer) {
    let (panel, right) = split_panel(area, 34);
    if app.session.view.is_none() || app.screens.survey.picking {
        sessions(app, panel, buf);
    } else {
        checklist(app, panel, buf);
    }
    let lines = step_lines(app);
    // The box grows by the rows its text wraps to (the values the next
    // capture uses that are not the profile's), up to half the column.
    let inner_w = right.width.saturating_sub(2) as usize;
    let rows: usize = lines
        .iter()
        .map(|l| super::chrome::wrap(&l.to_string(), inner_w).len().max(1))
        .sum();
    let h = (rows as u16 + 2).max(5).min((right.height / 2).max(5));
    let [step, prev] = Layout::vertical([Constraint::Length(h), Constraint::Min(1)]).areas(right);
    Paragraph::new(lines)
        .wrap(Wrap { trim: true })
        .block(block(app, "next step"))
        .render(step, buf);
    preview(app, prev, buf);
}

fn preview(app: &App, area: Rect, buf: &mut Buffer) {
    let cur = app.tracker.current.as_ref();
    let Some((c, (letter, img))) = cur.and_then(|c| first_frame(app, c).map(|f| (c, f))) else {
        Paragraph::new("no image yet")
            .block(block(app, "image"))
            .render(area, buf);
        return;
    };
    let s = stretch_of(img);
    let review = c.k == app.session.work.k && app.session.work.phase == Phase::Review;
    let lines = c.lines().filter(|_| review);
    let what = if lines.is_some() { " + lines" } else { "" };
    let title = format!("image {}{letter}{what}", c.k);
    let b = block2(app, &title, &format!("grey {}–{} stretched", s.lo, s.hi));
    let inner = b.inner(area);
    b.render(area, buf);
    let layer = match lines {
        Some(ls) => Layer::LinesOver(img, ls),
        None => Layer::Grey(img),
    };
    let mut p = Preview::new(layer, app.chrome.look.mode, app.chrome.look.colour);
    p.palette.c256 = app.chrome.look.c256;
    let nav = &app.screens.survey.nav;
    p.view = nav.view;
    if nav.cursor.is_some() {
        p.cursor = Some(nav.cursor_or_centre(img.size()));
    }
    p.render(inner, buf);
}

/// The first lighting captured, in profile order (the last one may be the
/// dark ambient frame).
fn first_frame<'a>(
    app: &App,
    c: &'a crate::tui::app::Loaded,
) -> Option<(char, &'a crate::llv::GreyImage)> {
    app.cell
        .letters
        .iter()
        .find_map(|l| c.frame(*l).map(|g| (*l, g)))
}

/// The session list's rows at `width` columns, each with the index of its
/// session: a session whose row would run past the edge (a long name, "in
/// use by" a long user name, why it does not read) goes on over more rows,
/// indented, rather than being cut. The drawing and the mouse both use it.
pub fn session_rows(app: &App, width: usize) -> Vec<(usize, Line<'static>)> {
    let t = app.theme();
    let mut rows = Vec::new();
    for (i, e) in app.session.list.iter().enumerate() {
        let st = if i == app.screens.survey.selected {
            t.selected()
        } else if e.damaged.is_some() {
            t.error()
        } else {
            Default::default()
        };
        let text = match &e.damaged {
            Some(why) => {
                // The row is narrow: the file's name, not its folder.
                let folder = format!("{}/", crate::text::path(&e.dir));
                let why = why.strip_prefix(folder.as_str()).unwrap_or(why);
                format!(" {}  DAMAGED: {why}", e.name)
            }
            None => format!(" {:<10} {}", e.name, e.summary),
        };
        let opts = textwrap::Options::new(width.max(4)).subsequent_indent("   ");
        for r in textwrap::wrap(&text, opts) {
            rows.push((i, Line::styled(r.into_owned(), st)));
        }
    }
    rows
}

/// The first row of the selected session in [`session_rows`].
pub fn selected_row(rows: &[(usize, Line)], selected: usize) -> usize {
    rows.iter().position(|r| r.0 == selected).unwrap_or(0)
}

fn sessions(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let inner_h = area.height.saturating_sub(2) as usize;
    let listed = session_rows(app, area.width.saturating_sub(2) as usize);
    let focus = selected_row(&listed, app.screens.survey.selected);
    let rows: Vec<Line> = listed.into_iter().map(|r| r.1).collect();
    let mut lines = vec![Line::raw("Sessions in the survey folder:")];
    if rows.is_empty() {
        lines.push(Line::styled("  (none yet)", t.dim()));
    }
    let room = inner_h.saturating_sub(4);
    lines.extend(window(rows, focus, room, t));
    lines.push(Line::raw(""));
    lines.push(Line::from(vec![
        Span::styled("↑↓ Enter", t.key()),
        Span::raw(" open · "),
        Span::styled("n", t.key()),
        Span::raw(" new"),
    ]));
    if app.screens.survey.picking {
        lines.push(Line::from(vec![
            Span::styled("Esc", t.key()),
            Span::raw(" back to the checklist"),
        ]));
    }
    let title = if app.screens.survey.picking {
        "open another session"
    } else {
        "choose a session"
    };
    Paragraph::new(lines)
        .block(block(app, title))
        .render(area, buf);
}

/// One checklist row: `> 1  1   1 abcde done e2`.
fn row_text(app: &App, k: u32) -> (String, bool) {
    let Some(v) = &app.session.view else {
        return (String::new(), false);
    };
    let st = v.images.iter().find(|i| i.k == k);
    let cur = app.tracker.current.as_ref().filter(|c| c.k == k);
    let captured: Vec<char> = match (cur, st) {
        (Some(c), _) => c.frames.iter().map(|f| f.0).collect(),
        (_, Some(i)) => i.captured.clone(),
        _ => Vec::new(),
    };
    let damaged: Vec<char> = st
        .map(|i| i.damaged.iter().map(|d| d.0).collect())
        .unwrap_or_default();
    let marks: String = v
        .letters
        .iter()
        .map(|l| {
            let unsaved = cur.is_some_and(|c| c.unsaved.iter().any(|d| d.0 == *l));
            if unsaved || damaged.contains(l) && cur.is_none_or(|c| c.frame(*l).is_none()) {
                '!'
            } else if captured.contains(l) {
                *l
            } else {
                '.'
            }
        })
        .collect();
    let w = &app.session.work;
    let (cam, loc) = match st {
        Some(i) if k != w.k || w.phase != Phase::Setup => (i.camera, i.location),
        _ => (w.camera, w.location),
    };
    let bad = st.is_some_and(|i| i.outputs_damaged.is_some()) || marks.contains('!');
    let out = match st {
        Some(i) if i.outputs_damaged.is_some() => "DAMAGED".to_string(),
        Some(i) if i.stale => "stale".into(),
        Some(i) if i.outputs && i.edits > 0 => format!("done e{}", i.edits),
        Some(i) if i.outputs => "done".into(),
        _ => "-".into(),
    };
    let here = if k == w.k && w.phase != Phase::Complete {
        '>'
    } else {
        ' '
    };
    (
        format!("{here}{k:>3} {cam:>3} {loc:>3} {marks:<6} {out}"),
        bad,
    )
}

fn checklist(app: &App, area: Rect, buf: &mut Buffer) {
    let t = app.theme();
    let Some(v) = &app.session.view else { return };
    let done = v.images.iter().filter(|i| i.done()).count();
    let problems = v.problems();
    let mut lines = vec![
        Line::styled(
            format!("lightings {}", v.letters.iter().collect::<String>()),
            t.dim(),
        ),
        if problems > 0 {
            Line::styled(format!("{problems} damaged or missing file(s)"), t.error())
        } else {
            Line::styled(format!("{done} of {} done", v.images.len()), t.ok())
        },
        Line::raw(" img cam loc lights out"),
    ];
    let ks = app.session.numbers();
    let sel = app.screens.survey.row(&app.session.work);
    let rows: Vec<Line> = ks
        .iter()
        .map(|&k| {
            let (text, bad) = row_text(app, k);
            let style = if k == sel {
                t.selected()
            } else if bad {
                t.error()
            } else if text.contains("done") {
                t.ok()
            } else {
                Default::default()
            };
            Line::styled(text, style)
        })
        .collect();
    let room = area.height.saturating_sub(2 + CHECKLIST_HEAD) as usize;
    let focus = ks.iter().position(|&k| k == sel).unwrap_or(0);
    lines.extend(window(rows, focus, room, t));
    Paragraph::new(lines)
        .block(block(app, &format!("session {}", v.name)))
        .render(area, buf);
}

/// The values the panel holds that are not the profile's, which the next
/// capture or run uses, and the key that puts them back.
fn changed_line(app: &App) -> Option<Line<'static>> {
    let t = app.theme();
    let changed = app.tracker.changed();
    if changed.is_empty() {
        return None;
    }
    Some(Line::from(vec![
        Span::styled(
            format!("not the profile's: {}", changed.join(", ")),
            t.warn(),
        ),
        Span::raw(" · "),
        Span::styled("D", t.key()),
        Span::raw(" profile's"),
    ]))
}

fn step_lines(app: &App) -> Vec<Line<'static>> {
    let t = app.theme();
    let w = &app.session.work;
    let key = |k: &'static str| Span::styled(k, t.key());
    let sel = app.screens.survey.row(w);
    let text: Vec<Line> = if app.read_only() {
        // Open only to look (`app::readonly`): nothing to capture or accept.
        let keys = if app.screens.survey.picking {
            vec![
                key("↑↓ Enter"),
                Span::raw(" opens a session; this one, to write"),
            ]
        } else {
            vec![
                key("↑↓ Enter"),
                Span::raw(" shows an image · "),
                key("o"),
                Span::raw(" opens another session"),
            ]
        };
        vec![
            Line::styled("Open only to look: nothing will be saved.", t.warn()),
            Line::from(keys),
        ]
    } else if let Some(v) = app
        .session
        .view
        .as_ref()
        .filter(|_| app.screens.survey.picking)
    {
        // The list of sessions is open beside this one: Enter opens the
        // session chosen there, not this one's next capture.
        vec![
            Line::raw(format!("Session {} stays open until another is.", v.name)),
            Line::from(vec![
                key("↑↓ Enter"),
                Span::raw(" opens a session · "),
                key("Esc"),
                Span::raw(" goes back"),
            ]),
        ]
    } else if app.session.view.is_some() && sel != w.k {
        vec![
            Line::raw(format!("Image {sel} chosen in the checklist.")),
            Line::from(vec![
                key("Enter"),
                Span::raw(format!(" goes to image {sel}, ")),
                key("R"),
                Span::raw(" captures it again"),
            ]),
            Line::from(vec![
                key("Esc"),
                Span::raw(if w.phase == Phase::Complete {
                    // The survey is done: there is no image `w.k`.
                    " back to the survey's end".to_string()
                } else {
                    format!(" back to image {}", w.k)
                }),
            ]),
        ]
    } else {
        match w.phase {
            Phase::NoSession => vec![Line::from(vec![
                Span::raw("Create a session ("),
                key("n"),
                Span::raw(") or open one ("),
                key("↑↓ Enter"),
                Span::raw(")."),
            ])],
            Phase::Setup => {
                let missing: String = app.missing_letters().iter().collect();
                let again = app
                    .tracker
                    .current
                    .as_ref()
                    .is_some_and(|c| c.k == w.k && !c.damaged.is_empty());
                vec![
                    Line::raw(format!(
                        "Image {}: camera {} (c), location {} (p)",
                        w.k, w.camera, w.location
                    )),
                    Line::from(vec![
                        key("Enter"),
                        Span::raw(if missing.is_empty() {
                            " runs the stages".to_string()
                        } else if again {
                            format!(" captures lighting {missing} again")
                        } else {
                            format!(" captures lightings {missing}")
                        }),
                    ]),
                ]
            }
            Phase::Capturing => {
                let now = match app.cell.device.transfer {
                    Some((FramePurpose::Survey { letter, .. }, 0, _))
                        if app.cell.device.settling =>
                    {
                        format!("lighting {letter}: lights settling…")
                    }
                    Some((FramePurpose::Survey { letter, .. }, d, n)) => {
                        format!("lighting {letter} {}", gauge_text(d, n, 26))
                    }
                    _ => "switching lights…".into(),
                };
                let total = app.cell.letters.len();
                let have = total - app.missing_letters().len();
                vec![
                    Line::raw(format!("Image {}: capturing {}/{total}", w.k, have + 1)),
                    Line::raw(now),
                    Line::from(vec![key("Esc"), Span::raw(" stops")]),
                ]
            }
            Phase::Processing => vec![Line::raw(format!("Image {}: running the stages…", w.k))],
            Phase::Review => {
                let cur = app.tracker.current.as_ref();
                let (n, raw) = cur
                    .and_then(|c| c.outputs.as_ref())
                    .map_or((0, 0), |o| (o.lines.len(), o.lines_raw.len()));
                let n = cur.and_then(|c| c.lines()).map_or(n, <[_]>::len);
                let unsaved = cur.map_or(String::new(), |c| c.unsaved_letters());
                if unsaved.is_empty() {
                    // Saved already (Ctrl-S on the Pipeline screen): a only
                    // goes on, as it says when pressed.
                    let saved = cur.is_some_and(|c| c.saved_with(&app.tracker.params));
                    let (head, mut a) = if saved {
                        (
                            ", saved",
                            vec![key("a"), Span::raw(" goes on: it is accepted · ")],
                        )
                    } else {
                        let asks = Span::raw(" asks) · ");
                        (
                            "",
                            vec![key("a"), Span::raw(" accepts ("), key("Enter"), asks],
                        )
                    };
                    a.extend([key("R"), Span::raw(" again")]);
                    vec![
                        Line::raw(format!(
                            "Image {}: {n} lines ({raw} before CONNECT){head}",
                            w.k
                        )),
                        Line::from(a),
                        Line::from(vec![
                            key("3"),
                            Span::raw(" tune · "),
                            key("4"),
                            Span::raw(" edit"),
                        ]),
                    ]
                } else {
                    // Not accepted until every lighting is on disk.
                    vec![
                        Line::raw(format!("Image {}: {n} lines ({raw} before CONNECT)", w.k)),
                        Line::styled(format!("{unsaved} NOT saved"), t.error()),
                        Line::from(vec![
                            key("R"),
                            Span::raw(" captures again · "),
                            key("!"),
                            Span::raw(" why"),
                        ]),
                    ]
                }
            }
            Phase::Complete => vec![
                match app.session.view.as_ref().map(|v| (v.complete_text(), v)) {
                    Some((text, v)) if !v.problem_list().is_empty() => {
                        Line::styled(format!("{text} — R on one puts it right"), t.error())
                    }
                    _ => Line::styled("Survey complete.", t.ok()),
                },
                Line::from(vec![key("5"), Span::raw(" writes the report (e)")]),
                // One line of at most 44 columns: the box's width at 80.
                Line::from(vec![
                    key("↑↓ Enter"),
                    Span::raw(" earlier image · "),
                    key("Enter"),
                    Span::raw(format!(" one more ({})", w.k)),
                ]),
            ],
        }
    };
    let mut text = text;
    // Which profile file the console runs on, where the operator starts.
    if matches!(w.phase, Phase::NoSession | Phase::Setup) {
        text.push(Line::styled(
            format!("profile: {}", app.cell.profile_file),
            t.dim(),
        ));
    }
    if matches!(
        w.phase,
        Phase::Setup | Phase::Processing | Phase::Review | Phase::Complete
    ) && let Some(l) = changed_line(app)
    {
        text.push(l);
    }
    // An acceptance that failed stays said here, first, until the image
    // is accepted: the message row only shows the newest message.
    let refused: Vec<Line> = app
        .session
        .refused
        .iter()
        // The image under review says it itself.
        .filter(|r| app.session.view.is_some() && !(r.k == w.k && w.phase == Phase::Review))
        .map(|crate::tui::app::Refused { k, why, .. }| {
            Line::styled(
                format!("Image {k} NOT accepted: its outputs were not saved ({why}) — ↑↓ Enter goes to it, then a"),
                t.error(),
            )
        })
        .collect();
    refused.into_iter().chain(text).collect()
}
