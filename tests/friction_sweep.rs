//! The friction sweep example (`examples/friction_sweep.rs`, the plot in the README) runs from
//! the examples `cargo test` builds, writes its CSV and SVG into a temporary directory, and its
//! ends agree with the references: mu = 0 is the paper, mu = 2 the hinged rod.

use rodcube::reference::{Family, Inputs, Reference, TimeRoute, to_f64};
use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/examples/friction_sweep`, built by `cargo test` beside this test's binary.
fn example() -> PathBuf {
    let exe = std::env::current_exe().expect("the test knows its path");
    let profile = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("tests run from target/<profile>/deps");
    let path = profile.join("examples").join("friction_sweep");
    assert!(
        path.exists(),
        "{} was not built (cargo test builds examples)",
        path.display()
    );
    path
}

#[test]
fn the_sweep_writes_its_table_and_plot_and_matches_its_limits() {
    let dir = std::env::temp_dir().join(format!("rodcube-friction-sweep-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(example())
        .args(["5", &dir.display().to_string()])
        .output()
        .expect("the example runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("boundary at mu ="), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("friction_sweep.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 5, "{csv}");
    let mus: Vec<f64> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
    assert_eq!(mus, [0.0, 0.5, 1.0, 1.5, 2.0]);
    let time = |r: &[&str]| -> f64 { r[1].parse().unwrap() };
    // The paper's t_sep (g = 9.81) to 15 digits, held to the 256-bit reference by
    // `tests/hard_cases.rs` (`the_quoted_paper_separation_time_is_the_references`).
    let paper = 0.108493254170856;
    assert!((time(&rows[0]) - paper).abs() < 1e-12 * paper, "{csv}");
    // At mu = 2 the foot sticks: the hinged rod, whose time is the 256-bit reference's
    // (`3 n s^3 + 3 s - 2 r = 0`, PHYSICS.md erratum 5, and its energy integral).
    let mut reference = Reference::new(Inputs {
        family: Family::HingedRod,
        m1: 1.0,
        m2: 3.0,
        ell: 1.0,
        a: 0.25,
        g: 9.81,
    })
    .unwrap();
    let hinged = to_f64(&reference.separation_time(TimeRoute::SinhGauss).unwrap());
    assert!(
        (time(&rows[4]) - hinged).abs() < 1e-10 * hinged,
        "{csv} vs {hinged}"
    );
    assert!(rows[4][3].contains("foot sticks; leaves the cube"), "{csv}");
    let svg = std::fs::read_to_string(dir.join("friction_sweep.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("hinged rod"),
        "{}",
        &svg[..200]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
