//! The console against a shop floor's files and folders: a session folder
//! moved away while it is open, a manifest that is not a file.

use vss::tui::keymap::{Action, SurveyAction};

use super::tui_harness::{Console, SURVEY, flat};

/// A session folder renamed while the console has it open (someone tidies
/// the survey folder): the next save is refused and said as what happened
/// — the folder is gone — not as a take-over by "nobody"; nothing is
/// written (no folder is made again at the old path); and once the folder
/// is put back, `a` saves.
#[test]
fn a_session_folder_moved_away_while_open_is_said_and_nothing_is_written() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let d = c.session();
    c.capture_current(1);
    // The review can come before the store has recorded the frames (the
    // pipeline does not wait for their saves): the folder goes once they
    // are recorded, lighting c last.
    let manifest = d.join("cube.toml");
    c.wait("image 1's frames recorded", 20, |_| {
        std::fs::read_to_string(&manifest).is_ok_and(|m| m.contains("cube1c.img"))
    });
    let moved = c.sessions().join("cube-moved");
    std::fs::rename(&d, &moved).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    let s = c.wait_text("outputs of image 1 NOT saved", 10);
    let s = flat(&s);
    assert!(s.contains("is gone (moved"), "what happened:\n{s}");
    assert!(!s.contains("taken over"), "not a take-over:\n{s}");
    assert!(!d.exists(), "nothing made at the old path");
    assert!(
        !moved.join("cube1.ldr").exists(),
        "nothing written where it went"
    );
    std::fs::rename(&moved, &d).unwrap();
    c.press(SURVEY, Action::Survey(SurveyAction::Accept));
    c.wait_text("image 1 accepted", 20);
    assert!(d.join("cube1.ldr").is_file());
    c.send("q");
    c.wait_exit(10);
}

/// A session whose manifest was replaced by a folder is listed DAMAGED
/// with why, not left out of the list as if there were no session.
#[test]
fn a_session_whose_manifest_is_a_folder_is_listed_damaged() {
    let mut c = Console::start(80, 24, &[]);
    c.create_session("cube");
    let m = c.session().join("cube.toml");
    let mut c = c.restart_after(|_| {
        std::fs::remove_file(&m).unwrap();
        std::fs::create_dir(&m).unwrap();
    });
    c.wait_text("choose a session", 10);
    c.wait("cube listed DAMAGED", 10, |s| {
        s.lines()
            .any(|r| r.contains("cube") && r.contains("DAMAGED"))
    });
    c.send("q");
    c.wait_exit(10);
}

/// The peak resident memory (VmHWM) of process `pid`, KiB.
fn vm_hwm_kib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap()
}

/// A frame of a session replaced by a huge one (a sparse 40000² `.img`,
/// 1.6 GB) is marked damaged when the console opens the session, read no
/// further than its header: the console stays small. It read the frame
/// whole (1.5 GB resident).
#[test]
fn a_frame_replaced_by_a_huge_one_is_marked_and_not_read() {
    let mut c = Console::start(80, 24, &[]);
    c.survey(1);
    let frame = c.session().join("cube1a.img");
    let mut c = c.restart_after(|_| {
        std::fs::remove_file(&frame).unwrap();
        let mut head = vec![0u8; 64];
        head[..2].copy_from_slice(b"IM");
        head[4..6].copy_from_slice(&40000u16.to_le_bytes());
        head[6..8].copy_from_slice(&40000u16.to_le_bytes());
        std::fs::write(&frame, &head).unwrap();
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(&frame)
            .unwrap();
        f.set_len(64 + 40000 * 40000).unwrap();
    });
    c.wait_text("choose a session", 10);
    c.wait("the session listed", 10, |s| s.contains("1/4 done"));
    c.send("\r");
    // The message line says the session has damage (held as the answer to
    // Enter); the log, as an operator opens it, says which file and why.
    c.wait_words("1 damaged or missing file(s) in this session", 30);
    c.send("m");
    let s = c.wait("the log", 30, |s| flat(s).contains("too large"));
    assert!(flat(&s).contains("cube1a.img"), "{s}");
    let pid = c.child.process_id().unwrap();
    let kib = vm_hwm_kib(pid);
    assert!(kib < 256 << 10, "the console's peak is {kib} KiB");
    c.send("q");
    c.wait_exit(10);
}

/// A flat grey 64 × 64 `.img` at `p`, a photograph to load.
fn grey_photo(p: &std::path::Path) {
    let img = vss::llv::GreyImage::new(64, 64, vec![128; 64 * 64]).unwrap();
    vss::formats::img::write_img(p, &vss::formats::img::ImgFile::new(img)).unwrap();
}

/// From the start: the Calibrate screen, and `o`'s question of which
/// photographs to load.
fn ask_for_photographs(c: &mut Console) {
    use vss::tui::keymap::{CalibrateAction as CA, GlobalAction, Scope, ScreenId};
    c.wait_text("Survey", 10);
    c.press(
        Scope::Global,
        Action::Global(GlobalAction::GoTo(ScreenId::Calibrate)),
    );
    c.wait_text("views kept: 0", 10);
    c.press(
        Scope::Screen(ScreenId::Calibrate),
        Action::Calibrate(CA::Open),
    );
    c.wait_text("photographs to load:", 10);
}

/// On the Calibrate screen, `o` with the name of one photograph whose name
/// holds a space (as a phone or a file manager names them) loads it. The
/// text was split at the space: "plate: no such file".
#[test]
fn a_photograph_whose_name_holds_a_space_is_loaded() {
    let mut c = Console::start(80, 24, &[]);
    grey_photo(&c.dir.path().join("plate 1.img"));
    ask_for_photographs(&mut c);
    c.send("plate 1.img\r");
    let s = c.wait("the photograph read", 20, |s| {
        flat(s).contains("1 photographs loaded") || flat(s).contains("no such file")
    });
    assert!(flat(&s).contains("1 photographs loaded"), "{s}");
    c.send("q");
    c.wait_exit(10);
}

/// A folder of photographs loaded on the Calibrate screen with a FIFO
/// among them (named as a photograph) says it did not load it, and why; it
/// was passed over without a word.
#[test]
fn a_fifo_among_the_photographs_is_said_not_loaded() {
    let mut c = Console::start(80, 24, &[]);
    let photos = c.dir.path().join("photos");
    std::fs::create_dir(&photos).unwrap();
    grey_photo(&photos.join("p1.img"));
    let fifo = photos.join("p2.png");
    crate::support::files::mkfifo(&fifo);
    ask_for_photographs(&mut c);
    c.send("photos\r");
    c.wait_words("1 photographs loaded", 20);
    c.send("m");
    let s = c.wait("the log", 10, |s| flat(s).contains("not loaded"));
    assert!(
        flat(&s).contains("p2.png") && flat(&s).contains("FIFO"),
        "{s}"
    );
    c.send("q");
    c.wait_exit(10);
}
