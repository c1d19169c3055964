//! Output files: atomic writes leave the old file or the new one and no temporary file, and
//! names that could leave the output directory are refused before anything is written.

use rodcube::io::{Error, OutDir, check_name, write_atomic, write_atomic_with};
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// A fresh, empty directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("io_atomic")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Names in a directory, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn writes_and_replaces_a_file() {
    let dir = fresh("replace");
    let path = dir.join("a.txt");
    write_atomic(&path, b"first").unwrap();
    write_atomic(&path, b"second, longer").unwrap();
    assert_eq!(fs::read_to_string(&path).unwrap(), "second, longer");
    assert_eq!(entries(&dir), ["a.txt"]);
}

#[test]
fn a_failure_while_writing_leaves_no_partial_file() {
    let dir = fresh("fail_new");
    let path = dir.join("results.json");
    let err = write_atomic_with(&path, |w| {
        w.write_all(b"{\"half\": ")?;
        Err(io::Error::other("disk full"))
    })
    .unwrap_err();
    assert!(matches!(err, Error::Write { .. }), "{err}");
    assert!(err.to_string().contains("disk full"), "{err}");
    assert_eq!(
        entries(&dir),
        Vec::<String>::new(),
        "neither the target nor a temporary file may remain"
    );
}

#[test]
fn a_failure_while_writing_keeps_the_old_file_intact() {
    let dir = fresh("fail_old");
    let path = dir.join("results.json");
    write_atomic(&path, b"old complete contents").unwrap();
    let err = write_atomic_with(&path, |w| {
        w.write_all(&[b'x'; 100_000])?;
        Err(io::Error::other("interrupted"))
    });
    assert!(err.is_err());
    assert_eq!(fs::read_to_string(&path).unwrap(), "old complete contents");
    assert_eq!(entries(&dir), ["results.json"]);
}

#[test]
fn a_failed_rename_removes_the_temporary_file() {
    let dir = fresh("fail_rename");
    // The target is a non-empty directory: the rename over it must fail.
    let target = dir.join("taken");
    fs::create_dir(&target).unwrap();
    fs::write(target.join("inside"), b"keep").unwrap();
    let err = write_atomic(&target, b"contents").unwrap_err();
    assert!(matches!(err, Error::Write { .. }), "{err}");
    assert_eq!(entries(&dir), ["taken"]);
    assert_eq!(fs::read_to_string(target.join("inside")).unwrap(), "keep");
}

#[test]
fn names_that_could_escape_are_refused() {
    for bad in [
        "",
        ".",
        "..",
        "../escape.txt",
        "a/../../b",
        "sub/file.csv",
        "/etc/passwd",
        "a\\b",
        ".hidden",
        "nul\0byte",
        "spaces are odd.csv",
        "θ.csv",
        &"x".repeat(200),
    ] {
        assert!(
            matches!(check_name(bad), Err(Error::BadName { .. })),
            "{bad:?} was accepted"
        );
    }
    for good in [
        "results.json",
        "theta_series.csv",
        "tip_trajectory.svg",
        "a-b.1",
    ] {
        check_name(good).unwrap();
    }
}

#[test]
fn out_dir_writes_only_inside_itself() {
    let base = fresh("outdir");
    let out = OutDir::create(base.join("run/nested")).unwrap();
    let written = out.write("theta_series.csv", b"t [s]\n0\n").unwrap();
    assert_eq!(written.parent(), Some(out.root()));
    assert_eq!(fs::read_to_string(&written).unwrap(), "t [s]\n0\n");

    let err = out.write("../escaped.csv", b"no").unwrap_err();
    assert!(err.to_string().contains("refusing output name"), "{err}");
    assert!(!base.join("run/escaped.csv").exists());
    assert!(out.write("/tmp/absolute.csv", b"no").is_err());
    assert_eq!(entries(out.root()), ["theta_series.csv"]);
    assert_eq!(out.path_of("x.svg").unwrap(), out.root().join("x.svg"));
}

#[test]
fn out_dir_that_cannot_be_created_is_an_error() {
    let base = fresh("blocked");
    fs::write(base.join("file"), b"").unwrap();
    let err = OutDir::create(base.join("file/sub")).unwrap_err();
    assert!(matches!(err, Error::CreateDir { .. }), "{err}");
}
