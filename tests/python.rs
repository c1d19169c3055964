//! The Python package (`python/`) as users get it: `maturin build --release` makes its abi3
//! wheel, which is installed into a fresh virtual environment under the test's temporary
//! directory with no Rust toolchain on the path (nor the package index: the wheel alone), then
//! its pytest suite (`python/tests`: the README's Python example, the notebook helpers and the
//! example notebook `examples/paper.ipynb` run by nbclient, whose numbers are checked against
//! what this build's `rodcube run` prints, and a model derived here from a spec of the test's own
//! into a directory of tapes, which `python/tests/test_tapes.py` loads with `load_models` and
//! runs by name, and `python/examples/dask_sweep.py`, run on a `dask.distributed` LocalCluster
//! of two workers and on a cluster given by its scheduler's address, whose result
//! `python/tests/test_dask_sweep.py` checks against the local sweep to the bit) runs against
//! it. Needs `python3` with `venv` and the Python package registry (for maturin, NumPy, pytest,
//! pandas, matplotlib, the notebook tools, dask and distributed, at the versions pinned in
//! `python/requirements-test.txt`); `.ci/run` installs them.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `program` in `cwd` with `env` added (or, with `clear`, as the whole environment) and
/// fails the test, with its output, unless it succeeds.
fn run(program: &Path, args: &[&str], cwd: &Path, env: &[(&str, &Path)], clear: bool) {
    let mut cmd = Command::new(program);
    if clear {
        cmd.env_clear();
    }
    cmd.args(args)
        .current_dir(cwd)
        .env("PYTHONDONTWRITEBYTECODE", "1");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", program.display()));
    assert!(
        out.status.success(),
        "{} {args:?} failed:\n{}\n{}",
        program.display(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn utf8(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// Builds the wheel into an emptied `dir` with maturin (from the virtual environment) and
/// returns its path: the one `.whl` there.
fn build_wheel(python: &Path, root: &Path, tmp: &Path, dir: &Path) -> PathBuf {
    if dir.exists() {
        std::fs::remove_dir_all(dir).expect("remove the old wheels");
    }
    // With its own target directory: not the test run's (whose lock `cargo test` may hold), nor
    // the one tests/capi.rs builds the C library in: the rodcube crate is a cdylib, whose files
    // cargo names without a hash, so this build's copy of it (other features) would replace that
    // one's.
    let target = tmp.join("target");
    run(
        python,
        &["-m", "maturin", "build", "--release", "--out", utf8(dir)],
        &root.join("python"),
        &[("CARGO_TARGET_DIR", &target)],
        false,
    );
    let wheels: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("the wheel directory")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "whl"))
        .collect();
    assert_eq!(wheels.len(), 1, "one wheel expected: {wheels:?}");
    let wheel = wheels[0].clone();
    let name = wheel.file_name().and_then(|n| n.to_str()).unwrap_or("");
    assert!(
        name.starts_with("rodcube-") && name.contains("-cp39-abi3-"),
        "an abi3 wheel for Python >= 3.9 expected, got {name}"
    );
    wheel
}

/// A model no build compiles in: the paper's rod on a free block as a plank on a crate, under
/// names of its own, with its fast phases (`plank_closed`, `plank_free`), which
/// `python/tests/test_tapes.py` checks against the paper's closed forms.
const PLANK_SPEC: &str = include_str!("specs/plank.yaml");

/// Derives [`PLANK_SPEC`]'s tapes into an emptied `tmp/tapes` with this build's `rodcube
/// derive --tapes-into` and returns that directory.
fn derive_plank(rodcube: &Path, tmp: &Path) -> PathBuf {
    let tapes = tmp.join("tapes");
    if tapes.exists() {
        std::fs::remove_dir_all(&tapes).expect("remove the old tapes");
    }
    std::fs::write(tmp.join("plank.yaml"), PLANK_SPEC).expect("write the spec");
    run(
        rodcube,
        &["derive", "--tapes-into", "tapes", "plank.yaml"],
        tmp,
        &[],
        false,
    );
    for model in ["plank", "plank_closed", "plank_free"] {
        let tape = tapes.join(format!("{model}.tape.json"));
        assert!(tape.is_file(), "no {}", tape.display());
    }
    tapes
}

#[test]
fn the_python_package_installs_from_its_wheel_and_passes_its_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR")).join("python");
    let venv = tmp.join("venv");
    std::fs::create_dir_all(&tmp).expect("temporary directory");
    if !venv.join("bin/python").exists() {
        run(
            Path::new("python3"),
            &["-m", "venv", "venv"],
            &tmp,
            &[],
            false,
        );
    }
    let python = venv.join("bin/python");
    let quiet = [
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ];
    // The exact versions `.ci/run` installs too.
    let requirements = root.join("python/requirements-test.txt");
    let mut deps = quiet.to_vec();
    deps.extend(["-r", utf8(&requirements)]);
    run(&python, &deps, &tmp, &[], false);
    let wheel = build_wheel(&python, root, &tmp, &tmp.join("wheels"));
    // Installed from the wheel alone: no index, nothing to build, and no Rust toolchain on the
    // path (the environment is cleared but for a PATH holding the virtual environment).
    let bin = venv.join("bin");
    assert!(!bin.join("cargo").exists() && !bin.join("rustc").exists());
    let mut install = quiet.to_vec();
    install.extend([
        "--force-reinstall",
        "--no-deps",
        "--no-index",
        "--only-binary",
        ":all:",
        utf8(&wheel),
    ]);
    run(&python, &install, &tmp, &[("PATH", &bin)], true);
    let tests = root.join("python/tests");
    // From the temporary directory, so that `import rodcube` finds the installed package and
    // pytest writes no cache into the repository.
    let rodcube = Path::new(env!("CARGO_BIN_EXE_rodcube"));
    let tapes = derive_plank(rodcube, &tmp);
    run(
        &python,
        &["-m", "pytest", "-q", "-p", "no:cacheprovider", utf8(&tests)],
        &tmp,
        &[("RODCUBE_BIN", rodcube), ("RODCUBE_TAPES", &tapes)],
        false,
    );
}
