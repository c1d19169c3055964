//! The `rodcube` binary on invalid input that needs no generated model: each error exits with
//! its documented status and names file:line:column and the field on stderr, with nothing on
//! stdout; `--help` shows examples. (Errors that need a real model are in cli_end_to_end.rs.)

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const EXIT_USAGE: i32 = 2;
const EXIT_SCENE: i32 = 3;

/// A fresh, empty directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_errors")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `rodcube run <scene>` on `text` written to `<test>/scene.yaml`, inside that directory.
fn run_scene(test: &str, text: &str) -> Output {
    let dir = fresh(test);
    fs::write(dir.join("scene.yaml"), text).unwrap();
    Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(&dir)
        .args(["run", "scene.yaml"])
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a scene error: status 3, empty stdout, and every `needle` on stderr.
fn scene_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(EXIT_SCENE), "stderr:\n{err}");
    assert!(o.stdout.is_empty(), "stdout must stay empty on error");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in stderr:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

const PARAMS: &str = "parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\n";

#[test]
fn yaml_syntax_error() {
    let o = run_scene(
        "syntax",
        "model: rod_cube\nwant: [separation_angle\nsamples: 10\n",
    );
    scene_error(&o, &["error[syntax]", "--> scene.yaml:", "invalid YAML"]);
}

#[test]
fn unknown_key() {
    let o = run_scene(
        "unknown_key",
        &format!("model: rod_cube\n{PARAMS}want: [separation_angle]\nsample: 10\n"),
    );
    scene_error(
        &o,
        &[
            "error[unknown-key]: sample: unknown key `sample`",
            "--> scene.yaml:4:1",
            "4 | sample: 10",
        ],
    );
}

#[test]
fn unknown_model_lists_the_available_ones() {
    let o = run_scene(
        "unknown_model",
        &format!("model: rod_cubo\n{PARAMS}want: [separation_angle]\n"),
    );
    scene_error(
        &o,
        &[
            "error[unknown-model]: model: unknown model `rod_cubo`",
            "--> scene.yaml:1:8",
            "available models: ",
        ],
    );
}

#[test]
fn tolerance_out_of_range() {
    let o = run_scene(
        "tolerance",
        &format!("model: rod_cube\n{PARAMS}want: [separation_angle]\ntolerance: 2.0\n"),
    );
    scene_error(
        &o,
        &[
            "error[out-of-range]: tolerance: must be between",
            "--> scene.yaml:4:12",
        ],
    );
}

#[test]
fn tolerance_not_finite() {
    let o = run_scene(
        "tolerance_nan",
        &format!("model: rod_cube\n{PARAMS}want: [separation_angle]\n\ntolerance: .nan\n"),
    );
    scene_error(
        &o,
        &[
            "error[not-finite]: tolerance: must be a finite number, not .nan",
            "--> scene.yaml:5:12",
        ],
    );
}

#[test]
fn samples_out_of_range() {
    let o = run_scene(
        "samples",
        &format!("model: rod_cube\nsamples: 1\n{PARAMS}want: [separation_angle]\n"),
    );
    scene_error(
        &o,
        &[
            "error[out-of-range]: samples: must be between 2 and",
            "--> scene.yaml:2:10",
        ],
    );
}

#[test]
fn wrong_type() {
    let o = run_scene(
        "wrong_type",
        &format!("model: rod_cube\n{PARAMS}want: separation_angle\n"),
    );
    scene_error(&o, &["error[structure]: want: ", "--> scene.yaml:3:7"]);
}

#[test]
fn missing_scene_file() {
    let dir = fresh("missing");
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(&dir)
        .args(["run", "nope.yaml"])
        .output()
        .unwrap();
    scene_error(
        &o,
        &["error[read]", "--> nope.yaml", "cannot read the scene"],
    );
}

#[test]
fn the_default_scene_is_built_in_and_a_missing_file_is_named() {
    // From a directory without scenes/, `rodcube run` runs the built-in paper's scene...
    let dir = fresh("default_scene");
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(&dir)
        .arg("run")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("out/paper"), "{}", stderr(&o));
    // ...while a scene file that is not there is a read error naming it.
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(&dir)
        .args(["run", "scenes/paper.yaml"])
        .output()
        .unwrap();
    scene_error(&o, &["scenes/paper.yaml", "cannot read"]);
}

#[test]
fn bad_command_line_is_a_usage_error() {
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(["run", "--colour"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(EXIT_USAGE), "{}", stderr(&o));
    // A flag without a subcommand is refused too (no subcommand alone runs the paper scene).
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .arg("--colour")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(EXIT_USAGE), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "usage errors print nothing on stdout");
}

#[test]
fn help_shows_examples_and_exit_statuses() {
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .arg("--help")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let out = String::from_utf8_lossy(&o.stdout);
    for want in [
        "Examples:",
        "rodcube run scenes/hinged.yaml",
        "rodcube models",
        "3 invalid scene",
        "run",
        "models",
    ] {
        assert!(out.contains(want), "missing {want:?} in\n{out}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .args(["run", "--help"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let out = String::from_utf8_lossy(&o.stdout);
    for want in [
        "--json",
        "--out <DIR>",
        "scenes/paper.yaml",
        "want:",
        "tolerance:",
    ] {
        assert!(out.contains(want), "missing {want:?} in\n{out}");
    }
}

#[test]
fn models_lists_without_failing() {
    let o = Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .arg("models")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!o.stdout.is_empty());
}

const EXIT_OUTPUT: i32 = 4;

/// Runs `rodcube <args>` in `dir`.
fn rodcube_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodcube"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// Asserts an output error: status 4, empty stdout, and every `needle` on stderr.
fn output_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(EXIT_OUTPUT), "stderr:\n{err}");
    assert!(o.stdout.is_empty(), "stdout must stay empty on error");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in stderr:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

const VALID: &str = "model: rod_cube\nparameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\nwant: [separation_angle]\n";

#[test]
fn unknown_subcommand_is_a_usage_error() {
    let o = rodcube_in(&fresh("unknown_subcommand"), &["frobnicate"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(EXIT_USAGE), "{err}");
    assert!(err.contains("frobnicate"), "{err}");
    assert!(o.stdout.is_empty());
}

#[test]
fn accuracy_options_that_name_nothing_are_usage_errors_that_write_nothing() {
    let dir = fresh("accuracy_options");
    for (args, needles) in [
        (
            &["--model", "rod_cube_spring,nope"][..],
            &["no model `nope`", "rod_cube_friction"][..],
        ),
        (
            &["--case", "upright"],
            &["no case `upright`", "near_upright"],
        ),
        (
            &["--model", "rod_cube_spring", "--case", "paper"],
            &["no case `paper`", "scene"],
        ),
        (&["--method", "rk4"], &["no method `rk4`", "dop853"]),
        (
            &["--model", "rod_cube_spring", "--method", "halley"],
            &["nothing to measure"],
        ),
    ] {
        let mut all = vec!["accuracy", "--out", "acc"];
        all.extend_from_slice(args);
        let o = rodcube_in(&dir, &all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(EXIT_USAGE), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: missing {n:?} in {err}");
        }
        assert!(!dir.join("acc").exists(), "{args:?}: nothing is written");
    }
}

#[test]
fn out_naming_a_file_is_an_output_error_naming_it() {
    let dir = fresh("out_is_a_file");
    fs::write(dir.join("scene.yaml"), VALID).unwrap();
    fs::write(dir.join("taken"), b"not a directory").unwrap();
    let o = rodcube_in(&dir, &["run", "scene.yaml", "--out", "taken"]);
    output_error(&o, &["taken"]);
    assert_eq!(fs::read(dir.join("taken")).unwrap(), b"not a directory");
}

#[test]
fn a_scene_whose_name_is_not_a_plain_name_needs_out() {
    // Without --out the output directory is out/<scene stem>/; a hidden stem is refused before
    // anything is created, and the message says what to do.
    let dir = fresh("hidden_stem");
    fs::write(dir.join(".hidden.yaml"), VALID).unwrap();
    let o = rodcube_in(&dir, &["run", ".hidden.yaml"]);
    output_error(&o, &[".hidden", "pass --out DIR"]);
    assert!(!dir.join("out").exists(), "nothing may be created");
}

#[test]
fn a_scene_that_is_not_utf8_is_a_read_error_naming_the_file() {
    let dir = fresh("not_utf8");
    fs::write(dir.join("scene.yaml"), b"model: rod_cube\n\xff\xfe\n").unwrap();
    let o = rodcube_in(&dir, &["run", "scene.yaml"]);
    scene_error(&o, &["error[read]", "--> scene.yaml", "not UTF-8"]);
}

#[test]
fn a_scene_that_is_a_directory_is_a_read_error_naming_it() {
    let dir = fresh("scene_is_dir");
    fs::create_dir_all(dir.join("scene.yaml")).unwrap();
    let o = rodcube_in(&dir, &["run", "scene.yaml"]);
    scene_error(
        &o,
        &["error[read]", "--> scene.yaml", "cannot read the scene"],
    );
}

/// `rodcube derive` on specs that fail before any symbolic work (so no Symbolica runs).
#[cfg(feature = "derive")]
mod derive {
    use super::*;

    fn derive(specs: &[&Path]) -> Output {
        let mut args = vec!["derive".to_string(), "--check".to_string()];
        args.extend(specs.iter().map(|p| p.display().to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        rodcube_in(Path::new(env!("CARGO_MANIFEST_DIR")), &args)
    }

    #[test]
    fn a_missing_spec_is_named() {
        let dir = fresh("derive_missing");
        let spec = dir.join("nope.yaml");
        let o = derive(&[&spec]);
        scene_error(&o, &[&spec.display().to_string(), "cannot read"]);
    }

    #[test]
    fn a_bad_spec_names_file_line_column_and_field() {
        let dir = fresh("derive_bad");
        let spec = dir.join("bad.yaml");
        let text = fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("derivations/rod_cube.yaml"),
        )
        .unwrap();
        let line = 1 + text
            .lines()
            .position(|l| l == "gravity: g")
            .expect("rod_cube.yaml declares `gravity: g`");
        fs::write(&spec, text.replace("gravity: g\n", "gravity: gee\n")).unwrap();
        let o = derive(&[&spec]);
        let place = format!("{}:{line}:1: field `gravity`", spec.display());
        scene_error(&o, &[&place, "`gee` is not a parameter"]);
    }
}
