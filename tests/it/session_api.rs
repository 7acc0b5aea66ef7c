//! The session API as the console uses it: create, save, resume, lock,
//! edits, stale detection, check, and refusal of bad names and manifests.

use std::fs;

use vss::formats::img::ImgFile;
use vss::llv::{EdgePoint, EdgePoints, GreyImage, Params, Point, ScanDir, Segment};
use vss::profile::{Lighting, Profile};
use vss::session::{OutputSet, OutputState, Session, SessionError, Step};

fn profile() -> Profile {
    let mut p = Profile {
        name: "test".into(),
        ..Default::default()
    };
    p.survey.cameras = 2;
    p.lighting = ['a', 'b']
        .into_iter()
        .map(|letter| Lighting {
            letter,
            on: vec![format!("light-{letter}")],
            note: String::new(),
        })
        .collect();
    p
}

fn grey(v: u8) -> ImgFile {
    ImgFile::new(GreyImage::filled(32, 24, v).unwrap()).with_comment("test")
}

fn edges(n: usize) -> EdgePoints {
    EdgePoints {
        dir: Some(ScanDir::Horizontal),
        width: 32,
        height: 24,
        points: (0..n)
            .map(|i| EdgePoint {
                x: 3.5,
                y: i as f32,
                response: 12.0,
            })
            .collect(),
    }
}

fn line(y: f64) -> Segment {
    Segment {
        response: 17.5,
        residual: 0.25,
        ..Segment::new(Point::new(1.0, y), Point::new(30.0, y))
    }
}

fn save_outputs(s: &mut Session, k: u32) {
    let e = edges(5);
    let raw = [line(3.0), line(9.0)];
    let lines = [line(3.0)];
    let set = OutputSet {
        edges_h: Some(&e),
        edges_v: Some(&e),
        lines_raw: Some(&raw),
        lines: Some(&lines),
        ..Default::default()
    };
    s.save_output_set(k, &set, &Params::default()).unwrap();
}

#[test]
fn survey_resumes_where_it_stopped() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "cube", &profile()).unwrap();
    let sdir = s.dir().to_path_buf();
    assert_eq!(
        s.progress().next_step(),
        Some(Step::Capture {
            image: 1,
            letter: 'a'
        })
    );
    s.save_image(1, 'a', &grey(10)).unwrap();
    s.save_image(1, 'b', &grey(20)).unwrap();
    assert_eq!(s.progress().next_step(), Some(Step::Process { image: 1 }));
    save_outputs(&mut s, 1);
    s.save_image(2, 'a', &grey(30)).unwrap();
    drop(s);

    // The files are there under VSS names, and .ses has three numbers.
    for f in [
        "cube1a.img",
        "cube1b.img",
        "cube1.hpo",
        "cube1.vpo",
        "cube1.lex",
        "cube1.ldr",
        "cube2a.img",
        "cube.toml",
    ] {
        assert!(sdir.join(f).is_file(), "{f}");
    }
    assert_eq!(
        fs::read_to_string(sdir.join("cube.ses")).unwrap(),
        "2\n2\n2\n"
    );
    assert!(!sdir.join("cube.lock").exists(), "lock released on drop");

    let s = Session::open(&sdir).unwrap();
    let p = s.progress();
    assert_eq!(
        p.next_step(),
        Some(Step::Capture {
            image: 2,
            letter: 'b'
        })
    );
    assert!(p.images[0].is_done());
    assert_eq!(p.images[1].camera, 2);
    let m = s.manifest();
    let o = m.image(1).unwrap().outputs.as_ref().unwrap();
    assert_eq!(
        (o.counts.edges_h, o.counts.lines_raw, o.counts.lines),
        (5, 2, 1)
    );
    assert_eq!(o.inputs.len(), 2);
    // Line attributes come back with the lines.
    let l = s.load_lines(1).unwrap();
    assert_eq!(l.len(), 1);
    assert_eq!((l[0].response, l[0].residual), (17.5, 0.25));
    assert!(s.check().is_ok(), "{:?}", s.check());
}

#[test]
fn second_opener_is_refused_with_the_holder_named() {
    let dir = tempfile::tempdir().unwrap();
    let s = Session::create(dir.path(), "cube", &profile()).unwrap();
    let err = Session::open(s.dir()).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(err, SessionError::Locked { stale: false, .. }),
        "{msg}"
    );
    assert!(
        msg.contains(&format!("process {}", std::process::id())),
        "{msg}"
    );
    assert!(
        Session::open_take_over(s.dir()).is_err(),
        "a live holder is never displaced"
    );
    // Read-only inspection works while locked, and refuses writes.
    let mut ro = Session::inspect(s.dir()).unwrap();
    assert!(matches!(
        ro.save_image(1, 'a', &grey(1)),
        Err(SessionError::ReadOnly { .. })
    ));
}

#[test]
fn new_capture_makes_outputs_stale_and_edits_are_logged() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "w", &profile()).unwrap();
    s.save_image(1, 'a', &grey(10)).unwrap();
    s.save_image(1, 'b', &grey(20)).unwrap();
    save_outputs(&mut s, 1);
    s.record_edit(1, "delete 2", &[line(3.0), line(12.0)])
        .unwrap();
    s.record_edit(1, "connect 1 2", &[line(5.0)]).unwrap();
    let rec = s.manifest().image(1).unwrap();
    assert_eq!(rec.edit.len(), 2);
    assert_eq!(rec.edit[1].op, "connect 1 2");
    assert_eq!(
        s.load_lines(1).unwrap(),
        vec![Segment::new(Point::new(1.0, 5.0), Point::new(30.0, 5.0))]
    );
    assert!(s.check().is_ok(), "{:?}", s.check());
    assert!(s.check().warnings.is_empty(), "{:?}", s.check());

    s.save_image(1, 'b', &grey(99)).unwrap();
    match &s.progress().images[0].outputs {
        OutputState::Stale(why) => assert!(why.contains("w1b.img"), "{why}"),
        o => panic!("expected stale, got {o:?}"),
    }
    let c = s.check();
    assert_eq!(c.stale.len(), 1);
    assert!(c.is_ok());
}

#[test]
fn check_finds_missing_and_broken_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "cube", &profile()).unwrap();
    s.save_image(1, 'a', &grey(10)).unwrap();
    s.save_image(1, 'b', &grey(10)).unwrap();
    save_outputs(&mut s, 1);
    fs::remove_file(s.path("cube1a.img")).unwrap();
    fs::write(s.path("cube1.lex"), "1 2 x\nFaces:\n").unwrap();
    fs::write(s.path("cube1.hpo"), b"garbage").unwrap();
    let c = s.check();
    assert_eq!(c.problems.len(), 3, "{c:?}");
    assert!(c.problems.iter().any(|p| p.contains("cube1a.img")));
    assert!(c.problems.iter().any(|p| p.contains("cube1.lex")));
}

#[test]
fn bad_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["a/b", "..", "../x", "ok\u{7}", &"x".repeat(300), "", "1abc"] {
        let err = Session::create(dir.path(), bad, &profile());
        assert!(
            matches!(err, Err(SessionError::Name(_))),
            "{bad:?}: {err:?}"
        );
    }
    assert_eq!(
        fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing created"
    );
    // A second create of the same name finds the manifest, whether the first
    // session is still open (its lock held) or closed: it exists.
    let first = Session::create(dir.path(), "cube", &profile()).unwrap();
    let again = Session::create(dir.path(), "cube", &profile());
    assert!(
        matches!(again, Err(SessionError::Exists { .. })),
        "{again:?}"
    );
    drop(first);
    let again = Session::create(dir.path(), "cube", &profile());
    assert!(
        matches!(again, Err(SessionError::Exists { .. })),
        "{again:?}"
    );
}

#[test]
fn nonsense_manifest_is_reported_with_its_line_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let s = Session::create(dir.path(), "cube", &profile()).unwrap();
    let sdir = s.dir().to_path_buf();
    drop(s);
    let path = sdir.join("cube.toml");
    let good = fs::read_to_string(&path).unwrap();
    let cases = [
        good.replace("cameras = 2", "cameras = \"two\""),
        good.replace("planned_images = 2", "planned_images = 2\nwhatever = 1"),
        format!(
            "{good}\n[[image]]\nnumber = 1\ncamera = 1\nlocation = 1\n[[image.grey]]\nletter = \"a\"\nfile = \"../../etc/passwd\"\nhash = \"x\"\nwidth = 1\nheight = 1\nsaved = \"\"\nversion = \"\"\n"
        ),
        "this is [not toml".to_string(),
    ];
    for bad in cases {
        fs::write(&path, &bad).unwrap();
        let err = Session::open(&sdir).unwrap_err();
        let msg = err.to_string();
        let SessionError::Manifest { line, .. } = err else {
            panic!("expected a manifest error, got {msg}");
        };
        assert!(line > 0, "{msg}");
        assert!(msg.contains(&format!("cube.toml:{line}:")), "{msg}");
        assert_eq!(fs::read_to_string(&path).unwrap(), bad, "not overwritten");
        assert!(
            !sdir.join("cube.lock").exists(),
            "lock released after the failure"
        );
    }
}

/// An image of many lines (a big or busy picture) saves and reopens: its
/// lines' attributes are recorded only up to `MAX_ATTRIBUTED_LINES`, so its
/// manifest record stays within what the reader takes. Without that, 8 000
/// lines made a record of 540 KB: the writer now refuses that ("nothing was
/// written"), and before the writer's check the next open refused it, the
/// whole session lost to the console.
#[test]
fn an_image_of_thousands_of_lines_saves_and_reopens() {
    use vss::session::manifest::MAX_ATTRIBUTED_LINES;
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::create(dir.path(), "busy", &profile()).unwrap();
    let sdir = s.dir().to_path_buf();
    s.save_image(1, 'a', &grey(10)).unwrap();
    s.save_image(1, 'b', &grey(20)).unwrap();
    let e = edges(5);
    let many: Vec<Segment> = (0..8000)
        .map(|i| Segment {
            response: 17.123_456_789_012 + f64::from(i),
            residual: 0.251_234_567_89,
            ..Segment::new(
                Point::new(1.0, 0.5),
                Point::new(30.0, 0.5 + f64::from(i) / 1e3),
            )
        })
        .collect();
    assert!(many.len() > MAX_ATTRIBUTED_LINES);
    let set = OutputSet {
        edges_h: Some(&e),
        edges_v: Some(&e),
        lines_raw: Some(&many),
        lines: Some(&many),
        ..Default::default()
    };
    s.save_output_set(1, &set, &Params::default()).unwrap();
    drop(s);
    let s = Session::open(&sdir).unwrap_or_else(|e| panic!("reopen: {e}"));
    assert_eq!(
        s.progress().next_step(),
        Some(Step::Capture {
            image: 2,
            letter: 'a'
        })
    );
    let text = fs::read_to_string(sdir.join("busy.toml")).unwrap();
    assert!(
        text.len() < vss::session::manifest::MAX_RECORD_LEN,
        "{}",
        text.len()
    );
}
