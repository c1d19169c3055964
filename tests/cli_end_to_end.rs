//! The `rodcube` binary end to end on the generated models (`rod_cube`, `hinged_rod`,
//! `wall_ladder`, ...): every shipped scene runs, the paper's scene prints and writes the
//! paper's figures, `--json` is valid JSON, `models` lists them, and scene errors that need a
//! model's parameters name file:line:column and the field.
//!
//! These fail until `generated/` holds the real models: the binary only knows those.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const EXIT_SCENE: i32 = 3;

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_end_to_end")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn rodcube(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn ok(o: &Output) -> String {
    assert_eq!(o.status.code(), Some(0), "stderr:\n{}", text(&o.stderr));
    text(&o.stdout)
}

fn scene_path(name: &str) -> String {
    manifest().join("scenes").join(name).display().to_string()
}

#[test]
fn every_shipped_scene_runs() {
    let dir = fresh("every_scene");
    let mut scenes: Vec<PathBuf> = fs::read_dir(manifest().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 4, "{scenes:?}");
    for scene in scenes {
        let stem = scene.file_stem().unwrap().to_str().unwrap().to_string();
        let out = dir.join(&stem);
        let o = rodcube(
            &dir,
            &[
                "run",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
        );
        let stdout = ok(&o);
        // What a scene asks for is printed: its scalar results, or (a scene that follows the
        // motion through impacts for them) its impacts.
        assert!(
            stdout.contains("\nResults\n") || stdout.contains("\nImpacts ("),
            "{stem}:\n{stdout}"
        );
        assert!(
            out.join("results.json").is_file(),
            "{stem}: no results.json"
        );
    }
}

#[test]
fn the_paper_scene_by_default_prints_the_papers_figures_and_writes_out_paper() {
    // From a directory holding a copy of scenes/paper.yaml, `rodcube run` alone must do it all.
    let dir = fresh("paper_default");
    fs::create_dir_all(dir.join("scenes")).unwrap();
    fs::copy(
        manifest().join("scenes/paper.yaml"),
        dir.join("scenes/paper.yaml"),
    )
    .unwrap();
    let o = rodcube(&dir, &["run"]);
    let stdout = ok(&o);
    // The paper's figures as printed (section 3), then the leading digits of ours: eq. (14)'s
    // root 9.6109706 deg (the degree column's six digits) and t_sep 0.10849325 s (the 256-bit
    // reference, tests/hard_cases.rs), eq. (10)'s time to the floor in contact 0.18692909 s
    // (mpmath quadrature) and sqrt(a/g) = 0.15963771 s, each a prefix of what is printed.
    for want in [
        "9.61°",
        "9.59°",
        "0.108 s",
        "0.187 s",
        "0.159 s",
        "9.61097°",
        "0.10849",
        "0.18692",
        "0.15963",
        "floor_impact_time",
    ] {
        assert!(stdout.contains(want), "missing {want:?} in\n{stdout}");
    }
    assert!(!stdout.contains("FAIL"), "a check failed:\n{stdout}");
    let out = dir.join("out/paper");
    for f in [
        "results.json",
        "theta_series.csv",
        "theta_series.svg",
        "contact_force_series.csv",
        "contact_force_series.svg",
        "tip_trajectory.csv",
        "tip_trajectory.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing in {}", out.display());
    }
    assert!(text(&o.stderr).contains("wrote"), "{}", text(&o.stderr));
}

#[test]
fn json_mode_prints_results_json_on_stdout() {
    let dir = fresh("json");
    let o = rodcube(
        &dir,
        &["run", &scene_path("paper.yaml"), "--json", "--out", "o"],
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    for k in ["model", "parameters", "results", "series", "checks", "work"] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    let t = v["results"]["separation_time"]["value"].as_f64().unwrap();
    // PHYSICS.md: t_sep = 0.10849 s at g = 9.81.
    assert!((t - 0.10849).abs() < 1e-5, "{t}");
    let on_disk: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("o/results.json")).unwrap()).unwrap();
    assert_eq!(v, on_disk);
}

#[test]
fn an_unwritable_output_directory_exits_with_4_before_solving() {
    let dir = fresh("unwritable");
    fs::write(dir.join("file"), b"").unwrap();
    let o = rodcube(
        &dir,
        &["run", &scene_path("angle_only.yaml"), "--out", "file/sub"],
    );
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(4), "{err}");
    assert!(
        err.contains("cannot create the output directory file/sub"),
        "{err}"
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn models_lists_every_model_with_parameters_and_quantities() {
    let stdout = ok(&rodcube(&fresh("models"), &["models"]));
    for want in [
        "rod_cube",
        "hinged_rod",
        "wall_ladder",
        "rod_cube_spring",
        "rod_cylinder",
        "m1",
        "kg",
        "m/s^2",
        "separation_angle",
        "tip_trajectory",
        "contact_force_series",
    ] {
        assert!(stdout.contains(want), "missing {want:?} in\n{stdout}");
    }
    // Phases are listed under their system, not as models a scene may name.
    assert!(
        stdout.contains("fast phases: rod_cube_closed (contact_force, floor_normal closed)")
            && !stdout.contains("\nrod_cube_free:"),
        "{stdout}"
    );
}

/// Runs a scene text and asserts a scene error with every needle on stderr.
fn scene_error(test: &str, scene: &str, needles: &[&str]) {
    let dir = fresh(test);
    fs::write(dir.join("s.yaml"), scene).unwrap();
    let o = rodcube(&dir, &["run", "s.yaml"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(EXIT_SCENE), "stderr:\n{err}");
    assert!(o.stdout.is_empty());
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in\n{err}");
    }
}

#[test]
fn unknown_parameter() {
    scene_error(
        "unknown_parameter",
        "model: rod_cube\nparameters:\n  m1: 1\n  m2: 3\n  ell: 1\n  a: 0.25\n  g: 9.81\n  mu: 0.2\nwant: [separation_angle]\n",
        &[
            "error[unknown-parameter]: parameters.mu:",
            "--> s.yaml:8:3",
            "m1, m2, ell, a, g",
        ],
    );
}

#[test]
fn missing_parameter() {
    scene_error(
        "missing_parameter",
        "model: rod_cube\nwant: [separation_angle]\nparameters: {m1: 1, m2: 3, ell: 1, g: 9.81}\n",
        &["error[missing-parameter]: parameters.a:", "--> s.yaml:3:1"],
    );
}

#[test]
fn non_positive_parameter() {
    scene_error(
        "non_positive",
        "model: rod_cube\nparameters:\n  m1: 1\n  m2: 0\n  ell: 1\n  a: 0.25\n  g: 9.81\nwant: [separation_angle]\n",
        &["error[not-positive]: parameters.m2:", "--> s.yaml:4:7"],
    );
}

#[test]
fn infinite_parameter() {
    scene_error(
        "infinite",
        "model: rod_cube\nparameters:\n  m1: 1\n  m2: .inf\n  ell: 1\n  a: 0.25\n  g: 9.81\nwant: [separation_angle]\n",
        &[
            "error[not-finite]: parameters.m2:",
            "--> s.yaml:4:7",
            ".inf",
        ],
    );
}

#[test]
fn unknown_quantity() {
    scene_error(
        "unknown_quantity",
        "model: rod_cube\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81}\nwant:\n  - separation_angle\n  - tip_trajectroy\n",
        &[
            "error[unknown-quantity]: want[1]:",
            "--> s.yaml:5:5",
            "tip_trajectory",
        ],
    );
}

#[test]
fn unavailable_quantity() {
    scene_error(
        "unavailable",
        "model: rod_cube_friction\nparameters: {m1: 1, m2: 3, ell: 1, a: 0.25, g: 9.81, mu: 0.1}\nwant: [contact_time_to_floor]\n",
        &[
            "error[unavailable-quantity]: want[0]:",
            "--> s.yaml:3:8",
            "no fast phase that starts at release",
        ],
    );
}

#[test]
fn requirement_a_below_ell() {
    scene_error(
        "requirement",
        "model: rod_cube\nparameters:\n  m1: 1\n  m2: 3\n  a: 1.5\n  ell: 1\n  g: 9.81\nwant: [separation_angle]\n",
        &["error[requirement]: parameters.a:", "--> s.yaml:5:3"],
    );
}

#[test]
fn a_bare_rodcube_runs_the_papers_scene_from_any_directory() {
    // An empty directory: the paper's scene is built into the binary, and the outputs go to
    // out/paper/ under the working directory (never into the repository).
    let dir = fresh("bare");
    let out = rodcube(&dir, &[]);
    let table = ok(&out);
    assert!(table.contains("model rod_cube"), "{table}");
    // eq. (14)'s root, 9.6109706 deg, as the table prints it.
    assert!(table.contains("9.61097°"), "{table}");
    assert!(dir.join("out/paper/results.json").is_file());
    // A file still overrides it.
    let scene = dir.join("light.yaml");
    fs::write(
        &scene,
        "model: rod_cube\nparameters: {m1: 1, m2: 0.5, ell: 1, a: 0.25, g: 9.81}\nwant: [separation_angle]\n",
    )
    .unwrap();
    let light = ok(&rodcube(&dir, &["run", "light.yaml"]));
    assert!(!light.contains("9.61097°"), "{light}");
    assert!(dir.join("out/light/results.json").is_file());
}
