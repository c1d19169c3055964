//! Sensitivities in what rodcube writes: `want: [sensitivities]` puts `d(<result>)/d(<p>)` with
//! the result's unit over the parameter's, and the elasticities, into results.json, equal to
//! the per-point solver's; notes where they do not exist or are not built; a scene error at its
//! position when they are of nothing the scene computes; `rodcube sweep --sensitivities`
//! columns.

use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::results::SensitivityGap;
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::fast::prior::{PRIOR_TOL, Prior};
use rodcube::solve::fast::sensitivity::{self, SensitivityWork, SeparationPoint};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const PAPER: [(&str, f64); 5] = [
    ("m1", 1.0),
    ("m2", 3.0),
    ("ell", 1.0),
    ("a", 0.25),
    ("g", 9.81),
];

/// A fresh, empty directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("sensitivity_reports")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// `rodcube <args>` in `dir`.
fn rodcube(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// Runs `text` as `<test>/scene.yaml`; the output and the directory.
fn run_scene(test: &str, text: &str) -> (Output, PathBuf) {
    let dir = fresh(test);
    fs::write(dir.join("scene.yaml"), text).unwrap();
    let out = rodcube(&dir, &["run", "scene.yaml", "--out", "out"]);
    (out, dir)
}

fn results_json(dir: &Path) -> serde_json::Value {
    let text = fs::read_to_string(dir.join("out").join("results.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn results_json_carries_every_sensitivity_with_its_unit_and_the_elasticities() {
    let scene = "# the paper's case with sensitivities\nmodel: rod_cube\n\
                 parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\n\
                 want: [separation_angle, separation_time, contact_end, floor_impact, sensitivities]\n";
    let (out, dir) = run_scene("paper", scene);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = results_json(&dir);
    let sens = json["sensitivities"]
        .as_object()
        .expect("a sensitivities block");
    // The per-point solver's numbers, independently of the planner.
    let model = rodcube::models::find("rod_cube").unwrap();
    let p: Vec<f64> = PAPER.iter().map(|(_, v)| *v).collect();
    let mut solver = LeanSolver::new(model).unwrap();
    let point = solver.solve(&p).unwrap();
    let (mut d_theta, mut d_t) = (vec![0.0; 5], vec![0.0; 5]);
    let mut work = SensitivityWork::default();
    solver
        .sensitivities(&p, &point, &mut work, &mut d_theta, &mut d_t)
        .unwrap()
        .unwrap();
    let units_angle = ["rad/kg", "rad/kg", "rad/m", "rad/m", "rad s^2/m"];
    let units_time = ["s/kg", "s/kg", "s/m", "s/m", "s^3/m"];
    let results = &json["results"];
    for (i, (name, value)) in PAPER.iter().enumerate() {
        for (of, unit, d, x) in [
            (
                "separation_angle",
                units_angle[i],
                d_theta[i],
                point.separation_angle,
            ),
            (
                "contact_end_angle",
                units_angle[i],
                d_theta[i],
                point.separation_angle,
            ),
            (
                "separation_time",
                units_time[i],
                d_t[i],
                point.separation_time,
            ),
            (
                "contact_end_time",
                units_time[i],
                d_t[i],
                point.separation_time,
            ),
            (
                "contact_force_end_time",
                units_time[i],
                d_t[i],
                point.separation_time,
            ),
        ] {
            let entry = &sens[&format!("d({of})/d({name})")];
            assert_eq!(entry["unit"], unit, "{of} {name}");
            let got = entry["value"].as_f64().unwrap();
            assert!(
                (got - d).abs() <= 1e-9 * d.abs().max(1e-12),
                "d({of})/d({name}): {got} against the per-point solver's {d}"
            );
            assert!(entry["meaning"].as_str().unwrap().contains(name));
            let elasticity = &sens[&format!("elasticity({of};{name})")];
            assert_eq!(elasticity["unit"], "1");
            // The elasticity is (p/x) dx/dp with x the value results.json reports.
            let x_reported = results[of]["value"].as_f64().unwrap();
            assert!((x_reported - x).abs() <= 1e-9 * x, "{of}");
            let e = elasticity["value"].as_f64().unwrap();
            let want = value / x_reported * got;
            assert!(
                (e - want).abs() <= 1e-12 * want.abs().max(1e-12),
                "{of} {name}"
            );
        }
    }
    // The angle does not depend on g at all: an exact zero.
    assert_eq!(sens["d(separation_angle)/d(g)"]["value"], 0.0);
    // The landing comes from the motion integrated with its forward sensitivities, with the
    // landing's units; the floor's contact holds to the landing: no number, and no note of
    // its own beside the one that says it holds.
    assert_eq!(sens["d(floor_impact_time)/d(ell)"]["unit"], "s/m");
    assert_eq!(sens["d(impact_angular_velocity)/d(g)"]["unit"], "rad s/m");
    assert_eq!(
        sens["d(impact_angular_velocity)/d(m1)"]["unit"],
        "rad kg^-1 s^-1"
    );
    let notes = json["notes"].as_object().unwrap();
    assert!(notes.contains_key("floor_normal_end"), "{notes:?}");
    assert!(
        !notes.keys().any(|k| k.starts_with("sensitivities.")),
        "{notes:?}"
    );
    assert!(!sens.keys().any(|k| k.contains("floor_normal")));
}

#[test]
fn sensitivities_of_nothing_wanted_are_a_scene_error_at_their_position() {
    let scene = "# sensitivities of nothing\nmodel: rod_cube\n\
                 parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\n\
                 want: [theta_series, sensitivities]\n";
    let (out, dir) = run_scene("of_nothing", scene);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(out.stdout.is_empty());
    for needle in [
        "scene.yaml:4:22",
        "want[1]",
        "`sensitivities` are of the separation",
    ] {
        assert!(err.contains(needle), "missing {needle:?} in:\n{err}");
    }
    assert!(!dir.join("out").exists(), "no output after a scene error");
}

#[test]
fn an_integrated_run_has_sensitivities_with_their_units() {
    // The friction model has no fast phase: its separation is integrated, with its forward
    // sensitivities (their values are checked against differences in
    // tests/forward_sensitivities.rs).
    let model = rodcube::models::find("rod_cube_friction").unwrap();
    let names: Vec<&str> = model.info().parameters.iter().map(|p| p.name).collect();
    let p: Vec<f64> = (names.iter())
        .map(|n| match *n {
            "m2" => 3.0,
            "a" => 0.25,
            "g" => 9.81,
            "mu" => 1.45,
            _ => 1.0,
        })
        .collect();
    let want = [
        Quantity::SeparationAngle,
        Quantity::SeparationTime,
        Quantity::Sensitivities,
    ];
    let res = plan::run(&Request::new(model, p).with_want(&want)).unwrap();
    assert!(res.results.contains_key("separation_time"));
    assert!(
        !res.notes.keys().any(|k| k.starts_with("sensitivities.")),
        "{:?}",
        res.notes
    );
    for name in names {
        for (of, unit) in [("separation_time", "s"), ("separation_angle", "rad")] {
            let s = &res.sensitivities[&format!("d({of})/d({name})")];
            assert!(s.value.is_finite(), "{of} {name}");
            if name == "mu" {
                assert_eq!(s.unit, unit, "{of} {name}");
            }
        }
    }
}

#[test]
fn a_contact_that_opens_at_release_has_no_sensitivity() {
    let model = rodcube::models::find("rod_cube_closed").unwrap();
    let red = model.reduction().unwrap();
    let p: Vec<f64> = PAPER.iter().map(|(_, v)| *v).collect();
    let mut k = vec![0.0; model.info().n_constants];
    model.prepare(&p, &mut k);
    let si = 0.25;
    let at = SeparationPoint {
        red,
        k: &k,
        parameters: 5,
        sin_initial: si,
        scale: 1.0 - si,
        fall: &[],
        singularities: None,
        sin_sep: si,
        drop: 0.0,
    };
    let (mut a, mut t) = (vec![f64::NAN; 5], vec![f64::NAN; 5]);
    let outcome = sensitivity::separation(
        &at,
        &Prior::new(PRIOR_TOL),
        1e-12,
        &mut SensitivityWork::default(),
        &mut a,
        &mut t,
    )
    .unwrap();
    assert_eq!(outcome, Err(SensitivityGap::AtRelease));
    assert!(a.iter().chain(&t).all(|x| x.is_nan()), "no number written");
}

#[test]
fn sweep_sensitivities_add_columns_equal_to_the_per_point_solver() {
    let dir = fresh("sweep");
    let out = rodcube(
        &dir,
        &[
            "sweep",
            "--n",
            "0.5,3",
            "--a-over-ell",
            "0.25",
            "--set",
            "m1=1,ell=1,g=9.81",
            "--sensitivities",
            "--out",
            "out",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = fs::read_to_string(dir.join("out").join("sweep.csv")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let row: Vec<f64> = (lines.nth(1).unwrap().split(','))
        .map(|x| x.parse().unwrap())
        .collect();
    let model = rodcube::models::find("rod_cube").unwrap();
    let p = [1.0, 3.0, 1.0, 0.25, 9.81];
    let mut solver = LeanSolver::new(model).unwrap();
    let point = solver.solve(&p).unwrap();
    let (mut d_theta, mut d_t) = (vec![0.0; 5], vec![0.0; 5]);
    solver
        .sensitivities(
            &p,
            &point,
            &mut SensitivityWork::default(),
            &mut d_theta,
            &mut d_t,
        )
        .unwrap()
        .unwrap();
    for (i, name) in ["m1", "m2", "ell", "a", "g"].iter().enumerate() {
        assert_eq!(
            row[col(&format!("d(separation_angle)/d({name})"))],
            d_theta[i]
        );
        assert_eq!(row[col(&format!("d(separation_time)/d({name})"))], d_t[i]);
        let e = row[col(&format!("elasticity(separation_time;{name})"))];
        assert_eq!(e, p[i] / point.separation_time * d_t[i]);
    }
}
