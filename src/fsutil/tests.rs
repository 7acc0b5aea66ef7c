//! Unit tests of the atomic writer and the input opener.

use super::*;
use std::os::unix::fs::symlink;

#[test]
fn replaces_whole_file_and_leaves_no_temp() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.txt");
    write_atomic(&p, b"first").unwrap();
    write_atomic(&p, b"second").unwrap();
    assert_eq!(fs::read(&p).unwrap(), b"second");
    let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn failed_fill_keeps_previous_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.txt");
    write_atomic(&p, b"good").unwrap();
    let err = write_atomic_with(&p, |_| Err(io::Error::other("boom")));
    assert!(err.is_err());
    assert_eq!(fs::read(&p).unwrap(), b"good");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn temp_names_embed_pid_and_host_and_differ() {
    let a = temp_name(OsStr::new("cube1.ldr"));
    let b = temp_name(OsStr::new("cube1.ldr"));
    assert_ne!(a, b);
    assert_eq!(temp_owner(&a), Some((std::process::id(), true)));
    assert_eq!(temp_owner(".cube1.ldr.tmp.42"), Some((42, true)));
    assert_eq!(temp_owner("cube1.ldr"), None);
    assert_eq!(temp_owner(".x.tmp.notapid"), None);
    // Another host's temporary file is not ours to judge.
    let other = format!(".x{TMP_MARK}42.{:08x}00000000", host_tag() ^ 1);
    assert_eq!(temp_owner(&other), Some((42, false)));
}

#[test]
fn a_planted_link_at_the_temp_name_is_never_opened() {
    let dir = tempfile::tempdir().unwrap();
    let outside = dir.path().join("outside");
    fs::write(&outside, b"precious").unwrap();
    let sub = dir.path().join("s");
    fs::create_dir(&sub).unwrap();
    // Whatever name is tried, a link planted under it is not followed.
    for _ in 0..4 {
        let name = temp_name(OsStr::new("a.txt"));
        symlink(&outside, sub.join(&name)).unwrap();
        let e = create_exclusive(&sub.join(&name)).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::AlreadyExists);
    }
    assert_eq!(fs::read(&outside).unwrap(), b"precious");
}

#[test]
fn a_link_as_the_target_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let outside = dir.path().join("outside");
    fs::write(&outside, b"precious").unwrap();
    let target = dir.path().join("out.ps");
    symlink(&outside, &target).unwrap();
    let e = write_atomic(&target, b"report").unwrap_err().to_string();
    assert!(e.contains("out.ps") && e.contains("symbolic link"), "{e}");
    assert_eq!(fs::read(&outside).unwrap(), b"precious");
    assert!(
        fs::symlink_metadata(&target)
            .unwrap()
            .file_type()
            .is_symlink()
    );
}

#[test]
fn stale_temps_of_dead_writers_are_swept_live_ones_kept() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let dead = child.id();
    child.wait().unwrap();
    let old = dir.path().join(format!(".a.txt.tmp.{dead}"));
    let new = dir
        .path()
        .join(format!(".b.img.tmp.{dead}.{:08x}0000abcd", host_tag()));
    let mine = dir
        .path()
        .join(format!(".c.img.tmp.{}", std::process::id()));
    let foreign = dir
        .path()
        .join(format!(".d.img.tmp.{dead}.{:08x}0000abcd", host_tag() ^ 1));
    for p in [&old, &new, &mine, &foreign] {
        fs::write(p, b"half").unwrap();
    }
    write_atomic(&dir.path().join("e.txt"), b"x").unwrap();
    assert!(!old.exists() && !new.exists(), "dead writers' temps swept");
    assert!(mine.exists(), "a live writer's temp is kept");
    assert!(foreign.exists(), "another host's temp is kept");
}

#[test]
fn inputs_must_be_regular_files_within_their_bound() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.cdf");
    fs::write(&p, b"0123456789").unwrap();
    assert_eq!(read_input(&p, 10).unwrap(), b"0123456789");
    let e = read_input(&p, 9).unwrap_err();
    assert_eq!(e.kind(), io::ErrorKind::FileTooLarge);
    let link = dir.path().join("l.cdf");
    symlink("/dev/zero", &link).unwrap();
    assert!(
        read_input(&link, 1 << 20)
            .unwrap_err()
            .to_string()
            .contains("symbolic link")
    );
    let e = read_input(Path::new("/dev/zero"), 1 << 20).unwrap_err();
    assert!(e.to_string().contains("device"), "{e}");
    let e = read_input(dir.path(), 1 << 20).unwrap_err();
    assert!(e.to_string().contains("folder"), "{e}");
}

/// Issue 34, N11: a replaced file keeps its mode (a 0600 `.cdf` stayed
/// 0600 only until the first save, which made it 0644).
#[test]
fn a_replaced_file_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cam1.cdf");
    write_atomic(&p, b"first").unwrap();
    for mode in [0o600, 0o640, 0o444] {
        fs::set_permissions(&p, fs::Permissions::from_mode(mode)).unwrap();
        write_atomic(&p, b"again").unwrap();
        let got = fs::metadata(&p).unwrap().permissions().mode() & 0o7777;
        assert_eq!(got, mode, "{mode:o} became {got:o}");
    }
}

/// Issue 34, N9: outputs written as a set: a failure while staging leaves
/// every target as it was (no mix of old and new), and nothing behind.
#[test]
fn staged_writes_replace_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("x1.hpo"), dir.path().join("x1.vpo"));
    write_atomic(&a, b"old a").unwrap();
    write_atomic(&b, b"old b").unwrap();
    // The second target cannot be staged (a folder is in its place).
    let c = dir.path().join("x1.lex");
    fs::create_dir(&c).unwrap();
    let mut set = StagedWrites::new();
    set.stage(&a, b"new a").unwrap();
    assert!(set.stage(&c, b"new c").is_err());
    drop(set);
    assert_eq!(fs::read(&a).unwrap(), b"old a");
    assert_eq!(
        fs::read_dir(dir.path()).unwrap().count(),
        3,
        "temporary files left"
    );
    let mut set = StagedWrites::new();
    set.stage(&a, b"new a").unwrap();
    set.stage(&b, b"new b").unwrap();
    assert_eq!(fs::read(&a).unwrap(), b"old a", "replaced before commit");
    assert_eq!(set.commit().unwrap(), vec![a.clone(), b.clone()]);
    assert_eq!(fs::read(&a).unwrap(), b"new a");
    assert_eq!(fs::read(&b).unwrap(), b"new b");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 3);
}
