//! A second `rodcube derive` waits for the first instead of aborting: while this test holds the
//! Symbolica lock file, a spawned `rodcube derive --check` says on stderr that it is waiting,
//! and it finishes (successfully) only after the lock is released. This test process never
//! calls Symbolica itself, so the two processes cannot collide; the in-process, many-threads
//! side is tests/cas_threads.rs.
#![cfg(feature = "derive")]

use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};

const WAITING: &str = "another process is using Symbolica";

#[test]
fn second_derivation_waits_for_the_lock() {
    let path = rodcube::derive::lock_path();
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    // Waits here if a derivation elsewhere on this machine holds it; that is fine.
    lock.lock().unwrap();

    let mut child = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["derive", "--check"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());

    // Read stderr until the waiting note; the child cannot get past the lock we hold.
    let mut before = String::new();
    let mut line = String::new();
    loop {
        line.clear();
        let n = stderr.read_line(&mut line).unwrap();
        if n == 0 {
            let status = child.wait().unwrap();
            lock.unlock().unwrap();
            panic!("`rodcube derive --check` ended ({status}) without waiting:\n{before}");
        }
        before.push_str(&line);
        if line.contains(WAITING) {
            break;
        }
    }
    assert!(
        line.contains(&path.display().to_string()),
        "the note should name the lock file: {line}"
    );
    // Still blocked: it has not exited, and it has said nothing more.
    assert!(
        child.try_wait().unwrap().is_none(),
        "it finished while the lock was held:\n{before}"
    );

    lock.unlock().unwrap();
    drop(lock);
    let mut after = String::new();
    stderr.read_to_string(&mut after).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(
        status.code(),
        Some(0),
        "after the lock was released:\n{before}{after}"
    );
    assert!(after.contains("files up to date"), "{after}");
    assert!(
        !after.contains("panicked") && !after.contains(WAITING),
        "{after}"
    );
}
