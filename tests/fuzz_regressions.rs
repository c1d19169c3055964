//! Replays every input kept in `fuzz/regressions/<target>/` (fuzzer findings and a few seeds)
//! through the same harness the fuzz target runs (`rodcube::fuzzing`): none may panic. The
//! fuzzers themselves run with `cargo fuzz run -s none <target>` (see fuzz/Cargo.toml).

use std::fs;
use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/regressions")
        .join(target);
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Runs `harness` on every kept input of `target`, naming the input that panics.
fn replay(target: &str, harness: fn(&[u8])) -> usize {
    let files = inputs(target);
    assert!(!files.is_empty(), "no regression inputs for `{target}`");
    let mut failed = Vec::new();
    for path in &files {
        let data = fs::read(path).unwrap();
        if std::panic::catch_unwind(|| harness(&data)).is_err() {
            failed.push(path.display().to_string());
        }
    }
    assert!(
        failed.is_empty(),
        "{target}: these inputs panic: {failed:#?}"
    );
    files.len()
}

#[test]
fn scene_regressions() {
    replay("scene", rodcube::fuzzing::scene);
}

#[test]
fn spec_regressions() {
    replay("spec", rodcube::fuzzing::spec);
}

#[test]
fn expr_regressions() {
    replay("expr", rodcube::fuzzing::expr);
}

#[test]
fn tape_regressions() {
    use rodcube::fuzzing::{TapeOutcome, tape};
    let n = replay("tape", |data| {
        tape(data);
    });
    assert!(n >= 3);
    // The first finding: a shape's `first` (the drawing's `sizes`) past what a caller could
    // allocate, which the loader now refuses; the seeds load.
    for path in inputs("tape") {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        let outcome = tape(&fs::read(&path).unwrap());
        if name.starts_with("crash-shape-first") {
            let TapeOutcome::Refused(e) = &outcome else {
                panic!("{name}: {outcome:?}");
            };
            assert!(e.to_string().contains("`sizes`"), "{name}: {e}");
        } else if name.starts_with("seed-rod") || name.starts_with("seed-ladder") {
            assert!(
                matches!(outcome, TapeOutcome::Accepted),
                "{name}: {outcome:?}"
            );
        }
    }
}

/// The harnesses are not vacuous: each one panics on the kind of failure it exists to catch.
#[test]
fn harnesses_catch_failures() {
    // A spec error must name the file it came from; `spec` asserts that on every error.
    let shown = rodcube::spec::parse(Path::new("fuzz.yaml"), "name: [").unwrap_err();
    assert!(shown.to_string().starts_with("fuzz.yaml:"), "{shown}");
    // The first expression finding: an i128 overflow while folding constants in `tidy`.
    let big = format!("{m}*{m}*x", m = i128::MAX);
    let tidy = rodcube::spec::expr::Expr::parse(&big).unwrap().tidy();
    assert!(tidy.to_infix().contains('x'));
    rodcube::fuzzing::expr(big.as_bytes());
    // The second: deep nesting overflowed the parser's stack; now it is a parse error.
    let deep = format!("{}x{}", "(".repeat(10_000), ")".repeat(10_000));
    let err = rodcube::spec::expr::Expr::parse(&deep).unwrap_err();
    assert!(err.message.contains("nested"), "{err:?}");
    let limit = rodcube::spec::expr::MAX_NESTING;
    let ok = format!("{}x{}", "(".repeat(limit - 1), ")".repeat(limit - 1));
    assert!(rodcube::spec::expr::Expr::parse(&ok).is_ok());
    // The third: a long chain of powers parsed, but printed as `a^(b^(...))` it nested too deep
    // to parse again. Trees are limited so that their printed form always parses.
    let depth = rodcube::spec::expr::MAX_DEPTH;
    let chain = format!("x{}", "^x".repeat(depth - 1));
    rodcube::fuzzing::expr(chain.as_bytes());
    let too_deep = format!("x{}", "^x".repeat(depth));
    assert!(rodcube::spec::expr::Expr::parse(&too_deep).is_err());
}
