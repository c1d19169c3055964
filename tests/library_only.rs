//! A program that links only the solvers builds the library without the command line's
//! dependencies: with `default-features = false` the dependency tree holds no argument parser,
//! plotting, table, CSV, progress-bar, thread-pool or high-precision crate, and the library
//! compiles.

use std::path::Path;
use std::process::Command;

/// Crates only the `cli` feature may bring in.
const CLI_ONLY: [&str; 8] = [
    "clap",
    "plotters",
    "comfy-table",
    "csv",
    "indicatif",
    "rayon",
    "astro-float",
    "anyhow",
];

fn cargo(args: &[&str]) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Not the test run's target directory (whose lock `cargo test` may hold) but that of
    // tests/capi.rs's build of the C library, where the check below finds the build scripts
    // and proc macros compiled (cargo's lock on the directory serialises the two).
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi");
    let out = Command::new(env!("CARGO"))
        .args(args)
        .arg("--manifest-path")
        .arg(root.join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", &target)
        .output()
        .expect("cargo runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cargo {args:?} failed:\n{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn the_library_alone_leaves_the_command_lines_crates_out() {
    let tree = cargo(&[
        "tree",
        "--offline",
        "-e",
        "normal",
        "--no-default-features",
        "--prefix",
        "none",
    ]);
    let crates: Vec<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(crates.contains(&"nalgebra"), "{tree}");
    for name in CLI_ONLY {
        assert!(
            !crates.contains(&name),
            "`{name}` in the library-only tree:\n{tree}"
        );
    }
    // With the command line they are all there (the feature does what it says).
    let full = cargo(&["tree", "--offline", "-e", "normal", "--prefix", "none"]);
    for name in CLI_ONLY {
        assert!(
            full.lines().any(|l| l.starts_with(&format!("{name} "))),
            "{name}"
        );
    }
}

#[test]
fn the_library_alone_compiles() {
    // In the release profile, like that build: a check generates no code and src/ has no
    // `cfg(debug_assertions)`, so the profile only decides whether it can reuse that build's
    // host units (build scripts, proc macros).
    cargo(&[
        "check",
        "--offline",
        "--release",
        "--lib",
        "--no-default-features",
    ]);
}
