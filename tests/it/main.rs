//! The integration tests of `vss`, one binary with a module per area:
//! linking one executable instead of one per file keeps a build after a
//! one-line edit short. Run one area with `cargo test --test it NAME::`.
//! Shared helpers live in `support/`. The accuracy floors are a binary of
//! their own, `tests/accuracy/` (`cargo test --test accuracy`).

mod support;

mod accuracy_cli;
mod calib;
mod calib_cli;
mod calib_console;
mod calib_real;
mod cli_formats;
mod cli_names;
mod cli_pipe;
mod cli_standalone;
mod formats_malformed;
mod formats_roundtrip;
#[cfg(feature = "genicam")]
mod genicam;
#[cfg(feature = "genicam")]
mod genicam_console;
mod golden;
mod llv_alloc;
mod llv_auto;
mod llv_auto_cli;
mod llv_cli;
mod llv_corners;
mod llv_engine;
mod llv_jpeg;
mod llv_lines;
mod llv_shadow;
mod photometric;
mod profile;
mod report_cli;
mod report_memory;
mod report_ps;
mod report_svg;
mod rig_cdf;
mod rig_cli;
mod rig_faults;
mod rig_images;
mod rig_lights;
mod rig_protocol;
mod robust_fs;
mod robust_fuzz;
mod robust_inputs;
mod robust_report;
mod robust_session;
mod robust_xfile;
mod session_api;
mod session_big;
mod session_cli;
mod session_crash;
mod session_link;
mod session_redo;
mod tui_answers;
mod tui_device;
mod tui_flow;
mod tui_golden;
mod tui_harness;
mod tui_pty;
mod tui_pty_builtin;
mod tui_pty_busy;
mod tui_pty_crossover;
mod tui_pty_edit;
mod tui_pty_feedback;
mod tui_pty_hidden;
mod tui_pty_layout;
mod tui_pty_look;
mod tui_pty_narrow;
mod tui_pty_operator;
mod tui_pty_polish;
mod tui_pty_readonly;
mod tui_pty_repeats;
mod tui_pty_review;
mod tui_pty_search;
mod tui_pty_shared;
mod tui_pty_switch;
mod tui_pty_takeover;
mod tui_pty_trouble;
mod tui_pty_tuning;
mod tui_pty_xcal;
mod tui_pty_xcdf;
mod tui_pty_xfile;
mod tui_pty_xterm;
mod tui_screens;
mod tui_truth;
