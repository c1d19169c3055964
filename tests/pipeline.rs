//! The whole runtime pipeline in-process, scene file → planner → reports, on the hand-typed
//! models of `tests/common/paper.rs` (so it runs before the generated models exist): the paper's
//! scene reproduces the paper's figures and writes its three plots.

mod common;

use common::paper::MODELS;
use rodcube::io::OutDir;
use rodcube::plan::{self, Request};
use rodcube::quantity::Quantity;
use rodcube::report;
use rodcube::results::RunResults;
use rodcube::scene::Scene;
use std::fs;
use std::path::{Path, PathBuf};

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    Scene::load_with(&path, MODELS).unwrap_or_else(|e| panic!("{e}"))
}

/// What `rodcube run` does between loading and reporting, with the local registry.
fn run(scene: &Scene) -> RunResults {
    let request = Request::new(scene.model, scene.parameters.clone())
        .with_want(&scene.want)
        .with_tolerance(scene.tolerance)
        .with_samples(scene.samples)
        .with_registry(MODELS);
    plan::run(&request).unwrap_or_else(|e| panic!("{e}"))
}

fn value(r: &RunResults, key: &str) -> f64 {
    r.results
        .get(key)
        .unwrap_or_else(|| panic!("no result {key}: {:?}", r.results.keys()))
        .value
}

#[test]
fn the_paper_scene_wants_every_quantity_of_its_model() {
    let s = scene("paper.yaml");
    let mut wanted = s.want.clone();
    wanted.sort();
    let mut all = Quantity::all(s.info());
    all.sort();
    assert_eq!(wanted, all);
    assert_eq!((s.tolerance, s.samples), (1e-12, 1000));
}

#[test]
fn the_paper_scene_reproduces_the_papers_figures() {
    let s = scene("paper.yaml");
    let r = run(&s);
    // PHYSICS.md, g = 9.81: 9.61°, 9.59°, 0.10849 s, 0.18693 s, 0.15964 s.
    assert_eq!(
        format!("{:.2}", value(&r, "separation_angle").to_degrees()),
        "9.61"
    );
    assert_eq!(
        format!(
            "{:.2}",
            value(&r, "linearised_separation_angle").to_degrees()
        ),
        "9.59"
    );
    assert_eq!(format!("{:.5}", value(&r, "separation_time")), "0.10849");
    assert_eq!(
        format!("{:.5}", value(&r, "contact_time_to_floor")),
        "0.18693"
    );
    assert_eq!(
        format!("{:.5}", value(&r, "point_mass_fall_time")),
        "0.15964"
    );

    let text = report::table::render(&r, Some(s.info()), &report::table::Layout::default());
    let ours = format!(
        "{}°",
        report::table::format_number(value(&r, "separation_angle").to_degrees(), 6)
    );
    for want in [
        "9.61°",
        "9.59°",
        "0.108 s",
        "0.187 s",
        "0.159 s",
        "floor_impact_time",
        &ours,
    ] {
        assert!(text.contains(want), "missing {want:?} in\n{text}");
    }

    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("pipeline")
        .join("paper");
    let _ = fs::remove_dir_all(&dir);
    let out = OutDir::create(&dir).unwrap();
    let written: Vec<PathBuf> = report::write_all(&out, &r).unwrap();
    for name in [
        "results.json",
        "theta_series.svg",
        "contact_force_series.svg",
        "tip_trajectory.svg",
        "theta_series.csv",
    ] {
        assert!(
            written.contains(&dir.join(name)),
            "{name} not written: {written:?}"
        );
    }
    let csv = fs::read_to_string(dir.join("theta_series.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + 1000,
        "header and one row per sample"
    );
    assert!(
        csv.starts_with("t [s],theta [rad],theta_dot [rad/s],theta_ddot [rad/s^2]\n"),
        "{}",
        &csv[..80]
    );
}

#[test]
fn the_angle_only_scene_does_only_polynomial_work() {
    let r = run(&scene("angle_only.yaml"));
    assert_eq!(r.results.keys().collect::<Vec<_>>(), ["separation_angle"]);
    assert!(r.series.is_empty() && r.checks.is_empty());
    assert!(r.work.polynomial_evals > 0);
    assert_eq!((r.work.integrand_evals, r.work.ode_steps), (0, 0));
    let text = report::table::render(&r, None, &report::table::Layout::default());
    assert!(text.contains("9.61°") && !text.contains("Series"), "{text}");
}
