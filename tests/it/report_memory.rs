//! What a report costs in memory (issues 33 and 34), measured on the real
//! binary: `vss report` runs with its address space limited (`ulimit -v`),
//! so a writer that holds more than the bound fails to allocate and the
//! test fails, whatever the machine. The reports were built whole in memory
//! (the PostScript text twice, and every image's pictures twice): a report
//! of an 8192² `.img` needed 511 MiB of address space, a five-image survey
//! of 512² pictures 75 MiB. They are now streamed page by page into the
//! temporary file, one image's pictures at a time (75 MiB and 12 MiB).
//!
//! Also: a write that fails half-way (here the file size limit, `ulimit -f`,
//! with SIGXFSZ ignored so the write returns EFBIG) leaves the report that
//! was there untouched, and the message says so.

use std::path::{Path, PathBuf};
use std::process::Output;

use vss::formats::img::ImgFile;
use vss::llv::{EdgePoint, EdgePoints, GreyImage, Params, Point, ScanDir, Segment};
use vss::profile::Profile;
use vss::session::{OutputSet, Session};

/// Runs `vss ARGS` in `cwd` after the shell commands `limits` (`ulimit …`,
/// `trap …`); returns its output.
fn vss_with(cwd: &Path, limits: &str, args: &[&str]) -> Output {
    crate::support::limited::vss_under(cwd, limits, args)
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Asserts that `vss` ended by itself and succeeded: an allocation over
/// the limit aborts it (a signal) or fails with "memory allocation".
fn assert_ok(o: &Output, what: &str) {
    assert!(
        o.status.code().is_some(),
        "{what}: vss was killed ({:?}), most likely by an allocation over the limit:\n{}",
        o.status,
        text(o)
    );
    assert!(o.status.success(), "{what}: vss failed:\n{}", text(o));
}

/// The pages a PostScript file has (`%%Page:` comments).
fn pages_in(ps: &Path) -> usize {
    use std::io::BufRead;
    let f = std::io::BufReader::new(std::fs::File::open(ps).expect("ps"));
    f.split(b'\n')
        .filter(|l| l.as_ref().is_ok_and(|l| l.starts_with(b"%%Page: ")))
        .count()
}

/// The pages a PostScript file declares, and whether it is complete.
fn declared_pages(ps: &Path) -> (Option<usize>, bool) {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(ps).expect("ps");
    let mut head = vec![0u8; 4096];
    let n = f.read(&mut head).expect("read");
    let head = String::from_utf8_lossy(&head[..n]).into_owned();
    let pages = head
        .lines()
        .find_map(|l| l.strip_prefix("%%Pages: "))
        .and_then(|p| p.trim().parse().ok());
    let mut tail = String::new();
    f.seek(SeekFrom::End(-16)).expect("seek");
    f.read_to_string(&mut tail).expect("tail");
    (pages, tail.ends_with("%%Trailer\n%%EOF\n"))
}

/// Issue 34, N5: the report of an `.img` at the picture bound (8192², a
/// 64 MiB file) within 4 × the file's size, the bound. It held the
/// file's bytes, the image and its PostScript text twice, 5 × the file
/// (337 MB resident). Now it holds one copy of the pixels (the `.img`
/// reader reads them into the image's own buffer) and a few buffers: the
/// limit here is what vss needs to start plus 1.3 × the file, which a
/// second copy of the pixels exceeds.
#[test]
fn a_report_of_the_largest_picture_holds_one_copy_of_its_pixels() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let side = 8192usize;
    let px: Vec<u8> = (0..side * side).map(|i| (i % 251) as u8).collect();
    let img = ImgFile::new(GreyImage::new(side, side, px).expect("image"));
    vss::formats::img::write_img(&root.join("max1a.img"), &img).expect("img");
    drop(img);
    let len = std::fs::metadata(root.join("max1a.img"))
        .expect("len")
        .len();
    // What vss needs to start, then 84 MiB: one copy of the pixels (64 MiB)
    // and the pages' buffers, not two copies.
    let limit_kib = crate::support::limited::baseline_kib() + 21 * len / 16 / 1024;
    let o = vss_with(
        root,
        &format!("ulimit -v {limit_kib}"),
        &["report", "--img", "max1a.img"],
    );
    assert_ok(&o, "report --img max1a.img");
    let ps = root.join("max1a.ps");
    assert_eq!(declared_pages(&ps), (Some(1), true));
    // Two hex digits a pixel, 72 to a line.
    let hex = (side * side * 2) as u64;
    let size = std::fs::metadata(&ps).expect("ps").len();
    assert!(
        size > hex + hex / 72 && size < hex + hex / 72 + 4096,
        "{size} bytes"
    );
}

/// A session of `images` images, each with every lighting of the default
/// profile at `side`², edge files and lines, as a survey leaves it.
fn survey(root: &Path, images: u32, side: usize) -> PathBuf {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("profiles/default.toml");
    let profile = Profile::load(manifest.to_str().expect("path")).expect("default profile");
    let mut s = Session::create(root, "cube", &profile).expect("session");
    let letters = s.letters();
    assert!(letters.len() >= 5, "{letters:?}");
    let edges = |dir| EdgePoints {
        dir: Some(dir),
        width: side,
        height: side,
        points: (0..2000)
            .map(|i| EdgePoint {
                x: (i % side) as f32,
                y: (i * 7 % side) as f32,
                response: 20.0 + (i % 50) as f32,
            })
            .collect(),
    };
    let (eh, ev) = (edges(ScanDir::Horizontal), edges(ScanDir::Vertical));
    let lines: Vec<Segment> = (0..40)
        .map(|i| {
            let v = (i * 11 % side) as f64;
            Segment::new(
                Point::new(v, 3.0),
                Point::new(side as f64 - v, side as f64 - 3.0),
            )
        })
        .collect();
    for k in 1..=images {
        for (n, &letter) in letters.iter().enumerate() {
            let px = (0..side * side)
                .map(|i| ((i % side + i / side + 37 * n + k as usize) % 256) as u8)
                .collect();
            let img = ImgFile::new(GreyImage::new(side, side, px).expect("image"));
            s.save_image(k, letter, &img).expect("save image");
        }
        let set = OutputSet {
            edges_h: Some(&eh),
            edges_v: Some(&ev),
            lines_raw: Some(&lines),
            lines: Some(&lines),
            ..Default::default()
        };
        s.save_output_set(k, &set, &Params::default())
            .expect("outputs");
    }
    s.dir().to_path_buf()
}

/// Issue 33: the report of a five-image survey holds one image's pictures
/// at a time and none of its text. At 1024², five lightings, every image's
/// pictures are 25 MiB and the PostScript 70 MiB; the report now runs in
/// 20 MiB of address space beyond what vss needs to start (12 MiB for the
/// default build, 33–64 MiB with `genicam`'s libraries), which holding all
/// the pictures at once (or
/// any file's text whole) does not fit. It needed 205 MB resident for such
/// a survey grabbed from the simulated cell.
#[test]
fn a_survey_report_holds_one_image_at_a_time() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let sdir = survey(root, 5, 1024);
    let d = sdir.to_str().expect("path");
    let o = vss_with(
        root,
        &format!(
            "ulimit -v {}",
            crate::support::limited::baseline_kib() + 20 * 1024
        ),
        &["report", d, "--ps", "all.ps", "--svg", "all.svg"],
    );
    assert_ok(&o, "report of the survey");
    // Per image: two pages of five greys and two edge images, one of
    // lines and notes.
    let ps = root.join("all.ps");
    assert_eq!(declared_pages(&ps), (Some(15), true));
    assert_eq!(pages_in(&ps), 15);
    for k in 1..=5 {
        assert!(root.join(format!("all{k}.svg")).is_file(), "all{k}.svg");
    }
}

/// A report that cannot be written to the end (the file size limit stops
/// it half-way) leaves the report that was there as it was, no temporary
/// file, and says which file is still the old one.
#[test]
fn a_report_that_fails_half_way_leaves_the_old_one_and_says_so() {
    let tmp = tempfile::tempdir().expect("tmp");
    let root = tmp.path();
    let sdir = survey(root, 2, 512);
    let d = sdir.to_str().expect("path");
    let o = vss_with(root, "true", &["report", d, "--ps", "all.ps"]);
    assert_ok(&o, "first report");
    let before = std::fs::read(root.join("all.ps")).expect("old report");
    assert!(before.len() > 2 << 20, "{} bytes", before.len());
    // 1 MiB files at most: the report stops in its first image's pages.
    let o = vss_with(
        root,
        "trap '' XFSZ && ulimit -f 2048",
        &["report", d, "--ps", "all.ps"],
    );
    let out = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("cannot write all.ps")
            && out.contains("all.ps on disk is the OLD report, untouched, written"),
        "{out}"
    );
    assert!(
        std::fs::read(root.join("all.ps")).expect("report") == before,
        "the old report is untouched"
    );
    let left: Vec<String> = std::fs::read_dir(root)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp."))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// The peak resident memory (VmHWM) of process `pid`, KiB.
fn vm_hwm_kib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("status");
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("VmHWM")
}

/// Issue 33: the console's report (`5 e`) costs next to nothing above what
/// the survey itself needed. Two images of three lightings at 1024²: the
/// report raised the console's peak by about 50 MiB (every picture held
/// twice, the PostScript text twice); now by at most 8 MiB. Memory, not
/// time: the peak is the same from run to run within a few MiB.
#[test]
fn the_console_s_report_adds_little_to_its_peak_memory() {
    use super::tui_harness::{Console, PROFILE};
    let profile = PROFILE
        .replace("width = 128", "width = 1024")
        .replace("height = 128", "height = 1024");
    let mut c = Console::start_with(&profile, 100, 32, &[], |_| {});
    c.survey(2);
    let pid = c.child.process_id().expect("pid");
    let survey = vm_hwm_kib(pid);
    c.send("5");
    c.wait_text("files (", 10);
    c.send("e");
    c.wait_text("report written", 60);
    let report = vm_hwm_kib(pid);
    eprintln!("console peak: {survey} KiB after the survey, {report} KiB after its report");
    c.send("q");
    c.wait_exit(15);
    assert!(
        c.session().join("cube.ps").is_file() && c.session().join("cube2.svg").is_file(),
        "the report is on disk"
    );
    assert!(
        report <= survey + 8 * 1024,
        "peak {survey} KiB after the survey, {report} KiB after its report"
    );
}
