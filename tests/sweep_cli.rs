//! `rodcube sweep` end to end: the CSV's first line says how every parameter was set, its rows
//! match the planner point by point, axes are any model's parameters or their ratios (a model
//! off the per-point solver goes through the planner), points files and heat maps work, and
//! bad input (an upright rod, `n` for a model without `m2`, an unknown model, a parameter that
//! nothing sets) is a clear error.

use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::reference::{Family, Inputs, Reference, RootRoute, TimeRoute, relative_error};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn rodcube(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(args)
        .output()
        .expect("run rodcube")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rodcube-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The CSV's comment, header and rows (as numbers; NaN for an empty cell).
fn read_csv(path: &Path) -> (String, Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let comment = lines.next().unwrap().to_string();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| c.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (comment, header, rows)
}

/// The 256-bit reference's separation angle and time of `family` at `m1 = ell = g = 1`,
/// `m2 = n`, `a = r` (`src/reference.rs`: no code shared with the sweep or the planner); the
/// returned errors are relative to it.
fn reference_errors(family: Family, n: f64, r: f64, theta: f64, t: f64) -> (f64, f64) {
    let mut reference = Reference::new(Inputs::dimensionless(family, n, r)).unwrap();
    let sep = reference.separation(RootRoute::ClosedForm).unwrap();
    let t_ref = reference.separation_time(TimeRoute::SinhGauss).unwrap();
    (
        relative_error(theta, &sep.theta).abs(),
        relative_error(t, &t_ref).abs(),
    )
}

fn planner(model: &str, p: Vec<f64>) -> (f64, f64) {
    let m = rodcube::models::find(model).unwrap();
    let res = plan::run(
        &Request::new(m, p).with_want(&[Quantity::SeparationAngle, Quantity::SeparationTime]),
    )
    .unwrap();
    (
        res.results["separation_angle"].value,
        res.results["separation_time"].value,
    )
}

#[test]
fn a_grid_sweep_matches_the_planner_and_says_it_is_dimensionless() {
    let dir = temp_dir("grid");
    let out = rodcube(&[
        "sweep",
        "--n",
        "1e-3:1e3:log:4",
        "--a-over-ell",
        "0.01:0.99:lin:3",
        "--set",
        "m1=1,ell=1,g=1",
        "--heatmap",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("swept 12 points"), "{stdout}");
    let (comment, header, rows) = read_csv(&dir.join("sweep.csv"));
    assert!(
        comment.starts_with('#')
            && comment.contains("m1 = 1, m2 = n * m1, ell = 1, a = a_over_ell * ell, g = 1")
            && !comment.contains("1*")
            && !comment.contains("not given"),
        "{comment}"
    );
    assert_eq!(
        header,
        ["n", "a_over_ell", "separation_angle", "separation_time"]
    );
    assert_eq!(rows.len(), 12);
    // Grid order: n outer, a/ell inner; the axes' ends are exact.
    assert_eq!((rows[0][0], rows[0][1]), (1e-3, 0.01));
    assert_eq!((rows[11][0], rows[11][1]), (1e3, 0.99));
    for row in &rows {
        let (theta, t) = planner("rod_cube", vec![1.0, row[0], 1.0, row[1], 1.0]);
        assert!(
            ((row[2] - theta) / theta).abs() < 1e-13,
            "{row:?} vs {theta}"
        );
        assert!(((row[3] - t) / t).abs() < 1e-11, "{row:?} vs {t}");
        // And both are the 256-bit reference's (at the sweep's default tolerance, 1e-10).
        let (ea, et) = reference_errors(Family::RodCube, row[0], row[1], row[2], row[3]);
        assert!(ea < 1e-12 && et < 1e-10, "{row:?}: {ea:e} {et:e}");
    }
    for svg in ["separation_angle.svg", "separation_time.svg"] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(
            text.starts_with("<svg") && text.contains("log10(n = m2/m1)"),
            "{svg}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn set_fixes_parameters_and_extra_quantities_come_from_the_planner() {
    let dir = temp_dir("si");
    let out = rodcube(&[
        "sweep",
        "--n",
        "3",
        "--a-over-ell",
        "0.25",
        "--set",
        "m1=1,ell=1,g=9.81",
        "--want",
        "point_mass_fall_time,linearised_separation_angle",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (comment, header, rows) = read_csv(&dir.join("sweep.csv"));
    assert!(
        comment.contains("SI units") && comment.contains("ell = 1, a = a_over_ell * ell, g = 9.81"),
        "{comment}"
    );
    assert!(
        header.contains(&"point_mass_fall_time".to_string()),
        "{header:?}"
    );
    assert!(header.contains(&"linearised_separation_angle".to_string()));
    let row = &rows[0];
    // The paper's case (PHYSICS.md, g = 9.81): theta_sep = 9.61 deg, t_sep = 0.10849 s, point
    // mass sqrt(a/g) = 0.15964 s.
    assert!((row[2].to_degrees() - 9.61).abs() < 0.005);
    assert!((row[3] - 0.10849).abs() < 5e-6, "{}", row[3]);
    let k = header
        .iter()
        .position(|h| h == "point_mass_fall_time")
        .unwrap();
    assert!((row[k] - 0.15964).abs() < 5e-6, "{}", row[k]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_points_file_is_swept_in_its_order() {
    let dir = temp_dir("points");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("points.csv");
    std::fs::write(&file, "# my points\nn,a_over_ell,label\n3,0.25,paper\n1e12,0.5,heavy\n1e-12,0.999999999,upright\n").unwrap();
    let out_dir = dir.join("out");
    let out = rodcube(&[
        "sweep",
        "--model",
        "hinged_rod",
        "--points",
        file.to_str().unwrap(),
        "--set",
        "m1=1,ell=1,g=1",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (_, _, rows) = read_csv(&out_dir.join("sweep.csv"));
    assert_eq!(rows.len(), 3);
    for (row, (n, r)) in rows
        .iter()
        .zip([(3.0, 0.25), (1e12, 0.5), (1e-12, 0.999999999)])
    {
        assert_eq!((row[0], row[1]), (n, r));
        let (theta, t) = planner("hinged_rod", vec![1.0, n, 1.0, r, 1.0]);
        assert!(((row[2] - theta) / theta).abs() < 1e-13);
        assert!(((row[3] - t) / t).abs() < 1e-10, "{row:?} vs {t}");
        // The reference, with the hinged rod's rounding limit near a heavy cube
        // (`tests/hard_cases.rs`: 16 eps sin(theta_i) / sin(theta_sep), here below 1e-10).
        let (ea, et) = reference_errors(Family::HingedRod, n, r, row[2], row[3]);
        assert!(ea < 1e-12 && et < 1e-10, "{row:?}: {ea:e} {et:e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_wall_ladder_sweeps_a_over_ell_alone_and_refuses_n() {
    let dir = temp_dir("wall");
    let out = rodcube(&[
        "sweep",
        "--model",
        "wall_ladder",
        "--a-over-ell",
        "0.3,0.6,0.9",
        "--set",
        "m1=1,ell=1,g=1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (_, header, rows) = read_csv(&dir.join("sweep.csv"));
    assert_eq!(
        header,
        ["a_over_ell", "separation_angle", "separation_time"]
    );
    for row in &rows {
        assert!((row[1].sin() - 2.0 * row[0] / 3.0).abs() < 1e-15);
    }
    let out = rodcube(&[
        "sweep",
        "--model",
        "wall_ladder",
        "--n",
        "3",
        "--a-over-ell",
        "0.5",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no parameter or ratio `n`"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sweeps_fail_with_a_clear_message() {
    let dir = temp_dir("bad");
    let d = dir.to_str().unwrap();
    for (args, needle) in [
        (
            vec![
                "sweep",
                "--n",
                "3",
                "--a-over-ell",
                "0.5:1:lin:3",
                "--set",
                "m1=1,ell=1,g=1",
                "--out",
                d,
            ],
            "a < ell",
        ),
        (
            vec![
                "sweep",
                "--n",
                "3",
                "--a-over-ell",
                "1.5",
                "--set",
                "m1=1,ell=1,g=1",
                "--out",
                d,
            ],
            "point 1 (n = 3, a_over_ell = 1.5)",
        ),
        (
            vec!["sweep", "--axis", "m2=1", "--n", "3", "--out", d],
            "set twice",
        ),
        (
            vec!["sweep", "--axis", "a_over_m1=0.5", "--out", d],
            "not dimensionless",
        ),
        (
            vec!["sweep", "--axis", "m2", "--out", d],
            "expected NAME=SPEC",
        ),
        (
            vec!["sweep", "--n", "3", "--set", "mass=2", "--out", d],
            "no parameter `mass`",
        ),
        (
            vec!["sweep", "--n", "3", "--set", "g=down", "--out", d],
            "is not a number",
        ),
        (vec!["sweep", "--out", d], "give the axes"),
        (
            vec![
                "sweep",
                "--model",
                "wall_ladder",
                "--n",
                "3",
                "--a-over-ell",
                "0.5",
                "--out",
                d,
            ],
            "wall_ladder",
        ),
        (
            vec![
                "sweep",
                "--n",
                "0:1:log:3",
                "--a-over-ell",
                "0.5",
                "--out",
                d,
            ],
            "positive ends",
        ),
        (
            vec![
                "sweep",
                "--n",
                "1:2:cubic:3",
                "--a-over-ell",
                "0.5",
                "--out",
                d,
            ],
            "neither lin nor log",
        ),
        (
            vec![
                "sweep",
                "--model",
                "rod_cube_free",
                "--a-over-ell",
                "0.5",
                "--out",
                d,
            ],
            "phase of the system `rod_cube`",
        ),
        (
            vec![
                "sweep",
                "--model",
                "nope",
                "--a-over-ell",
                "0.5",
                "--out",
                d,
            ],
            "no model `nope`",
        ),
        (
            vec![
                "sweep",
                "--n",
                "3",
                "--a-over-ell",
                "0.5",
                "--want",
                "theta_series",
                "--out",
                d,
            ],
            "not a number per point",
        ),
    ] {
        // Each is a command line that cannot be honoured: exit status 2, as clap's own errors.
        let out = rodcube(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_parameter_needs_a_value_and_each_missing_one_is_named_with_its_unit() {
    let dir = temp_dir("missing");
    let d = dir.to_str().unwrap();
    let out = rodcube(&["sweep", "--n", "3", "--a-over-ell", "0.25", "--out", d]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no value for 3 parameters"), "{err}");
    for line in [
        "m1 [kg]: mass of the rod; the axis `n` is measured against it",
        "ell [m]: length of the rod; the axis `a_over_ell` is measured against it",
        "g [m/s^2]: gravitational acceleration",
        "--set m1=...",
    ] {
        assert!(err.contains(line), "{line}: {err}");
    }
    // Only those: m2 and a are set by the ratios, and nothing was written.
    assert!(!err.contains("m2 [") && !err.contains("  a ["), "{err}");
    assert!(!dir.exists(), "{err}");
    // One left out of --set is still missing: no value is ever assumed.
    let friction =
        "sweep --model rod_cube_friction --n 3 --a-over-ell 0.25 --set m1=1,ell=1,g=9.81";
    let mut args: Vec<&str> = friction.split(' ').collect();
    args.extend(["--out", d]);
    let out = rodcube(&args);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no value for 1 parameter (") && err.contains("mu [1]"),
        "{err}"
    );
    assert!(!dir.exists(), "{err}");
}

#[test]
fn any_model_sweeps_over_its_own_parameters_and_ratios() {
    // rod_cylinder has no per-point solver (its separation condition is not polynomial): the
    // sweep goes through the planner, and its axes are its own parameters.
    let dir = temp_dir("cylinder");
    let out = rodcube(&[
        "sweep",
        "--model",
        "rod_cylinder",
        "--axis",
        "m2_over_m1=1,3",
        "--axis",
        "R=0.05,0.1",
        "--set",
        "m1=1,ell=1,th0=0.9,g=9.81",
        "--heatmap",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (comment, header, rows) = read_csv(&dir.join("sweep.csv"));
    assert!(
        comment.contains("m2 = m2_over_m1 * m1") && comment.contains("R = R"),
        "{comment}"
    );
    assert_eq!(
        header,
        ["m2_over_m1", "R", "separation_angle", "separation_time"]
    );
    assert_eq!(rows.len(), 4);
    for row in &rows {
        // m1, m2, ell, R, th0, g
        let (theta, t) = planner("rod_cylinder", vec![1.0, row[0], 1.0, row[1], 0.9, 9.81]);
        assert_eq!((row[2], row[3]), (theta, t), "{row:?}");
    }
    let svg = std::fs::read_to_string(dir.join("separation_time.svg")).unwrap();
    assert!(
        svg.contains("\nm2/m1\n") && svg.contains("\nR\n"),
        "axis labels"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_tolerance_shown_in_help_is_the_planners_default() {
    let shown: f64 = plan::DEFAULT_TOLERANCE_TEXT.parse().unwrap();
    assert_eq!(shown, plan::DEFAULT_TOLERANCE);
    let help = String::from_utf8_lossy(&rodcube(&["sweep", "--help"]).stdout).into_owned();
    assert!(help.contains("[default: 1e-10]"), "{help}");
}

#[test]
fn want_takes_any_scalar_quantity_of_an_integrated_model() {
    // The friction model (integrated, no per-point solver) with `contact_end` and
    // `floor_impact`: their columns whatever the points, the contact's end at mu = 0 the
    // paper's separation (t_sep = 0.108493254170856 s at g = 9.81, held to the 256-bit
    // reference by tests/hard_cases.rs).
    let dir = temp_dir("friction-want");
    succeeds(&[
        "sweep",
        "--model",
        "rod_cube_friction",
        "--axis",
        "mu=0,0.5",
        "--set",
        "m1=1,m2=3,ell=1,a=0.25,g=9.81",
        "--want",
        "contact_end,floor_impact",
        "--tolerance",
        "1e-12",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (_, header, rows) = read_csv(&dir.join("sweep.csv"));
    let col = |name: &str| {
        (header.iter().position(|h| h == name)).unwrap_or_else(|| panic!("{name}: {header:?}"))
    };
    for name in [
        "contact_end_angle",
        "floor_normal_end_time",
        "impact_angular_velocity",
    ] {
        col(name);
    }
    let (end, separation) = (col("contact_end_time"), col("separation_time"));
    assert!(
        (rows[0][end] - 0.108493254170856).abs() < 1e-11,
        "{}",
        rows[0][end]
    );
    // The separation is the first contact's end by its force: one number, two columns.
    for row in &rows {
        assert_eq!(row[end].to_bits(), row[separation].to_bits());
        assert!(row[end] < row[col("floor_impact_time")]);
    }
    // The floor holds the foot throughout: no end of its own, an empty cell.
    assert!(
        rows.iter()
            .all(|r| r[col("floor_normal_end_time")].is_nan())
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs rodcube, failing the test with its error output unless it succeeds.
fn succeeds(args: &[&str]) -> Output {
    let out = rodcube(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}
