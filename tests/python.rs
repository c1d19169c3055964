//! The Python package (`python/`): built by `pip install ./python` (maturin) in a fresh virtual
//! environment under the test's temporary directory, then its pytest suite (`python/tests`,
//! the README's Python example included) runs against it. Needs `python3` with `venv` and
//! the Python package registry (for maturin, NumPy and pytest, at the versions pinned in
//! `python/requirements-test.txt`); `.ci/run` installs them.

use std::path::Path;
use std::process::Command;

fn run(program: &Path, args: &[&str], cwd: &Path, env: &[(&str, &Path)]) {
    let mut cmd = Command::new(program);
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

#[test]
fn the_python_package_installs_and_passes_its_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR")).join("python");
    let venv = tmp.join("venv");
    std::fs::create_dir_all(&tmp).expect("temporary directory");
    if !venv.join("bin/python").exists() {
        run(Path::new("python3"), &["-m", "venv", "venv"], &tmp, &[]);
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
    let requirements = requirements.to_str().expect("UTF-8 path");
    let mut deps = quiet.to_vec();
    deps.extend(["-r", requirements]);
    run(&python, &deps, &tmp, &[]);
    // Built in place from python/, with its own target directory (not the test run's).
    let target = tmp.join("target");
    let mut install = quiet.to_vec();
    let package = root.join("python");
    let package = package.to_str().expect("UTF-8 path");
    install.extend(["--force-reinstall", "--no-deps", package]);
    run(&python, &install, &tmp, &[("CARGO_TARGET_DIR", &target)]);
    let tests = root.join("python/tests");
    let tests = tests.to_str().expect("UTF-8 path");
    // From the temporary directory, so that `import rodcube` finds the installed package and
    // pytest writes no cache into the repository.
    run(
        &python,
        &["-m", "pytest", "-q", "-p", "no:cacheprovider", tests],
        &tmp,
        &[],
    );
}
