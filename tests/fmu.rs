//! `rodcube fmu`: the FMU of the paper's model, its shared library the one cargo's own build of
//! the crate left (`librodcube.so`, the `cdylib` of Cargo.toml's `[lib]`, in `deps/` beside the
//! `rodcube` binary when the library was built only for it, as by `cargo test` or `cargo run`;
//! no second cargo command), which `rodcube fmu` finds by itself, checked by FMPy, an FMI
//! host independent of rodcube (`tests/fmu/check_fmu.py`, in a virtual environment with the
//! versions pinned in `tests/fmu/requirements.txt`; `.ci/run` installs them): the model
//! description validates; the FMU carries the tapes of the system and its fast phases;
//! theta at a 1e-4 s output step equals `rodcube run`'s series at the
//! same times within 1e-9; the contact force first vanishes within one step of the paper's
//! separation; the FMU stops at the landing; a parameter out of its domain is `fmi2Error`
//! with a logged message; the tunable parameters (g, the masses) set between steps change the
//! motion from then on (the same g again: theta within 1e-9 of the unchanged run; a new g:
//! the energy with it conserved within 1e-8 until the contact ends, by the paper's energy
//! integral written out in the script), a fixed one (ell) is refused. The FMU of a model that
//! is only a tape (`tests/specs/sled.yaml`, derived at test time, compiled into no library):
//! every output within 1e-9 of `rodcube run --models` through the push's end and the landing's
//! impact, unzipped where its resource location needs percent-encoding; without its tape, or
//! with the tape edited, `fmi2Instantiate` fails with a logged reason. And the command's
//! refusals: exit status 2, no partial `.fmu`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("fmu")
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed ({:?}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The shared library with the FMI entry points: the one cargo wrote into `deps/` beside this
/// test's `rodcube` when it built the crate for it (Cargo.toml's `[lib]` is also a `cdylib`,
/// and the default features include `fmi`; cargo copies up beside the binary only what was
/// asked for, as `cargo build` asks for the library), where `rodcube fmu` looks for it too.
fn library() -> PathBuf {
    let exe = Path::new(env!("CARGO_BIN_EXE_rodcube"));
    exe.with_file_name("deps").join("librodcube.so")
}

fn rodcube(args: &[&str]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_rodcube"));
    cmd.args(args);
    cmd
}

/// A fresh, empty directory under the test's temporary directory.
fn fresh(name: &str) -> PathBuf {
    let dir = tmp().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temporary directory");
    dir
}

/// The virtual environment with FMPy (made where missing), its Python.
fn python() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let venv = tmp().join("venv");
    std::fs::create_dir_all(tmp()).expect("temporary directory");
    if !venv.join("bin/python").exists() {
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv));
    }
    let python = venv.join("bin/python");
    run(Command::new(&python)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "-r",
        ])
        .arg(root.join("tests/fmu/requirements.txt")));
    python
}

const PAPER: &str = "model: rod_cube\nparameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}\ntolerance: 1.0e-12\n";

#[test]
fn fmpy_validates_and_simulates_the_papers_fmu_as_rodcube_run() {
    let dir = fresh("paper");
    let out = dir.to_str().expect("UTF-8 path");
    // No --binary: the library the build left (as `cargo run` leaves it).
    assert!(
        library().is_file(),
        "the build wrote no {}",
        library().display()
    );
    run(&mut rodcube(&["fmu", "rod_cube", "--out", out]));
    let fmu = dir.join("rod_cube.fmu");
    // `rodcube run`'s series on the FMU's 1e-4 s grid: 0.18 s (before the landing) in 1800
    // steps; and the landing time of the whole motion.
    let series = dir.join("series.yaml");
    let want = "want: [theta_series]\nsamples: 1801\nuntil: 0.18\n";
    std::fs::write(&series, format!("{PAPER}{want}")).expect("scene");
    let landing = dir.join("landing.yaml");
    std::fs::write(&landing, format!("{PAPER}want: [floor_impact]\n")).expect("scene");
    for (scene, name) in [(&series, "series"), (&landing, "landing")] {
        let json = run(rodcube(&["run", "--json", "--out"])
            .arg(dir.join(name))
            .arg(scene))
        .stdout;
        std::fs::write(dir.join(format!("{name}.json")), json).expect("results");
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = run(Command::new(python())
        .arg(root.join("tests/fmu/check_fmu.py"))
        .arg("paper")
        .arg(&fmu)
        .arg(dir.join("series.json"))
        .arg(dir.join("landing.json"))
        .arg("0.18")
        .current_dir(&dir)
        .env("PYTHONDONTWRITEBYTECODE", "1"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("first zero contact force"), "{stdout}");
    assert!(stdout.contains("energy conserved within"), "{stdout}");
    assert!(stdout.contains("carries the tapes of rod_cube"), "{stdout}");
}

/// The spec of a model compiled into no library (as tests/tapes.rs derives it).
const SLED_SPEC: &str = include_str!("specs/sled.yaml");

/// Its scene: every output's series on the FMU's 1e-4 s grid to 0.2 s, through the push's end
/// (0.108 s) and the rod's landing (an impact at 0.187 s).
const SLED_SCENE: &str = "\
model: sled
parameters: {mr: 1.0, mb: 3.0, L: 1.0, h: 0.25, W: 5.0, g: 9.81}
want: [theta_series, push_series, foot_series, tip_floor_series, wall_series, tip_trajectory,
       centre_trajectory, contact_end, impacts]
tolerance: 1.0e-12
samples: 2001
until: 0.2
";

#[test]
fn fmpy_simulates_the_fmu_of_a_model_that_is_only_a_tape_as_rodcube_run() {
    let dir = fresh("sled");
    std::fs::write(dir.join("sled.yaml"), SLED_SPEC).expect("spec");
    std::fs::write(dir.join("scene.yaml"), SLED_SCENE).expect("scene");
    let models = dir.join("models");
    run(rodcube(&["derive", "--tapes-into"])
        .arg(&models)
        .arg("sled.yaml")
        .current_dir(&dir));
    assert_eq!(listing(&models), ["sled.tape.json"]);
    let lib = library().to_str().expect("UTF-8 path").to_string();
    let (models, fmu_dir) = (path_text(&models), path_text(&dir.join("fmu")));
    // Not compiled in: without its tapes there is no such model; and no scene names it.
    let no_tape = ["fmu", "sled", "--out", &fmu_dir, "--binary", &lib];
    refused(&no_tape, "no model `sled`");
    let no_scene = [
        "fmu", "sled", "--models", &models, "--out", &fmu_dir, "--binary", &lib,
    ];
    refused(&no_scene, "give its start values with --scene FILE");
    run(
        rodcube(&["fmu", "sled", "--models", &models, "--scene", "scene.yaml"])
            .args(["--out", &fmu_dir, "--binary", &lib])
            .current_dir(&dir),
    );
    assert_eq!(listing(&dir.join("fmu")), ["sled.fmu"]);
    let json = run(
        rodcube(&["run", "scene.yaml", "--models", &models, "--json"])
            .args(["--out", "run"])
            .current_dir(&dir),
    )
    .stdout;
    std::fs::write(dir.join("run.json"), json).expect("results");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = run(Command::new(python())
        .arg(root.join("tests/fmu/check_fmu.py"))
        .arg("tape")
        .arg(dir.join("fmu/sled.fmu"))
        .arg(dir.join("run.json"))
        .arg(&models)
        .arg("0.2")
        .current_dir(&dir)
        .env("PYTHONDONTWRITEBYTECODE", "1"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    for line in [
        "resources/ carries sled.tape.json as derived",
        "10 outputs (th, th_dot, push, foot, tip_floor, wall, tip.x, tip.y, centre.x, centre.y)",
        "%20",
        "0 to 2",
        "without its tape: fmi2Instantiate fails",
        "with its body edited: fmi2Instantiate fails",
    ] {
        assert!(stdout.contains(line), "{line:?} not in:\n{stdout}");
    }
}

/// A path as the text of an argument.
fn path_text(path: &Path) -> String {
    path.to_str().expect("UTF-8 path").to_string()
}

/// Runs `rodcube fmu` expecting exit status 2 with `message` on stderr.
fn refused(args: &[&str], message: &str) {
    let out = rodcube(args).output().expect("rodcube runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(message), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// The files in `dir`, by name.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn refusals_exit_2_and_leave_no_partial_fmu() {
    let dir = fresh("refusals");
    let lib = library().to_str().expect("UTF-8 path").to_string();
    let out = dir.to_str().expect("UTF-8 path").to_string();
    refused(
        &["fmu", "no_such_model", "--out", &out],
        "no model `no_such_model`",
    );
    refused(
        &["fmu", "rod_cube_closed", "--out", &out],
        "export `rod_cube`",
    );
    let missing = dir.join("missing.so");
    let missing = missing.to_str().expect("UTF-8 path");
    refused(
        &["fmu", "rod_cube", "--out", &out, "--binary", missing],
        "build it with `cargo build --release`",
    );
    // A library with only the first two entry points (as the C library without `fmi` has none).
    let not_fmi = fresh("not_fmi").join("librodcube.so");
    std::fs::write(&not_fmi, b"\x7fELF\0fmi2GetTypesPlatform\0fmi2GetVersion\0").expect("file");
    let not_fmi = not_fmi.to_str().expect("UTF-8 path");
    refused(
        &["fmu", "rod_cube", "--out", &out, "--binary", not_fmi],
        "built without the feature `fmi`",
    );
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
    // An output directory that cannot be made (under a file: refused even to root).
    std::fs::write(dir.join("file"), "").expect("file");
    let under_file = dir.join("file/sub");
    let under_file = under_file.to_str().expect("UTF-8 path");
    let args = ["fmu", "rod_cube", "--out", under_file, "--binary", &lib];
    refused(&args, "cannot create the output directory");
    // A target that cannot be replaced (a directory in its place): the temporary file is gone.
    std::fs::create_dir(dir.join("rod_cube.fmu")).expect("directory");
    refused(
        &["fmu", "rod_cube", "--out", &out, "--binary", &lib],
        "cannot write",
    );
    assert_eq!(listing(&dir), ["file", "rod_cube.fmu"]);
    assert!(dir.join("rod_cube.fmu").is_dir());
    // A system whose fast phases are not loaded: its FMU would lack their tapes.
    let models = dir.join("models");
    std::fs::create_dir(&models).expect("directory");
    std::fs::write(models.join("cube_two.tape.json"), renamed_paper_tape()).expect("tape");
    let scene = dir.join("cube_two.yaml");
    let text = format!(
        "{}want: [separation_angle]\n",
        PAPER.replace("rod_cube", "cube_two")
    );
    std::fs::write(&scene, text).expect("scene");
    let (models, scene) = (path_text(&models), path_text(&scene));
    let args = ["fmu", "cube_two", "--models", &models, "--scene", &scene];
    refused(
        &[&args[..], &["--out", &out, "--binary", &lib]].concat(),
        "the system `cube_two` has the fast phase `cube_two_closed`, which is not loaded",
    );
    assert_eq!(
        listing(&dir),
        ["cube_two.yaml", "file", "models", "rod_cube.fmu"]
    );
}

/// The paper's tape with the system named `cube_two` and its fast phases `cube_two_*`, which
/// no tape holds (the body's digest brought up to date).
fn renamed_paper_tape() -> String {
    let text = rodcube::models::embedded_tape("rod_cube").expect("embedded");
    let mut v: serde_json::Value = serde_json::from_str(text).expect("json");
    v["model"] = "cube_two".into();
    let info = &mut v["body"]["info"];
    info["name"] = "cube_two".into();
    info["system"] = "cube_two".into();
    for p in info["phases"].as_array_mut().expect("phases") {
        let name = p["model"]
            .as_str()
            .expect("a name")
            .replace("rod_cube", "cube_two");
        p["model"] = name.into();
    }
    let body: rodcube::tape::format::Body =
        serde_json::from_value(v["body"].clone()).expect("body");
    v["body_digest"] = body.digest().into();
    serde_json::to_string(&v).expect("json")
}
