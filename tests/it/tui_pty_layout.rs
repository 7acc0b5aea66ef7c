//! A stable layout and few bytes per parameter key (issue 33, annoyance
//! 5), measured on the real binary in a pty on the built-in cell (512 ×
//! 512, five lightings), as an operator on a slow link meets it: every
//! byte the console writes after a parameter key, until it is quiet, is
//! counted (at most 4 KiB at 120 × 40, 2 KiB at 80 × 24), and every frame
//! it draws meanwhile is replayed through a terminal emulator to check
//! that the picture keeps its place (it moved one column and back while
//! "running…" took a second hint row at 120 × 40, and each move sent the
//! whole picture again: 32.4 KiB a key).

use std::time::{Duration, Instant};

use vss::tui::keymap::{Action, PipelineAction, Scope, ScreenId};

use super::tui_harness::{Console, PIPELINE, panel_value};

/// The console with the built-in profile in an empty folder, `HOME` and
/// the XDG folders in another empty one (kept alive by the caller).
fn start_bare(cols: u16, rows: u16, home: &std::path::Path) -> Console {
    let dir = tempfile::tempdir().unwrap();
    let h = |sub: &str| home.join(sub).to_string_lossy().into_owned();
    let env = [
        ("HOME", home.to_string_lossy().into_owned()),
        ("XDG_CONFIG_HOME", h(".config")),
        ("XDG_DATA_HOME", h(".local/share")),
        ("XDG_CACHE_HOME", h(".cache")),
        ("XDG_STATE_HOME", h(".local/state")),
    ];
    let env: Vec<(&str, &str)> = env.iter().map(|(k, v)| (*k, v.as_str())).collect();
    Console::start_in(dir, cols, rows, &env, &[])
}

/// Waits until the console has written nothing for `quiet` (at most 30 s).
fn settle(c: &Console, quiet: Duration) -> usize {
    let end = Instant::now() + Duration::from_secs(30);
    let mut last = (c.raw.lock().unwrap().len(), Instant::now());
    loop {
        std::thread::sleep(Duration::from_millis(20));
        let n = c.raw.lock().unwrap().len();
        if n != last.0 {
            last = (n, Instant::now());
        } else if last.1.elapsed() >= quiet {
            return n;
        }
        assert!(Instant::now() < end, "the console never went quiet");
    }
}

/// The columns from the first to the last drawn cell of the picture (the
/// preview box right of the parameter panel, its border left out), over
/// every row of the box.
fn picture_columns(s: &vt100::Screen, cols: u16, rows: u16) -> Option<(u16, u16)> {
    let mut span: Option<(u16, u16)> = None;
    // The preview box starts at the parameter panel's width (32).
    for r in 2..rows.saturating_sub(6) {
        for col in 33..cols.saturating_sub(1) {
            let drawn = s
                .cell(r, col)
                .is_some_and(|c| !c.contents().trim().is_empty() && c.contents() != "│");
            if drawn {
                span = Some(span.map_or((col, col), |(a, b)| (a.min(col), b.max(col))));
            }
        }
    }
    span
}

/// Bytes written after one `+` on `param`, and the picture's columns in
/// every frame drawn meanwhile.
fn one_key(c: &mut Console, cols: u16, rows: u16, param: &str) -> (usize, Vec<(u16, u16)>) {
    let before = settle(c, Duration::from_millis(700));
    let old = panel_value(&c.screen(), param).expect("the parameter on screen");
    c.press(PIPELINE, Action::Pipeline(PipelineAction::Inc));
    c.wait(&format!("{param} changed and run"), 30, |s| {
        panel_value(s, param).is_some_and(|v| v != old) && !s.contains("running")
    });
    let after = settle(c, Duration::from_millis(700));
    let raw = c.raw.lock().unwrap().clone();
    // Replay: the screen before the key, then frame by frame.
    let mut p = vt100::Parser::new(rows, cols, 0);
    p.process(&raw[..before]);
    let mut spans = vec![picture_columns(p.screen(), cols, rows).expect("a picture")];
    let end = b"\x1b[?2026l";
    let mut rest = &raw[before..after];
    while !rest.is_empty() {
        let cut = rest
            .windows(end.len())
            .position(|w| w == end)
            .map_or(rest.len(), |i| i + end.len());
        p.process(&rest[..cut]);
        rest = &rest[cut..];
        if let Some(s) = picture_columns(p.screen(), cols, rows) {
            spans.push(s);
        }
    }
    (after - before, spans)
}

fn parameter_keys_keep_the_picture_still(cols: u16, rows: u16, ceiling: usize) {
    let home = tempfile::tempdir().unwrap();
    let mut c = start_bare(cols, rows, home.path());
    c.create_session("cube");
    c.capture_current(1);
    c.open_pipeline();
    let mut report = Vec::new();
    let mut at = 0;
    for param in ["edges.floor", "connect.min_line_length"] {
        let want = vss::llv::params::PARAMS
            .iter()
            .position(|sp| sp.key == param)
            .unwrap();
        for _ in at..want {
            c.press(PIPELINE, Action::Pipeline(PipelineAction::ParamNext));
        }
        at = want;
        for _ in 0..2 {
            let (bytes, spans) = one_key(&mut c, cols, rows, param);
            report.push(format!("{param}: {bytes} B"));
            assert!(
                spans.windows(2).all(|w| w[0] == w[1]),
                "at {cols} × {rows} a `+` on {param} moved the picture (first and last \
                 columns frame by frame): {spans:?}\n{}",
                c.screen()
            );
            assert!(
                bytes <= ceiling,
                "at {cols} × {rows} a `+` on {param} wrote {bytes} B (at most {ceiling})\n{}",
                c.screen()
            );
        }
    }
    eprintln!("{cols} × {rows}: {}", report.join(", "));
    c.send("q");
}

/// The Pipeline screen's hints on one row, in columns (as the hint row
/// lays them out: key, space, label, two spaces).
fn pipeline_hints_width() -> u16 {
    use vss::tui::keymap::hints;
    [
        Scope::Screen(ScreenId::Pipeline),
        Scope::Picture,
        Scope::Global,
    ]
    .into_iter()
    .flat_map(hints)
    .map(|(k, d)| (k.chars().count() + 1 + d.chars().count() + 2) as u16)
    .sum()
}

/// Where the hints just fit one row, "running…" made them two and took a
/// row from the picture: it moved a column and was sent again whole (at
/// 120 × 40 before the Pipeline screen's hints grew past one row).
#[test]
fn a_parameter_key_where_the_hints_just_fit_one_row_keeps_the_picture_still() {
    parameter_keys_keep_the_picture_still(pipeline_hints_width() + 1, 40, 4096);
}

#[test]
fn a_parameter_key_at_120_by_40_keeps_the_picture_still_within_4_kib() {
    parameter_keys_keep_the_picture_still(120, 40, 4096);
}

#[test]
fn a_parameter_key_at_80_by_24_keeps_the_picture_still_within_2_kib() {
    parameter_keys_keep_the_picture_still(80, 24, 2048);
}
