//! File names with control characters in them (a line break, an escape
//! sequence) are shown escaped in the command line's messages — success
//! and error alike, `two\nlines.png` — on one line, never raw: a name can
//! neither split a message in two (so that its second half reads as a
//! message of its own) nor send the terminal a command.

use std::ffi::OsStr;
use std::path::Path;

use crate::support::vss;
use vss::formats::{imageio, img::ImgFile};
use vss::llv::GreyImage;

/// A name with a line break in it, and as messages show it.
const NL: &str = "two\nlines";
const NL_SHOWN: &str = "two\\nlines";
/// A name with an escape sequence (clear the screen), and as shown.
const ESC: &str = "esc\x1b[2Jape";
const ESC_SHOWN: &str = "esc\\x1b[2Jape";

/// Runs vss in `cwd`: whether it succeeded, stdout, stderr.
fn run(cwd: &Path, args: &[&OsStr]) -> (bool, String, String) {
    let o = vss().current_dir(cwd).args(args).output().unwrap();
    (
        o.status.success(),
        String::from_utf8(o.stdout).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    )
}

fn os(s: &str) -> &OsStr {
    OsStr::new(s)
}

/// `text` names the file as `shown` and holds no control character but
/// the line breaks between messages, and no line of it is the name's
/// second half.
fn assert_shown(text: &str, shown: &str) {
    assert!(text.contains(shown), "{shown:?} not in {text:?}");
    assert!(
        !text.chars().any(|c| c.is_control() && c != '\n'),
        "a control character in {text:?}"
    );
    for l in text.lines() {
        assert!(!l.starts_with("lines") && !l.starts_with("ape"), "{text:?}");
    }
}

fn grey(dir: &Path, name: &str) {
    let data = (0..64u8).map(|v| v * 4).collect();
    let image = GreyImage::new(8, 8, data).unwrap();
    imageio::write_any(&dir.join(name), &ImgFile::new(image)).unwrap();
}

#[test]
fn convert_llv_session_and_report_show_names_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    grey(d, &format!("{NL}.png"));
    let (ok, so, se) = run(
        d,
        &[
            os("convert"),
            os(&format!("{NL}.png")),
            os(&format!("{ESC}.pgm")),
        ],
    );
    assert!(ok, "{se}");
    assert_eq!(so, format!("{NL_SHOWN}.png → {ESC_SHOWN}.pgm (8 × 8)\n"));
    assert_shown(&se, "");
    // Errors: one line each, the name escaped.
    for args in [
        vec![
            os("convert"),
            os(&format!("{NL}.png")),
            os(&format!("{ESC}.jpg")),
        ],
        vec![os("convert"), os(&format!("gone{NL}.png")), os("out.png")],
        vec![os("llv"), os(&format!("gone{NL}.img"))],
        vec![os("info"), os(&format!("gone{NL}.img"))],
        vec![os("session"), os("show"), os(&format!("no{NL}"))],
        vec![os("session"), os("check"), os(&format!("no{ESC}"))],
        vec![os("report"), os(&format!("no{NL}"))],
        vec![os("report"), os("--img"), os(&format!("gone{NL}.png"))],
    ] {
        let (ok, so, se) = run(d, &args);
        assert!(!ok, "{args:?}: {so}");
        assert_eq!(se.lines().count(), 1, "{args:?}: {se:?}");
        assert!(
            se.contains("two\\nlines") || se.contains(ESC_SHOWN),
            "{args:?}: {se:?}"
        );
        assert_shown(&se, "vss: error: ");
    }
    // The report names what it wrote.
    let (ok, so, se) = run(
        d,
        &[
            os("report"),
            os("--img"),
            os(&format!("{NL}.png")),
            os("--ps"),
            os(&format!("{ESC}.ps")),
        ],
    );
    assert!(ok, "{se}");
    assert_shown(&so, &format!("wrote {ESC_SHOWN}.ps"));
    assert!(d.join(format!("{ESC}.ps")).is_file());
}

#[test]
fn calibrate_shows_view_names_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(d.join("board.toml"), crate::calib_real::BOARD).unwrap();
    let photos = crate::calib_real::photo_paths();
    let view = d.join(format!("{NL}.jpg"));
    std::fs::copy(&photos[6], &view).unwrap();
    let cdf = format!("{ESC}.cdf");
    let mut args: Vec<&OsStr> = vec![
        os("calibrate"),
        os("--plate"),
        os("board.toml"),
        os("--scale"),
        os("0.001,0.001"),
        os("--out"),
        os(&cdf),
    ];
    args.extend(photos[..5].iter().map(|p| p.as_os_str()));
    args.push(view.as_os_str());
    let (ok, so, se) = run(d, &args);
    assert!(ok, "{so}\n{se}");
    assert_shown(&so, &format!("{NL_SHOWN}.jpg"));
    assert_shown(&so, &format!("{ESC_SHOWN}.cdf"));
    assert_shown(&se, "");
    // A view that is not there: refused, named on one line.
    let gone = format!("gone{NL}.jpg");
    args.push(os(&gone));
    let (ok, _, se) = run(d, &args);
    assert!(!ok);
    assert_shown(&se, &format!("gone{NL_SHOWN}.jpg"));
    assert_eq!(se.lines().count(), 1, "{se:?}");
}
